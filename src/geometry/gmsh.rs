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

use super::gmsh_header::{check_version, physical_names};
use super::segment::Point;
use mshio::{ElementType, MshFile};
use std::collections::{BTreeMap, BTreeSet, HashMap};
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

fn parse(bytes: &[u8]) -> Result<MshFile<u64, i32, f64>, GmshErrorKind> {
    // mshio still has a few unwraps on malformed input; a panic there is a damaged file.
    let result = std::panic::catch_unwind(|| {
        mshio::parse_msh_bytes(bytes).map_err(|e| {
            let mut s = e.to_string();
            s.truncate(s.char_indices().nth(400).map_or(s.len(), |(i, _)| i));
            s
        })
    });
    match result {
        Ok(Ok(m)) => Ok(m),
        Ok(Err(detail)) => Err(GmshErrorKind::Damaged { detail }),
        Err(_) => Err(GmshErrorKind::Damaged {
            detail: "the parser gave up on malformed data".into(),
        }),
    }
}

fn import(bytes: &[u8]) -> Result<GmshMesh, GmshErrorKind> {
    check_version(bytes)?;
    let names = physical_names(bytes)?;
    let msh = parse(bytes)?;
    let name_of = |dim: i32, tag: i32| {
        names
            .iter()
            .find(|(d, t, _)| *d == dim && *t == tag)
            .map_or_else(|| tag.to_string(), |(_, _, n)| n.clone())
    };
    let Some(entities) = &msh.data.entities else {
        return Err(GmshErrorKind::NoPhysicalGroups);
    };
    let elements = msh
        .data
        .elements
        .as_ref()
        .map_or(&[][..], |e| &e.element_blocks[..]);
    let volume_blocks = elements.iter().filter(|b| b.entity_dim == 3).count();
    if !entities.volumes.is_empty() || volume_blocks > 0 {
        return Err(GmshErrorKind::Volumes {
            count: entities.volumes.len().max(volume_blocks),
        });
    }
    let surface_groups: HashMap<i32, &[i32]> = entities
        .surfaces
        .iter()
        .map(|s| (s.tag, &s.physical_tags[..]))
        .collect();
    let curve_groups: HashMap<i32, &[i32]> = entities
        .curves
        .iter()
        .map(|c| (c.tag, &c.physical_tags[..]))
        .collect();
    let any_group = entities.points.iter().any(|p| !p.physical_tags.is_empty())
        || curve_groups.values().any(|g| !g.is_empty())
        || surface_groups.values().any(|g| !g.is_empty());
    if !any_group {
        return Err(GmshErrorKind::NoPhysicalGroups);
    }
    let surface_tags: BTreeSet<i32> = surface_groups
        .values()
        .flat_map(|g| g.iter().copied())
        .collect();
    if surface_tags.is_empty() {
        return Err(GmshErrorKind::NoPhysicalSurfaces);
    }
    let surface_index: HashMap<i32, usize> = surface_tags
        .iter()
        .enumerate()
        .map(|(i, &t)| (t, i))
        .collect();

    let (coords, classified) = read_nodes(&msh)?;
    let lookup = |id: u64| {
        coords
            .get(&id)
            .copied()
            .ok_or(GmshErrorKind::UnknownNode { node: id })
    };

    // Surface elements, by surface index, as node tags.
    let mut tris: Vec<Vec<[u64; 3]>> = vec![Vec::new(); surface_tags.len()];
    let mut quads: Vec<Vec<[u64; 4]>> = vec![Vec::new(); surface_tags.len()];
    let mut curve_segments: BTreeMap<i32, Vec<[u64; 2]>> = BTreeMap::new();
    for block in elements {
        let unsupported = || GmshErrorKind::UnsupportedElement {
            element: format!("{:?}", block.element_type),
            entity_dim: block.entity_dim,
            entity: block.entity_tag,
        };
        match block.entity_dim {
            2 => {
                let groups: BTreeSet<i32> = surface_groups
                    .get(&block.entity_tag)
                    .map_or_else(BTreeSet::new, |g| g.iter().copied().collect());
                let groups: Vec<i32> = groups.into_iter().collect();
                let s = match groups[..] {
                    [] => {
                        return Err(GmshErrorKind::UnassignedSurface {
                            entity: block.entity_tag,
                        })
                    }
                    [g] => surface_index[&g],
                    [a, b, ..] => {
                        // Report a node inside the entity: it is certainly in both groups.
                        let inside = classified
                            .iter()
                            .filter(|(_, &c)| c == (2, block.entity_tag))
                            .map(|(&id, _)| id)
                            .min();
                        let first = block
                            .elements
                            .first()
                            .and_then(|e| e.nodes.first())
                            .copied();
                        return Err(GmshErrorKind::NodeInTwoSurfaces {
                            node: inside.or(first).unwrap_or(0),
                            surfaces: [name_of(2, a), name_of(2, b)],
                        });
                    }
                };
                for e in &block.elements {
                    match (block.element_type, &e.nodes[..]) {
                        (ElementType::Tri3, &[a, b, c]) => tris[s].push([a, b, c]),
                        (ElementType::Qua4, &[a, b, c, d]) => quads[s].push([a, b, c, d]),
                        _ => return Err(unsupported()),
                    }
                }
            }
            1 => {
                let groups = curve_groups.get(&block.entity_tag).copied().unwrap_or(&[]);
                for e in &block.elements {
                    let &[a, b] = &e.nodes[..] else {
                        return Err(unsupported());
                    };
                    if block.element_type != ElementType::Lin2 {
                        return Err(unsupported());
                    }
                    for &g in groups {
                        curve_segments.entry(g).or_default().push([a, b]);
                    }
                }
            }
            0 => {}
            _ => return Err(unsupported()),
        }
    }

    // A node inside a surface entity is used by that surface alone (entities in two groups
    // were refused above), so the lowest surface using a node is its owner in every case.
    let mut owner: BTreeMap<u64, usize> = BTreeMap::new();
    let mut users: Vec<BTreeSet<u64>> = vec![BTreeSet::new(); surface_tags.len()];
    for s in 0..surface_tags.len() {
        for &id in tris[s].iter().flatten().chain(quads[s].iter().flatten()) {
            users[s].insert(id);
            owner.entry(id).or_insert(s);
        }
    }
    let index: HashMap<u64, usize> = owner.keys().enumerate().map(|(i, &id)| (id, i)).collect();
    let mut nodes = Vec::with_capacity(owner.len());
    for (&id, &surface) in &owner {
        nodes.push(GmshNode {
            id,
            position: lookup(id)?,
            size: 0.0,
            surface,
        });
    }
    mesh_sizes(&mut nodes, &index, &tris, &quads);

    let surfaces = surface_tags
        .iter()
        .enumerate()
        .map(|(s, &tag)| PhysicalSurface {
            name: name_of(2, tag),
            tag,
            nodes: users[s].iter().map(|id| index[id]).collect(),
            triangles: tris[s].iter().map(|t| t.map(|id| index[&id])).collect(),
            quads: quads[s].iter().map(|q| q.map(|id| index[&id])).collect(),
        })
        .collect();
    let mut curves = Vec::new();
    for (tag, segments) in curve_segments {
        let coordinates = segments
            .iter()
            .map(|&[a, b]| Ok([lookup(a)?, lookup(b)?]))
            .collect::<Result<Vec<_>, GmshErrorKind>>()?;
        curves.push(PhysicalCurve {
            name: name_of(1, tag),
            tag,
            segments,
            coordinates,
        });
    }
    Ok(GmshMesh {
        path: PathBuf::new(),
        nodes,
        surfaces,
        curves,
    })
}

