//! Scenes: the problem description a user runs, as a TOML document (SI units).
//!
//! A scene is either a built-in (`cantilever`, `footing`, ...: [`BUILTINS`]) or a `.toml`
//! file. `--set a.b.c=value` overrides are applied to the TOML tree before it is read,
//! and every table rejects unknown keys, so typos are errors that name the key. Layout:
//!
//! ```toml
//! name = "cantilever"
//! [body]                # union of axis-aligned rectangles filled with a particle lattice
//! rectangles = [ { origin = [0.0, 0.0], size = [10.0, 1.0] } ]
//! [mesh]
//! h = 0.125             # particle spacing (m)
//! alpha = 1.3           # alpha shape: keep triangles with circumradius <= alpha*h (default 1.3)
//! refine = true         # particle insertion/removal (default true)
//! smooth = false        # Laplacian smoothing of interior particles (default false)
//! [material]
//! model = "linear-elastic"   # or "tresca", "tresca-softening", "mohr-coulomb", "drucker-prager"
//! young = 12.0e6             # Pa
//! poisson = 0.2
//! density = 0.0              # kg/m3 (default 0); body force = density * gravity.g
//! cu = 0.0                   # Pa, undrained shear strength, "tresca" only (default 0)
//! # "tresca-softening": cu (intact, at the reference rate), remoulded_ratio, xi95, optional
//! # rate_parameter and reference_rate (1/s; the steps then need a time: steps.duration or
//! # a duration/velocity on the [[rigid]] stages), xi95_reference_spacing (m)
//! # "mohr-coulomb" and "drucker-prager": cohesion (Pa), friction_angle and dilation_angle
//! # (degrees, dilation <= friction); tension_cutoff (Pa, "mohr-coulomb", optional);
//! # match = "plane-strain" | "outer" | "inner" ("drucker-prager", default "plane-strain")
//! [gravity]                  # optional
//! g = [0.0, 0.0]             # m/s2
//! [[fixed]]                  # zero displacement; selection re-evaluated on every remesh
//! where = "x <= 0"           # "x <= c", "x >= c", "y <= c", "y >= c" joined by "and"
//! dofs = ["x", "y"]
//! [[point_load]]             # force on the particle nearest to `at` when the case is created
//! at = [10.0, 0.5]
//! force = [0.0, -100.0e3]    # N per metre thickness at load factor 1
//! [[prescribed]]             # imposed displacement of the selected particles
//! where = "y >= 10 and x <= 1"
//! dofs = ["y"]
//! total = [0.0, -0.1]        # m, reached at the end of loading, applied linearly
//! [steps]
//! count = 50
//! # duration = 10.0         # s for the whole run (optional): a time for rate-dependent clay
//! [history]
//! kind = "cantilever"        # "cantilever" | "footing" | "block": history.csv columns
//! [output]                   # optional
//! checkpoint_every = 0       # 0 = only at the end (default 0)
//! checkpoint_keep = 3        # (default 3)
//! [solver]                   # optional
//! newton_max_it = 25         # (default 25)
//! newton_rtol = 1e-9         # (default 1e-9)
//! linear = "auto"            # "auto" | "direct" | "iterative" (default "auto", by size)
//! symmetric = true          # LDLᵀ for symmetric (elastic P2) tangents (default true)
//! reuse_factorisation = false # keep LU factors while Newton converges fast (default false)
//! ```
//!
//! The field-by-field reference, with the validation rules, is on the types in [`schema`].

#[path = "scene/builtin.rs"]
pub mod builtin;

