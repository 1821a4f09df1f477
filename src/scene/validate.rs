//! Physical and geometric sanity of a deserialized scene. Each failure names the field at fault
//! and the offending value, so that a user can fix the scene file without reading code.

use std::collections::HashSet;

use super::field_path::FieldPath;
use super::lattice::{self, generate_particles};
use super::schema::{Dof, HistoryKind, Material, MaterialModel, Scene, Selection};
use super::selector::{Axis, Selector};

/// Upper bound on the initial particle count, so that a mistyped `mesh.h` is reported instead
/// of exhausting memory or disk: `new` builds the whole lattice in one process, and a particle
/// takes 140 bytes in memory and in the case file (`gid`, `position`, `displacement`,
/// `increment`, `h`, 9 state values, `flags`), so the limit is a 7 GB case file.
pub const MAX_PARTICLES: u64 = 50_000_000;
/// Why [`MAX_PARTICLES`] is what it is, for the error message.
pub const LIMIT_REASON: &str =
    "140 bytes a particle: a 7 GB case file, built in one process by `pfem-mpi new`";
/// Largest `mesh.alpha`: the alpha shape keeps triangles of circumradius up to alpha * h, so it
/// joins boundaries up to 2 alpha h apart; beyond 2 it bridges gaps of 4 h and fills concave
/// corners, which stiffens the body (PFEM practice is 1.2 to 1.5).
pub const MAX_ALPHA: f64 = 2.0;

pub type Invalid = (FieldPath, String);

fn fail<T>(path: FieldPath, message: String) -> Result<T, Invalid> {
    Err((path, message))
}

fn vec2(v: [f64; 2]) -> String {
    format!("[{}, {}]", v[0], v[1])
}

fn finite2(path: FieldPath, v: [f64; 2]) -> Result<(), Invalid> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        fail(path, format!("must be finite (got {})", vec2(v)))
    }
}

fn positive(path: FieldPath, x: f64) -> Result<(), Invalid> {
    if x > 0.0 && x.is_finite() {
        Ok(())
    } else {
        fail(path, format!("must be > 0 (got {x})"))
    }
}

fn non_negative(path: FieldPath, x: f64) -> Result<(), Invalid> {
    if x >= 0.0 && x.is_finite() {
        Ok(())
    } else {
        fail(path, format!("must be >= 0 (got {x})"))
    }
}

fn dofs(path: FieldPath, dofs: &[Dof]) -> Result<(), Invalid> {
    if dofs.is_empty() {
        return fail(path, "must list at least one of \"x\", \"y\"".to_string());
    }
    let mut seen = HashSet::new();
    for d in dofs {
        if !seen.insert(d) {
            return fail(path, format!("lists \"{}\" twice", d.as_str()));
        }
    }
    Ok(())
}

/// `[mesh.adapt]`: spacings, fractions and grading in range, and refinement on to act on them.
fn check_adapt(s: &Scene, a: &super::schema::Adapt) -> Result<(), Invalid> {
    let at = FieldPath::key("mesh").join("adapt");
    positive(at.join("h_min"), a.h_min)?;
    positive(at.join("h_max"), a.h_max)?;
    if a.h_max <= a.h_min {
        return fail(
            at.join("h_max"),
            format!("must be larger than h_min = {} (got {})", a.h_min, a.h_max),
        );
    }
    let fraction = |x: f64| x > 0.0 && x <= 1.0;
    if !fraction(a.refine_above) {
        return fail(
            at.join("refine_above"),
            format!(
                "must be in (0, 1], a fraction of the largest indicator (got {})",
                a.refine_above
            ),
        );
    }
    if !(fraction(a.coarsen_below) && a.coarsen_below < a.refine_above) {
        return fail(
            at.join("coarsen_below"),
            format!(
                "must be > 0 and smaller than refine_above = {} (got {})",
                a.refine_above, a.coarsen_below
            ),
        );
    }
    if !(1.2..=2.0).contains(&a.grading) {
        return fail(
            at.join("grading"),
            format!(
                "must be in [1.2, 2] (got {}): the largest ratio of neighbouring spacings; \
                 larger jumps leave triangles the alpha shape and refinement cannot keep good",
                a.grading
            ),
        );
    }
    if a.every == 0 {
        return fail(at.join("every"), "must be >= 1 (got 0)".to_string());
    }
    if !s.mesh.refine {
        return fail(
            at,
            "needs mesh.refine = true: the adapted spacing acts through the refinement's \
             splits and merges"
                .to_string(),
        );
    }
    let area: f64 = s
        .body
        .rectangles
        .iter()
        .map(|r| r.size[0] * r.size[1])
        .sum::<f64>()
        + super::zones::area(s);
    let upper = area / (a.h_min * a.h_min);
    if upper > MAX_PARTICLES as f64 {
        return fail(
            at.join("h_min"),
            format!(
                "h_min = {} could refine the body to about {upper:.3e} particles, more than the \
                 limit of {MAX_PARTICLES} ({LIMIT_REASON})",
                a.h_min
            ),
        );
    }
    Ok(())
}

