//! From `mshio`'s view of a file (entities, node blocks, element blocks) to zones and
//! boundaries: physical surfaces with their nodes and elements, physical curves as segments.

use super::gmsh::{GmshErrorKind, GmshMesh, GmshNode, PhysicalCurve, PhysicalSurface};
use super::gmsh_header::{check_version, physical_names};
use super::segment::Point;
use mshio::{ElementBlock, ElementType, Entities, MshFile};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::PathBuf;

type Msh = MshFile<u64, i32, f64>;

pub(super) fn import(bytes: &[u8]) -> Result<GmshMesh, GmshErrorKind> {
    check_version(bytes)?;
    let names = physical_names(bytes)?;
    let msh = parse(bytes)?;
    let Some(entities) = &msh.data.entities else {
        return Err(GmshErrorKind::NoPhysicalGroups);
    };
    let blocks = msh
        .data
        .elements
        .as_ref()
        .map_or(&[][..], |e| &e.element_blocks[..]);
    let volume_blocks = blocks.iter().filter(|b| b.entity_dim == 3).count();
    if !entities.volumes.is_empty() || volume_blocks > 0 {
        return Err(GmshErrorKind::Volumes {
            count: entities.volumes.len().max(volume_blocks),
        });
    }
    let groups = Groups::new(entities, names)?;
    let nodes = read_nodes(&msh)?;
    let elements = collect_elements(blocks, &groups, &nodes)?;
    assemble(&groups, &elements, &nodes)
}

fn parse(bytes: &[u8]) -> Result<Msh, GmshErrorKind> {
    // mshio still has unwraps on malformed input (`check_version` screens the known ones); a
    // panic there is a damaged file, not a crash.
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

/// Which physical groups each entity is in, and the physical surfaces in tag order.
struct Groups<'a> {
    names: Vec<(i32, i32, String)>,
    surface_groups: HashMap<i32, &'a [i32]>,
    curve_groups: HashMap<i32, &'a [i32]>,
    surface_tags: Vec<i32>,
    surface_index: HashMap<i32, usize>,
}

impl<'a> Groups<'a> {
    fn new(
        entities: &'a Entities<i32, f64>,
        names: Vec<(i32, i32, String)>,
    ) -> Result<Self, GmshErrorKind> {
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
        let tags: BTreeSet<i32> = surface_groups
            .values()
            .flat_map(|g| g.iter().copied())
            .collect();
        if tags.is_empty() {
            return Err(GmshErrorKind::NoPhysicalSurfaces);
        }
        let surface_tags: Vec<i32> = tags.into_iter().collect();
        let surface_index = surface_tags
            .iter()
            .enumerate()
            .map(|(i, &t)| (t, i))
            .collect();
        Ok(Groups {
            names,
            surface_groups,
            curve_groups,
            surface_tags,
            surface_index,
        })
    }

    /// The name from `$PhysicalNames`, or the tag in decimal.
    fn name(&self, dim: i32, tag: i32) -> String {
        self.names
            .iter()
            .find(|(d, t, _)| *d == dim && *t == tag)
            .map_or_else(|| tag.to_string(), |(_, _, n)| n.clone())
    }
}

/// Node coordinates and the entity `(dim, tag)` each node is classified on.
struct Nodes {
    coords: HashMap<u64, Point>,
    classified: HashMap<u64, (i32, i32)>,
}

impl Nodes {
    fn position(&self, id: u64) -> Result<Point, GmshErrorKind> {
        self.coords
            .get(&id)
            .copied()
            .ok_or(GmshErrorKind::UnknownNode { node: id })
    }
}

/// Reads every node, refusing any off the plane z = 0 or not finite.
fn read_nodes(msh: &Msh) -> Result<Nodes, GmshErrorKind> {
    let mut nodes = Nodes {
        coords: HashMap::new(),
        classified: HashMap::new(),
    };
    let Some(section) = &msh.data.nodes else {
        return Ok(nodes);
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
            if !(node.x.is_finite() && node.y.is_finite()) {
                return Err(GmshErrorKind::Damaged {
                    detail: format!("node {tag} has a coordinate that is not a finite number"),
                });
            }
            if node.z != 0.0 {
                return Err(GmshErrorKind::NodeOutOfPlane {
                    node: tag,
                    z: node.z,
                });
            }
            nodes.coords.insert(tag, [node.x, node.y]);
            nodes
                .classified
                .insert(tag, (block.entity_dim, block.entity_tag));
        }
    }
    Ok(nodes)
}

/// Elements by physical surface index and line segments by physical curve tag, as node tags.
struct Elements {
    tris: Vec<Vec<[u64; 3]>>,
    quads: Vec<Vec<[u64; 4]>>,
    curves: BTreeMap<i32, Vec<[u64; 2]>>,
}

