#!/usr/bin/env python3
"""Compares the last frames of `yarnhom sim` runs (scripts/study_one_solve_floor.sh).

    python3 scripts/compare_last_frames.py OUT_DIR

OUT_DIR holds run folders named PREFIX_VARIANT (PREFIX = material_scene_resolution); in each
group the run PREFIX_newton is the reference. One markdown table row per run: the rms / max
vertex distance of its last frame to the reference's (m), to the nearest other Newton run of the
group (newton_*), the centre of mass's move (vertex mean, m), the lowest point (m), the bounding
box's extents (m), how far the sheet moved over the last frame (rms, m), the potential and kinetic
energy and largest speed at the last step, and the residual force the run's log reports for its
last frame (yarnhom sim's summary line "residual force ...", if present).
"""
import csv
import glob
import math
import os
import re
import sys


def frames(d):
    return sorted(glob.glob(os.path.join(d, "frames", "frame_*.obj")))


def read_obj(path):
    with open(path) as f:
        return [tuple(float(t) for t in l.split()[1:4]) for l in f if l.startswith("v ")]


def dist(a, b):
    if not a or not b or len(a) != len(b):
        return None
    ds = [math.dist(p, q) for p, q in zip(a, b)]
    return math.sqrt(sum(x * x for x in ds) / len(ds)), max(ds)


def fmt(d):
    return "" if d is None else "%.4f / %.4f" % d


def main():
    out = sys.argv[1]
    runs = {}
    for st in sorted(glob.glob(os.path.join(out, "*.status"))):
        d = st[: -len(".status")]
        base = os.path.basename(d)
        m = re.match(r"(.*_\d+)_((?:newton|linearized).*)$", base)
        if not m:
            continue
        runs.setdefault(m.group(1), {})[m.group(2)] = d
    head = ("run", "exit", "steps", "it/step", "last frame to Newton's, rms / max (m)",
            "to the nearest other Newton run (m)", "centre of mass moved (m)", "lowest point (m)",
            "extents x / y / z (m)", "last frame's move, rms (m)", "potential (J)", "kinetic (J)",
            "max speed (m/s)", "residual force / vertex weight off the colliders, rms / max")
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for prefix, group in runs.items():
        last = {}
        for var, d in group.items():
            fs = frames(d)
            last[var] = (read_obj(fs[-1]) if fs else None, read_obj(fs[-2]) if len(fs) > 1 else None)
        ref = last.get("newton", (None, None))[0]
        for var in sorted(group, key=lambda v: (not v.startswith("newton"), v != "newton", v)):
            d = group[var]
            status = open(d + ".status").read().strip()
            a, prev = last[var]
            path = os.path.join(d, "steps.csv")
            steps = list(csv.DictReader(open(path))) if os.path.exists(path) else []
            if not steps or not a:
                print("| %s | %s |%s" % (os.path.basename(d), status, " |" * (len(head) - 2)))
                continue
            its = sum(float(s["newton_iterations"]) for s in steps) / len(steps)
            others = [dist(a, last[o][0]) for o in group if o.startswith("newton") and o != var and last[o][0]]
            others = [o for o in others if o]
            nearest = min(others) if others else None
            n = len(a)
            com = [sum(p[k] for p in a) / n for k in range(3)]
            com_move = ""
            if ref:
                cr = [sum(p[k] for p in ref) / n for k in range(3)]
                com_move = "%.4f" % math.dist(com, cr)
            lo = [min(p[k] for p in a) for k in range(3)]
            hi = [max(p[k] for p in a) for k in range(3)]
            up = 2  # z is up (gravity along -z)
            moved = dist(a, prev)
            residual = ""
            log = d + ".log"
            if os.path.exists(log):
                for line in open(log):
                    r = re.search(r"residual force[^:]*: rms ([0-9.eE+-]+), max ([0-9.eE+-]+)", line)
                    if r:
                        residual = "%s / %s" % (r.group(1), r.group(2))
            s = steps[-1]
            row = (os.path.basename(d), status, str(len(steps)), "%.2f" % its,
                   "" if var == "newton" else fmt(dist(a, ref)), fmt(nearest), com_move, "%.4f" % lo[up],
                   "%.3f / %.3f / %.3f" % tuple(h - l for h, l in zip(hi, lo)),
                   "%.2g" % moved[0] if moved else "", "%.6g" % float(s["potential_J"]),
                   "%.3g" % float(s["kinetic_J"]), "%.3g" % float(s["max_speed_m_per_s"]), residual)
            print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
