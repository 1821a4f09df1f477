//! MPI test of the case file: collective writes on 1..=W ranks (uneven counts, ranks with no
//! particles), reads back on 1..=W ranks compared bit for bit, and clean errors for damaged,
//! foreign, too-new and misshapen files.
//!
//! Run with W >= 3 to cover reading on 1, 2 and 3 ranks:
//!   OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
//!     mpirun -n 3 --oversubscribe target/debug/case_mpi_test
//! Prints `N passed, M failed` on rank 0 and exits non-zero on any failure.

use std::path::{Path, PathBuf};

use mpi::collective::SystemOperation;
use mpi::topology::{Color, SimpleCommunicator};
use mpi::traits::*;

use pfem_mpi::case_file::{
    block_range, new_case, read_case, summarize, write_case, CaseErrorKind, CaseHeader, ParticleSet,
};
use pfem_mpi::scene::load_scene;

struct Checks {
    rank: i32,
    passed: u64,
    failed: u64,
}

impl Checks {
    fn check(&mut self, ok: bool, what: &str) {
        if ok {
            self.passed += 1;
        } else {
            self.failed += 1;
            eprintln!("rank {}: FAILED: {what}", self.rank);
        }
    }
}

/// Deterministic f64 bit patterns, with the values most likely to be mangled by a conversion.
fn value(seed: u64) -> f64 {
    const SPECIAL: [u64; 6] = [
        0x8000_0000_0000_0000, // -0.0
        0x0000_0000_0000_0001, // smallest subnormal
        0x7fef_ffff_ffff_ffff, // f64::MAX
        0x7ff8_dead_beef_0001, // NaN with payload
        0xfff0_0000_0000_0000, // -inf
        0x3ff0_0000_0000_0001, // 1 + ulp
    ];
    let x = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15).rotate_left(17) ^ 0x5851_f42d_4c95_7f2d;
    if seed % 11 == 3 {
        f64::from_bits(SPECIAL[(seed / 11 % 6) as usize])
    } else {
        // A finite normal number: clear the top exponent bit so it is never inf/NaN.
        f64::from_bits(x & 0xbfff_ffff_ffff_ffff)
    }
}

/// The cantilever's state rows: the stress alone (an elastic law keeps nothing else).
const STATE_LEN: usize = 4;

fn global_particles(n: usize) -> ParticleSet {
    let mut p = ParticleSet::with_capacity(n, STATE_LEN);
    for i in 0..n as u64 {
        p.gid.push(1000 + 7 * i);
        p.position.push([value(10 * i), value(10 * i + 1)]);
        p.displacement.push([value(10 * i + 2), value(10 * i + 3)]);
        p.increment.push([value(10 * i + 8), value(10 * i + 9)]);
        p.h.push(value(10 * i + 4));
        let row: [f64; STATE_LEN] = std::array::from_fn(|k| value(10 * i + 5 + 1000 * k as u64));
        p.state.push(&row);
        p.flags.push((i as u32).wrapping_mul(0x9e37_79b9));
        // The cantilever has one material.
        p.material.push(0);
    }
    p
}

fn bits2(v: &[[f64; 2]]) -> Vec<u64> {
    v.iter()
        .flat_map(|a| a.iter().map(|x| x.to_bits()))
        .collect()
}

fn same_bits(a: &ParticleSet, b: &ParticleSet) -> bool {
    a.gid == b.gid
        && bits2(&a.position) == bits2(&b.position)
        && bits2(&a.displacement) == bits2(&b.displacement)
        && bits2(&a.increment) == bits2(&b.increment)
        && a.h
            .iter()
            .map(|x| x.to_bits())
            .eq(b.h.iter().map(|x| x.to_bits()))
        && a.state.len() == b.state.len()
        && a.state
            .iter()
            .zip(b.state.iter())
            .all(|(x, y)| (0..STATE_LEN).all(|k| x[k].to_bits() == y[k].to_bits()))
        && a.flags == b.flags
        && a.material == b.material
}

fn same_header(a: &CaseHeader, b: &CaseHeader) -> bool {
    a.code_version == b.code_version
        && a.scene_toml == b.scene_toml
        && a.scene_source == b.scene_source
        && a.step == b.step
        && a.load_factor.to_bits() == b.load_factor.to_bits()
        && a.time.to_bits() == b.time.to_bits()
        && a.next_gid == b.next_gid
        && a.tracked_gids == b.tracked_gids
}

/// The first `k` ranks of `world`, or None on the others.
fn first_ranks(world: &SimpleCommunicator, k: i32) -> Option<SimpleCommunicator> {
    let color = if world.rank() < k {
        Color::with_value(0)
    } else {
        Color::undefined()
    };
    world.split_by_color(color)
}

