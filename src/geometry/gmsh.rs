//! Import of a 2D Gmsh mesh (MSH 4.1, ASCII or binary) through the `mshio` parser: the nodes
//! and elements of each physical surface, a local mesh size at each node, and each physical
//! curve as segments.
//!
//! Node ownership: a node inside a surface entity belongs to that entity's physical surface
//! (an entity in two physical surfaces is refused: its nodes would be in both). A node on a
//! curve or point shared by several physical surfaces (an interface between layers) belongs
//! to the one with the lowest physical tag; surfaces are listed in tag order, so this is the
//! lowest zone index, as for [`super::fill_zones`].
//!
//! When a file's node tags are dense, `mshio` does not keep them; they are then taken as
//! consecutive from the smallest tag in block order, which is how Gmsh writes them.

use super::gmsh_import::import;
use super::segment::Point;
use std::fmt;
use std::path::{Path, PathBuf};

/// A node of a physical surface: a particle to be.
#[derive(Debug, Clone, PartialEq)]
pub struct GmshNode {
    /// The node's tag in the file.
    pub id: u64,
    pub position: Point,
    /// Mean length of the mesh edges meeting at the node.
    pub size: f64,
    /// Index into [`GmshMesh::surfaces`] of the surface that owns the node.
    pub surface: usize,
}

/// A physical surface (a zone) and its elements.
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicalSurface {
    /// The name from `$PhysicalNames`, or the tag in decimal if the group has no name.
    pub name: String,
    pub tag: i32,
    /// Indices into [`GmshMesh::nodes`] of every node its elements use (shared interface
    /// nodes included), ascending.
    pub nodes: Vec<usize>,
    /// Three-node triangles, as indices into [`GmshMesh::nodes`].
    pub triangles: Vec<[usize; 3]>,
    /// Four-node quadrangles, as indices into [`GmshMesh::nodes`].
    pub quads: Vec<[usize; 4]>,
}

/// A physical curve (a named boundary).
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicalCurve {
    pub name: String,
    pub tag: i32,
    /// Node tags of each two-node line element.
    pub segments: Vec<[u64; 2]>,
    /// The same segments as coordinates.
    pub coordinates: Vec<[Point; 2]>,
}

/// What a 2D Gmsh file holds, as zones and boundaries.
#[derive(Debug, Clone, PartialEq)]
pub struct GmshMesh {
    pub path: PathBuf,
    /// Every node of every physical surface, once, by ascending tag.
    pub nodes: Vec<GmshNode>,
    /// By ascending physical tag.
    pub surfaces: Vec<PhysicalSurface>,
    /// By ascending physical tag.
    pub curves: Vec<PhysicalCurve>,
}

/// A file that could not be imported, and which file.
#[derive(Debug, Clone, PartialEq)]
pub struct GmshError {
    pub path: PathBuf,
    pub kind: GmshErrorKind,
}

#[derive(Debug, Clone, PartialEq)]
pub enum GmshErrorKind {
    NotFound,
    Unreadable {
        message: String,
    },
    /// Not a well-formed MSH 4.1 file.
    Damaged {
        detail: String,
    },
    /// The `$MeshFormat` version is not 4.1.
    Version {
        found: String,
    },
    /// A node off the plane z = 0.
    NodeOutOfPlane {
        node: u64,
        z: f64,
    },
    /// Volume entities or volume elements.
    Volumes {
        count: usize,
    },
    NoPhysicalGroups,
    /// Physical groups, but none of dimension 2: nothing to make zones from.
    NoPhysicalSurfaces,
    /// A node inside a surface entity that belongs to two physical surfaces.
    NodeInTwoSurfaces {
        node: u64,
        surfaces: [String; 2],
    },
    /// Elements on a surface entity that is in no physical surface.
    UnassignedSurface {
        entity: i32,
    },
    /// An element type other than 3-node triangles, 4-node quadrangles, 2-node lines, points.
    UnsupportedElement {
        element: String,
        entity_dim: i32,
        entity: i32,
    },
    /// An element refers to a node the file does not define.
    UnknownNode {
        node: u64,
    },
}

impl fmt::Display for GmshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use GmshErrorKind::*;
        let p = self.path.display();
        match &self.kind {
            NotFound => write!(f, "{p}: mesh file not found"),
            Unreadable { message } => write!(f, "{p}: cannot read the mesh file: {message}"),
            Damaged { detail } => write!(f, "{p}: damaged MSH file: {detail}"),
            Version { found } => write!(
                f,
                "{p}: MSH format version {found}; only 4.1 is read (Gmsh: -format msh41)"
            ),
            NodeOutOfPlane { node, z } => write!(
                f,
                "{p}: node {node} has z = {z}; only 2D meshes in the plane z = 0 are read"
            ),
            Volumes { count } => {
                write!(
                    f,
                    "{p}: {count} volume entities or element blocks; only 2D meshes are read"
                )
            }
            NoPhysicalGroups => write!(
                f,
                "{p}: no physical groups; name the soil zones with Physical Surface(\"name\")"
            ),
            NoPhysicalSurfaces => write!(f, "{p}: physical groups but no Physical Surface"),
            NodeInTwoSurfaces { node, surfaces } => write!(
                f,
                "{p}: node {node} is in physical surfaces {:?} and {:?}",
                surfaces[0], surfaces[1]
            ),
            UnassignedSurface { entity } => {
                write!(
                    f,
                    "{p}: surface {entity} is meshed but in no physical surface"
                )
            }
            UnsupportedElement {
                element,
                entity_dim,
                entity,
            } => write!(
                f,
                "{p}: element type {element} on entity ({entity_dim}, {entity}); only 3-node \
                 triangles, 4-node quadrangles and 2-node lines are read"
            ),
            UnknownNode { node } => write!(f, "{p}: an element refers to undefined node {node}"),
        }
    }
}

impl std::error::Error for GmshError {}

/// Reads and imports the MSH 4.1 file at `path`.
pub fn read_msh(path: &Path) -> Result<GmshMesh, GmshError> {
    let err = |kind| GmshError {
        path: path.to_path_buf(),
        kind,
    };
    let bytes = std::fs::read(path).map_err(|e| {
        err(match e.kind() {
            std::io::ErrorKind::NotFound => GmshErrorKind::NotFound,
            _ => GmshErrorKind::Unreadable {
                message: e.to_string(),
            },
        })
    })?;
    parse_msh(path, &bytes)
}

/// Imports MSH 4.1 content; `path` is only used in errors and the result.
pub fn parse_msh(path: &Path, bytes: &[u8]) -> Result<GmshMesh, GmshError> {
    let mut mesh = import(bytes).map_err(|kind| GmshError {
        path: path.to_path_buf(),
        kind,
    })?;
    mesh.path = path.to_path_buf();
    Ok(mesh)
}
