//! Scene tables for rigid bodies pushed into the soil, their contact, surface pressure and the
//! geostatic initial stress (`[[rigid]]`, `[contact]`, `[[surface_pressure]]`, `[geostatic]`),
//! and the named measurements `history.csv` records (`[[probe]]`, `[[history.columns]]`).

use serde::{Deserialize, Serialize};

use super::selector::Selector;

/// `[[rigid]]`: a rigid, convex body moved by stages. Exactly one of `circle` and `polygon`.
///
/// ```toml
/// [[rigid]]
/// name = "pipe"
/// circle = { centre = [0.24, 0.22], radius = 0.02 }
/// stages = [ { to = [0.0, -0.02], steps = 50 }, { to = [0.08, -0.02], steps = 200 } ]
/// adhesion = 0.0
/// ```
///
/// A half model (symmetry plane through the body) gives the whole shape: the soil lies on one
/// side of the plane, so only that half is ever touched, and the body's force is the half
/// model's (a history column's `scale` doubles it for the whole body).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rigid {
    /// Name used by history measures (`rigid.NAME.fy`), unique among the bodies.
    pub name: String,
    /// A circle: `{ centre = [x, y], radius = r }` (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub circle: Option<Circle>,
    /// A convex polygon, optionally with rounded corners: `{ vertices = [[x, y], ...],
    /// corner_radius = 0.0 }` (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon: Option<Polygon>,
    /// The motion: each stage moves the body linearly, over `steps` steps, to the displacement
    /// `to` (m, from the initial position). The body holds still after its last stage; the
    /// scene's step count is the longest body's stage total. Default: no motion.
    #[serde(default)]
    pub stages: Vec<Stage>,
    /// Interface adhesion factor α, 0 <= α <= 1: the interface shear stress is limited to
    /// α·cu (stick below, slip at the limit). 0 = smooth (default), 1 = fully rough.
    #[serde(default)]
    pub adhesion: f64,
    /// Uniform pressure the soil around the body is under (Pa, default 0): a surcharge on
    /// weightless clay, which changes no stress difference. The soil is modelled without it
    /// (its stresses are the excess over it) and the interface carries suction up to it before
    /// it separates, as it would under the surcharge. At most 1000 `material.young`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub ambient_pressure: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Circle {
    pub centre: [f64; 2],
    pub radius: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Polygon {
    /// Corners of the convex polygon (either orientation), at least 3.
    pub vertices: Vec<[f64; 2]>,
    /// Radius of the rounded corners (m), default 0 (sharp).
    #[serde(default)]
    pub corner_radius: f64,
    /// A mesh node on each corner that the soil wraps (default true): where the corner's
    /// rounding is below the particle spacing, the boundary particle nearest to the corner
    /// (within 0.3 spacing) is moved onto it at every remesh and takes the soil's state there,
    /// so that the soil's boundary bends where the body does as the soil flows past. `false`
    /// leaves a corner to the particles that pass it: for a corner whose soil falls away
    /// behind it (a spudcan's rim, where the free surface beside the rim's top would be drawn
    /// down with it).
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub corner_nodes: bool,
}

fn yes() -> bool {
    true
}

fn is_true(x: &bool) -> bool {
    *x
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stage {
    /// Displacement of the body from its initial position at the end of the stage (m).
    pub to: [f64; 2],
    /// Steps the stage takes, >= 1.
    pub steps: u32,
    /// How long the stage takes (s, > 0), its steps evenly: gives the steps a time, which a
    /// rate-dependent material needs. Optional; not with `velocity`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration: Option<f64>,
    /// The body's speed along the stage (m/s, > 0): the stage lasts its travel over `velocity`.
    /// Optional; not with `duration`. When one stage of a body is timed, all its stages are,
    /// and only one body's stages may be, the one whose stages set the step count.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<f64>,
}

/// `[contact]`: the contact law every rigid body shares, solved inside each Newton iteration
/// (see `rigid::contact`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Contact {
    /// The complementarity constant c as a multiple of E/h (h the spacing at the node), 1 to
    /// 1e7: how a node's pressure is weighed against its gap, and its shear against its slip,
    /// when Newton decides, away from the solution, whether it touches (p − c g > 0) and
    /// whether it sticks. The converged answer does not depend on it. Default 1: at 1000 a
    /// rough platen's nodes flipped between slipping either way on slips of 1e-8 m and Newton
    /// never converged (tests/contact.rs, the stick step).
    pub penalty: f64,
    /// A converged increment must hold every touching node on the body's face, and keep every
    /// free one out of it, to this fraction of its spacing, 1e-9 to 0.01; else Newton goes on
    /// from there (at most twice, each time to `solver.newton_rtol` of the residual there),
    /// then a smaller increment is tried. Default 1e-6.
    pub tolerance: f64,
    /// No longer read (it bounded the augmentation loop that Newton's active set replaced);
    /// accepted so that older scenes load, with a warning at `new`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_augmentations: Option<u32>,
    /// Carry which nodes touch across the remesh by node identity: a node that touched at the
    /// end of the last increment may hold suction in this one. Default true.
    pub carry_state: bool,
}

