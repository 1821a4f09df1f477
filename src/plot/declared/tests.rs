//! Tests of the declared-columns picture: the x column, the reference lines read back from a
//! run's `scene.toml` text, and the PNG itself.

use std::fs;
use std::path::{Path, PathBuf};

use super::*;
use crate::plot::font;
use crate::plot::history::parse;
use crate::plot::scene_file;
use crate::scene::load_scene;

/// A built-in scene as a run folder holds it: written with `to_toml` and read back.
fn scene_from_toml(name: &str) -> Scene {
    let text = load_scene(name, &[]).unwrap().0.to_toml();
    scene_file::parse(&text, Path::new("out/scene.toml")).unwrap()
}

/// A fresh, empty folder for one test.
fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pfem-plot-{name}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// Width, height and RGB pixels of a PNG.
fn decode(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
    let file = fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reader = png::Decoder::new(file).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = match info.color_type {
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        other => panic!("{}: colour type {other:?}", path.display()),
    };
    let rgb = buf[..info.buffer_size()]
        .chunks_exact(channels)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    (info.width, info.height, rgb)
}

fn count(pixels: &[[u8; 3]], colour: RGBColor) -> usize {
    pixels
        .iter()
        .filter(|p| **p == [colour.0, colour.1, colour.2])
        .count()
}

/// A T-bar history: w/D rising 0.01 per step, Nc rising to about 9.
fn tbar_history(steps: u32) -> History {
    let rows: String = (1..=steps)
        .map(|k| {
            let w = 0.01 * f64::from(k);
            format!("{k},{w},{}\n", 9.0 * (1.0 - (-20.0 * w).exp()))
        })
        .collect();
    parse(&format!("step,w_over_D,Nc\n{rows}")).unwrap()
}

/// The pipeline's two stages: down 0.5 D in 50 steps, then sideways 2 D at that depth.
fn pipeline_history() -> History {
    let rows: String = (1..=250)
        .map(|k| {
            let (uy, ux) = if k <= 50 {
                (0.01 * f64::from(k), 0.0)
            } else {
                (0.5, 0.01 * f64::from(k - 50))
            };
            format!("{k},{uy},{ux},{},{}\n", 10.0 * uy, 3.0 * ux.min(0.3))
        })
        .collect();
    parse(&format!(
        "step,uy_over_D,ux_over_D,V_over_Dcu,H_over_Dcu\n{rows}"
    ))
    .unwrap()
}

#[test]
fn x_is_the_first_column_when_it_moves_one_way() {
    let tbar = tbar_history(5);
    assert_eq!(x_column(&tbar), 1);
    assert_eq!(y_columns(&tbar, 1), [2]);
    // Falling strictly is one way too; a diverged step (NaN) is skipped.
    let h = parse("step,depth,F\n1,-0.1,1\n2,NaN,2\n3,-0.3,3\n").unwrap();
    assert_eq!(x_column(&h), 1);
    // With one column, there is nothing to draw against it: x is the step.
    let h = parse("step,Nc\n1,1\n2,2\n").unwrap();
    assert_eq!(x_column(&h), 0);
    assert_eq!(y_columns(&h, 0), [1]);
}

#[test]
fn x_is_the_step_when_the_first_column_holds_or_turns() {
    // The pipeline's depth holds still while it moves sideways.
    let pipeline = pipeline_history();
    assert_eq!(x_column(&pipeline), 0);
    assert_eq!(y_columns(&pipeline, 0), [1, 2, 3, 4]);
    let turning = parse("step,w,F\n1,0.1,1\n2,0.2,2\n3,0.15,3\n").unwrap();
    assert_eq!(x_column(&turning), 0);
    assert!(!strictly_monotonic(&[0.0, 0.1, 0.1]));
    assert!(strictly_monotonic(&[0.3, 0.2, f64::INFINITY, 0.1]));
}