type NodeMaps = (HashMap<u64, Point>, HashMap<u64, (i32, i32)>);

/// Coordinates and classifying entity `(dim, tag)` of every node, checking z = 0.
fn read_nodes(msh: &MshFile<u64, i32, f64>) -> Result<NodeMaps, GmshErrorKind> {
    let mut coords = HashMap::new();
    let mut classified = HashMap::new();
    let Some(section) = &msh.data.nodes else {
        return Ok((coords, classified));
    };
    let mut next = section.min_node_tag;
    for block in &section.node_blocks {
        let tags: Vec<u64> = match &block.node_tags {
            Some(map) => {
                let mut t = vec![0; block.nodes.len()];
                for (&tag, &i) in map {
                    if let Some(slot) = t.get_mut(i) {
                        *slot = tag;
                    }
                }
                t
            }
            None => {
                let t = (0..block.nodes.len() as u64).map(|k| next + k).collect();
                next += block.nodes.len() as u64;
                t
            }
        };
        for (node, &tag) in block.nodes.iter().zip(&tags) {
            if node.z != 0.0 {
                return Err(GmshErrorKind::NodeOutOfPlane {
                    node: tag,
                    z: node.z,
                });
            }
            coords.insert(tag, [node.x, node.y]);
            classified.insert(tag, (block.entity_dim, block.entity_tag));
        }
    }
    Ok((coords, classified))
}

/// Mean length of the element edges (each counted once) at each node.
fn mesh_sizes(
    nodes: &mut [GmshNode],
    index: &HashMap<u64, usize>,
    tris: &[Vec<[u64; 3]>],
    quads: &[Vec<[u64; 4]>],
) {
    let mut edges: BTreeSet<(usize, usize)> = BTreeSet::new();
    let mut add = |ring: &[u64]| {
        for k in 0..ring.len() {
            let (a, b) = (index[&ring[k]], index[&ring[(k + 1) % ring.len()]]);
            edges.insert((a.min(b), a.max(b)));
        }
    };
    tris.iter().flatten().for_each(|t| add(t));
    quads.iter().flatten().for_each(|q| add(q));
    let mut sum = vec![0.0; nodes.len()];
    let mut count = vec![0usize; nodes.len()];
    for (a, b) in edges {
        let (p, q) = (nodes[a].position, nodes[b].position);
        let len = (p[0] - q[0]).hypot(p[1] - q[1]);
        for v in [a, b] {
            sum[v] += len;
            count[v] += 1;
        }
    }
    for (k, n) in nodes.iter_mut().enumerate() {
        n.size = if count[k] > 0 {
            sum[k] / count[k] as f64
        } else {
            0.0
        };
    }
}
