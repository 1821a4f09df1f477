//! Reading the last frame of `DIR/fields.xdmf` (layout in `crate::output`): the series file
//! names the frame's HDF5 file, which holds positions, triangles and per-particle fields.

use std::path::{Path, PathBuf};

use super::PlotError;

/// Opening of every frame's grid element in the series file.
const GRID_OPEN: &str = "<Grid Name=\"step_";
const GRID_CLOSE: &str = "</Grid>";

/// The last frame a series lists.
#[derive(Debug, Clone, PartialEq)]
struct Listed {
    step: u64,
    /// The frame's load factor; `None` when the frame gives none.
    time: Option<f64>,
    /// The frame's HDF5 file, relative to the output folder.
    data_file: String,
}

/// The mesh of one frame, with its file open for reading fields.
pub(crate) struct Frame {
    pub step: u64,
    pub time: Option<f64>,
    /// The frame file, for error messages.
    pub path: PathBuf,
    /// Current particle positions.
    pub position: Vec<[f64; 2]>,
    /// Triangles as rows of `position`.
    pub triangles: Vec<[usize; 3]>,
    file: hdf5::File,
}

/// The last frame of the series `DIR/fields.xdmf`; `None` when there is no series file or it
/// lists no frame yet.
pub(crate) fn last_frame(dir: &Path) -> Result<Option<Frame>, PlotError> {
    let series = dir.join("fields.xdmf");
    let text = match std::fs::read_to_string(&series) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(PlotError::new(&series, format!("cannot read: {e}"))),
    };
    let Some(listed) = last_listed(&text).map_err(|m| PlotError::new(&series, m))? else {
        return Ok(None);
    };
    let path = dir.join(&listed.data_file);
    let file = hdf5::File::open(&path)
        .map_err(|e| PlotError::new(&path, format!("cannot open (listed in fields.xdmf): {e}")))?;
    let mesh = read_mesh(&file).map_err(|m| PlotError::new(&path, m))?;
    Ok(Some(Frame {
        step: listed.step,
        time: listed.time,
        path,
        position: mesh.0,
        triangles: mesh.1,
        file,
    }))
}

/// The text of the first `<DataItem ...>TEXT</DataItem>` in `xml`.
fn data_item(xml: &str) -> Option<&str> {
    let start = xml.find("<DataItem")?;
    let open_end = start + xml[start..].find('>')? + 1;
    let close = open_end + xml[open_end..].find("</DataItem>")?;
    Some(xml[open_end..close].trim())
}

