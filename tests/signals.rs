//! Issue 32, finding 4: SIGUSR1 at any moment of a run, from start-up on, ends it with exit 0
//! and a loadable checkpoint. Before the fix the handlers were installed after MPI and PETSc
//! had started, and a signal in the first 0.3 s killed a rank (exit 138, no checkpoint).

mod common;

use common::{mpirun, ok, small_cantilever, workdir};
use std::path::Path;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

/// A line of /proc/PID/status (`Name:`, `PPid:`, ...), without its key.
fn status_field(pid: u32, key: &str) -> Option<String> {
    let text = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    text.lines()
        .find_map(|l| l.strip_prefix(key).map(|v| v.trim().to_string()))
}

/// The pfem-mpi processes mpirun `parent` has started (after their exec).
fn ranks_of(parent: u32) -> Vec<u32> {
    let Ok(dir) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    dir.filter_map(|e| e.ok()?.file_name().to_str()?.parse::<u32>().ok())
        .filter(|&pid| {
            status_field(pid, "PPid:").and_then(|p| p.parse().ok()) == Some(parent)
                && status_field(pid, "Name:").as_deref() == Some("pfem-mpi")
        })
        .collect()
}

/// Whether `pid` has a handler for SIGUSR1 (bit 10 of SigCgt), and how many threads it runs.
fn catches_usr1(pid: u32) -> Option<(bool, usize)> {
    let caught = u64::from_str_radix(&status_field(pid, "SigCgt:")?, 16).ok()?;
    let threads = status_field(pid, "Threads:")?.parse().ok()?;
    Some((caught & (1 << 9) != 0, threads))
}

/// Waits until both ranks catch SIGUSR1; returns the thread count each had at that moment.
fn wait_for_handlers(child: &mut Child) -> Vec<usize> {
    let start = Instant::now();
    let mut first: std::collections::HashMap<u32, usize> = Default::default();
    while first.len() < 2 {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the ranks never caught SIGUSR1"
        );
        if child.try_wait().expect("try_wait").is_some() {
            panic!("the run ended before its ranks could be signalled");
        }
        for pid in ranks_of(child.id()) {
            if let Some((true, threads)) = catches_usr1(pid) {
                first.entry(pid).or_insert(threads);
            }
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    first.into_values().collect()
}

fn newest_checkpoint(dir: &Path) -> Option<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".h5"))
        .collect();
    v.sort();
    v.pop()
}

#[test]
fn sigusr1_from_start_up_to_the_end_checkpoints_and_exits_zero() {
    let dir = workdir("signal-moments");
    small_cantilever(&dir, 16, &[]);
    // Seconds after both ranks can catch the signal: at once (MPI is still starting), then
    // while the case loads, during the first steps, and at or after the end of the run.
    // One thread when a rank is first seen catching SIGUSR1: its handlers were there before MPI
    // started its own threads. The poll can come late on a busy machine (CI saw [1, 3] once),
    // so the signal at once is sent up to five times, and one start seen in time proves the order;
    // handlers installed after MPI would never show one thread.
    let mut seen_before_mpi = false;
    let delays = [0.0_f64, 0.0, 0.0, 0.0, 0.0, 0.1, 0.3, 0.8, 2.0, 8.0];
    for (k, delay) in delays.into_iter().enumerate() {
        if k > 0 && k < 5 && seen_before_mpi {
            continue;
        }
        let out = format!("o{k}");
        let mut child = mpirun(2)
            .args(["c.h5", "--out", &out])
            .current_dir(&dir)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn mpirun");
        let threads = wait_for_handlers(&mut child);
        if threads.contains(&1) {
            seen_before_mpi = true;
        }
        std::thread::sleep(Duration::from_secs_f64(delay));
        let _ = std::process::Command::new("kill")
            .args(["-USR1", &child.id().to_string()])
            .status();
        let output = child.wait_with_output().expect("wait");
        assert!(
            output.status.success(),
            "SIGUSR1 {delay} s after start-up: {}\n{}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        );
        let newest = newest_checkpoint(&dir.join(&out).join("checkpoints"))
            .unwrap_or_else(|| panic!("SIGUSR1 {delay} s after start-up: no checkpoint"));
        let info = ok(&dir, 1, &["info", &format!("{out}/checkpoints/{newest}")]);
        assert!(info.contains("particles"), "{info}");
    }
    assert!(
        seen_before_mpi,
        "in five starts no rank caught SIGUSR1 while it ran one thread: the handlers come after MPI"
    );
}
