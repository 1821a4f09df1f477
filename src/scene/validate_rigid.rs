//! Checks of the rigid-body, contact, load and history tables (see `rigid.rs`).

use std::collections::HashSet;

use super::field_path::FieldPath;
use super::rigid::Measure;
use super::schema::Scene;
use super::validate::Invalid;
use crate::rigid::shape::Shape;

fn fail<T>(path: FieldPath, message: String) -> Result<T, Invalid> {
    Err((path, message))
}

/// The longest stage total of the rigid bodies (0 without stages).
pub fn stage_total(s: &Scene) -> u64 {
    s.rigid.iter().map(|r| r.stage_steps()).max().unwrap_or(0)
}

/// The stages of every body, checked before the step count is taken from them: each stage
/// moves somewhere finite in at least one step, their total fits the step counter, and a scene
/// that leaves `steps.count` out has a stage to take it from. `count_given`: `steps.count` was
/// in the scene (0 means left out). Returns the step count the scene runs.
pub fn check_stages(s: &Scene, count_given: bool) -> Result<u32, Invalid> {
    for (i, r) in s.rigid.iter().enumerate() {
        let path = FieldPath::key("rigid").at(i).join("stages");
        for (k, st) in r.stages.iter().enumerate() {
            let sp = path.at(k);
            if !st.to.iter().all(|x| x.is_finite()) {
                return fail(sp.join("to"), format!("must be finite (got {:?})", st.to));
            }
            if st.steps < 1 {
                return fail(sp.join("steps"), "must be >= 1 (got 0)".to_string());
            }
        }
        if r.stage_steps() > u32::MAX as u64 {
            return fail(
                path,
                format!(
                    "take {} steps together, more than the largest step count {}",
                    r.stage_steps(),
                    u32::MAX
                ),
            );
        }
    }
    if count_given {
        return Ok(s.steps.count);
    }
    match s.rigid.iter().position(|r| r.stages.is_empty()) {
        Some(i) if stage_total(s) == 0 => fail(
            FieldPath::key("rigid").at(i).join("stages"),
            "is empty and steps.count is left out: give the body a stage, e.g. `stages = [{ to \
             = [0.0, -0.01], steps = 10 }]`, or set steps.count"
                .to_string(),
        ),
        _ => Ok(stage_total(s) as u32),
    }
}

/// The shape of `[[rigid]]` entry `i` at its initial position.
pub fn shape_of(s: &Scene, i: usize) -> Result<Shape, Invalid> {
    let r = &s.rigid[i];
    let path = FieldPath::key("rigid").at(i);
    match (&r.circle, &r.polygon) {
        (Some(c), None) => Shape::circle(c.centre, c.radius).map_err(|e| (path.join("circle"), e)),
        (None, Some(p)) => {
            Shape::polygon(&p.vertices, p.corner_radius).map_err(|e| (path.join("polygon"), e))
        }
        _ => fail(
            path,
            "needs exactly one shape: `circle = { centre, radius }` or `polygon = { vertices, \
             corner_radius }`"
                .to_string(),
        ),
    }
}

/// A body wished in place is lined with particles at the cloud's spacing (at most `mesh.h`, at
/// least the finest `[[mesh.fine]]` spacing): its perimeter must stay within the particle limit
/// (a radius of 1e308 made the lining's spacing NaN, and a large finite one exhausts memory).
fn check_lining(s: &Scene, i: usize, shape: &Shape) -> Result<(), Invalid> {
    let core = shape.core();
    let edges: f64 = if core.len() > 1 {
        (0..core.len())
            .map(|k| {
                let (a, b) = (core[k], core[(k + 1) % core.len()]);
                (b[0] - a[0]).hypot(b[1] - a[1])
            })
            .sum()
    } else {
        0.0
    };
    let perimeter = edges + 2.0 * std::f64::consts::PI * shape.radius();
    let finest = s.mesh.fine.iter().map(|f| f.h).fold(s.mesh.h, f64::min);
    let points = perimeter / finest;
    if points.is_finite() && points <= super::validate::MAX_PARTICLES as f64 {
        return Ok(());
    }
    let path = FieldPath::key("rigid").at(i);
    let path = if s.rigid[i].circle.is_some() {
        path.join("circle").join("radius")
    } else {
        path.join("polygon")
    };
    fail(
        path,
        format!(
            "the body's perimeter ({perimeter:.3e} m) would take {points:.3e} lining particles at \
             the spacing {finest}, more than the limit of {} ({})",
            super::validate::MAX_PARTICLES,
            super::validate::LIMIT_REASON
        ),
    )
}

