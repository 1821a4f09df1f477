//! Checks that a run does what it was asked and that what it reports means something: a
//! request that would run no step, or a step that went through on a body that is gone (no
//! triangle left, its area collapsed, a point load on a particle the mesh no longer holds),
//! where the solver has nothing left to fail on and would report success.

use super::{RunError, RunOptions, Simulation, StepReport};
use crate::mesh::LocalMesh;
use crate::scene::Scene;
use pfem_partition::{sum_f64, Comm};

/// Smallest body area, as a fraction of the scene's, that a step may end with. Plastic flow
/// and remeshing change a body's area by a few per cent; an area halved means the body was
/// crushed, inverted or torn away by the alpha shape, and its stresses mean nothing.
pub(super) const MIN_AREA_RATIO: f64 = 0.5;

/// Refuses an `--until-step` that leaves nothing to run: 0, or a step the case has already
/// reached. Not collective: every rank holds the same header, so every rank agrees.
pub(super) fn check_until_step(opts: &RunOptions, sim: &Simulation) -> Result<(), RunError> {
    let Some(until) = opts.until_step else {
        return Ok(());
    };
    let (step, total) = (sim.step(), sim.total_steps());
    if until > step {
        return Ok(());
    }
    let why = if until == 0 {
        "a run stops after a step it has made".to_string()
    } else {
        format!("{} is already at step {step}", opts.case.display())
    };
    let instead = if step < total {
        format!("give a step from {} to {total} (steps.count)", step + 1)
    } else {
        format!("the case has made all its steps (steps.count = {total})")
    };
    Err(RunError::UntilStep {
        until,
        reason: format!("{why}; {instead}"),
    })
}

/// Area of the union of the scene's body rectangles (overlaps counted once).
fn body_area(scene: &Scene) -> f64 {
    if !scene.body.zones.is_empty() {
        return crate::scene::zones::area(scene);
    }
    let rects = &scene.body.rectangles;
    let mut xs: Vec<f64> = rects
        .iter()
        .flat_map(|r| [r.origin[0], r.origin[0] + r.size[0]])
        .collect();
    let mut ys: Vec<f64> = rects
        .iter()
        .flat_map(|r| [r.origin[1], r.origin[1] + r.size[1]])
        .collect();
    xs.sort_by(f64::total_cmp);
    ys.sort_by(f64::total_cmp);
    let mut area = 0.0;
    for x in xs.windows(2) {
        for y in ys.windows(2) {
            let mid = [0.5 * (x[0] + x[1]), 0.5 * (y[0] + y[1])];
            let covered = rects
                .iter()
                .any(|r| (0..2).all(|c| mid[c] > r.origin[c] && mid[c] < r.origin[c] + r.size[c]));
            if covered {
                area += (x[1] - x[0]) * (y[1] - y[0]);
            }
        }
    }
    area
}

/// Whether this rank holds particle `gid` as a vertex of one of its triangles.
fn holds_in_a_triangle(mesh: &LocalMesh, gid: u64) -> bool {
    let Some(i) = mesh.gids[..mesh.n_owned].iter().position(|&g| g == gid) else {
        return false;
    };
    let i = i as u32;
    mesh.tris.iter().any(|t| t.contains(&i))
}