fn last_listed(text: &str) -> Result<Option<Listed>, String> {
    if !text.contains("<Xdmf") {
        return Err("not an XDMF file".to_string());
    }
    let Some(start) = text.rfind(GRID_OPEN) else {
        return Ok(None);
    };
    let block = &text[start..];
    let end = block
        .find(GRID_CLOSE)
        .ok_or("the last frame is not terminated by </Grid>")?;
    let block = &block[..end];
    let digits: String = block[GRID_OPEN.len()..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    let step: u64 = digits
        .parse()
        .map_err(|_| "the last frame has no step number in its name".to_string())?;
    let time = block
        .find("<Time Value=\"")
        .map(|i| &block[i + "<Time Value=\"".len()..])
        .and_then(|rest| rest.split('"').next())
        .and_then(|v| v.trim().parse::<f64>().ok());
    let geometry = block
        .find("<Geometry")
        .and_then(|i| data_item(&block[i..]))
        .ok_or_else(|| format!("frame of step {step} has no geometry data item"))?;
    // `FILE:/DATASET`; the dataset path starts with '/', the file name may hold ':' itself.
    let data_file = geometry
        .rsplit_once(":/")
        .map(|(f, _)| f.trim())
        .filter(|f| !f.is_empty())
        .ok_or_else(|| {
            format!("frame of step {step}: geometry \"{geometry}\" is not FILE:/DATASET")
        })?;
    Ok(Some(Listed {
        step,
        time,
        data_file: data_file.to_string(),
    }))
}

/// Dataset `name` of `file` as f64, with its shape.
fn read_f64(file: &hdf5::File, name: &str) -> Result<(Vec<usize>, Vec<f64>), String> {
    let ds = file
        .dataset(name)
        .map_err(|_| format!("no dataset /{name}"))?;
    let values = ds
        .read_raw::<f64>()
        .map_err(|e| format!("cannot read /{name}: {e}"))?;
    Ok((ds.shape(), values))
}

type Mesh = (Vec<[f64; 2]>, Vec<[usize; 3]>);

fn read_mesh(file: &hdf5::File) -> Result<Mesh, String> {
    let (shape, xy) = read_f64(file, "geometry")?;
    if shape.len() != 2 || shape[1] != 2 {
        return Err(format!("/geometry has shape {shape:?}, expected n x 2"));
    }
    let n = shape[0];
    let position: Vec<[f64; 2]> = xy.chunks_exact(2).map(|p| [p[0], p[1]]).collect();

    let ds = file
        .dataset("connectivity")
        .map_err(|_| "no dataset /connectivity".to_string())?;
    let shape = ds.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(format!("/connectivity has shape {shape:?}, expected m x 3"));
    }
    let rows = ds
        .read_raw::<i64>()
        .map_err(|e| format!("cannot read /connectivity: {e}"))?;
    let vertex = |v: i64| usize::try_from(v).ok().filter(|&i| i < n);
    let triangles = rows
        .chunks_exact(3)
        .enumerate()
        .map(|(t, r)| match (vertex(r[0]), vertex(r[1]), vertex(r[2])) {
            (Some(a), Some(b), Some(c)) => Ok([a, b, c]),
            _ => Err(format!(
                "/connectivity row {t} ({}, {}, {}) is not a row of /geometry (n = {n})",
                r[0], r[1], r[2]
            )),
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok((position, triangles))
}

impl Frame {
    /// Per-particle values of field `name`: a scalar as is, a vector as its length. `None` when
    /// the frame has no such field.
    pub fn field(&self, name: &str) -> Result<Option<Vec<f64>>, PlotError> {
        let dataset = format!("point_data/{name}");
        if self.file.dataset(&dataset).is_err() {
            return Ok(None);
        }
        let (shape, values) =
            read_f64(&self.file, &dataset).map_err(|m| PlotError::new(&self.path, m))?;
        let n = self.position.len();
        let bad = |what: &str| {
            PlotError::new(
                &self.path,
                format!("/{dataset} has shape {shape:?}: {what} (n = {n} particles)"),
            )
        };
        if shape.first() != Some(&n) {
            return Err(bad("not one row per particle"));
        }
        match shape.get(1).copied().unwrap_or(1) {
            1 => Ok(Some(values)),
            w if w <= 3 => Ok(Some(
                values
                    .chunks_exact(w)
                    .map(|v| v.iter().map(|c| c * c).sum::<f64>().sqrt())
                    .collect(),
            )),
            _ => Err(bad("not a scalar or a vector")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SERIES: &str = "<?xml version=\"1.0\"?>\n<Xdmf Version=\"3.0\"><Domain>\
        <Grid Name=\"fields\" GridType=\"Collection\" CollectionType=\"Temporal\">\n\
        <Grid Name=\"step_000001\" GridType=\"Uniform\"><Time Value=\"0.5\"/>\
        <Geometry GeometryType=\"XY\"><DataItem Format=\"HDF\">fields/step_000001.h5:/geometry\
        </DataItem></Geometry></Grid>\n\
        <Grid Name=\"step_000012\" GridType=\"Uniform\"><Time Value=\"1.25\"/>\
        <Topology><DataItem Format=\"HDF\">fields/step_000012.h5:/connectivity</DataItem></Topology>\
        <Geometry GeometryType=\"XY\">\n <DataItem Dimensions=\"9 2\" Format=\"HDF\">\
        fields/step_000012.h5:/geometry</DataItem></Geometry></Grid>\n\
        </Grid></Domain></Xdmf>\n";

    #[test]
    fn the_last_frame_is_found() {
        let l = last_listed(SERIES).unwrap().unwrap();
        assert_eq!(
            l,
            Listed {
                step: 12,
                time: Some(1.25),
                data_file: "fields/step_000012.h5".to_string()
            }
        );
    }

    #[test]
    fn empty_and_damaged_series() {
        let empty = "<Xdmf><Domain><Grid Name=\"fields\"></Grid></Domain></Xdmf>";
        assert_eq!(last_listed(empty).unwrap(), None);
        assert!(last_listed("hello").unwrap_err().contains("not an XDMF"));
        let cut = &SERIES[..SERIES.rfind("</Grid>\n</Grid>").unwrap()];
        assert!(last_listed(cut).unwrap_err().contains("not terminated"));
        let no_file = SERIES.replace("fields/step_000012.h5:/geometry", "geometry");
        assert!(last_listed(&no_file).unwrap_err().contains("FILE:/DATASET"));
    }
}
