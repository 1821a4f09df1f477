#!/usr/bin/env bash
# Any site (issue 27): the vertical cut's stability number at collapse against the spacing and
# the collapse rule, on 1 and 2 ranks, with the wall time of each run.
#   bench/site_study.sh            # h = H/10, H/20 (and H/40 with FINE=1)
source "$(dirname "$0")/setup.sh" site_study
hs=(0.5 0.25)
[[ ${FINE:-0} == 1 ]] && hs+=(0.125)
printf '%-6s %-6s %-10s %-8s %-8s %s\n' h ranks compliance Ns error wall_s
for h in "${hs[@]}"; do
  for c in 20 50 200; do
    for n in 1 2; do
      "$bin" new vertical-cut -o c.h5 --set mesh.h=$h --set steps.collapse_compliance=$c >/dev/null
      rm -rf c.out
      start=$(date +%s.%N)
      mpirun -n $n "$bin" c.h5 >/dev/null
      wall=$(echo "$(date +%s.%N) - $start" | bc)
      ns=$(tail -1 c.out/history.csv | cut -d, -f3)
      err=$(python3 -c "print(f'{($ns)/3.78-1:+.3%}')")
      printf '%-6s %-6s %-10s %-8.4f %-8s %.1f\n' $h $n $c $ns $err $wall
    done
  done
done
