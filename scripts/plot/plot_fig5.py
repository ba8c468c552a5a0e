#!/usr/bin/env python3
"""Supplement Fig. 5 style picture: the yarn-level strip and the continuum strip at one stretch,
side by side, top view, coloured by displacement from the unstretched state (mm).

usage: plot_fig5.py YARN_REST.obj YARN_STEP.obj CONT_REST.obj CONT_STEP.obj TITLE OUT.png

Only draws: the geometry comes from the OBJ files that `strip` and `sim stretch` write
(yarnhom study table5 calls this). Both strips are centred on their bounding boxes.
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection

import objfile


def read_obj(path):
    v, f, lines = objfile.read_obj(path)
    return v, f, [idx for _, idx in lines]


def main():
    yr, ys, cr, cs, title, out = sys.argv[1:7]
    Y0, _, ylines = read_obj(yr)
    Y1, _, _ = read_obj(ys)
    C0, F, _ = read_obj(cr)
    C1, _, _ = read_obj(cs)
    # Displacement relative to the rest state, after centring both states (rigid placement aside).
    def centre(A):
        return A - 0.5 * (A.min(axis=0) + A.max(axis=0))
    dy = np.linalg.norm(centre(Y1) - centre(Y0), axis=1) * 1e3
    dc = np.linalg.norm(centre(C1) - centre(C0), axis=1) * 1e3
    Y1c, C1c = centre(Y1) * 100, centre(C1) * 100  # cm
    vmax = max(dy.max(), dc.max(), 1e-12)
    fig, ax = plt.subplots(1, 2, figsize=(10, 6), sharex=True, sharey=True)
    segs, cols = [], []
    for ln in ylines:
        for a, b in zip(ln[:-1], ln[1:]):
            segs.append([Y1c[a, :2], Y1c[b, :2]])
            cols.append(0.5 * (dy[a] + dy[b]))
    lc = LineCollection(segs, array=np.array(cols), cmap="viridis", linewidths=1.0)
    lc.set_clim(0, vmax)
    ax[0].add_collection(lc)
    ax[0].set_title("yarn level")
    tp = ax[1].tripcolor(C1c[:, 0], C1c[:, 1], F, dc, shading="gouraud", cmap="viridis", vmin=0, vmax=vmax)
    ax[1].set_title("continuum")
    for a in ax:
        a.set_aspect("equal")
        a.set_xlabel("cm")
        a.autoscale()
    ax[0].set_ylabel("cm")
    fig.colorbar(tp, ax=ax, label="displacement (mm)", shrink=0.8)
    fig.suptitle(title)
    fig.savefig(out, dpi=120)


if __name__ == "__main__":
    main()
