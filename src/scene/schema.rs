//! The scene document: one struct per TOML table. Field documentation here is the reference for
//! scene authors; every table rejects unknown keys so that a typo is an error, not a silently
//! ignored setting. Units are SI throughout.

use serde::{Deserialize, Serialize};

use super::rigid::{Column, Contact, Geostatic, Probe, Rigid, SurfacePressure};
use super::selector::Selector;

/// A complete, validated problem description.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Short name shown in summaries and output.
    pub name: String,
    /// `"plane-strain"` (the default: a slice of unit thickness, forces per metre) or
    /// `"axisymmetric"` (x is the radius r ≥ 0 and y the axis of revolution; the body must lie
    /// at x ≥ 0, particles on the axis are held radially, and every force, reaction and
    /// history column is for the whole circle, in N).
    #[serde(default, skip_serializing_if = "is_plane_strain")]
    pub analysis: crate::fem::analysis::Analysis,
    pub body: Body,
    pub mesh: Mesh,
    /// `[material]`, or several named `[[material]]` tables that `body.zones` place.
    pub material: Materials,
    /// Defaults to no gravity.
    #[serde(default)]
    pub gravity: Gravity,
    /// `[[fixed]]` entries: zero-displacement supports.
    #[serde(default)]
    pub fixed: Vec<Fixed>,
    /// `[[point_load]]` entries: concentrated forces on tracked particles.
    #[serde(default)]
    pub point_load: Vec<PointLoad>,
    /// `[[prescribed]]` entries: imposed displacements (footings, platens).
    #[serde(default)]
    pub prescribed: Vec<Prescribed>,
    /// `[[rigid]]` bodies pushed into the soil, with contact.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rigid: Vec<Rigid>,
    /// `[contact]`: penalty and augmentation of the contact with every rigid body.
    #[serde(default, skip_serializing_if = "is_default_contact")]
    pub contact: Contact,
    /// `[[surface_pressure]]`: follower pressures on the free surface.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub surface_pressure: Vec<SurfacePressure>,
    /// `[geostatic]`: initial stress from self-weight, surcharge and K0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geostatic: Option<Geostatic>,
    /// `[[probe]]`: particles whose displacement history columns read.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub probe: Vec<Probe>,
    /// May be left out when `[[rigid]]` stages set the step count.
    #[serde(default)]
    pub steps: Steps,
    pub history: History,
    #[serde(default)]
    pub output: Output,
    #[serde(default)]
    pub solver: Solver,
}

fn is_plane_strain(a: &crate::fem::analysis::Analysis) -> bool {
    *a == crate::fem::analysis::Analysis::PlaneStrain
}

fn is_default_contact(c: &Contact) -> bool {
    *c == Contact::default()
}

/// `[body]`: the initial domain: a union of axis-aligned rectangles filled with a square
/// particle lattice of spacing `mesh.h`, or zones of any shape (`[[body.zones]]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// `rectangles = [ { origin = [x0, y0], size = [width, height] }, ... ]` (m). Every origin
    /// offset (from the first rectangle's origin) and every size must be a whole number of
    /// particle spacings, so that rectangle edges carry particles and adjacent rectangles share
    /// them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rectangles: Vec<Rectangle>,
    /// `[[body.zones]]`: the body as zones of any shape, instead of `rectangles`. Zones may
    /// touch (sharing edges or vertices) but not overlap. Each is filled with particles: on
    /// every boundary edge at spacing about `mesh.h` (vertices included), and a square lattice
    /// of spacing `mesh.h` (anchored at the first zone's first vertex, so touching zones share
    /// it) inside, lattice points closer than h/2 to a boundary dropped.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub zones: Vec<Zone>,
    /// `mesh = "site.msh"`: the body imported from a 2D Gmsh mesh (MSH 4.1, ASCII or binary;
    /// the path relative to the scene file). Every node of a physical surface becomes a particle
    /// whose spacing is the mean length of the mesh edges at the node; each physical surface
    /// becomes zones (one per outline, holes included) of the `[[material]]` of the same name, or
    /// of the material that a `[[body.zones]]` entry with that `name` and no shape names (with
    /// one material, every surface is of it); each physical curve names the zone edges it runs
    /// along, for `on = "..."` selections. Instead of `rectangles`; `new` resolves it into
    /// `zones` and `imported`, so a case file never needs the mesh file again.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<String>,
    /// Written by `new` in place of `mesh`: the Gmsh file the zones and particles came from. A
    /// resolved scene given to `new` again (without `mesh`) fills those zones with the lattice
    /// of spacing `mesh.h` instead.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imported: Option<String>,
    /// The nodes of `mesh`, read while the scene is loaded; never written.
    #[serde(skip)]
    pub imported_nodes: Option<std::sync::Arc<Vec<ImportedNode>>>,
    /// Random offset of every particle lying more than h/2 inside a rectangle, as a fraction of
    /// its spacing h (the finer one inside `[[mesh.fine]]` regions) in each direction (0 <=
    /// jitter < 0.5; default 0). Deterministic per particle id. An irregular cloud has no grid
    /// lines for the plastic slip lines to cut across (a lattice's collapse loads are higher and
    /// approached slowly); supports and loads stay on the lattice.
    #[serde(default)]
    pub jitter: f64,
}