/// Checks everything that can be checked without generating particles.
fn check_fields(s: &Scene) -> Result<(), Invalid> {
    let root = FieldPath::default();
    if s.name.trim().is_empty() {
        return fail(root.join("name"), "must not be empty".to_string());
    }

    let rects = root.join("body").join("rectangles");
    match (s.body.rectangles.is_empty(), s.body.zones.is_empty()) {
        (true, true) => {
            return fail(
                rects,
                "must contain at least one rectangle (or give the body as [[body.zones]])"
                    .to_string(),
            )
        }
        (false, false) => {
            return fail(
                root.join("body").join("zones"),
                "a body is either `rectangles` or `zones`, not both".to_string(),
            )
        }
        (true, false) => {
            super::zones::shapes(s)?;
        }
        (false, true) => {
            if let Some(i) = s.mesh.fine.iter().position(|r| r.polygon.is_some()) {
                return fail(
                    root.join("mesh").join("fine").at(i).join("polygon"),
                    "refines a body of [[body.zones]]; in a body of rectangles a region is a \
                     rectangle (origin, size)"
                        .to_string(),
                );
            }
        }
    }
    for (i, r) in s.body.rectangles.iter().enumerate() {
        finite2(rects.at(i).join("origin"), r.origin)?;
        if !(r.size[0] > 0.0 && r.size[1] > 0.0 && r.size.iter().all(|x| x.is_finite())) {
            return fail(
                rects.at(i).join("size"),
                format!("must be > 0 in both components (got {})", vec2(r.size)),
            );
        }
    }

    let jitter = s.body.jitter;
    if !(0.0..0.5).contains(&jitter) {
        return fail(
            root.join("body").join("jitter"),
            format!("must be in [0, 0.5) (got {jitter})"),
        );
    }

    let mesh = root.join("mesh");
    positive(mesh.join("h"), s.mesh.h)?;
    for (i, r) in s.mesh.fine.iter().enumerate() {
        let at = mesh.join("fine").at(i);
        positive(at.join("h"), r.h)?;
        if r.h >= s.mesh.h {
            return fail(
                at.join("h"),
                format!("must be smaller than mesh.h = {} (got {})", s.mesh.h, r.h),
            );
        }
        if r.polygon.is_some() {
            if r.size != [0.0; 2] || r.origin != [0.0; 2] {
                return fail(
                    at.join("polygon"),
                    "a region is a rectangle (origin, size) or a polygon, not both".to_string(),
                );
            }
            super::zones::fine_region(r, &at)?;
        } else if !(r.size[0] > 0.0
            && r.size[1] > 0.0
            && r.size.iter().chain(&r.origin).all(|x| x.is_finite()))
        {
            return fail(
                at.join("size"),
                format!("must be > 0 in both components (got {})", vec2(r.size)),
            );
        }
    }
    if let Some(a) = &s.mesh.adapt {
        check_adapt(s, a)?;
    }
    positive(mesh.join("alpha"), s.mesh.alpha)?;
    if s.mesh.alpha < std::f64::consts::FRAC_1_SQRT_2 {
        return fail(
            mesh.join("alpha"),
            format!(
                "must be >= 0.7071 (got {}): smaller values delete every triangle of the \
                 square particle lattice",
                s.mesh.alpha
            ),
        );
    }
    if s.mesh.alpha > MAX_ALPHA {
        return fail(
            mesh.join("alpha"),
            format!(
                "must be <= {MAX_ALPHA} (got {}): the alpha shape would keep triangles across \
                 gaps of up to 2 alpha h and fill concave corners, stiffening the body \
                 (usual values 1.2 to 1.5)",
                s.mesh.alpha
            ),
        );
    }

    check_materials(s)?;

    finite2(root.join("gravity").join("g"), s.gravity.g)?;

    for (i, f) in s.fixed.iter().enumerate() {
        dofs(root.join("fixed").at(i).join("dofs"), &f.dofs)?;
    }
    for (i, p) in s.point_load.iter().enumerate() {
        let path = root.join("point_load").at(i);
        finite2(path.join("at"), p.at)?;
        finite2(path.join("force"), p.force)?;
    }
    for (i, p) in s.prescribed.iter().enumerate() {
        let path = root.join("prescribed").at(i);
        dofs(path.join("dofs"), &p.dofs)?;
        finite2(path.join("total"), p.total)?;
        if p.select == Selection::Current {
            for d in &p.dofs {
                let axis = if d.index() == 0 { Axis::X } else { Axis::Y };
                let (lo, hi) = p.region.interval(axis);
                if lo.is_finite() == hi.is_finite() {
                    return fail(
                        path.join("where"),
                        format!(
                            "select = \"current\" needs `where` bounded on one side only in {} \
                             (the platen's face), e.g. \"{} >= 1\"",
                            d.as_str(),
                            d.as_str()
                        ),
                    );
                }
            }
        }
    }

    if s.steps.count < 1 {
        return fail(
            root.join("steps").join("count"),
            format!("must be >= 1 (got {})", s.steps.count),
        );
    }
    let tol = s.steps.collapse_tolerance;
    if !(tol > 0.0 && tol < 1.0) {
        return fail(
            root.join("steps").join("collapse_tolerance"),
            format!("must be > 0 and < 1 (got {tol})"),
        );
    }
    let c = s.steps.collapse_compliance;
    if !(c > 1.0 && c.is_finite()) {
        return fail(
            root.join("steps").join("collapse_compliance"),
            format!("must be > 1 and finite (got {c})"),
        );
    }
    if s.gravity.ramp && s.geostatic.is_some() {
        return fail(
            root.join("gravity").join("ramp"),
            "ramps the weight up from nothing, so the body starts unstressed; [geostatic] is the \
             stress of the full weight: leave one of them out"
                .to_string(),
        );
    }

    let kind = root.join("history").join("kind");
    match s.history.kind {
        Some(HistoryKind::Cantilever) if s.point_load.is_empty() => {
            return fail(
                kind,
                "\"cantilever\" records the displacement of the first [[point_load]]'s \
                 particle, but the scene has no [[point_load]]"
                    .to_string(),
            );
        }
        Some(HistoryKind::Footing | HistoryKind::Block) if s.prescribed.is_empty() => {
            return fail(
                kind,
                format!(
                    "\"{}\" records the force on the [[prescribed]] particles, but the scene \
                     has no [[prescribed]]",
                    s.history.kind.map_or("", |k| k.as_str())
                ),
            );
        }
        Some(k @ (HistoryKind::Footing | HistoryKind::Block)) if s.material.model.frictional() => {
            return fail(
                kind,
                format!(
                    "\"{}\" divides by cu and draws Tresca's collapse loads, which a \"{}\" \
                     material has not: declare the columns instead ([[history.columns]], e.g. \
                     `reaction.NAME.fy` with a scale of -1/(c B))",
                    k.as_str(),
                    s.material.model.as_str()
                ),
            );
        }
        _ => {}
    }

    if s.output.checkpoint_keep < 1 {
        return fail(
            root.join("output").join("checkpoint_keep"),
            format!("must be >= 1 (got {})", s.output.checkpoint_keep),
        );
    }
    let solver = root.join("solver");
    if s.solver.newton_max_it < 1 {
        return fail(
            solver.join("newton_max_it"),
            format!("must be >= 1 (got {})", s.solver.newton_max_it),
        );
    }
    let rtol = s.solver.newton_rtol;
    if !(rtol > 0.0 && rtol < 1.0) {
        return fail(
            solver.join("newton_rtol"),
            format!("must be > 0 and < 1 (got {rtol})"),
        );
    }
    Ok(())
}