/// The time of the steps (`steps.duration`, timed `[[rigid]]` stages).
#[path = "scene/clock.rs"]
pub mod clock;
#[path = "scene/error.rs"]
mod error;
#[path = "scene/field_path.rs"]
pub mod field_path;
#[path = "scene/gmsh_body.rs"]
mod gmsh_body;
#[path = "scene/lattice.rs"]
pub mod lattice;
#[path = "scene/overrides.rs"]
mod overrides;
#[path = "scene/rigid.rs"]
pub mod rigid;
#[path = "scene/schema.rs"]
pub mod schema;
#[path = "scene/selector.rs"]
pub mod selector;
#[path = "scene/validate.rs"]
mod validate;
#[path = "scene/validate_axisymmetry.rs"]
mod validate_axisymmetry;
#[path = "scene/validate_fine.rs"]
mod validate_fine;
#[path = "scene/validate_loads.rs"]
mod validate_loads;
#[path = "scene/validate_motion.rs"]
mod validate_motion;
#[path = "scene/validate_rigid.rs"]
pub mod validate_rigid;
#[path = "scene/validate_supports.rs"]
mod validate_supports;
#[path = "scene/validate_umat.rs"]
mod validate_umat;
#[path = "scene/value_de.rs"]
mod value_de;
pub mod zones;

use std::borrow::Cow;
use std::path::Path;

use serde::Deserialize;

pub use builtin::{builtin, builtin_names, BUILTINS};
pub use error::SceneError;
pub use lattice::generate_particles;
pub use rigid::{
    Circle, Column, Contact, Geostatic, Measure, Polygon, Probe, ReferenceLine, Rigid, Stage,
    SurfacePressure,
};
pub use schema::{
    Body, ConeMatch, Dof, ElementChoice, FineRegion, Fixed, Gravity, History, HistoryKind,
    ImportedNode, LineSearch, LinearChoice, Material, MaterialModel, Mesh, Output, PointLoad,
    Prescribed, Rectangle, Scene, Selection, Solver, Steps,
};
pub use selector::{Axis, Comparison, Condition, Selector};

use field_path::FieldPath;
use overrides::SetArg;
use value_de::{DeErrorKind, ValueDeserializer};

/// 1-based line and column of a byte offset, for TOML syntax errors.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// The `--set` argument (last one wins) whose path overlaps `path`.
fn responsible_set<'a>(sets: &'a [SetArg], path: &FieldPath) -> Option<&'a SetArg> {
    sets.iter().rev().find(|s| s.path.overlaps(path))
}

impl Scene {
    /// Parses, overrides and validates a scene from TOML text. `source` names the scene in
    /// errors (file path or built-in name); `sets` are `--set` arguments (`a.b.c=value`).
    pub fn from_toml(text: &str, source: &str, sets: &[String]) -> Result<Scene, SceneError> {
        let mut table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
            let (line, column) = line_column(text, e.span().map_or(0, |s| s.start));
            SceneError::new(
                source,
                format!(
                    "invalid TOML at line {line}, column {column}: {}",
                    e.message().trim().replace('\n', "; ")
                ),
            )
        })?;

        let mut parsed = Vec::with_capacity(sets.len());
        for raw in sets {
            let set = SetArg::parse(raw).map_err(|message| SceneError {
                set: Some(raw.clone()),
                ..SceneError::new(source, message)
            })?;
            set.apply(&mut table)
                .map_err(|(path, message)| SceneError {
                    set: Some(raw.clone()),
                    field: Some(path.to_string()),
                    ..SceneError::new(source, message)
                })?;
            parsed.push(set);
        }

        let tree = toml::Value::Table(table);
        let mut scene = Scene::deserialize(ValueDeserializer::new(&tree)).map_err(|e| {
            let set = responsible_set(&parsed, &e.path);
            let message = match (e.kind, set) {
                (DeErrorKind::UnknownKey, Some(_)) => {
                    e.message
                        .replacen("unknown key", "no such key in the scene schema", 1)
                }
                _ => e.message,
            };
            SceneError {
                set: set.map(|s| s.raw.clone()),
                field: (!e.path.is_empty()).then(|| e.path.to_string()),
                ..SceneError::new(source, message)
            }
        })?;

        let invalid = |(path, message): validate::Invalid| SceneError {
            set: responsible_set(&parsed, &path).map(|s| s.raw.clone()),
            field: Some(path.to_string()),
            ..SceneError::new(source, message)
        };
        // `young` left out beside `young_over_cu` is the stiffness at the strength `cu`.
        for m in scene.material.0.iter_mut() {
            if let (Some(ratio), true) = (m.young_over_cu, m.young.is_nan()) {
                m.young = ratio * m.cu;
            }
        }
        gmsh_body::import(&mut scene, source).map_err(invalid)?;
        validate_umat::resolve_libraries(&mut scene, source);
        zones::apply_within(&mut scene).map_err(invalid)?;
        scene.steps.count =
            validate_rigid::check_stages(&scene, scene.steps.count != 0).map_err(invalid)?;
        validate::validate(&scene).map_err(invalid)?;
        Ok(scene)
    }

    /// The complete scene, defaults included, as TOML. [`Scene::from_toml`] reads it back to an
    /// equal scene (floats are written in shortest round-trip form).
    pub fn to_toml(&self) -> String {
        // toml refuses only a None outside a table, a unit value, an invalid date, a non-string
        // key and an integer beyond i64. A Scene has none: each Option is a table field (skipped
        // when None), each key a field name, and its usize fields were read from TOML integers.
        toml::to_string(self).expect("a Scene always has a TOML representation")
    }

    /// `[[xmin, ymin], [xmax, ymax]]` of the body rectangles and zones.
    pub fn bounding_box(&self) -> [[f64; 2]; 2] {
        let empty = zones::bounding_box(&self.body.zones);
        self.body.rectangles.iter().fold(empty, |[lo, hi], r| {
            let top = [r.origin[0] + r.size[0], r.origin[1] + r.size[1]];
            [
                [lo[0].min(r.origin[0]), lo[1].min(r.origin[1])],
                [hi[0].max(top[0]), hi[1].max(top[1])],
            ]
        })
    }

    /// Boundary slack of geometric selections: 1e-9 times the body's largest dimension.
    pub fn tolerance(&self) -> f64 {
        let bb = self.bounding_box();
        1e-9 * (bb[1][0] - bb[0][0]).max(bb[1][1] - bb[0][1])
    }
}