/// One zone of the body: exactly one of `polygon`, `circle` or `rectangle`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Zone {
    /// Shown in messages; optional.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The `[[material]]` this zone is made of (by name); optional with one material.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// This zone's coefficient of earth pressure at rest, instead of `geostatic.k0`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k0: Option<f64>,
    /// Vertices `[[x, y], ...]` (m) of a simple polygon, either orientation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon: Option<Vec<[f64; 2]>>,
    /// Holes of the polygon, each a list of vertices inside it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub holes: Vec<Vec<[f64; 2]>>,
    /// Names of the polygon's edges, edge k from vertex k to k + 1 (the last one closing the
    /// ring): `edges = ["seabed", "", "", ""]`, "" for an unnamed edge. A selection's `on =
    /// "seabed"` picks the particles on the edges of that name. Optional.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub edges: Vec<String>,
    /// Names of the edges of each hole, as `edges` for the outer ring. Optional.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub hole_edges: Vec<Vec<String>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub circle: Option<CircleZone>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rectangle: Option<Rectangle>,
}

/// A particle of a body imported from Gmsh: a mesh node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImportedNode {
    pub position: [f64; 2],
    /// The local mesh size (m).
    pub h: f64,
    /// Index into the scene's `[[material]]` list.
    pub material: u32,
}

fn is_zero2(v: &[f64; 2]) -> bool {
    *v == [0.0; 2]
}

/// `circle = { centre = [x, y], radius = r }` (m).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CircleZone {
    pub centre: [f64; 2],
    pub radius: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rectangle {
    /// Lower-left corner (m).
    pub origin: [f64; 2],
    /// Width and height (m), both > 0.
    pub size: [f64; 2],
}

/// `[[mesh.fine]]`: a region of the body filled with a finer particle lattice: a rectangle
/// (`origin`, `size`) or, in a body of `[[body.zones]]`, a `polygon`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FineRegion {
    /// Lower-left corner (m); origin and size are whole multiples of the next coarser spacing,
    /// so the coarse particles on the region's edges are also fine-lattice particles.
    #[serde(default, skip_serializing_if = "is_zero2")]
    pub origin: [f64; 2],
    #[serde(default, skip_serializing_if = "is_zero2")]
    pub size: [f64; 2],
    /// Vertices `[[x, y], ...]` (m) of a simple polygon, instead of `origin` and `size` (zone
    /// bodies only). Its outline carries particles at `h`; any `h` smaller than `mesh.h` that
    /// divides it a whole number of times.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon: Option<Vec<[f64; 2]>>,
    /// Particle spacing inside (m), a whole fraction of the next coarser spacing.
    pub h: f64,
}

