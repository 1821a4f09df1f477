//! `body.mesh`: a body imported from a 2D Gmsh mesh, resolved into the scene's own terms.
//!
//! Each physical surface becomes zones, one per outline (with the holes inside it), whose
//! polygons run through the surface's boundary nodes; each physical curve names the zone edges
//! it runs along; each node becomes a particle with the local mesh size as its spacing. The
//! resolved scene keeps the zones and records the file in `body.imported`, so everything after
//! `new` (the triangles' materials, geostatic stress, `on =` selections, the notch rules, a
//! case file read on another machine) works from the scene alone, as for drawn zones.

use super::field_path::FieldPath;
use super::schema::{ImportedNode, Scene, Zone};
use super::validate::Invalid;
use crate::geometry::{self, GmshMesh, Point};
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where `body.mesh` is read from: relative to the scene file's folder (a built-in scene or a
/// bare name: the working directory).
fn mesh_path(source: &str, mesh: &str) -> PathBuf {
    let given = Path::new(mesh);
    match super::scene_file(source).and_then(Path::parent) {
        Some(dir) if given.is_relative() => dir.join(given),
        _ => given.to_path_buf(),
    }
}

/// Reads `body.mesh` and replaces it by zones, `body.imported` and the nodes to become particles.
/// `body.zones` entries may only claim physical surfaces for materials (a `name` and a
/// `material`, no shape).
pub fn import(scene: &mut Scene, source: &str) -> Result<(), Invalid> {
    let Some(mesh) = scene.body.mesh.clone() else {
        return Ok(());
    };
    let field = FieldPath::key("body").join("mesh");
    if !scene.body.rectangles.is_empty() {
        return Err((
            field,
            "a body is either `rectangles` or an imported `mesh`, not both".to_string(),
        ));
    }
    let claims = claims(scene)?;
    let path = mesh_path(source, &mesh);
    let msh = geometry::read_msh(&path).map_err(|e| (field.clone(), e.to_string()))?;
    let surfaces_of = surface_materials(scene, &msh, &claims, &field)?;
    let mut zones = Vec::new();
    for (s, surface) in msh.surfaces.iter().enumerate() {
        let outlines = outlines(&msh, s).map_err(|m| {
            (
                field.clone(),
                format!(
                    "{}: physical surface \"{}\": {m}",
                    path.display(),
                    surface.name
                ),
            )
        })?;
        let claim = claims.get(surface.name.as_str());
        for outline in outlines {
            let zone = Zone {
                name: Some(surface.name.clone()),
                material: surfaces_of[s].1.clone(),
                k0: claim.and_then(|z| z.k0),
                polygon: Some(outline.rings[0].clone()),
                holes: outline.rings[1..].to_vec(),
                edges: named_or_empty(&outline.names[0]),
                hole_edges: hole_names(&outline.names[1..]),
                circle: None,
                rectangle: None,
            };
            super::zones::shape(&zone, &field).map_err(|(_, m)| {
                (
                    field.clone(),
                    format!(
                        "{}: physical surface \"{}\" does not bound a simple polygon: {m}",
                        path.display(),
                        surface.name
                    ),
                )
            })?;
            zones.push(zone);
        }
    }
    let nodes = msh
        .nodes
        .iter()
        .map(|n| ImportedNode {
            position: n.position,
            h: n.size,
            material: surfaces_of[n.surface].0,
        })
        .collect();
    scene.body.zones = zones;
    scene.body.imported = Some(mesh);
    scene.body.mesh = None;
    scene.body.imported_nodes = Some(Arc::new(nodes));
    Ok(())
}

/// The `[[body.zones]]` entries, each a claim of a physical surface by name for a material.
fn claims(scene: &Scene) -> Result<HashMap<&str, &Zone>, Invalid> {
    let at = FieldPath::key("body").join("zones");
    let mut out = HashMap::new();
    for (i, z) in scene.body.zones.iter().enumerate() {
        let shaped = z.polygon.is_some() || z.circle.is_some() || z.rectangle.is_some();
        let Some(name) = z.name.as_deref().filter(|_| !shaped) else {
            return Err((
                at.at(i),
                "with body.mesh, a zone only gives a physical surface of the mesh (`name`) its \
                 `material` (and `k0`): no polygon, circle or rectangle"
                    .to_string(),
            ));
        };
        if out.insert(name, z).is_some() {
            return Err((
                at.at(i).join("name"),
                format!("claims physical surface \"{name}\" a second time"),
            ));
        }
    }
    Ok(out)
}

/// Each physical surface's material: (index, name as a zone names it).
fn surface_materials(
    scene: &Scene,
    msh: &GmshMesh,
    claims: &HashMap<&str, &Zone>,
    field: &FieldPath,
) -> Result<Vec<(u32, Option<String>)>, Invalid> {
    let at = FieldPath::key("body").join("zones");
    let names: Vec<&str> = msh.surfaces.iter().map(|s| s.name.as_str()).collect();
    for (i, z) in scene.body.zones.iter().enumerate() {
        let name = z.name.as_deref().unwrap_or_default();
        if !names.contains(&name) {
            return Err((
                at.at(i).join("name"),
                format!(
                    "\"{name}\" is no physical surface of {} (it has: {})",
                    msh.path.display(),
                    names.join(", ")
                ),
            ));
        }
    }
    let all = scene.material.all();
    let mut out = Vec::with_capacity(names.len());
    for name in names {
        let by_claim = claims.get(name).and_then(|z| z.material.clone());
        let chosen = by_claim.or_else(|| {
            all.iter()
                .filter_map(|m| m.name.clone())
                .find(|m| m == name)
        });
        let resolved = match chosen {
            Some(m) => scene.material.index_of(&m).map(|i| (i as u32, Some(m))),
            None if all.len() == 1 => Some((0, None)),
            None => None,
        };
        let Some(resolved) = resolved else {
            return Err((
                field.clone(),
                format!(
                    "{}: physical surface \"{name}\" is claimed by no [[material]] of that \
                     name and no [[body.zones]] entry (name = \"{name}\", material = \"...\")",
                    msh.path.display()
                ),
            ));
        };
        out.push(resolved);
    }
    Ok(out)
}

