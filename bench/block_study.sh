#!/usr/bin/env bash
# Block compression (`block-compression`, 100 steps to 50 % strain): the default h = 0.1 lattice,
# the same cloud jittered by 0.3 h, and the h = 0.05 lattice, on 1, 2 and 3 ranks. For each: the
# strain reached, how far from 2·cu the stress got once yielded, where it first left 2·cu by 1e-6
# (the onset of shear bands), the volume, the Newton iterations and the wall time. Prints a
# Markdown table.
# Usage: bench/block_study.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/setup.sh block

echo "| cloud | ranks | reached strain | worst stress/cu − 2 | at strain | first off by 1e-6 at strain | worst volume − 1 | final particles | Newton its | wall time (s) |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for cloud in "h=0.1 lattice|mesh.h=0.1" "h=0.1 jittered 0.3|body.jitter=0.3" "h=0.05 lattice|mesh.h=0.05"; do
  label=${cloud%|*}
  name=$(echo "$label" | tr -c 'a-z0-9.\n' '_')
  "$bin" new block-compression -o "$name.h5" --set "${cloud#*|}" >/dev/null
  for ranks in 1 2 3; do
    run="${name}_r$ranks"
    t0=$(date +%s.%N)
    status=ok
    mpirun -n "$ranks" "$bin" "$name.h5" --out "$run.out" >"$run.log" 2>&1 || status=failed
    t1=$(date +%s.%N)
    reached=$(tail -1 "$run.out/history.csv" 2>/dev/null | cut -d, -f2 || true)
    if [[ $status == failed ]]; then
      reached="$reached (then $(grep -m1 -o -e 'Newton did not converge ([A-Z_]*)' -e 'Newton stalled' "$run.log" || true))"
    fi
    its=$(grep -o '[0-9]* Newton iterations' "$run.log" | cut -d' ' -f1 || true)
    n=$(grep '^step' "$run.log" | tail -1 | grep -o 'particles [0-9]*' | cut -d' ' -f2 || true)
    # From step 2 on the block is yielded (step 1 ends at 0.5 % strain, partly elastic).
    awk -F, -v c="$label" -v r="$ranks" -v reached="$reached" -v n="$n" -v its="${its:--}" \
      -v t="$(echo "$t1 - $t0" | bc)" '
      NR > 2 {
        d = $3 - 2; a = d < 0 ? -d : d
        if (a > worst) { worst = a; signed = d; at = $2 }
        if (a > 1e-6 && onset == "") onset = $2
        v = $4 - 1; if ((v < 0 ? -v : v) > (vw < 0 ? -vw : vw)) vw = v
      }
      END {
        printf "| %s | %d | %s | %+.2e | %s | %s | %+.2e | %s | %s | %.1f |\n", c, r, reached, signed,
          at, (onset == "" ? "never" : onset), vw, n, its, t
      }' "$run.out/history.csv" 2>/dev/null || echo "| $label | $ranks | failed before step 1 | | | | | | | |"
  done
done