/// `[mesh]`: particle spacing and remeshing controls.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mesh {
    /// Particle spacing (m), > 0.
    pub h: f64,
    /// Alpha-shape parameter: a Delaunay triangle is kept when its circumradius is at most
    /// `alpha * h`. Must be at least sqrt(2)/2, the circumradius ratio of the lattice's own
    /// triangles. Default 1.3.
    #[serde(default = "default_alpha")]
    pub alpha: f64,
    /// Insert/remove particles to keep the spacing near `h` (Fig. 4 of the method). Default true.
    #[serde(default = "default_true")]
    pub refine: bool,
    /// Laplacian smoothing of interior particles after remeshing. Default false.
    #[serde(default)]
    pub smooth: bool,
    /// Map every triangle's state through the particles after every remesh, as Abaqus' mesh-to-
    /// mesh solution mapping does, instead of keeping the Gauss states of triangles the remesh
    /// left unchanged. For studying the cost of mapping. Default false.
    #[serde(default)]
    pub remap_all: bool,
    /// Keep the curve a boundary edge's midside node took in the last increment across the
    /// remesh, while its two particles stay joined on the boundary (`mesh::curved`): the soil
    /// stays wrapped round a rigid body's rounded corner instead of its chords cutting in. On a
    /// rigid body only where the straight chord would cut in by 0.05 spacing or more. Default
    /// true.
    #[serde(default = "default_true")]
    pub curved_edges: bool,
    /// Nested finer lattices, e.g. around a footing edge: `fine = [{ origin = [0.5, 9.5],
    /// size = [1.0, 0.5], h = 0.0625 }]`. Where regions overlap the finest spacing wins. Default
    /// none.
    #[serde(default)]
    pub fine: Vec<FineRegion>,
    /// Particle spacing that follows the solution (opt-in; default none): see [`Adapt`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adapt: Option<Adapt>,
}

/// `[mesh.adapt]`: after every `every` steps, each particle's target spacing `h` is set from the
/// solution, between `h_min` and `h_max`, before the refinement splits and merges (so it needs
/// `mesh.refine = true`). The indicator of a particle is the largest, over the triangles around
/// it, of the engineering shear strain of the last step's displacement increment (the plastic
/// strain increment where the clay yields), relative to its largest value over the body: at or
/// above `refine_above` the target is `h_min`, at or below `coarsen_below` it is `h_max`, in
/// between it is interpolated geometrically. Then no spacing may exceed `grading` times a
/// mesh neighbour's. Where it is coarsened, an interior particle closer than 0.4 h to another
/// goes only if no close interior neighbour outranks it (a hash of the global id), so a fine
/// region thins out over a few steps instead of emptying at once.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Adapt {
    /// `"shear_strain_increment"` (the only one; default).
    #[serde(default)]
    pub indicator: AdaptIndicator,
    /// Finest and coarsest target spacing (m), 0 < h_min < h_max.
    pub h_min: f64,
    pub h_max: f64,
    /// Fractions of the largest indicator, 0 < coarsen_below < refine_above <= 1.
    /// Defaults 0.1 and 0.01.
    #[serde(default = "default_refine_above")]
    pub refine_above: f64,
    #[serde(default = "default_coarsen_below")]
    pub coarsen_below: f64,
    /// Largest ratio of neighbouring spacings, 1.2 to 2. Default 1.5.
    #[serde(default = "default_grading")]
    pub grading: f64,
    /// Adapt after every this many steps (>= 1; at the start of steps every + 1,
    /// 2 every + 1, ...). Default 1.
    #[serde(default = "default_every")]
    pub every: u32,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AdaptIndicator {
    #[default]
    ShearStrainIncrement,
}

fn default_refine_above() -> f64 {
    0.1
}

fn default_coarsen_below() -> f64 {
    0.01
}

fn default_grading() -> f64 {
    1.5
}

fn default_every() -> u32 {
    1
}

fn default_alpha() -> f64 {
    1.3
}

