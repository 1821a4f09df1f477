//! Mesh-quality control of the method's Fig. 4, as local decisions that every rank takes
//! identically: they read only the rank-local mesh around owned particles (equal to the global
//! mesh there) and break ties by global id. Applying them (new ids, moving state) is the driver's.

use super::adapt::merge_priority;
use super::LocalMesh;
use std::collections::BTreeSet;

/// Thresholds in units of the local spacing h.
#[derive(Debug, Clone, Copy)]
pub struct RefineParams {
    /// Split an edge longer than this (a lattice diagonal is sqrt(2) = 1.41).
    pub split_length: f64,
    /// Remove a particle closer than this to a neighbour with a smaller global id.
    pub merge_distance: f64,
    /// Move interior particles to the centroid of their neighbours...
    pub smooth: bool,
    /// ...when a triangle around them has an angle below this (radians): smoothing repairs bad
    /// triangles and leaves a good cloud (a lattice) alone.
    pub smooth_below_angle: f64,
    /// An interior particle closer than the merge distance to others goes only if it outranks
    /// every close neighbour (`adapt::merge_priority`), instead of whenever one of them has a
    /// smaller id: the removed particles are never neighbours, so a region whose spacing grows
    /// past 2.5 times its particles' distance (`[mesh.adapt]` coarsening) thins out over a few
    /// steps instead of losing all but one particle at once.
    pub independent_merges: bool,
}

impl Default for RefineParams {
    fn default() -> Self {
        RefineParams {
            split_length: 1.6,
            merge_distance: 0.4,
            smooth: false,
            smooth_below_angle: 25f64.to_radians(),
            independent_merges: false,
        }
    }
}

/// What to change, in local indices of `mesh.points`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Plan {
    /// Edges (smaller-gid endpoint owned here) that get a particle at their midpoint.
    pub split: Vec<[u32; 2]>,
    /// Owned particles to remove.
    pub remove: Vec<u32>,
    /// Owned interior particles and their smoothed positions.
    pub smooth: Vec<(u32, [f64; 2])>,
}

impl Plan {
    pub fn is_empty(&self) -> bool {
        self.split.is_empty() && self.remove.is_empty() && self.smooth.is_empty()
    }
}

/// How far (in its spacing) the outline may move where a held particle away from a body merges
/// into a neighbour on its support.
const MAX_OUTLINE_SHIFT: f64 = 0.1;

