//! The per-rank table after the end-of-run line (weak-scaling measurements, bench/CLUSTER.md):
//! one row per rank, whose owned particles and triangles add up to the run's totals, whose
//! owned dofs add up to the same global count on any rank count, with a halo exactly when there
//! is more than one rank, and a peak RSS.

mod common;

use common::{ok, small_cantilever, workdir};

/// One row of the table: rank, owned, ghost, dofs, ghost_dofs, owned_tris, local_tris,
/// solve_cpu, cpu_total, peak_rss_MB.
#[derive(Debug)]
struct Row {
    rank: u64,
    owned: u64,
    ghost: u64,
    dofs: u64,
    ghost_dofs: u64,
    owned_tris: u64,
    local_tris: u64,
    solve_cpu: f64,
    cpu_total: f64,
    peak_rss_mb: f64,
}

/// The table's rows: the lines after its header, which comes after the `done:` line.
fn table(stdout: &str) -> Vec<Row> {
    let lines: Vec<&str> = stdout.lines().collect();
    let done = lines
        .iter()
        .position(|l| l.starts_with("done:"))
        .unwrap_or_else(|| panic!("no end-of-run line in\n{stdout}"));
    let header = lines[done..]
        .iter()
        .position(|l| l.split_whitespace().take(2).eq(["rank", "owned"]))
        .map(|i| done + i)
        .unwrap_or_else(|| panic!("no per-rank table after the end-of-run line in\n{stdout}"));
    let columns: Vec<&str> = lines[header].split_whitespace().collect();
    assert_eq!(
        columns,
        [
            "rank",
            "owned",
            "ghost",
            "dofs",
            "ghost_dofs",
            "owned_tris",
            "local_tris",
            "solve_cpu",
            "cpu_total",
            "peak_rss_MB"
        ]
    );
    lines[header + 1..]
        .iter()
        .map(|l| {
            let v: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(v.len(), columns.len(), "a full row: {l}");
            let int = |i: usize| -> u64 { v[i].parse().unwrap_or_else(|_| panic!("{l}")) };
            let real = |i: usize| -> f64 { v[i].parse().unwrap_or_else(|_| panic!("{l}")) };
            Row {
                rank: int(0),
                owned: int(1),
                ghost: int(2),
                dofs: int(3),
                ghost_dofs: int(4),
                owned_tris: int(5),
                local_tris: int(6),
                solve_cpu: real(7),
                cpu_total: real(8),
                peak_rss_mb: real(9),
            }
        })
        .collect()
}

/// The last progress line's `name <count>`.
fn last_count(stdout: &str, name: &str) -> u64 {
    stdout
        .lines()
        .filter(|l| l.starts_with("step "))
        .filter_map(|l| l.split(&format!(" {name} ")).nth(1))
        .map(|r| r.split_whitespace().next().unwrap().parse().unwrap())
        .next_back()
        .unwrap_or_else(|| panic!("no '{name}' in a progress line of\n{stdout}"))
}

#[test]
fn per_rank_table_adds_up_on_one_and_two_ranks() {
    let dir = workdir("rank-table");
    small_cantilever(&dir, 4, &[]);
    let mut global_dofs = Vec::new();
    for ranks in [1, 2] {
        let out = format!("o{ranks}");
        let stdout = ok(&dir, ranks, &["c.h5", "--out", &out, "--until-step", "2"]);
        let rows = table(&stdout);
        assert_eq!(rows.len(), ranks, "one row per rank:\n{stdout}");
        for (r, row) in rows.iter().enumerate() {
            assert_eq!(row.rank, r as u64, "rows in rank order:\n{stdout}");
            assert!(row.owned > 0 && row.dofs >= 2 * row.owned, "{row:?}");
            assert!(row.local_tris >= row.owned_tris, "{row:?}");
            assert!(row.peak_rss_mb > 1.0, "a peak RSS from VmHWM: {row:?}");
            assert!(
                row.solve_cpu > 0.0 && row.solve_cpu <= row.cpu_total + 0.02,
                "the solves are part of the process's CPU: {row:?}"
            );
            // A halo exactly when another rank owns part of the body.
            assert_eq!(row.ghost > 0, ranks > 1, "{row:?}");
            assert_eq!(row.ghost_dofs > 0, ranks > 1, "{row:?}");
        }
        let sum = |f: fn(&Row) -> u64| rows.iter().map(f).sum::<u64>();
        assert_eq!(
            sum(|r| r.owned),
            last_count(&stdout, "particles"),
            "owned particles add up to the total:\n{stdout}"
        );
        assert_eq!(
            sum(|r| r.owned_tris),
            last_count(&stdout, "triangles"),
            "owned triangles add up to the total:\n{stdout}"
        );
        global_dofs.push(sum(|r| r.dofs));
    }
    assert_eq!(
        global_dofs[0], global_dofs[1],
        "the same mesh has the same number of dofs on any rank count"
    );
}
