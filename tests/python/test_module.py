#!/usr/bin/env python3
"""The Python module's test (ctest PythonModule.AgreesWithEval): a small baked material, made by
the program (synth, one epoch of train-all, bake, export-hylc), evaluated through the module
agrees with `yarnhom eval` to 1e-12, and the material's stress and tangent are the derivatives
of its energy. Exit 77 (ctest: skipped) when numpy is missing.

Usage: test_module.py --module-dir DIR --yarnhom BINARY
"""
import argparse
import csv
import io
import os
import subprocess
import sys
import tempfile


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--module-dir", required=True)
    ap.add_argument("--yarnhom", required=True)
    a = ap.parse_args()
    try:
        import numpy as np
    except ImportError:
        print("skipped: numpy is not installed")
        return 77
    sys.path.insert(0, a.module_dir)
    import yarnhom

    with tempfile.TemporaryDirectory(prefix="yarnhom_py_") as d:
        def run(*args):
            r = subprocess.run([a.yarnhom, *args], capture_output=True, text=True)
            if r.returncode != 0:
                sys.exit(f"yarnhom {' '.join(args)} failed ({r.returncode}): {r.stderr}")
            return r.stdout

        ds, model, baked, hylc = (os.path.join(d, n) for n in ("d.h5", "m.h5", "b.h5", "m.json"))
        run("synth", "-o", ds, "--preset", "quick")
        run("train-all", ds, "-o", model, "--recipe", "paper", "--epochs", "1", "--threads", "1", "-q",
            "--terms", "0,1,2,3,5,02,13")
        run("bake", model, "-o", baked)
        run("export-hylc", baked, "-o", hylc, "--density", "0.3")

        # One term at a time, against `yarnhom eval` (inside the box and out, in the safeguard).
        worst = 0.0
        for term, pts in (("0", [[-0.3], [0.05], [0.4], [2.0]]),
                          ("02", [[0.1, 0.2], [0.5, -0.1], [-0.4, 1.5], [0.0, 0.0]]),
                          ("13", [[0.2, 30.0], [-1.0, -400.0]])):
            args = ["eval", baked, "--term", term]
            for p in pts:
                args += ["--at", ",".join(repr(v) for v in p)]
            rows = list(csv.reader(io.StringIO(run(*args))))
            header, vals = rows[0], np.array([[float(v) for v in r] for r in rows[1:]])
            d_ = len(pts[0])
            assert header[d_:] == yarnhom.term_columns(term), (header, yarnhom.term_columns(term))
            jet = yarnhom.term_jet(baked, term, np.array(pts, float))
            assert jet.shape == (len(pts), len(header) - d_), jet.shape
            err = np.abs(jet - vals[:, d_:]) / np.maximum(1.0, np.abs(vals[:, d_:]))
            worst = max(worst, err.max())
        print(f"term_jet against yarnhom eval: largest difference {worst:.3g} (relative above 1)")
        assert worst <= 1e-12, worst

        # The whole material: stress and tangent are the derivatives of the energy (central
        # differences), guarded or not; the HYLC export evaluates the same tables.
        rng = np.random.default_rng(1)
        S = rng.uniform([-0.05, -0.2, -0.05, -50, -20, -50], [0.3, 0.2, 0.3, 50, 20, 50], size=(5, 6))
        for guard in (True, False):
            m = yarnhom.Material(baked, guard=guard)
            assert m.kind == "baked"
            psi, stress, tangent = m.evaluate(S)
            assert psi.shape == (5,) and stress.shape == (5, 6) and tangent.shape == (5, 6, 6)
            p0, g0, h0 = m.evaluate(S[0])
            assert abs(p0 - psi[0]) == 0 and np.array_equal(g0, stress[0]) and np.array_equal(h0, tangent[0])
            for i in range(6):
                h = 1e-6 * max(1.0, abs(S[0, i]))
                e = np.zeros(6)
                e[i] = h
                fd = (m.energy(S[0] + e) - m.energy(S[0] - e)) / (2 * h)
                assert abs(fd - stress[0, i]) <= 1e-5 * max(1.0, abs(stress[0, i])), (i, fd, stress[0, i])
                fd2 = (m.stress(S[0] + e) - m.stress(S[0] - e)) / (2 * h)
                assert np.allclose(fd2, tangent[0, :, i], rtol=1e-4, atol=1e-6), (i, fd2, tangent[0, :, i])
        hy = yarnhom.Material(hylc, guard=False)
        assert hy.kind == "hylc"
        bk = yarnhom.Material(baked, guard=False)
        diff = np.abs(hy.energy(S) - bk.energy(S)).max()
        print(f"HYLC export against the baked file: energy difference {diff:.3g} J/m^2")
        assert diff <= 1e-9 * max(1.0, np.abs(bk.energy(S)).max()), diff
        try:
            bk.evaluate(np.zeros(5))
            raise AssertionError("a strain of 5 numbers was accepted")
        except ValueError:
            pass
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
