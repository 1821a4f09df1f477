//! The batch-job scripts in jobs/: run-case.sh without a scheduler on a small cantilever split
//! into jobs of two steps, its signal forwarding and PETSc options (with a stand-in launcher), and
//! the Slurm and PBS scripts' chaining against stand-in sbatch/qsub commands.

mod common;
use common::*;

use std::fs;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn jobs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("jobs")
}

/// `bash jobs/SCRIPT args` in `dir`, with the scheduler's and the scripts' variables cleared so
/// that the outcome does not depend on where the tests run (e.g. inside a Slurm job).
fn script(dir: &Path, name: &str, args: &[&str], envs: &[(&str, &str)]) -> Command {
    let mut cmd = Command::new("bash");
    cmd.arg(jobs().join(name)).args(args).current_dir(dir);
    for (key, _) in std::env::vars() {
        if key.starts_with("SLURM_") || key.starts_with("PBS_") {
            cmd.env_remove(key);
        }
    }
    for key in [
        "RANKS",
        "STEPS_PER_JOB",
        "MPIRUN",
        "MPIRUN_ARGS",
        "PETSC_OPTIONS",
        "FORWARD_SIGNAL",
        "CHAIN_INDEX",
        "MAX_CHAIN",
        "CHAIN_SBATCH_ARGS",
        "CHAIN_QSUB_ARGS",
        "RUN_CASE",
        "JOB_SCRIPT",
        "STOP_MARGIN",
        "CASE",
        "OUTDIR",
    ] {
        cmd.env_remove(key);
    }
    cmd.env("PFEM_BIN", bin())
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        .env("OMPI_MCA_hwloc_base_binding_policy", "none")
        .env("OMP_NUM_THREADS", "1");
    for (k, v) in envs {
        cmd.env(k, v);
    }
    cmd
}

fn finish(name: &str, out: Output) -> (i32, String) {
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("--- {name}: {:?}\n{stdout}{stderr}", out.status);
    let code = out
        .status
        .code()
        .unwrap_or_else(|| panic!("{name} killed by a signal\n{stdout}{stderr}"));
    (code, format!("{stdout}{stderr}"))
}

fn call(dir: &Path, name: &str, args: &[&str], envs: &[(&str, &str)]) -> (i32, String) {
    let out = script(dir, name, args, envs)
        .output()
        .unwrap_or_else(|e| panic!("bash jobs/{name}: {e}"));
    finish(name, out)
}

