//! Named boundaries (polygon edges named in a scene, Gmsh physical curves) and selecting
//! points on them, for `on = "seabed"` selections.

use super::bvh::SegmentTree;
use super::gmsh::GmshMesh;
use super::segment::Point;
use super::shape::Shape;
use std::collections::BTreeMap;
use std::fmt;

/// An `on =` name that no zone edge or physical curve carries.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownBoundary {
    pub name: String,
    /// The names that exist, sorted.
    pub known: Vec<String>,
}

impl fmt::Display for UnknownBoundary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "no boundary is named {:?} (named boundaries: {:?})",
            self.name, self.known
        )
    }
}

impl std::error::Error for UnknownBoundary {}

/// Segments grouped by name, each group indexed for distance queries.
#[derive(Debug, Clone, Default)]
pub struct NamedBoundaries {
    by_name: BTreeMap<String, SegmentTree>,
}

impl NamedBoundaries {
    /// Groups `(name, segment)` pairs; a name may come from several sources (a zone edge and a
    /// physical curve, several zones).
    pub fn from_segments(segs: impl IntoIterator<Item = (String, [Point; 2])>) -> NamedBoundaries {
        let mut groups: BTreeMap<String, Vec<[Point; 2]>> = BTreeMap::new();
        for (name, s) in segs {
            groups.entry(name).or_default().push(s);
        }
        NamedBoundaries {
            by_name: groups
                .into_iter()
                .map(|(n, s)| (n, SegmentTree::new(s)))
                .collect(),
        }
    }

    pub fn names(&self) -> Vec<&str> {
        self.by_name.keys().map(String::as_str).collect()
    }

    /// Distance from `p` to the boundary `name`.
    pub fn distance(&self, name: &str, p: Point) -> Result<f64, UnknownBoundary> {
        let tree = self.tree(name)?;
        Ok(tree.nearest(p).map_or(f64::INFINITY, |(d, _)| d))
    }

    /// Indices of the `points` within `tol` of the boundary `name`, ascending. Particles placed
    /// on an edge by the fill, or Gmsh nodes of a curve, are within rounding of it, so a `tol`
    /// of about 1e-6 h selects exactly them.
    pub fn select(
        &self,
        name: &str,
        points: &[Point],
        tol: f64,
    ) -> Result<Vec<usize>, UnknownBoundary> {
        let tree = self.tree(name)?;
        Ok((0..points.len())
            .filter(|&k| tree.nearest(points[k]).is_some_and(|(d, _)| d <= tol))
            .collect())
    }

    fn tree(&self, name: &str) -> Result<&SegmentTree, UnknownBoundary> {
        self.by_name.get(name).ok_or_else(|| UnknownBoundary {
            name: name.to_string(),
            known: self.by_name.keys().cloned().collect(),
        })
    }
}

/// The named edges of `zones` (circles cut into chords at spacing `h`).
pub fn zone_segments(zones: &[Shape], h: f64) -> Vec<(String, [Point; 2])> {
    zones
        .iter()
        .flat_map(|z| z.boundary(h))
        .filter_map(|s| s.name.map(|n| (n, [s.a, s.b])))
        .collect()
}

/// The segments of every physical curve of `mesh`, by the curve's name.
pub fn gmsh_segments(mesh: &GmshMesh) -> Vec<(String, [Point; 2])> {
    mesh.curves
        .iter()
        .flat_map(|c| c.coordinates.iter().map(move |&s| (c.name.clone(), s)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::fill::{fill_zones, FillParams};
    use crate::geometry::gmsh::read_msh;
    use crate::geometry::polygon::Polygon;

    #[test]
    fn selects_fill_particles_on_a_named_slope_face() {
        let h = 0.5;
        let run = 6.0 / 30f64.to_radians().tan();
        let outer = vec![
            [0.0, 0.0],
            [30.0, 0.0],
            [30.0, 10.0],
            [8.0 + run, 10.0],
            [8.0, 4.0],
            [0.0, 4.0],
        ];
        let mut names = vec![None; 6];
        names[0] = Some("base".to_string());
        names[3] = Some("face".to_string());
        let zones = [Shape::Polygon(
            Polygon::with_edge_names(outer, vec![], vec![names]).unwrap(),
        )];
        let pts: Vec<Point> = fill_zones(&zones, &FillParams::new(h, [0.0, 0.0]))
            .unwrap()
            .into_iter()
            .map(|p| p.position)
            .collect();
        let b = NamedBoundaries::from_segments(zone_segments(&zones, h));
        assert_eq!(b.names(), ["base", "face"]);
        let face = b.select("face", &pts, 1e-6 * h).unwrap();
        // 12 m of face at h = 0.5: 24 parts, 25 particles, all on the line through its ends.
        assert_eq!(face.len(), 25);
        for &k in &face {
            let p = pts[k];
            assert!(((p[1] - 4.0) - (p[0] - 8.0) * 30f64.to_radians().tan()).abs() < 1e-9);
        }
        assert_eq!(b.select("base", &pts, 1e-6 * h).unwrap().len(), 61);
        let err = b.select("seabed", &pts, 1e-6).unwrap_err();
        assert_eq!(err.known, ["base", "face"]);
        assert!(err.to_string().contains("seabed"));
    }

    #[test]
    fn selects_gmsh_nodes_on_a_physical_curve() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/layered-site.msh");
        let m = read_msh(&path).unwrap();
        let b = NamedBoundaries::from_segments(gmsh_segments(&m));
        let pts: Vec<Point> = m.nodes.iter().map(|n| n.position).collect();
        let seabed = b.select("seabed", &pts, 1e-9).unwrap();
        let top: Vec<usize> = (0..pts.len()).filter(|&k| pts[k][1] == 7.0).collect();
        assert_eq!(seabed, top);
        assert_eq!(b.distance("base", [3.0, 2.5]).unwrap(), 2.5);
    }
}
