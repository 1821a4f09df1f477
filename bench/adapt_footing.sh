#!/usr/bin/env bash
# The footing's run time against error with `[mesh.adapt]` (issue 10, item 5, last sentence):
# one run of the default `footing` push (2 m, z/B = 1) with the spacing factor FACTOR applied to
# `mesh.h` and the `mesh.fine` regions (bench/error_vs_time.py `mesh`), STEPS steps, RANKS ranks,
# the direct solver, and the `[mesh.adapt]` table ADAPT (empty: no adaptation), measured as
# bench/error_vs_time.sh measures (`nice -n 19`, `/usr/bin/time` around each rank, CPU s summed
# over the ranks; error against the h/2 curve at z/B = 0.25-1, and the worst step from z/B = 0.25
# on). Appends a row to bench/results/footing-adapt.csv and the invocation to
# bench/results/footing-adapt.commands.
#
# EXTRA: further `--set` overrides, separated by ';' (applied last), e.g. EXTRA='mesh.fine=[]'.
#
# Usage: FACTOR=2 STEPS=100 RANKS=1 ADAPT='{h_min=0.125,h_max=1.0}' bench/adapt_footing.sh
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
helper=$root/bench/error_vs_time.py
factor=${FACTOR:-1}
steps=${STEPS:-100}
ranks=${RANKS:-1}
adapt=${ADAPT:-}
extra=${EXTRA:-}
timeout=${TIMEOUT:-3000}
csv=$root/bench/results/footing-adapt.csv
echo "FACTOR=$factor STEPS=$steps RANKS=$ranks ADAPT='$adapt'${extra:+ EXTRA='$extra'} TIMEOUT=$timeout bench/adapt_footing.sh" \
  >>"$root/bench/results/footing-adapt.commands"
source bench/setup.sh "adapt_footing_f${factor}_n${steps}_r${ranks}${adapt:+_adapt}${extra:+_extra}"
mapfile -t mesh < <(python3 "$helper" mesh footing "$factor")
mapfile -t push < <(python3 "$helper" push footing "$steps")
sets=(--set 'solver.linear="direct"')
for s in "${mesh[@]}" "${push[@]}"; do sets+=(--set "$s"); done
[[ -z $adapt ]] || sets+=(--set "mesh.adapt=$adapt")
IFS=';' read -ra more <<<"$extra"
for s in "${more[@]}"; do sets+=(--set "$s"); done
"$bin" new footing -o case.h5 "${sets[@]}" >new.log
particles=$("$bin" info case.h5 | awk '/^particles/ {print $2}')
code=0
nice -n 19 timeout -k 30 "$timeout" mpirun -n "$ranks" sh -c \
  'exec /usr/bin/time -f "%U %S %M" -o "run.time.$OMPI_COMM_WORLD_RANK" "$@"' run \
  "$bin" case.h5 --out run.out >run.log 2>&1 || code=$?
cpu=$(cat run.time.* | awk '$1 ~ /^[0-9.]+$/ { c += $1 + $2 } END { printf "%.2f", c }')
done_line=$(grep -m1 '^done:' run.log || true)
newton=$(grep -o '[0-9]* Newton iterations' <<<"$done_line" | cut -d' ' -f1 || true)
last_particles=$(grep '^step' run.log | tail -1 | grep -o 'particles [0-9]*' | cut -d' ' -f2 || true)
cuts=$(grep -c 'cut [0-9]*x' run.log || true)
last=$(tail -1 run.out/history.csv 2>/dev/null | cut -d, -f1 || true)
if ((code == 0)) && [[ $last == "$steps" ]]; then
  result=$(python3 "$helper" measure footing run.out/history.csv)
else
  result="failed (exit $code, last step ${last:-none}): $(grep -m1 -i -E 'error|did not' run.log | cut -c1-160)"
fi
[[ -f $csv ]] || echo "factor,steps,ranks,adapt,particles_start,particles_end,cpu_s,newton_its,steps_cut,result" >"$csv"
echo "$factor,$steps,$ranks,\"$adapt${extra:+ $extra}\",$particles,$last_particles,$cpu,$newton,$cuts,\"$result\"" | tee -a "$csv"