impl Default for Contact {
    fn default() -> Self {
        Contact {
            penalty: 1.0,
            tolerance: 1e-6,
            max_augmentations: None,
            carry_state: true,
        }
    }
}

/// `[[surface_pressure]]`: a uniform pressure (compression positive) on the boundary edges
/// whose two end particles started in `where`, found again after every remesh and following
/// the edges as they move (a follower load). Constant over the run: with `[geostatic]` the
/// surcharge is in equilibrium from step 1.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfacePressure {
    /// Optional with `on`; at least one of the two.
    #[serde(
        rename = "where",
        default = "Selector::all",
        skip_serializing_if = "Selector::has_no_conditions"
    )]
    pub region: Selector,
    /// `on = "crest"`: the boundary edges whose two ends started on the named boundary (a zone
    /// edge name or a Gmsh physical curve), and in `where` if given too.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub on: Option<String>,
    /// `within = [[x, y], ...]`: only particles inside this polygon (edges included, within
    /// 1e-9 of the body's size), e.g. a sloping face; with `where` and `on`, all must hold.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub within: Option<Vec<[f64; 2]>>,
    /// Pa.
    pub pressure: f64,
}

/// `[geostatic]`: the initial stress of a level ground: vertical σ_v = −(surcharge + γ·(surface
/// − y)) with γ = density·|g|, horizontal and out-of-plane K0·σ_v (compression negative).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Geostatic {
    /// Level of the ground surface (m).
    pub surface: f64,
    /// Pressure on the surface (Pa), default 0; pair it with a `[[surface_pressure]]`.
    #[serde(default)]
    pub surcharge: f64,
    /// Coefficient of earth pressure at rest, default 1.
    #[serde(default = "one")]
    pub k0: f64,
    /// Bring the column stresses into equilibrium with gravity, the supports and the surface
    /// pressures before step 1, as Abaqus' geostatic step does: Newton solves at the starting
    /// load factor whose stresses are kept and whose displacements are dropped (the particles
    /// stay where they were drawn). Needed on sloping ground, where column weights are not in
    /// equilibrium. Default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub equilibrate: bool,
}

fn one() -> f64 {
    1.0
}

/// `[[probe]]`: a particle whose displacement history measures read (`probe.NAME.ux`): the one
/// nearest to `at` when the case is created (on the boundary `on` if given), like a point
/// load's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Probe {
    pub name: String,
    pub at: [f64; 2],
    /// `on = "crest"`: the nearest particle to `at` among those on the named boundary.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub on: Option<String>,
}

/// `[[history.columns]]`: one column of `history.csv`, `scale * measure`.
///
/// Measures: `load_factor`, `time` (s, when the scene gives its steps a time: `steps.duration`
/// or timed `[[rigid]]` stages; else the load factor), `area` (body area, m²), `probe.NAME.ux|uy`,
/// `rigid.NAME.ux|uy` (the body's displacement), `rigid.NAME.fx|fy` (the force the soil puts on
/// the body: the sum of the contact tractions, N/m), `rigid.NAME+NAME.fx|fy` (the sum over
/// bodies moved together, such as a cone and its shaft), `reaction.NAME.fx|fy` (the force on
/// the particles of a named `[[fixed]]` or `[[prescribed]]` set).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Column {
    pub name: String,
    pub measure: String,
    /// Default 1.
    #[serde(default = "one")]
    pub scale: f64,
    /// Horizontal reference lines drawn on the plot of this column: `[{ value = 9.142,
    /// label = "exact" }]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub reference: Vec<ReferenceLine>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceLine {
    pub value: f64,
    pub label: String,
}

