# Sourced by every bench script: `source bench/setup.sh NAME` from the repository root builds the
# release binary, sets the MPI environment (root, oversubscription) and enters a fresh
# target/bench/NAME; `$bin` is the binary.
#
# Overrides: BIN=/path/to/pfem-mpi uses that binary and skips `cargo build` (a prebuilt binary of
# the same code, e.g. while someone else builds on the machine); BENCH_WORK=DIR puts the work
# folder at DIR/NAME instead of target/bench/NAME.
set -euo pipefail
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# Concurrent jobs (tests, studies) would all pin their rank 0 to core 0: let the kernel place ranks.
# Unbound, a rank sees every core: one OpenMP thread per rank (SuperLU_dist, MUMPS), or the
# ranks oversubscribe the cores and SuperLU_dist's sums lose their fixed order.
export OMPI_MCA_hwloc_base_binding_policy=none OMP_NUM_THREADS=1
if [[ -n ${BIN:-} ]]; then
  bin=$(realpath "$BIN")
  [[ -x $bin ]] || { echo "BIN=$BIN is not an executable" >&2; exit 2; }
else
  cargo build --release -q
  bin=$PWD/target/release/pfem-mpi
fi
work=${BENCH_WORK:-target/bench}/$1
rm -rf "$work" && mkdir -p "$work" && cd "$work"
# The largest relative difference between two history.csv files (same columns), or "rows differ".
compare_histories() {
  python3 - "$1" "$2" <<'PY'
import csv, sys
a = list(csv.reader(open(sys.argv[1])))[1:]
b = list(csv.reader(open(sys.argv[2])))[1:]
worst = 0.0
for ra, rb in zip(a, b):
    for x, y in zip(ra, rb):
        x, y = float(x), float(y)
        s = max(abs(x), abs(y))
        if s > 0:
            worst = max(worst, abs(x - y) / s)
print(f"{worst:.1e}" if len(a) == len(b) else "rows differ")
PY
}