/// Collective. After a step solved on `mesh`: an error when the mesh had no triangle, when the
/// body's area fell below [`MIN_AREA_RATIO`] of the scene's, or when a `[[point_load]]`'s
/// particle was in no triangle (the load was not applied). The same verdict on every rank.
/// Under `steps.until_collapse`, the line saying where the collapse was bracketed; reaching
/// the last step without one is an error (the load never got there). The same on every rank.
pub(super) fn check_collapse(
    sim: &Simulation,
    collapse: Option<[f64; 2]>,
    until_step: Option<u64>,
) -> Result<Option<String>, RunError> {
    let steps = sim.scene().steps;
    if !steps.until_collapse {
        return Ok(None);
    }
    match collapse {
        Some([held, failed]) => Ok(Some(format!(
            "collapse reached: equilibrium holds at load factor {held:.6} and fails by \
             {failed:.6} (steps.collapse_tolerance = {})",
            steps.collapse_tolerance
        ))),
        None if sim.step() >= sim.total_steps() && until_step.is_none_or(|u| u >= sim.step()) => {
            Err(RunError::Sanity {
                step: sim.step(),
                what: format!(
                    "steps.until_collapse: equilibrium held up to load factor {:.6}, the end \
                     of the load; raise the load (gravity.g, the prescribed motion) so that \
                     the body collapses",
                    sim.load_factor()
                ),
            })
        }
        None => Ok(None),
    }
}

pub(super) fn check_step(
    world: &Comm,
    sim: &Simulation,
    mesh: &LocalMesh,
    report: &StepReport,
) -> Result<(), RunError> {
    let scene = sim.scene();
    let step = sim.step();
    let loads = &scene.point_load;
    let mut local = vec![sim.last_area];
    local.extend(loads.iter().enumerate().map(|(k, _)| {
        let held = sim
            .header
            .tracked_gids
            .get(k)
            .is_some_and(|&g| holds_in_a_triangle(mesh, g));
        f64::from(u8::from(held))
    }));
    // Per body: triangles that reached into it, and the size of the soil's force on it.
    let n_loads = local.len();
    let crossing = sim.crossing.borrow();
    for (b, _) in sim.model.bodies.iter().enumerate() {
        let f = sim.last_body_force.get(b).copied().unwrap_or([0.0; 2]);
        local.push(crossing.get(b).copied().unwrap_or(0) as f64);
        local.push(f[0].abs() + f[1].abs());
    }
    let global = sum_f64(world, &local);
    let stop = "the run stops before writing this step";
    for (b, pair) in global[n_loads..].chunks_exact(2).enumerate() {
        if pair[0] > 0.0 && pair[1] == 0.0 {
            return Err(RunError::Sanity {
                step,
                what: format!(
                    "the rigid body \"{}\" lies in the soil ({} triangles of the mesh reached \
                     into it) but no soil node touches it: the contact lost it (a body thinner \
                     than the particle spacing, or one that moved through the soil in a step); \
                     {stop}",
                    sim.model.bodies[b].name, pair[0]
                ),
            });
        }
    }
    let global = &global[..n_loads];
    if report.triangles == 0 {
        return Err(RunError::Sanity {
            step,
            what: format!(
                "the mesh has no triangle left: the body was crushed or torn apart (no \
                 particles within alpha * h of each other); {stop}"
            ),
        });
    }
    let ratio = global[0] / body_area(scene);
    if ratio.is_nan() || ratio < MIN_AREA_RATIO {
        return Err(RunError::Sanity {
            step,
            what: format!(
                "the body's area is {ratio:.3} of its initial area (limit {MIN_AREA_RATIO}): \
                 it was crushed or inverted; {stop}"
            ),
        });
    }
    if let Some(k) = global[1..].iter().position(|&held| held == 0.0) {
        let particle = match sim.header.tracked_gids.get(k) {
            Some(g) => format!("its particle (gid {g}) is in no triangle of the mesh"),
            None => "the case file's tracked_gids names no particle for it".to_string(),
        };
        return Err(RunError::Sanity {
            step,
            what: format!(
                "point_load[{k}] at [{}, {}] does not reach the body: {particle}, so the load \
                 was not applied; {stop}",
                loads[k].at[0], loads[k].at[1]
            ),
        });
    }
    Ok(())
}

/// Poisson's ratio from which the displacement (P2) element locks: its volumetric stiffness
/// grows as 1/(1 - 2 nu) and swamps the shear response, so Newton stalls at any step size.
const LOCKING_POISSON: f64 = 0.499;

