//! Supports and loads that conflict or leave the problem singular, checked on the generated
//! lattice before anything runs: a `[[prescribed]]` and a `[[fixed]]` on the same component of
//! a particle (one would silently win), a point load on constrained components only (it would
//! do nothing), and a part of the body that its supports do not hold against rigid-body motion
//! (its stiffness matrix is singular, and Newton fails with no useful message).

use super::field_path::FieldPath;
use super::schema::Scene;
use super::validate::Invalid;

fn fail<T>(path: FieldPath, message: String) -> Result<T, Invalid> {
    Err((path, message))
}

/// How selections match: the slack of `where`, and the named boundaries of `on`.
struct Sel {
    tol: f64,
    h: f64,
    boundaries: crate::geometry::NamedBoundaries,
}

impl Sel {
    fn on(&self, name: Option<&str>, x: [f64; 2]) -> bool {
        name.is_none_or(|n| crate::model::on_boundary(&self.boundaries, n, x, self.h))
    }
}

/// The `[[fixed]]` entry (index < fixed.len()) or `[[prescribed]]` entry constraining each
/// component of the particle at `x`, first entry first.
fn constrained_by(s: &Scene, x: [f64; 2], sel: &Sel) -> [Vec<FieldPath>; 2] {
    let tol = sel.tol;
    let mut by: [Vec<FieldPath>; 2] = Default::default();
    for (i, f) in s.fixed.iter().enumerate() {
        if f.region.matches(x, tol) && sel.on(f.on.as_deref(), x) {
            for d in &f.dofs {
                by[d.index()].push(FieldPath::key("fixed").at(i));
            }
        }
    }
    for (i, p) in s.prescribed.iter().enumerate() {
        if p.region.matches(x, tol) && sel.on(p.on.as_deref(), x) {
            for d in &p.dofs {
                by[d.index()].push(FieldPath::key("prescribed").at(i));
            }
        }
    }
    by
}

fn entry_text(s: &Scene, path: &FieldPath) -> String {
    let text = path.to_string();
    let region = if let Some(i) = text.strip_prefix("fixed[") {
        i.trim_end_matches(']')
            .parse::<usize>()
            .ok()
            .and_then(|i| s.fixed.get(i))
            .map(|f| f.region.to_string())
    } else {
        text.strip_prefix("prescribed[")
            .and_then(|i| i.trim_end_matches(']').parse::<usize>().ok())
            .and_then(|i| s.prescribed.get(i))
            .map(|p| p.region.to_string())
    };
    format!("{text} (where = \"{}\")", region.unwrap_or_default())
}

/// A component held by a `[[fixed]]` and a `[[prescribed]]` entry at once: the prescribed
/// motion would silently win over the clamp.
fn check_overlaps(s: &Scene, positions: &[[f64; 2]], sel: &Sel) -> Result<(), Invalid> {
    for &x in positions {
        for (d, by) in constrained_by(s, x, sel).iter().enumerate() {
            let fixed = by.iter().find(|p| p.to_string().starts_with("fixed"));
            let prescribed = by.iter().find(|p| p.to_string().starts_with("prescribed"));
            if let (Some(f), Some(p)) = (fixed, prescribed) {
                return fail(
                    p.join("where"),
                    format!(
                        "{} and {} both constrain {} of the particle at [{}, {}]: a particle's \
                         component is either fixed or prescribed; narrow one of the two `where`s",
                        entry_text(s, p),
                        entry_text(s, f),
                        ["x", "y"][d],
                        x[0],
                        x[1]
                    ),
                );
            }
        }
    }
    Ok(())
}

/// A point load whose non-zero components all act on constrained components does nothing.
fn check_point_loads(
    s: &Scene,
    positions: &[[f64; 2]],
    sel: &Sel,
    nearest: impl Fn([f64; 2]) -> Option<usize>,
) -> Result<(), Invalid> {
    for (i, load) in s.point_load.iter().enumerate() {
        let Some(p) = nearest(load.at) else { continue };
        let x = positions[p];
        let by = constrained_by(s, x, sel);
        let loaded: Vec<usize> = (0..2).filter(|&d| load.force[d] != 0.0).collect();
        if !loaded.is_empty() && loaded.iter().all(|&d| !by[d].is_empty()) {
            let holders: Vec<String> = loaded
                .iter()
                .map(|&d| format!("{} held by {}", ["x", "y"][d], entry_text(s, &by[d][0])))
                .collect();
            return fail(
                FieldPath::key("point_load").at(i).join("force"),
                format!(
                    "the load acts on constrained components only: its particle at [{}, {}] \
                     has {}, so the load would do nothing",
                    x[0],
                    x[1],
                    holders.join(" and ")
                ),
            );
        }
    }
    Ok(())
}