/// The scene reference (every table and key, from the schema's doc comments), generated at
/// build time by `build/scene_reference.rs`; `pfem-mpi schema` prints it and
/// `docs/guide/scene-reference.md` is its committed copy.
pub const REFERENCE: &str = include_str!(concat!(env!("OUT_DIR"), "/scene_reference.md"));

/// The file [`load_scene`] reads for `name_or_path`, or `None` when it names a built-in (or
/// nothing).
pub fn scene_file(name_or_path: &str) -> Option<&Path> {
    let is_path = name_or_path.ends_with(".toml")
        || name_or_path.contains('/')
        || name_or_path.contains(std::path::MAIN_SEPARATOR);
    let exists = Path::new(name_or_path).exists();
    let builtin = builtin(name_or_path).is_some();
    (is_path || (!builtin && exists)).then(|| Path::new(name_or_path))
}

/// Loads a built-in scene by name or a scene file by path (anything ending in `.toml` or
/// containing a `/` is a path), applies `--set` overrides and validates. Returns the scene and
/// its resolved TOML (overrides and defaults applied), which is what a case file records.
pub fn load_scene(name_or_path: &str, sets: &[String]) -> Result<(Scene, String), SceneError> {
    let text: Cow<'static, str> = match builtin(name_or_path) {
        Some(text) if scene_file(name_or_path).is_none() => Cow::Borrowed(text),
        None if scene_file(name_or_path).is_none() => {
            return Err(SceneError::new(
                name_or_path,
                format!(
                    "no built-in scene of that name (built-ins: {}) and no such file",
                    builtin_names()
                ),
            ));
        }
        _ => Cow::Owned(std::fs::read_to_string(name_or_path).map_err(|e| {
            SceneError::new(name_or_path, format!("cannot read the scene file: {e}"))
        })?),
    };
    let scene = Scene::from_toml(&text, name_or_path, sets)?;
    let resolved = scene.to_toml();
    Ok((scene, resolved))
}

#[cfg(test)]
#[path = "scene/tests.rs"]
mod tests;

#[cfg(test)]
#[path = "scene/tests_rigid.rs"]
mod tests_rigid;
