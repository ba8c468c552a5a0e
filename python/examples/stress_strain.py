#!/usr/bin/env python3
"""Stress-strain curves of a material through the `yarnhom` Python module (docs/python.md).

Usage: stress_strain.py MATERIAL [-o stress_strain.png] [--module-dir build/python]

MATERIAL: a baked file (yarnhom bake) or a HYLC material JSON (yarnhom export-hylc, or HYLC's
own). Draws, for uniaxial strains along the course (s_x) and the wale (s_y) and for shear (s_a),
the other strains held at 0: the stress dPsi/ds (N/m) and the tangent stiffness d2Psi/ds2 (N/m),
as the simulator sees them (collapse guard included); the data box of each strain is not known
to the module, so the range is the README demo's (-0.2 to 1.0, shear -0.7 to 0.7).
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("material")
    ap.add_argument("-o", "--out", default="stress_strain.png")
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--module-dir", default=os.path.join(here, "..", "..", "build", "python"),
                    help="where yarnhom.*.so was built (default: build/python of this checkout)")
    a = ap.parse_args()
    sys.path.insert(0, a.module_dir)
    import yarnhom  # noqa: E402

    m = yarnhom.Material(a.material)
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4))
    for i, name, lo, hi in ((0, "s_x (course)", -0.2, 1.0), (2, "s_y (wale)", -0.2, 1.0), (1, "s_a (shear)", -0.7, 0.7)):
        s = np.zeros((301, 6))
        s[:, i] = np.linspace(lo, hi, 301)
        psi, stress, tangent = m.evaluate(s)
        ax.plot(s[:, i], stress[:, i], label=name)
        bx.plot(s[:, i], tangent[:, i, i], label=name)
    ax.set_xlabel("strain")
    ax.set_ylabel("stress dPsi/ds (N/m)")
    ax.set_title("stress, the other strains at 0")
    bx.set_xlabel("strain")
    bx.set_ylabel("tangent stiffness d2Psi/ds2 (N/m)")
    bx.set_title("tangent stiffness")
    for x in (ax, bx):
        x.grid(alpha=0.3)
        x.axhline(0, color="k", lw=0.5)
        x.legend()
    fig.suptitle(f"{os.path.basename(a.material)} ({m.kind})")
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