/// Rectangle corners must sit on the lattice so that edges carry particles; zones hold no more
/// particles than the limit.
fn check_alignment(s: &Scene) -> Result<(), Invalid> {
    let h = s.mesh.h;
    if s.body.rectangles.is_empty() {
        let [lo, hi] = s.bounding_box();
        return particle_limit(h, ((hi[0] - lo[0]) / h + 2.0) * ((hi[1] - lo[1]) / h + 2.0));
    }
    let anchor = s.body.rectangles[0].origin;
    let rects = FieldPath::key("body").join("rectangles");
    for (i, r) in s.body.rectangles.iter().enumerate() {
        for axis in 0..2 {
            let offset = (r.origin[axis] - anchor[axis]) / h;
            if lattice::whole(offset).is_none() {
                return fail(
                    rects.at(i).join("origin"),
                    format!(
                        "{} is {offset:.4} particle spacings (mesh.h = {h}) from the first \
                         rectangle's origin; it must be a whole number",
                        vec2(r.origin)
                    ),
                );
            }
            let count = r.size[axis] / h;
            if lattice::whole(count).is_none() {
                return fail(
                    rects.at(i).join("size"),
                    format!(
                        "{} is {count:.4} particle spacings (mesh.h = {h}) along {}; it must \
                         be a whole number",
                        r.size[axis],
                        ["x", "y"][axis]
                    ),
                );
            }
        }
    }
    let upper: f64 = s
        .body
        .rectangles
        .iter()
        .map(|r| super::validate_fine::lattice_count(r.size, h))
        .sum();
    particle_limit(h, upper)
}