fn test_header(scene_toml: &str) -> CaseHeader {
    CaseHeader {
        format_version: 2,
        code_version: "0.1.0-test".to_string(),
        scene_toml: scene_toml.to_string(),
        scene_source: "cantilever".to_string(),
        step: 17,
        load_factor: value(77),
        time: 1.5,
        next_gid: 5000,
        ranks: 0,
        tracked_gids: vec![1007, 1000 + 7 * 56, u64::MAX],
        rank_counts: Vec::new(),
        collapse_reference: None,
        state_columns: ["stress_xx", "stress_yy", "stress_zz", "stress_xy"]
            .map(String::from)
            .to_vec(),
    }
}

/// Writes `global` split as `counts` over the first `counts.len()` ranks, then reads it back on
/// every rank count 1..=world size.
fn round_trip(
    world: &SimpleCommunicator,
    c: &mut Checks,
    path: &Path,
    header: &CaseHeader,
    global: &ParticleSet,
    counts: &[usize],
) {
    let k = counts.len() as i32;
    let label = format!("counts {counts:?}");
    if let Some(comm) = first_ranks(world, k) {
        let start: usize = counts[..comm.rank() as usize].iter().sum();
        let local = global.slice(start..start + counts[comm.rank() as usize]);
        let written = write_case(&comm, path, header, &local);
        c.check(written.is_ok(), &format!("{label}: write: {written:?}"));
    }
    world.barrier();
    if world.rank() == 0 {
        let mut tmp = path.as_os_str().to_owned();
        tmp.push(".tmp");
        c.check(
            !Path::new(&tmp).exists(),
            &format!("{label}: temporary file left behind"),
        );
    }
    for r in 1..=world.size() {
        let Some(comm) = first_ranks(world, r) else {
            continue;
        };
        match read_case(&comm, path) {
            Ok((h, p)) => {
                // The writer's rank count reads back the writer's blocks (a restart keeps its
                // partition); any other count reads even blocks.
                let block = if r == k {
                    let start: usize = counts[..comm.rank() as usize].iter().sum();
                    start as u64..(start + counts[comm.rank() as usize]) as u64
                } else {
                    block_range(global.len() as u64, r as u64, comm.rank() as u64)
                };
                let expect = global.slice(block.start as usize..block.end as usize);
                c.check(
                    same_header(&h, header),
                    &format!("{label}: header read on {r}"),
                );
                c.check(
                    h.ranks == k as u32,
                    &format!("{label}: ranks attribute {}", h.ranks),
                );
                c.check(
                    h.rank_counts == counts.iter().map(|&n| n as u64).collect::<Vec<_>>(),
                    &format!("{label}: rank_counts attribute {:?}", h.rank_counts),
                );
                c.check(h.format_version == 2, &format!("{label}: format_version"));
                c.check(
                    same_bits(&p, &expect),
                    &format!("{label}: particles read on {r} ranks"),
                );
                let mut total = 0u64;
                comm.all_reduce_into(&(p.len() as u64), &mut total, SystemOperation::sum());
                c.check(
                    total == global.len() as u64,
                    &format!("{label}: total read on {r}"),
                );
            }
            Err(e) => c.check(false, &format!("{label}: read on {r} ranks: {e}")),
        }
    }
    world.barrier();
}

/// Rank 0 prepares a damaged copy with `damage`; every rank then reads it collectively and
/// checks the error.
fn expect_error(
    world: &SimpleCommunicator,
    c: &mut Checks,
    good: &Path,
    bad: &Path,
    damage: impl FnOnce(&Path),
    kinds: &[CaseErrorKind],
    message: Option<&str>,
) {
    if world.rank() == 0 {
        let _ = std::fs::remove_file(bad);
        if good.exists() {
            std::fs::copy(good, bad).expect("copy the test file");
        }
        damage(bad);
    }
    world.barrier();
    let label = bad.file_name().unwrap().to_string_lossy().to_string();
    match read_case(world, bad) {
        Ok(_) => c.check(
            false,
            &format!("{label}: read_case accepted a damaged file"),
        ),
        Err(e) => {
            c.check(
                kinds.contains(&e.kind),
                &format!("{label}: kind {:?}: {e}", e.kind),
            );
            c.check(
                e.to_string().starts_with(&bad.display().to_string()),
                &format!("{label}: error does not name the file: {e}"),
            );
            if let Some(m) = message {
                c.check(
                    e.to_string() == m,
                    &format!("{label}: got {e}, expected {m}"),
                );
            }
            if world.rank() == 0 {
                println!("  {label}: {e}");
            }
        }
    }
    if world.rank() == 0 {
        let s = summarize(bad);
        c.check(
            s.is_err(),
            &format!("{label}: summarize accepted a damaged file"),
        );
    }
    world.barrier();
}

