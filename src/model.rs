//! What a scene means for the solver: material, supports, prescribed motion, loads.

use crate::material::elastic::LinearElastic;
use crate::material::Material;
use crate::scene::{MaterialModel, Scene};

pub struct Model {
    pub material: Box<dyn Material>,
    pub body_force: [f64; 2],
    /// Selector tolerance: 1e-9 of the body's size.
    pub tol: f64,
    pub scene: Scene,
}

impl Model {
    pub fn new(scene: &Scene) -> Result<Model, String> {
        let m = &scene.material;
        let material: Box<dyn Material> = match m.model {
            MaterialModel::LinearElastic => Box::new(
                LinearElastic::new(m.young, m.poisson).map_err(|e| format!("material: {e}"))?,
            ),
            MaterialModel::Tresca => {
                return Err("material.model: \"tresca\" is not available in this build yet".into())
            }
        };
        let mut size: f64 = 0.0;
        for r in &scene.body.rectangles {
            size = size
                .max(r.size[0])
                .max(r.size[1])
                .max(r.origin[0].abs())
                .max(r.origin[1].abs());
        }
        Ok(Model {
            material,
            body_force: [
                m.density * scene.gravity.g[0],
                m.density * scene.gravity.g[1],
            ],
            tol: 1e-9 * size.max(1.0),
            scene: scene.clone(),
        })
    }

    /// Load factor at the end of `step` (equal increments).
    pub fn load_factor(&self, step: u64) -> f64 {
        step as f64 / self.scene.steps.count as f64
    }

    /// Prescribed displacement increment of a step for a particle at reference position `x`.
    pub fn step_bc(&self, x: [f64; 2]) -> [Option<f64>; 2] {
        let mut bc = [None, None];
        for f in &self.scene.fixed {
            if f.region.matches(x, self.tol) {
                for d in &f.dofs {
                    bc[d.index()] = Some(0.0);
                }
            }
        }
        let n = self.scene.steps.count as f64;
        for p in &self.scene.prescribed {
            if p.region.matches(x, self.tol) {
                for d in &p.dofs {
                    bc[d.index()] = Some(p.total[d.index()] / n);
                }
            }
        }
        bc
    }
}
