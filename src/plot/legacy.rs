//! The load–displacement pictures of the three legacy history kinds (`history.kind` =
//! cantilever, footing, block), with the reference solutions of `docs/reference.md` drawn
//! alongside the run's results. Their columns are fixed, so the references are too.

use std::path::Path;

use plotters::style::BLACK;

use crate::scene::HistoryKind;

use super::history::History;
use super::panel::{
    draw_panel, Curve, Look, Panel, REFERENCE_HIGH, REFERENCE_LOW, RESULT_U, RESULT_V,
};
use super::picture::{save, Area, Drawn};
use super::reference::{DEEP_STRIP, ELASTICA, ISOCHORIC, PRANDTL, REISSNER, TRESCA_COMPRESSION};
use super::PlotError;

/// Width and height in pixels of the load–displacement picture of a cantilever or a footing.
pub const CURVE_SIZE: (u32, u32) = (1000, 700);
/// Width and height in pixels of a block's picture: stress above, volume ratio below.
pub const BLOCK_SIZE: (u32, u32) = (1000, 1200);

fn cantilever(history: &History) -> Panel {
    let reference = |k: usize| ELASTICA.iter().map(|r| (r[0], r[k])).collect::<Vec<_>>();
    let reissner = |k: usize| REISSNER.iter().map(|r| (r[0], r[k])).collect::<Vec<_>>();
    let mut reissner_v = Curve::new("", reissner(2), BLACK, Look::Points);
    reissner_v.label = None;
    Panel {
        caption: "Cantilever: tip displacement against load".to_string(),
        x_desc: "λ = P L² / (E I)".to_string(),
        y_desc: "u/L (shortening), v/L (deflection)".to_string(),
        curves: vec![
            Curve::new(
                "u/L, this run",
                history.curve("lambda", "u_over_L"),
                RESULT_U,
                Look::Result,
            ),
            Curve::new(
                "v/L, this run",
                history.curve("lambda", "v_over_L"),
                RESULT_V,
                Look::Result,
            ),
            Curve::new(
                "u/L, elastica (Bisshopp–Drucker)",
                reference(1),
                RESULT_U,
                Look::Reference,
            ),
            Curve::new(
                "v/L, elastica (Bisshopp–Drucker)",
                reference(2),
                RESULT_V,
                Look::Reference,
            ),
            Curve::new(
                "plane-strain Reissner beam",
                reissner(1),
                BLACK,
                Look::Points,
            ),
            reissner_v,
        ],
        y_from_zero: true,
    }
}

fn footing(history: &History) -> Panel {
    Panel {
        caption: "Strip footing: bearing pressure against penetration".to_string(),
        x_desc: "z/B".to_string(),
        y_desc: "q/cu".to_string(),
        curves: vec![
            Curve::new(
                "q/cu, this run",
                history.curve("z_over_B", "q_over_cu"),
                RESULT_U,
                Look::Result,
            ),
            Curve::new(
                "Prandtl, 2 + π = 5.142",
                Vec::new(),
                REFERENCE_LOW,
                Look::Level(PRANDTL),
            ),
            Curve::new(
                "deep smooth strip, 2 + 2π = 8.28",
                Vec::new(),
                REFERENCE_HIGH,
                Look::Level(DEEP_STRIP),
            ),
        ],
        y_from_zero: true,
    }
}

fn block_stress(history: &History) -> Panel {
    Panel {
        caption: "Block: stress against strain".to_string(),
        x_desc: "strain".to_string(),
        y_desc: "stress/cu".to_string(),
        curves: vec![
            Curve::new(
                "stress/cu, this run",
                history.curve("strain", "stress_over_cu"),
                RESULT_U,
                Look::Result,
            ),
            Curve::new(
                "Tresca strength, 2 cu",
                Vec::new(),
                REFERENCE_LOW,
                Look::Level(TRESCA_COMPRESSION),
            ),
        ],
        y_from_zero: true,
    }
}

fn block_volume(history: &History) -> Panel {
    Panel {
        caption: "Block: volume against strain".to_string(),
        x_desc: "strain".to_string(),
        y_desc: "V / V₀".to_string(),
        curves: vec![
            Curve::new(
                "volume ratio, this run",
                history.curve("strain", "volume_ratio"),
                RESULT_U,
                Look::Result,
            ),
            Curve::new(
                "isochoric, 1",
                Vec::new(),
                REFERENCE_LOW,
                Look::Level(ISOCHORIC),
            ),
        ],
        y_from_zero: false,
    }
}

/// Writes the load–displacement picture of `history`, a history of the legacy `kind`, to `path`.
pub(crate) fn draw(history: &History, kind: HistoryKind, path: &Path) -> Result<(), PlotError> {
    match kind {
        HistoryKind::Cantilever => {
            let panel = cantilever(history);
            save(path, CURVE_SIZE, |root: &Area<'_>| draw_panel(root, &panel))
        }
        HistoryKind::Footing => {
            let panel = footing(history);
            save(path, CURVE_SIZE, |root: &Area<'_>| draw_panel(root, &panel))
        }
        HistoryKind::Block => {
            let panels = [block_stress(history), block_volume(history)];
            save(path, BLOCK_SIZE, |root: &Area<'_>| -> Drawn<'_> {
                let (top, bottom) = root.split_vertically(BLOCK_SIZE.1 / 2);
                draw_panel(&top, &panels[0])?;
                draw_panel(&bottom, &panels[1])
            })
        }
    }
}