/// Bounds of `[contact]`, measured on issue 32's pipe (tests/scenes/pipe-on-ground.toml, 2
/// ranks): every penalty from 0.1 to 1e7 gave fy = 4 055.05 N/m, 1e8 gave 4 030 (fx of the
/// wrong sign) and 0.1 took 72 s against the default's 4 s; a tolerance of 1e-9 settled, 1e-12 did
/// not (the pressures stalled at 2.5e-9 relative), 0.01 gave 4 055.7 and 0.5 gave 5 730; one
/// solve can never confirm a pressure.
const PENALTY: (f64, f64) = (1.0, 1e7);
const TOLERANCE: (f64, f64) = (1e-9, 1e-2);

/// Largest `ambient_pressure` as a multiple of `material.young`. Measured on the base pipe
/// (E = 1 MPa): the force is the same from 1e5 to 1e12 Pa, and from 1e15 Pa a node held by
/// suction away from the body takes more augmentations to let go than any step allows.
const AMBIENT_PER_YOUNG: f64 = 1e3;

fn check_contact(s: &Scene) -> Result<(), Invalid> {
    let c = FieldPath::key("contact");
    let penalty = s.contact.penalty;
    if !(PENALTY.0..=PENALTY.1).contains(&penalty) {
        return fail(
            c.join("penalty"),
            format!(
                "must be from {:e} to {:e} (got {penalty:e}; default 1): the constant that weighs \
                 a contact node's pressure against its gap while Newton decides whether it \
                 touches; far above 1, sticking nodes flip between slipping either way",
                PENALTY.0, PENALTY.1
            ),
        );
    }
    let tolerance = s.contact.tolerance;
    if !(TOLERANCE.0..=TOLERANCE.1).contains(&tolerance) {
        return fail(
            c.join("tolerance"),
            format!(
                "must be from {:e} to {} (got {tolerance:e}; default 1e-6): below, round-off \
                 keeps the pressures from settling; above, the force is off (by 41 % at 0.5)",
                TOLERANCE.0, TOLERANCE.1
            ),
        );
    }
    Ok(())
}

