#!/usr/bin/env bash
# Prandtl study on the built-in `footing-shallow` (stiff clay, graded jittered cloud, pushed to
# z/B = 0.003): the default mesh and the same grading with every spacing doubled (2h) and
# quadrupled (4h), and h/2 with `--fine`; P2-P1 against plain P2. Prints a Markdown table.
# Usage: bench/footing_study.sh [RANKS] [--fine]
set -euo pipefail
cd "$(dirname "$0")/.."
ranks=${1:-2}
source bench/setup.sh footing

# mesh.h and the three fine spacings, finest at the footing edge.
meshes=("4h 1.0 0.5 0.25 0.125" "2h 0.5 0.25 0.125 0.0625" "h 0.25 0.125 0.0625 0.03125")
if [[ "${2:-}" == "--fine" ]]; then
  meshes+=("h/2 0.125 0.0625 0.03125 0.015625")
fi
echo "| element | mesh | finest h (m) | particles | q/cu at z/B = 0.002 | q/cu at z/B = 0.003 | error at 0.003 | Newton its | wall time (s) |"
echo "|---|---|---|---|---|---|---|---|---|"
for element in p2p1 p2; do
  for m in "${meshes[@]}"; do
    read -r label h h1 h2 h3 <<<"$m"
    name="${element}_${label//\//_}"
    fine="mesh.fine=[{origin=[0.0,8.0],size=[4.0,2.0],h=$h1},{origin=[0.5,9.5],size=[1.0,0.5],h=$h2},{origin=[0.75,9.75],size=[0.5,0.25],h=$h3}]"
    "$bin" new footing-shallow -o "$name.h5" --set mesh.h=$h --set "$fine" \
      --set solver.element=$element >/dev/null
    t0=$(date +%s.%N)
    if mpirun -n "$ranks" "$bin" "$name.h5" --out "$name.out" >"$name.log" 2>&1; then
      t1=$(date +%s.%N)
      q2=$(awk -F, '$1 == 20 { print $3 }' "$name.out/history.csv")
      q3=$(tail -1 "$name.out/history.csv" | cut -d, -f3)
      n=$("$bin" info "$name.h5" | awk '/^particles/ {print $2}')
      its=$(grep -o 'done: .* \([0-9]*\) Newton' "$name.log" | grep -o '[0-9]* Newton' | cut -d' ' -f1)
      err=$(awk -v q="$q3" 'BEGIN { printf "%+.2f", 100 * (q / (2 + atan2(0, -1)) - 1) }')
      printf '| %s | %s | %s | %s | %.4f | %.4f | %s %% | %s | %.1f |\n' "$element" "$label" "$h3" "$n" \
        "$q2" "$q3" "$err" "$its" "$(echo "$t1 - $t0" | bc)"
    else
      printf '| %s | %s | %s | | failed: %s | | | | |\n' "$element" "$label" "$h3" \
        "$(grep -m1 -o 'step [0-9]*: Newton did not converge ([A-Z_]*)' "$name.log")"
    fi
  done
done
