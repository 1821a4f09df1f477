//! MPI test of the ParaView output (`pfem_mpi::output`): writes frames of a synthetic
//! triangulated square distributed over the ranks, checks that bad frames fail the same way on
//! every rank, and re-opens the series as a restart would.
//!
//!   OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
//!     mpirun -n 3 --oversubscribe target/debug/examples/xdmf_selftest OUT_DIR
//!
//! Leaves in OUT_DIR a series of frames 1..=4 for `tests/check_xdmf.py` to verify. The square
//! of frame s is [0,1]^2 cut into (3+s)^2 cells of two counter-clockwise triangles each, sheared
//! and stretched: x = X + 0.1 s Y, y = (1 + 0.05 s) Y, so its area is 1 + 0.05 s. Time is
//! 0.1 s. Fields are functions of the current position (x, y) and time t:
//!
//! - `pressure` (scalar) = sin(3x) + y^2
//! - `level` (scalar, borrowed) = t + x
//! - `velocity` (vector, borrowed) = (x y, x - 2y)
//! - `flow` (vector) = (cos x, t y)
//! - `stress` (tensor, Voigt xx, yy, zz, xy) = (x, y, x + y, x y)
//!
//! Particle ids are 1000 + 7 k for lattice index k. Particles and triangles are dealt to ranks
//! by unrelated rules, so most triangles have vertices owned elsewhere; in frame 2 the last rank
//! (of two or more) owns nothing. Prints `N passed, M failed` on rank 0 and exits non-zero on
//! any failure.

use std::path::{Path, PathBuf};

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

use pfem_mpi::output::{Field, FieldsWriter, Frame, OutputError};
use pfem_partition::allgather_u64;

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

/// One rank's part of the synthetic square of frame `step`.
struct Part {
    step: u64,
    gid: Vec<u64>,
    position: Vec<[f64; 2]>,
    triangles: Vec<[u64; 3]>,
}

fn cells(step: u64) -> u64 {
    3 + step
}

fn gid_of(k: u64) -> u64 {
    1000 + 7 * k
}

/// Ranks that get particles in frame `step`: all but the last in frame 2.
fn owners(step: u64, size: u64) -> u64 {
    if step == 2 && size > 1 {
        size - 1
    } else {
        size
    }
}

/// Owner of lattice point (i, j).
fn point_owner(step: u64, size: u64, i: u64, j: u64) -> u64 {
    (7 * i + 3 * j + step) % owners(step, size)
}

/// Owner of the particle `gid` in frame `step`, if it is one.
fn owner_of_gid(step: u64, size: u64, gid: u64) -> Option<i32> {
    let side = cells(step) + 1;
    let k = gid.checked_sub(1000).filter(|d| d % 7 == 0)? / 7;
    if k >= side * side {
        return None;
    }
    i32::try_from(point_owner(step, size, k % side, k / side)).ok()
}

fn position(step: u64, i: u64, j: u64) -> [f64; 2] {
    let n = cells(step) as f64;
    let s = step as f64;
    let (x0, y0) = (i as f64 / n, j as f64 / n);
    [x0 + 0.1 * s * y0, (1.0 + 0.05 * s) * y0]
}

fn part(step: u64, size: u64, rank: u64) -> Part {
    let n = cells(step);
    let side = n + 1;
    let mut gid = Vec::new();
    let mut pos = Vec::new();
    for j in 0..side {
        for i in 0..side {
            if point_owner(step, size, i, j) == rank {
                gid.push(gid_of(j * side + i));
                pos.push(position(step, i, j));
            }
        }
    }
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let [a, b, c, d] =
                [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)].map(|(i, j)| gid_of(j * side + i));
            let pair = if (i + j) % 2 == 0 {
                [[a, b, c], [a, c, d]]
            } else {
                [[a, b, d], [b, c, d]]
            };
            for (k, t) in pair.into_iter().enumerate() {
                let cell = j * n + i;
                if (5 * cell + k as u64 + step) % owners(step, size) == rank {
                    triangles.push(t);
                }
            }
        }
    }
    // Particles were generated in lattice order, which is gid order.
    Part {
        step,
        gid,
        position: pos,
        triangles,
    }
}

