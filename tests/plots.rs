//! `pfem_mpi::plot::plot_run` on synthetic output folders: a history of each scene kind, and a
//! frame written here with the hdf5 crate in the solver's layout (see `src/output`). The PNGs
//! are decoded and checked for size and content.

use std::fs;
use std::path::{Path, PathBuf};

use pfem_mpi::plot::{
    colour_map, plot_run, plot_run_in, Window, BLOCK_SIZE, COLOUR_BAR_WIDTH, CONTOUR_SIZE,
    CURVE_SIZE,
};

/// A fresh, empty folder for one test.
fn folder(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("plots-{name}"));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// A decoded RGB picture.
struct Picture {
    width: u32,
    height: u32,
    rgb: Vec<[u8; 3]>,
}

impl Picture {
    fn read(path: &Path) -> Picture {
        let file = fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut reader = png::Decoder::new(file).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        let channels = match info.color_type {
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            other => panic!("{}: unexpected colour type {other:?}", path.display()),
        };
        assert_eq!(info.bit_depth, png::BitDepth::Eight);
        let rgb = buf[..info.buffer_size()]
            .chunks_exact(channels)
            .map(|p| [p[0], p[1], p[2]])
            .collect();
        Picture {
            width: info.width,
            height: info.height,
            rgb,
        }
    }

    fn distinct_colours(&self) -> usize {
        let mut c = self.rgb.clone();
        c.sort_unstable();
        c.dedup();
        c.len()
    }

    /// Pixels (column, row) left of `right_edge` within `tolerance` of `colour`.
    fn near(&self, colour: [u8; 3], tolerance: i32, right_edge: u32) -> Vec<(u32, u32)> {
        (0..self.height)
            .flat_map(|r| (0..right_edge).map(move |c| (c, r)))
            .filter(|&(c, r)| {
                let p = self.rgb[(r * self.width + c) as usize];
                (0..3).all(|k| (i32::from(p[k]) - i32::from(colour[k])).abs() <= tolerance)
            })
            .collect()
    }
}

fn mean(v: &[(u32, u32)], pick: impl Fn(&(u32, u32)) -> u32) -> f64 {
    v.iter().map(|p| f64::from(pick(p))).sum::<f64>() / v.len() as f64
}

fn assert_drawn(path: &Path, size: (u32, u32)) -> Picture {
    let p = Picture::read(path);
    assert_eq!((p.width, p.height), size, "{}", path.display());
    let colours = p.distinct_colours();
    assert!(colours >= 20, "{}: {colours} colours", path.display());
    let white = p.rgb.iter().filter(|c| **c == [255, 255, 255]).count();
    assert!(white < p.rgb.len(), "{} is blank", path.display());
    p
}

const CANTILEVER: &str = "step,lambda,u_over_L,v_over_L\n\
    1,2,0.15,0.48\n2,4,0.32,0.66\n3,6,0.43,0.74\n4,8,0.50,0.78\n5,10,0.55,0.81\n";

/// Nodes of an `n` x `n` grid on the unit square, sheared a little as a deformed body is.
fn grid(n: usize) -> (Vec<[f64; 2]>, Vec<[i64; 3]>) {
    let mut xy = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64);
            xy.push([x + 0.1 * y, y]);
        }
    }
    let mut tri = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = (j * n + i) as i64;
            let (b, c, d) = (a + 1, a + 1 + n as i64, a + n as i64);
            tri.push([a, b, c]);
            tri.push([a, c, d]);
        }
    }
    (xy, tri)
}

/// The series file of one frame, as `crate::output` writes it.
fn series(step: u64, points: usize, triangles: usize) -> String {
    let file = format!("fields/step_{step:06}.h5");
    let item = |dims: String, kind: &str, ds: &str| {
        format!(
            "<DataItem Dimensions=\"{dims}\" NumberType=\"{kind}\" Precision=\"8\" \
             Format=\"HDF\">{file}:/{ds}</DataItem>"
        )
    };
    let scalar = |name: &str| {
        format!(
            "<Attribute Name=\"{name}\" AttributeType=\"Scalar\" Center=\"Node\">{}</Attribute>\n",
            item(points.to_string(), "Float", &format!("point_data/{name}"))
        )
    };
    format!(
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n    \
         <Grid Name=\"fields\" GridType=\"Collection\" CollectionType=\"Temporal\">\n      \
         <Grid Name=\"step_{step:06}\" GridType=\"Uniform\">\n        <Time Value=\"0.5\"/>\n\
         <Topology TopologyType=\"Triangle\" NumberOfElements=\"{triangles}\">{}</Topology>\n\
         <Geometry GeometryType=\"XY\">\n{}\n</Geometry>\n{}{}{}\
         </Grid>\n    </Grid>\n  </Domain>\n</Xdmf>\n",
        item(format!("{triangles} 3"), "Int", "connectivity"),
        item(format!("{points} 2"), "Float", "geometry"),
        scalar("eps_q"),
        scalar("sigma_yy"),
        scalar("tau_xy"),
    )
}

