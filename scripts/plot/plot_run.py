#!/usr/bin/env python3
"""Draws a run's pictures from the numbers `yarnhom plot` computed (plotdata.h5).

Usage: plot_run.py PLOTDATA.h5 OUT_DIR

Writes, when the data are there:
  loss_curves.png        train / validation loss per term with the learning rate (supp. Fig. 1)
  surface_<term>.png     2D term over its box widened by half a width on each side: the surface
                         coloured by safeguard sector (supp. Fig. 3a) and the magnitude of its
                         third derivatives (Fig. 3b)
  convexity.png          sign of the Hessian's smallest eigenvalue over each 2D box (Fig. 4)
  lines_1d.png           data against network (and baked table) along each 1D term
Needs numpy, h5py and matplotlib (Debian: python3-numpy python3-h5py python3-matplotlib).
"""
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap, LogNorm  # noqa: E402

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
    if "history" not in f or len(f["history"]) == 0:
        return None
    names = ordered(f["history"])
    fig, axes = panel_grid(len(names), 3.6, 2.8)
    for ax, name in zip(axes.flat, names):
        g = f["history"][name]
        ep = np.arange(1, len(g["train_loss"]) + 1)
        ax.semilogy(ep, g["train_loss"][:], label="train", lw=1)
        ax.semilogy(ep, g["val_loss"][:], label="validation", lw=1)
        ax.set_title(f"term {name}", fontsize=9)
        ax.set_xlabel("epoch", fontsize=8)
        ax.tick_params(labelsize=7)
        lr = ax.twinx()
        lr.semilogy(ep, g["lr"][:], color="grey", ls="--", lw=0.8, label="lr")
        lr.tick_params(labelsize=7, colors="grey")
        if ax is axes.flat[0]:
            h1, l1 = ax.get_legend_handles_labels()
            h2, l2 = lr.get_legend_handles_labels()
            ax.legend(h1 + h2, l1 + l2, fontsize=7)
    fig.suptitle("loss (normalized units) and learning rate (dashed, right axis)", fontsize=10)
    path = save(fig, out, "loss_curves.png")
    return path


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
        ax.set_title(f"Psi_{name} with the safeguard, coloured by sector", fontsize=9)
        handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in SECTOR_COLOURS]
        ax.legend(handles, SECTOR_NAMES, fontsize=6, loc="upper left", ncol=3)
        ax2 = fig.add_subplot(1, 2, 2)
        d3p = np.maximum(d3, max(d3.max() * 1e-6, 1e-300))
        m = ax2.pcolormesh(X, Y, d3p, shading="auto", norm=LogNorm(vmin=d3p.min(), vmax=d3p.max()), cmap="magma")
        box_outline(ax2, lo, hi)
        fig.colorbar(m, ax=ax2, label="|third derivatives| (box-normalized units)")
        ax2.set_xlabel(sx)
        ax2.set_ylabel(sy)
        ax2.set_title(f"third derivatives of Psi_{name} (box outlined)", fontsize=9)
        path = save(fig, out, f"surface_{name}.png")
        paths.append(path)
    return paths


def convexity(f, out):
    if "convexity" not in f or len(f["convexity"]) == 0:
        return None
    names = ordered(f["convexity"])
    fig, axes = panel_grid(len(names), 3.2, 3.0)
    cmap = ListedColormap(["#d62728", "#1f77b4"])  # red non-convex, blue convex
    for ax, name in zip(axes.flat, names):
        g = f["convexity"][name]
        X, Y = np.meshgrid(g["x"][:], g["y"][:], indexing="ij")
        lam = g["lam_min"][:]
        ax.pcolormesh(X, Y, (lam >= 0).astype(float), shading="auto", cmap=cmap, vmin=0, vmax=1)
        frac = 100.0 * np.mean(lam < 0)
        ax.set_title(f"{name}: {frac:.0f}% non-convex ({attr_str(g.attrs['source'])})", fontsize=8)
        ax.set_xlabel(attr_str(g.attrs["symbol_x"]), fontsize=8)
        ax.set_ylabel(attr_str(g.attrs["symbol_y"]), fontsize=8)
        ax.tick_params(labelsize=7)
    fig.suptitle("sign of the Hessian's smallest eigenvalue (blue >= 0 convex, red < 0)", fontsize=10)
    path = save(fig, out, "convexity.png")
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
        ax.set_title(f"Psi_{name}", fontsize=9)
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
