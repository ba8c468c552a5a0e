#!/usr/bin/env python3
"""PyTorch reference of yarnhom's training math (spec section 6), used as the peer that the
C++ kernels are checked and timed against, as llm.c checks itself against PyTorch.

  yarnhom_ref.py check IN.h5 OUT.h5
      IN holds one network (hidden sizes, flat parameters in yarnhom's layout), a batch (x, y,
      g), off-domain points (xo, no) and loss weights; OUT receives the loss terms and the
      gradient of the total loss with respect to the flat parameters, computed with autograd
      (double precision, derivatives to third order through create_graph=True).

  yarnhom_ref.py train DATASET.h5 [--epochs N] [--terms 0,02] [--threads T] [--device cpu|cuda]
      The paper's recipe (Adam 1e-3, ReduceLROnPlateau(0.5, 80, 0.01), batch 4 / 128, 50 fresh
      off-domain points per batch, 90/10 split) in plain PyTorch, float32, one network after
      the other as a PyTorch user would write it. Prints seconds per epoch for each network
      and the extrapolation to 500 epochs. This is the speed peer of `yarnhom train-all`.
"""
import argparse
import math
import sys
import time

import h5py
import numpy as np
import torch


def unflatten(flat, d, hidden):
    """Flat parameter vector -> list of (W [out, in], b [out]) in yarnhom's layout."""
    sizes = [d] + list(hidden) + [1]
    layers, off = [], 0
    for k in range(len(sizes) - 1):
        n_in, n_out = sizes[k], sizes[k + 1]
        W = flat[off:off + n_out * n_in].reshape(n_out, n_in)
        off += n_out * n_in
        b = flat[off:off + n_out]
        off += n_out
        layers.append((W, b))
    return layers


def mlp(layers, x):
    h = x
    for k, (W, b) in enumerate(layers):
        h = h @ W.T + b
        if k + 1 < len(layers):
            h = torch.sigmoid(h)
    return h[:, 0]


def jets(layers, x, order):
    """Value, gradient [B,d], Hessian entries (xx, xy, yy) and third derivatives (xxx, xxy,
    xyy, yyy) per point, in yarnhom's channel order, by repeated autograd."""
    x = x.detach().requires_grad_(True)
    d = x.shape[1]
    f = mlp(layers, x)
    out = {"f": f}
    if order < 1:
        return out
    g = torch.autograd.grad(f.sum(), x, create_graph=True)[0]
    out["g"] = g
    if order < 2:
        return out
    if d == 1:
        fxx = torch.autograd.grad(g[:, 0].sum(), x, create_graph=True)[0][:, 0]
        out["h"] = [fxx]
        if order >= 3:
            out["t"] = [torch.autograd.grad(fxx.sum(), x, create_graph=True)[0][:, 0]]
        return out
    hx = torch.autograd.grad(g[:, 0].sum(), x, create_graph=True)[0]
    hy = torch.autograd.grad(g[:, 1].sum(), x, create_graph=True)[0]
    fxx, fxy, fyy = hx[:, 0], hx[:, 1], hy[:, 1]
    out["h"] = [fxx, fxy, fyy]
    if order >= 3:
        tx = torch.autograd.grad(fxx.sum(), x, create_graph=True)[0]
        ty = torch.autograd.grad(fyy.sum(), x, create_graph=True)[0]
        out["t"] = [tx[:, 0], tx[:, 1], ty[:, 0], ty[:, 1]]
    return out


def min_eig(h):
    if len(h) == 1:
        return h[0]
    a, b, c = h
    return 0.5 * (a + c) - torch.sqrt(0.25 * (a - c) ** 2 + b ** 2)


def losses(layers, x, y, g, xo, no, w):
    """The spec's L_Z, L_F, L_C (exact), L_S, L_X and the weighted total."""
    wz, wf, wc, ws, wx = w
    order = 3 if wc != 0 else (2 if wx != 0 else 1)
    j = jets(layers, x, order)
    L = {}
    L["z"] = ((j["f"] - y) ** 2).mean()
    L["f"] = ((j["g"] - g) ** 2).sum(dim=1).mean()
    L["c"] = sum(t.abs() for t in j["t"]).mean() if wc != 0 else torch.zeros((), dtype=x.dtype)
    L["x"] = (torch.relu(-min_eig(j["h"])) ** 2).mean() if wx != 0 else torch.zeros((), dtype=x.dtype)
    if xo is not None and xo.shape[0] > 0:
        jo = jets(layers, xo, 1)
        L["s"] = (torch.relu(-(jo["g"] * no).sum(dim=1)) ** 2).mean()
    else:
        L["s"] = torch.zeros((), dtype=x.dtype)
    L["total"] = wz * L["z"] + wf * L["f"] + wc * L["c"] + ws * L["s"] + wx * L["x"]
    return L


