#!/usr/bin/env bash
# Run time against error with `[mesh.adapt]` (issue 10, item 5, last sentence) for SCENE
# (`footing`, `tbar-smooth`, `tbar-rough` or `pipeline`): one run of the scene's short push
# (bench/error_vs_time.py `push`: the footing's 2 m, z/B = 1; the T-bar's 0.25D; the pipeline's
# vertical stage alone, w = 0.5D) with the spacing factor FACTOR applied to
# `mesh.h` and the `mesh.fine` regions (bench/error_vs_time.py `mesh`), STEPS steps, RANKS ranks,
# the direct solver, and the `[mesh.adapt]` table ADAPT (empty: no adaptation), measured as
# bench/error_vs_time.sh measures (`nice -n 19`, unbound `mpirun`, `/usr/bin/time` around each
# rank, CPU s summed over the ranks) and judged by bench/error_vs_time.py `measure`:
#   footing      the q/cu curve against the h/2 curve at z/B = 0.25-1, and the worst step from
#                z/B = 0.25 on
#   tbar-smooth  |mean Nc / 9.142 - 1| over the steps with w >= 0.1D (tbar-rough: 11.940)
#   pipeline     |V/(D cu) / V_ref - 1| at w = 0.5D, V_ref the reference of
#                bench/results/pipeline.csv (as in pipeline.md: 4.4301, the finest spacing's value)
# Appends a row to bench/results/SCENE-adapt.csv and the invocation to
# bench/results/SCENE-adapt.commands. A setting `pfem-mpi new` refuses gets a row with its first
# error line (exit 1). A run that fails or is cut by TIMEOUT (s of wall) gets a
# row too, with its exit code, the last step it reached, the solver's first error line and the
# figure measured so far (no error: it did not compute what was asked).
#
# EXTRA: further `--set` overrides, separated by ';' (applied last), e.g. EXTRA='mesh.fine=[]'.
# BIN / BENCH_WORK: a prebuilt binary instead of `cargo build`, and where the work folders go
# (bench/setup.sh).
#
# Usage: FACTOR=2 STEPS=100 RANKS=1 ADAPT='{h_min=0.125,h_max=1.0}' bench/adapt_study.sh footing
#        FACTOR=2 STEPS=10 ADAPT='{h_min=0.005,h_max=0.04}' BIN=/path/pfem-mpi bench/adapt_study.sh tbar-smooth
#        FACTOR=4 STEPS=50 ADAPT='{h_min=0.01,h_max=0.04}' EXTRA='mesh.fine=[]' bench/adapt_study.sh pipeline
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
scene=${1:?usage: bench/adapt_study.sh footing|tbar-smooth|tbar-rough|pipeline}
case $scene in
  footing) default_steps=100 default_timeout=3000 ;;
  tbar-smooth | tbar-rough) default_steps=10 default_timeout=900 ;;
  pipeline) default_steps=50 default_timeout=900 ;;
  *) echo "adapt_study.sh: unknown scene $scene (footing, tbar-smooth, tbar-rough or pipeline)" >&2 && exit 2 ;;
esac
helper=$root/bench/error_vs_time.py
factor=${FACTOR:-1}
steps=${STEPS:-$default_steps}
ranks=${RANKS:-1}
adapt=${ADAPT:-}
extra=${EXTRA:-}
timeout=${TIMEOUT:-$default_timeout}
csv=$root/bench/results/$scene-adapt.csv
echo "FACTOR=$factor STEPS=$steps RANKS=$ranks ADAPT='$adapt'${extra:+ EXTRA='$extra'} TIMEOUT=$timeout bench/adapt_study.sh $scene" \
  >>"$root/bench/results/$scene-adapt.commands"
# One work folder per setting (a short hash of ADAPT and EXTRA keeps different settings apart).
tag=$(printf '%s|%s' "$adapt" "$extra" | md5sum | cut -c1-6)
source bench/setup.sh "adapt_${scene}_f${factor}_n${steps}_r${ranks}${adapt:+_adapt}${extra:+_extra}_$tag"
mapfile -t mesh < <(python3 "$helper" mesh "$scene" "$factor")
mapfile -t push < <(python3 "$helper" push "$scene" "$steps")
sets=(--set 'solver.linear="direct"')
for s in "${mesh[@]}" "${push[@]}"; do sets+=(--set "$s"); done
[[ -z $adapt ]] || sets+=(--set "mesh.adapt=$adapt")
IFS=';' read -ra more <<<"$extra"
for s in "${more[@]}"; do sets+=(--set "$s"); done
[[ -f $csv ]] || echo "factor,steps,ranks,adapt,particles_start,particles_end,cpu_s,newton_its,steps_cut,result" >"$csv"
settings=$adapt${adapt:+${extra:+ }}$extra
if ! "$bin" new "$scene" -o case.h5 "${sets[@]}" >new.log 2>&1; then
  # A setting the scene refuses (e.g. a fine region off the coarser lattice) gets a row too.
  result="not built (pfem-mpi new): $(grep -m1 -i error new.log | cut -c1-300)"
  echo "$factor,$steps,$ranks,\"$settings\",,,,,,\"${result//\"/\'}\"" | tee -a "$csv"
  exit 1
fi
particles=$("$bin" info case.h5 | awk '/^particles/ {print $2}')
code=0
SECONDS=0
nice -n 19 timeout -k 30 "$timeout" mpirun --bind-to none -n "$ranks" sh -c \
  'exec /usr/bin/time -f "%U %S %M" -o "run.time.$OMPI_COMM_WORLD_RANK" "$@"' run \
  "$bin" case.h5 --out run.out >run.log 2>&1 || code=$?
wall=$SECONDS
# Empty when a rank was killed before /usr/bin/time wrote its line.
cpu=$( (cat run.time.* 2>/dev/null || true) | awk '$1 ~ /^[0-9.]+$/ { c += $1 + $2; n++ } END { if (n) printf "%.2f", c }')
done_line=$(grep -m1 '^done:' run.log || true)
newton=$(grep -o '[0-9]* Newton iterations' <<<"$done_line" | cut -d' ' -f1 || true)
last_particles=$(grep '^step' run.log | tail -1 | grep -o 'particles [0-9]*' | cut -d' ' -f2 || true)
cuts=$(grep -c 'cut [0-9]*x' run.log || true)
last=$(tail -1 run.out/history.csv 2>/dev/null | cut -d, -f1 || true)
[[ $last != step ]] || last=''  # the header alone: no step finished
if ((code == 0)) && [[ $last == "$steps" ]]; then
  result=$(python3 "$helper" measure "$scene" run.out/history.csv)
else
  if ((code == 124 || code == 137)); then
    result="timeout after $wall s (last step ${last:-none})"
  else
    result="failed (exit $code, last step ${last:-none}): $(grep -m1 -i -E 'error|did not|panick' run.log | cut -c1-300)"
  fi
  if [[ -n $last ]]; then
    result+="; so far: $(python3 "$helper" measure "$scene" run.out/history.csv 2>/dev/null |
      sed 's/ error [^(]*(/ (/' || echo 'not measured')"
  fi
fi
result=${result//\"/\'}
echo "$factor,$steps,$ranks,\"$settings\",$particles,$last_particles,$cpu,$newton,$cuts,\"$result\"" | tee -a "$csv"