#[test]
fn reference_lines_come_from_the_scene_toml() {
    let scene = scene_from_toml("tbar-smooth");
    let lines = references(Some(&scene), "Nc");
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0].value, 9.142);
    assert_eq!(lines[0].label, "exact, smooth");
    assert!(references(Some(&scene), "w_over_D").is_empty());
    assert!(references(None, "Nc").is_empty());

    let drawn = panels(&tbar_history(10), Some(&scene));
    assert_eq!(drawn.len(), 1);
    let p = &drawn[0];
    assert_eq!((p.x_desc.as_str(), p.y_desc.as_str()), ("w_over_D", "Nc"));
    assert_eq!(p.caption, "tbar-smooth: Nc against w_over_D");
    assert_eq!(p.curves.len(), 2);
    assert_eq!(p.curves[0].points.len(), 10);
    assert!(matches!(p.curves[1].look, Look::Level(v) if v == 9.142));
    assert_eq!(p.curves[1].label.as_deref(), Some("exact, smooth: 9.142"));
    assert!(p.y_from_zero);

    // Without a scene: the result only.
    let bare = panels(&tbar_history(10), None);
    assert_eq!(bare[0].curves.len(), 1);
    assert_eq!(bare[0].caption, "Nc against w_over_D");
}

#[test]
fn labels_and_axes_fit_the_values() {
    let line = |value, label: &str| ReferenceLine {
        value,
        label: label.to_string(),
    };
    assert_eq!(reference_label(&line(5.142, "2 + pi")), "2 + pi: 5.142");
    assert_eq!(reference_label(&line(1.0, "isochoric, 1")), "isochoric, 1");
    assert!(reaches_zero([0.5, 9.0].into_iter()));
    assert!(reaches_zero([-1.0, 2.0].into_iter()));
    assert!(reaches_zero(std::iter::empty()));
    assert!(!reaches_zero([0.98, 1.0].into_iter()));
    assert!(!reaches_zero([-1.02, -1.0].into_iter()));
}

#[test]
fn pictures_have_a_panel_per_column_and_draw_the_references() {
    font::register().unwrap();
    let dir = folder("declared");
    let scene = scene_from_toml("tbar-smooth");

    let with = dir.join("tbar.png");
    draw(&tbar_history(40), Some(&scene), &with).unwrap();
    let (w, h, pixels) = decode(&with);
    assert_eq!((w, h), CURVE_SIZE);
    // The reference line is drawn in the first reference colour, the result in its own.
    let reference = count(&pixels, REFERENCE_LOW);
    assert!(reference > 200, "{reference} reference pixels");
    assert!(count(&pixels, RESULT_U) > 200);

    let without = dir.join("bare.png");
    draw(&tbar_history(40), None, &without).unwrap();
    let (_, _, pixels) = decode(&without);
    assert_eq!(count(&pixels, REFERENCE_LOW), 0);

    // The pipeline: four panels against the step, stacked.
    let pipeline = scene_from_toml("pipeline");
    let path = dir.join("pipeline.png");
    draw(&pipeline_history(), Some(&pipeline), &path).unwrap();
    let (w, h, pixels) = decode(&path);
    assert_eq!((w, h), declared_size(4));
    assert_eq!((w, h), (CURVE_SIZE.0, 4 * PANEL_HEIGHT));
    // V_over_Dcu's reference is in the third panel from the top, the only one with any.
    let rows = |k: u32| {
        let band = &pixels[(k * PANEL_HEIGHT * w) as usize..((k + 1) * PANEL_HEIGHT * w) as usize];
        count(band, REFERENCE_LOW)
    };
    assert_eq!([rows(0), rows(1), rows(3)], [0, 0, 0]);
    assert!(rows(2) > 200, "{} reference pixels", rows(2));

    // A header of `step` alone still draws a picture.
    let path = dir.join("empty.png");
    draw(&parse("step\n1\n").unwrap(), None, &path).unwrap();
    assert_eq!(decode(&path).0, CURVE_SIZE.0);
    fs::remove_dir_all(&dir).unwrap();
}