fn default_true() -> bool {
    true
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MaterialModel {
    /// `"linear-elastic"`: `young`, `poisson`.
    LinearElastic,
    /// `"tresca"`: elastic-perfectly plastic with undrained shear strength `cu`.
    Tresca,
    /// `"tresca-softening"`: Tresca whose strength softens with the accumulated plastic shear
    /// strain and rises with the shear strain rate (Einav & Randolph 2005): `cu` (the intact
    /// strength at the reference rate), `remoulded_ratio`, `xi95`, optional `rate_parameter`,
    /// `reference_rate`, `xi95_reference_spacing`.
    TrescaSoftening,
    /// `"mohr-coulomb"`: drained, elastic-perfectly plastic: `cohesion`, `friction_angle`,
    /// `dilation_angle`, optional `tension_cutoff`.
    MohrCoulomb,
    /// `"drucker-prager"`: the smooth cone matched to Mohr–Coulomb's `cohesion`,
    /// `friction_angle`, `dilation_angle` by `match`.
    DruckerPrager,
    /// `"umat"`: an Abaqus UMAT in a shared library (`library`, `props`, `state_variables`).
    Umat,
}

impl MaterialModel {
    pub fn as_str(self) -> &'static str {
        match self {
            MaterialModel::LinearElastic => "linear-elastic",
            MaterialModel::Tresca => "tresca",
            MaterialModel::TrescaSoftening => "tresca-softening",
            MaterialModel::MohrCoulomb => "mohr-coulomb",
            MaterialModel::DruckerPrager => "drucker-prager",
            MaterialModel::Umat => "umat",
        }
    }

    /// Whether the model is undrained clay with a strength `cu` (Tresca, Tresca-softening).
    pub fn undrained(self) -> bool {
        matches!(self, MaterialModel::Tresca | MaterialModel::TrescaSoftening)
    }

    /// Whether the model's strength depends on the mean stress (Mohr–Coulomb, Drucker–Prager).
    pub fn frictional(self) -> bool {
        matches!(
            self,
            MaterialModel::MohrCoulomb | MaterialModel::DruckerPrager
        )
    }
}

/// `match` of a `"drucker-prager"` material: which Mohr–Coulomb section the cone fits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ConeMatch {
    /// The cone whose plane-strain limit state is Mohr–Coulomb's (the default).
    #[default]
    PlaneStrain,
    /// Through Mohr–Coulomb's triaxial-compression corners (circumscribed).
    Outer,
    /// Through its triaxial-extension corners.
    Inner,
}

/// The scene's materials: one `[material]` table, or an array of named `[[material]]` tables.
/// The first is the scene's reference material: history columns normalised by cu, the contact
/// penalty's stiffness scale and `info` read it (through `Deref`).
#[derive(Debug, Clone, PartialEq)]
pub struct Materials(pub Vec<Material>);

impl std::ops::Deref for Materials {
    type Target = Material;
    fn deref(&self) -> &Material {
        &self.0[0]
    }
}

impl std::ops::DerefMut for Materials {
    fn deref_mut(&mut self) -> &mut Material {
        &mut self.0[0]
    }
}

impl Materials {
    pub fn all(&self) -> &[Material] {
        &self.0
    }

    /// Index of the material called `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.0.iter().position(|m| m.name.as_deref() == Some(name))
    }
}

impl Serialize for Materials {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        // One material stays a `[material]` table, as scenes were written before zones.
        match self.0.as_slice() {
            [one] => one.serialize(s),
            many => many.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Materials {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Materials;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a [material] table or [[material]] tables")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, a: A) -> Result<Materials, A::Error> {
                let m = Material::deserialize(serde::de::value::MapAccessDeserializer::new(a))?;
                Ok(Materials(vec![m]))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, a: A) -> Result<Materials, A::Error> {
                let v =
                    Vec::<Material>::deserialize(serde::de::value::SeqAccessDeserializer::new(a))?;
                if v.is_empty() {
                    return Err(serde::de::Error::custom("needs at least one material"));
                }
                Ok(Materials(v))
            }
        }
        d.deserialize_any(V)
    }
}

