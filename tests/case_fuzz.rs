//! Issue 11: 2 000 seeded corruptions of a small case, each validated in-process by the function
//! the reader calls (`validate_case`): zero panics, each case within a time bound, and every
//! corruption that breaks a rule is rejected with an error naming the file and a dataset or
//! attribute. No MPI is needed: the rules are plain functions.

use std::path::Path;
use std::time::{Duration, Instant};

use pfem_mpi::case_file::validate::validate_case;
use pfem_mpi::case_file::{new_case, CaseHeader, GaussRecords, ParticleSet, GAUSS_POINTS};
use pfem_mpi::material::Rows;
use pfem_mpi::rng::next;
use pfem_mpi::scene::load_scene;

const CASES: u64 = 2000;
const BOUND: Duration = Duration::from_secs(2);

/// The cantilever at h = 0.5 with one counter-clockwise triangle per lattice square (right and
/// upper neighbour), keyed smallest id first: a valid case with `/gauss`.
fn base() -> (CaseHeader, ParticleSet, GaussRecords) {
    let (scene, _) = load_scene("cantilever", &["mesh.h=0.5".to_string()]).unwrap();
    let (mut header, p) = new_case(&scene, "cantilever");
    header.step = 1;
    let find = |x: [f64; 2]| {
        p.position
            .iter()
            .position(|q| (q[0] - x[0]).abs() < 1e-9 && (q[1] - x[1]).abs() < 1e-9)
    };
    let width = GAUSS_POINTS * header.state_columns.len();
    let mut g = GaussRecords {
        state: Rows::new(width),
        ..GaussRecords::default()
    };
    for (i, x) in p.position.iter().enumerate() {
        let (Some(b), Some(c)) = (find([x[0] + 0.5, x[1]]), find([x[0] + 0.5, x[1] + 0.5])) else {
            continue;
        };
        let mut key = [p.gid[i], p.gid[b], p.gid[c]];
        let k = (0..3).min_by_key(|&k| key[k]).unwrap();
        key.rotate_left(k);
        g.key.push(key);
        g.state.push(&vec![1.0; width]);
        g.nodes.push([f64::NAN; 18]);
        g.contact.push([f64::NAN; 18]);
        g.bulge.push([f64::NAN; 3]);
    }
    assert!(g.len() > 10);
    (header, p, g)
}

struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        (next(&mut self.0) % n.max(1) as u64) as usize
    }
    fn pick<T: Copy>(&mut self, from: &[T]) -> T {
        from[self.below(from.len())]
    }
}

const NASTY: [f64; 8] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e300,
    -1e300,
    f64::MAX,
    -0.0,
    1e-310,
];

