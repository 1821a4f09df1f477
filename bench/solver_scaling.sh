#!/usr/bin/env bash
# Direct (MUMPS LU) against iterative (GMRES + GAMG with the rigid-body near-null space) on the
# elastic cantilever, 5 steps, at several spacings on 1 and 2 ranks: wall time, Newton and linear
# iterations, seconds per Newton iteration, peak memory per rank (max RSS, /usr/bin/time) and
# the iterative history's largest relative difference from the direct one.
# Usage: [UNTIL=K] bench/solver_scaling.sh ["0.0625 0.03125 0.015625"] ["1 2"] [-- PETSc options]
# UNTIL stops after K of the 5 steps (a cheaper per-Newton-iteration figure at large sizes).
set -euo pipefail
cd "$(dirname "$0")/.."
spacings=${1:-0.0625 0.03125 0.015625}
ranks_list=${2:-1 2}
shift $(( $# > 2 ? 2 : $# ))
[ "${1:-}" = "--" ] && shift
extra=("$@")
until=${UNTIL:-5}
source bench/setup.sh solver_scaling
echo "| h | particles | ranks | path | wall (s) | CPU (s, all ranks) | Newton | linear | wall s per Newton it. | max RSS per rank (MB) | rel. diff. to direct |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for h in $spacings; do
  for path in direct iterative; do
    "$bin" new cantilever -o "c_${h}_$path.h5" --set mesh.h="$h" --set steps.count=5 \
      --set "solver.linear=\"$path\"" >/dev/null
  done
  for ranks in $ranks_list; do
    for path in direct iterative; do
      out="o_${h}_${ranks}_$path"
      t0=$(date +%s.%N)
      if mpirun -n "$ranks" /usr/bin/time -f "rss_kb %M cpu_s %U" "$bin" "c_${h}_$path.h5" \
        --out "$out" --until-step "$until" -- "${extra[@]}" >"$out.log" 2>&1 </dev/null; then
        t1=$(date +%s.%N)
        wall=$(echo "$t1 - $t0" | bc)
        newton=$(grep -o '[0-9]* Newton iterations' "$out.log" | cut -d' ' -f1)
        linear=$(grep -o '[0-9]* linear iterations' "$out.log" | cut -d' ' -f1)
        particles=$(grep -o 'particles [0-9]*' "$out.log" | tail -1 | cut -d' ' -f2)
        rss=$(grep -o 'rss_kb [0-9]*' "$out.log" | awk '{m = $2 > m ? $2 : m} END {printf "%.0f", m / 1024}')
        cpu=$(grep -o 'cpu_s [0-9.]*' "$out.log" | awk '{s += $2} END {printf "%.1f", s}')
        diff=-
        [ "$path" = iterative ] && diff=$(compare_histories "o_${h}_${ranks}_direct/history.csv" "$out/history.csv")
        printf '| %s | %s | %s | %s | %.1f | %s | %s | %s | %.3f | %s | %s |\n' "$h" "$particles" \
          "$ranks" "$path" "$wall" "$cpu" "$newton" "$linear" "$(echo "$wall / $newton" | bc -l)" \
          "$rss" "$diff"
      else
        printf '| %s | | %s | %s | failed: %s | | | | | | |\n' "$h" "$ranks" "$path" \
          "$(grep -m1 'error' "$out.log" | cut -c1-120)"
      fi
    done
  done
done
