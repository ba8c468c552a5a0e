#!/usr/bin/env python3
"""Draws a `yarnhom sim` run: chosen frames as shaded PNG renders, a video of every frame, and
for a stretch run the force per clamp width against stretch.

Usage: render_sim.py OUT_DIR [--frames 0,30,90] [--mp4]

Reads OUT_DIR/frames/frame_NNNN.obj, OUT_DIR/scene_info.json (colliders) and OUT_DIR/stretch.csv;
writes OUT_DIR/renders/frame_NNNN.png, OUT_DIR/stretch.png and, with --mp4, OUT_DIR/sim.mp4 (every
frame, at most 150 evenly spaced, through ffmpeg when it is installed; one line saying so when
not). Every picture of a run has the same axes: the box of all its frames and colliders. The
cloth is drawn over the colliders: a collider's faces hidden behind the cloth, seen from the
camera, are left out (matplotlib sorts polygons by depth, which alone lets a sphere show through
a cloth lying on it). Moving colliders are drawn where their motion puts them at each frame's
time (scene_info's frame_time times the frame): a capsule along its path, a mesh collider
interpolated between its OBJ frames as the simulator does (held at the last); the simulator
lets an obstacle that the cloth blocks lag behind its path, which the picture does not show. Needs numpy and matplotlib (Debian: python3-numpy python3-matplotlib).
"""
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

import objfile  # noqa: E402


def read_obj(path):
    v, f, _ = objfile.read_obj(path)
    return v, f


def shade(tris, base=(0.85, 0.35, 0.25)):
    """Lambert shading, two-sided, of triangles [m, 3, 3], as RGB (the cloth's warm colour by default)."""
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    light = np.array([0.3, -0.5, 0.8])
    light /= np.linalg.norm(light)
    lam = 0.35 + 0.65 * np.abs(n @ light)
    return np.clip(lam[:, None] * np.asarray(base)[None, :], 0, 1)


ELEV, AZIM = 22, -60  # the camera


def view_dir():
    """Unit vector from the scene toward the camera (matplotlib's view_init angles)."""
    e, a = np.radians(ELEV), np.radians(AZIM)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def sphere_faces(cen, r, nu=48, nv=24):
    """The sphere as quads [m, 4, 3]."""
    u = np.linspace(0, 2 * np.pi, nu + 1)
    v = np.linspace(0, np.pi, nv + 1)
    P = np.stack([np.outer(np.cos(u), np.sin(v)), np.outer(np.sin(u), np.sin(v)),
                  np.outer(np.ones_like(u), np.cos(v))], axis=-1) * r + cen
    quads = np.stack([P[:-1, :-1], P[1:, :-1], P[1:, 1:], P[:-1, 1:]], axis=2)
    return quads.reshape(-1, 4, 3)


