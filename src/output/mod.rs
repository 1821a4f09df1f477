//! ParaView output: the particles and triangles of each output step with per-particle fields,
//! as an XDMF time series over one HDF5 file per frame.
//!
//! Layout of an output folder `DIR`:
//!
//! - `DIR/fields.xdmf`: XDMF 3 series, a `Temporal` collection of one `Uniform` grid per frame
//!   (named `step_NNNNNN`, with `<Time Value>` the frame's load factor). Open it in ParaView
//!   with the "XDMF Reader" (checked with VTK's `vtkXdmfReader`, which that reader is) or read
//!   it with meshio's `TimeSeriesReader`. Rank 0 rewrites it after
//!   every frame via a temporary file and a rename, so a reader never sees half a file.
//! - `DIR/fields/step_NNNNNN.h5`: one frame, written collectively by all ranks, each its own
//!   rows, particles and triangles in rank order. n = particles, m = triangles:
//!
//! | dataset | type | shape | meaning |
//! |---|---|---|---|
//! | `/geometry` | f64 | n x 2 | current position |
//! | `/connectivity` | i64 | m x 3 | rows of `/geometry`, counter-clockwise |
//! | `/gid` | i64 | n | global particle id |
//! | `/point_data/NAME` | f64 | n, n x 3 or n x 9 | scalar, vector or tensor field `NAME` |
//!
//! with root attributes `format` = `"pfem-mpi fields"`, `format_version` = 1 (u32), `step`
//! (u64), `time` (f64) and `ranks` (u32, ranks that wrote the file).
//!
//! Choices made for ParaView: the geometry stays `XY` (the XDMF readers of ParaView and meshio
//! accept it; ParaView adds z = 0 itself); vectors are stored with three components, z = 0,
//! because ParaView shows only three-component arrays as vectors (Glyph orientation, Warp By
//! Vector and Stream Tracer list nothing else) while a two-component array is just a pair of
//! numbers; plane-strain tensors are stored as full 3 x 3 row-major tensors (XDMF `Tensor`),
//! the one tensor layout whose component order every reader agrees on. Ids and connectivity
//! are signed 64-bit, VTK's id type, as XDMF `Int` with precision 8 is read by every reader.
//! The ids come last in each grid so that readers make the first scalar field the active one.
//!
//! A frame without any triangle is written like any other and reads back with h5py or meshio,
//! but `vtkXdmfReader` reports an error on its empty datasets; a real run always has triangles.

mod connectivity;
mod error;
mod field;
mod frame_file;
mod replace;
mod xdmf;

use std::path::{Path, PathBuf};

use mpi::traits::Communicator;
use pfem_partition::{allgather_u64, exscan_u64, Comm};

pub use error::OutputError;
pub use field::Field;
pub use replace::replace_file;

use error::agree;
use field::{check_fields, signature, FieldDesc};
use frame_file::{Contents, Rows};
use xdmf::{data_file_name, frame_entry, parse_series, series, FrameEntry, FrameInfo};

/// One output frame: this rank's owned particles and owned triangles.
pub struct Frame<'a> {
    /// The load step; names the frame file and orders the series.
    pub step: u64,
    /// The load factor (pseudo-time) of the step, shown by ParaView as the frame's time.
    pub time: f64,
    /// Owned particles, sorted ascending.
    pub gid: &'a [u64],
    /// Current position of each owned particle.
    pub position: &'a [[f64; 2]],
    /// Per owned particle; every rank passes the same names and kinds in the same order.
    pub point_data: Vec<Field<'a>>,
    /// Owned triangles, counter-clockwise, as global particle ids (vertices may be owned by
    /// other ranks).
    pub triangles: &'a [[u64; 3]],
    /// Owner rank of a non-owned vertex gid appearing in `triangles`.
    pub owner_of: &'a dyn Fn(u64) -> Option<i32>,
}

/// Writes the frames of a run: one HDF5 file per frame and the XDMF series listing them.
pub struct FieldsWriter {
    dir: PathBuf,
    /// Frames of the series, oldest first. Only rank 0, which alone writes the series file,
    /// keeps them; other ranks hold none.
    frames: Vec<FrameEntry>,
}