def cmd_check(args):
    with h5py.File(args.input, "r") as f:
        d = int(f.attrs["d"])
        hidden = [int(v) for v in f.attrs["hidden"]]
        w = [float(v) for v in f.attrs["weights"]]
        params = torch.tensor(f["params"][:], dtype=torch.float64, requires_grad=True)
        x = torch.tensor(f["x"][:], dtype=torch.float64).reshape(-1, d)
        y = torch.tensor(f["y"][:], dtype=torch.float64)
        g = torch.tensor(f["g"][:], dtype=torch.float64).reshape(-1, d)
        xo = torch.tensor(f["xo"][:], dtype=torch.float64).reshape(-1, d)
        no = torch.tensor(f["no"][:], dtype=torch.float64).reshape(-1, d)
    L = losses(unflatten(params, d, hidden), x, y, g, xo, no, w)
    grad = torch.autograd.grad(L["total"], params)[0]
    with h5py.File(args.output, "w") as f:
        for k in ("total", "z", "f", "c", "s", "x"):
            f.attrs[k] = float(L[k])
        f["grad"] = grad.detach().numpy()


def cmd_train(args):
    torch.set_num_threads(args.threads)
    dev = torch.device(args.device)
    rng = np.random.default_rng(0)
    with h5py.File(args.dataset, "r") as f:
        names = list(f["terms"].keys()) if args.terms == "all" else args.terms.split(",")
        data = {}
        for n in names:
            g = f["terms"][n]
            data[n] = (g["strain"][:], g["energy"][:], g["gradient"][:],
                       np.array(g.attrs["lower"]), np.array(g.attrs["upper"]))
    total_extrapolated = 0.0
    print(f"PyTorch {torch.__version__} on {dev}, {torch.get_num_threads()} thread(s), "
          f"{args.epochs} epoch(s) per network", flush=True)
    for n in names:
        s, e, gr, lo, up = data[n]
        d = s.shape[1]
        c, h = 0.5 * (lo + up), 0.5 * (up - lo)
        perm = rng.permutation(len(e))
        n_val = max(1, min(len(e) - 1, round(0.1 * len(e))))
        tr = perm[n_val:]
        mu, sd = e[tr].mean(), e[tr].std() or 1.0
        X = torch.tensor((s - c) / h, dtype=torch.float32, device=dev)
        Y = torch.tensor((e - mu) / sd, dtype=torch.float32, device=dev)
        G = torch.tensor(gr * h / sd, dtype=torch.float32, device=dev)
        sizes = [d, 16, 32, 16, 1]
        mods = [torch.nn.Linear(sizes[k], sizes[k + 1]) for k in range(4)]
        model = torch.nn.ModuleList(mods).to(dev)
        opt = torch.optim.Adam(model.parameters(), lr=1e-3)
        sched = torch.optim.lr_scheduler.ReduceLROnPlateau(opt, factor=0.5, patience=80, threshold=0.01)
        layers = lambda: [(m.weight, m.bias) for m in model]
        bs = 4 if d == 1 else 128
        tr_t = torch.tensor(tr, device=dev)
        val_t = torch.tensor(perm[:n_val], device=dev)
        w = (1.0, 0.05, 1e-3, 1e2, 0.0)

        def offdomain(k):
            # uniform in [-1.5, 1.5]^d outside [-1, 1]^d, normal of the farthest-beyond face
            pts = []
            while len(pts) < k:
                p = rng.uniform(-1.5, 1.5, size=(4 * k, d))
                p = p[np.abs(p).max(axis=1) > 1.0]
                pts.extend(p.tolist())
            p = np.array(pts[:k])
            ax = np.abs(p).argmax(axis=1)
            nrm = np.zeros_like(p)
            nrm[np.arange(k), ax] = np.sign(p[np.arange(k), ax])
            return (torch.tensor(p, dtype=torch.float32, device=dev),
                    torch.tensor(nrm, dtype=torch.float32, device=dev))

        xo_val, no_val = offdomain(256)
        if dev.type == "cuda":
            torch.cuda.synchronize()
        t0 = time.perf_counter()
        for epoch in range(args.epochs):
            order = tr_t[torch.randperm(len(tr_t), device=dev)]
            for b in range(0, len(order), bs):
                idx = order[b:b + bs]
                xo, no = offdomain(50)
                L = losses(layers(), X[idx], Y[idx], G[idx], xo, no, w)
                opt.zero_grad()
                L["total"].backward()
                opt.step()
            Lv = losses(layers(), X[val_t], Y[val_t], G[val_t], xo_val, no_val, w)
            sched.step(float(Lv["total"]))
        if dev.type == "cuda":
            torch.cuda.synchronize()
        dt = time.perf_counter() - t0
        per_epoch = dt / args.epochs
        total_extrapolated += per_epoch * 500
        print(f"term {n:>3}: {per_epoch * 1e3:8.2f} ms/epoch -> {per_epoch * 500:8.1f} s for 500 epochs"
              f" (val loss {float(Lv['total']):.3e})", flush=True)
    print(f"all {len(names)} networks, 500 epochs each, extrapolated: {total_extrapolated:.1f} s")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("check", help="loss terms and parameter gradient of one batch")
    c.add_argument("input")
    c.add_argument("output")
    t = sub.add_parser("train", help="time the paper's recipe in PyTorch")
    t.add_argument("dataset")
    t.add_argument("--epochs", type=int, default=3)
    t.add_argument("--terms", default="all")
    t.add_argument("--threads", type=int, default=1)
    t.add_argument("--device", default="cpu")
    args = ap.parse_args()
    torch.set_default_dtype(torch.float64)
    if args.cmd == "check":
        cmd_check(args)
    else:
        torch.set_default_dtype(torch.float32)
        cmd_train(args)


if __name__ == "__main__":
    main()