def capsule_faces(a, b, r, nu=32, nv=16):
    """A capsule (segment a-b, radius r) as quads [m, 4, 3]: a cylinder and two half spheres."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    ax = b - a
    L = np.linalg.norm(ax)
    w = ax / L
    t = np.cross(w, [1.0, 0, 0] if abs(w[0]) < 0.9 else [0, 1.0, 0])
    t /= np.linalg.norm(t)
    s = np.cross(w, t)
    u = np.linspace(0, 2 * np.pi, nu + 1)
    # Profile: polar angle from -pi/2 (a's cap) to pi/2 (b's cap), the cylinder between.
    th = np.concatenate([np.linspace(-np.pi / 2, 0, nv // 2 + 1), np.linspace(0, np.pi / 2, nv // 2 + 1)])
    off = np.concatenate([np.zeros(nv // 2 + 1), np.full(nv // 2 + 1, L)])
    ring = np.cos(th)[None, :, None] * r * (np.cos(u)[:, None, None] * t + np.sin(u)[:, None, None] * s)
    P = a + ring + (np.sin(th) * r + off)[None, :, None] * w
    quads = np.stack([P[:-1, :-1], P[1:, :-1], P[1:, 1:], P[:-1, 1:]], axis=2)
    return quads.reshape(-1, 4, 3)


def path_offset(path, t):
    """A keyframe path [[t, dx, dy, dz], ...] at time t: piecewise linear, held at both ends
    (sim/obstacles.cpp's path_offset)."""
    if not path:
        return np.zeros(3)
    ts = [k[0] for k in path]
    return np.array([np.interp(t, ts, [k[i] for k in path]) for i in (1, 2, 3)])


class MeshCollider:
    """A mesh collider of scene_info.json: OBJ frames (scaled, moved) or the vertices given."""

    def __init__(self, spec, out):
        self.dt = spec.get("frame_dt", 1.0 / 30)
        self.files = [f if os.path.isabs(f) else os.path.join(out, f) for f in spec.get("frames", [])]
        self.scale = spec.get("scale", 1.0)
        self.offset = np.array(spec.get("translate", [0.0, 0.0, 0.0]))
        self.cache = {}
        if "vertices" in spec:
            self.cache = {k: np.array(v, float) for k, v in enumerate(spec["vertices"])}
            self.faces = np.array(spec["triangles"], int).reshape(-1, 3)
            self.count = len(spec["vertices"])
        else:
            self.count = len(self.files)
            self.faces = None
            self.frame(0)
        self.closed = closed_mesh(self.faces)
        if self.closed:  # turned outward (positive signed volume), so that its back faces can be hidden
            x = self.frame(0)[self.faces]
            if np.einsum("ij,ij->i", x[:, 0], np.cross(x[:, 1], x[:, 2])).sum() < 0:
                self.faces = self.faces[:, ::-1]

    def frame(self, k):
        if k not in self.cache:
            v, f = read_obj(self.files[k])
            if self.faces is None:
                self.faces = f
            self.cache[k] = v * self.scale + self.offset
        return self.cache[k]

    def at(self, t):
        """Vertex positions at time t: linear between frames floor(t / dt) and the next."""
        f = max(0.0, t / self.dt)
        i = min(int(f), self.count - 1)
        j = min(i + 1, self.count - 1)
        u = 0.0 if i == j else f - i
        return (1 - u) * self.frame(i) + u * self.frame(j) if u > 0 else self.frame(i)


def closed_mesh(faces):
    """Whether every edge of the triangles lies in exactly two, once each way (a closed,
    consistently oriented surface: its faces turned away from the camera are hidden)."""
    if faces is None or len(faces) == 0:
        return False
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    fwd = {tuple(x) for x in e.tolist()}
    return len(fwd) == len(e) and all((b, a) in fwd for a, b in fwd)


def frame_time(info, fr):
    return fr * info.get("frame_time", 0.0)


def collider_poses(info, meshes, t):
    """Each drawable collider at time t: ("sphere", centre, r), ("capsule", a, b, r) or
    ("mesh", triangles [m, 3, 3], closed)."""
    out, k = [], 0
    for c in info.get("colliders", []):
        if "sphere" in c:
            out.append(("sphere", np.array(c["sphere"]["center"], float), c["sphere"]["radius"]))
        elif "capsule" in c:
            cp = c["capsule"]
            d = path_offset(cp.get("path", []), t)
            if cp.get("moving") and "path" not in cp:
                continue  # written before paths were: where it is is unknown
            out.append(("capsule", np.array(cp["a"], float) + d, np.array(cp["b"], float) + d, cp["radius"]))
        elif "mesh" in c:
            m = meshes[k]
            k += 1
            x = m.at(t)
            out.append(("mesh", x[m.faces], m.closed))
    return out


def hidden_by(points, tris, d):
    """For each point, whether the ray point + t d (t > 0) hits one of the triangles [m, 3, 3]
    (Moller-Trumbore, vectorized in chunks)."""
    hit = np.zeros(len(points), bool)
    if len(tris) == 0:
        return hit
    v0, e1, e2 = tris[:, 0], tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-18
    v0, e1, e2, p, inv = v0[ok], e1[ok], e2[ok], p[ok], 1.0 / det[ok]
    for s in range(0, len(points), 64):
        o = points[s:s + 64, None, :] - v0[None]
        u = np.einsum("kij,ij->ki", o, p) * inv
        q = np.cross(o, e1[None])
        v = (q @ d) * inv
        t = np.einsum("kij,ij->ki", q, e2) * inv
        hit[s:s + 64] = np.any((u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6), axis=1)
    return hit


def scene_box(out, info, frames, meshes):
    """The box of every frame's vertices and of the colliders where they are at those frames:
    the same axes for every picture."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for fr in frames:
        x, _ = read_obj(os.path.join(out, "frames", "frame_%04d.obj" % fr))
        lo, hi = np.minimum(lo, x.min(axis=0)), np.maximum(hi, x.max(axis=0))
        for c in collider_poses(info, meshes, frame_time(info, fr)):
            if c[0] == "sphere":
                q = np.stack([c[1] - c[2], c[1] + c[2]])
            elif c[0] == "capsule":
                q = np.stack([np.minimum(c[1], c[2]) - c[3], np.maximum(c[1], c[2]) + c[3]])
            else:
                q = c[1].reshape(-1, 3)
            lo, hi = np.minimum(lo, q.min(axis=0)), np.maximum(hi, q.max(axis=0))
    for c in info.get("colliders", []):
        if "plane" in c and abs(c["plane"]["normal"][2]) > 0.9:
            lo[2] = min(lo[2], c["plane"]["point"][2])
    return lo, hi


def render(obj, info, meshes, t, out_png, title, box, dpi=110):
    x, f = read_obj(obj)
    tris = x[f]
    lo, hi = box
    fig = plt.figure(figsize=(6, 5))
    ax = fig.add_subplot(111, projection="3d")
    ax.computed_zorder = False  # drawn in this order: floor, then cloth and colliders sorted together
    for c in info.get("colliders", []):
        if "plane" in c:
            p, nrm = np.array(c["plane"]["point"]), np.array(c["plane"]["normal"])
            if abs(nrm[2]) > 0.9:  # horizontal floors only, under the scene
                xs = np.array([[lo[0], hi[0]], [lo[0], hi[0]]])
                ys = np.array([[lo[1], lo[1]], [hi[1], hi[1]]])
                ax.plot_surface(xs, ys, np.full_like(xs, p[2]), color="0.85", alpha=0.5, zorder=0)
    polys, colours = list(tris), list(shade(tris))
    d = view_dir()
    for c in collider_poses(info, meshes, t):
        if c[0] == "capsule":
            a, b, r = c[1], c[2], c[3]
            q = capsule_faces(a, b, r)
            mid = q.mean(axis=1)
            w = (b - a) / np.linalg.norm(b - a)
            foot = a + np.clip((mid - a) @ w, 0, np.linalg.norm(b - a))[:, None] * w
            front = (mid - foot) @ d > 0
        elif c[0] == "sphere":
            cen, r = c[1], c[2]
            q = sphere_faces(cen, r)
            mid = q.mean(axis=1)
            front = (mid - cen) @ d > 0  # the half facing the camera
        else:
            q, r = c[1], 1e-3  # r: the nudge toward the camera below (m)
            mid = q.mean(axis=1)
            if c[2]:  # closed: the faces turned toward the camera
                front = np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]) @ d > 0
            else:
                front = np.ones(len(q), bool)
        q, mid = q[front], mid[front]
        keep = ~hidden_by(mid + 1e-4 * r * d, tris, d)  # not behind the cloth
        polys += list(q[keep])
        colours += list(shade(q[keep], (0.8, 0.82, 0.86)))  # shaded, so that a collider's shape shows
    pc = Poly3DCollection(polys, facecolors=colours, edgecolors=colours, linewidths=0.2, zorder=1)  # no seams
    ax.add_collection3d(pc)
    mid, half = (lo + hi) / 2, max((hi - lo).max() / 2, 1e-3)
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
    ax.set_zlim(mid[2] - half, mid[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=ELEV, azim=AZIM)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(out_png, dpi=dpi)
    plt.close(fig)


def obstacle_lags(out):
    """Per frame, how far (m) the obstacles ended its last step from their path (steps.csv's
    obstacle_lag_m: the simulator holds back an obstacle that the cloth blocks); {} without."""
    p = os.path.join(out, "steps.csv")
    lags = {}
    if os.path.exists(p):
        for r in csv.DictReader(open(p)):
            if r.get("obstacle_lag_m") not in (None, ""):
                lags[int(r["frame"])] = float(r["obstacle_lag_m"])
    return lags


def title(name, fr, lags):
    """The picture's title; it says so where the obstacles lag behind the path they are drawn on."""
    lag = lags.get(fr, 0.0)
    if lag > 1e-3:
        return "%s, frame %d\n(obstacles drawn on their path; the simulation held them %.0f mm behind)" % (name, fr, 1e3 * lag)
    return "%s, frame %d" % (name, fr)


def video(out, info, meshes, name, frames, box):
    """OUT/sim.mp4 of the frames (at most 150, evenly spaced) through ffmpeg."""
    if os.environ.get("YARNHOM_NO_VIDEO", "") not in ("", "0"):
        return  # asked for no video (timing runs, test suites)
    ffmpeg = shutil.which("ffmpeg")
    if not ffmpeg:
        print("sim: no ffmpeg found: no MP4 written (Debian: apt-get install ffmpeg)", file=sys.stderr)
        return
    if len(frames) < 2:
        return
    pick = sorted(set(frames[int(round(i))] for i in np.linspace(0, len(frames) - 1, min(150, len(frames)))))
    fps = max(2, min(30, round(len(pick) / 4)))  # a short run lasts about 4 s
    lags = obstacle_lags(out)
    tmp = tempfile.mkdtemp(prefix="video.", dir=out)
    try:
        for k, fr in enumerate(pick):
            render(os.path.join(out, "frames", "frame_%04d.obj" % fr), info, meshes, frame_time(info, fr),
                   os.path.join(tmp, "%05d.png" % k), title(name, fr, lags), box, dpi=72)
        part = os.path.join(out, "sim.mp4.part")
        cmd = [ffmpeg, "-y", "-loglevel", "error", "-framerate", str(fps), "-i", os.path.join(tmp, "%05d.png"),
               "-vf", "scale=trunc(iw/2)*2:trunc(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p", "-f", "mp4", part]
        if subprocess.run(cmd).returncode == 0:
            os.replace(part, os.path.join(out, "sim.mp4"))
            print("sim: %s (%d frames at %d per second)" % (os.path.join(out, "sim.mp4"), len(pick), fps), file=sys.stderr)
        else:
            print("sim: ffmpeg failed: no MP4 written (%s)" % " ".join(cmd), file=sys.stderr)
            if os.path.exists(part):
                os.remove(part)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


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
    fdir = os.path.join(out, "frames")
    written = sorted(int(n[6:-4]) for n in (os.listdir(fdir) if os.path.isdir(fdir) else [])
                     if n.startswith("frame_") and n.endswith(".obj") and n[6:-4].isdigit())
    # The box of at most 150 evenly spaced frames and the drawn ones (reading every frame of a
    # long run would take longer than drawing).
    sample = sorted(set(written[int(round(i))] for i in np.linspace(0, len(written) - 1, min(150, len(written))))
                    | (set(frames) & set(written))) if written else []
    meshes = [MeshCollider(c["mesh"], out) for c in info.get("colliders", []) if "mesh" in c]
    box = scene_box(out, info, sample, meshes) if written else None
    lags = obstacle_lags(out)
    if frames:
        os.makedirs(os.path.join(out, "renders"), exist_ok=True)
    for fr in frames:
        if fr not in written:
            print("render_sim: %s missing, skipped" % os.path.join(fdir, "frame_%04d.obj" % fr), file=sys.stderr)
            continue
        if lags.get(fr, 0.0) > 1e-3:
            print("render_sim: frame %d: the obstacles ended %.0f mm from their path (the cloth held them back); "
                  "drawn on their path" % (fr, 1e3 * lags[fr]), file=sys.stderr)
        render(os.path.join(fdir, "frame_%04d.obj" % fr), info, meshes, frame_time(info, fr),
               os.path.join(out, "renders", "frame_%04d.png" % fr), title(name, fr, lags), box)
    if "--mp4" in args and written:
        video(out, info, meshes, name, written, box)
    sc = os.path.join(out, "stretch.csv")
    if os.path.exists(sc):
        stretch_plot(sc, os.path.join(out, "stretch.png"), name)
    return 0


if __name__ == "__main__":
    sys.exit(main())
