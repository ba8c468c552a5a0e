#!/usr/bin/env python3
"""Draws the PNG of a `yarnhom study` subcommand from the CSV it wrote (the numbers come from
the program; this script only draws them).

    plot_study.py architectures CSV PNG TITLE
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


if __name__ == "__main__":
    if len(sys.argv) != 5 or sys.argv[1] != "architectures":
        sys.exit("usage: plot_study.py architectures CSV PNG TITLE")
    architectures(sys.argv[2], sys.argv[3], sys.argv[4])