fn rewrite(path: &Path, edit: impl FnOnce(&hdf5::File) -> hdf5::Result<()>) {
    let f = hdf5::File::open_rw(path).expect("open the test copy");
    edit(&f).expect("edit the test copy");
    f.close().expect("close the test copy");
}

fn main() {
    let universe = mpi::initialize().expect("MPI initialisation");
    let world = universe.world();
    let mut c = Checks {
        rank: world.rank(),
        passed: 0,
        failed: 0,
    };

    let mut pid = std::process::id();
    world.process_at_rank(0).broadcast_into(&mut pid);
    let dir = std::env::temp_dir().join(format!("pfem-case-mpi-test-{pid}"));
    if world.rank() == 0 {
        std::fs::create_dir_all(&dir).expect("create the test directory");
        println!(
            "case_mpi_test on {} ranks in {}",
            world.size(),
            dir.display()
        );
    }
    world.barrier();
    let at = |name: &str| -> PathBuf { dir.join(name) };

    let (scene, resolved) = load_scene("cantilever", &[]).expect("built-in scene");
    let header = test_header(&resolved);
    let global = global_particles(57);
    let path = at("case.h5");
    let patterns: [&[usize]; 9] = [
        &[57],
        &[0],
        &[0, 1],
        &[57, 0],
        &[0, 57],
        &[40, 17],
        &[0, 0],
        &[5, 0, 52],
        &[20, 20, 17],
    ];
    for counts in patterns {
        if counts.len() as i32 <= world.size() {
            let g = global.slice(0..counts.iter().sum());
            round_trip(&world, &mut c, &path, &header, &g, counts);
        }
    }

    // A real case: the cantilever lattice split unevenly over the first two ranks.
    let (case_header, particles) = new_case(&scene, "cantilever");
    let cpath = at("cantilever.h5");
    let k = world.size().min(2);
    let counts: Vec<usize> = if k == 2 { vec![500, 229] } else { vec![729] };
    round_trip(&world, &mut c, &cpath, &case_header, &particles, &counts);
    if world.rank() == 0 {
        match summarize(&cpath) {
            Ok(text) => {
                println!("{text}");
                c.check(text.contains("cantilever"), "summary names the scene");
                c.check(text.contains("729"), "summary gives the particle count");
                c.check(
                    text.contains("gid 404 at (10, 0.5)"),
                    "summary gives the tracked particle",
                );
            }
            Err(e) => c.check(false, &format!("summarize: {e}")),
        }
    }

    // Damaged and foreign files: every one is a clean, collective error.
    let good = at("case.h5");
    round_trip(&world, &mut c, &good, &header, &global, &[57]);
    let n = global.len();
    expect_error(
        &world,
        &mut c,
        &good,
        &at("truncated-half.h5"),
        |p| {
            let len = std::fs::metadata(p).unwrap().len();
            std::fs::OpenOptions::new()
                .write(true)
                .open(p)
                .unwrap()
                .set_len(len / 2)
                .unwrap();
        },
        &[CaseErrorKind::Malformed, CaseErrorKind::Io],
        None,
    );
    expect_error(
        &world,
        &mut c,
        &good,
        &at("truncated-100.h5"),
        |p| {
            std::fs::OpenOptions::new()
                .write(true)
                .open(p)
                .unwrap()
                .set_len(100)
                .unwrap();
        },
        &[CaseErrorKind::Malformed, CaseErrorKind::Io],
        None,
    );
    expect_error(
        &world,
        &mut c,
        &good,
        &at("truncated-4.h5"),
        |p| {
            std::fs::OpenOptions::new()
                .write(true)
                .open(p)
                .unwrap()
                .set_len(4)
                .unwrap();
        },
        &[CaseErrorKind::NotHdf5],
        None,
    );
    expect_error(
        &world,
        &mut c,
        &good,
        &at("superblock.h5"),
        |p| {
            let mut bytes = std::fs::read(p).unwrap();
            for b in &mut bytes[8..96] {
                *b = 0xa5;
            }
            std::fs::write(p, bytes).unwrap();
        },
        &[CaseErrorKind::Malformed, CaseErrorKind::Io],
        None,
    );
    let garbage = at("garbage.h5");
    expect_error(
        &world,
        &mut c,
        Path::new("/nonexistent"),
        &garbage,
        |p| {
            std::fs::write(p, vec![0x42u8; 4096]).unwrap();
        },
        &[CaseErrorKind::NotHdf5],
        Some(&format!("{}: not an HDF5 file", garbage.display())),
    );
    expect_error(
        &world,
        &mut c,
        Path::new("/nonexistent"),
        &at("missing.h5"),
        |_| {},
        &[CaseErrorKind::Io],
        None,
    );
    let newer = at("newer.h5");
    expect_error(
        &world,
        &mut c,
        &good,
        &newer,
        |p| {
            rewrite(p, |f| {
                f.delete_attr("format_version")?;
                f.new_attr::<u32>()
                    .create("format_version")?
                    .write_scalar(&7u32)
            })
        },
        &[CaseErrorKind::TooNew],
        Some(&format!(
            "{}: format_version 7 is newer than this pfem-mpi (2)",
            newer.display()
        )),
    );
    let shape = at("shape.h5");
    expect_error(
        &world,
        &mut c,
        &good,
        &shape,
        |p| {
            rewrite(p, |f| {
                let g = f.group("particles")?;
                g.unlink("position")?;
                g.new_dataset::<f64>().shape((n, 3)).create("position")?;
                Ok(())
            })
        },
        &[CaseErrorKind::Malformed],
        Some(&format!(
            "{}: dataset /particles/position: expected shape (n, 2), found ({n}, 3)",
            shape.display()
        )),
    );
    let rows = at("rows.h5");
    expect_error(
        &world,
        &mut c,
        &good,
        &rows,
        |p| {
            rewrite(p, |f| {
                let g = f.group("particles")?;
                g.unlink("h")?;
                g.new_dataset::<f64>().shape(n - 1).create("h")?;
                Ok(())
            })
        },
        &[CaseErrorKind::Malformed],
        Some(&format!(
            "{}: dataset /particles/h: has {} particles but /particles/gid has {n}",
            rows.display(),
            n - 1
        )),
    );
    let dtype = at("dtype.h5");
    expect_error(
        &world,
        &mut c,
        &good,
        &dtype,
        |p| {
            rewrite(p, |f| {
                let g = f.group("particles")?;
                g.unlink("gid")?;
                g.new_dataset::<i64>().shape(n).create("gid")?;
                Ok(())
            })
        },
        &[CaseErrorKind::Malformed],
        Some(&format!(
            "{}: dataset /particles/gid: expected type uint64, found int64",
            dtype.display()
        )),
    );
    let missing = at("no-flags.h5");
    expect_error(
        &world,
        &mut c,
        &good,
        &missing,
        |p| rewrite(p, |f| f.group("particles")?.unlink("flags")),
        &[CaseErrorKind::Malformed],
        Some(&format!(
            "{}: dataset /particles/flags: missing",
            missing.display()
        )),
    );
    let attr = at("no-step.h5");
    expect_error(
        &world,
        &mut c,
        &good,
        &attr,
        |p| rewrite(p, |f| f.delete_attr("step")),
        &[CaseErrorKind::Malformed],
        Some(&format!("{}: attribute step: missing", attr.display())),
    );
    let foreign = at("foreign.h5");
    expect_error(
        &world,
        &mut c,
        Path::new("/nonexistent"),
        &foreign,
        |p| {
            let f = hdf5::File::create(p).unwrap();
            f.new_dataset::<f64>().shape(10).create("data").unwrap();
        },
        &[CaseErrorKind::NotACase],
        None,
    );

    // Write failures are reported on every rank and leave nothing behind.
    let nowhere = Path::new("/nonexistent-dir/case.h5");
    let e = write_case(
        &world,
        nowhere,
        &header,
        &global.slice(0..world.rank() as usize),
    );
    c.check(
        matches!(&e, Err(e) if e.kind == CaseErrorKind::Io),
        &format!("write to missing dir: {e:?}"),
    );
    let mut uneven = global.slice(0..3);
    if world.rank() == world.size() - 1 {
        uneven.h.pop();
    }
    let e = write_case(&world, &at("uneven.h5"), &header, &uneven);
    c.check(
        matches!(&e, Err(e) if e.kind == CaseErrorKind::InvalidInput && e.message.contains("h entries")),
        &format!("inconsistent particle set: {e:?}"),
    );
    c.check(
        !at("uneven.h5").exists() && !at("uneven.h5.tmp").exists(),
        "no file from a refused write",
    );

    world.barrier();
    if world.rank() == 0 {
        std::fs::remove_dir_all(&dir).expect("remove the test directory");
    }
    let mut passed = 0u64;
    let mut failed = 0u64;
    world.all_reduce_into(&c.passed, &mut passed, SystemOperation::sum());
    world.all_reduce_into(&c.failed, &mut failed, SystemOperation::sum());
    if world.rank() == 0 {
        println!("{passed} passed, {failed} failed");
    }
    drop(universe);
    if failed > 0 {
        std::process::exit(1);
    }
}