fn collect_elements(
    blocks: &[ElementBlock<u64, i32>],
    groups: &Groups,
    nodes: &Nodes,
) -> Result<Elements, GmshErrorKind> {
    let n = groups.surface_tags.len();
    let mut out = Elements {
        tris: vec![Vec::new(); n],
        quads: vec![Vec::new(); n],
        curves: BTreeMap::new(),
    };
    for block in blocks {
        let unsupported = || GmshErrorKind::UnsupportedElement {
            element: format!("{:?}", block.element_type),
            entity_dim: block.entity_dim,
            entity: block.entity_tag,
        };
        match block.entity_dim {
            2 => {
                let s = surface_of(block, groups, nodes)?;
                for e in &block.elements {
                    match (block.element_type, &e.nodes[..]) {
                        (ElementType::Tri3, &[a, b, c]) => out.tris[s].push([a, b, c]),
                        (ElementType::Qua4, &[a, b, c, d]) => out.quads[s].push([a, b, c, d]),
                        _ => return Err(unsupported()),
                    }
                }
            }
            1 => {
                let in_groups = groups
                    .curve_groups
                    .get(&block.entity_tag)
                    .copied()
                    .unwrap_or(&[]);
                for e in &block.elements {
                    let (ElementType::Lin2, &[a, b]) = (block.element_type, &e.nodes[..]) else {
                        return Err(unsupported());
                    };
                    for &g in in_groups {
                        out.curves.entry(g).or_default().push([a, b]);
                    }
                }
            }
            0 => {}
            _ => return Err(unsupported()),
        }
    }
    Ok(out)
}

/// The physical surface of a block of surface elements: its entity must be in exactly one.
fn surface_of(
    block: &ElementBlock<u64, i32>,
    groups: &Groups,
    nodes: &Nodes,
) -> Result<usize, GmshErrorKind> {
    let tags: BTreeSet<i32> = groups
        .surface_groups
        .get(&block.entity_tag)
        .map_or_else(BTreeSet::new, |g| g.iter().copied().collect());
    let tags: Vec<i32> = tags.into_iter().collect();
    match tags[..] {
        [] => Err(GmshErrorKind::UnassignedSurface {
            entity: block.entity_tag,
        }),
        [g] => Ok(groups.surface_index[&g]),
        [a, b, ..] => {
            // Report a node inside the entity: it is certainly in both groups.
            let inside = nodes
                .classified
                .iter()
                .filter(|(_, &c)| c == (2, block.entity_tag))
                .map(|(&id, _)| id)
                .min();
            let first = block
                .elements
                .first()
                .and_then(|e| e.nodes.first())
                .copied();
            Err(GmshErrorKind::NodeInTwoSurfaces {
                node: inside.or(first).unwrap_or(0),
                surfaces: [groups.name(2, a), groups.name(2, b)],
            })
        }
    }
}

fn assemble(
    groups: &Groups,
    elements: &Elements,
    nodes: &Nodes,
) -> Result<GmshMesh, GmshErrorKind> {
    let Elements {
        tris,
        quads,
        curves,
    } = elements;
    // A node inside a surface entity is used by that surface alone (entities in two groups
    // were refused), so the lowest surface using a node is its owner in every case.
    let mut owner: BTreeMap<u64, usize> = BTreeMap::new();
    let mut users: Vec<BTreeSet<u64>> = vec![BTreeSet::new(); groups.surface_tags.len()];
    for (s, used) in users.iter_mut().enumerate() {
        for &id in tris[s].iter().flatten().chain(quads[s].iter().flatten()) {
            used.insert(id);
            owner.entry(id).or_insert(s);
        }
    }
    let index: HashMap<u64, usize> = owner.keys().enumerate().map(|(i, &id)| (id, i)).collect();
    let mut mesh_nodes = Vec::with_capacity(owner.len());
    for (&id, &surface) in &owner {
        mesh_nodes.push(GmshNode {
            id,
            position: nodes.position(id)?,
            size: 0.0,
            surface,
        });
    }
    mesh_sizes(&mut mesh_nodes, &index, tris, quads);
    let surfaces = groups
        .surface_tags
        .iter()
        .enumerate()
        .map(|(s, &tag)| PhysicalSurface {
            name: groups.name(2, tag),
            tag,
            nodes: users[s].iter().map(|id| index[id]).collect(),
            triangles: tris[s].iter().map(|t| t.map(|id| index[&id])).collect(),
            quads: quads[s].iter().map(|q| q.map(|id| index[&id])).collect(),
        })
        .collect();
    let mut out_curves = Vec::new();
    for (&tag, segments) in curves {
        let coordinates = segments
            .iter()
            .map(|&[a, b]| Ok([nodes.position(a)?, nodes.position(b)?]))
            .collect::<Result<Vec<_>, GmshErrorKind>>()?;
        out_curves.push(PhysicalCurve {
            name: groups.name(1, tag),
            tag,
            segments: segments.clone(),
            coordinates,
        });
    }
    Ok(GmshMesh {
        path: PathBuf::new(),
        nodes: mesh_nodes,
        surfaces,
        curves: out_curves,
    })
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
