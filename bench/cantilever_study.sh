#!/usr/bin/env bash
# Cantilever convergence study (seed Figs 8-9): mesh size h x number of load steps, error at
# lambda = 5 and 10 against the plane-strain Reissner reference (reference.md §1), run time.
# Usage: bench/cantilever_study.sh [RANKS]   (prints a Markdown table; work files in target/bench)
set -euo pipefail
cd "$(dirname "$0")/.."
ranks=${1:-2}
source bench/setup.sh cantilever
echo "| h (m) | steps | particles | u/L at λ=10 | err u | v/L at λ=10 | err v | err v at λ=5 | wall time (s) |"
echo "|---|---|---|---|---|---|---|---|---|"
for h in 0.25 0.125 0.1; do
  for steps in 20 50 100; do
    name="h${h}_n${steps}"
    "$bin" new cantilever -o "$name.h5" --set mesh.h=$h --set steps.count=$steps >/dev/null
    t0=$(date +%s.%N)
    mpirun -n "$ranks" "$bin" "$name.h5" >/dev/null
    t1=$(date +%s.%N)
    python3 - "$name.out/history.csv" "$h" "$steps" "$t0" "$t1" "$name.h5" "$bin" <<'PY'
import csv, subprocess, sys
path, h, steps, t0, t1, case, binary = sys.argv[1:]
rows = list(csv.DictReader(open(path)))
def at(lam):
    return min(rows, key=lambda r: abs(float(r["lambda"]) - lam))
ref = {10: (0.548, 0.8175), 5: (0.378, 0.713)}
r10, r5 = at(10), at(5)
u, v = float(r10["u_over_L"]), float(r10["v_over_L"])
v5 = float(r5["v_over_L"])
n = [l for l in subprocess.run([binary, "info", case], capture_output=True, text=True).stdout.splitlines() if l.startswith("particles")][0].split()[1]
print(f"| {h} | {steps} | {n} | {u:.4f} | {100*(u/ref[10][0]-1):+.2f} % | {v:.4f} | {100*(v/ref[10][1]-1):+.2f} % | {100*(v5/ref[5][1]-1):+.2f} % | {float(t1)-float(t0):.1f} |")
PY
  done
done