/// At most [`MAX_PARTICLES`], `upper` bounding the count that spacing `h` makes.
fn particle_limit(h: f64, upper: f64) -> Result<(), Invalid> {
    if upper > MAX_PARTICLES as f64 {
        return fail(
            FieldPath::key("mesh").join("h"),
            format!(
                "h = {h} would create about {upper:.3e} particles, more than the limit of \
                 {MAX_PARTICLES} ({LIMIT_REASON})"
            ),
        );
    }
    Ok(())
}

/// A selection (`where` within `on`) that picks at least one particle; `on` naming a boundary
/// that exists. `entry` is the table's path.
fn check_selects_something(
    entry: FieldPath,
    (region, on): (&Selector, Option<&str>),
    boundaries: &crate::geometry::NamedBoundaries,
    s: &Scene,
    positions: &[[f64; 2]],
) -> Result<(), Invalid> {
    let tol = s.tolerance();
    if region.is_all() && on.is_none() {
        return fail(
            entry.join("where"),
            "is required (or `on`, naming a boundary, or a `within` polygon): which particles?"
                .to_string(),
        );
    }
    if let Some(name) = on {
        if let Err(e) = boundaries.distance(name, [0.0; 2]) {
            let known = if e.known.is_empty() {
                "the body has no named boundary (name polygon edges with body.zones[].edges)"
                    .to_string()
            } else {
                format!("the named boundaries are {}", e.known.join(", "))
            };
            return fail(
                entry.join("on"),
                format!("\"{name}\" names no boundary: {known}"),
            );
        }
    }
    let on_it =
        |p: [f64; 2]| on.is_none_or(|n| crate::model::on_boundary(boundaries, n, p, s.mesh.h));
    if positions
        .iter()
        .any(|&p| region.matches(p, tol) && on_it(p))
    {
        return Ok(());
    }
    let mut what = match (region.has_no_conditions(), on) {
        (true, None) => "the `within` polygon".to_string(),
        (false, None) => format!("\"{region}\""),
        (true, Some(n)) => format!("on = \"{n}\""),
        (false, Some(n)) => format!("\"{region}\" on \"{n}\""),
    };
    if !region.is_all() && region.has_no_conditions() && on.is_some() {
        what.push_str(" within its polygon");
    }
    let key = match (region.has_no_conditions(), on) {
        (false, _) => "where",
        (true, Some(_)) => "on",
        (true, None) => "within",
    };
    fail(
        entry.join(key),
        format!("{what} selects no particle of the body"),
    )
}

