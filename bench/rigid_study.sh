#!/usr/bin/env bash
# One built-in rigid-body scene (footing, tbar-smooth, tbar-rough, pipeline) run to its end on
# RANKS ranks, with optional `--set` overrides: prints particles, steps, Newton iterations, wall
# time, the history at the listed steps, and the largest deviation of the force column from its
# 11-step running mean after the first fifth of the run (the curve's smoothness; for the footing
# that is after z/B = 0.2).
# Usage: bench/rigid_study.sh SCENE RANKS "STEP STEP ..." [--set KEY=VALUE ...]
# e.g.   bench/rigid_study.sh footing 2 "20 50 100 150 200"
#        bench/rigid_study.sh tbar-smooth 2 "10 20 50 100 150" --set mesh.h=0.01
set -euo pipefail
cd "$(dirname "$0")/.."
scene=$1 ranks=$2 rows=$3
shift 3
source bench/setup.sh "rigid_${scene}_$ranks"

"$bin" new "$scene" -o case.h5 "$@" >/dev/null
t0=$(date +%s.%N)
status=0
mpirun -n "$ranks" "$bin" case.h5 --out out >run.log 2>&1 || status=$?
t1=$(date +%s.%N)
echo "scene $scene, $ranks ranks, overrides: ${*:-none}"
echo "particles at the start: $("$bin" info case.h5 | awk '/^particles/ {print $2}')"
tail -1 run.log
printf 'wall time %.1f s (exit %d)\n' "$(echo "$t1 - $t0" | bc)" "$status"
echo
head -1 out/history.csv | tr ',' '\t'
for r in $rows; do
  awk -F, -v r="$r" '$1 == r' out/history.csv | tr ',' '\t'
done
# The force column is the last declared column for the footing and T-bars, V for the pipeline.
col=$(head -1 out/history.csv | tr ',' '\n' | grep -n -m1 -E '^(q_over_cu|Nc|V_over_Dcu)$' | cut -d: -f1)
awk -F, -v c="$col" 'NR > 1 { v[NR - 1] = $c; n = NR - 1 }
  END {
    worst = 0
    for (i = (n / 5 > 6 ? int(n / 5) : 6); i <= n - 5; i++) {
      s = 0; for (k = i - 5; k <= i + 5; k++) s += v[k]; m = s / 11
      d = (v[i] - m) / m; if (d < 0) d = -d; if (d > worst) { worst = d; at = i }
    }
    printf "largest deviation from the 11-step running mean: %.2f %% (step %d)\n", 100 * worst, at
  }' out/history.csv
exit "$status"
