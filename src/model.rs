//! What a scene means for the solver: material, element, supports, prescribed motion, loads.

use crate::fem::analysis::Analysis;
use crate::geometry::NamedBoundaries;
use crate::material::drucker_prager::{DruckerPrager, Match};
use crate::material::elastic::LinearElastic;
use crate::material::mohr_coulomb::MohrCoulomb;
use crate::material::placed::{union_layout, Placed};
use crate::material::tresca::{CuProfile, Tresca};
use crate::material::tresca_softening::TrescaSoftening;
use crate::material::umat::{self, Umat};
use crate::material::{InternalVar, Material, MaterialError, StateLayout};
use crate::rigid::RigidBody;
use crate::scene::{
    Axis, ConeMatch, ElementChoice, Fixed, MaterialModel, Prescribed, Scene, Selection,
};
use crate::solve::Kernel;
use crate::solve::Law;
use crate::solve::Pressure;
use std::borrow::Cow;
use std::path::Path;

/// The internal variables of a scene material's model. They depend on the model alone (not on
/// its parameters' values), so they are known before the parameters are checked.
fn model_variables(m: &crate::scene::Material) -> Cow<'static, [InternalVar]> {
    Cow::Borrowed(match m.model {
        MaterialModel::LinearElastic => &[],
        MaterialModel::Tresca if m.cu_gradient != 0.0 => {
            &crate::material::tresca::VARIABLES_WITH_CU
        }
        MaterialModel::Tresca => &crate::material::tresca::VARIABLES,
        MaterialModel::TrescaSoftening => {
            crate::material::tresca_softening::variables(m.cu_gradient != 0.0)
        }
        MaterialModel::MohrCoulomb | MaterialModel::DruckerPrager => {
            &crate::material::mohr_coulomb::VARIABLES
        }
        MaterialModel::Umat => return Cow::Owned(umat::variables(&umat_state_names(m))),
    })
}

/// The names of a UMAT material's state variables: `state_names`, or `statev_1 ...`.
fn umat_state_names(m: &crate::scene::Material) -> Vec<String> {
    match m.state_names.is_empty() {
        true => umat::default_names(m.state_variables),
        false => m.state_names.clone(),
    }
}

/// The layout of the state rows of a scene: what case files, checkpoints and output hold per
/// particle and Gauss point. With several materials, the union of their variables.
pub fn state_layout(scene: &Scene) -> StateLayout {
    let vars: Vec<_> = scene.material.all().iter().map(model_variables).collect();
    union_layout(vars.iter().map(|v| v.as_ref()))
}

/// The constitutive models of a scene, in its `[[material]]` order, their parameters checked;
/// with several materials each works in the scene's union layout.
pub fn materials_of(scene: &Scene) -> Result<Vec<Box<dyn Material>>, String> {
    let all = scene.material.all();
    let layout = state_layout(scene);
    let mut out = Vec::with_capacity(all.len());
    for (i, m) in all.iter().enumerate() {
        let at = match all.len() {
            1 => "material".to_string(),
            _ => format!("material[{i}]"),
        };
        let model = match m.model {
            MaterialModel::Umat => umat_of(m).map_err(|e| format!("{at}.library: {e}"))?,
            _ => material_of(m, scene.analysis).map_err(|e| format!("{at}: {e}"))?,
        };
        out.push(match all.len() {
            1 => model,
            _ => Box::new(Placed::new(model, &layout)?) as Box<dyn Material>,
        });
    }
    Ok(out)
}

