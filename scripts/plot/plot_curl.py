#!/usr/bin/env python3
"""How a strip curls along its length, yarn against continuum (docs/accuracy_rows.md, "The
continuum's curl"): each strip's projected width across its long axis in bands along it, and its
middle cross-section, side by side.

usage: plot_curl.py OUT.png NAME=FILE.obj [NAME=FILE.obj ...] [--bands 11]

FILE.obj: a yarn strip's centrelines (`strip`'s centrelines/step_NNN.obj; its boundary yarn
left out, the fabric alone) or a continuum strip's frame (`sim stretch`'s frames/frame_NNNN.obj).
The width of a band is the extent across of the points within 3 mm of the band's centre, the
measure of accuracy/middle_width.* (whose middle band is the middle one here). Prints the table
it draws (mm).
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import objfile  # noqa: E402

HALF_BAND = 0.003


def fabric_points(path):
    v, _, lines = objfile.read_obj(path)
    if not lines:
        return v
    keep = sorted({i for group, idx in lines if group != "boundary" for i in idx})
    return v[keep]


def profile(p, bands):
    ext = p.max(0) - p.min(0)
    along = 0 if ext[0] >= ext[1] else 1
    across = 1 - along
    lo, hi = p[:, along].min(), p[:, along].max()
    centres = np.linspace(lo, hi, bands)
    widths = []
    for c in centres:
        b = p[np.abs(p[:, along] - c) <= HALF_BAND]
        widths.append((b[:, across].max() - b[:, across].min()) if len(b) else np.nan)
    mid = (lo + hi) / 2
    section = p[np.abs(p[:, along] - mid) <= HALF_BAND][:, [across, 2]]
    return (centres - lo) / (hi - lo), np.array(widths), section


def main(argv):
    if len(argv) < 3:
        sys.exit(__doc__)
    bands = 11
    if "--bands" in argv:
        k = argv.index("--bands")
        bands = int(argv[k + 1])
        argv = argv[:k] + argv[k + 2:]
    out, items = argv[1], [a.split("=", 1) for a in argv[2:]]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    print("position along (fraction of length): " + " ".join(f"{t:5.2f}" for t in np.linspace(0, 1, bands)))
    for name, path in items:
        t, w, sec = profile(fabric_points(path), bands)
        print(f"{name:>12}: " + " ".join(f"{x * 1e3:5.1f}" for x in w))
        ax1.plot(t, w * 1e3, marker="o", label=name)
        c = sec - sec.mean(0)
        ax2.plot(c[:, 0] * 1e3, c[:, 1] * 1e3, "o", ms=2 if len(c) > 100 else 5, label=name)
    ax1.set_xlabel("position along the strip (fraction of its length)")
    ax1.set_ylabel("projected width across (mm)")
    ax1.set_title("width along the strip")
    ax1.legend()
    ax2.set_aspect("equal")
    ax2.set_xlabel("across (mm)")
    ax2.set_ylabel("height (mm)")
    ax2.set_title("middle cross-section (points within 3 mm)")
    ax2.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv)