/// Checks that depend on the generated lattice: selections must select something and point
/// loads must sit on the body.
fn check_against_particles(s: &Scene) -> Result<(), Invalid> {
    let particles = generate_particles(s);
    let tol = s.tolerance();
    let boundaries = crate::model::named_boundaries(s);
    let x = &particles.position;
    for (i, f) in s.fixed.iter().enumerate() {
        let entry = FieldPath::key("fixed").at(i);
        check_selects_something(entry, (&f.region, f.on.as_deref()), &boundaries, s, x)?;
    }
    for (i, p) in s.prescribed.iter().enumerate() {
        let entry = FieldPath::key("prescribed").at(i);
        if p.on.is_some() && p.select == Selection::Current {
            return fail(
                entry.join("on"),
                "selects by the body's initial boundary, so it needs select = \"initial\"; a \
                 platen (select = \"current\") selects with `where`"
                    .to_string(),
            );
        }
        check_selects_something(entry, (&p.region, p.on.as_deref()), &boundaries, s, x)?;
    }
    for (i, sp) in s.surface_pressure.iter().enumerate() {
        // `where` alone is checked for a boundary edge with the other loads.
        if sp.on.is_some() || sp.region.is_all() {
            let entry = FieldPath::key("surface_pressure").at(i);
            check_selects_something(entry, (&sp.region, sp.on.as_deref()), &boundaries, s, x)?;
        }
    }
    for (i, p) in s.probe.iter().enumerate() {
        if p.on.is_some() {
            let entry = FieldPath::key("probe").at(i);
            check_selects_something(
                entry,
                (&Selector::all(), p.on.as_deref()),
                &boundaries,
                s,
                x,
            )?;
        }
    }
    super::validate_loads::check(s, &particles)?;
    super::validate_motion::check(s, &particles)?;
    // The particle a point load goes to (`lattice::nearest`, ties to the smaller id).
    let nearest = |at: [f64; 2]| {
        let (gid, _) = lattice::nearest(&particles, at)?;
        particles.gid.iter().position(|&g| g == gid)
    };
    super::validate_supports::check(s, &particles.position, tol, nearest)
}

pub fn validate(s: &Scene) -> Result<(), Invalid> {
    check_fields(s)?;
    super::validate_axisymmetry::check(s)?;
    super::validate_rigid::check(s)?;
    super::clock::check(s)?;
    check_alignment(s)?;
    super::validate_fine::check(s)?;
    check_against_particles(s)
}

/// Every material's parameters; names (required, unique) with several; zones that name them.
fn check_materials(s: &Scene) -> Result<(), Invalid> {
    let all = s.material.all();
    let root = FieldPath::key("material");
    let at = |i: usize| {
        if all.len() == 1 {
            root.clone()
        } else {
            root.at(i)
        }
    };
    for (i, m) in all.iter().enumerate() {
        check_material(s, m, &at(i))?;
        if all.len() > 1 {
            match m.name.as_deref().map(str::trim) {
                None | Some("") => {
                    return fail(
                        at(i).join("name"),
                        "is required with several [[material]] tables: zones name their material"
                            .to_string(),
                    )
                }
                Some(n) if all[..i].iter().any(|o| o.name.as_deref() == Some(n)) => {
                    return fail(at(i).join("name"), format!("\"{n}\" is given twice"));
                }
                _ => {}
            }
        }
    }
    let zones = FieldPath::key("body").join("zones");
    for (i, z) in s.body.zones.iter().enumerate() {
        match &z.material {
            Some(name) if s.material.index_of(name).is_none() => {
                let known: Vec<&str> = all.iter().filter_map(|m| m.name.as_deref()).collect();
                let known = if known.is_empty() {
                    "the [material] table has no `name`".to_string()
                } else {
                    format!("the materials are {}", known.join(", "))
                };
                return fail(
                    zones.at(i).join("material"),
                    format!("\"{name}\" names no [[material]]: {known}"),
                );
            }
            None if all.len() > 1 => {
                return fail(
                    zones.at(i).join("material"),
                    "is required with several [[material]] tables".to_string(),
                )
            }
            _ => {}
        }
    }
    if all.len() > 1 && s.body.zones.is_empty() {
        return fail(
            root,
            "several materials need a body of [[body.zones]], each naming its material".to_string(),
        );
    }
    if s.geostatic.is_some()
        && s.body.zones.is_empty()
        && all.iter().any(|m| m.density != all[0].density)
    {
        return fail(
            FieldPath::key("geostatic"),
            "takes one density for a body of rectangles, but the materials' densities differ"
                .to_string(),
        );
    }
    for (i, z) in s.body.zones.iter().enumerate() {
        if let Some(k0) = z.k0 {
            if !(k0.is_finite() && k0 >= 0.0) {
                return fail(
                    FieldPath::key("body").join("zones").at(i).join("k0"),
                    format!("must be >= 0 and finite (got {k0})"),
                );
            }
            if s.geostatic.is_none() {
                return fail(
                    FieldPath::key("body").join("zones").at(i).join("k0"),
                    "needs [geostatic]: it is the zone's horizontal-to-vertical ratio of the \
                     geostatic stress"
                        .to_string(),
                );
            }
        }
    }
    Ok(())
}