/// Writes `DIR/fields.xdmf` and the frame file of `step` with the fields the solver writes,
/// leaving out `omit` and writing `zero` as zero everywhere.
fn write_frame(dir: &Path, step: u64, omit: &str, bad_vertex: bool, zero: &str) {
    let (xy, mut tri) = grid(7);
    if bad_vertex {
        tri[3][1] = xy.len() as i64;
    }
    fs::create_dir_all(dir.join("fields")).unwrap();
    fs::write(dir.join("fields.xdmf"), series(step, xy.len(), tri.len())).unwrap();
    let file = hdf5::File::create(dir.join(format!("fields/step_{step:06}.h5"))).unwrap();
    let n = xy.len();
    file.new_dataset::<f64>()
        .shape((n, 2))
        .create("geometry")
        .unwrap()
        .write_raw(xy.as_flattened())
        .unwrap();
    file.new_dataset::<i64>()
        .shape((tri.len(), 3))
        .create("connectivity")
        .unwrap()
        .write_raw(tri.as_flattened())
        .unwrap();
    let group = file.create_group("point_data").unwrap();
    let scalar = |name: &str, f: &dyn Fn([f64; 2]) -> f64| {
        if name != omit {
            let v: Vec<f64> = xy
                .iter()
                .map(|&p| if name == zero { 0.0 } else { f(p) })
                .collect();
            let ds = group.new_dataset::<f64>().shape(n).create(name).unwrap();
            ds.write_raw(&v).unwrap();
        }
    };
    // eps_q grows to the right, sigma_yy upwards (compression at the bottom).
    scalar("eps_q", &|p| 0.2 * p[0]);
    scalar("sigma_yy", &|p| -1000.0 * (1.0 - p[1]));
    scalar("tau_xy", &|p| 300.0 * p[0] * p[1]);
    scalar("pressure", &|p| 500.0 * (1.0 - p[1]));
    scalar("rank", &|_| 0.0);
    let vector: Vec<f64> = xy.iter().flat_map(|p| [0.01 * p[1], -0.02, 0.0]).collect();
    for name in ["displacement", "incremental_displacement"] {
        if name != omit {
            let ds = group
                .new_dataset::<f64>()
                .shape((n, 3))
                .create(name)
                .unwrap();
            ds.write_raw(&vector).unwrap();
        }
    }
}

#[test]
fn cantilever_history_and_contours() {
    let dir = folder("cantilever");
    fs::write(dir.join("history.csv"), CANTILEVER).unwrap();
    write_frame(&dir, 7, "", false, "");
    let written = plot_run(&dir).unwrap();
    let names: Vec<String> = written
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "history.png",
            "incremental_displacement.png",
            "eps_q.png",
            "sigma_yy.png",
            "tau_xy.png"
        ]
    );
    assert!(written
        .iter()
        .all(|p| p.parent() == Some(&dir.join("plots"))));

    assert_drawn(&written[0], CURVE_SIZE);
    let mesh_right = CONTOUR_SIZE.0 - COLOUR_BAR_WIDTH;
    for (path, min_side, max_side) in [
        (&written[2], "left", "right"),
        (&written[3], "bottom", "top"),
    ] {
        let p = assert_drawn(path, CONTOUR_SIZE);
        let low = p.near(colour_map(0.0), 40, mesh_right);
        let high = p.near(colour_map(1.0), 40, mesh_right);
        let name = path.display();
        assert!(
            low.len() > 50,
            "{name}: {} minimum-coloured pixels",
            low.len()
        );
        assert!(
            high.len() > 50,
            "{name}: {} maximum-coloured pixels",
            high.len()
        );
        if min_side == "left" {
            assert!(
                mean(&low, |p| p.0) < mean(&high, |p| p.0),
                "{name}: minimum not {min_side} of maximum ({max_side})"
            );
        } else {
            // Image rows grow downwards.
            assert!(
                mean(&low, |p| p.1) > mean(&high, |p| p.1),
                "{name}: minimum not {min_side} of maximum ({max_side})"
            );
        }
        // The middle of the scale is there too: the field is interpolated, not flat.
        assert!(p.near(colour_map(0.5), 40, mesh_right).len() > 50, "{name}");
    }
    assert_drawn(&written[4], CONTOUR_SIZE);
}

