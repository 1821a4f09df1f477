#!/usr/bin/env bash
# run-case.sh: run or resume one pfem-mpi analysis, with or without a batch scheduler.
#
#   jobs/run-case.sh CASE.h5 [OUTDIR] [-- PETSc options]
#
# Resumes from the newest checkpoint in OUTDIR/checkpoints/ when there is one, else starts CASE.
# OUTDIR defaults to what pfem-mpi itself uses: CASE with `.out` instead of `.h5`, or X.out when
# CASE is a checkpoint X.out/checkpoints/step_NNNNNN.h5.
#
# Environment:
#   RANKS          MPI ranks (default: SLURM_NTASKS, PBS_NP, lines of PBS_NODEFILE, else nproc)
#   STEPS_PER_JOB  stop after this many steps (pfem-mpi --until-step); unset = run to the end
#   PFEM_BIN       the solver (default: pfem-mpi on PATH, else <repo>/target/release/pfem-mpi)
#   MPIRUN         the launcher, may carry options (default: mpirun), e.g. "srun --mpi=pmix"
#   MPIRUN_ARGS    extra launcher options, e.g. "--bind-to core"
#   PETSC_OPTIONS  PETSc options, passed after `--` (and not also through the environment)
#   FORWARD_SIGNAL signal sent to the launcher when this script gets SIGTERM or SIGUSR1
#                  (default USR1: Open MPI's mpirun and Slurm's srun pass SIGUSR1 on to the
#                  ranks, while Open MPI's mpirun answers SIGTERM by killing the ranks a moment
#                  later, too soon for a checkpoint)
#
# Exit status: 0 = the analysis is complete, 99 = more steps to do (run this again),
# anything else = failure (2 = bad usage or setup, 3 = OUTDIR is in use by another run,
# otherwise the launcher's status).
set -euo pipefail

readonly EXIT_DONE=0 EXIT_MORE=99 EXIT_USAGE=2 EXIT_BUSY=3

log() { printf 'run-case: %s\n' "$*"; }
die() {
    local code="$1"
    shift
    printf 'run-case: error: %s\n' "$*" >&2
    exit "$code"
}
usage() {
    sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p;}' "${BASH_SOURCE[0]}" >&2
    exit "$EXIT_USAGE"
}

# ---- arguments ---------------------------------------------------------------------------------
case_file=""
outdir=""
extra_petsc=()
while (($# > 0)); do
    case "$1" in
    -h | --help) usage ;;
    --)
        shift
        extra_petsc=("$@")
        break
        ;;
    *)
        if [[ -z "$case_file" ]]; then
            case_file="$1"
        elif [[ -z "$outdir" ]]; then
            outdir="$1"
        else
            printf 'run-case: error: unexpected argument %q\n' "$1" >&2
            usage
        fi
        ;;
    esac
    shift
done
[[ -n "$case_file" ]] || usage
[[ -f "$case_file" ]] || die "$EXIT_USAGE" "case file not found: $case_file"

if [[ -z "$outdir" ]]; then
    case_dir="$(dirname -- "$case_file")"
    if [[ "$(basename -- "$case_dir")" == checkpoints ]]; then
        outdir="$(dirname -- "$case_dir")"
    else
        outdir="${case_file%.h5}.out"
    fi
fi

# ---- settings ----------------------------------------------------------------------------------
is_count() { [[ "$1" =~ ^[1-9][0-9]*$ ]]; }

if [[ -z "${RANKS:-}" ]]; then
    if [[ -n "${SLURM_NTASKS:-}" ]]; then
        RANKS="$SLURM_NTASKS"
    elif [[ -n "${PBS_NP:-}" ]]; then
        RANKS="$PBS_NP"
    elif [[ -n "${PBS_NODEFILE:-}" && -r "${PBS_NODEFILE:-}" ]]; then
        RANKS="$(grep -c . "$PBS_NODEFILE" || true)"
    else
        RANKS="$(nproc 2>/dev/null || getconf _NPROCESSORS_ONLN 2>/dev/null || echo 1)"
    fi
