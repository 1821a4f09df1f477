//! Particle spacing that follows the solution (`[mesh.adapt]`): the indicator, the target spacing
//! and the gradation limit, as rank-local pieces that read only the mesh around owned particles
//! (equal to the global mesh there) and combine values with `max`/`min` only, so that every rank
//! count gives the same spacings bit for bit. The driver (`run::adapt`) supplies the global
//! largest indicator and copies the owners' spacings to the ghosts between gradation sweeps.

use super::LocalMesh;
use crate::fem::p1::gradient;
use crate::scene::schema::Adapt;

/// Engineering shear strain of a linear displacement field over a triangle,
/// sqrt((ux − vy)² + (uy + vx)²): twice the largest in-plane shear strain. `x` and `u` are in the
/// triangle's canonical vertex order (smallest global id first), so that the same triangle gives
/// the same value on every rank.
pub fn triangle_shear(x: [[f64; 2]; 3], u: [[f64; 2]; 3]) -> f64 {
    let (Some(gu), Some(gv)) = (gradient(x, u.map(|v| v[0])), gradient(x, u.map(|v| v[1]))) else {
        return 0.0;
    };
    (gu[0] - gv[1]).hypot(gu[1] + gv[0])
}

/// Rotates a triangle's vertices so that the smallest global id comes first (orientation kept).
fn canonical(t: [u32; 3], gids: &[u64]) -> [u32; 3] {
    let k = (0..3).min_by_key(|&k| gids[t[k] as usize]).unwrap_or(0);
    [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
}

/// Indicator of every owned particle: the largest [`triangle_shear`] of the displacement
/// increment `du(p)` (local point p, owned or ghost) over the triangles around it; 0 for a
/// particle in no triangle.
pub fn shear_indicator(mesh: &LocalMesh, du: impl Fn(usize) -> [f64; 2]) -> Vec<f64> {
    let mut out = vec![0.0f64; mesh.n_owned];
    for t in &mesh.tris {
        let c = canonical(*t, &mesh.gids);
        let g = triangle_shear(
            c.map(|v| mesh.points[v as usize]),
            c.map(|v| du(v as usize)),
        );
        for &v in t {
            if (v as usize) < mesh.n_owned {
                out[v as usize] = out[v as usize].max(g);
            }
        }
    }
    out
}

/// Target spacing for an indicator `value` when the largest over the body is `largest` (> 0):
/// `h_min` at or above `refine_above` × largest, `h_max` at or below `coarsen_below` × largest,
/// geometric in between (log h linear in log value).
pub fn target_spacing(value: f64, largest: f64, a: &Adapt) -> f64 {
    let r = value / largest;
    if r >= a.refine_above {
        return a.h_min;
    }
    if r <= a.coarsen_below || !r.is_finite() {
        return a.h_max;
    }
    let s = (r / a.coarsen_below).ln() / (a.refine_above / a.coarsen_below).ln();
    let h = a.h_max * (a.h_min / a.h_max).powf(s);
    h.clamp(a.h_min, a.h_max)
}

/// One Jacobi sweep of the gradation limit: every owned particle's spacing becomes
/// min(its target, `grading` × the smallest spacing of its mesh neighbours), `h` holding the
/// current spacing of every local point (owned, then ghosts). Returns the new owned spacings and
/// whether any changed. Repeated, with the ghosts' values copied from their owners between
/// sweeps, it reaches the one fixed point min over j of target_j × grading^(edges from i to j),
/// whatever the order or the partition.
pub fn gradation_sweep(
    mesh: &LocalMesh,
    h: &[f64],
    target: &[f64],
    grading: f64,
) -> (Vec<f64>, bool) {
    let n = mesh.n_owned;
    let mut next: Vec<f64> = target.to_vec();
    for t in &mesh.tris {
        for k in 0..3 {
            let (p, q) = (t[k] as usize, t[(k + 1) % 3] as usize);
            for (a, b) in [(p, q), (q, p)] {
                if a < n {
                    next[a] = next[a].min(grading * h[b]);
                }
            }
        }
    }
    let changed = next.iter().zip(&h[..n]).any(|(x, y)| x != y);
    (next, changed)
}

/// How far one adaptation may move a particle's spacing: the graded target, but no less than
/// half and no more than twice the particle's spacing `old`, within `h_min`..`h_max`. The alpha
/// shape keeps a triangle only if its circumradius is at most alpha (1.3) × its vertices'
/// largest spacing, so a spacing far below the particles' actual distances opens holes in the
/// body; one round of splits (edges longer than 1.6 h) halves the distances, so the spacing
/// follows the target in halvings, one a step.
pub fn limit_rate(graded: f64, old: f64, a: &Adapt) -> f64 {
    graded.max(0.5 * old).min(2.0 * old).clamp(a.h_min, a.h_max)
}

/// Priority of a particle among close neighbours when coarsening (`refine::plan` with
/// `independent_merges`): a hash of its global id (splitmix64), ties by the id itself, so that
/// removals spread over a fine region instead of following the lattice's id order.
pub fn merge_priority(gid: u64) -> (u64, u64) {
    let mut z = gid.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    (z ^ (z >> 31), gid)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::schema::AdaptIndicator;

    fn params() -> Adapt {
        Adapt {
            indicator: AdaptIndicator::ShearStrainIncrement,
            h_min: 0.1,
            h_max: 0.8,
            refine_above: 0.1,
            coarsen_below: 0.01,
            grading: 1.5,
            every: 1,
        }
    }

    /// A jittered lattice, all owned (one rank), triangles in `order`.
    fn cloud(nx: usize, ny: usize, h: f64) -> LocalMesh {
        let mut pts = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let k = (j * nx + i) as f64;
                let d = [0.2 * h * (k * 1.7).sin(), 0.2 * h * (k * 2.3).cos()];
                pts.push([i as f64 * h + d[0], j as f64 * h + d[1]]);
            }
        }
        let n = pts.len();
        LocalMesh::build(
            pts,
            (0..n as u64).collect(),
            vec![0; n],
            vec![h; n],
            n,
            0,
            1.3,
            true,
        )
        .unwrap()
    }

    /// Runs the gradation sweeps to their fixed point on a one-rank mesh.
    fn graded(mesh: &LocalMesh, target: &[f64], grading: f64) -> Vec<f64> {
        let mut h = target.to_vec();
        for _ in 0..1000 {
            let (next, changed) = gradation_sweep(mesh, &h, target, grading);
            h = next;
            if !changed {
                return h;
            }
        }
        panic!("gradation did not settle");
    }

    #[test]
    fn shear_of_a_simple_shear_and_of_a_rigid_motion() {
        let x = [[0.0, 0.0], [1.0, 0.2], [0.3, 1.0]];
        // u = 0.01 y (simple shear): engineering shear 0.01.
        let u = x.map(|p| [0.01 * p[1], 0.0]);
        assert!((triangle_shear(x, u) - 0.01).abs() < 1e-15);
        // A small rigid rotation plus a translation: no shear.
        let r = x.map(|p| [0.3 - 1e-3 * p[1], -0.2 + 1e-3 * p[0]]);
        assert!(triangle_shear(x, r) < 1e-15);
        // A volume change alone (isotropic): none either.
        let v = x.map(|p| [1e-3 * p[0], 1e-3 * p[1]]);
        assert!(triangle_shear(x, v) < 1e-15);
    }

    #[test]
    fn target_is_bounded_and_monotone() {
        let a = params();
        let mut last = f64::INFINITY;
        for k in 0..=200 {
            let v = 10f64.powf(-4.0 + 4.0 * k as f64 / 200.0);
            let h = target_spacing(v, 1.0, &a);
            assert!((a.h_min..=a.h_max).contains(&h), "{v}: {h}");
            assert!(h <= last, "not monotone at {v}");
            last = h;
        }
        assert_eq!(target_spacing(0.5, 1.0, &a), a.h_min);
        assert_eq!(target_spacing(0.005, 1.0, &a), a.h_max);
        assert_eq!(target_spacing(0.0, 1.0, &a), a.h_max);
        // Halfway in log between the thresholds: halfway in log between the spacings.
        let mid = target_spacing(0.1f64.sqrt() * 0.1, 1.0, &a);
        assert!((mid - (a.h_min * a.h_max).sqrt()).abs() < 1e-12, "{mid}");
    }

    #[test]
    fn the_rate_limit_halves_or_doubles_at_most_and_keeps_the_bounds() {
        let a = params();
        assert_eq!(limit_rate(0.1, 0.8, &a), 0.4);
        assert_eq!(limit_rate(0.8, 0.1, &a), 0.2);
        assert_eq!(limit_rate(0.3, 0.4, &a), 0.3);
        // A particle of the initial lattice outside the bounds is brought into them.
        assert_eq!(limit_rate(0.8, 4.0, &a), 0.8);
        assert_eq!(limit_rate(0.1, 0.05, &a), 0.1);
    }

    #[test]
    fn gradation_bounds_neighbouring_spacings_and_keeps_the_fine_spot() {
        let m = cloud(16, 12, 0.25);
        let a = params();
        // One particle wants h_min, every other h_max.
        let target: Vec<f64> = (0..m.n_owned)
            .map(|p| if p == 100 { a.h_min } else { a.h_max })
            .collect();
        let h = graded(&m, &target, a.grading);
        assert_eq!(h[100], a.h_min);
        for t in &m.tris {
            for k in 0..3 {
                let (p, q) = (t[k] as usize, t[(k + 1) % 3] as usize);
                assert!(
                    h[p] <= a.grading * h[q] * (1.0 + 1e-15),
                    "{p}-{q}: {} {}",
                    h[p],
                    h[q]
                );
            }
        }
        assert!(h.iter().all(|&x| (a.h_min..=a.h_max).contains(&x)));
        // The limit only lowers targets, and far away they are untouched.
        assert!(h.iter().zip(&target).all(|(x, t)| x <= t));
        assert_eq!(h[0], a.h_max);
        // Without the limit the spot would be a jump of 8 to its neighbours: it must act.
        assert!(h.iter().filter(|&&x| x < a.h_max).count() > 9);
    }

    #[test]
    fn indicator_and_gradation_do_not_depend_on_the_triangle_order() {
        let m = cloud(12, 10, 0.25);
        let du = |p: usize| {
            let x = m.points[p];
            // A shear band along y = 1.2.
            [0.01 * (8.0 * (x[1] - 1.2)).tanh(), 0.002 * x[0]]
        };
        let ind = shear_indicator(&m, du);
        let mut shuffled = m.clone();
        // Reverse the triangle list and rotate every triangle's vertices.
        shuffled.tris.reverse();
        for t in &mut shuffled.tris {
            *t = [t[1], t[2], t[0]];
        }
        assert_eq!(ind, shear_indicator(&shuffled, du));
        let largest = ind.iter().copied().fold(0.0, f64::max);
        assert!(largest > 0.0);
        let a = params();
        let target: Vec<f64> = ind
            .iter()
            .map(|&v| target_spacing(v, largest, &a))
            .collect();
        assert!(target.contains(&a.h_min) && target.iter().any(|&h| h > a.h_min));
        assert_eq!(graded(&m, &target, 1.5), graded(&shuffled, &target, 1.5));
    }

    #[test]
    fn merge_priority_is_a_total_order_that_mixes_ids() {
        let p: Vec<_> = (0..64u64).map(merge_priority).collect();
        let rises = p.windows(2).filter(|w| w[1] > w[0]).count();
        assert!((16..48).contains(&rises), "{rises} of 63");
        let mut sorted = p.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), 64);
    }
}
