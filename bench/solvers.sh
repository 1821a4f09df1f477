#!/usr/bin/env bash
# Linear-solver choices for the default cantilever (729 particles, 50 steps) on 1 and 2 ranks:
# wall time, Newton iterations, tip deflection. Usage: bench/solvers.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/setup.sh solvers
"$bin" new cantilever -o c.h5 >/dev/null
echo "| PETSc options | ranks | wall time (s) | Newton iterations | v/L at λ=10 |"
echo "|---|---|---|---|---|"
while IFS='|' read -r label opts; do
  for ranks in 1 2; do
    out="o_${ranks}_$(echo "$label" | tr -c 'A-Za-z0-9' _)"
    t0=$(date +%s.%N)
    # shellcheck disable=SC2086
    if mpirun -n "$ranks" "$bin" c.h5 --out "$out" -- $opts >"$out.log" 2>&1 </dev/null; then
      t1=$(date +%s.%N)
      its=$(grep -o 'done: .*' "$out.log" | grep -o '[0-9]* Newton' | cut -d' ' -f1)
      v=$(tail -1 "$out/history.csv" | cut -d, -f4)
      printf '| %s | %s | %.1f | %s | %.6f |\n' "$label" "$ranks" "$(echo "$t1 - $t0" | bc)" "$its" "$v"
    else
      printf '| %s | %s | failed: %s | | |\n' "$label" "$ranks" "$(grep -m1 -o 'Newton did not converge ([A-Z_]*)' "$out.log")"
    fi
  done
done <<'LIST'
MUMPS LU (default)|
SuperLU_dist LU|-pc_factor_mat_solver_type superlu_dist
GMRES + BoomerAMG|-ksp_type gmres -pc_type hypre -ksp_rtol 1e-10 -ksp_max_it 2000
GMRES + GAMG|-ksp_type gmres -pc_type gamg -ksp_rtol 1e-10 -ksp_max_it 2000
LIST