/// One material: `[material]` for the whole body, or a named `[[material]]` of a zone.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// The name zones give in `material = "..."`; required with several materials.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// `"linear-elastic"`, `"tresca"`, `"tresca-softening"`, `"mohr-coulomb"`,
    /// `"drucker-prager"` or `"umat"`.
    pub model: MaterialModel,
    /// Young's modulus (Pa), > 0. Required, except for `"tresca"` with `young_over_cu`, where it
    /// is the stiffness at the strength `cu` (young_over_cu · cu, filled in when left out). For
    /// `"umat"` the elastic constants the element and contact take their pressure law and
    /// stiffness scale from (the UMAT's own, in `props`, should agree).
    #[serde(default = "not_given")]
    pub young: f64,
    /// Poisson's ratio, -1 < poisson < 0.5.
    pub poisson: f64,
    /// Mass density (kg/m3), >= 0; the body force is `density * gravity.g`. Default 0.
    #[serde(default)]
    pub density: f64,
    /// Undrained shear strength (Pa); required > 0 for `"tresca"` and `"tresca-softening"` (the
    /// intact strength at the reference rate, su_ref), ignored otherwise. Default 0. With
    /// `cu_gradient` it is the strength at `reference_level` and above.
    #[serde(default)]
    pub cu: f64,
    /// `"tresca"` and `"tresca-softening"`: strength growing with depth below `reference_level`,
    /// cu(y) = cu +
    /// cu_gradient * (reference_level − y) (Pa/m; offshore clays: 1-2 kPa/m). Each particle
    /// keeps the strength of its initial position as it moves (an internal variable `cu` in the
    /// state and the output). Default 0 (uniform).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub cu_gradient: f64,
    /// Level (m) below which `cu_gradient` applies; required with it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_level: Option<f64>,
    /// `"tresca"` and `"tresca-softening"`: E = young_over_cu · cu at every point (offshore practice, typically
    /// 100–500), so the stiffness grows with `cu_gradient` as the strength does; the mixed
    /// element's bulk modulus follows point by point. Default: one `young` everywhere.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub young_over_cu: Option<f64>,
    /// `"tresca"` in `analysis = "axisymmetric"` only, where the hoop stress is one of the
    /// principal stresses the criterion judges: the rounding δ/cu of the edges of Tresca's
    /// prism (σr = σθ on the axis puts a penetrometer's plastic zone on an edge), in (0, 0.1].
    /// The edge is ρ/4 weaker than 2cu; a wider rounding gives Newton a stiffer tangent there.
    /// Default 0.01 (0.25 % weaker); the cone penetrometer on a fine cloud needs 0.05
    /// (docs/validation/cpt.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edge_rounding: Option<f64>,
    /// `"tresca-softening"` only: δ_rem, the remoulded strength over the intact one, in (0, 1]
    /// (1: no softening). Required.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub remoulded_ratio: Option<f64>,
    /// `"tresca-softening"` only: ξ95, the accumulated plastic shear strain (engineering, see
    /// docs/guide/materials-softening.md) at which 95 % of the softening has happened, > 0.
    /// Required.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xi95: Option<f64>,
    /// `"tresca-softening"` only: the element size h_ref (m, > 0) at which `xi95` holds; an
    /// element of size h then softens with ξ95 · h_ref / h (the band regularisation that makes
    /// the softening load–displacement curve independent of the spacing). Default: none
    /// (`xi95` everywhere, and the result depends on the spacing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xi95_reference_spacing: Option<f64>,
    /// `"tresca-softening"` only: μ, the strength's rise per decade of shear strain rate, >= 0.
    /// Default 0 (rate-independent). With μ > 0 the steps need a duration.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_parameter: Option<f64>,
    /// `"tresca-softening"` only: γ̇_ref (1/s, > 0), the shear strain rate at which the
    /// strength is `cu`; slower steps keep it (the rate factor is never below 1). Required when
    /// `rate_parameter` > 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_rate: Option<f64>,
    /// `"mohr-coulomb"` and `"drucker-prager"`: cohesion c (Pa), >= 0 (> 0 when
    /// friction_angle = 0). Required.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cohesion: Option<f64>,
    /// Their friction angle φ (degrees), 0 <= φ < 90. Required.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_angle: Option<f64>,
    /// Their dilation angle ψ (degrees), 0 <= ψ <= φ: ψ = φ is associated flow, ψ < φ gives a
    /// non-symmetric tangent (LU and GMRES, as for every plastic scene). Required.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dilation_angle: Option<f64>,
    /// `"mohr-coulomb"` only: the largest principal stress (Pa, tension positive), >= 0.
    /// Default: none (the cone's apex c cot φ bounds tension).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tension_cutoff: Option<f64>,
    /// `"drucker-prager"` only: `"plane-strain"` (default), `"outer"` or `"inner"`.
    #[serde(default, rename = "match", skip_serializing_if = "Option::is_none")]
    pub cone_match: Option<ConeMatch>,
    /// `"umat"` only: the shared library holding `umat_`, relative to the scene file (to the
    /// working directory for a built-in scene); the resolved scene records it absolute.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub library: Option<String>,
    /// `"umat"` only: PROPS, in the order the UMAT reads them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub props: Vec<f64>,
    /// `"umat"` only: the number of PROPS the UMAT expects, checked against `props` when given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nprops: Option<usize>,
    /// `"umat"` only: NSTATV, state variables per Gauss point, `statev_1 ...` unless named.
    #[serde(default, skip_serializing_if = "is_zero_usize")]
    pub state_variables: usize,
    /// `"umat"` only: names of the state variables in outputs and checkpoints.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub state_names: Vec<String>,
}