fn time(step: u64) -> f64 {
    0.1 * step as f64
}

/// Values of the fields at `p`, owned by the caller so that some can be borrowed by a frame.
struct Values {
    level: Vec<f64>,
    velocity: Vec<[f64; 2]>,
}

fn values(p: &Part) -> Values {
    let t = time(p.step);
    Values {
        level: p.position.iter().map(|&[x, _]| t + x).collect(),
        velocity: p
            .position
            .iter()
            .map(|&[x, y]| [x * y, x - 2.0 * y])
            .collect(),
    }
}

fn fields<'a>(p: &Part, v: &'a Values) -> Vec<Field<'a>> {
    let t = time(p.step);
    vec![
        Field::Scalar(
            "pressure".into(),
            p.position
                .iter()
                .map(|&[x, y]| (3.0 * x).sin() + y * y)
                .collect(),
        ),
        Field::ScalarRef("level".into(), &v.level),
        Field::VectorRef("velocity".into(), &v.velocity),
        Field::Vector(
            "flow".into(),
            p.position.iter().map(|&[x, y]| [x.cos(), t * y]).collect(),
        ),
        Field::Tensor(
            "stress".into(),
            p.position
                .iter()
                .map(|&[x, y]| [x, y, x + y, x * y])
                .collect(),
        ),
    ]
}

fn frame<'a>(p: &'a Part, v: &'a Values, owner_of: &'a dyn Fn(u64) -> Option<i32>) -> Frame<'a> {
    Frame {
        step: p.step,
        time: time(p.step),
        gid: &p.gid,
        position: &p.position,
        point_data: fields(p, v),
        triangles: &p.triangles,
        owner_of,
    }
}

/// Writes frame `step` of the synthetic square.
fn write_step(world: &SimpleCommunicator, w: &mut FieldsWriter, step: u64) -> Result<(), String> {
    let size = world.size() as u64;
    let p = part(step, size, world.rank() as u64);
    let v = values(&p);
    let owner = move |g: u64| owner_of_gid(step, size, g);
    w.write(world, &frame(&p, &v, &owner))
        .map_err(|e| e.to_string())
}