/// The constitutive model of one scene material, its parameters checked.
/// In axisymmetry a model judges the hoop stress among the principal ones.
fn material_of(
    m: &crate::scene::Material,
    analysis: Analysis,
) -> Result<Box<dyn Material>, MaterialError> {
    let named = |e: MaterialError| e;
    Ok(match m.model {
        MaterialModel::LinearElastic => {
            Box::new(LinearElastic::new(m.young, m.poisson).map_err(named)?)
        }
        MaterialModel::Tresca => {
            let mut t = Tresca::new(m.young, m.poisson, m.cu).map_err(named)?;
            if let Some(ratio) = m.young_over_cu {
                t = t.with_young_over_cu(ratio);
            }
            if analysis.has_hoop() {
                t = t.in_principal_stresses();
            }
            if let Some(rho) = m.edge_rounding {
                t = t.with_edge_rounding(rho)?;
            }
            match (m.cu_gradient, m.reference_level) {
                (k, Some(level)) if k != 0.0 => {
                    Box::new(t.with_profile(CuProfile { gradient: k, level }))
                }
                _ => Box::new(t),
            }
        }
        MaterialModel::TrescaSoftening => {
            let nan = f64::NAN;
            let mut t = TrescaSoftening::new(
                m.young,
                m.poisson,
                m.cu,
                m.remoulded_ratio.unwrap_or(nan),
                m.xi95.unwrap_or(nan),
                m.rate_parameter.unwrap_or(0.0),
                m.reference_rate,
            )?;
            if let Some(ratio) = m.young_over_cu {
                t = t.with_young_over_cu(ratio);
            }
            if let Some(h) = m.xi95_reference_spacing {
                t = t.with_reference_spacing(h)?;
            }
            match (m.cu_gradient, m.reference_level) {
                (k, Some(level)) if k != 0.0 => {
                    Box::new(t.with_profile(CuProfile { gradient: k, level }))
                }
                _ => Box::new(t),
            }
        }
        MaterialModel::MohrCoulomb => {
            let [c, phi, psi] = strength(m);
            Box::new(MohrCoulomb::new(
                m.young,
                m.poisson,
                c,
                phi,
                psi,
                m.tension_cutoff,
            )?)
        }
        MaterialModel::DruckerPrager => {
            let [c, phi, psi] = strength(m);
            let fit = match m.cone_match.unwrap_or_default() {
                ConeMatch::PlaneStrain => Match::PlaneStrain,
                ConeMatch::Outer => Match::Outer,
                ConeMatch::Inner => Match::Inner,
            };
            Box::new(DruckerPrager::new(m.young, m.poisson, c, phi, psi, fit)?)
        }
        MaterialModel::Umat => umat_of(m).map_err(MaterialError::Plugin)?,
    })
}

/// c, φ, ψ of a frictional material (validation has required them; a missing one is NaN, which
/// the model rejects by name).
fn strength(m: &crate::scene::Material) -> [f64; 3] {
    [m.cohesion, m.friction_angle, m.dilation_angle].map(|v| v.unwrap_or(f64::NAN))
}

/// A UMAT material: its library opened (the scene recorded the path absolute).
fn umat_of(m: &crate::scene::Material) -> Result<Box<dyn Material>, String> {
    let Some(lib) = m.library.as_deref() else {
        return Err("is required for model \"umat\"".to_string());
    };
    let names = umat_state_names(m);
    let u = Umat::new(Path::new(lib), m.props.clone(), &names, m.name.as_deref())?;
    Ok(Box::new(u))
}

/// The named edges of a scene's zones (empty for a body of rectangles).
pub fn named_boundaries(scene: &Scene) -> NamedBoundaries {
    let shapes = crate::scene::zones::shapes(scene).unwrap_or_default();
    NamedBoundaries::from_segments(crate::geometry::zone_segments(&shapes, scene.mesh.h))
}

/// Whether `x0` lies on boundary `name` of `b`: the fill puts particles on the edges to within
/// rounding, so 1e-6 of the spacing `h` picks exactly them.
pub fn on_boundary(b: &NamedBoundaries, name: &str, x0: [f64; 2], h: f64) -> bool {
    b.distance(name, x0).is_ok_and(|d| d <= 1e-6 * h)
}

pub struct Model {
    /// The scene's materials, in its `[[material]]` order (a particle's `material` indexes it).
    pub materials: Vec<Box<dyn Material>>,
    /// Bulk modulus of each material (the mixed kernel's pressure–volume relation).
    pub bulk: Vec<f64>,
    pub kernel: Kernel,
    /// Body force per unit volume of each material at load factor 1.
    pub body_force: Vec<[f64; 2]>,
    /// Selector tolerance: 1e-9 of the body's size.
    pub tol: f64,
    /// The `[[rigid]]` bodies, in scene order.
    pub bodies: Vec<RigidBody>,
    /// The named zone edges that `on =` selections pick.
    pub boundaries: NamedBoundaries,
    /// The zones as drawn, with each one's material (empty for a body of rectangles).
    pub zones: Vec<(crate::geometry::Shape, u32)>,
    pub scene: Scene,
}