/// A required number left out (NaN: no TOML scene writes it by accident).
fn not_given() -> f64 {
    f64::NAN
}

fn is_zero_usize(n: &usize) -> bool {
    *n == 0
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// `[gravity]`: gravitational acceleration vector (m/s2), e.g. `g = [0.0, -9.81]`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gravity {
    #[serde(default)]
    pub g: [f64; 2],
    /// Scale the body force with the load factor, from nothing at the start to `density * g`
    /// at load factor 1, so that a slope or cut can be loaded by its own weight (to collapse
    /// with `steps.until_collapse`). The body then starts unstressed: no `[geostatic]`. Default
    /// false (the full weight from the first step, in equilibrium with `[geostatic]`).
    #[serde(default, skip_serializing_if = "is_false")]
    pub ramp: bool,
}

fn is_false(b: &bool) -> bool {
    !*b
}

/// A displacement component.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Dof {
    X,
    Y,
}

impl Dof {
    pub fn as_str(self) -> &'static str {
        match self {
            Dof::X => "x",
            Dof::Y => "y",
        }
    }

    /// Component index into `[ux, uy]`.
    pub fn index(self) -> usize {
        match self {
            Dof::X => 0,
            Dof::Y => 1,
        }
    }
}

/// `[[fixed]]`: zero displacement of `dofs` for every particle selected by `where`. The
/// selection is geometric and is re-evaluated on every remesh.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fixed {
    /// Optional name for history measures (`reaction.NAME.fy`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// `where = "x <= 0"`: comparisons `x <= c`, `x >= c`, `y <= c`, `y >= c` joined by `and`;
    /// boundaries are matched within 1e-9 times the body's largest dimension. Optional with
    /// `on` (then every particle of that boundary); at least one of the two.
    #[serde(
        rename = "where",
        default = "Selector::all",
        skip_serializing_if = "Selector::has_no_conditions"
    )]
    pub region: Selector,
    /// `on = "seabed"`: the particles on the zone edges of that name (`body.zones[].edges`),
    /// within 1e-6 mesh.h, and within `where` if given too.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub on: Option<String>,
    /// `within = [[x, y], ...]`: only particles inside this polygon (edges included, within
    /// 1e-9 of the body's size), e.g. a sloping face; with `where` and `on`, all must hold.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub within: Option<Vec<[f64; 2]>>,
    /// Constrained components, a non-empty subset of `["x", "y"]`.
    pub dofs: Vec<Dof>,
}

/// `[[point_load]]`: a force applied to one tracked particle, scaled by the load factor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLoad {
    /// The tracked particle is the one nearest to this point when the case is created (ties go
    /// to the smaller global id); it must lie within one spacing of the body.
    pub at: [f64; 2],
    /// Force (N per metre of thickness) at full load, load factor 1.
    pub force: [f64; 2],
}

/// `[[prescribed]]`: imposed displacement of the particles selected by `where`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Prescribed {
    /// Optional name for history measures (`reaction.NAME.fy`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Same syntax as `fixed.where`, e.g. `"y >= 10 and x <= 1"`.
    #[serde(
        rename = "where",
        default = "Selector::all",
        skip_serializing_if = "Selector::has_no_conditions"
    )]
    pub region: Selector,
    /// As `fixed.on` (with `select = "initial"` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub on: Option<String>,
    /// As `fixed.within` (with `select = "initial"` only): only particles inside this polygon (edges included, within
    /// 1e-9 of the body's size), e.g. a sloping face; with `where` and `on`, all must hold.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub within: Option<Vec<[f64; 2]>>,
    /// Prescribed components, a non-empty subset of `["x", "y"]`.
    pub dofs: Vec<Dof>,
    /// Displacement (m) reached at the end of loading, applied linearly over the steps. Only the
    /// components listed in `dofs` are used.
    pub total: [f64; 2],
    /// Which particles `where` selects. Default `"initial"`.
    #[serde(default, skip_serializing_if = "Selection::is_initial")]
    pub select: Selection,
}

