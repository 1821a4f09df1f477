#!/usr/bin/env bash
# The built-in `footing-mohr-coulomb` (smooth strip on weightless c-phi soil, phi = psi = 30 deg)
# at its default on 1 and 2 ranks against the exact Nc = 30.14; with --study also the same
# grading with every spacing doubled (2h, the tests' coarse cloud) and halved (h/2), 1 rank.
# Prints a Markdown table: particles, steps, q/c at z/B = 0.001 and 0.002, the error at 0.002,
# Newton iterations, wall time; then the largest difference between the 1- and 2-rank curves.
# Usage: bench/footing_mohr_coulomb.sh [--study]
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/setup.sh footing-mohr-coulomb

# (Nq - 1) cot phi with Nq = e^(pi tan phi) tan^2(45 deg + phi/2).
nc=$(python3 -c 'import math; p = math.radians(30); print((math.exp(math.pi * math.tan(p)) * math.tan(math.pi / 4 + p / 2) ** 2 - 1) / math.tan(p))')
runs=("h 1 0.5 0.25 0.125 0.0625" "h 2 0.5 0.25 0.125 0.0625")
if [[ "${1:-}" == "--study" ]]; then
  runs+=("2h 1 1.0 0.5 0.25 0.125" "h/2 1 0.25 0.125 0.0625 0.03125")
fi
echo "Nc = $nc"
echo
echo "| cloud | ranks | particles | steps | q/c at z/B = 0.001 | q/c at z/B = 0.002 | error at 0.002 | Newton its | wall time (s) |"
echo "|---|---|---|---|---|---|---|---|---|"
for r in "${runs[@]}"; do
  read -r label ranks h h1 h2 h3 <<<"$r"
  name="${label//\//_}_$ranks"
  fine="mesh.fine=[{origin=[0.0,3.0],size=[11.0,4.0],h=$h1},{origin=[0.0,5.5],size=[3.0,1.5],h=$h2},{origin=[0.5,6.5],size=[1.0,0.5],h=$h3}]"
  "$bin" new footing-mohr-coulomb -o "$name.h5" --set mesh.h="$h" --set "$fine" >/dev/null
  n=$("$bin" info "$name.h5" | awk '/^particles/ {print $2}')
  t0=$(date +%s.%N)
  if mpirun -n "$ranks" "$bin" "$name.h5" --out "$name.out" >"$name.log" 2>&1; then
    t1=$(date +%s.%N)
    h=$name.out/history.csv
    q1=$(awk -F, '$1 == 10 { print $3 }' "$h")
    q2=$(awk -F, '$1 == 20 { print $3 }' "$h")
    its=$(grep -o 'done: .* \([0-9]*\) Newton' "$name.log" | grep -o '[0-9]* Newton' | cut -d' ' -f1)
    err=$(awk -v q="$q2" -v nc="$nc" 'BEGIN { printf "%+.2f", 100 * (q / nc - 1) }')
    printf '| %s | %s | %s | 20 | %.3f | %.3f | %s %% | %s | %.1f |\n' "$label" "$ranks" "$n" \
      "$q1" "$q2" "$err" "$its" "$(echo "$t1 - $t0" | bc)"
  else
    last=$(tail -1 "$name.out/history.csv" 2>/dev/null | cut -d, -f1,3)
    printf '| %s | %s | %s | | failed: %s; last row (step, q/c) %s | | | | |\n' "$label" "$ranks" "$n" \
      "$(grep -m1 -o 'step [0-9]*: Newton did not converge ([A-Z_]*)' "$name.log")" "$last"
  fi
done
echo
echo "1 rank against 2 ranks, largest relative difference: $(compare_histories h_1.out/history.csv h_2.out/history.csv)"
