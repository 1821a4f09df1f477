//! What a case file must satisfy beyond its types and shapes: the scene rules of a new case,
//! and the invariants of the format. A damaged file (a flipped bit, an edit, a bug elsewhere)
//! must not run silently: every rule breaks with an error naming the dataset or attribute.
//!
//! The rules are split by what they need to see: [`check_header`] the root attributes,
//! [`check_particles`] one block of particles, [`check_gauss_block`] one block of `/gauss`
//! records, and the rules across the whole file (ids unique, every id a triangle or a point
//! load names is a particle, triangles counter-clockwise, keys unique) take the facts gathered
//! from all ranks. [`validate_case`] applies all of them to a case held in memory; the parallel
//! reader applies the same functions to what it gathers.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use super::error::{CaseError, CaseErrorKind};
use super::gauss::GaussRecords;
use super::particles::ParticleSet;
use super::CaseHeader;
use crate::particles::flag;
use crate::scene::Scene;

/// Particle flag bits a case file may hold.
pub const KNOWN_FLAGS: u32 = flag::TRACKED;
/// How far, in multiples of the scene's size, a particle may lie from the scene's body.
pub const REACH: f64 = 1e6;

fn bad(path: &Path, at: &str, message: String) -> CaseError {
    CaseError::new(path, CaseErrorKind::Malformed, message).at(at.to_string())
}

/// The scene (parsed and validated as for a new case) and the root attributes' own rules.
pub fn check_header(path: &Path, h: &CaseHeader, n: u64) -> Result<Scene, CaseError> {
    let scene = Scene::from_toml(&h.scene_toml, &path.display().to_string(), &[])
        .map_err(|e| bad(path, "attribute scene", e.to_string()))?;
    if h.step > scene.steps.count as u64 {
        return Err(bad(
            path,
            "attribute step",
            format!(
                "{} is beyond the scene's steps.count = {}",
                h.step, scene.steps.count
            ),
        ));
    }
    for (name, v) in [("load_factor", h.load_factor), ("time", h.time)] {
        if !v.is_finite() {
            return Err(bad(
                path,
                &format!("attribute {name}"),
                format!("{v} is not finite"),
            ));
        }
    }
    let wanted = scene.point_load.len() + scene.probe.len();
    if h.tracked_gids.len() != wanted {
        return Err(bad(
            path,
            "attribute tracked_gids",
            format!(
                "holds {} ids but the scene has {} point load(s) and {} probe(s), one id each",
                h.tracked_gids.len(),
                scene.point_load.len(),
                scene.probe.len()
            ),
        ));
    }
    if n > h.next_gid {
        return Err(bad(
            path,
            "attribute next_gid",
            format!("{} is less than the {n} particles", h.next_gid),
        ));
    }
    if !h.rank_counts.is_empty() {
        let sum: u64 = h.rank_counts.iter().fold(0, |a, &c| a.saturating_add(c));
        if sum != n || h.rank_counts.len() != h.ranks as usize {
            return Err(bad(
                path,
                "attribute rank_counts",
                format!(
                    "{} counts summing to {sum}, for {} ranks and {n} particles",
                    h.rank_counts.len(),
                    h.ranks
                ),
            ));
        }
    }
    Ok(scene)
}

/// The box no particle may leave: the scene's body grown by [`REACH`] times its size.
fn reach(scene: &Scene) -> [[f64; 2]; 2] {
    let [lo, hi] = scene.bounding_box();
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(0.0);
    let r = REACH * size;
    [[lo[0] - r, lo[1] - r], [hi[0] + r, hi[1] + r]]
}