/// Distance from `p` to the segment from `a` to `c`.
fn off_segment(p: [f64; 2], a: [f64; 2], c: [f64; 2]) -> f64 {
    let ac = [c[0] - a[0], c[1] - a[1]];
    let ap = [p[0] - a[0], p[1] - a[1]];
    let len2 = ac[0] * ac[0] + ac[1] * ac[1];
    let t = if len2 > 0.0 {
        ((ap[0] * ac[0] + ap[1] * ac[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (ap[0] - t * ac[0]).hypot(ap[1] - t * ac[1])
}

/// Plans refinement of `mesh` (`h[p]` is the spacing of local point p). `protected(p)` marks
/// owned particles that must neither move nor vanish (tracked or constrained ones), with one
/// exception: `support_gap(p)` is the distance to the nearest rigid body of a local point (owned
/// or ghost) held by a sliding support (constrained in one direction only: a symmetry plane),
/// `None` for any other. Where a symmetry plane meets a body (the soil under a T-bar's tip), the
/// stagnating flow drives the plane's particles into the body and would pile them up without
/// bound, so such a particle goes when a neighbour on the same support, nearer the body, is
/// closer than the merge distance; farther than that from the body, only where the outline stays
/// (the flow ahead of the body compresses the plane there too). Other boundary particles
/// never move and vanish only where `slides(p)`: on a rigid body's face, where the soil flows
/// along the body and converging flow would otherwise pile particles up without bound.
pub fn plan(
    mesh: &LocalMesh,
    protected: impl Fn(usize) -> bool,
    slides: impl Fn(usize) -> bool,
    support_gap: impl Fn(usize) -> Option<f64>,
    params: &RefineParams,
) -> Plan {
    let n = mesh.n_owned;
    let h = &mesh.h;
    let mut edges: BTreeSet<(u64, u64, u32, u32)> = BTreeSet::new();
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
    for t in &mesh.tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (ga, gb) = (mesh.gids[a as usize], mesh.gids[b as usize]);
            let (lo, hi) = if ga < gb { (a, b) } else { (b, a) };
            if (lo as usize) < n {
                edges.insert((ga.min(gb), ga.max(gb), lo, hi));
            }
            for (p, q) in [(a, b), (b, a)] {
                if (p as usize) < n {
                    neighbours[p as usize].push(q);
                }
            }
        }
    }
    let dist = |a: u32, b: u32| {
        let (p, q) = (mesh.points[a as usize], mesh.points[b as usize]);
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
    };
    // The coarser end's spacing: edges between a fine and a coarse lattice are not "too long".
    let spacing = |a: u32, b: u32| h[a as usize].max(h[b as usize]);
    let split: Vec<[u32; 2]> = edges
        .iter()
        .filter(|&&(_, _, a, b)| dist(a, b) > params.split_length * spacing(a, b))
        .map(|&(_, _, a, b)| [a, b])
        .collect();
    let mut worst_angle = vec![std::f64::consts::PI; n];
    if params.smooth {
        for t in &mesh.tris {
            let a = min_angle(t.map(|v| mesh.points[v as usize]));
            for &v in t {
                if (v as usize) < n {
                    worst_angle[v as usize] = worst_angle[v as usize].min(a);
                }
            }
        }
    }
    let mut along: Vec<Vec<u32>> = vec![Vec::new(); n];
    for e in &mesh.boundary_edges {
        for (p, q) in [(e[0], e[1]), (e[1], e[0])] {
            if (p as usize) < n {
                along[p as usize].push(q);
            }
        }
    }
    let mut remove = Vec::new();
    let mut smooth = Vec::new();
    for (p, nb) in neighbours.iter_mut().enumerate() {
        nb.sort_unstable();
        nb.dedup();
        let pu = p as u32;
        if nb.is_empty() {
            continue;
        }
        if protected(p) {
            // Only a boundary particle between two boundary neighbours is asked for its gap
            // (a closest-point query per body): most protected particles are not.
            if let [a, c] = &along[p][..] {
                let Some(gap) = support_gap(p) else {
                    continue;
                };
                // Of two crowded neighbours on the support the one farther from the body goes
                // (the larger id on a tie), near the body or not: the flow ahead of a body
                // compresses the plane's particles beyond the merge distance from it too, and
                // held ones never merge otherwise (the softening T-bar's 7th stroke: eight
                // held particles within 8 mm below the bar, two 3.7e-6 m apart, and the sliver
                // between them stopped Newton). Away from the body only where the edge
                // that replaces its two stays on the outline: a corner of the body (the top of
                // a symmetry plane) keeps its shape.
                let before = |q: u32| {
                    support_gap(q as usize).is_some_and(|g| {
                        g < gap || g == gap && mesh.gids[q as usize] < mesh.gids[p]
                    })
                };
                let crowded = [*a, *c]
                    .iter()
                    .any(|&q| dist(pu, q) < params.merge_distance * spacing(pu, q) && before(q));
                let on_outline = || {
                    off_segment(
                        mesh.points[p],
                        mesh.points[*a as usize],
                        mesh.points[*c as usize],
                    ) < MAX_OUTLINE_SHIFT * h[p]
                };
                if crowded
                    && (gap < params.merge_distance * h[p] || on_outline())
                    && dist(*a, *c) < params.split_length * spacing(*a, *c)
                {
                    remove.push(pu);
                }
            }
            continue;
        }
        if mesh.on_boundary[p] {
            // Only a particle between exactly two boundary neighbours, close to the one with
            // the smaller id, and whose neighbours stay closer than the split length: the
            // boundary edge that replaces its two is neither split again nor a shortcut across
            // a corner.
            // A neighbour held on a symmetry plane near a body cannot give way, so a particle
            // sliding into it goes whatever the ids: at a stagnation point on the plane (the
            // top of a T-bar, where the soil closes behind it) the pair would otherwise close
            // to a sliver that Newton's iterates invert.
            if let [a, c] = along[p][..] {
                // The distance first: `support_gap` is a boundary-condition and closest-point
                // query, asked only of a neighbour that is already too close.
                let close = [a, c].iter().any(|&q| {
                    dist(pu, q) < params.merge_distance * spacing(pu, q)
                        && (mesh.gids[q as usize] < mesh.gids[p]
                            || support_gap(q as usize).is_some())
                });
                if close && slides(p) && dist(a, c) < params.split_length * spacing(a, c) {
                    remove.push(pu);
                }
            }
            continue;
        }
        let near = |q: u32| dist(pu, q) < params.merge_distance * spacing(pu, q);
        let close = if params.independent_merges {
            let rank = |q: usize| merge_priority(mesh.gids[q]);
            nb.iter().any(|&q| near(q))
                && nb.iter().all(|&q| !near(q) || rank(q as usize) < rank(p))
        } else {
            nb.iter()
                .any(|&q| mesh.gids[q as usize] < mesh.gids[p] && near(q))
        };
        if close {
            remove.push(pu);
        } else if params.smooth
            && !mesh.on_boundary[p]
            && worst_angle[p] < params.smooth_below_angle
        {
            let mut c = [0.0; 2];
            for &q in nb.iter() {
                c[0] += mesh.points[q as usize][0];
                c[1] += mesh.points[q as usize][1];
            }
            let k = nb.len() as f64;
            let target = [c[0] / k, c[1] / k];
            if dist_to(mesh.points[p], target) > 1e-3 * h[p] {
                smooth.push((pu, target));
            }
        }
    }
    Plan {
        split,
        remove,
        smooth,
    }
}

/// Boundary edges (smaller-gid end owned here) whose midpoint lies deeper than
/// `max_depth` × spacing inside a rigid body: `depth(x)` is how far `x` lies inside the nearest
/// body (<= 0 outside). Such a chord stands for soil that wraps round a curved face it cannot
/// follow (the footing's rounded edge, of radius 1.6 spacings): as the soil flows round, the
/// chord lengthens and cuts ever deeper, the load it carries falls, and at the split length
/// (1.6 spacings) it jumped back by 0.6 % in one step, every 15 steps. Split where the chord
/// first cuts in, it follows the face in smaller, even steps. A chord of length L on a face of
/// radius R cuts in by L²/8R: on the default T-bar's and pipe's faces (R = 4 spacings) that
/// stays below 0.1 spacing up to the split length; on their coarse test meshes (R = 2
/// spacings) it splits chords longer than 1.26 spacings. Only chords longer than `min_length`
/// spacings are split: round a sharp corner every chord cuts in, and halves shorter than the
/// merge distance would be merged again at the next step.
pub fn deep_chords(
    mesh: &LocalMesh,
    depth: impl Fn([f64; 2]) -> f64,
    max_depth: f64,
    min_length: f64,
) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for &[a, b] in &mesh.boundary_edges {
        let (ga, gb) = (mesh.gids[a as usize], mesh.gids[b as usize]);
        let (lo, hi) = if ga < gb { (a, b) } else { (b, a) };
        if lo as usize >= mesh.n_owned {
            continue;
        }
        let (p, q) = (mesh.points[a as usize], mesh.points[b as usize]);
        let mid = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
        let h = mesh.h[a as usize].max(mesh.h[b as usize]);
        let long = (q[0] - p[0]).hypot(q[1] - p[1]) > min_length * h;
        if long && depth(mid) > max_depth * h {
            out.push([lo, hi]);
        }
    }
    out
}

/// Smallest interior angle of a triangle (radians).
pub fn min_angle(v: [[f64; 2]; 3]) -> f64 {
    let mut best = std::f64::consts::PI;
    for k in 0..3 {
        let (o, a, b) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
        let (u, w) = ([a[0] - o[0], a[1] - o[1]], [b[0] - o[0], b[1] - o[1]]);
        let cross = (u[0] * w[1] - u[1] * w[0]).abs();
        let dot = u[0] * w[0] + u[1] * w[1];
        best = best.min(cross.atan2(dot));
    }
    best
}

fn dist_to(p: [f64; 2], q: [f64; 2]) -> f64 {
    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(nx: usize, ny: usize, h: f64, jitter: impl Fn(usize) -> [f64; 2]) -> LocalMesh {
        let mut pts = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let d = jitter(j * nx + i);
                pts.push([i as f64 * h + d[0], j as f64 * h + d[1]]);
            }
        }
        let n = pts.len();
        let gids = (0..n as u64).collect();
        LocalMesh::build(pts, gids, vec![0; n], vec![h; n], n, 0, 1.3, true).unwrap()
    }

    #[test]
    fn regular_lattice_needs_nothing() {
        let m = lattice(6, 5, 0.5, |_| [0.0, 0.0]);
        let p = plan(&m, |_| false, |_| false, |_| None, &RefineParams::default());
        assert!(p.is_empty(), "{p:?}");
    }

    #[test]
    fn close_pair_loses_the_larger_id_and_long_edges_split() {
        // Particle 8 (interior) pushed next to particle 7.
        let m = lattice(
            5,
            5,
            1.0,
            |i| if i == 12 { [-0.7, 0.0] } else { [0.0, 0.0] },
        );
        let p = plan(&m, |_| false, |_| false, |_| None, &RefineParams::default());
        assert_eq!(p.remove, vec![12]);
        assert!(!p.split.is_empty(), "the gap left at x = 2 has long edges");
        for [a, b] in &p.split {
            assert!(m.gids[*a as usize] < m.gids[*b as usize]);
        }
    }

    #[test]
    fn independent_merges_thin_a_crowded_region_without_emptying_it() {
        // A lattice of spacing 1 whose spacing asks for 4: every interior particle is close to
        // its neighbours. The id rule removes every interior particle (each has a neighbour with a
        // smaller id).
        let mut m = lattice(8, 8, 1.0, |_| [0.0, 0.0]);
        m.h = vec![4.0; m.points.len()];
        let by_id = plan(&m, |_| false, |_| false, |_| None, &RefineParams::default());
        let interior = (0..m.n_owned).filter(|&p| !m.on_boundary[p]).count();
        assert_eq!(by_id.remove.len(), interior);
        let params = RefineParams {
            independent_merges: true,
            ..Default::default()
        };
        let spread = plan(&m, |_| false, |_| false, |_| None, &params);
        assert!(!spread.remove.is_empty());
        assert!(
            spread.remove.len() <= interior / 3,
            "{}",
            spread.remove.len()
        );
        // No two removed particles are neighbours.
        for t in &m.tris {
            let gone = t.iter().filter(|v| spread.remove.contains(v)).count();
            assert!(gone <= 1, "{t:?}");
        }
    }

    fn star_quality(m: &LocalMesh, p: u32, at: [f64; 2]) -> f64 {
        m.tris
            .iter()
            .filter(|t| t.contains(&p))
            .map(|t| min_angle(t.map(|v| if v == p { at } else { m.points[v as usize] })))
            .fold(std::f64::consts::PI, f64::min)
    }

    #[test]
    fn smoothing_repairs_bad_stars_and_leaves_a_lattice_alone() {
        let params = RefineParams {
            smooth: true,
            ..Default::default()
        };
        let lattice = lattice(6, 5, 0.5, |_| [0.0, 0.0]);
        assert!(plan(&lattice, |_| false, |_| false, |_| None, &params).is_empty());

        let m = lattice_with(12, [0.58, 0.0]);
        let p = plan(&m, |_| false, |_| false, |_| None, &params);
        assert!(p.smooth.iter().all(|(i, _)| !m.on_boundary[*i as usize]));
        let (_, target) = p
            .smooth
            .iter()
            .find(|(i, _)| *i == 12)
            .expect("12 is smoothed");
        let (before, after) = (
            star_quality(&m, 12, m.points[12]),
            star_quality(&m, 12, *target),
        );
        assert!(
            after > before,
            "smoothing must improve the worst angle: {before} -> {after}"
        );
        let none = plan(&m, |i| i == 12, |_| false, |_| None, &params);
        assert!(none.smooth.iter().all(|(i, _)| *i != 12));
    }

    #[test]
    fn boundary_particles_merge_only_where_they_slide() {
        // Bottom row: particle 2 crowds particle 1, particle 3 closes the gap it would leave.
        let m = lattice(5, 5, 1.0, |i| match i {
            2 => [-0.7, 0.0],
            3 => [-0.5, 0.0],
            _ => [0.0, 0.0],
        });
        assert!(m.on_boundary[2]);
        let params = RefineParams::default();
        assert!(plan(&m, |_| false, |_| false, |_| None, &params)
            .remove
            .is_empty());
        assert_eq!(
            plan(&m, |_| false, |_| true, |_| None, &params).remove,
            vec![2]
        );
        assert!(plan(&m, |i| i == 2, |_| true, |_| None, &params)
            .remove
            .is_empty());
        // Without particle 3 closing in, removing 2 would leave an edge to split at once.
        let gap = lattice_with(2, [-0.7, 0.0]);
        assert!(plan(&gap, |_| false, |_| true, |_| None, &params)
            .remove
            .is_empty());
    }

    #[test]
    fn a_particle_sliding_into_one_held_on_a_symmetry_plane_goes_whatever_the_ids() {
        // Bottom row: 3 has slid to 0.3 from 4, held on the plane x = 4 where it meets a body
        // (the stagnation point on a T-bar's top); 2 follows, closing the gap 3 would leave.
        let m = lattice(5, 5, 1.0, |i| match i {
            3 => [0.7, 0.0],
            2 => [0.5, 0.0],
            _ => [0.0, 0.0],
        });
        let on_plane = |p: usize| m.points[p][0] == 4.0;
        let params = RefineParams::default();
        let near_body = |p: usize| on_plane(p).then_some(0.0);
        assert_eq!(
            plan(&m, on_plane, |_| true, near_body, &params).remove,
            vec![3]
        );
        // Held but with no body near, the smaller id stays, as anywhere else.
        assert!(plan(&m, on_plane, |_| true, |_| None, &params)
            .remove
            .is_empty());
    }

    #[test]
    fn a_symmetry_plane_sheds_crowded_particles_the_one_farther_from_the_body_first() {
        // Left column x = 0 is a symmetry plane; a body's face is at y = 4 (particle 20 on it).
        // The flow has carried 15 up to 0.3 below it, and 10 after it.
        let m = lattice(5, 5, 1.0, |i| match i {
            15 => [0.0, 0.7],
            10 => [0.0, 0.5],
            _ => [0.0, 0.0],
        });
        let on_plane = |p: usize| m.points[p][0] == 0.0;
        let gap = |p: usize| on_plane(p).then(|| 4.0 - m.points[p][1]);
        let params = RefineParams::default();
        assert_eq!(plan(&m, on_plane, |_| false, gap, &params).remove, vec![15]);
        // Held in both directions (no sliding support), or with no body near: it stays.
        assert!(plan(&m, on_plane, |_| false, |_| None, &params)
            .remove
            .is_empty());
        // Far from the body the pair merges all the same (the flow ahead of a body compresses
        // the plane beyond the merge distance from it): the one farther from the body goes.
        let far = |p: usize| on_plane(p).then(|| 10.0 - m.points[p][1]);
        assert_eq!(plan(&m, on_plane, |_| false, far, &params).remove, vec![15]);
        // Equally far (a plane parallel to the body's face): the larger id would go, but not
        // the corner where the plane meets the free top (the outline would move 0.29).
        let level = |p: usize| on_plane(p).then_some(5.0);
        assert!(plan(&m, on_plane, |_| false, level, &params)
            .remove
            .is_empty());
        let low = lattice(5, 5, 1.0, |i| if i == 10 { [0.0, 0.7] } else { [0.0, 0.0] });
        let on_low = |p: usize| low.points[p][0] == 0.0;
        let level = |p: usize| on_low(p).then_some(5.0);
        assert_eq!(
            plan(&low, on_low, |_| false, level, &params).remove,
            vec![15]
        );
    }

    fn lattice_with(moved: usize, by: [f64; 2]) -> LocalMesh {
        lattice(5, 5, 1.0, |i| if i == moved { by } else { [0.0, 0.0] })
    }

    #[test]
    fn a_chord_cutting_deep_into_a_body_is_split_and_a_shallow_one_is_not() {
        // A disc whose face passes through the top-row particles (1, 2) and (2, 2): their chord
        // of length 1 cuts in by R - sqrt(R² - 1/4), 0.109 for R = 1.2 and 0.080 for R = 1.6.
        let m = lattice(5, 3, 1.0, |_| [0.0, 0.0]);
        let inside = |r: f64| {
            let centre = [1.5, 2.0 + (r * r - 0.25_f64).sqrt()];
            move |x: [f64; 2]| r - ((x[0] - centre[0]).powi(2) + (x[1] - centre[1]).powi(2)).sqrt()
        };
        let deep = deep_chords(&m, inside(1.2), 0.1, 0.9);
        assert_eq!(deep.len(), 1, "{deep:?}");
        let [p, q] = deep[0].map(|v| m.points[v as usize]);
        let mut xs = [p[0], q[0]];
        xs.sort_by(f64::total_cmp);
        assert_eq!((xs, p[1], q[1]), ([1.0, 2.0], 2.0, 2.0));
        assert!(deep_chords(&m, inside(1.6), 0.1, 0.9).is_empty());
        // Too short to split (a sharp corner).
        assert!(deep_chords(&m, inside(1.2), 0.1, 1.1).is_empty());
    }
}
