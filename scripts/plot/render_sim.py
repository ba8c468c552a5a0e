#!/usr/bin/env python3
"""Draws a `yarnhom sim` run: chosen frames as shaded PNG renders, and for a stretch run the
force per clamp width against stretch.

Usage: render_sim.py OUT_DIR [--frames 0,30,90]

Reads OUT_DIR/frames/frame_NNNN.obj, OUT_DIR/scene_info.json (colliders) and OUT_DIR/stretch.csv;
writes OUT_DIR/renders/frame_NNNN.png and OUT_DIR/stretch.png. Needs numpy and matplotlib
(Debian: python3-numpy python3-matplotlib).
"""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

import objfile  # noqa: E402


def read_obj(path):
    v, f, _ = objfile.read_obj(path)
    return v, f


def shade(tris):
    """Lambert shading, two-sided, of triangles [m, 3, 3], as RGB."""
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    light = np.array([0.3, -0.5, 0.8])
    light /= np.linalg.norm(light)
    lam = 0.35 + 0.65 * np.abs(n @ light)
    base = np.array([0.85, 0.35, 0.25])  # front: warm; back side slightly darker
    return np.clip(lam[:, None] * base[None, :], 0, 1)


def render(obj, info, out_png, title):
    x, f = read_obj(obj)
    tris = x[f]
    fig = plt.figure(figsize=(6, 5))
    ax = fig.add_subplot(111, projection="3d")
    lo, hi = x.min(axis=0), x.max(axis=0)
    for c in info.get("colliders", []):
        if "sphere" in c:
            s = c["sphere"]
            cen, r = np.array(s["center"]), s["radius"]
            u, v = np.mgrid[0:2 * np.pi:24j, 0:np.pi:12j]
            ax.plot_wireframe(cen[0] + r * np.cos(u) * np.sin(v), cen[1] + r * np.sin(u) * np.sin(v),
                              cen[2] + r * np.cos(v), color="0.6", linewidth=0.4)
            lo, hi = np.minimum(lo, cen - r), np.maximum(hi, cen + r)
    for c in info.get("colliders", []):
        if "plane" in c:
            p, nrm = np.array(c["plane"]["point"]), np.array(c["plane"]["normal"])
            if abs(nrm[2]) > 0.9:  # draw horizontal floors only, under the scene
                z = p[2] - (nrm[0] * 0 + nrm[1] * 0)
                xs = np.array([[lo[0], hi[0]], [lo[0], hi[0]]])
                ys = np.array([[lo[1], lo[1]], [hi[1], hi[1]]])
                ax.plot_surface(xs, ys, np.full_like(xs, z), color="0.85", alpha=0.5)
                lo[2] = min(lo[2], z)
    pc = Poly3DCollection(tris, facecolors=shade(tris), edgecolors="none")
    ax.add_collection3d(pc)
    mid, half = (lo + hi) / 2, max((hi - lo).max() / 2, 1e-3)
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
    ax.set_zlim(mid[2] - half, mid[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=22, azim=-60)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
    plt.close(fig)


def stretch_plot(csv_path, out_png, name):
    rows = list(csv.DictReader(open(csv_path)))
    if not rows:
        return
    st = np.array([100 * float(r["stretch"]) for r in rows])
    n = np.array([float(r["force_per_width_N_per_m"]) for r in rows])
    key = [k for k in rows[0] if k.startswith("middle_dPsi")][0]
    d = np.array([float(r[key]) for r in rows])
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.plot(st, n, "o-", label="clamp reaction / undeformed width")
    ax.plot(st, d, "x--", label=key.replace("middle_", "material ").replace("_N_per_m", "") + " at the middle")
    ax.set_xlabel("stretch (%)")
    ax.set_ylabel("force per width (N/m)")
    ax.set_title(name)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
    plt.close(fig)


def main():
    args = sys.argv[1:]
    if not args:
        print(__doc__)
        return 2
    out = args[0]
    frames = []
    if "--frames" in args:
        frames = [int(s) for s in args[args.index("--frames") + 1].split(",") if s]
    info_path = os.path.join(out, "scene_info.json")
    info = json.load(open(info_path)) if os.path.exists(info_path) else {}
    name = info.get("name", "sim")
    if frames:
        os.makedirs(os.path.join(out, "renders"), exist_ok=True)
    for fr in frames:
        obj = os.path.join(out, "frames", "frame_%04d.obj" % fr)
        if not os.path.exists(obj):
            print("render_sim: %s missing, skipped" % obj, file=sys.stderr)
            continue
        render(obj, info, os.path.join(out, "renders", "frame_%04d.png" % fr), "%s, frame %d" % (name, fr))
    sc = os.path.join(out, "stretch.csv")
    if os.path.exists(sc):
        stretch_plot(sc, os.path.join(out, "stretch.png"), name)
    return 0


if __name__ == "__main__":
    sys.exit(main())
