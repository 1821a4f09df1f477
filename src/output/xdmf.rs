//! The XDMF series file: a temporal collection with one uniform grid per frame, each pointing
//! into its frame's HDF5 file. Also reads back the frames of a series this module wrote, so a
//! restarted run can continue it.

use std::fmt::Write;

use super::field::{FieldDesc, Kind, GID};
use super::frame_file::POINT_DATA;

/// Name of the series file in the output folder.
pub(crate) const SERIES: &str = "fields.xdmf";
/// Folder, inside the output folder, of the frame files.
pub(crate) const DATA_DIR: &str = "fields";

/// File name of the frame file of `step`.
pub(crate) fn data_file_name(step: u64) -> String {
    format!("step_{step:06}.h5")
}

/// A frame listed in the series: its step and its `<Grid>` element, as text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct FrameEntry {
    pub step: u64,
    pub xml: String,
}

/// What the series needs to know about a frame to describe its file.
pub(crate) struct FrameInfo<'a> {
    pub step: u64,
    /// Finite; shown by ParaView as the frame's time.
    pub time: f64,
    pub points: usize,
    pub triangles: usize,
    pub fields: &'a [FieldDesc],
}

/// Opening of the grid element of every frame; [`parse_series`] finds frames by it.
const GRID_OPEN: &str = "<Grid Name=\"step_";
const GRID_CLOSE: &str = "</Grid>";

/// One `<DataItem>` line referring to dataset `dataset` of the frame file `file`.
fn data_item(out: &mut String, dims: &str, number: &str, file: &str, dataset: &str) {
    // Writing to a String cannot fail.
    let _ = writeln!(
        out,
        "          <DataItem Dimensions=\"{dims}\" NumberType=\"{number}\" Precision=\"8\" \
         Format=\"HDF\">{DATA_DIR}/{file}:/{dataset}</DataItem>"
    );
}

fn attribute(out: &mut String, name: &str, kind: Kind, points: usize, number: &str, file: &str) {
    let _ = writeln!(
        out,
        "        <Attribute Name=\"{name}\" AttributeType=\"{}\" Center=\"Node\">",
        kind.attribute_type()
    );
    let dims = match kind {
        Kind::Scalar => points.to_string(),
        k => format!("{points} {}", k.components()),
    };
    let dataset = if name == GID {
        GID.to_string()
    } else {
        format!("{POINT_DATA}/{name}")
    };
    data_item(out, &dims, number, file, &dataset);
    out.push_str("        </Attribute>\n");
}

/// The `<Grid>` element of a frame. Field names need no escaping: they are restricted to
/// letters, digits, `_` and `-`.
pub(crate) fn frame_entry(f: &FrameInfo<'_>) -> FrameEntry {
    let file = data_file_name(f.step);
    let (n, m) = (f.points, f.triangles);
    let mut x = String::new();
    let _ = writeln!(x, "{GRID_OPEN}{:06}\" GridType=\"Uniform\">", f.step);
    // Debug formatting of f64 is the shortest text that reads back to the same value.
    let _ = writeln!(x, "        <Time Value=\"{:?}\"/>", f.time);
    let _ = writeln!(
        x,
        "        <Topology TopologyType=\"Triangle\" NumberOfElements=\"{m}\">"
    );
    data_item(&mut x, &format!("{m} 3"), "Int", &file, "connectivity");
    x.push_str("        </Topology>\n");
    x.push_str("        <Geometry GeometryType=\"XY\">\n");
    data_item(&mut x, &format!("{n} 2"), "Float", &file, "geometry");
    x.push_str("        </Geometry>\n");
    for d in f.fields {
        attribute(&mut x, &d.name, d.kind, n, "Float", &file);
    }
    // Last, so that readers make the caller's first scalar field, not the ids, the active one.
    attribute(&mut x, GID, Kind::Scalar, n, "Int", &file);
    x.push_str("      ");
    x.push_str(GRID_CLOSE);
    FrameEntry {
        step: f.step,
        xml: x,
    }
}

/// The whole series file listing `frames` in order.
pub(crate) fn series(frames: &[FrameEntry]) -> String {
    let mut x = String::from(
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n\
         <Xdmf Version=\"3.0\">\n  <Domain>\n    \
         <Grid Name=\"fields\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
    );
    for f in frames {
        x.push_str("      ");
        x.push_str(&f.xml);
        x.push('\n');
    }
    x.push_str("    </Grid>\n  </Domain>\n</Xdmf>\n");
    x
}

