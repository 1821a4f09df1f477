#!/usr/bin/env python3
"""Nc per stroke of a `tbar-softening` run: the mean and range of Nc over each stroke's travel
beyond 0.5D from its reversal (the penetration stroke from w = 0).

Usage: bench/tbar_strokes.py RUN_DIR/history.csv [FIRST_STEPS STROKE_STEPS]
(defaults 120 and 240, the built-in's stages)."""
import csv
import sys

path = sys.argv[1]
first = int(sys.argv[2]) if len(sys.argv) > 2 else 120
each = int(sys.argv[3]) if len(sys.argv) > 3 else 240
with open(path) as f:
    rows = [[float(v) for v in r] for r in list(csv.reader(f))[1:]]
bounds = [(0, first)] + [(first + each * k, first + each * (k + 1)) for k in range(20)]
for i, (a, b) in enumerate(bounds):
    seg = [r for r in rows if a < r[0] <= b]
    if not seg:
        break
    w0 = 0.0 if i == 0 else rows[a - 1][1]
    steady = [r[2] for r in seg if abs(r[1] - w0) >= 0.5 - 1e-9]
    part = "" if seg[-1][0] == b else " (part)"
    if steady:
        print(
            f"stroke {i}{part}: w/D {w0:.2f} -> {seg[-1][1]:.2f}, Nc beyond 0.5D: mean "
            f"{sum(steady) / len(steady):.3f}, {min(steady):.3f} to {max(steady):.3f} "
            f"({len(steady)} steps)"
        )