/// A parsed history measure.
#[derive(Debug, Clone, PartialEq)]
pub enum Measure {
    LoadFactor,
    Time,
    Area,
    Probe(String, usize),
    RigidDisplacement(String, usize),
    /// The force on one body, or the sum over bodies moved together (`rigid.cone+shaft.fy`).
    RigidForce(Vec<String>, usize),
    Reaction(String, usize),
}

impl Measure {
    pub fn parse(text: &str) -> Result<Measure, String> {
        let comp = |c: &str, a: &str, b: &str| match c {
            _ if c == a => Some(0),
            _ if c == b => Some(1),
            _ => None,
        };
        let parts: Vec<&str> = text.split('.').collect();
        let bad = || {
            format!(
                "unknown measure \"{text}\" (expected load_factor, time, area, probe.NAME.ux|uy, \
                 rigid.NAME.ux|uy|fx|fy, rigid.NAME+NAME.fx|fy or \
                 reaction.NAME.fx|fy)"
            )
        };
        match parts.as_slice() {
            ["load_factor"] => Ok(Measure::LoadFactor),
            ["time"] => Ok(Measure::Time),
            ["area"] => Ok(Measure::Area),
            ["probe", n, c] => comp(c, "ux", "uy")
                .map(|i| Measure::Probe(n.to_string(), i))
                .ok_or_else(bad),
            ["rigid", n, c] => {
                let names: Vec<String> = n.split('+').map(str::to_string).collect();
                if names.iter().any(String::is_empty) {
                    return Err(bad());
                }
                match (comp(c, "ux", "uy"), comp(c, "fx", "fy")) {
                    (Some(i), _) if names.len() == 1 => {
                        Ok(Measure::RigidDisplacement(n.to_string(), i))
                    }
                    (_, Some(i)) => Ok(Measure::RigidForce(names, i)),
                    _ => Err(bad()),
                }
            }
            ["reaction", n, c] => comp(c, "fx", "fy")
                .map(|i| Measure::Reaction(n.to_string(), i))
                .ok_or_else(bad),
            _ => Err(bad()),
        }
    }
}

impl Rigid {
    /// Steps of all stages.
    pub fn stage_steps(&self) -> u64 {
        self.stages.iter().map(|s| s.steps as u64).sum()
    }

    /// Displacement of the body after `step` steps (fractional within a step: linear).
    pub fn displacement_at(&self, step: f64) -> [f64; 2] {
        let mut from = [0.0; 2];
        let mut start = 0.0;
        for s in &self.stages {
            let end = start + s.steps as f64;
            if step <= end {
                let t = ((step - start) / s.steps as f64).clamp(0.0, 1.0);
                return [
                    from[0] + t * (s.to[0] - from[0]),
                    from[1] + t * (s.to[1] - from[1]),
                ];
            }
            from = s.to;
            start = end;
        }
        from
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stages_are_reached_linearly_and_held() {
        let r = Rigid {
            name: "pipe".into(),
            circle: None,
            polygon: None,
            stages: vec![
                Stage {
                    to: [0.0, -0.02],
                    steps: 50,
                    duration: None,
                    velocity: None,
                },
                Stage {
                    to: [0.08, -0.02],
                    steps: 200,
                    duration: None,
                    velocity: None,
                },
            ],
            adhesion: 0.0,
            ambient_pressure: 0.0,
        };
        assert_eq!(r.stage_steps(), 250);
        assert_eq!(r.displacement_at(25.0), [0.0, -0.01]);
        assert_eq!(r.displacement_at(50.0), [0.0, -0.02]);
        let d = r.displacement_at(150.0);
        assert!((d[0] - 0.04).abs() < 1e-15 && d[1] == -0.02);
        assert_eq!(r.displacement_at(300.0), [0.08, -0.02]);
    }

    #[test]
    fn measures_parse() {
        assert_eq!(
            Measure::parse("rigid.tbar.fy"),
            Ok(Measure::RigidForce(vec!["tbar".into()], 1))
        );
        assert_eq!(
            Measure::parse("rigid.cone+shaft.fy"),
            Ok(Measure::RigidForce(vec!["cone".into(), "shaft".into()], 1))
        );
        assert!(Measure::parse("rigid.cone+shaft.uy").is_err());
        assert!(Measure::parse("rigid.cone+.fy").is_err());
        assert_eq!(
            Measure::parse("probe.tip.ux"),
            Ok(Measure::Probe("tip".into(), 0))
        );
        assert!(Measure::parse("rigid.tbar.fz").is_err());
        assert!(Measure::parse("force").is_err());
    }
}
