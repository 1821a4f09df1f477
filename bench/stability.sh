#!/usr/bin/env bash
# Long-run stability: an elastic 1 m x 1 m block (h = 0.25, E = 1 MPa, nu = 0.3, base on rollers)
# pressed by a smooth rigid platen to 5 % strain and released, CYCLES times, STEPS steps per
# half cycle (default 20 x 250 = 10 000 remesh-solve steps). Prints, per cycle end (platen back
# at 0): the particle count, the body area - 1 (volume drift), the top corner's displacement (the
# elastic return; the incremental elastic update drifts by a first-order amount per cycle, see
# bench/VALIDATION.md) and the platen force at the cycle's peak; then the wall time.
# Usage: bench/stability.sh [CYCLES] [STEPS]
set -euo pipefail
cycles=${1:-20}
half=${2:-250}
cd "$(dirname "$0")/.."
source bench/setup.sh stability
stages=$(for _ in $(seq "$cycles"); do
  printf '{ to = [0.0, -0.05], steps = %d }, { to = [0.0, 0.0], steps = %d }, ' "$half" "$half"
done)
cat >cycles.toml <<TOML
name = "cycles"
[body]
rectangles = [{ origin = [0.0, 0.0], size = [1.0, 1.0] }]
[mesh]
h = 0.25
refine = false
[material]
model = "linear-elastic"
young = 1.0e6
poisson = 0.3
[[fixed]]
where = "y <= 0"
dofs = ["y"]
[[fixed]]
where = "y <= 0 and x <= 0"
dofs = ["x"]
[[probe]]
name = "top"
at = [1.0, 1.0]
[[rigid]]
name = "platen"
polygon = { vertices = [[-0.5, 1.0], [1.5, 1.0], [1.5, 1.2], [-0.5, 1.2]] }
stages = [${stages%, }]
[output]
fields_every = 0
checkpoint_every = 0
[history]
columns = [
  { name = "area", measure = "area" },
  { name = "fy", measure = "rigid.platen.fy" },
  { name = "top_ux", measure = "probe.top.ux" },
  { name = "top_uy", measure = "probe.top.uy" },
]
TOML
"$bin" new cycles.toml -o cycles.h5 >/dev/null
t0=$(date +%s.%N)
"$bin" cycles.h5 --out cycles.out >run.log 2>&1 || { tail -3 run.log; exit 1; }
t1=$(date +%s.%N)
echo "| cycle | step | area − 1 | top ux (m) | top uy (m) | peak platen force (N/m) |"
echo "|---|---|---|---|---|---|"
awk -F, -v half="$half" 'NR > 1 {
  if ($1 % (2 * half) == half) peak = $3
  if ($1 % (2 * half) == 0) printf "| %d | %d | %.3e | %.3e | %.3e | %.5e |\n", $1 / (2 * half), $1, $2 - 1, $4, $5, peak
}' cycles.out/history.csv
n=$(grep -o 'particles [0-9]*' run.log | sort -u | tr '\n' ' ')
echo
echo "particle counts reported: $n; worst |area − 1|: $(awk -F, 'NR > 1 { d = $2 - 1; if (d < 0) d = -d; if (d > w) w = d } END { printf "%.3e", w }' cycles.out/history.csv); wall time $(echo "$t1 - $t0" | bc) s"