impl Model {
    pub fn new(scene: &Scene) -> Result<Model, String> {
        let m = &scene.material;
        let materials = materials_of(scene)?;
        // Incompressible plastic flow locks the displacement-only element.
        let mixed_default = materials.iter().any(|m| m.yields());
        let mixed = match scene.solver.element {
            ElementChoice::Auto => mixed_default,
            ElementChoice::P2 => false,
            ElementChoice::P2p1 => true,
        };
        let g = m.young / (2.0 * (1.0 + m.poisson));
        let kernel = if mixed {
            Kernel::P2P1 {
                scale: g / scene.mesh.h,
            }
        } else {
            Kernel::P2
        };
        let [[x0, y0], [x1, y1]] = scene.bounding_box();
        let size = (x1 - x0)
            .abs()
            .max((y1 - y0).abs())
            .max(x0.abs())
            .max(y0.abs());
        let mut bodies = Vec::with_capacity(scene.rigid.len());
        for (i, r) in scene.rigid.iter().enumerate() {
            let shape = crate::scene::validate_rigid::shape_of(scene, i)
                .map_err(|(path, e)| format!("{path}: {e}"))?;
            bodies.push(RigidBody::new(r, shape, m.cu, scene.steps.count));
        }
        let shapes = crate::scene::zones::shapes(scene).unwrap_or_default();
        let zones = shapes
            .into_iter()
            .zip(&scene.body.zones)
            .map(|(shape, z)| {
                let m = z
                    .material
                    .as_deref()
                    .and_then(|n| scene.material.index_of(n));
                (shape, m.unwrap_or(0) as u32)
            })
            .collect();
        Ok(Model {
            zones,
            boundaries: named_boundaries(scene),
            bodies,
            materials,
            bulk: (m.all().iter())
                .map(|m| m.young / (3.0 * (1.0 - 2.0 * m.poisson)))
                .collect(),
            kernel,
            body_force: (m.all().iter())
                .map(|m| {
                    [
                        m.density * scene.gravity.g[0],
                        m.density * scene.gravity.g[1],
                    ]
                })
                .collect(),
            tol: 1e-9 * size.max(1.0),
            scene: scene.clone(),
        })
    }

    /// Whether a material can yield (Newton then backtracks).
    pub fn plastic(&self) -> bool {
        self.materials.iter().any(|m| m.yields())
    }

    /// The layout of every state row of the run.
    pub fn layout(&self) -> StateLayout {
        self.materials[0].layout()
    }

