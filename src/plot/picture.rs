//! One PNG picture: a white canvas handed to a drawing function, then encoded to its file.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::error::drawing;
use super::PlotError;

/// The whole canvas of a picture.
pub(crate) type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// What a drawing function returns: plotters' own error, turned into a [`PlotError`] naming the
/// picture by [`save`].
pub(crate) type Drawn<'a> =
    Result<(), DrawingAreaErrorKind<<BitMapBackend<'a> as DrawingBackend>::ErrorType>>;

/// Draws a `size` (width, height) picture with `draw` and writes it to `path` as PNG.
pub(crate) fn save<F>(path: &Path, size: (u32, u32), draw: F) -> Result<(), PlotError>
where
    F: for<'b> FnOnce(&Area<'b>) -> Drawn<'b>,
{
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(drawing(path))?;
    draw(&root).map_err(drawing(path))?;
    root.present()
        .map_err(|e| PlotError::new(path, format!("cannot write: {e}")))
}
