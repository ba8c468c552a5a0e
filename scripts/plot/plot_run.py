#!/usr/bin/env python3
"""Draws a run's pictures from the numbers `yarnhom plot` computed (plotdata.h5).

Usage: plot_run.py PLOTDATA.h5 OUT_DIR

Writes, when the data are there:
  loss_curves.png        train / validation loss per term with the learning rate (supp. Fig. 1):
                         the Adam epochs, then the L-BFGS polish on its own x-axis segment
  surface_<term>.png     2D term over its box widened by half a width on each side: the surface
                         coloured by safeguard sector (supp. Fig. 3a) with the data points, and
                         the magnitude of its third derivatives (Fig. 3b); a term that fails the
                         fit limits says so in red in its title
  convexity.png          sign of the Hessian's smallest eigenvalue over each 2D box (Fig. 4): of
                         the residual term alone and of the pair's total, explained on the figure
  lines_1d.png           data against network (and baked table) along each 1D term, failing
                         terms marked
Needs numpy, h5py and matplotlib (Debian: python3-numpy python3-h5py python3-matplotlib).
"""
import os
import sys
import textwrap

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap, LogNorm  # noqa: E402
from matplotlib.ticker import NullFormatter  # noqa: E402

# Sector colours: 0 inside (blue, as in the supplement), 1-4 edge bands, 5-8 corners.
SECTOR_COLOURS = ["#3b6fb6", "#e6a532", "#d9603b", "#6ab04c", "#9b59b6",
                  "#f1c40f", "#e67e22", "#1abc9c", "#e84393"]
SECTOR_NAMES = ["inside", "x lower", "x upper", "y lower", "y upper",
                "corner --", "corner +-", "corner -+", "corner ++"]


# The terms in the spec's catalogue order (HDF5 lists groups alphabetically).
ORDER = "0 1 2 3 5 01 02 03 05 12 13 15 23 25".split()


def ordered(group):
    return sorted(group.keys(), key=lambda n: ORDER.index(n) if n in ORDER else len(ORDER))


def attr_str(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def grid_shape(n):
    cols = min(n, 5)
    return (n + cols - 1) // cols, cols


def save(fig, out, name):
    """Lays the figure out, writes OUT/name at 110 dpi, closes it; returns the path."""
    fig.tight_layout()
    path = os.path.join(out, name)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def panel_grid(n, width, height):
    """A figure with n panels of width x height inches, up to 5 a row; unused panels hidden."""
    rows, cols = grid_shape(n)
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows), squeeze=False)
    for ax in axes.flat[n:]:
        ax.axis("off")
    return fig, axes