pub fn check(s: &Scene) -> Result<(), Invalid> {
    let mut names = HashSet::new();
    for (i, r) in s.rigid.iter().enumerate() {
        let path = FieldPath::key("rigid").at(i);
        if r.name.trim().is_empty() || r.name.contains('.') {
            return fail(
                path.join("name"),
                format!("must be a non-empty name without dots (got {:?})", r.name),
            );
        }
        if !names.insert(r.name.clone()) {
            return fail(path.join("name"), format!("\"{}\" is used twice", r.name));
        }
        check_lining(s, i, &shape_of(s, i)?)?;
        if !(0.0..=1.0).contains(&r.adhesion) {
            return fail(
                path.join("adhesion"),
                format!("must be in [0, 1] (got {})", r.adhesion),
            );
        }
        let most = AMBIENT_PER_YOUNG * s.material.young;
        if !(r.ambient_pressure >= 0.0 && r.ambient_pressure <= most) {
            return fail(
                path.join("ambient_pressure"),
                format!(
                    "must be from 0 to {AMBIENT_PER_YOUNG} material.young = {most:e} Pa (got {:e}): \
                     a soil under a larger pressure than that is no soil, and the interface \
                     could not let go of the soil it holds",
                    r.ambient_pressure
                ),
            );
        }
        if r.adhesion > 0.0 && !s.material.model.undrained() {
            return fail(
                path.join("adhesion"),
                "limits the interface shear to adhesion * material.cu, which needs model = \
                 \"tresca\" or \"tresca-softening\""
                    .to_string(),
            );
        }
    }
    check_contact(s)?;
    for (i, p) in s.surface_pressure.iter().enumerate() {
        if !p.pressure.is_finite() {
            return fail(
                FieldPath::key("surface_pressure").at(i).join("pressure"),
                format!("must be finite (got {})", p.pressure),
            );
        }
    }
    if let Some(g) = &s.geostatic {
        let path = FieldPath::key("geostatic");
        if !g.surface.is_finite() {
            return fail(
                path.join("surface"),
                format!("must be finite (got {})", g.surface),
            );
        }
        if !(g.surcharge >= 0.0 && g.surcharge.is_finite()) {
            return fail(
                path.join("surcharge"),
                format!("must be >= 0 (got {})", g.surcharge),
            );
        }
        if !(g.k0 > 0.0 && g.k0.is_finite()) {
            return fail(path.join("k0"), format!("must be > 0 (got {})", g.k0));
        }
    }
    let mut probes = HashSet::new();
    for (i, p) in s.probe.iter().enumerate() {
        let path = FieldPath::key("probe").at(i);
        if p.name.trim().is_empty() || p.name.contains('.') || !probes.insert(p.name.clone()) {
            return fail(
                path.join("name"),
                format!("must be a unique name without dots (got {:?})", p.name),
            );
        }
        if !p.at.iter().all(|x| x.is_finite()) {
            return fail(path.join("at"), format!("must be finite (got {:?})", p.at));
        }
    }
    let total = stage_total(s);
    let count = FieldPath::key("steps").join("count");
    if total > 0 && s.steps.count as u64 != total {
        return fail(
            count,
            format!(
                "is {} but the [[rigid]] stages take {total} steps; leave it out or make them \
                 agree",
                s.steps.count
            ),
        );
    }
    check_history(s)
}

fn check_history(s: &Scene) -> Result<(), Invalid> {
    let h = FieldPath::key("history");
    if s.history.kind.is_none() && s.history.columns.is_empty() {
        return fail(
            h,
            "needs `kind` or at least one [[history.columns]] entry".to_string(),
        );
    }
    let set_names: Vec<&String> = s
        .fixed
        .iter()
        .filter_map(|f| f.name.as_ref())
        .chain(s.prescribed.iter().filter_map(|p| p.name.as_ref()))
        .collect();
    let mut seen: HashSet<String> = match s.history.kind {
        Some(k) => crate::history::columns(k)
            .iter()
            .map(|c| c.to_string())
            .collect(),
        None => ["step".to_string()].into(),
    };
    for (i, c) in s.history.columns.iter().enumerate() {
        let path = h.join("columns").at(i);
        let bad_name = c.name.is_empty()
            || !c
                .name
                .chars()
                .all(|ch| ch.is_ascii_alphanumeric() || ch == '_');
        if bad_name || !seen.insert(c.name.clone()) {
            return fail(
                path.join("name"),
                format!(
                    "must be a unique column name of letters, digits and _ (got {:?})",
                    c.name
                ),
            );
        }
        if !c.scale.is_finite() {
            return fail(
                path.join("scale"),
                format!("must be finite (got {})", c.scale),
            );
        }
        let m = Measure::parse(&c.measure).map_err(|e| (path.join("measure"), e))?;
        let known = match &m {
            Measure::Probe(n, _) => s.probe.iter().any(|p| &p.name == n),
            Measure::RigidDisplacement(n, _) => s.rigid.iter().any(|r| &r.name == n),
            Measure::RigidForce(names, _) => {
                names.iter().all(|n| s.rigid.iter().any(|r| &r.name == n))
            }
            Measure::Reaction(n, _) => set_names.contains(&n),
            _ => true,
        };
        if !known {
            return fail(
                path.join("measure"),
                format!(
                    "\"{}\" names no [[probe]], [[rigid]] or named [[fixed]]/[[prescribed]] entry",
                    c.measure
                ),
            );
        }
    }
    let mut sets = HashSet::new();
    for n in set_names {
        if !sets.insert(n) {
            return fail(
                h,
                format!("the [[fixed]]/[[prescribed]] name \"{n}\" is used twice"),
            );
        }
    }
    Ok(())
}