    /// The laws of the materials at load factor `lambda`, in scene order.
    pub fn laws(&self, lambda: f64) -> Vec<Law<'_>> {
        (0..self.materials.len())
            .map(|i| Law {
                material: self.materials[i].as_ref(),
                bulk: self.bulk[i],
                body_force: self.body_force_at(i, lambda),
            })
            .collect()
    }

    pub fn mixed(&self) -> bool {
        matches!(self.kernel, Kernel::P2P1 { .. })
    }

    /// The pressure unknowns of the element on a mesh whose triangles have the materials
    /// `tri_material`: one per vertex and material of the triangles around it where the scene
    /// has several materials, so that the pressure may jump across their interfaces.
    pub fn pressure<'a>(&self, tri_material: &'a [u32]) -> Pressure<'a> {
        if !self.mixed() {
            Pressure::None
        } else if self.materials.len() > 1 {
            Pressure::PerMaterial(tri_material)
        } else {
            Pressure::Continuous
        }
    }

    /// The body force of material `material` at load factor `lambda`: `density * g`, scaled by
    /// `lambda` under `gravity.ramp`.
    pub fn body_force_at(&self, material: usize, lambda: f64) -> [f64; 2] {
        let b = self.body_force[material];
        if self.scene.gravity.ramp {
            b.map(|b| lambda * b)
        } else {
            b
        }
    }

    /// The time (s) at load factor `lambda`, when the scene gives its steps a time
    /// ([`crate::scene::clock`]).
    pub fn seconds_at(&self, lambda: f64) -> Option<f64> {
        crate::scene::clock::time_at(&self.scene, lambda)
    }

    /// Load factor at the end of `step` (equal increments).
    pub fn load_factor(&self, step: u64) -> f64 {
        step as f64 / self.scene.steps.count as f64
    }

    /// How far the last step's increment, kept per whole step, goes towards the increment
    /// from load factor `from` to `to`: the pieces' ratio `(to − from) · steps`, times the
    /// factor by which the rigid bodies' motion now is a multiple of their motion just before
    /// `from`, where it is one (a stage that reverses, speeds up, slows down or holds them
    /// along the same line). Where a stage reverses a body (a cycled T-bar) the last increment
    /// points the wrong way: scaled by +1 it started the softening T-bar's first step down
    /// with the clay under the bar 0.74 mm (0.15 spacing) inside it, and no piece down to 1/64
    /// of the step converged (bench/VALIDATION.md, fourteenth session). A stage that turns a
    /// body (the pipeline's and the untuned footing's drag) keeps the plain ratio: its
    /// projection (zero) was tried, and the untuned rough footing's first drag step then
    /// converged on 2 ranks and crawled and was cut on 1, where with the plain ratio both cut
    /// alike.
    pub fn predictor_scale(&self, from: f64, to: f64) -> f64 {
        let steps = self.scene.steps.count as f64;
        let ratio = (to - from) * steps;
        // Pieces are at least 1/64 of a step and a stage changes only at a step's end, so the
        // last 1/64 of a step before `from` moved like the last increment did.
        let back = 1.0 / (64.0 * steps);
        if from - back < 0.0 {
            return ratio;
        }
        let (mut along, mut last, mut now2) = (0.0, 0.0, 0.0);
        for b in &self.bodies {
            let [a, c, d] = [from - back, from, to].map(|l| b.displacement(l));
            let before = [(c[0] - a[0]) / back, (c[1] - a[1]) / back];
            let now = [(d[0] - c[0]) / (to - from), (d[1] - c[1]) / (to - from)];
            along += before[0] * now[0] + before[1] * now[1];
            last += before[0] * before[0] + before[1] * before[1];
            now2 += now[0] * now[0] + now[1] * now[1];
        }
        let collinear = along * along >= (1.0 - 1e-9) * last * now2;
        // A stage that holds the bodies is collinear with factor 0.
        if last > 0.0 && collinear {
            ratio * along / last
        } else {
            ratio
        }
    }

    /// Prescribed displacement increment, from load factor `from` to `to`, of a particle at
    /// reference position `x0` and current position `x`.
    pub fn step_bc(&self, x0: [f64; 2], x: [f64; 2], from: f64, to: f64) -> [Option<f64>; 2] {
        let mut bc = [None, None];
        for f in &self.scene.fixed {
            if self.fixes(f, x0) {
                for d in &f.dofs {
                    bc[d.index()] = Some(0.0);
                }
            }
        }
        for p in &self.scene.prescribed {
            if !self.selects(p, x0, x, from) {
                continue;
            }
            for d in &p.dofs {
                let c = d.index();
                bc[c] = Some(match p.select {
                    Selection::Initial => p.total[c] * (to - from),
                    // Onto the platen's face where it will be: a particle that has just reached
                    // the platen is put on it.
                    Selection::Current => face(p, c) + p.total[c] * to - x[c],
                });
            }
        }
        // On the axis of an axisymmetric body a radial displacement would open a hole (or
        // pass through the axis): symmetry holds it, whatever the scene says.
        if self.scene.analysis.has_hoop() && x[0].abs() <= self.tol {
            bc[0] = Some(0.0);
        }
        bc
    }

    /// Whether a particle (reference position `x0`, current `x`) is driven by the first
    /// `[[prescribed]]` entry (the footing, the top platen) at load factor `lambda`: history
    /// reports the force on it.
    pub fn in_first_prescribed(&self, x0: [f64; 2], x: [f64; 2], lambda: f64) -> bool {
        self.scene
            .prescribed
            .first()
            .is_some_and(|p| self.selects(p, x0, x, lambda))
    }

    /// Whether a particle is in set `set`: the `[[fixed]]` entries, then the `[[prescribed]]`
    /// ones, in scene order.
    pub fn in_set(&self, set: usize, x0: [f64; 2], x: [f64; 2], lambda: f64) -> bool {
        let nf = self.scene.fixed.len();
        if set < nf {
            self.fixes(&self.scene.fixed[set], x0)
        } else {
            self.scene
                .prescribed
                .get(set - nf)
                .is_some_and(|p| self.selects(p, x0, x, lambda))
        }
    }

    /// Whether `[[fixed]]` entry `f` holds a particle starting at `x0`.
    fn fixes(&self, f: &Fixed, x0: [f64; 2]) -> bool {
        f.region.matches(x0, self.tol) && self.on(f.on.as_deref(), x0)
    }

    /// Whether `x0` lies on the named boundary (true without a name).
    pub fn on(&self, name: Option<&str>, x0: [f64; 2]) -> bool {
        name.is_none_or(|n| on_boundary(&self.boundaries, n, x0, self.scene.mesh.h))
    }

    fn selects(&self, p: &Prescribed, x0: [f64; 2], x: [f64; 2], lambda: f64) -> bool {
        match p.select {
            Selection::Initial => p.region.matches(x0, self.tol) && self.on(p.on.as_deref(), x0),
            Selection::Current => {
                let mut back = x;
                for d in &p.dofs {
                    back[d.index()] -= p.total[d.index()] * lambda;
                }
                p.region.matches(back, self.tol)
            }
        }
    }
}

