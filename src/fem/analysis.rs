//! The analysis type: which 3-D body a 2-D mesh stands for.
//!
//! - Plane strain: a slice of unit thickness of a body that is long in z; F_zz = 1, and every
//!   integral is per metre of length.
//! - Axisymmetric: x is the radius r ≥ 0, y the axis of revolution, and the mesh is the
//!   meridian section of a body of revolution loaded symmetrically. A radial displacement u_r
//!   stretches the hoop by F_θθ = 1 + u_r/r, and every integral is over the whole circle
//!   (dV = 2π r dA, dΓ = 2π r ds), so forces and reactions are those of the whole body.
//!
//! The element kernels take this one value; nothing else in the code branches on it except
//! where a 3-D quantity is reported or the axis needs its symmetry condition.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which 3-D body the 2-D mesh stands for; see the module docs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Analysis {
    /// A slice of unit thickness (m) of a long body; F_zz = 1. The default.
    #[default]
    PlaneStrain,
    /// x is the radius r ≥ 0, y the axis of revolution; integrals over the whole circle.
    Axisymmetric,
}

impl Analysis {
    /// Volume (or surface) measure per unit area (or length) of the section at radius `x`:
    /// 1 in plane strain (unit thickness), 2π r in axisymmetry (the whole circle).
    #[inline]
    pub fn measure(self, x: f64) -> f64 {
        match self {
            Analysis::PlaneStrain => 1.0,
            Analysis::Axisymmetric => 2.0 * PI * x,
        }
    }

    /// Whether the hoop direction stretches with the radial displacement.
    #[inline]
    pub fn has_hoop(self) -> bool {
        self == Analysis::Axisymmetric
    }

    /// The name in case files and logs.
    pub fn name(self) -> &'static str {
        match self {
            Analysis::PlaneStrain => "plane-strain",
            Analysis::Axisymmetric => "axisymmetric",
        }
    }
}

/// The hoop stretch at a point of start-of-step radius `r` with radial step displacement `ur`:
/// h_θ = u_r / r, F_θθ = 1 + h_θ (0 in plane strain).
#[inline]
pub fn hoop_gradient(analysis: Analysis, r: f64, ur: f64) -> f64 {
    if analysis.has_hoop() {
        ur / r
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn measures_are_unit_thickness_and_the_whole_circle() {
        assert_eq!(Analysis::PlaneStrain.measure(3.0), 1.0);
        assert!((Analysis::Axisymmetric.measure(0.5) - PI).abs() < 1e-15);
        assert_eq!(Analysis::default(), Analysis::PlaneStrain);
    }

    #[test]
    fn case_file_names_round_trip() {
        #[derive(Serialize, Deserialize)]
        struct S {
            analysis: Analysis,
        }
        for a in [Analysis::PlaneStrain, Analysis::Axisymmetric] {
            let text = toml::to_string(&S { analysis: a }).expect("serialises");
            assert!(text.contains(a.name()), "{text}");
            let back: S = toml::from_str(&text).expect("parses");
            assert_eq!(back.analysis, a);
        }
    }
}