fi
is_count "$RANKS" || die "$EXIT_USAGE" "RANKS must be a positive whole number (got '$RANKS')"

STEPS_PER_JOB="${STEPS_PER_JOB:-}"
if [[ -n "$STEPS_PER_JOB" ]] && ! is_count "$STEPS_PER_JOB"; then
    die "$EXIT_USAGE" "STEPS_PER_JOB must be a positive whole number (got '$STEPS_PER_JOB')"
fi

if [[ -z "${PFEM_BIN:-}" ]]; then
    if PFEM_BIN="$(command -v pfem-mpi)"; then
        :
    else
        script_dir="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")" && pwd)"
        PFEM_BIN="$script_dir/../target/release/pfem-mpi"
    fi
fi
[[ -x "$PFEM_BIN" ]] || die "$EXIT_USAGE" "solver not found or not executable: $PFEM_BIN (set PFEM_BIN)"

read -r -a mpirun_cmd <<<"${MPIRUN:-mpirun}"
((${#mpirun_cmd[@]} > 0)) || die "$EXIT_USAGE" "MPIRUN is empty"
command -v -- "${mpirun_cmd[0]}" >/dev/null || die "$EXIT_USAGE" "launcher not found: ${mpirun_cmd[0]}"
read -r -a mpirun_args <<<"${MPIRUN_ARGS:-}"
read -r -a petsc_args <<<"${PETSC_OPTIONS:-}"
petsc_args+=("${extra_petsc[@]}")

FORWARD_SIGNAL="${FORWARD_SIGNAL:-USR1}"

# ---- signals: remember a stop request, forward it to the launcher once it runs --------------------
child=""
stop_signal=""
signals_seen=0
# shellcheck disable=SC2317  # called from the traps below
on_signal() {
    stop_signal="$1"
    signals_seen=$((signals_seen + 1))
    if [[ -n "$child" ]] && kill -0 "$child" 2>/dev/null; then
        log "got SIG$1: asking the solver to finish its step, checkpoint and stop (SIG$FORWARD_SIGNAL to launcher pid $child)"
        kill -s "$FORWARD_SIGNAL" "$child" 2>/dev/null || true
    else
        log "got SIG$1: no solver running; will not start one"
    fi
}
trap 'on_signal TERM' TERM
trap 'on_signal USR1' USR1

# ---- progress ----------------------------------------------------------------------------------
# progress FILE -> "S N" from `pfem-mpi info`; fails when the file cannot be read.
progress() {
    local text line
    text="$("$PFEM_BIN" info "$1" 2>&1)" || return 1
    while IFS= read -r line; do
        if [[ "$line" =~ ^progress[[:space:]]+step[[:space:]]+([0-9]+)[[:space:]]+of[[:space:]]+([0-9]+) ]]; then
            printf '%s %s\n' "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}"
            return 0
        fi
    done <<<"$text"
    return 1
}

# checkpoints -> checkpoint files in OUTDIR, newest (highest step) first.
checkpoints() {
    local f name n
    shopt -s nullglob
    for f in "$outdir"/checkpoints/step_*.h5; do
        name="${f##*/step_}"
        n="${name%.h5}"
        if [[ "$n" =~ ^[0-9]+$ ]]; then
            printf '%s\t%s\n' "$((10#$n))" "$f"
        fi
    done | sort -t $'\t' -k1,1nr | cut -f2-
    shopt -u nullglob
}

# resume_point -> sets start_file, step, total: the newest readable checkpoint, else the case.
resume_point() {
    local f p
    start_file=""
    while IFS= read -r f; do
        if p="$(progress "$f")"; then
            start_file="$f"
            break
        fi
        log "skipping unreadable checkpoint $f (interrupted while written?)"
    done < <(checkpoints)
    if [[ -z "$start_file" ]]; then
        p="$(progress "$case_file")" || die 1 "cannot read the progress of $case_file ('$PFEM_BIN info' failed)"
        start_file="$case_file"
    fi
    read -r step total <<<"$p"
}

# ---- one run -----------------------------------------------------------------------------------
mkdir -p -- "$outdir"

# One run per OUTDIR at a time (where flock is available and the file system supports it).
if command -v flock >/dev/null; then
    exec 9>>"$outdir/.run-case.lock"
    lock_rc=0
    flock -n -E 75 9 || lock_rc=$?
    if ((lock_rc == 75)); then
        die "$EXIT_BUSY" "another run is using $outdir (lock $outdir/.run-case.lock)"
    elif ((lock_rc != 0)); then
        log "warning: could not lock $outdir (flock status $lock_rc); make sure no other run uses it"
    fi
fi

resume_point
if [[ "$start_file" == "$case_file" ]]; then
    log "no checkpoint in $outdir/checkpoints: starting $case_file at step $step of $total"
else
    log "resuming from $start_file (step $step of $total)"
fi
if ((step >= total)); then
    log "analysis complete: step $step of $total; results in $outdir"
    exit "$EXIT_DONE"
fi
if [[ -n "$stop_signal" ]]; then
    log "stop requested (SIG$stop_signal) before the run started: more to do, step $step of $total"
    exit "$EXIT_MORE"
fi

run_args=("$start_file" --out "$outdir")
if [[ -n "$STEPS_PER_JOB" ]] && ((step + STEPS_PER_JOB < total)); then
    run_args+=(--until-step "$((step + STEPS_PER_JOB))")
fi
if ((${#petsc_args[@]} > 0)); then
    run_args+=(-- "${petsc_args[@]}")
fi

launch_env=(env -u PETSC_OPTIONS)
if "${mpirun_cmd[0]}" --version 2>&1 | grep -q 'Open MPI'; then
    if [[ "$(id -u)" == 0 && -z "${OMPI_ALLOW_RUN_AS_ROOT:-}" ]]; then
        log "running as root: setting OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1"
        launch_env+=(OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1)
    fi
    # Outside a scheduler's allocation Open MPI allows one rank per core unless told otherwise.
    if [[ -z "${SLURM_JOB_ID:-}${PBS_JOBID:-}" ]] &&
        ((RANKS > $(nproc 2>/dev/null || echo 1))) &&
        [[ " ${mpirun_args[*]} " != *" --oversubscribe "* ]]; then
        log "$RANKS ranks on $(nproc) cores: adding --oversubscribe"
        mpirun_args+=(--oversubscribe)
    fi
fi

cmd=("${mpirun_cmd[@]}" -n "$RANKS" "${mpirun_args[@]}" "$PFEM_BIN" "${run_args[@]}")
log "running: ${cmd[*]}"
"${launch_env[@]}" "${cmd[@]}" &
child=$!

# `wait` returns early (status > 128) when a trapped signal arrives; wait again until the launcher
# itself has ended (bash keeps the status of a child that ended in between).
while :; do
    seen="$signals_seen"
    rc=0
    wait "$child" || rc=$?
    if ((rc > 128 && signals_seen != seen)); then
        continue
    fi
    break
done
child=""

if ((rc != 0)); then
    if [[ -n "$stop_signal" ]]; then
        log "the solver did not stop cleanly on SIG$stop_signal"
    fi
    log "the run failed (launcher status $rc); the newest checkpoint is kept for a retry"
    ((rc == EXIT_MORE)) && rc=1
    exit "$rc"
fi

before="$step"
resume_point
if ((step >= total)); then
    log "analysis complete: step $step of $total; results in $outdir"
    exit "$EXIT_DONE"
fi
if ((step > before)); then
    log "more to do: checkpoint $start_file at step $step of $total; run again to continue"
    exit "$EXIT_MORE"
fi
if [[ -n "$stop_signal" ]]; then
    log "stopped on SIG$stop_signal before a new checkpoint: more to do, step $step of $total"
    exit "$EXIT_MORE"
fi
die 1 "the solver exited 0 but no checkpoint past step $before appeared in $outdir/checkpoints"
