#!/usr/bin/env python3
"""Nkt of a `cpt` run by depth: the mean and range over each band of z/D, and the largest fall
of Nkt from one step to the next once the cone's shoulder is in the clay (z/D > 0.9).

Usage: bench/cpt_bands.py RUN_DIR/history.csv [BAND]   (BAND in diameters, default 0.5)
The history's columns are `z_over_D` and `Nkt`, or `Nkt_cone` and `Nkt_shaft` (summed)."""
import csv
import sys

path = sys.argv[1]
band = float(sys.argv[2]) if len(sys.argv) > 2 else 0.5
with open(path) as f:
    rows = list(csv.DictReader(f))
z = [float(r["z_over_D"]) for r in rows]
if "Nkt" in rows[0]:
    n = [float(r["Nkt"]) for r in rows]
else:
    n = [float(r["Nkt_cone"]) + float(r["Nkt_shaft"]) for r in rows]
k = 0
while k * band < z[-1]:
    lo, hi = k * band, (k + 1) * band
    v = [b for a, b in zip(z, n) if lo <= a + 1e-9 < hi]
    if v:
        print(f"z/D {lo:.2f}-{hi:.2f}: Nkt {sum(v) / len(v):.3f} ({min(v):.3f}-{max(v):.3f}), {len(v)} steps")
    k += 1
falls = [(n[i] / n[i - 1], z[i]) for i in range(1, len(n)) if z[i] > 0.9 and n[i - 1] > 0]
if falls:
    ratio, at = min(falls)
    print(f"largest fall after z/D 0.9: {100 * (1 - ratio):.1f} % at z/D {at:.2f}")
print(f"last: z/D {z[-1]:.3f}, Nkt {n[-1]:.3f}")
