#!/usr/bin/env python3
"""Admissibility of the recovered and mapped states of a run (issue 28 item 5).

usage: bench/admissible.py RUN_DIR CU [W_OVER_D_FROM]

Reads the last checkpoint of RUN_DIR (particles/state: the states recovered at the particles;
gauss/state: the last step's Gauss states, whose eps_q is at least the mapped start value of a
new triangle) and prints: the particles with negative eps_q (and xi, where the model keeps it),
the most negative, the largest in-plane shear stress over CU at particles and at Gauss points
(over the point's su where the model keeps one), and from RUN_DIR/history.csv the mean, min and
max of the Nc column from w_over_D >= W_OVER_D_FROM (default 0.3).
"""
import csv
import glob
import sys

import h5py
import numpy as np


def columns(ds):
    return [n.decode() if isinstance(n, bytes) else str(n) for n in ds.attrs["names"]]


def report(name, rows, names, cu):
    idx = {n: i for i, n in enumerate(names)}
    tau = np.hypot(0.5 * (rows[:, 0] - rows[:, 1]), rows[:, 3])
    out = [f"{name}: {len(rows)}"]
    for var in ("eps_q", "xi"):
        if var in idx:
            v = rows[:, idx[var]]
            out.append(f"{var} < 0 at {int((v < 0).sum())} (min {v.min():.4g})")
    out.append(f"max tau/cu {tau.max() / cu:.4f}")
    if "su" in idx:
        out.append(f"max tau/su {(tau / rows[:, idx['su']]).max():.4f}")
    print(", ".join(out))


def main():
    run, cu = sys.argv[1], float(sys.argv[2])
    start = float(sys.argv[3]) if len(sys.argv) > 3 else 0.3
    last = sorted(glob.glob(f"{run}/checkpoints/step_*.h5"))[-1]
    with h5py.File(last, "r") as h:
        p = h["particles/state"]
        report("particles", p[...], columns(p), cu)
        g = h["gauss/state"]
        names = columns(g)
        report("gauss points", g[...].reshape(-1, len(names)), names, cu)
    with open(f"{run}/history.csv") as f:
        rows = list(csv.DictReader(f))
    nc = np.array([float(r["Nc"]) for r in rows if float(r["w_over_D"]) >= start - 1e-12])
    print(
        f"Nc from w/D = {start}: mean {nc.mean():.4f}, min {nc.min():.4f}, max {nc.max():.4f}"
        f" ({len(nc)} steps); last {nc[-1]:.4f}"
    )


if __name__ == "__main__":
    main()
