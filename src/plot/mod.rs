//! PNG pictures of a run's output folder `DIR` (`pfem-mpi plot DIR`), written to `DIR/plots/`:
//!
//! - `history.png`, from `DIR/history.csv` and the run's scene `DIR/scene.toml` (when the run
//!   wrote one). A legacy history kind gets its fixed picture, with the reference solutions of
//!   `docs/reference.md`, when the header is that kind's and the scene asked for the kind (or
//!   there is no `scene.toml`: runs from before it was written):
//!   - cantilever: u/L and v/L against λ = P L²/(E I), with the Bisshopp–Drucker elastica
//!     (dashed) and the plane-strain Reissner beam at λ = 2, 5, 10 (crosses);
//!   - footing: q/cu against z/B, with Prandtl's 2 + π and the deep smooth-strip limit 2 + 2π;
//!   - block: stress/cu against strain with the Tresca strength 2, above the volume ratio
//!     against strain with the isochoric 1.
//!
//!   The picture is [`CURVE_SIZE`], or [`BLOCK_SIZE`] for a block. Any other history (a scene's
//!   `[[history.columns]]`) is drawn column by column: x is the first column after `step` when it
//!   strictly rises or falls over the run, otherwise `step` (a pipeline's depth holds while it
//!   moves sideways); one panel per other column, stacked, with the reference lines the scene
//!   declares for that column (dashed, labelled in the legend; none without `scene.toml`),
//!   axes named by the columns. The picture is [`declared_size`] for its number of panels.
//! - `FIELD.png` for `FIELD` = `eps_q`, `sigma_yy`, `tau_xy` (and `incremental_displacement`,
//!   as its length, when the frame has it), when `DIR/fields.xdmf` lists a frame and the field
//!   is not zero everywhere (an elastic run has no `eps_q.png`): the field on the deformed mesh
//!   of the last frame, interpolated linearly in each triangle, with the rigid bodies of
//!   `scene.toml` where their stages put them at the frame's step, axes in metres at equal
//!   scale over the region where the field varies ([`window::focus`]) or the window asked for,
//!   a colour bar ([`colour_map()`], viridis; [`diverging_colour_map()`] about zero for a field
//!   of both signs) with the minimum and maximum written out, titled with the field and the
//!   step. The picture is [`CONTOUR_SIZE`], the colour bar its rightmost [`COLOUR_BAR_WIDTH`]
//!   pixels.
//!
//! Text is drawn with a font compiled into the binary, so plotting needs no system fonts.

mod colour_map;
mod contour;
mod declared;
mod error;
mod font;
mod frame;
mod history;
mod history_picture;
mod legacy;
mod numbers;
mod panel;
mod picture;
mod reference;
mod rigid_outline;
mod scene_file;
pub mod window;

use std::path::{Path, PathBuf};

pub use colour_map::{colour_map, diverging_colour_map};
pub use contour::{COLOUR_BAR_WIDTH, CONTOUR_SIZE};
pub use declared::{declared_size, PANEL_HEIGHT};
pub use error::PlotError;
pub use legacy::{BLOCK_SIZE, CURVE_SIZE};
pub use window::Window;

/// Writes `DIR/plots/*.png`: the history's curve(s) with reference lines (a legacy kind's, or
/// the scene's declared columns' from `DIR/scene.toml`), and contour pictures of eps_q,
/// sigma_yy, tau_xy on the deformed mesh of the last frame (if `DIR/fields.xdmf` exists and
/// lists a frame), each framed on where it varies; see the module documentation. Returns the
/// files written, history first.
pub fn plot_run(dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    plot_run_in(dir, None)
}

/// [`plot_run`], the contour pictures showing `window` when given (`pfem-mpi plot DIR --window
/// x0,y0,x1,y1`); a window that shows none of the body is an error naming `--window`.
///
/// All inputs are read before any picture is written. Errors name the file at fault: a missing
/// or malformed `history.csv`, a damaged `fields.xdmf`, a frame file that cannot be read or
/// lacks a field, or a picture that cannot be written. A `scene.toml` that cannot be read or
/// parsed is no error: a warning on stderr, and the history is drawn as without one. Values
/// that are not finite or beyond `history::DRAWABLE` are left out of the curves, the latter
/// with a warning on stderr.
pub fn plot_run_in(dir: &Path, window: Option<Window>) -> Result<Vec<PathBuf>, PlotError> {
    font::register()?;
    let history_file = dir.join("history.csv");
    let history = history::read(&history_file)?;
    if let Some((count, first)) = history.undrawable() {
        eprintln!(
            "pfem-mpi: warning: {}: {count} value(s) beyond ±{:e} left out of history.png \
             (first: {first})",
            history_file.display(),
            history::DRAWABLE
        );
    }
    let scene = scene_file::read(dir);
    let frame = frame::last_frame(dir)?;
    let mut fields = Vec::new();
    if let Some(frame) = &frame {
        for spec in contour::CONTOURS {
            match frame.field(spec.field)? {
                Some(values) => fields.push((spec, values)),
                None if spec.required => {
                    return Err(PlotError::new(
                        &frame.path,
                        format!("no dataset /point_data/{}", spec.field),
                    ))
                }
                None => {}
            }
        }
    }

    let bodies = match (&scene, &frame) {
        (Some(scene), Some(frame)) => rigid_outline::outlines(scene, frame.step),
        _ => Vec::new(),
    };
    if let (Some(w), Some(frame)) = (window, &frame) {
        check_window(&w, frame)?;
    }

    let out = dir.join("plots");
    std::fs::create_dir_all(&out)
        .map_err(|e| PlotError::new(&out, format!("cannot create folder: {e}")))?;
    let mut written = Vec::new();
    let path = out.join("history.png");
    history_picture::draw(&history, scene.as_ref(), &path)?;
    written.push(path);
    if let Some(frame) = &frame {
        let when = match frame.time {
            Some(t) => format!("step {}, t = {}", frame.step, numbers::short(t)),
            None => format!("step {}", frame.step),
        };
        let boxes: Vec<Window> = bodies
            .iter()
            .filter_map(|b| Window::around(b.iter().copied()))
            .collect();
        for (spec, values) in &fields {
            let path = out.join(format!("{}.png", spec.field));
            // A field that is zero everywhere (the plastic strain of an elastic run) says
            // nothing a picture would show; an older picture of it is not this run's.
            if values.iter().all(|&v| v == 0.0) {
                let _ = std::fs::remove_file(&path);
                continue;
            }
            let focus = || window::focus(&frame.position, &frame.triangles, values, &boxes);
            let Some(window) = window.or_else(focus) else {
                continue;
            };
            let view = contour::View {
                window,
                bodies: &bodies,
            };
            contour::draw(
                frame,
                values,
                &view,
                &format!("{} — {when}", spec.label),
                &path,
            )?;
            written.push(path);
        }
    }
    Ok(written)
}

/// A `--window` must show some of the body.
fn check_window(w: &Window, frame: &frame::Frame) -> Result<(), PlotError> {
    let used = frame.triangles.iter().flatten().map(|&i| frame.position[i]);
    let Some(body) = Window::around(used) else {
        return Ok(());
    };
    if body.intersect(*w).is_some() {
        return Ok(());
    }
    Err(PlotError::new(
        &frame.path,
        format!(
            "--window {},{},{},{} shows none of the body, which spans x {} .. {}, y {} .. {}",
            w.x0,
            w.y0,
            w.x1,
            w.y1,
            numbers::short(body.x0),
            numbers::short(body.x1),
            numbers::short(body.y0),
            numbers::short(body.y1)
        ),
    ))
}