def loss_curves(f, out):
    """Per term: the Adam epochs on the left half of the x axis, the L-BFGS polish that follows
    (when the recipe has one) on the right half, one log loss axis across both."""
    if "history" not in f or len(f["history"]) == 0:
        return None
    names = ordered(f["history"])
    fig, axes = panel_grid(len(names), 3.8, 2.9)
    any_polish = False
    for ax, name in zip(axes.flat, names):
        g = f["history"][name]
        n_ep = len(g["train_loss"])
        has_polish = "polish_train_loss" in g and len(g["polish_train_loss"]) > 0
        any_polish |= has_polish
        # Epochs at x in (0, 1]; polish iteration k of K at 1 + k / K.
        ep = np.arange(1, n_ep + 1) / n_ep
        ax.semilogy(ep, g["train_loss"][:], color="C0", lw=1, label="train")
        ax.semilogy(ep, g["val_loss"][:], color="C1", lw=1, label="validation")
        ticks, labels = [0, 0.5, 1], ["0", str(n_ep // 2), str(n_ep)]
        if has_polish:
            pt, pv = g["polish_train_loss"][:], g["polish_val_loss"][:]
            k = len(pt)
            px = 1 + np.arange(1, k + 1) / k
            ax.axvspan(1, 2, color="#f2f2f2", zorder=0)
            ax.semilogy(px, pt, color="C0", lw=1)
            ax.semilogy(px, pv, color="C1", lw=1)
            best = int(np.argmin(pv))
            ax.semilogy([px[best]], [pv[best]], "o", color="C3", ms=4, label="polish's result (best validation)")
            ticks += [1.5, 2]
            labels += [str(k // 2), str(k)]
            ax.set_xlim(0, 2)
            ax.set_xlabel("Adam epoch | L-BFGS polish iteration", fontsize=8)
        else:
            ax.set_xlim(0, 1)
            ax.set_xlabel("Adam epoch", fontsize=8)
        ax.set_xticks(ticks)
        ax.set_xticklabels(labels)
        ax.axvline(1, color="k", lw=0.6)
        ax.set_title(f"term {name}", fontsize=9)
        ax.tick_params(labelsize=7)
        lr = ax.twinx()
        lr.semilogy(ep, g["lr"][:], color="grey", ls="--", lw=0.8, label="Adam lr")
        lr.tick_params(which="both", labelsize=6, colors="grey")
        lr.yaxis.set_minor_formatter(NullFormatter())
        if ax is axes.flat[0]:
            h1, l1 = ax.get_legend_handles_labels()
            h2, l2 = lr.get_legend_handles_labels()
            ax.legend(h1 + h2, l1 + l2, fontsize=6)
    title = "loss (normalized units) per term; learning rate dashed, right axis"
    if any_polish:
        title += ("\nleft half: Adam epochs (L_Z + w_F L_F + w_C L_C + w_S L_S); grey right half: the full-batch "
                  "L-BFGS polish that follows (data loss L_Z + w_F L_F), ending on its best validation iterate")
    fig.suptitle(title, fontsize=9)
    path = save(fig, out, "loss_curves.png")
    return path


def fit_title(g, text, width=80):
    """The title with the term's fit verdict (the pipeline report's): 'FAILS' in red when it fails."""
    if "fit_ok" not in g.attrs:
        return text, "black"
    if int(g.attrs["fit_ok"]):
        rule = " by the data rule" if attr_str(g.attrs["verdict"]).startswith("ok by the data rule") else ""
        return text + "  [fit ok" + rule + "]", "black"
    v = attr_str(g.attrs["verdict"]).replace("FAILS: ", "FAILS the fit limits (validation): ")
    return text + "\n" + "\n".join(textwrap.wrap(v, width)), "#c0392b"


def box_outline(ax, lo, hi):
    ax.plot([lo[0], hi[0], hi[0], lo[0], lo[0]], [lo[1], lo[1], hi[1], hi[1], lo[1]], "k-", lw=0.8)


def surfaces(f, out):
    paths = []
    if "surface" not in f:
        return paths
    cmap = ListedColormap(SECTOR_COLOURS)
    for name in ordered(f["surface"]):
        g = f["surface"][name]
        x, y = g["x"][:], g["y"][:]
        psi, sec, d3 = g["psi"][:], g["sector"][:].astype(int), g["d3"][:]
        lo, hi = g.attrs["lower"], g.attrs["upper"]
        sx, sy = attr_str(g.attrs["symbol_x"]), attr_str(g.attrs["symbol_y"])
        X, Y = np.meshgrid(x, y, indexing="ij")
        fig = plt.figure(figsize=(11, 4.6))
        ax = fig.add_subplot(1, 2, 1, projection="3d")
        colours = cmap(sec / 8.0)
        ax.plot_surface(X, Y, psi, facecolors=colours, rstride=2, cstride=2, linewidth=0, antialiased=False, shade=False)
        ax.set_xlabel(sx)
        ax.set_ylabel(sy)
        ax.set_zlabel("Psi (J/m^2)")
        handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in SECTOR_COLOURS]
        names_ = list(SECTOR_NAMES)
        if "data_x" in g:  # the data the network was fitted to, on top (validation rows hollow)
            dx, dy, dp = g["data_x"][:], g["data_y"][:], g["data_psi"][:]
            val = np.zeros(len(dx), bool)
            if "data_val" in g:
                val[g["data_val"][:].astype(int)] = True
            ax.computed_zorder = False  # the points over the surface, all of them
            ax.scatter(dx[~val], dy[~val], dp[~val], s=6, c="k", depthshade=False, zorder=3)
            ax.scatter(dx[val], dy[val], dp[val], s=16, facecolors="white", edgecolors="k", depthshade=False, zorder=4)
            handles += [plt.Line2D([], [], ls="", marker="o", ms=3, color="k"),
                        plt.Line2D([], [], ls="", marker="o", ms=4, mfc="none", mec="k")]
            names_ += ["data (training)", "data (validation)"]
        text, colour = fit_title(g, f"Psi_{name} with the safeguard, coloured by sector")
        ax.set_title(text, fontsize=9, color=colour)
        ax.legend(handles, names_, fontsize=6, loc="upper left", ncol=3)
        ax2 = fig.add_subplot(1, 2, 2)
        d3p = np.maximum(d3, max(d3.max() * 1e-6, 1e-300))
        m = ax2.pcolormesh(X, Y, d3p, shading="auto", norm=LogNorm(vmin=d3p.min(), vmax=d3p.max()), cmap="magma")
        box_outline(ax2, lo, hi)
        fig.colorbar(m, ax=ax2, label="|third derivatives| (box-normalized units)")
        ax2.set_xlabel(sx)
        ax2.set_ylabel(sy)
        if "data_x" in g:
            ax2.plot(g["data_x"][:], g["data_y"][:], ".", ms=2, color="c", label="data points")
            ax2.legend(fontsize=6, loc="upper right")
        ax2.set_title(f"third derivatives of Psi_{name} (box outlined)", fontsize=9)
        path = save(fig, out, f"surface_{name}.png")
        paths.append(path)
    return paths


CONVEXITY_NOTE = (
    "Blue: the coupling term Psi_IJ alone and the pair's total are convex there. A 2D term is a residual, Psi_IJ = Psi - Psi_I - Psi_J, "
    "zero on both axes; a coupling like c s_I s_J has Hessian eigenvalues +-c, so a residual is expected to be "
    "non-convex almost everywhere,\nand that alone says nothing about stability. What the material feels is the pair's "
    "total Psi_I + Psi_J + Psi_IJ: light red, the residual is non-convex but the total is convex (expected, harmless); "
    "dark red, the total itself is non-convex\n(also where a 1D term bends down; the fabric softens: buckling under compression, jamming under shear; "
    "the simulator's Newton solve projects each element's Hessian to PSD). docs/bake.md, \"Convexity\".")


def convexity(f, out):
    if "convexity" not in f or len(f["convexity"]) == 0:
        return None
    names = ordered(f["convexity"])
    fig, axes = panel_grid(len(names), 3.4, 3.1)
    # 0 total non-convex (dark red), 1 residual non-convex but total convex (light red), 2 convex (blue)
    cmap = ListedColormap(["#8b0000", "#f4a6a6", "#1f77b4"])
    for ax, name in zip(axes.flat, names):
        g = f["convexity"][name]
        X, Y = np.meshgrid(g["x"][:], g["y"][:], indexing="ij")
        lam = g["lam_min"][:]
        cls = np.where(lam >= 0, 2.0, 1.0)
        title = f"{name}: residual {100.0 * np.mean(lam < 0):.0f}% non-convex"
        if "lam_min_pair" in g:
            pair = g["lam_min_pair"][:]
            cls = np.where(pair < 0, 0.0, cls)
            title += f"\npair total {100.0 * np.mean(pair < 0):.0f}% non-convex"
        title += f" ({attr_str(g.attrs['source'])})"
        ax.pcolormesh(X, Y, cls, shading="auto", cmap=cmap, vmin=0, vmax=2)
        ax.set_title(title, fontsize=8)
        ax.set_xlabel(attr_str(g.attrs["symbol_x"]), fontsize=8)
        ax.set_ylabel(attr_str(g.attrs["symbol_y"]), fontsize=8)
        ax.tick_params(labelsize=7)
    fig.suptitle("sign of the Hessian's smallest eigenvalue over each 2D term's box", fontsize=10)
    fig.tight_layout(rect=(0, 0.11, 1, 0.97))
    fig.text(0.01, 0.01, CONVEXITY_NOTE, fontsize=7, va="bottom", ha="left", wrap=True)
    path = os.path.join(out, "convexity.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def lines(f, out):
    if "line" not in f or len(f["line"]) == 0:
        return None
    names = ordered(f["line"])
    fig, axes = plt.subplots(1, len(names), figsize=(3.6 * len(names), 3.2), squeeze=False)
    for ax, name in zip(axes.flat, names):
        g = f["line"][name]
        x = g["x"][:]
        lo, hi = g.attrs["lower"][0], g.attrs["upper"][0]
        ax.axvspan(x[0], lo, color="#eee")
        ax.axvspan(hi, x[-1], color="#eee")
        ax.plot(x, g["baked"][:], "-", lw=1.2, label="baked (+ safeguard)")
        if "network" in g:
            ax.plot(x, g["network"][:], "--", lw=1, label="network")
        if "data_x" in g:
            ax.plot(g["data_x"][:], g["data_psi"][:], ".", ms=3, color="k", label="data")
        text, colour = fit_title(g, f"Psi_{name}", 45)
        ax.set_title(text, fontsize=8, color=colour)
        ax.set_xlabel(attr_str(g.attrs["symbol"]), fontsize=8)
        ax.tick_params(labelsize=7)
    axes.flat[0].legend(fontsize=7)
    fig.suptitle("1D terms (grey: outside the trained box)", fontsize=10)
    path = save(fig, out, "lines_1d.png")
    return path


def main():
    if len(sys.argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    data, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    with h5py.File(data, "r") as f:
        fmt = attr_str(f.attrs.get("format", ""))
        if fmt != "yarnhom-plotdata":
            sys.stderr.write(f"{data}: not a yarnhom plot-data file (format '{fmt}')\n")
            return 1
        written = [loss_curves(f, out), *surfaces(f, out), convexity(f, out), lines(f, out)]
    for p in written:
        if p:
            print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