/// The parameters of one material, at `mat`.
fn check_material(s: &Scene, m: &Material, mat: &FieldPath) -> Result<(), Invalid> {
    if m.young.is_nan() {
        return fail(mat.join("young"), "required key is missing".to_string());
    }
    if let Some(ratio) = m.young_over_cu {
        positive(mat.join("young_over_cu"), ratio)?;
        let derived = ratio * m.cu;
        if (m.young - derived).abs() > 1e-12 * derived.abs() {
            return fail(
                mat.join("young"),
                format!(
                    "is young_over_cu · cu = {derived:e} Pa with young_over_cu, or left out \
                     (got {:e})",
                    m.young
                ),
            );
        }
    }
    positive(mat.join("young"), m.young)?;
    let nu = m.poisson;
    if !(nu > -1.0 && nu < 0.5) {
        return fail(
            mat.join("poisson"),
            format!("must be > -1 and < 0.5 (got {nu})"),
        );
    }
    non_negative(mat.join("density"), m.density)?;
    foreign_keys(m, mat)?;
    super::validate_umat::check(m, mat)?;
    match m.model {
        MaterialModel::Umat => non_negative(mat.join("cu"), m.cu),
        MaterialModel::Tresca | MaterialModel::TrescaSoftening => {
            if !(m.cu > 0.0 && m.cu.is_finite()) {
                return fail(
                    mat.join("cu"),
                    format!(
                        "must be > 0 for model \"{}\" (got {})",
                        m.model.as_str(),
                        m.cu
                    ),
                );
            }
            cu_profile(s, m, mat)?;
            edge_rounding(s, m, mat)?;
            if m.model == MaterialModel::TrescaSoftening {
                softening(m, mat)?;
            }
            Ok(())
        }
        MaterialModel::LinearElastic => non_negative(mat.join("cu"), m.cu),
        MaterialModel::MohrCoulomb | MaterialModel::DruckerPrager => {
            let mut strength = [0.0; 3];
            for (v, (key, given)) in strength.iter_mut().zip([
                ("cohesion", m.cohesion),
                ("friction_angle", m.friction_angle),
                ("dilation_angle", m.dilation_angle),
            ]) {
                *v = given.ok_or_else(|| {
                    (
                        mat.join(key),
                        format!("is required for model \"{}\"", m.model.as_str()),
                    )
                })?;
            }
            let [c, phi, psi] = strength;
            let checked =
                crate::material::mohr_coulomb::check_strength(c, phi, psi).and_then(|()| {
                    match m.tension_cutoff {
                        Some(t) => crate::material::mohr_coulomb::MohrCoulomb::new(
                            m.young,
                            m.poisson,
                            c,
                            phi,
                            psi,
                            Some(t),
                        )
                        .map(|_| ()),
                        None => Ok(()),
                    }
                });
            match checked {
                Err(crate::material::MaterialError::InvalidParameter {
                    name,
                    value,
                    requirement,
                }) => fail(
                    mat.join(name),
                    format!("must satisfy {requirement} (got {value})"),
                ),
                _ => Ok(()),
            }
        }
    }
}

/// Tresca's `edge_rounding`: in its range, and only where the criterion has edges to round.
fn edge_rounding(s: &Scene, m: &Material, mat: &FieldPath) -> Result<(), Invalid> {
    let Some(rho) = m.edge_rounding else {
        return Ok(());
    };
    if !s.analysis.has_hoop() {
        return fail(
            mat.join("edge_rounding"),
            "applies only with analysis = \"axisymmetric\" (plane strain judges Tresca by the \
             largest in-plane shear, which has no edges to round)"
                .to_string(),
        );
    }
    let max = crate::material::rounded_prism::MAX_ROUNDING;
    if !(rho > 0.0 && rho <= max) {
        return fail(
            mat.join("edge_rounding"),
            format!("must be > 0 and <= {max} (got {rho})"),
        );
    }
    Ok(())
}