fn checkpoints(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir.join("c.out/checkpoints"))
        .map(|d| {
            d.filter_map(|e| e.ok()?.file_name().into_string().ok())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

fn steps(dir: &Path) -> Vec<f64> {
    let (_, rows) = history(&dir.join("c.out/history.csv"));
    rows.iter().map(|r| r[0]).collect()
}

fn executable(path: &Path, text: &str) {
    fs::write(path, text).unwrap();
    fs::set_permissions(path, fs::Permissions::from_mode(0o755)).unwrap();
}

fn wait_for(path: &Path, what: &str) {
    let start = Instant::now();
    while !path.exists() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "{what} never happened"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn wait_output(name: &str, child: Child) -> (i32, String) {
    finish(name, child.wait_with_output().expect("wait"))
}

/// A stand-in launcher: records its arguments and PETSC_OPTIONS, then runs until SIGUSR1 or
/// SIGTERM (recorded) or 30 s.
fn fake_launcher(dir: &Path) -> PathBuf {
    let path = dir.join("fake-mpirun");
    let d = dir.display();
    executable(
        &path,
        &format!(
            r#"#!/usr/bin/env bash
if [[ "${{1:-}}" == --version ]]; then echo "a stand-in launcher"; exit 0; fi
printf '%s\n' "$@" > "{d}/launcher-args"
printf '%s\n' "${{PETSC_OPTIONS-unset}}" > "{d}/launcher-petsc-env"
trap 'echo USR1 > "{d}/launcher-signal"; exit 0' USR1
trap 'echo TERM > "{d}/launcher-signal"; exit 0' TERM
touch "{d}/launcher-started"
for _ in $(seq 300); do sleep 0.1; done
exit 1
"#
        ),
    );
    path
}

#[test]
fn run_case_splits_resumes_and_completes_without_a_scheduler() {
    let dir = workdir("jobs-run-case");
    small_cantilever(&dir, 6, &[]);
    let env = [("RANKS", "2"), ("STEPS_PER_JOB", "2")];

    let (code, log) = call(&dir, "run-case.sh", &["c.h5"], &env);
    assert_eq!(code, 99, "first call: more to do\n{log}");
    assert!(log.contains("starting c.h5 at step 0 of 6"), "{log}");
    assert!(log.contains("--until-step 2"), "{log}");
    assert_eq!(checkpoints(&dir), ["step_000002.h5"]);
    assert_eq!(steps(&dir), [1.0, 2.0]);

    let (code, log) = call(&dir, "run-case.sh", &["c.h5"], &env);
    assert_eq!(code, 99, "second call: more to do\n{log}");
    assert!(
        log.contains("resuming from c.out/checkpoints/step_000002.h5 (step 2 of 6)"),
        "{log}"
    );
    assert!(log.contains("--until-step 4"), "{log}");
    assert!(checkpoints(&dir).contains(&"step_000004.h5".to_string()));

    let (code, log) = call(&dir, "run-case.sh", &["c.h5"], &env);
    assert_eq!(code, 0, "third call: complete\n{log}");
    assert!(
        log.contains("resuming from c.out/checkpoints/step_000004.h5 (step 4 of 6)"),
        "{log}"
    );
    assert!(checkpoints(&dir).contains(&"step_000006.h5".to_string()));
    assert_eq!(steps(&dir), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);

    let before = fs::read(dir.join("c.out/history.csv")).unwrap();
    let (code, log) = call(&dir, "run-case.sh", &["c.h5"], &env);
    assert_eq!(code, 0, "fourth call: nothing to do\n{log}");
    assert!(log.contains("analysis complete: step 6 of 6"), "{log}");
    assert!(
        !log.contains("running:"),
        "the fourth call must not run\n{log}"
    );
    assert_eq!(fs::read(dir.join("c.out/history.csv")).unwrap(), before);
}

#[test]
fn run_case_skips_an_unreadable_newest_checkpoint() {
    let dir = workdir("jobs-torn-checkpoint");
    small_cantilever(&dir, 6, &[]);
    let env = [("RANKS", "2"), ("STEPS_PER_JOB", "2")];
    let (code, log) = call(&dir, "run-case.sh", &["c.h5"], &env);
    assert_eq!(code, 99, "{log}");
    // A checkpoint cut short, as by a kill while it was written.
    fs::write(dir.join("c.out/checkpoints/step_000003.h5"), b"not hdf5").unwrap();
    let (code, log) = call(&dir, "run-case.sh", &["c.h5"], &env);
    assert_eq!(code, 99, "{log}");
    assert!(log.contains("skipping unreadable checkpoint"), "{log}");
    assert!(
        log.contains("resuming from c.out/checkpoints/step_000002.h5"),
        "{log}"
    );
    assert_eq!(steps(&dir), [1.0, 2.0, 3.0, 4.0]);
}

#[test]
fn run_case_passes_petsc_options_and_forwards_a_stop_signal_as_usr1() {
    let dir = workdir("jobs-signal");
    small_cantilever(&dir, 6, &[]);
    let launcher = fake_launcher(&dir);
    let child = script(
        &dir,
        "run-case.sh",
        &["c.h5", "out", "--", "-snes_rtol", "1e-9"],
        &[
            ("RANKS", "3"),
            ("MPIRUN", launcher.to_str().unwrap()),
            ("PETSC_OPTIONS", "-ksp_type preonly -pc_type lu"),
        ],
    )
    .stdout(Stdio::piped())
    .stderr(Stdio::piped())
    .spawn()
    .expect("spawn run-case.sh");
    wait_for(&dir.join("launcher-started"), "launcher start");
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let (code, log) = wait_output("run-case.sh", child);
    assert_eq!(code, 99, "stopped before a checkpoint: more to do\n{log}");
    assert_eq!(
        fs::read_to_string(dir.join("launcher-signal")).unwrap(),
        "USR1\n",
        "SIGTERM reaches the launcher as SIGUSR1\n{log}"
    );
    let args = fs::read_to_string(dir.join("launcher-args")).unwrap();
    let args: Vec<&str> = args.lines().collect();
    assert_eq!(
        args,
        [
            "-n",
            "3",
            bin(),
            "c.h5",
            "--out",
            "out",
            "--",
            "-ksp_type",
            "preonly",
            "-pc_type",
            "lu",
            "-snes_rtol",
            "1e-9"
        ]
    );
    assert_eq!(
        fs::read_to_string(dir.join("launcher-petsc-env")).unwrap(),
        "unset\n",
        "PETSC_OPTIONS goes on the command line only, not twice"
    );
}

/// The whole contract: SIGTERM to run-case.sh reaches the solver (as SIGUSR1 through mpirun), the
/// solver checkpoints after its current step and exits 0, run-case.sh says "more to do", and the
/// next call resumes from that checkpoint.
#[test]
fn run_case_stopped_by_sigterm_checkpoints_and_resumes() {
    let dir = workdir("jobs-sigterm");
    small_cantilever(&dir, 2000, &[]);
    let child = script(&dir, "run-case.sh", &["c.h5"], &[("RANKS", "2")])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn run-case.sh");
    let start = Instant::now();
    while fs::read_to_string(dir.join("c.out/history.csv"))
        .map(|t| t.lines().count() < 3)
        .unwrap_or(true)
    {
        assert!(start.elapsed() < Duration::from_secs(120), "no steps run");
        std::thread::sleep(Duration::from_millis(50));
    }
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let stopped = Instant::now();
    let (code, log) = wait_output("run-case.sh", child);
    assert!(
        stopped.elapsed() < Duration::from_secs(60),
        "must stop soon"
    );
    assert_eq!(code, 99, "stopped with a checkpoint: more to do\n{log}");
    let newest = checkpoints(&dir).pop().expect("a checkpoint");
    let step: usize = newest
        .trim_start_matches("step_")
        .trim_end_matches(".h5")
        .parse()
        .expect("step number");
    assert!((2..2000).contains(&step), "{newest}");
    assert_eq!(steps(&dir).len(), step, "history up to the checkpoint");

    let (code, log) = call(
        &dir,
        "run-case.sh",
        &["c.h5"],
        &[("RANKS", "2"), ("STEPS_PER_JOB", "2")],
    );
    assert_eq!(code, 99, "{log}");
    assert!(
        log.contains(&format!("resuming from c.out/checkpoints/{newest}")),
        "{log}"
    );
    let want: Vec<f64> = (1..=step + 2).map(|s| s as f64).collect();
    assert_eq!(steps(&dir), want);
}

#[test]
fn run_case_reports_a_failed_launch() {
    let dir = workdir("jobs-failure");
    small_cantilever(&dir, 6, &[]);
    let (code, log) = call(&dir, "run-case.sh", &["c.h5"], &[("MPIRUN", "false")]);
    assert!(
        code != 0 && code != 99,
        "failure is neither 0 nor 99\n{log}"
    );
    let (code, log) = call(&dir, "run-case.sh", &["missing.h5"], &[]);
    assert_eq!(code, 2, "{log}");
}

/// Stand-ins for sbatch, scontrol and squeue (Slurm) or qsub and qstat (PBS): submissions are
/// appended to `submitted`, one line per call.
fn fake_scheduler(dir: &Path) -> String {
    let bin_dir = dir.join("fake-bin");
    fs::create_dir_all(&bin_dir).unwrap();
    let d = dir.display();
    let submit =
        format!("#!/usr/bin/env bash\nprintf '%s|' \"$@\" >> \"{d}/submitted\"\necho >> \"{d}/submitted\"\necho 2002\n");
    executable(&bin_dir.join("sbatch"), &submit);
    executable(&bin_dir.join("qsub"), &submit);
    executable(
        &bin_dir.join("scontrol"),
        &format!(
            "#!/usr/bin/env bash\necho '   Command={}/slurm.sbatch'\n",
            jobs().display()
        ),
    );
    executable(
        &bin_dir.join("squeue"),
        "#!/usr/bin/env bash\necho 4:00:00\n",
    );
    executable(
        &bin_dir.join("qstat"),
        "#!/usr/bin/env bash\nprintf 'Job Id: 77.server\\n    Job_Name = pfem\\n    Resource_List.select = 1:ncpus=2:mp\\n\\tiprocs=2\\n    Resource_List.walltime = 00:00:04\\n'\n",
    );
    format!("{}:{}", bin_dir.display(), std::env::var("PATH").unwrap())
}

fn submitted(dir: &Path) -> Vec<String> {
    fs::read_to_string(dir.join("submitted"))
        .unwrap_or_default()
        .lines()
        .map(String::from)
        .collect()
}

#[test]
fn slurm_script_chains_until_done_and_stops_at_max_chain_or_failure() {
    let dir = workdir("jobs-slurm");
    small_cantilever(&dir, 6, &[]);
    let path = fake_scheduler(&dir);
    let slurm = |extra: &[(&str, &str)]| {
        let mut env = vec![
            ("PATH", path.as_str()),
            ("SLURM_JOB_ID", "1001"),
            ("SLURM_JOB_NAME", "pfem"),
            ("SLURM_NTASKS", "2"),
            ("SLURM_JOB_PARTITION", "batch"),
        ];
        env.extend_from_slice(extra);
        call(&dir, "slurm.sbatch", &["c.h5"], &env)
    };

    let (code, log) = slurm(&[("STEPS_PER_JOB", "2")]);
    assert_eq!(code, 0, "{log}");
    let expected = format!(
        "--parsable|--dependency=afterany:1001|--job-name=pfem|--export=ALL,CHAIN_INDEX=2|\
         --ntasks=2|--time=4:00:00|--partition=batch|{}/slurm.sbatch|c.h5|",
        jobs().display()
    );
    assert_eq!(submitted(&dir), [expected]);

    // The follow-up, the last one MAX_CHAIN allows: more to do, but no further submission.
    let (code, log) = slurm(&[
        ("STEPS_PER_JOB", "2"),
        ("CHAIN_INDEX", "2"),
        ("MAX_CHAIN", "2"),
    ]);
    assert_eq!(code, 0, "{log}");
    assert!(log.contains("not chaining further"), "{log}");
    assert_eq!(submitted(&dir).len(), 1);

    // A failure stops the chain.
    let (code, log) = slurm(&[("MPIRUN", "false")]);
    assert!(code != 0, "{log}");
    assert_eq!(submitted(&dir).len(), 1);

    // The rest of the analysis: complete, nothing submitted.
    let (code, log) = slurm(&[]);
    assert_eq!(code, 0, "{log}");
    assert!(log.contains("analysis complete"), "{log}");
    assert_eq!(submitted(&dir).len(), 1);
    assert_eq!(steps(&dir), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
}

#[test]
fn pbs_script_stops_the_solver_before_the_walltime_and_chains() {
    let dir = workdir("jobs-pbs");
    small_cantilever(&dir, 6, &[]);
    let path = fake_scheduler(&dir);
    let launcher = fake_launcher(&dir);
    let job_script = jobs().join("pbs.pbs");
    let (code, log) = call(
        &dir,
        "pbs.pbs",
        &[],
        &[
            ("PATH", path.as_str()),
            ("PBS_JOBID", "77.server"),
            ("PBS_JOBNAME", "pfem"),
            ("PBS_O_WORKDIR", dir.to_str().unwrap()),
            ("PBS_O_QUEUE", "workq"),
            ("CASE", "c.h5"),
            ("RANKS", "2"),
            ("STOP_MARGIN", "2"),
            ("MPIRUN", launcher.to_str().unwrap()),
            ("JOB_SCRIPT", job_script.to_str().unwrap()),
        ],
    );
    assert_eq!(code, 0, "{log}");
    assert!(
        log.contains("will ask the solver to checkpoint and stop after 2 s"),
        "{log}"
    );
    assert_eq!(
        fs::read_to_string(dir.join("launcher-signal")).unwrap(),
        "USR1\n",
        "{log}"
    );
    let expected = format!(
        "-V|-W|depend=afterany:77.server|-v|CHAIN_INDEX=2|-N|pfem|-q|workq|\
         -l|select=1:ncpus=2:mpiprocs=2|-l|walltime=00:00:04|{}|",
        job_script.display()
    );
    assert_eq!(submitted(&dir), [expected]);
}

#[test]
fn batch_scripts_parse_and_pass_shellcheck() {
    for name in ["run-case.sh", "slurm.sbatch", "pbs.pbs"] {
        let out = Command::new("bash")
            .arg("-n")
            .arg(jobs().join(name))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "bash -n {name}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    match Command::new("shellcheck")
        .args(["run-case.sh", "slurm.sbatch", "pbs.pbs"])
        .current_dir(jobs())
        .output()
    {
        Ok(out) => assert!(
            out.status.success(),
            "shellcheck\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ),
        Err(e) => {
            prerequisite(&format!("shellcheck ({e})"), false);
        }
    }
}