/// How `[[prescribed]].where` selects particles.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Selection {
    /// `"initial"`: the particles whose initial position lies in `where`, for the whole run (a
    /// platen glued to the body).
    #[default]
    Initial,
    /// `"current"`: a rigid platen. `where` moves with the prescribed displacement, and at the
    /// start of every increment it selects the particles now inside it: every particle that
    /// reaches the platen is put on its face and moves with it from then on, so the body never
    /// passes through it. Each prescribed component must be bounded on one side only in `where`
    /// (`y >= 1`: the face is y = 1 plus the platen's displacement).
    Current,
}

impl Selection {
    fn is_initial(&self) -> bool {
        *self == Selection::Initial
    }
}

/// `[steps]`: load stepping.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Steps {
    /// Number of load steps, >= 1; the load factor goes from 0 to 1 in equal increments. With
    /// `[[rigid]]` stages it may be left out: it is then the longest body's stage total (and if
    /// given, it must equal that total).
    #[serde(default)]
    pub count: u32,
    /// Collapse is the expected end of the run (a slope or cut loaded by `gravity.ramp`, a
    /// footing pushed by force): when Newton fails, the step is cut until the load factor of
    /// collapse is bracketed within `collapse_tolerance`, the run reports the largest load
    /// factor at which equilibrium held, and exits 0. Without it, a step that does not converge
    /// is an error. Reaching the last step without collapse is an error too. Default false.
    #[serde(default, skip_serializing_if = "is_false")]
    pub until_collapse: bool,
    /// The run's duration in seconds (> 0), spread evenly over its steps: step k of `count`
    /// lasts `duration / count`. A rate-dependent material (`tresca-softening` with
    /// `rate_parameter` > 0) needs the time of its steps, from here or from a `duration` or
    /// `velocity` on the `[[rigid]]` stages (not both); a UMAT then gets seconds as TIME and
    /// DTIME. Default: none (the run is quasi-static, its time the load factor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration: Option<f64>,
    /// A load increment under which the body's largest displacement per unit load factor
    /// exceeds this multiple of the first increment's (elastic) one is a mechanism: its
    /// stiffness has fallen to 1/collapse_compliance of the initial. Collapse is the load factor
    /// where that happens (or where equilibrium fails, if first): without this rule a large-
    /// deformation run finds equilibrium again in the slumped shape (a cut flattens into a
    /// stable slope) far above the collapse load of the body as drawn. Default 50.
    #[serde(
        default = "default_collapse_compliance",
        skip_serializing_if = "is_default_collapse_compliance"
    )]
    pub collapse_compliance: f64,
    /// Width of the bracket on the collapse load factor (in load-factor units, 0 < tolerance
    /// < 1). Default 0.001.
    #[serde(
        default = "default_collapse_tolerance",
        skip_serializing_if = "is_default_collapse_tolerance"
    )]
    pub collapse_tolerance: f64,
}

impl Default for Steps {
    fn default() -> Steps {
        Steps {
            count: 0,
            until_collapse: false,
            duration: None,
            collapse_tolerance: default_collapse_tolerance(),
            collapse_compliance: default_collapse_compliance(),
        }
    }
}

fn default_collapse_compliance() -> f64 {
    50.0
}

fn is_default_collapse_compliance(c: &f64) -> bool {
    *c == default_collapse_compliance()
}

fn default_collapse_tolerance() -> f64 {
    1e-3
}

fn is_default_collapse_tolerance(t: &f64) -> bool {
    *t == default_collapse_tolerance()
}

/// Which quantities `history.csv` records.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum HistoryKind {
    /// Tip displacement of the first point load's tracked particle. Needs a `[[point_load]]`.
    Cantilever,
    /// Footing load against settlement. Needs a `[[prescribed]]`.
    Footing,
    /// Platen force against platen displacement. Needs a `[[prescribed]]`.
    Block,
}

impl HistoryKind {
    pub fn as_str(self) -> &'static str {
        match self {
            HistoryKind::Cantilever => "cantilever",
            HistoryKind::Footing => "footing",
            HistoryKind::Block => "block",
        }
    }
}