/// The initial face of a `select = "current"` platen along component `c`: the one finite bound
/// of `where` (validation guarantees it).
fn face(p: &Prescribed, c: usize) -> f64 {
    let axis = if c == 0 { Axis::X } else { Axis::Y };
    let (lo, hi) = p.region.interval(axis);
    if lo.is_finite() {
        lo
    } else {
        hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene;

    #[test]
    fn predictor_follows_the_bodies_motion_across_stages() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9 * b.abs().max(1.0);
        // 120 steps down, then 240 up, 240 down, ...: 4 920 steps.
        let (scene, _) = load_scene("tbar-softening", &[]).unwrap();
        let model = Model::new(&scene).unwrap();
        let at = |step: f64| step / 4920.0;
        // The second stage goes up at half the first's speed per step: 0.06 m in 240 steps
        // against 0.06 m in 120; the third down at 0.12 m in 240.
        let cases = [
            ("first step", 0.0, 1.0, 1.0),
            ("within a stage", 5.0, 6.0, 1.0),
            ("a piece", 5.0, 5.25, 0.25),
            ("reversal", 120.0, 121.0, -0.5),
            ("piece after it", 120.5, 121.0, 0.5),
            ("next reversal", 360.0, 360.5, -1.0),
        ];
        for (what, from, to, want) in cases {
            let got = model.predictor_scale(at(from), at(to));
            assert!(close(got, want), "{what}: {got} against {want}");
        }
        // The pipeline turns from vertical (0.02 m in 50 steps) to lateral.
        let (scene, _) = load_scene("pipeline", &[]).unwrap();
        let model = Model::new(&scene).unwrap();
        let full = 1.0 / 250.0;
        assert!(
            close(model.predictor_scale(50.0 * full, 51.0 * full), 1.0),
            "a turn"
        );
        assert!(close(model.predictor_scale(51.0 * full, 52.0 * full), 1.0));
        // Without bodies, proportional loading.
        let (scene, _) = load_scene("cantilever", &[]).unwrap();
        let model = Model::new(&scene).unwrap();
        assert!(close(
            model.predictor_scale(0.3, 0.35),
            0.05 * scene.steps.count as f64
        ));
    }

    #[test]
    fn rigid_platen_takes_particles_that_reach_it_onto_its_face() {
        // Top platen "y >= 1", total -0.25 over the run, `select = "current"`.
        let (scene, _) = load_scene("block-compression", &[]).unwrap();
        let model = Model::new(&scene).unwrap();
        let (from, to) = (0.4, 0.41);
        let face_to = 1.0 - 0.25 * to;
        // On the face: moves with the platen.
        let on = [0.3, 1.0 - 0.25 * from];
        let bc = model.step_bc([0.3, 1.0], on, from, to);
        assert!((bc[1].unwrap() - (face_to - on[1])).abs() < 1e-15);
        assert!((bc[1].unwrap() + 0.25 * 0.01).abs() < 1e-12);
        assert_eq!(bc[0], None, "smooth: horizontally free");
        // A side particle that bulged past the face is put back on it.
        let past = [1.2, 1.0 - 0.25 * from + 0.003];
        let bc = model.step_bc([1.0, 0.9], past, from, to);
        assert!((past[1] + bc[1].unwrap() - face_to).abs() < 1e-15);
        // One still below the face is free, whatever its initial position.
        let below = [0.5, 1.0 - 0.25 * from - 0.01];
        assert_eq!(model.step_bc([0.5, 1.0], below, from, to), [None, None]);
        assert!(model.in_first_prescribed([1.0, 0.9], past, from));
        assert!(!model.in_first_prescribed([0.5, 1.0], below, from));
    }
}