fn fingerprint(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Collective. True when `s` is the same on every rank.
fn same_everywhere(world: &SimpleCommunicator, s: &str) -> bool {
    let all = allgather_u64(world, &[fingerprint(s)]);
    all.iter().all(|&h| h == all[0])
}

/// Collective. Checks that `result` is an error on every rank, the same everywhere, naming
/// `file` and containing `needle`.
fn expect_error<T>(
    world: &SimpleCommunicator,
    c: &mut Checks,
    what: &str,
    result: Result<T, OutputError>,
    file: &Path,
    needle: &str,
) {
    let text = match &result {
        Ok(_) => "no error".to_string(),
        Err(e) => e.to_string(),
    };
    let prefix = format!("{}: ", file.display());
    c.check(
        result.is_err() && text.starts_with(&prefix) && text.contains(needle),
        &format!("{what}: expected \"{prefix}...{needle}...\", got \"{text}\""),
    );
    c.check(
        same_everywhere(world, &text),
        &format!("{what}: error differs between ranks"),
    );
}

/// Steps listed in the series file, in order (read on rank 0 only; empty elsewhere).
fn listed_steps(world: &SimpleCommunicator, series: &Path) -> Vec<u64> {
    if world.rank() != 0 {
        return Vec::new();
    }
    let text = std::fs::read_to_string(series).unwrap_or_default();
    text.split("<Grid Name=\"step_")
        .skip(1)
        .filter_map(|s| s.split('"').next().and_then(|d| d.parse().ok()))
        .collect()
}

fn check_listed(world: &SimpleCommunicator, c: &mut Checks, series: &Path, want: &[u64]) {
    if world.rank() == 0 {
        let got = listed_steps(world, series);
        c.check(
            got == want,
            &format!(
                "{} lists steps {got:?}, expected {want:?}",
                series.display()
            ),
        );
    }
}

/// Bad frames: every rank gets the same error naming the frame file, and the series is untouched.
fn bad_frames(world: &SimpleCommunicator, c: &mut Checks, w: &mut FieldsWriter) {
    let size = world.size() as u64;
    let rank = world.rank() as u64;
    let last = world.size() - 1;
    let step = 9;
    let file = w.frame_path(step);
    let mut p = part(step, size, rank);
    let v = values(&p);
    let owner = move |g: u64| owner_of_gid(step, size, g);

    // A field of the wrong length on rank 0 only.
    let mut f = frame(&p, &v, &owner);
    if world.rank() == 0 {
        f.point_data[0] = Field::Scalar("pressure".into(), vec![0.0; p.gid.len() + 1]);
    }
    expect_error(
        world,
        c,
        "short field",
        w.write(world, &f),
        &file,
        "field \"pressure\" has",
    );

    // A vertex nobody can name the owner of.
    let unknown = |_: u64| None;
    let f = frame(&p, &v, &unknown);
    let any_ghost = allgather_u64(world, &[u64::from(size > 1)])[0] == 1;
    if any_ghost {
        expect_error(
            world,
            c,
            "unknown owner",
            w.write(world, &f),
            &file,
            "nor has a known owner",
        );
    }

    // A vertex that its claimed owner does not have: asked of rank 0 by the last rank.
    let mut bogus = p.triangles.clone();
    if world.rank() == last {
        bogus.push([p.gid.first().copied().unwrap_or(1000), 1000, 5]);
    }
    let claims = move |g: u64| if g == 5 { Some(0) } else { owner(g) };
    let mut f = frame(&p, &v, &claims);
    f.triangles = &bogus;
    let needle = if size == 1 {
        "said to be owned by rank 0, which does not own it"
    } else {
        "triangle vertex 5 was asked of rank 0, which does not own it"
    };
    expect_error(world, c, "wrong owner", w.write(world, &f), &file, needle);

    // Ranks that disagree on the field list.
    if size > 1 {
        let mut f = frame(&p, &v, &owner);
        if world.rank() == last {
            f.point_data.pop();
        }
        expect_error(
            world,
            c,
            "different fields",
            w.write(world, &f),
            &file,
            &format!("rank {last} passes a different step, time or field list"),
        );
    }

    // Unsorted ids on the last rank.
    if world.rank() == last && p.gid.len() > 1 {
        p.gid.swap(0, 1);
    }
    let f = frame(&p, &v, &owner);
    let unsorted = allgather_u64(world, &[p.gid.len() as u64]);
    if unsorted[last as usize] > 1 {
        expect_error(
            world,
            c,
            "unsorted ids",
            w.write(world, &f),
            &file,
            "not sorted ascending",
        );
    }
    if world.rank() == last && p.gid.len() > 1 {
        p.gid.swap(0, 1);
    }

    // A reserved or malformed field name.
    let mut f = frame(&p, &v, &owner);
    f.point_data[0] = Field::Scalar("a/b".into(), vec![0.0; p.gid.len()]);
    expect_error(
        world,
        c,
        "bad name",
        w.write(world, &f),
        &file,
        "field name \"a/b\"",
    );
    c.check(!file.exists(), "no frame file from refused frames");
}

fn run(world: &SimpleCommunicator, c: &mut Checks, dir: &Path) {
    let series = dir.join("fields.xdmf");
    if world.rank() == 0 {
        let _ = std::fs::remove_dir_all(dir);
        std::fs::create_dir_all(dir).expect("create the output folder");
        // Left over by an earlier run: a fresh start (first step 0) must not read it.
        std::fs::write(&series, "left over").expect("write a stale series");
    }
    world.barrier();

    let mut w = match FieldsWriter::open(world, dir, 0) {
        Ok(w) => w,
        Err(e) => {
            c.check(false, &format!("open: {e}"));
            return;
        }
    };
    c.check(w.series_path() == series, "series path");
    check_listed(world, c, &series, &[]);
    for step in 1..=3 {
        let r = write_step(world, &mut w, step);
        c.check(r.is_ok(), &format!("write step {step}: {r:?}"));
    }
    check_listed(world, c, &series, &[1, 2, 3]);

    bad_frames(world, c, &mut w);
    check_listed(world, c, &series, &[1, 2, 3]);
    let r = write_step(world, &mut w, 4);
    c.check(r.is_ok(), &format!("write after errors: {r:?}"));
    check_listed(world, c, &series, &[1, 2, 3, 4]);

    // A restart from step 2 drops frames 3 and 4, then writes them anew.
    let mut w = match FieldsWriter::open(world, dir, 2) {
        Ok(w) => w,
        Err(e) => {
            c.check(false, &format!("re-open: {e}"));
            return;
        }
    };
    check_listed(world, c, &series, &[1, 2]);
    for step in 3..=4 {
        let r = write_step(world, &mut w, step);
        c.check(
            r.is_ok(),
            &format!("write step {step} after restart: {r:?}"),
        );
    }
    check_listed(world, c, &series, &[1, 2, 3, 4]);
    c.check(
        !dir.join("fields.xdmf.tmp").exists(),
        "no temporary series file left",
    );

    // A frame with nothing at all on any rank is still a valid, empty frame.
    let empty = dir.join("empty");
    let written = FieldsWriter::open(world, &empty, 0).and_then(|mut w| {
        let nobody = |_: u64| None;
        let f = Frame {
            step: 1,
            time: 0.0,
            gid: &[],
            position: &[],
            point_data: vec![Field::Vector("u".into(), Vec::new())],
            triangles: &[],
            owner_of: &nobody,
        };
        w.write(world, &f)
    });
    c.check(written.is_ok(), &format!("empty frame: {written:?}"));
    check_listed(world, c, &empty.join("fields.xdmf"), &[1]);

    // Folders that cannot be used.
    let damaged = dir.join("damaged");
    if world.rank() == 0 {
        std::fs::create_dir_all(&damaged).expect("create a folder");
        std::fs::write(damaged.join("fields.xdmf"), "<html/>").expect("write a damaged series");
    }
    world.barrier();
    expect_error(
        world,
        c,
        "damaged series on restart",
        FieldsWriter::open(world, &damaged, 5),
        &damaged.join("fields.xdmf"),
        "cannot continue the series",
    );
    let under_file = series.join("out");
    expect_error(
        world,
        c,
        "folder under a file",
        FieldsWriter::open(world, &under_file, 0),
        &under_file.join("fields"),
        "cannot create folder",
    );
    if world.rank() == 0 {
        let _ = std::fs::remove_dir_all(&damaged);
        let _ = std::fs::remove_dir_all(&empty);
    }
}

fn main() {
    let Some(universe) = mpi::initialize() else {
        eprintln!("MPI initialisation failed");
        std::process::exit(2);
    };
    let world = universe.world();
    let Some(dir) = std::env::args().nth(1).map(PathBuf::from) else {
        if world.rank() == 0 {
            eprintln!("usage: xdmf_selftest OUT_DIR");
        }
        drop(universe);
        std::process::exit(2);
    };
    let mut c = Checks {
        rank: world.rank(),
        passed: 0,
        failed: 0,
    };
    run(&world, &mut c, &dir);

    let mut passed = 0u64;
    let mut failed = 0u64;
    world.all_reduce_into(&c.passed, &mut passed, SystemOperation::sum());
    world.all_reduce_into(&c.failed, &mut failed, SystemOperation::sum());
    if world.rank() == 0 {
        println!(
            "xdmf selftest on {} ranks: {passed} passed, {failed} failed",
            world.size()
        );
    }
    drop(universe);
    if failed > 0 {
        std::process::exit(1);
    }
}