#[test]
fn footing_without_fields_draws_the_history_only() {
    let dir = folder("footing");
    let rows: String = (0..=100)
        .map(|k| {
            let z = 0.01 * f64::from(k);
            format!("{k},{z},{}\n", 5.2 * (1.0 - (-40.0 * z).exp()) + 1.5 * z)
        })
        .collect();
    fs::write(
        dir.join("history.csv"),
        format!("step,z_over_B,q_over_cu\n{rows}"),
    )
    .unwrap();
    let written = plot_run(&dir).unwrap();
    assert_eq!(written, vec![dir.join("plots/history.png")]);
    assert_drawn(&written[0], CURVE_SIZE);

    // A series with no frame yet draws no contours either.
    fs::write(
        dir.join("fields.xdmf"),
        "<?xml version=\"1.0\"?>\n<Xdmf Version=\"3.0\"><Domain><Grid Name=\"fields\" \
         GridType=\"Collection\" CollectionType=\"Temporal\"></Grid></Domain></Xdmf>\n",
    )
    .unwrap();
    assert_eq!(plot_run(&dir).unwrap().len(), 1);
}

#[test]
fn block_draws_two_panels() {
    let dir = folder("block");
    let rows: String = (0..=40)
        .map(|k| {
            let e = 0.005 * f64::from(k);
            format!("{k},{e},{},{}\n", (400.0 * e).min(2.0), 1.0 - 0.01 * e)
        })
        .collect();
    fs::write(
        dir.join("history.csv"),
        format!("step,strain,stress_over_cu,volume_ratio\n{rows}"),
    )
    .unwrap();
    let written = plot_run(&dir).unwrap();
    assert_drawn(&written[0], BLOCK_SIZE);

    // A run stopped before its first step has a header only: the references are still drawn.
    fs::write(
        dir.join("history.csv"),
        "step,strain,stress_over_cu,volume_ratio\n",
    )
    .unwrap();
    assert_drawn(&plot_run(&dir).unwrap()[0], BLOCK_SIZE);
}

#[test]
fn bad_history_is_an_error_naming_the_file() {
    let dir = folder("bad-history");
    let path = dir.join("history.csv");
    let e = plot_run(&dir).unwrap_err();
    assert_eq!(e.file, path);
    assert!(
        e.to_string().starts_with(&path.display().to_string()),
        "{e}"
    );

    fs::write(
        &path,
        "step,lambda,u_over_L,v_over_L\n1,1,0.05,0.3\n2,2,abc,0.5\n",
    )
    .unwrap();
    let e = plot_run(&dir).unwrap_err().to_string();
    assert!(e.contains("history.csv") && e.contains("line 3"), "{e}");
    assert!(e.contains("\"abc\" in column u_over_L"), "{e}");

    fs::write(&path, "step,lambda,u_over_L,v_over_L\n1,1,0.05\n").unwrap();
    let e = plot_run(&dir).unwrap_err().to_string();
    assert!(
        e.contains("history.csv: line 2: 3 values for 4 columns"),
        "{e}"
    );

    fs::write(&path, "time,force\n0,1\n").unwrap();
    let e = plot_run(&dir).unwrap_err().to_string();
    assert!(e.contains("history.csv: unknown columns"), "{e}");
    assert!(
        !dir.join("plots").exists(),
        "nothing is written for bad input"
    );
}

#[test]
fn bad_frames_are_errors_naming_the_file() {
    let dir = folder("bad-frame");
    fs::write(dir.join("history.csv"), CANTILEVER).unwrap();

    write_frame(&dir, 3, "sigma_yy", false, "");
    let e = plot_run(&dir).unwrap_err().to_string();
    assert!(
        e.contains("step_000003.h5") && e.contains("no dataset /point_data/sigma_yy"),
        "{e}"
    );

    write_frame(&dir, 4, "", true, "");
    let e = plot_run(&dir).unwrap_err().to_string();
    assert!(
        e.contains("step_000004.h5") && e.contains("/connectivity row 3"),
        "{e}"
    );

    fs::remove_file(dir.join("fields/step_000004.h5")).unwrap();
    let e = plot_run(&dir).unwrap_err().to_string();
    assert!(
        e.contains("step_000004.h5") && e.contains("cannot open"),
        "{e}"
    );

    fs::write(dir.join("fields.xdmf"), "not xml").unwrap();
    let e = plot_run(&dir).unwrap_err().to_string();
    assert!(e.contains("fields.xdmf: not an XDMF file"), "{e}");
}

/// The pixels of exactly `colour` left of the colour bar.
fn count_exact(p: &Picture, colour: [u8; 3]) -> usize {
    p.near(colour, 0, CONTOUR_SIZE.0 - COLOUR_BAR_WIDTH).len()
}