/// `[history]`: the built-in columns of `kind`, then the declared `columns`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct History {
    /// `"cantilever"`, `"footing"` or `"block"`: the legacy benchmark columns. Optional.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<HistoryKind>,
    /// `[[history.columns]]`: named measurements, each with a scale factor.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub columns: Vec<Column>,
}

/// `[output]`: checkpointing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Output {
    /// Write a checkpoint every this many steps; 0 = only at the end. Default 0.
    pub checkpoint_every: u32,
    /// Number of most recent checkpoints kept on disk, >= 1. Default 3.
    pub checkpoint_keep: u32,
    /// ParaView output (`DIR/fields.xdmf`) every this many steps; 0 = only the last step of a
    /// run. Default 0.
    pub fields_every: u32,
}

impl Default for Output {
    fn default() -> Self {
        Output {
            checkpoint_every: 0,
            checkpoint_keep: 3,
            fields_every: 0,
        }
    }
}

/// `[solver]`: Newton-Raphson controls.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Solver {
    /// Maximum Newton iterations per step, >= 1. Default 25.
    pub newton_max_it: u32,
    /// Relative residual tolerance, 0 < newton_rtol < 1. Default 1e-9.
    pub newton_rtol: f64,
    /// `"auto"` (default: `"p2p1"` where a material yields, `"p2"` otherwise), `"p2"` (6-node
    /// displacement triangles) or `"p2p1"` (Taylor–Hood mixed u–p: P2 displacement, P1
    /// pressure; a frictional model's own pressure is projected onto the P1 field).
    pub element: ElementChoice,
    /// Newton's line search: `"auto"` (default: `"basic"`, full steps, for elastic scenes;
    /// `"bt"`, backtracking, for plastic ones), `"basic"`, `"bt"`, `"l2"` (secant on the
    /// residual norm, more evaluations per iteration but it carries localised plastic flow
    /// further) or `"cp"`. `-snes_linesearch_type` on the command line overrides it.
    pub line_search: LineSearch,
    /// Newton's linear solver: `"auto"` (default: direct up to 150 000 global dofs and for
    /// every `"p2p1"` mesh or plastic scene, the p-multigrid for larger elastic `"p2"` meshes,
    /// where it is the faster and leaner of the two),
    /// `"direct"` (MUMPS LU) or `"iterative"` (GMRES, or CG where `symmetric` applies, with
    /// algebraic multigrid for `"p2"`; with a Schur-complement field split, AMG on
    /// the displacements and the pressure mass matrix scaled by 1/G on the pressures, for
    /// `"p2p1"`). PETSc options on the command line (`-ksp_type`, `-pc_type`, ...) override it.
    pub linear: LinearChoice,
    /// Whether the direct solver factors LDLᵀ (MUMPS) instead of LU, and the iterative one
    /// uses conjugate gradients instead of GMRES, where every tangent is symmetric: an elastic
    /// `"p2"` scene without rigid bodies or surface pressures. Half the factor's entries and
    /// flops; a few Krylov vectors instead of one per iteration; the history is LU's (GMRES's)
    /// to round-off. Default true.
    pub symmetric: bool,
    /// Whether the direct solver keeps a factorisation for the next Newton iteration while
    /// Newton converges fast, solving the exact tangent with GCR preconditioned by it
    /// (relative tolerance 1e-10). Default false: on the cantilever each kept factorisation
    /// needed 5–9 Krylov iterations, as dear as factoring afresh. The PETSc option
    /// `-pfem_lu_reuse true|false` overrides it.
    pub reuse_factorisation: bool,
}

/// `solver.linear`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LinearChoice {
    #[default]
    Auto,
    Direct,
    Iterative,
}

/// `solver.line_search`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LineSearch {
    #[default]
    Auto,
    Basic,
    Bt,
    L2,
    Cp,
}

/// `solver.element`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ElementChoice {
    #[default]
    Auto,
    P2,
    P2p1,
}

impl Default for Solver {
    fn default() -> Self {
        Solver {
            newton_max_it: 25,
            newton_rtol: 1e-9,
            element: ElementChoice::Auto,
            line_search: LineSearch::Auto,
            linear: LinearChoice::Auto,
            symmetric: true,
            reuse_factorisation: false,
        }
    }
}
