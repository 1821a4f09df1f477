#!/usr/bin/env bash
# The field split at yield: a plastic P2–P1 scene solved by the direct path, the field split with
# the yield zone (GAMG on the displacement block, an exact solve on its yielded rows; the
# default) and the field split with GAMG alone (`-pfem_yield_zone false`), at several spacings:
# wall time, Newton and linear iterations, linear iterations per Newton iteration, peak memory
# per rank and the iterative history's largest relative difference from the direct one.
# Usage: [UNTIL=K] [RANKS=N] [PATHS="direct zone gamg"] bench/yield_zone.sh SCENE "h1 h2 ..." [--set key=value ...]
# e.g. bench/yield_zone.sh block-compression "0.1 0.05 0.025"
#      UNTIL=10 bench/yield_zone.sh footing-shallow "0.25 0.125 0.0625" --set 'mesh.fine=[]'
set -euo pipefail
cd "$(dirname "$0")/.."
scene=$1
spacings=$2
shift 2
sets=("$@")
ranks=${RANKS:-1}
paths=${PATHS:-direct zone gamg}
until=${UNTIL:-}
source bench/setup.sh "yield_zone_$scene"
echo "| h | particles | ranks | path | wall (s) | Newton | linear | linear per Newton | max RSS per rank (MB) | rel. diff. to direct |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for h in $spacings; do
  for path in $paths; do
    linear=iterative
    options=()
    case $path in
      direct) linear=direct ;;
      gamg) options=(-pfem_yield_zone false) ;;
    esac
    "$bin" new "$scene" -o "c_${h}_$path.h5" --set mesh.h="$h" --set "solver.linear=\"$linear\"" \
      "${sets[@]}" >/dev/null
    out="o_${h}_$path"
    stop=()
    [ -n "$until" ] && stop=(--until-step "$until")
    t0=$(date +%s.%N)
    if mpirun -n "$ranks" /usr/bin/time -f "rss_kb %M" "$bin" "c_${h}_$path.h5" --out "$out" \
      "${stop[@]}" -- "${options[@]}" >"$out.log" 2>&1 </dev/null; then
      wall=$(echo "$(date +%s.%N) - $t0" | bc)
      newton=$(grep -o '[0-9]* Newton iterations' "$out.log" | cut -d' ' -f1)
      linear=$(grep -o '[0-9]* linear iterations' "$out.log" | cut -d' ' -f1)
      particles=$(grep -o 'particles [0-9]*' "$out.log" | tail -1 | cut -d' ' -f2)
      rss=$(grep -o 'rss_kb [0-9]*' "$out.log" | awk '{m = $2 > m ? $2 : m} END {printf "%.0f", m / 1024}')
      diff=-
      [ "$path" != direct ] && [ -f "o_${h}_direct/history.csv" ] &&
        diff=$(compare_histories "o_${h}_direct/history.csv" "$out/history.csv")
      printf '| %s | %s | %s | %s | %.1f | %s | %s | %.1f | %s | %s |\n' "$h" "$particles" "$ranks" \
        "$path" "$wall" "$newton" "$linear" "$(echo "$linear / $newton" | bc -l)" "$rss" "$diff"
    else
      printf '| %s | | %s | %s | failed: %s | | | | | |\n' "$h" "$ranks" "$path" \
        "$(grep -m1 'error' "$out.log" | cut -c1-140)"
    fi
  done
done
