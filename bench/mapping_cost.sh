#!/usr/bin/env bash
# What state mapping costs in accuracy: the default cantilever with unchanged triangles keeping
# their Gauss states (default) against every triangle mapped Gauss -> particle -> Gauss every step
# (mesh.remap_all = true, as Abaqus' mesh-to-mesh mapping does). Usage: bench/mapping_cost.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/setup.sh mapping
echo "| mapping | h (m) | u/L at λ=10 | v/L at λ=10 | v/L change |"
echo "|---|---|---|---|---|"
for h in 0.25 0.125; do
  "$bin" new cantilever -o keep.h5 --set mesh.h=$h >/dev/null
  "$bin" new cantilever -o remap.h5 --set mesh.h=$h --set mesh.remap_all=true >/dev/null
  mpirun -n 2 "$bin" keep.h5 >/dev/null
  mpirun -n 2 "$bin" remap.h5 >/dev/null
  python3 - "$h" <<'PY'
import sys
h = sys.argv[1]
k = open("keep.out/history.csv").read().split()[-1].split(",")
r = open("remap.out/history.csv").read().split()[-1].split(",")
for name, row in (("keep unchanged triangles", k), ("remap every triangle", r)):
    print(f"| {name} | {h} | {float(row[2]):.5f} | {float(row[3]):.5f} | {100*(float(row[3])/float(k[3])-1):+.3f} % |")
PY
  rm -rf keep.out remap.out
done
