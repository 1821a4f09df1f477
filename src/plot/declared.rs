//! The history picture of a scene's own columns (`[[history.columns]]`, or any header that is
//! not a legacy kind's): one panel per column, stacked, each with the reference lines the scene
//! declares for that column.

use std::path::Path;

use plotters::style::RGBColor;

use crate::scene::{ReferenceLine, Scene};

use super::history::{drawable, History};
use super::legacy::CURVE_SIZE;
use super::numbers::short;
use super::panel::{draw_panel, Curve, Look, Panel, REFERENCE_HIGH, REFERENCE_LOW, RESULT_U};
use super::picture::{save, Area, Drawn};
use super::PlotError;

/// Height in pixels of each panel of a picture with several; a single panel is [`CURVE_SIZE`],
/// like a legacy curve.
pub const PANEL_HEIGHT: u32 = 600;

/// Colours of a column's reference lines, in declaration order (repeating after the last).
const REFERENCE_COLOURS: [RGBColor; 4] = [
    REFERENCE_LOW,
    REFERENCE_HIGH,
    RGBColor(220, 120, 0),
    RGBColor(90, 90, 90),
];

/// Width and height in pixels of a declared-columns picture of `panels` panels.
pub fn declared_size(panels: usize) -> (u32, u32) {
    if panels <= 1 {
        CURVE_SIZE
    } else {
        // A history has a handful of columns: the height stays far below u32::MAX.
        (CURVE_SIZE.0, PANEL_HEIGHT * panels as u32)
    }
}

/// The index of the x column: the first after `step` when it moves strictly one way over the
/// run (a penetration, a load factor), so that each of its values stands for one step.
/// Otherwise `step` (index 0): a column that holds still or turns back — the pipeline's depth
/// while it is pulled sideways — would fold every other curve onto a vertical line or back over
/// itself. With a single column after `step`, x is `step` too, or nothing would be left to draw.
pub(crate) fn x_column(history: &History) -> usize {
    if history.names.len() > 2 && strictly_monotonic(&history.column(1)) {
        1
    } else {
        0
    }
}

/// Whether the drawable `values` strictly rise or strictly fall. Others are skipped: those steps
/// diverged and are left out of the curves as well.
fn strictly_monotonic(values: &[f64]) -> bool {
    let finite: Vec<f64> = values.iter().copied().filter(|&v| drawable(v)).collect();
    finite.windows(2).all(|w| w[1] > w[0]) || finite.windows(2).all(|w| w[1] < w[0])
}

/// The indices of the y columns, one panel each: every column after `step` but `x`.
pub(crate) fn y_columns(history: &History, x: usize) -> Vec<usize> {
    (1..history.names.len()).filter(|&i| i != x).collect()
}

/// The reference lines `scene` declares for its column `name`: none without a scene, or for a
/// column it does not declare (a legacy kind's).
pub(crate) fn references<'a>(scene: Option<&'a Scene>, name: &str) -> &'a [ReferenceLine] {
    scene
        .and_then(|s| s.history.columns.iter().find(|c| c.name == name))
        .map_or(&[], |c| c.reference.as_slice())
}

/// Legend text of a reference line: its label, with the value unless the label spells it out.
fn reference_label(line: &ReferenceLine) -> String {
    let value = short(line.value);
    if line.label.contains(&value) {
        line.label.clone()
    } else {
        format!("{}: {value}", line.label)
    }
}

/// Whether the y axis reaches zero: loads and displacements grow from rest and read best against
/// zero, but a quantity far from zero (an area, a ratio near 1) would be squashed flat.
fn reaches_zero(values: impl Iterator<Item = f64>) -> bool {
    let (lo, hi) = values
        .filter(|&v| drawable(v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi || (lo <= 0.0 && hi >= 0.0) {
        return true;
    }
    lo.abs().min(hi.abs()) <= hi - lo
}

/// The panel of column `y` against column `x`.
fn panel(history: &History, scene: Option<&Scene>, x: usize, y: usize) -> Panel {
    let (x_name, y_name) = (&history.names[x], &history.names[y]);
    let mut curves = vec![Curve::new(
        &format!("{y_name}, this run"),
        history.curve_at(x, y),
        RESULT_U,
        Look::Result,
    )];
    for (line, colour) in references(scene, y_name)
        .iter()
        .zip(REFERENCE_COLOURS.iter().cycle())
    {
        curves.push(Curve::new(
            &reference_label(line),
            Vec::new(),
            *colour,
            Look::Level(line.value),
        ));
    }
    let ys = curves.iter().flat_map(|c| match c.look {
        Look::Level(v) => vec![v],
        _ => c.points.iter().map(|p| p.1).collect(),
    });
    let y_from_zero = reaches_zero(ys);
    Panel {
        caption: caption(scene, &format!("{y_name} against {x_name}")),
        x_desc: x_name.clone(),
        y_desc: y_name.clone(),
        curves,
        y_from_zero,
    }
}

/// `what`, after the scene's name when there is a scene.
fn caption(scene: Option<&Scene>, what: &str) -> String {
    match scene {
        Some(s) => format!("{}: {what}", s.name),
        None => what.to_string(),
    }
}

/// The panels of the picture, top to bottom.
pub(crate) fn panels(history: &History, scene: Option<&Scene>) -> Vec<Panel> {
    let x = x_column(history);
    let ys = y_columns(history, x);
    if ys.is_empty() {
        // A scene that records nothing but the step still gets a picture that says so.
        return vec![Panel {
            caption: caption(scene, "history.csv has no columns besides step"),
            x_desc: "step".to_string(),
            y_desc: String::new(),
            curves: Vec::new(),
            y_from_zero: true,
        }];
    }
    ys.into_iter()
        .map(|y| panel(history, scene, x, y))
        .collect()
}

/// Writes the declared-columns picture of `history` to `path`, with the reference lines of
/// `scene` (none without one).
pub(crate) fn draw(history: &History, scene: Option<&Scene>, path: &Path) -> Result<(), PlotError> {
    let panels = panels(history, scene);
    save(
        path,
        declared_size(panels.len()),
        |root: &Area<'_>| -> Drawn<'_> {
            for (area, panel) in root.split_evenly((panels.len(), 1)).iter().zip(&panels) {
                draw_panel(area, panel)?;
            }
            Ok(())
        },
    )
}

#[cfg(test)]
mod tests;
