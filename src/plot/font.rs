//! The plots' one text face, compiled into the binary (see `assets/fonts/README.md`), so that
//! drawing text needs neither system fonts nor fontconfig and FreeType, and pictures look the
//! same on every machine.

use std::path::Path;
use std::sync::OnceLock;

use plotters::style::{register_font, FontStyle};

use super::PlotError;

/// Where the face comes from, for error messages.
const SOURCE: &str = "assets/fonts/DejaVuSans-subset.ttf";
const DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans-subset.ttf");

/// Family under which the face is registered; plotters' own defaults (legend, tick labels) ask
/// for this family too.
pub(crate) const FAMILY: &str = "sans-serif";

/// Registers the face with plotters, once per process.
pub(crate) fn register() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok =
        *REGISTERED.get_or_init(|| register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS).is_ok());
    if ok {
        Ok(())
    } else {
        Err(PlotError::new(
            Path::new(SOURCE),
            "the compiled-in font is not a TrueType font",
        ))
    }
}