/// One random corruption; returns whether it surely breaks a rule.
fn corrupt(r: &mut Rng, h: &mut CaseHeader, p: &mut ParticleSet, g: &mut GaussRecords) -> bool {
    let n = p.len();
    let i = r.below(n);
    let bad = |v: f64| !v.is_finite();
    match r.below(16) {
        0 => {
            let v = r.pick(&NASTY);
            let k = r.below(2);
            if let Some(x) = p.position.get_mut(i) {
                x[k] = v;
            }
            bad(v) || v.abs() > 1e20
        }
        1 => {
            let v = r.pick(&NASTY);
            let k = r.below(2);
            if let Some(x) = p.displacement.get_mut(i) {
                x[k] = v;
            }
            bad(v)
        }
        2 => {
            let v = r.pick(&NASTY);
            let k = r.below(2);
            if let Some(x) = p.increment.get_mut(i) {
                x[k] = v;
            }
            bad(v)
        }
        3 => {
            let v = r.pick(&NASTY);
            let k = r.below(p.state.width());
            if i < p.state.len() {
                p.state.row_mut(i)[k] = v;
            }
            bad(v)
        }
        4 => {
            let v = r.pick(&[0.0, -0.5, f64::NAN, f64::INFINITY, -1e-300, 1e-300]);
            if let Some(x) = p.h.get_mut(i) {
                *x = v;
            }
            v <= 0.0 || bad(v)
        }
        5 => {
            // An id at or above next_gid, or another particle's.
            if r.below(2) == 0 {
                p.gid[i] = h.next_gid + r.below(1000) as u64;
            } else {
                let j = (i + 1 + r.below(n - 1)) % n;
                p.gid[i] = p.gid[j];
            }
            true
        }
        6 => {
            let bit = 1 << (1 + r.below(31));
            if let Some(x) = p.flags.get_mut(i) {
                *x = bit;
            }
            true
        }
        7 => {
            h.step = h.step.max(1) + 1000 + r.below(1 << 20) as u64;
            true
        }
        8 => {
            // The step reset on a displaced body.
            h.step = 0;
            if let Some(x) = p.displacement.get_mut(i) {
                *x = [1e-3, 0.0];
            }
            true
        }
        9 => {
            match r.below(3) {
                0 => h.tracked_gids.clear(),
                1 => h.tracked_gids.push(0),
                _ => h.tracked_gids[0] = h.next_gid + r.below(50) as u64,
            }
            true
        }
        10 => {
            // Arrays of different lengths.
            match r.below(4) {
                0 => {
                    p.h.pop();
                }
                1 => {
                    p.state.truncate(r.below(n));
                }
                2 => {
                    g.state.pop();
                }
                _ => {
                    p.position.push([0.0, 0.0]);
                }
            }
            true
        }
        11 => {
            // Flipped bytes or a cut in the scene text (kept UTF-8, as the reader ensures).
            let mut bytes = h.scene_toml.clone().into_bytes();
            let at = r.below(bytes.len());
            if r.below(2) == 0 {
                bytes.truncate(at);
            } else {
                bytes[at] ^= 1 << r.below(8);
            }
            h.scene_toml = String::from_utf8_lossy(&bytes).into_owned();
            false
        }
        12 => {
            // A clockwise key, or one naming no particle, or twice the same triangle.
            let t = r.below(g.len());
            match r.below(3) {
                0 => g.key[t].swap(1, 2),
                1 => g.key[t][1 + r.below(2)] = h.next_gid + 7,
                _ => {
                    let (k, other) = (g.key[t], (t + 1) % g.len());
                    g.key[other] = k;
                }
            }
            true
        }
        13 => {
            let t = r.below(g.len());
            let (k, v) = (r.below(g.state.width()), r.pick(&NASTY[..3]));
            if t < g.state.len() {
                g.state.row_mut(t)[k] = v;
            }
            true
        }
        14 => {
            let v = r.pick(&[f64::NAN, f64::INFINITY, 0.5, -3.0]);
            if r.below(2) == 0 {
                h.load_factor = v;
            } else {
                h.time = v;
            }
            bad(v)
        }
        _ => {
            // next_gid below the particle count.
            h.next_gid = r.below(n) as u64;
            true
        }
    }
}

#[test]
fn two_thousand_corruptions_never_panic_and_rule_breakers_are_rejected() {
    let path = Path::new("fuzz.h5");
    let (h0, p0, g0) = base();
    assert!(validate_case(path, &h0, &p0, &g0).is_ok());
    let mut r = Rng(20261123);
    let (mut rejected, mut slowest) = (0, Duration::ZERO);
    for case in 0..CASES {
        let (mut h, mut p, mut g) = (h0.clone(), p0.clone(), g0.clone());
        let mut must_fail = false;
        for _ in 0..1 + r.below(3) {
            must_fail |= corrupt(&mut r, &mut h, &mut p, &mut g);
        }
        let start = Instant::now();
        let outcome = std::panic::catch_unwind(|| validate_case(path, &h, &p, &g));
        let took = start.elapsed();
        slowest = slowest.max(took);
        assert!(took < BOUND, "case {case} took {took:?}");
        let outcome = outcome.unwrap_or_else(|_| panic!("case {case} panicked"));
        match outcome {
            Ok(_) => assert!(
                !must_fail,
                "case {case}: a corruption that breaks a rule passed"
            ),
            Err(e) => {
                rejected += 1;
                let text = e.to_string();
                assert!(text.starts_with("fuzz.h5: "), "case {case}: {text}");
                assert!(
                    e.location
                        .as_deref()
                        .is_some_and(|l| l.starts_with("dataset /")
                            || l.starts_with("attribute ")
                            || l.starts_with("group /")),
                    "case {case}: {text}"
                );
            }
        }
    }
    println!("{CASES} corruptions: {rejected} rejected, slowest {slowest:?}");
    assert!(rejected > CASES / 2);
}