/// Groups of rectangles the mesh can join: overlapping, touching, or closer than the widest
/// gap the alpha shape bridges (2 alpha h). Returns the group of each rectangle.
fn rectangle_groups(s: &Scene) -> Vec<usize> {
    let rects = &s.body.rectangles;
    let reach = 2.0 * s.mesh.alpha * s.mesh.h;
    let mut group: Vec<usize> = (0..rects.len()).collect();
    fn root(group: &mut [usize], mut i: usize) -> usize {
        while group[i] != i {
            group[i] = group[group[i]];
            i = group[i];
        }
        i
    }
    for a in 0..rects.len() {
        for b in a + 1..rects.len() {
            let gap = (0..2)
                .map(|c| {
                    let (ra, rb) = (&rects[a], &rects[b]);
                    (ra.origin[c] - (rb.origin[c] + rb.size[c]))
                        .max(rb.origin[c] - (ra.origin[c] + ra.size[c]))
                        .max(0.0)
                })
                .fold(0.0_f64, |acc, g| acc.hypot(g));
            if gap <= reach * (1.0 + 1e-9) {
                let (ga, gb) = (root(&mut group, a), root(&mut group, b));
                group[ga.max(gb)] = ga.min(gb);
            }
        }
    }
    (0..rects.len()).map(|i| root(&mut group, i)).collect()
}

/// Every part of the body must be held against its three rigid-body motions (two translations
/// and a rotation) by its own supports: a constrained x at two heights, or a constrained y at
/// two abscissae, plus one constraint of the other component. Rigid bodies in contact do not
/// count: contact is found during the step, after the first Newton iteration needs a
/// non-singular matrix.
fn check_rigid_modes(s: &Scene, positions: &[[f64; 2]], sel: &Sel) -> Result<(), Invalid> {
    let tol = sel.tol;
    // A body of zones is held as one part.
    let zoned = s.body.rectangles.is_empty();
    let groups = if zoned { vec![0] } else { rectangle_groups(s) };
    let rects = &s.body.rectangles;
    let inside = |x: [f64; 2], r: usize| {
        zoned
            || (0..2).all(|c| {
                x[c] >= rects[r].origin[c] - tol
                    && x[c] <= rects[r].origin[c] + rects[r].size[c] + tol
            })
    };
    let n_groups = groups.iter().max().map_or(0, |g| g + 1);
    // Per group: the heights of x-constrained particles and the abscissae of y-constrained ones
    // (their extremes suffice to see two distinct values).
    let mut x_heights = vec![(f64::INFINITY, f64::NEG_INFINITY); n_groups];
    let mut y_abscissae = vec![(f64::INFINITY, f64::NEG_INFINITY); n_groups];
    for &x in positions {
        let Some(r) = (0..groups.len()).find(|&r| inside(x, r)) else {
            continue;
        };
        let g = groups[r];
        let by = constrained_by(s, x, sel);
        if !by[0].is_empty() {
            x_heights[g] = (x_heights[g].0.min(x[1]), x_heights[g].1.max(x[1]));
        }
        if !by[1].is_empty() {
            y_abscissae[g] = (y_abscissae[g].0.min(x[0]), y_abscissae[g].1.max(x[0]));
        }
    }
    for g in 0..n_groups {
        let first = groups.iter().position(|&h| h == g).unwrap_or(0);
        let (xs, ys) = (x_heights[g], y_abscissae[g]);
        let has = |r: (f64, f64)| r.0 <= r.1;
        let spread = |r: (f64, f64)| r.1 - r.0 > tol;
        // A body of revolution has one rigid mode, along the axis: a radial motion strains
        // its hoop, and the axis holds its particles radially.
        let free = if s.analysis.has_hoop() {
            (!has(ys)).then_some(
                "no [[fixed]] or [[prescribed]] entry holds its y: it can slide along the axis",
            )
        } else if !has(xs) && !has(ys) {
            Some("nothing holds it (no [[fixed]] or [[prescribed]] particle in it)")
        } else if !has(xs) {
            Some("no [[fixed]] or [[prescribed]] entry holds its x: it can slide sideways")
        } else if !has(ys) {
            Some("no [[fixed]] or [[prescribed]] entry holds its y: it can slide vertically")
        } else if !spread(xs) && !spread(ys) {
            Some(
                "its supports hold x and y at a single point only: it can rotate about it \
                 (hold x at two heights or y at two abscissae)",
            )
        } else {
            None
        };
        if let Some(why) = free {
            let part = if n_groups == 1 {
                "the body".to_string()
            } else {
                let members: Vec<String> = (0..rects.len())
                    .filter(|&r| groups[r] == g)
                    .map(|r| format!("body.rectangles[{r}]"))
                    .collect();
                format!(
                    "the part of the body made of {} (apart from the rest by more than 2 \
                     mesh.alpha mesh.h, so the mesh does not join them)",
                    members.join(", ")
                )
            };
            let at = if zoned {
                FieldPath::key("body").join("zones")
            } else {
                FieldPath::key("body").join("rectangles").at(first)
            };
            return fail(
                at,
                format!(
                    "{part} is not held against rigid-body motion: {why}; its stiffness \
                     matrix would be singular. Add [[fixed]] or [[prescribed]] supports to it"
                ),
            );
        }
    }
    Ok(())
}

/// All the checks of this module, on the particles of the generated lattice.
pub(super) fn check(
    s: &Scene,
    positions: &[[f64; 2]],
    tol: f64,
    nearest: impl Fn([f64; 2]) -> Option<usize>,
) -> Result<(), Invalid> {
    let sel = Sel {
        tol,
        h: s.mesh.h,
        boundaries: crate::model::named_boundaries(s),
    };
    check_overlaps(s, positions, &sel)?;
    check_point_loads(s, positions, &sel, nearest)?;
    check_rigid_modes(s, positions, &sel)
}
