//! Gmsh import: the committed layered site (always), the same site meshed now by Gmsh in ASCII
//! and binary (when `gmsh` is on PATH), and each refusal.

use super::gmsh::{parse_msh, read_msh, GmshErrorKind, GmshMesh};
use super::segment::orient;
use std::path::{Path, PathBuf};
use std::process::Command;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// A fresh directory under the system temp dir, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(tag: &str) -> TempDir {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let dir =
            std::env::temp_dir().join(format!("pfem-geo-{tag}-{}-{nanos}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// What any import of layered-site.geo must satisfy, whatever the mesh size.
fn check_layered_site(m: &GmshMesh, file_nodes: usize) {
    let names: Vec<&str> = m.surfaces.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["stiff-clay", "soft-clay"]);
    let curves: Vec<&str> = m.curves.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(curves, ["base", "seabed", "sides"]);
    // Every node of the file is in a surface here, each once: particles = nodes.
    assert_eq!(m.nodes.len(), file_nodes);
    assert!(m.nodes.windows(2).all(|w| w[0].id < w[1].id));
    // Element areas add up to each layer's area.
    for (s, want) in m.surfaces.iter().zip([80.0, 60.0]) {
        let area: f64 = s
            .triangles
            .iter()
            .map(|t| {
                0.5 * orient(
                    m.nodes[t[0]].position,
                    m.nodes[t[1]].position,
                    m.nodes[t[2]].position,
                )
                .abs()
            })
            .sum();
        assert!((area - want).abs() < 1e-9, "{}: {area}", s.name);
    }
    // Interface nodes (y = 4) are used by both layers and owned by the lower tag.
    let interface: Vec<usize> = (0..m.nodes.len())
        .filter(|&k| m.nodes[k].position[1] == 4.0)
        .collect();
    assert!(interface.len() >= 3);
    for &k in &interface {
        assert_eq!(m.nodes[k].surface, 0);
        assert!(m.surfaces.iter().all(|s| s.nodes.binary_search(&k).is_ok()));
    }
    for n in &m.nodes {
        let expect = if n.position[1] < 4.0 {
            0
        } else if n.position[1] > 4.0 {
            1
        } else {
            0
        };
        assert_eq!(n.surface, expect, "{n:?}");
        assert!(n.size > 0.0);
    }
    // The seabed is the top, y = 7, covered once from x = 0 to 20.
    let seabed = &m.curves[1];
    assert!(seabed
        .coordinates
        .iter()
        .all(|s| s[0][1] == 7.0 && s[1][1] == 7.0));
    let len: f64 = seabed
        .coordinates
        .iter()
        .map(|s| (s[1][0] - s[0][0]).abs())
        .sum();
    assert!((len - 20.0).abs() < 1e-9);
    let sides = &m.curves[2];
    let len: f64 = sides
        .coordinates
        .iter()
        .map(|s| (s[1][1] - s[0][1]).abs())
        .sum();
    assert!((len - 14.0).abs() < 1e-9);
    assert_eq!(seabed.segments.len(), seabed.coordinates.len());
}

fn file_node_count(bytes: &[u8]) -> usize {
    let text = String::from_utf8_lossy(bytes);
    let mut lines = text.lines().skip_while(|l| l.trim() != "$Nodes");
    lines.next();
    lines
        .next()
        .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        .unwrap()
}

#[test]
fn committed_ascii_mesh_of_the_layered_site() {
    let path = data("layered-site.msh");
    let m = read_msh(&path).unwrap();
    assert_eq!(m.path, path);
    check_layered_site(&m, file_node_count(&std::fs::read(&path).unwrap()));
    // Made with -clscale 2.5 from lc = 1: sizes near 2.5.
    let mean = m.nodes.iter().map(|n| n.size).sum::<f64>() / m.nodes.len() as f64;
    assert!((1.5..3.5).contains(&mean), "mean size {mean}");
}

#[test]
fn gmsh_meshes_the_committed_geo_in_ascii_and_binary() {
    if Command::new("gmsh").arg("--version").output().is_err() {
        eprintln!("gmsh not on PATH: skipping the .geo -> .msh round trip");
        return;
    }
    let dir = TempDir::new("gmsh");
    let mut meshes = Vec::new();
    for binary in [false, true] {
        let out = dir.0.join(if binary { "bin.msh" } else { "ascii.msh" });
        let mut cmd = Command::new("gmsh");
        cmd.arg("-2")
            .arg("-format")
            .arg("msh41")
            .arg(data("layered-site.geo"))
            .arg("-o")
            .arg(&out);
        if binary {
            cmd.arg("-bin");
        }
        let status = cmd.output().unwrap();
        assert!(
            status.status.success(),
            "{}",
            String::from_utf8_lossy(&status.stderr)
        );
        meshes.push(read_msh(&out).unwrap());
    }
    let ascii_nodes = file_node_count(&std::fs::read(dir.0.join("ascii.msh")).unwrap());
    check_layered_site(&meshes[0], ascii_nodes);
    // ASCII keeps 16 significant digits, binary all 17: the same mesh to rounding.
    let (a, b) = (&meshes[0], &meshes[1]);
    assert!(a.surfaces == b.surfaces, "element lists differ");
    assert_eq!(a.nodes.len(), b.nodes.len());
    for (p, q) in a.nodes.iter().zip(&b.nodes) {
        assert_eq!((p.id, p.surface), (q.id, q.surface));
        assert!(
            (p.position[0] - q.position[0]).abs() + (p.position[1] - q.position[1]).abs() < 1e-12
        );
    }
    let segs = |m: &GmshMesh| {
        m.curves
            .iter()
            .map(|c| (c.name.clone(), c.segments.clone()))
            .collect::<Vec<_>>()
    };
    assert!(segs(a) == segs(b), "curves differ");
    // lc = 1 in the .geo.
    let mean = a.nodes.iter().map(|n| n.size).sum::<f64>() / a.nodes.len() as f64;
    assert!((0.7..1.3).contains(&mean), "mean size {mean}");
}

/// A one-triangle MSH 4.1 file: surface physical tags `phys`, third node at height `z`, with
/// an optional volume entity.
fn tiny(z: f64, phys: &[i32], names: &str, volume: bool) -> String {
    let tags: String = phys.iter().map(|t| format!(" {t}")).collect();
    let vol = if volume { "1 0 0 0 1 1 1 0 0\n" } else { "" };
    format!(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n{names}$Entities\n0 0 1 {}\n1 0 0 0 1 1 0 {}{tags} 0\n{vol}$EndEntities\n\
         $Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 {z}\n$EndNodes\n\
         $Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n",
        volume as u8,
        phys.len()
    )
}

fn kind(text: &str) -> GmshErrorKind {
    parse_msh(Path::new("t.msh"), text.as_bytes())
        .unwrap_err()
        .kind
}

#[test]
fn tiny_file_imports() {
    let m = parse_msh(
        Path::new("t.msh"),
        tiny(
            0.0,
            &[7],
            "$PhysicalNames\n1\n2 7 \"clay\"\n$EndPhysicalNames\n",
            false,
        )
        .as_bytes(),
    )
    .unwrap();
    assert_eq!(m.surfaces.len(), 1);
    assert_eq!(
        (m.surfaces[0].name.as_str(), m.surfaces[0].tag),
        ("clay", 7)
    );
    assert_eq!(m.surfaces[0].triangles, vec![[0, 1, 2]]);
    assert_eq!(m.nodes[2].position, [0.0, 1.0]);
    // Node 1's edges: 1 and 1.
    assert_eq!(m.nodes[0].size, 1.0);
    // Unnamed groups are named by their tag.
    let m = parse_msh(Path::new("t.msh"), tiny(0.0, &[7], "", false).as_bytes()).unwrap();
    assert_eq!(m.surfaces[0].name, "7");
}

#[test]
fn refusals_name_the_file_and_the_reason() {
    let e = read_msh(Path::new("/nonexistent/site.msh")).unwrap_err();
    assert_eq!(e.kind, GmshErrorKind::NotFound);
    assert!(e.to_string().contains("/nonexistent/site.msh"));
    assert_eq!(
        kind("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n0\n$EndNodes\n"),
        GmshErrorKind::Version {
            found: "2.2".into()
        }
    );
    assert_eq!(
        kind(&tiny(0.5, &[1], "", false)),
        GmshErrorKind::NodeOutOfPlane { node: 3, z: 0.5 }
    );
    assert_eq!(
        kind(&tiny(0.0, &[1], "", true)),
        GmshErrorKind::Volumes { count: 1 }
    );
    assert_eq!(
        kind(&tiny(0.0, &[], "", false)),
        GmshErrorKind::NoPhysicalGroups
    );
    let names = "$PhysicalNames\n2\n2 1 \"soft\"\n2 2 \"stiff\"\n$EndPhysicalNames\n";
    assert_eq!(
        kind(&tiny(0.0, &[1, 2], names, false)),
        GmshErrorKind::NodeInTwoSurfaces {
            node: 1,
            surfaces: ["soft".into(), "stiff".into()]
        }
    );
    let unknown =
        tiny(0.0, &[1], "", false).replace("1 1 2 3\n$EndElements", "1 1 2 9\n$EndElements");
    assert_eq!(kind(&unknown), GmshErrorKind::UnknownNode { node: 9 });
    let infinite = tiny(0.0, &[1], "", false).replace("\n1 0 0\n", "\ninf 0 0\n");
    assert!(
        matches!(kind(&infinite), GmshErrorKind::Damaged { .. }),
        "{:?}",
        kind(&infinite)
    );
    // mshio unwraps the data-size field and would panic on this one.
    let huge = "$MeshFormat\n4.1 0 99999999999999999999999\n$EndMeshFormat\n";
    assert!(matches!(kind(huge), GmshErrorKind::Damaged { .. }));
    let quad9 =
        tiny(0.0, &[1], "", false).replace("2 1 2 1\n1 1 2 3\n", "2 1 10 1\n1 1 2 3 1 2 3 1 2 3\n");
    assert!(matches!(
        kind(&quad9),
        GmshErrorKind::UnsupportedElement { .. }
    ));
}

#[test]
fn truncated_and_garbled_files_are_damaged_not_panics() {
    let good = std::fs::read(data("layered-site.msh")).unwrap();
    let dir = TempDir::new("bin");
    let mut inputs: Vec<Vec<u8>> = Vec::new();
    // Cut at 40 places through the file.
    for k in 1..40 {
        inputs.push(good[..good.len() * k / 40].to_vec());
    }
    // Overwrite bytes at pseudo-random places with pseudo-random values.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..200 {
        let mut g = good.clone();
        for _ in 0..3 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let at = (state % g.len() as u64) as usize;
            g[at] = (state >> 32) as u8;
        }
        inputs.push(g);
    }
    // A binary file cut short, when gmsh can make one.
    let bin = dir.0.join("b.msh");
    let made = Command::new("gmsh")
        .args(["-2", "-format", "msh41", "-bin"])
        .arg(data("layered-site.geo"))
        .arg("-o")
        .arg(&bin)
        .output()
        .is_ok_and(|o| o.status.success());
    if made {
        let b = std::fs::read(&bin).unwrap();
        for k in 1..20 {
            inputs.push(b[..b.len() * k / 20].to_vec());
        }
    }
    let mut refused = 0;
    for input in &inputs {
        // Garbling may leave a valid file (e.g. a digit in a coordinate); it must not panic.
        let r = std::panic::catch_unwind(|| parse_msh(Path::new("x.msh"), input));
        let r = r.expect("the importer panicked");
        if let Err(e) = r {
            assert_eq!(e.path, Path::new("x.msh"));
            refused += 1;
        }
    }
    // Every truncated file is refused.
    assert!(
        refused >= 39 + if made { 19 } else { 0 },
        "{refused} refused"
    );
}
