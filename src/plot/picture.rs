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

/// Draws a `size` (width, height) picture with `draw` and writes it to `path` as PNG. The
/// picture is drawn and encoded in memory, then written through `path.tmp` and a rename, so a
/// full disk never leaves a truncated picture under `path`.
pub(crate) fn save<F>(path: &Path, size: (u32, u32), draw: F) -> Result<(), PlotError>
where
    F: for<'b> FnOnce(&Area<'b>) -> Drawn<'b>,
{
    let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        root.fill(&WHITE).map_err(drawing(path))?;
        draw(&root).map_err(drawing(path))?;
        root.present().map_err(drawing(path))?;
    }
    let png =
        encode(&rgb, size).map_err(|e| PlotError::new(path, format!("cannot encode: {e}")))?;
    crate::output::replace_file(path, &png).map_err(|m| PlotError::new(path, m))
}

fn encode(rgb: &[u8], size: (u32, u32)) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, size.0, size.1);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(out)
}
