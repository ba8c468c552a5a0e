#!/usr/bin/env python3
"""Pictures of a `yarnhom strip` run (docs/strip.md): the generated strip, the strip at the
last load step (top and side views, yarn black, boundary yarn red) and the force curve.

usage: plot_strip.py RUN_DIR        (writes RUN_DIR/strip.png, deformed.png, force.png)

Only draws what the run wrote: strip.obj, centrelines/step_*.obj, force.csv.
"""
import csv
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

import objfile  # noqa: E402


def read_obj(path):
    """Vertices (n x 3, m) and polylines with their group ('yarn' or 'boundary')."""
    v, _, lines = objfile.read_obj(path)
    return v, lines


def draw(ax, v, lines, axes, width):
    for group, idx in lines:
        p = v[idx][:, axes] * 1e3  # mm
        seg = np.stack([p[:-1], p[1:]], axis=1)
        boundary = group == "boundary"
        ax.add_collection(LineCollection(seg, colors="tab:red" if boundary else "k",
                                         linewidths=0.5 * width if boundary else width))
    ax.autoscale()
    ax.set_aspect("equal")


def views(obj, png, title):
    v, lines = read_obj(obj)
    ext = np.ptp(v, axis=0)
    w = 14.0
    fig, (top, side) = plt.subplots(2, 1, figsize=(w, w * (ext[1] + 0.35 * ext[0]) / max(ext[0], 1e-12) * 0.9 + 1.5),
                                    gridspec_kw={"height_ratios": [max(ext[1], 1e-12), max(ext[2], 0.2 * ext[1])]})
    lw = max(0.3, min(1.5, 2000.0 / len(v)))
    draw(top, v, lines, [0, 1], lw)
    top.set_title(title + " - top view (x: course, y: wale; red: boundary yarn)")
    top.set_xlabel("x (mm)")
    top.set_ylabel("y (mm)")
    draw(side, v, lines, [0, 2], lw)
    side.set_title("side view")
    side.set_xlabel("x (mm)")
    side.set_ylabel("z (mm)")
    fig.tight_layout()
    fig.savefig(png, dpi=130)
    plt.close(fig)


def force_plot(csv_path, png):
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return
    lam = [100 * float(r["stretch"]) for r in rows]
    ten = [float(r["tension_N_per_m"]) for r in rows]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(lam, ten, "o-")
    ax.set_xlabel("stretch (%)")
    ax.set_ylabel("clamp force / width (N/m)")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=130)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    run = sys.argv[1]
    views(os.path.join(run, "strip.obj"), os.path.join(run, "strip.png"), "generated strip")
    steps = sorted(glob.glob(os.path.join(run, "centrelines", "step_*.obj")))
    if steps:
        views(steps[-1], os.path.join(run, "deformed.png"), "last load step (" + os.path.basename(steps[-1]) + ")")
    if os.path.exists(os.path.join(run, "force.csv")):
        force_plot(os.path.join(run, "force.csv"), os.path.join(run, "force.png"))


if __name__ == "__main__":
    main()