#[test]
fn a_field_that_is_zero_everywhere_gets_no_picture() {
    let dir = folder("zero-field");
    fs::write(dir.join("history.csv"), CANTILEVER).unwrap();
    write_frame(&dir, 7, "", false, "");
    assert!(plot_run(&dir)
        .unwrap()
        .contains(&dir.join("plots/eps_q.png")));
    // The elastic run's eps_q: no picture, and the older one is not left to mislead.
    write_frame(&dir, 8, "", false, "eps_q");
    let written = plot_run(&dir).unwrap();
    assert!(
        !written.contains(&dir.join("plots/eps_q.png")),
        "{written:?}"
    );
    assert!(!dir.join("plots/eps_q.png").exists());
    assert!(
        written.contains(&dir.join("plots/tau_xy.png")),
        "{written:?}"
    );
}

/// A scene of the unit square under a rigid bar (a circle of radius 0.1 at (0.5, 1.1)) pushed
/// 0.2 m down over 10 steps: at step 7 it is 0.14 m down, its lowest point at y = 0.86.
const BAR_SCENE: &str = r#"
name = "plot-bar"

[body]
rectangles = [{ origin = [0.0, 0.0], size = [1.0, 1.0] }]

[mesh]
h = 0.1

[material]
model = "tresca"
young = 1.0e6
poisson = 0.49
cu = 1.0e3

[[fixed]]
where = "y <= 0"
dofs = ["x", "y"]

[[rigid]]
name = "bar"
circle = { centre = [0.5, 1.1], radius = 0.1 }
stages = [{ to = [0.0, -0.2], steps = 10 }]

[steps]
count = 10

[history]
columns = [{ name = "depth", measure = "rigid.bar.uy", scale = -1.0 }]
"#;

#[test]
fn rigid_bodies_are_drawn_where_their_stages_put_them() {
    let dir = folder("rigid-outline");
    fs::write(dir.join("history.csv"), "step,depth\n7,0.14\n").unwrap();
    write_frame(&dir, 7, "", false, "");
    plot_run(&dir).unwrap();
    let without = Picture::read(&dir.join("plots/tau_xy.png"));
    // A few pixels of the smoothed text may happen to have the fill's grey.
    let base = count_exact(&without, [200, 200, 200]);
    assert!(
        base < 50,
        "{base} pixels of the body's grey without a scene"
    );
    fs::write(dir.join("scene.toml"), BAR_SCENE).unwrap();
    plot_run(&dir).unwrap();
    let with = Picture::read(&dir.join("plots/tau_xy.png"));
    let fill = with.near([200, 200, 200], 0, CONTOUR_SIZE.0 - COLOUR_BAR_WIDTH);
    let line = count_exact(&with, [60, 60, 60]);
    // The circle is 0.2 m across in a picture about 1.2 m across 600 pixels: about 100 pixels.
    assert!(
        fill.len() > 2000,
        "{} pixels of the body's fill",
        fill.len()
    );
    assert!(line > 150, "{line} pixels of its outline");
    // It is at the top of the body, in the middle.
    let (col, row) = (mean(&fill, |p| p.0), mean(&fill, |p| p.1));
    let mid = f64::from(CONTOUR_SIZE.0 - COLOUR_BAR_WIDTH) / 2.0;
    assert!(
        (col - mid).abs() < 80.0,
        "column {col} against the middle {mid}"
    );
    assert!(
        row < f64::from(CONTOUR_SIZE.1) / 3.0,
        "row {row}: not at the top"
    );
}

#[test]
fn a_window_frames_the_pictures_and_one_off_the_body_is_refused() {
    let dir = folder("window");
    fs::write(dir.join("history.csv"), CANTILEVER).unwrap();
    write_frame(&dir, 7, "", false, "");
    // eps_q = 0.2 x: a window along the bottom left, wider than the picture's aspect, shows
    // x up to about 0.42 m of the 1.1, the lower half of the scale only.
    let left = Window::parse("0,0,0.4,0.2").unwrap();
    let written = plot_run_in(&dir, Some(left)).unwrap();
    let p = Picture::read(&written[2]);
    assert!(written[2].ends_with("eps_q.png"));
    let mesh_right = CONTOUR_SIZE.0 - COLOUR_BAR_WIDTH;
    assert!(p.near(colour_map(0.0), 30, mesh_right).len() > 50);
    assert_eq!(
        p.near(colour_map(1.0), 30, mesh_right).len(),
        0,
        "x = 1.1 is out of the window"
    );
    let e = plot_run_in(&dir, Some(Window::parse("5,5,6,6").unwrap()))
        .unwrap_err()
        .to_string();
    assert!(e.contains("--window 5,5,6,6 shows none of the body"), "{e}");
}
