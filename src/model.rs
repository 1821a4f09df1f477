//! What a scene means for the solver: material, element, supports, prescribed motion, loads.

use crate::material::elastic::LinearElastic;
use crate::material::tresca::Tresca;
use crate::material::Material;
use crate::scene::{ElementChoice, MaterialModel, Scene};
use crate::solve::Kernel;

pub struct Model {
    pub material: Box<dyn Material>,
    pub kernel: Kernel,
    pub body_force: [f64; 2],
    /// Selector tolerance: 1e-9 of the body's size.
    pub tol: f64,
    pub scene: Scene,
}

impl Model {
    pub fn new(scene: &Scene) -> Result<Model, String> {
        let m = &scene.material;
        let named = |e: crate::material::MaterialError| format!("material: {e}");
        let (material, mixed_default): (Box<dyn Material>, bool) = match m.model {
            MaterialModel::LinearElastic => (
                Box::new(LinearElastic::new(m.young, m.poisson).map_err(named)?),
                false,
            ),
            MaterialModel::Tresca => (
                Box::new(Tresca::new(m.young, m.poisson, m.cu).map_err(named)?),
                true,
            ),
        };
        let mixed = match scene.solver.element {
            ElementChoice::Auto => mixed_default,
            ElementChoice::P2 => false,
            ElementChoice::P2p1 => true,
        };
        let g = m.young / (2.0 * (1.0 + m.poisson));
        let kernel = if mixed {
            Kernel::P2P1 {
                bulk: m.young / (3.0 * (1.0 - 2.0 * m.poisson)),
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
        Ok(Model {
            material,
            kernel,
            body_force: [
                m.density * scene.gravity.g[0],
                m.density * scene.gravity.g[1],
            ],
            tol: 1e-9 * size.max(1.0),
            scene: scene.clone(),
        })
    }

    /// Whether the material can yield (Newton then backtracks).
    pub fn plastic(&self) -> bool {
        self.scene.material.model == MaterialModel::Tresca
    }

    pub fn mixed(&self) -> bool {
        matches!(self.kernel, Kernel::P2P1 { .. })
    }

    /// Load factor at the end of `step` (equal increments).
    pub fn load_factor(&self, step: u64) -> f64 {
        step as f64 / self.scene.steps.count as f64
    }

    /// Prescribed displacement increment for a load-factor increment `dlambda` (1/steps for a
    /// whole step) for a particle at reference position `x`.
    pub fn step_bc(&self, x: [f64; 2], dlambda: f64) -> [Option<f64>; 2] {
        let mut bc = [None, None];
        for f in &self.scene.fixed {
            if f.region.matches(x, self.tol) {
                for d in &f.dofs {
                    bc[d.index()] = Some(0.0);
                }
            }
        }
        for p in &self.scene.prescribed {
            if p.region.matches(x, self.tol) {
                for d in &p.dofs {
                    bc[d.index()] = Some(p.total[d.index()] * dlambda);
                }
            }
        }
        bc
    }

    /// Whether a particle at reference position `x` is driven by the first `[[prescribed]]`
    /// entry (the footing, the top platen): history reports the force on it.
    pub fn in_first_prescribed(&self, x: [f64; 2]) -> bool {
        self.scene
            .prescribed
            .first()
            .is_some_and(|p| p.region.matches(x, self.tol))
    }
}