/// Rules on one block of particles, rows `first..` of the file. Returns whether any particle
/// of the block is displaced (a step-0 case must not be).
pub fn check_particles(
    path: &Path,
    h: &CaseHeader,
    scene: &Scene,
    p: &ParticleSet,
    first: usize,
) -> Result<bool, CaseError> {
    p.check_lengths()
        .map_err(|m| bad(path, "group /particles", m))?;
    let [lo, hi] = reach(scene);
    let row = |i: usize| format!("row {} (gid {})", first + i, p.gid[i]);
    let mut displaced = false;
    for i in 0..p.len() {
        if p.gid[i] >= h.next_gid {
            return Err(bad(
                path,
                "dataset /particles/gid",
                format!("{}: not below next_gid = {}", row(i), h.next_gid),
            ));
        }
        let x = p.position[i];
        if !x.iter().all(|v| v.is_finite()) {
            return Err(bad(
                path,
                "dataset /particles/position",
                format!("{}: ({}, {}) is not finite", row(i), x[0], x[1]),
            ));
        }
        if x[0] < lo[0] || x[0] > hi[0] || x[1] < lo[1] || x[1] > hi[1] {
            return Err(bad(
                path,
                "dataset /particles/position",
                format!(
                    "{}: ({:e}, {:e}) lies more than {REACH:e} times the scene's size from \
                     its body",
                    row(i),
                    x[0],
                    x[1]
                ),
            ));
        }
        let vectors = [
            ("displacement", &p.displacement[i][..]),
            ("increment", &p.increment[i][..]),
            ("state", p.state.row(i)),
        ];
        for (name, v) in vectors {
            if let Some(k) = v.iter().position(|v| !v.is_finite()) {
                return Err(bad(
                    path,
                    &format!("dataset /particles/{name}"),
                    format!("{}: value {k} is {}", row(i), v[k]),
                ));
            }
        }
        displaced |= p.displacement[i] != [0.0, 0.0];
        let hi_ = p.h[i];
        if !(hi_.is_finite() && hi_ > 0.0) {
            return Err(bad(
                path,
                "dataset /particles/h",
                format!("{}: spacing {hi_} is not a positive number", row(i)),
            ));
        }
        if p.flags[i] & !KNOWN_FLAGS != 0 {
            return Err(bad(
                path,
                "dataset /particles/flags",
                format!(
                    "{}: unknown bits {:#x} (known: {KNOWN_FLAGS:#x})",
                    row(i),
                    p.flags[i] & !KNOWN_FLAGS
                ),
            ));
        }
        let materials = scene.material.all().len();
        if p.material[i] as usize >= materials {
            return Err(bad(
                path,
                "dataset /particles/material",
                format!(
                    "{}: material {} of a scene with {materials} material{}",
                    row(i),
                    p.material[i],
                    if materials == 1 { "" } else { "s" }
                ),
            ));
        }
    }
    Ok(displaced)
}

/// A case at step 0 is undeformed.
pub fn check_displaced(path: &Path, h: &CaseHeader, displaced: bool) -> Result<(), CaseError> {
    if h.step == 0 && displaced {
        return Err(bad(
            path,
            "attribute step",
            "0, but the particles are displaced: a deformed body's step was reset".to_string(),
        ));
    }
    Ok(())
}

/// Rules on one block of `/gauss` records on their own: keys with their smallest id first and
/// three distinct ids, finite Gauss states.
pub fn check_gauss_block(path: &Path, g: &GaussRecords, first: usize) -> Result<(), CaseError> {
    for (t, k) in g.key.iter().enumerate() {
        if !(k[0] < k[1] && k[0] < k[2] && k[1] != k[2]) {
            return Err(bad(
                path,
                "dataset /gauss/key",
                format!(
                    "row {}: {k:?} is not a triangle key (three ids, the smallest first)",
                    first + t
                ),
            ));
        }
        if let Some(s) = (t < g.state.len()).then(|| g.state.row(t)) {
            if let Some(i) = s.iter().position(|v| !v.is_finite()) {
                return Err(bad(
                    path,
                    "dataset /gauss/state",
                    format!("row {}: value {i} is {}", first + t, s[i]),
                ));
            }
        }
    }
    Ok(())
}

/// The first id of sorted `ids` that appears twice.
pub fn duplicate_id(path: &Path, sorted: &[u64]) -> Result<(), CaseError> {
    match sorted.windows(2).find(|w| w[0] == w[1]) {
        Some(w) => Err(bad(
            path,
            "dataset /particles/gid",
            format!("id {} is given to two particles", w[0]),
        )),
        None => Ok(()),
    }
}

/// The first key of sorted `keys` that appears twice.
pub fn duplicate_key(path: &Path, sorted: &[[u64; 3]]) -> Result<(), CaseError> {
    match sorted.windows(2).find(|w| w[0] == w[1]) {
        Some(w) => Err(bad(
            path,
            "dataset /gauss/key",
            format!("triangle {:?} is stored twice", w[0]),
        )),
        None => Ok(()),
    }
}

/// `tracked[k]` (point loads, then probes) names no particle.
pub fn missing_tracked(path: &Path, k: usize, gid: u64) -> CaseError {
    bad(
        path,
        "attribute tracked_gids",
        format!("entry {k}: gid {gid} names no particle"),
    )
}

/// A triangle's doubled area over its longest edge squared that still counts as flat.
const FLAT: f64 = 1e-10;