/// Writes the series `text` to `path` through `path.tmp` and a rename, so that `path` is
/// always either the old or the new file.
fn replace_series(path: &Path, text: &str) -> Result<(), OutputError> {
    replace_file(path, text.as_bytes()).map_err(|m| OutputError::new(path, m))
}

/// The frames of the existing series at `path` up to `last_step`; none when there is no file.
fn kept_frames(path: &Path, last_step: u64) -> Result<Vec<FrameEntry>, OutputError> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(OutputError::new(path, format!("cannot read: {e}"))),
    };
    let mut frames = parse_series(&text).map_err(|m| {
        OutputError::new(
            path,
            format!("cannot continue the series ({m}); move the file away to start a new one"),
        )
    })?;
    frames.retain(|f| f.step <= last_step);
    Ok(frames)
}

/// FNV-1a: a cheap fingerprint for checking that all ranks describe the same frame.
fn fingerprint(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Checks of one rank's frame made before any exchange; returns the ids as stored.
fn check_frame(frame: &Frame<'_>) -> Result<Vec<i64>, String> {
    let n = frame.gid.len();
    if !frame.time.is_finite() {
        return Err(format!("time {} is not finite", frame.time));
    }
    if frame.position.len() != n {
        return Err(format!(
            "{} positions for {n} owned particles",
            frame.position.len()
        ));
    }
    if let Some(w) = frame.gid.windows(2).find(|w| w[0] >= w[1]) {
        return Err(format!(
            "owned particle ids are not sorted ascending and unique ({} then {})",
            w[0], w[1]
        ));
    }
    check_fields(&frame.point_data, n)?;
    frame
        .gid
        .iter()
        .map(|&g| i64::try_from(g).map_err(|_| format!("particle id {g} exceeds i64")))
        .collect()
}

impl FieldsWriter {
    /// Collective. Prepares output folder `dir`: creates it and `dir/fields`, and writes
    /// `dir/fields.xdmf` listing, when `first_step` > 0 (a restart), the frames of steps up to
    /// `first_step` already listed in an existing `dir/fields.xdmf`, otherwise no frame. Frame
    /// files of dropped frames stay on disk until a frame of the same step replaces them. Every
    /// rank returns the same result.
    pub fn open(comm: &Comm, dir: &Path, first_step: u64) -> Result<FieldsWriter, OutputError> {
        let mut frames = Vec::new();
        let local = if comm.rank() == 0 {
            let data_dir = dir.join(xdmf::DATA_DIR);
            let series_path = dir.join(xdmf::SERIES);
            std::fs::create_dir_all(&data_dir)
                .map_err(|e| OutputError::new(&data_dir, format!("cannot create folder: {e}")))
                .and_then(|_| {
                    if first_step > 0 {
                        frames = kept_frames(&series_path, first_step)?;
                    }
                    replace_series(&series_path, &series(&frames))
                })
        } else {
            Ok(())
        };
        agree(comm, local)?;
        Ok(FieldsWriter {
            dir: dir.to_path_buf(),
            frames,
        })
    }

    /// The series file, `DIR/fields.xdmf`.
    pub fn series_path(&self) -> PathBuf {
        self.dir.join(xdmf::SERIES)
    }

    /// The frame file of `step`, `DIR/fields/step_NNNNNN.h5`.
    pub fn frame_path(&self, step: u64) -> PathBuf {
        self.dir.join(xdmf::DATA_DIR).join(data_file_name(step))
    }

    /// Collective; every rank calls it, also with no particles or triangles. Writes the frame
    /// file of `frame.step` (collective hyperslab writes, particles in rank order, triangles
    /// rewritten from gids to rows of that file), then rank 0 rewrites the series file with
    /// this frame last, dropping listed frames of the same or later steps. Every rank returns
    /// the same result; after an error the writer can still be used.
    pub fn write(&mut self, comm: &Comm, frame: &Frame<'_>) -> Result<(), OutputError> {
        let path = self.frame_path(frame.step);
        let gid = agree(
            comm,
            check_frame(frame).map_err(|m| OutputError::new(&path, m)),
        )?;

        let descs: Vec<FieldDesc> = frame.point_data.iter().map(Field::desc).collect();
        let mut id = signature(&descs);
        id.extend_from_slice(&frame.step.to_le_bytes());
        id.extend_from_slice(&frame.time.to_bits().to_le_bytes());
        let ids = allgather_u64(comm, &[fingerprint(&id)]);
        if let Some(r) = ids.iter().position(|&h| h != ids[0]) {
            return Err(OutputError::new(
                &path,
                format!("rank {r} passes a different step, time or field list than rank 0"),
            ));
        }

        let (p0, n) = exscan_u64(comm, frame.gid.len() as u64);
        let (t0, m) = exscan_u64(comm, frame.triangles.len() as u64);
        let conn = connectivity::triangle_rows(
            comm,
            &path,
            frame.gid,
            p0,
            frame.triangles,
            frame.owner_of,
        )?;
        let rows = |first: u64, total: u64| Rows {
            first: first as usize,
            total: total as usize,
        };
        let contents = Contents {
            step: frame.step,
            time: frame.time,
            points: rows(p0, n),
            triangles: rows(t0, m),
            gid: &gid,
            position: frame.position,
            connectivity: &conn,
            fields: &frame.point_data,
        };
        frame_file::write(comm, &path, &contents)?;

        let local = if comm.rank() == 0 {
            self.frames.retain(|f| f.step < frame.step);
            self.frames.push(frame_entry(&FrameInfo {
                step: frame.step,
                time: frame.time,
                points: n as usize,
                triangles: m as usize,
                fields: &descs,
            }));
            replace_series(&self.series_path(), &series(&self.frames))
        } else {
            Ok(())
        };
        agree(comm, local)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame<'a>(gid: &'a [u64], position: &'a [[f64; 2]], time: f64) -> Frame<'a> {
        Frame {
            step: 1,
            time,
            gid,
            position,
            point_data: vec![Field::Scalar("p".into(), vec![0.0; gid.len()])],
            triangles: &[],
            owner_of: &|_| None,
        }
    }

    #[test]
    fn frames_are_checked_before_any_exchange() {
        let pos = [[0.0; 2]; 3];
        assert_eq!(
            check_frame(&frame(&[1, 5, 9], &pos, 0.5)),
            Ok(vec![1, 5, 9])
        );
        let e = check_frame(&frame(&[1, 9, 5], &pos, 0.5)).unwrap_err();
        assert!(e.contains("9 then 5"), "{e}");
        assert!(check_frame(&frame(&[1, 1, 5], &pos, 0.5)).is_err());
        assert!(check_frame(&frame(&[1, 5], &pos, 0.5))
            .unwrap_err()
            .contains("3 positions for 2"));
        assert!(check_frame(&frame(&[1, 5, 9], &pos, f64::NAN))
            .unwrap_err()
            .contains("not finite"));
        assert!(check_frame(&frame(&[1, 5, u64::MAX], &pos, 0.0))
            .unwrap_err()
            .contains("exceeds i64"));
    }

    #[test]
    fn restart_keeps_frames_up_to_the_first_step() {
        let dir = std::env::temp_dir().join(format!("pfem-xdmf-keep-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("fields.xdmf");
        assert_eq!(kept_frames(&path, 3).unwrap(), vec![]);
        let entries: Vec<FrameEntry> = [1u64, 2, 4]
            .iter()
            .map(|&step| {
                frame_entry(&FrameInfo {
                    step,
                    time: step as f64,
                    points: 1,
                    triangles: 0,
                    fields: &[],
                })
            })
            .collect();
        replace_series(&path, &series(&entries)).unwrap();
        assert!(!dir.join("fields.xdmf.tmp").exists());
        let kept = kept_frames(&path, 3).unwrap();
        assert_eq!(kept, entries[..2].to_vec());
        std::fs::write(&path, "not xml").unwrap();
        let e = kept_frames(&path, 3).unwrap_err();
        assert!(
            e.to_string().starts_with(&path.display().to_string()),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