/// The frames of a series written by [`series`], in file order, each element kept verbatim.
pub(crate) fn parse_series(text: &str) -> Result<Vec<FrameEntry>, String> {
    if !text.contains("<Xdmf") || !text.contains("CollectionType=\"Temporal\"") {
        return Err("not an XDMF temporal collection".to_string());
    }
    let mut frames: Vec<FrameEntry> = Vec::new();
    let mut rest = text;
    while let Some(start) = rest.find(GRID_OPEN) {
        let block = &rest[start..];
        let end = block
            .find(GRID_CLOSE)
            .map(|e| e + GRID_CLOSE.len())
            .ok_or_else(|| format!("unterminated frame at byte {}", text.len() - block.len()))?;
        let xml = &block[..end];
        let digits: String = block[GRID_OPEN.len()..]
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        let step: u64 = digits.parse().map_err(|_| {
            format!(
                "frame without a step number at byte {}",
                text.len() - block.len()
            )
        })?;
        if xml[1..].contains("<Grid") {
            return Err(format!("frame of step {step} is not a single uniform grid"));
        }
        if let Some(prev) = frames.last().filter(|p| p.step >= step) {
            return Err(format!(
                "frame of step {step} follows the frame of step {}",
                prev.step
            ));
        }
        frames.push(FrameEntry {
            step,
            xml: xml.to_string(),
        });
        rest = &block[end..];
    }
    Ok(frames)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(step: u64, time: f64) -> FrameEntry {
        let fields = [
            FieldDesc {
                name: "p".into(),
                kind: Kind::Scalar,
            },
            FieldDesc {
                name: "u".into(),
                kind: Kind::Vector,
            },
            FieldDesc {
                name: "s".into(),
                kind: Kind::Tensor,
            },
        ];
        frame_entry(&FrameInfo {
            step,
            time,
            points: 9,
            triangles: 8,
            fields: &fields,
        })
    }

    #[test]
    fn frame_describes_every_dataset() {
        let e = entry(12, 0.25);
        let x = &e.xml;
        assert!(
            x.starts_with("<Grid Name=\"step_000012\" GridType=\"Uniform\">"),
            "{x}"
        );
        assert!(x.ends_with("</Grid>"));
        assert!(x.contains("<Time Value=\"0.25\"/>"));
        assert!(x.contains("NumberOfElements=\"8\""));
        assert!(x.contains(
            "Dimensions=\"8 3\" NumberType=\"Int\" Precision=\"8\" \
             Format=\"HDF\">fields/step_000012.h5:/connectivity<"
        ));
        assert!(x.contains("Dimensions=\"9 2\" NumberType=\"Float\""));
        assert!(x.contains(">fields/step_000012.h5:/gid<"));
        assert!(x.contains("Dimensions=\"9\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">fields/step_000012.h5:/point_data/p<"));
        assert!(x.contains("AttributeType=\"Vector\""));
        assert!(x.contains("Dimensions=\"9 3\""));
        assert!(x.contains("AttributeType=\"Tensor\""));
        assert!(x.contains("Dimensions=\"9 9\""));
    }

    #[test]
    fn times_read_back_exactly() {
        for t in [0.1 + 0.2, 1e-7, 3.0, 1e300] {
            let e = entry(1, t);
            let text = e.xml.split("Time Value=\"").nth(1).unwrap();
            let value: f64 = text.split('"').next().unwrap().parse().unwrap();
            assert_eq!(value, t);
        }
    }

    #[test]
    fn series_round_trips() {
        let frames = vec![entry(1, 0.1), entry(2, 0.2), entry(10, 1.0)];
        let text = series(&frames);
        assert!(text.starts_with("<?xml"));
        assert_eq!(parse_series(&text).unwrap(), frames);
        assert_eq!(parse_series(&series(&[])).unwrap(), vec![]);
    }

    #[test]
    fn damaged_series_are_rejected() {
        assert!(parse_series("hello").is_err());
        let text = series(&[entry(1, 0.1), entry(2, 0.2)]);
        let cut = &text[..text.rfind("</Grid>\n    </Grid>").unwrap()];
        assert!(parse_series(cut).unwrap_err().contains("unterminated"));
        let swapped = series(&[entry(2, 0.1), entry(1, 0.2)]);
        assert!(parse_series(&swapped).unwrap_err().contains("follows"));
    }
}