/// A triangle's vertex is no particle, or the triangle is not counter-clockwise at the stored
/// positions (`None` where a vertex is missing).
pub fn check_triangle(
    path: &Path,
    key: [u64; 3],
    at: [Option<[f64; 2]>; 3],
) -> Result<(), CaseError> {
    let mut x = [[0.0; 2]; 3];
    for (v, p) in at.iter().enumerate() {
        x[v] = p.ok_or_else(|| {
            bad(
                path,
                "dataset /gauss/key",
                format!("triangle {key:?}: vertex {} is no particle", key[v]),
            )
        })?;
    }
    let area2 =
        (x[1][0] - x[0][0]) * (x[2][1] - x[0][1]) - (x[1][1] - x[0][1]) * (x[2][0] - x[0][0]);
    // Flat is let through: a sliver flattened by the last increment is no damage, and refusing
    // it would make a sound checkpoint unusable. Flat to round-off counts: two particles put on
    // the axis at a body's apex by the last update lay 3e-16 m apart, and their triangle's
    // doubled area came out -1e-18 (the cone at D/8.6, step 390).
    let longest = (0..3)
        .map(|v| {
            let (p, q) = (x[v], x[(v + 1) % 3]);
            (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)
        })
        .fold(0.0, f64::max);
    if area2.is_nan() || area2 < -FLAT * longest {
        return Err(bad(
            path,
            "dataset /gauss/key",
            format!("triangle {key:?} is not counter-clockwise at the particles' positions"),
        ));
    }
    Ok(())
}

/// Every rule, on a whole case held in memory (one block of all particles and all `/gauss`
/// records); returns the scene. The reader applies the same rules, spread over its ranks.
pub fn validate_case(
    path: &Path,
    h: &CaseHeader,
    p: &ParticleSet,
    g: &GaussRecords,
) -> Result<Scene, CaseError> {
    let scene = check_header(path, h, p.len() as u64)?;
    let displaced = check_particles(path, h, &scene, p, 0)?;
    check_displaced(path, h, displaced)?;
    check_gauss_lengths(path, g)?;
    check_gauss_block(path, g, 0)?;
    let mut ids = p.gid.clone();
    ids.sort_unstable();
    duplicate_id(path, &ids)?;
    let at: HashMap<u64, [f64; 2]> = p
        .gid
        .iter()
        .copied()
        .zip(p.position.iter().copied())
        .collect();
    for (k, gid) in h.tracked_gids.iter().enumerate() {
        if !at.contains_key(gid) {
            return Err(missing_tracked(path, k, *gid));
        }
    }
    let mut seen = HashSet::new();
    for key in &g.key {
        check_triangle(path, *key, key.map(|v| at.get(&v).copied()))?;
        if !seen.insert(*key) {
            return Err(duplicate_key(path, &[*key, *key]).unwrap_err());
        }
    }
    Ok(scene)
}

/// `/gauss` arrays of one length (the reader's shapes make them so; an in-memory case may not).
pub fn check_gauss_lengths(path: &Path, g: &GaussRecords) -> Result<(), CaseError> {
    let m = g.key.len();
    for (name, len) in [
        ("state", g.state.len()),
        ("nodes", g.nodes.len()),
        ("contact", g.contact.len()),
    ] {
        if len != m {
            return Err(bad(
                path,
                &format!("dataset /gauss/{name}"),
                format!("has {len} rows but /gauss/key has {m}"),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangles_must_be_counter_clockwise_flat_ones_pass() {
        let p = Path::new("c.h5");
        let (a, b, c) = ([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]);
        assert!(check_triangle(p, [1, 2, 3], [Some(a), Some(b), Some(c)]).is_ok());
        let e = check_triangle(p, [1, 3, 2], [Some(a), Some(c), Some(b)]).unwrap_err();
        assert!(e.to_string().contains("not counter-clockwise"), "{e}");
        assert!(check_triangle(p, [1, 2, 3], [Some(a), Some(b), Some([2.0, 0.0])]).is_ok());
        let e = check_triangle(p, [1, 2, 3], [Some(a), None, Some(c)]).unwrap_err();
        assert!(e.to_string().contains("vertex 2 is no particle"), "{e}");
        let nan = [f64::NAN, 0.0];
        assert!(check_triangle(p, [1, 2, 3], [Some(a), Some(b), Some(nan)]).is_err());
        // Two vertices a round-off apart (as put on the axis at an apex): flat, let through;
        // a sliver inverted by a thousandth of its side is not.
        let (u, v, w) = (
            [0.0031049186515673373, 0.6611419075734871],
            [0.0, 0.6612699999999998],
            [0.0, 0.6612700000000001],
        );
        assert!(check_triangle(p, [1, 2, 3], [Some(u), Some(v), Some(w)]).is_ok());
        assert!(check_triangle(p, [1, 3, 2], [Some(u), Some(w), Some(v)]).is_ok());
        let e = check_triangle(p, [1, 2, 3], [Some(a), Some(b), Some([0.5, -1e-3])]).unwrap_err();
        assert!(e.to_string().contains("not counter-clockwise"), "{e}");
    }
}