/// The keys of other models than `m`'s, each rejected by name: a table holds exactly its
/// model's parameters.
fn foreign_keys(m: &Material, mat: &FieldPath) -> Result<(), Invalid> {
    use MaterialModel::*;
    const SOFT: &[MaterialModel] = &[TrescaSoftening];
    let given: [(&str, bool, &[MaterialModel]); 15] = [
        (
            "cu",
            m.cu != 0.0,
            &[Tresca, TrescaSoftening, LinearElastic, Umat],
        ),
        (
            "cu_gradient",
            m.cu_gradient != 0.0,
            &[Tresca, TrescaSoftening],
        ),
        (
            "reference_level",
            m.reference_level.is_some(),
            &[Tresca, TrescaSoftening],
        ),
        (
            "young_over_cu",
            m.young_over_cu.is_some(),
            &[Tresca, TrescaSoftening],
        ),
        ("edge_rounding", m.edge_rounding.is_some(), &[Tresca]),
        ("remoulded_ratio", m.remoulded_ratio.is_some(), SOFT),
        ("xi95", m.xi95.is_some(), SOFT),
        (
            "xi95_reference_spacing",
            m.xi95_reference_spacing.is_some(),
            SOFT,
        ),
        ("rate_parameter", m.rate_parameter.is_some(), SOFT),
        ("reference_rate", m.reference_rate.is_some(), SOFT),
        (
            "cohesion",
            m.cohesion.is_some(),
            &[MohrCoulomb, DruckerPrager],
        ),
        (
            "friction_angle",
            m.friction_angle.is_some(),
            &[MohrCoulomb, DruckerPrager],
        ),
        (
            "dilation_angle",
            m.dilation_angle.is_some(),
            &[MohrCoulomb, DruckerPrager],
        ),
        ("tension_cutoff", m.tension_cutoff.is_some(), &[MohrCoulomb]),
        ("match", m.cone_match.is_some(), &[DruckerPrager]),
    ];
    for (key, present, owners) in given {
        if present && !owners.contains(&m.model) {
            let names: Vec<String> = owners
                .iter()
                .map(|o| format!("\"{}\"", o.as_str()))
                .collect();
            return fail(
                mat.join(key),
                format!(
                    "is a parameter of model {}, not of \"{}\"",
                    names.join(" and "),
                    m.model.as_str()
                ),
            );
        }
    }
    Ok(())
}

/// The softening and rate parameters of a `"tresca-softening"` material, each checked by the
/// model and named at fault.
fn softening(m: &Material, mat: &FieldPath) -> Result<(), Invalid> {
    for (key, given) in [("remoulded_ratio", m.remoulded_ratio), ("xi95", m.xi95)] {
        if given.is_none() {
            return fail(
                mat.join(key),
                "is required for model \"tresca-softening\"".to_string(),
            );
        }
    }
    let nan = f64::NAN;
    let checked = crate::material::tresca_softening::TrescaSoftening::new(
        m.young,
        m.poisson,
        m.cu,
        m.remoulded_ratio.unwrap_or(nan),
        m.xi95.unwrap_or(nan),
        m.rate_parameter.unwrap_or(0.0),
        m.reference_rate,
    )
    .and_then(|t| match m.xi95_reference_spacing {
        Some(h) => t.with_reference_spacing(h),
        None => Ok(t),
    });
    match checked {
        Err(crate::material::MaterialError::InvalidParameter {
            name,
            value,
            requirement,
        }) => fail(
            mat.join(name),
            format!("must satisfy {requirement} (got {value})"),
        ),
        _ => Ok(()),
    }
}

/// A Tresca strength profile: a finite gradient with its reference level, and cu > 0 down to the
/// lowest point of the body.
fn cu_profile(s: &Scene, m: &Material, mat: &FieldPath) -> Result<(), Invalid> {
    let k = m.cu_gradient;
    if !k.is_finite() {
        return fail(mat.join("cu_gradient"), format!("must be finite (got {k})"));
    }
    let Some(level) = m.reference_level else {
        if k != 0.0 {
            return fail(
                mat.join("reference_level"),
                "is required with cu_gradient: the level below which cu grows".to_string(),
            );
        }
        return Ok(());
    };
    if !level.is_finite() {
        return fail(
            mat.join("reference_level"),
            format!("must be finite (got {level})"),
        );
    }
    let [[_, y_min], _] = s.bounding_box();
    let lowest = m.cu + k * (level - y_min).max(0.0);
    if lowest.is_nan() || lowest <= 0.0 {
        return fail(
            mat.join("cu_gradient"),
            format!(
                "makes cu = {lowest} Pa at y = {y_min} m, the body's lowest point: cu must stay \
                 > 0 everywhere"
            ),
        );
    }
    Ok(())
}