/// The rings of one zone, outer first, and each ring's edge names (edge k from vertex k).
struct Outline {
    rings: Vec<Vec<Point>>,
    names: Vec<Vec<Option<String>>>,
}

fn shoelace(ring: &[Point]) -> f64 {
    let n = ring.len();
    (0..n)
        .map(|k| {
            let (a, b) = (ring[k], ring[(k + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        * 0.5
}

/// The outlines of surface `s`: its elements' edges that no other element of the surface
/// shares, chained into rings (counter-clockwise around the surface, so clockwise around its
/// holes), each hole given to the smallest outline around it.
fn outlines(msh: &GmshMesh, s: usize) -> Result<Vec<Outline>, String> {
    let surface = &msh.surfaces[s];
    let at = |i: usize| msh.nodes[i].position;
    let elements = (surface.triangles.iter().map(|t| t.to_vec()))
        .chain(surface.quads.iter().map(|q| q.to_vec()));
    let mut directed: HashSet<(usize, usize)> = HashSet::new();
    for mut e in elements {
        if shoelace(&e.iter().map(|&i| at(i)).collect::<Vec<_>>()) < 0.0 {
            e.reverse();
        }
        for k in 0..e.len() {
            directed.insert((e[k], e[(k + 1) % e.len()]));
        }
    }
    let mut next: BTreeMap<usize, usize> = BTreeMap::new();
    for &(a, b) in &directed {
        if !directed.contains(&(b, a)) && next.insert(a, b).is_some() {
            return Err(format!(
                "its outline touches itself at node {} ({}, {})",
                msh.nodes[a].id,
                at(a)[0],
                at(a)[1]
            ));
        }
    }
    let curve_of = curve_names(msh);
    let mut outers: Vec<Outline> = Vec::new();
    let mut holes: Vec<Outline> = Vec::new();
    while let Some((&start, _)) = next.first_key_value() {
        let mut ring = vec![start];
        let mut here = start;
        loop {
            let Some(to) = next.remove(&here) else {
                return Err(format!(
                    "its outline is open at node {}",
                    msh.nodes[here].id
                ));
            };
            if to == start {
                break;
            }
            ring.push(to);
            here = to;
        }
        let names = (0..ring.len())
            .map(|k| {
                let (a, b) = (
                    msh.nodes[ring[k]].id,
                    msh.nodes[ring[(k + 1) % ring.len()]].id,
                );
                curve_of.get(&(a.min(b), a.max(b))).cloned()
            })
            .collect();
        let points: Vec<Point> = ring.iter().map(|&i| at(i)).collect();
        let outline = Outline {
            rings: vec![points],
            names: vec![names],
        };
        if shoelace(&outline.rings[0]) > 0.0 {
            outers.push(outline);
        } else {
            holes.push(outline);
        }
    }
    for hole in holes {
        let probe = hole.rings[0][0];
        let around = (outers.iter().enumerate())
            .filter(|(_, o)| {
                geometry::Polygon::new(o.rings[0].clone(), Vec::new())
                    .is_ok_and(|p| p.contains(probe))
            })
            .min_by(|a, b| shoelace(&a.1.rings[0]).total_cmp(&shoelace(&b.1.rings[0])))
            .map(|(i, _)| i);
        let Some(o) = around else {
            return Err(format!(
                "a hole at ({}, {}) lies in none of its outlines",
                probe[0], probe[1]
            ));
        };
        outers[o].rings.extend(hole.rings);
        outers[o].names.extend(hole.names);
    }
    Ok(outers)
}

/// The physical curve of each line element by its node tags (lower first); a segment in
/// several curves takes the one of the lowest tag.
fn curve_names(msh: &GmshMesh) -> HashMap<(u64, u64), String> {
    let mut out = HashMap::new();
    for curve in &msh.curves {
        for &[a, b] in &curve.segments {
            out.entry((a.min(b), a.max(b)))
                .or_insert_with(|| curve.name.clone());
        }
    }
    out
}

/// A ring's edge names for the scene ("" unnamed), or none at all when no edge is named.
fn named_or_empty(names: &[Option<String>]) -> Vec<String> {
    if names.iter().all(Option::is_none) {
        return Vec::new();
    }
    names
        .iter()
        .map(|n| n.clone().unwrap_or_default())
        .collect()
}

fn hole_names(holes: &[Vec<Option<String>>]) -> Vec<Vec<String>> {
    let mut out: Vec<Vec<String>> = holes.iter().map(|h| named_or_empty(h)).collect();
    while out.last().is_some_and(Vec::is_empty) {
        out.pop();
    }
    out
}
