#!/usr/bin/env python3
"""Draws the PNG of a `yarnhom study` subcommand from the CSV it wrote (the numbers come from
the program; this script only draws them).

    plot_study.py architectures CSV PNG TITLE
    plot_study.py strip-width CSV PNG TITLE
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def architectures(csv_path, png_path, title):
    rows = list(csv.DictReader(open(csv_path)))
    names = [f"{r['net']}\n[{r['hidden']}]" for r in rows]
    x = range(len(rows))
    fig, ax = plt.subplots(1, 3, figsize=(13, 4))
    ax[0].bar([i - 0.2 for i in x], [float(r["val_loss"]) for r in rows], 0.4, label="yarnhom")
    ax[0].bar([i + 0.2 for i in x], [float(r["paper_val_loss"]) for r in rows], 0.4, label="paper (basket term 0)")
    ax[0].set_ylabel("validation loss (normalized units)")
    ax[0].set_yscale("log")
    ax[0].legend()
    ax[1].bar(list(x), [float(r["seconds"]) for r in rows], 0.5, color="tab:green")
    ax[1].set_ylabel("training time (s)")
    ax[1].set_title("paper: 83.5-114.3 s per network (GPU)", fontsize=9)
    ax[2].bar([i - 0.2 for i in x], [100 * float(r["val_energy_rel_range"]) for r in rows], 0.4,
              label="energy RMSE / range")
    ax[2].bar([i + 0.2 for i in x], [100 * float(r["val_grad_rel_mean"]) for r in rows], 0.4,
              label="gradient error / mean")
    ax[2].axhline(3, color="tab:blue", ls=":", lw=1)
    ax[2].axhline(10, color="tab:orange", ls=":", lw=1)
    ax[2].set_ylabel("validation fit (%)")
    ax[2].set_yscale("log")
    ax[2].legend(fontsize=8)
    for a in ax:
        a.set_xticks(list(x))
        a.set_xticklabels(names, fontsize=8)
    fig.suptitle(f"Supplement Table 3: architectures ({title})")
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)


def strip_width(csv_path, png_path, title):
    """Force per undeformed width against the strip's width, one colour per stretch ratio:
    yarn-level strips solid, continuum strips dashed. A homogenized model describes the bulk,
    so the two should meet as the strip widens if the gap is an edge effect."""
    rows = list(csv.DictReader(open(csv_path)))
    stretches = sorted({r["stretch"] for r in rows}, key=float)
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    for i, s in enumerate(stretches):
        if float(s) == 1.0:
            continue
        sub = sorted((r for r in rows if r["stretch"] == s), key=lambda r: float(r["width_m"]))
        w = [100 * float(r["width_m"]) for r in sub]
        c = f"C{i % 10}"
        ax[0].plot(w, [float(r["N_yarn"]) for r in sub], "o-", color=c, label=f"{100 * float(s):.0f} % yarn")
        ax[0].plot(w, [float(r["N_neural"]) for r in sub], "s--", color=c, mfc="none",
                   label=f"{100 * float(s):.0f} % continuum")
        ax[1].plot(w, [100 * float(r["N_yarn"]) / float(r["N_neural"]) for r in sub], "o-", color=c,
                   label=f"{100 * float(s):.0f} %")
    ax[0].set_xlabel("strip width (cm)")
    ax[0].set_ylabel("clamp force per undeformed width (N/m)")
    ax[0].legend(fontsize=7, ncol=2)
    ax[1].axhline(100, color="k", lw=0.8)
    ax[1].set_xlabel("strip width (cm)")
    ax[1].set_ylabel("yarn / continuum (%)")
    ax[1].legend(fontsize=8)
    fig.suptitle(f"Strip-width study: {title}")
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)


if __name__ == "__main__":
    plots = {"architectures": architectures, "strip-width": strip_width}
    if len(sys.argv) != 5 or sys.argv[1] not in plots:
        sys.exit("usage: plot_study.py architectures|strip-width CSV PNG TITLE")
    plots[sys.argv[1]](sys.argv[2], sys.argv[3], sys.argv[4])
