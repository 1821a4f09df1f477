//! What a run shows while it steps (`--progress`): JSON for scripts that agrees with
//! history.csv, the per-step lines when stdout is not a terminal, a bar on a terminal, and every
//! step's full line (and the final error) in `DIR/run.log` whatever stdout shows.

mod common;
use common::*;
use std::process::Command;

/// The per-step lines (`step k/N load ...`) of a text.
fn step_lines(text: &str) -> Vec<&str> {
    text.lines()
        .filter(|l| l.starts_with("step ") && l.contains(" load "))
        .collect()
}

#[test]
fn json_progress_has_one_object_a_step_with_the_history_row_on_1_and_2_ranks() {
    let dir = workdir("progress-json");
    small_cantilever(&dir, 6, &[]);
    for ranks in [1, 2] {
        let out = format!("r{ranks}");
        let stdout = ok(&dir, ranks, &["c.h5", "--out", &out, "--progress", "json"]);
        let objects = json_objects(&stdout);
        let steps = json_steps(&stdout);
        assert_eq!(steps.len(), 6, "{stdout}");
        assert_eq!(objects.len(), 7, "six steps and the end: {stdout}");
        let done = objects.last().unwrap();
        assert_eq!(done["event"], "done");
        assert_eq!(done["step"], 6);
        let newton: u64 = steps.iter().map(|s| s["newton"].as_u64().unwrap()).sum();
        assert_eq!(done["newton"].as_u64(), Some(newton), "the totals add up");
        let (header, rows) = history(&dir.join(&out).join("history.csv"));
        for (k, (s, row)) in steps.iter().zip(&rows).enumerate() {
            assert_eq!(s["step"].as_u64(), Some(k as u64 + 1));
            assert_eq!(s["steps"], 6);
            assert!(s["newton"].as_u64() > Some(0) && s["wall"].as_f64() > Some(0.0));
            assert!(s["phases"]["solve"].as_f64().is_some(), "{s}");
            // The history row by column name, bit for bit what history.csv holds.
            for (name, value) in header.iter().zip(row).skip(1) {
                assert_eq!(
                    s["history"][name].as_f64(),
                    Some(*value),
                    "{name} at step {k}"
                );
            }
        }
        assert_eq!(steps[5]["load_factor"].as_f64(), Some(1.0));
        // The log has every step's full line all the same.
        let log = std::fs::read_to_string(dir.join(&out).join("run.log")).unwrap();
        assert_eq!(step_lines(&log).len(), 6, "{log}");
        assert!(log.contains("done: step 6"), "{log}");
    }
}

#[test]
fn without_a_terminal_stdout_has_a_line_per_5_percent_and_the_log_every_step() {
    let dir = workdir("progress-lines");
    small_cantilever(&dir, 40, &[]);
    let stdout = ok(&dir, 1, &["c.h5", "--out", "quiet"]);
    let shown = step_lines(&stdout);
    assert_eq!(shown.len(), 20, "every second step of 40:\n{stdout}");
    assert!(
        shown[0].starts_with("step     2/40 load 0.0500 newton"),
        "{}",
        shown[0]
    );
    assert!(stdout.contains("done: step 40"), "{stdout}");
    let log = std::fs::read_to_string(dir.join("quiet/run.log")).unwrap();
    assert!(
        log.starts_with("pfem-mpi "),
        "the log names the run first:\n{log}"
    );
    assert_eq!(step_lines(&log).len(), 40, "{log}");
    // A run stopped short of the end shows its last step all the same.
    let stopped = ok(&dir, 1, &["c.h5", "--out", "stopped", "--until-step", "7"]);
    let shown = step_lines(&stopped);
    assert!(
        shown.last().unwrap().starts_with("step     7/40"),
        "{stopped}"
    );
    assert_eq!(shown.len(), 4, "steps 2, 4, 6 and the last, 7:\n{stopped}");
    let verbose = ok(&dir, 2, &["c.h5", "--out", "verbose", "--verbose"]);
    assert_eq!(
        step_lines(&verbose).len(),
        40,
        "--verbose: every step:\n{verbose}"
    );
    // Another run into the folder continues its log.
    ok(&dir, 1, &["c.h5", "--out", "quiet"]);
    let log = std::fs::read_to_string(dir.join("quiet/run.log")).unwrap();
    assert_eq!(step_lines(&log).len(), 80, "two runs appended");
}

#[test]
fn the_error_a_run_ends_with_is_the_last_line_of_its_log() {
    let dir = workdir("progress-error");
    small_cantilever(&dir, 4, &[]);
    // On 1 rank the error is agreed; on 2, rank 0 fails alone and aborts the job.
    for ranks in [1, 2] {
        let folder = format!("failed{ranks}");
        let out = pfem(ranks)
            .args(["c.h5", "--out", &folder])
            .env("PFEM_INJECT_FAULT", "0:solve:error:3")
            .current_dir(&dir)
            .output()
            .unwrap();
        assert!(!out.status.success());
        let stderr = String::from_utf8_lossy(&out.stderr);
        let log = std::fs::read_to_string(dir.join(&folder).join("run.log")).unwrap();
        let last = log.lines().last().unwrap();
        assert!(
            last.starts_with("pfem-mpi: error: "),
            "{ranks} ranks:\n{log}"
        );
        assert!(
            stderr.contains(last),
            "the message of stderr:\n{stderr}\n{log}"
        );
        assert_eq!(step_lines(&log).len(), 2, "steps 1 and 2 ran:\n{log}");
    }
}

/// On a terminal (a pseudo-terminal from `script`, on 1 rank and under mpirun on 2): the bar
/// with the step, load and ETA, and no per-step line; the log still has them all.
#[test]
fn on_a_terminal_a_bar_replaces_the_step_lines() {
    let dir = workdir("progress-bar");
    small_cantilever(&dir, 5, &[]);
    if !prerequisite(
        "script (util-linux), to give the run a terminal",
        tool_runs("script"),
    ) {
        return;
    }
    for ranks in [1, 2] {
        let out = format!("bar{ranks}");
        let launch = if ranks == 1 {
            format!("{} c.h5 --out {out}", bin())
        } else {
            format!(
                "mpirun -n 2 --oversubscribe --bind-to none {} c.h5 --out {out}",
                bin()
            )
        };
        let mut script = Command::new("script");
        script
            .args(["-qec", &launch, "/dev/null"])
            .current_dir(&dir)
            .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
            .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1");
        let shown = script.output().unwrap();
        let text = String::from_utf8_lossy(&shown.stdout);
        assert!(shown.status.success(), "{text}");
        assert!(
            text.contains("step 5/5"),
            "{ranks} ranks: the bar's last state:\n{text}"
        );
        assert!(
            text.contains("ETA") && text.contains("load 1.0000"),
            "{text}"
        );
        assert!(text.contains("done: step 5"), "{text}");
        assert!(
            !text.contains("step     1/5"),
            "no per-step line on the terminal:\n{text}"
        );
        let log = std::fs::read_to_string(dir.join(&out).join("run.log")).unwrap();
        assert_eq!(step_lines(&log).len(), 5, "{log}");
    }
}
