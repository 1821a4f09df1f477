#!/usr/bin/env bash
# Weak scaling: a fixed number of particles per rank on 1, 2 and 4 (oversubscribed here) ranks,
# with the direct (MUMPS LU) and the iterative (GMRES + GAMG, rigid-body near-null space) path.
# The scene is an elastic block clamped at its base and loaded by a body force with a sideways
# part (so it shears and bends: a few Newton iterations), built from one 1 m x 1 m tile per rank:
# 1 x 1 tiles on 1 rank, 2 x 1 on 2, 2 x 2 on 4, so every METIS part is about a square tile,
# as the interior parts of a large 2D run are. Spacing h gives (1/h + 1)^2 particles per tile.
# One step (the whole load); records per rank, from the run's per-rank table: owned and ghost
# particles, owned and ghost dofs, CPU seconds of the solve phase, peak RSS (VmHWM); and from the
# end-of-run line: Newton and Krylov iterations. CPU of every whole process from /usr/bin/time.
# Usage: bench/weak_scaling.sh ["0.01 0.005"] ["1 2 4"] ["direct iterative"]
# Runs under `nice -n 10`, one mpirun at a time. Logs: target/bench/weak_scaling/*.log.
set -euo pipefail
cd "$(dirname "$0")/.."
spacings=${1:-0.01 0.005}
ranks_list=${2:-1 2 4}
paths=${3:-direct iterative}
source bench/setup.sh weak_scaling

# Tiles (columns x rows) for a rank count: as square as the count allows.
tiles() {
  case $1 in
    1) echo "1 1" ;; 2) echo "2 1" ;; 4) echo "2 2" ;; 8) echo "4 2" ;; 16) echo "4 4" ;;
    *) echo "$1 1" ;;
  esac
}

scene() { # w h spacing path
  cat <<EOF
name = "weak-block"
[body]
rectangles = [{ origin = [0.0, 0.0], size = [$1, $2] }]
[mesh]
h = $3
alpha = 1.3
refine = false
[material]
model = "linear-elastic"
young = 12.0e6
poisson = 0.2
density = 2000.0
[gravity]
g = [30.0, -60.0]
[[fixed]]
where = "y <= 0"
dofs = ["x", "y"]
[[point_load]]
at = [$1, $2]
force = [0.0, 0.0]
[steps]
count = 1
[history]
kind = "cantilever"
[solver]
linear = "$4"
EOF
}

echo "| h | ranks | path | particles | owned per rank (min–max) | ghost per rank (max) | ghost / owned (max) | ghost dofs / owned dofs (max) | Newton | Krylov per Newton | solve CPU s per Newton (max rank) | CPU s all ranks (/usr/bin/time) | peak RSS per rank MB (max) | peak RSS summed, kB per particle |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for h in $spacings; do
  for ranks in $ranks_list; do
    read -r nx ny < <(tiles "$ranks")
    for path in $paths; do
      name="w_${h}_${ranks}_$path"
      scene "$nx.0" "$ny.0" "$h" "$path" >"$name.toml"
      "$bin" new "$name.toml" -o "$name.h5" >/dev/null
      if nice -n 10 mpirun -n "$ranks" /usr/bin/time -f "rss_kb %M cpu_s %U %S" "$bin" "$name.h5" \
        --out "$name.out" >"$name.log" 2>&1 </dev/null; then
        newton=$(grep -o '[0-9]* Newton iterations' "$name.log" | cut -d' ' -f1)
        linear=$(grep -o '[0-9]* linear iterations' "$name.log" | cut -d' ' -f1)
        cpu=$(grep -o 'cpu_s [0-9.]* [0-9.]*' "$name.log" | awk '{s += $2 + $3} END {printf "%.1f", s}')
        # The per-rank table: the lines after its header, up to the end of the log.
        awk -v newton="$newton" -v linear="$linear" -v h="$h" -v r="$ranks" -v p="$path" -v cpu="$cpu" '
          $1 == "rank" && $2 == "owned" { on = 1; next }
          on && $1 ~ /^[0-9]+$/ {
            n++; tot += $2
            if (n == 1 || $2 < omin) omin = $2
            if ($2 > omax) omax = $2
            if ($3 > gmax) gmax = $3
            if ($3 / $2 > ratio) ratio = $3 / $2
            if ($5 / $4 > dratio) dratio = $5 / $4
            if ($8 > smax) smax = $8
            if ($10 > rmax) rmax = $10
            rsum += $10
          }
          END {
            printf "| %s | %d | %s | %d | %d–%d | %d | %.4f | %.4f | %d | %.1f | %.2f | %s | %.0f | %.1f |\n",
              h, r, p, tot, omin, omax, gmax, ratio, dratio, newton, linear / newton,
              smax / newton, cpu, rmax, rsum * 1024 / tot
          }' "$name.log"
      else
        printf '| %s | %s | %s | failed: %s | | | | | | | | | | |\n' "$h" "$ranks" "$path" \
          "$(grep -m1 'error' "$name.log" | cut -c1-120)"
      fi
    done
  done
done
