#!/usr/bin/env bash
# How a strain-softening result depends on the particle spacing, and what the regularisation
# ξ95_eff = ξ95 · h_ref / h (material.xi95_reference_spacing) does to it: the rough biaxial block
# of bench/scenes/softening-biaxial.toml at h = 0.1, 0.05 and 0.025, plain and regularised with
# h_ref = 0.1, on RANKS ranks (default 2). Prints the platen stress q/su_ref (nominal: force over
# the initial width) at platen displacements w = 0.025 ... 0.2 m and the peak, as a Markdown table.
# Usage: bench/softening_spacing.sh [RANKS]
set -euo pipefail
cd "$(dirname "$0")/.."
scene=$PWD/bench/scenes/softening-biaxial.toml
ranks=${1:-2}
source bench/setup.sh softening-spacing

echo "| xi95 | h | particles | peak q/su | w of peak (m) | q/su at w = 0.05 | 0.1 | 0.15 | 0.2 | Newton its | wall (s) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for reg in plain regularised; do
  for h in 0.1 0.05 0.025; do
    name="${reg}_$h"
    sets=(--set "mesh.h=$h")
    [[ $reg == regularised ]] && sets+=(--set material.xi95_reference_spacing=0.1)
    "$bin" new "$scene" -o "$name.h5" "${sets[@]}" >/dev/null
    t0=$(date +%s.%N)
    mpirun -n "$ranks" "$bin" "$name.h5" --out "$name.out" >"$name.log" 2>&1 || echo "($name failed: $(tail -1 "$name.log"))" >&2
    t1=$(date +%s.%N)
    n=$(grep '^step' "$name.log" | tail -1 | grep -o 'particles [0-9]*' | cut -d' ' -f2 || true)
    its=$(grep -o '[0-9]* Newton iterations' "$name.log" | cut -d' ' -f1 || true)
    awk -F, -v reg="$reg" -v h="$h" -v n="$n" -v its="${its:--}" -v t="$(echo "$t1 - $t0" | bc)" '
      NR > 1 {
        if ($3 > peak) { peak = $3; at = $2 }
        for (k = 1; k <= 4; k++) if ($2 > 0.05 * k - 1e-9 && $2 < 0.05 * k + 1e-9) q[k] = $3
      }
      END {
        printf "| %s | %s | %s | %.4f | %.3f | %.4f | %.4f | %.4f | %.4f | %s | %.0f |\n", reg, h, n, peak, at, q[1], q[2], q[3], q[4], its, t
      }' "$name.out/history.csv"
  done
done
