//! A rigid body of the scene at any load factor.

use super::shape::Shape;
use crate::scene::Rigid;

#[derive(Debug, Clone)]
pub struct RigidBody {
    pub name: String,
    /// Shape at the initial position.
    pub initial: Shape,
    /// Largest interface shear stress (Pa): adhesion * cu; 0 for a smooth body.
    pub shear_limit: f64,
    /// Suction the interface carries before it separates (Pa, >= 0).
    pub suction: f64,
    /// Whether the soil gets a node on each of the body's unresolved corners.
    pub corner_nodes: bool,
    motion: Rigid,
    /// Steps of the whole run: load factor 1 is the end of the last step.
    steps: f64,
}

impl RigidBody {
    pub fn new(spec: &Rigid, initial: Shape, cu: f64, steps: u32) -> RigidBody {
        RigidBody {
            name: spec.name.clone(),
            initial,
            shear_limit: spec.adhesion * cu,
            suction: spec.ambient_pressure,
            corner_nodes: spec.polygon.as_ref().is_some_and(|p| p.corner_nodes),
            motion: spec.clone(),
            steps: steps as f64,
        }
    }

    /// Displacement from the initial position at load factor `lambda`.
    pub fn displacement(&self, lambda: f64) -> [f64; 2] {
        self.motion.displacement_at(lambda * self.steps)
    }

    /// The shape where the body is at load factor `lambda`.
    pub fn shape(&self, lambda: f64) -> Shape {
        self.initial.translated(self.displacement(lambda))
    }
}