/// A lower bound of the strain the scene's loads impose: point loads over the body's smaller
/// dimension, surface pressures and the body's weight, each divided by Young's modulus.
fn load_strain(scene: &Scene) -> f64 {
    let rects = &scene.body.rectangles;
    let extent = |c: usize| {
        let lo = rects
            .iter()
            .map(|r| r.origin[c])
            .fold(f64::INFINITY, f64::min);
        let hi = rects
            .iter()
            .map(|r| r.origin[c] + r.size[c])
            .fold(f64::NEG_INFINITY, f64::max);
        hi - lo
    };
    let e = scene.material.young;
    let point: f64 = scene
        .point_load
        .iter()
        .map(|p| p.force[0].hypot(p.force[1]))
        .sum::<f64>()
        / extent(0).min(extent(1));
    let surface = scene
        .surface_pressure
        .iter()
        .map(|p| p.pressure.abs())
        .fold(0.0, f64::max);
    let weight = scene.material.density * scene.gravity.g[0].hypot(scene.gravity.g[1]) * extent(1);
    point.max(surface).max(weight) / e
}

/// What to tell the user when Newton could not get through a step even in the smallest piece:
/// what in the scene makes the system ill-posed when something does, else the usual remedies.
/// `contact`: Newton converged but left a contact node off the body's face.
pub(super) fn divergence_advice(model: &crate::model::Model, contact: bool) -> String {
    let scene = &model.scene;
    if contact {
        let c = &scene.contact;
        return format!(
            "Newton converged with a contact node off the body's face: loosen contact.tolerance \
             (= {:e}, default 1e-6) or tighten solver.newton_rtol (= {:e}, default 1e-9)",
            c.tolerance, scene.solver.newton_rtol
        );
    }
    let nu = scene.material.poisson;
    if !model.mixed() && nu >= LOCKING_POISSON {
        return format!(
            "material.poisson = {nu} is nearly incompressible, where the displacement (P2) \
             element locks at any step size: use the mixed element, solver.element = \"p2p1\""
        );
    }
    let strain = load_strain(scene);
    if strain > 1.0 {
        return format!(
            "the loads would strain the body by at least {strain:.1e} at this stiffness \
             (material.young = {:e} Pa): no step size helps; check material.young against the \
             loads (point_load forces in N per metre, pressures in Pa)",
            scene.material.young
        );
    }
    "a smaller step (steps.count) or another line search (solver.line_search) may get through"
        .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn body_area_counts_overlaps_once() {
        let (mut scene, _) = crate::scene::load_scene("cantilever", &[]).unwrap();
        assert_eq!(body_area(&scene), 10.0);
        let mut r = scene.body.rectangles[0];
        r.origin = [9.0, 0.0];
        r.size = [2.0, 2.0];
        scene.body.rectangles.push(r);
        assert_eq!(body_area(&scene), 10.0 + 2.0 * 2.0 - 1.0);
    }

    #[test]
    fn divergence_advice_names_what_is_ill_posed() {
        let model = |sets: &[&str]| {
            let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
            let (scene, _) = crate::scene::load_scene("cantilever", &sets).unwrap();
            crate::model::Model::new(&scene).unwrap()
        };
        assert!(divergence_advice(&model(&[]), false).contains("a smaller step"));
        let locked = divergence_advice(&model(&["material.poisson=0.49999999"]), false);
        assert!(locked.contains("solver.element = \"p2p1\""), "{locked}");
        let mixed = model(&["material.poisson=0.49999999", "solver.element=\"p2p1\""]);
        assert!(divergence_advice(&mixed, false).contains("a smaller step"));
        let soft = divergence_advice(&model(&["material.young=1e-300"]), false);
        assert!(soft.contains("material.young = 1e-300 Pa"), "{soft}");
        let contact = divergence_advice(&model(&[]), true);
        assert!(contact.contains("contact.tolerance (= 1e-6"), "{contact}");
    }
}
