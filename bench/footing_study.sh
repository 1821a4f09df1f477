#!/usr/bin/env bash
# Prandtl study: the smooth strip footing on stiff Tresca clay (E/cu = 1e4, so the plateau is
# reached at z/B = 0.005 with negligible geometry change), P2 against P2-P1, h and h/2, with run
# times. Usage: bench/footing_study.sh [RANKS]
set -euo pipefail
cd "$(dirname "$0")/.."
ranks=${1:-2}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
cargo build --release -q
bin=$PWD/target/release/pfem-mpi
work=target/bench/footing
rm -rf "$work" && mkdir -p "$work" && cd "$work"
echo "| element | h (m) | particles | q/cu at z/B=0.005 | error vs 2+π | wall time (s) |"
echo "|---|---|---|---|---|---|"
for element in p2 p2p1; do
  for h in 0.5 0.25 0.125; do
    name="${element}_$h"
    "$bin" new footing-shallow -o "$name.h5" --set mesh.h=$h --set material.young=1e7 \
      --set 'prescribed[0].total=[0.0,-0.01]' --set steps.count=20 --set solver.element=$element \
      --set solver.newton_max_it=60 >/dev/null
    t0=$(date +%s.%N)
    if mpirun -n "$ranks" "$bin" "$name.h5" >"$name.log" 2>&1; then
      t1=$(date +%s.%N)
      q=$(tail -1 "$name.out/history.csv" | cut -d, -f3)
      n=$("$bin" info "$name.h5" | awk '/^particles/ {print $2}')
      err=$(awk -v q="$q" 'BEGIN { printf "%+.2f", 100 * (q / (2 + atan2(0, -1)) - 1) }')
      printf '| %s | %s | %s | %.4f | %s %% | %.1f |\n' "$element" "$h" "$n" "$q" "$err" "$(echo "$t1 - $t0" | bc)"
    else
      printf '| %s | %s | | failed: %s | | |\n' "$element" "$h" "$(grep -m1 -o 'step [0-9]*: Newton did not converge ([A-Z_]*)' "$name.log")"
    fi
  done
done
