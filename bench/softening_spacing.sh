#!/usr/bin/env bash
# How a strain-softening result depends on the particle spacing, and what the regularisation
# ξ95_eff = ξ95 · h_ref / h (material.xi95_reference_spacing) does to it: the built-in rough T-bar
# (tbar-rough: D = 0.04 m, 9D deep, pushed 1.5D in 150 steps) in tresca-softening clay with
# δ_rem = 1/3, ξ95 = 10, μ = 0 (the rate effect off, to see the softening alone), at two
# spacings around the bar: h = 0.01 (the default's outer fine region only) and h = 0.005 (the
# default), plain and regularised with h_ref = 0.01, on RANKS ranks (default 2). Prints Nc at
# w/D = 0.25 ... 1.5 as a Markdown table.
# Usage: bench/softening_spacing.sh [RANKS]
set -euo pipefail
cd "$(dirname "$0")/.."
ranks=${1:-2}
source bench/setup.sh softening-spacing

soft=(--set material.model=tresca-softening --set material.remoulded_ratio=0.3333333333333333
  --set material.xi95=10)
coarse='mesh.fine=[{ origin = [0.0, 0.26], size = [0.16, 0.28], h = 0.01 }]'
echo "| ξ95 | h at the bar | particles | Nc at w/D = 0.25 | 0.5 | 0.75 | 1.0 | 1.25 | 1.5 | peak (w/D) | Newton its | wall (s) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for reg in plain regularised; do
  for h in 0.01 0.005; do
    name="${reg}_$h"
    sets=("${soft[@]}")
    [[ $h == 0.01 ]] && sets+=(--set "$coarse")
    [[ $reg == regularised ]] && sets+=(--set material.xi95_reference_spacing=0.01)
    "$bin" new tbar-rough -o "$name.h5" "${sets[@]}" >/dev/null
    t0=$(date +%s.%N)
    mpirun -n "$ranks" "$bin" "$name.h5" --out "$name.out" >"$name.log" 2>&1 ||
      echo "($name failed: $(grep -m1 error "$name.log"))" >&2
    t1=$(date +%s.%N)
    n=$(grep '^step' "$name.log" | tail -1 | grep -o 'particles [0-9]*' | cut -d' ' -f2 || true)
    its=$(grep -o '[0-9]* Newton iterations' "$name.log" | cut -d' ' -f1 || true)
    awk -F, -v reg="$reg" -v h="$h" -v n="$n" -v its="${its:--}" -v t="$(echo "$t1 - $t0" | bc)" '
      NR > 1 {
        if ($3 > peak) { peak = $3; at = $2 }
        for (k = 1; k <= 6; k++) if ($2 > 0.25 * k - 1e-9 && $2 < 0.25 * k + 1e-9) q[k] = $3
      }
      END {
        printf "| %s | %s | %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f (%.2f) | %s | %.0f |\n",
          reg, h, n, q[1], q[2], q[3], q[4], q[5], q[6], peak, at, its, t
      }' "$name.out/history.csv"
  done
done
