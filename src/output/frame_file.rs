//! One frame's HDF5 file, written collectively: every rank its own rows of each dataset, in
//! rank order.

use std::path::Path;

use hdf5::types::VarLenUnicode;
use hdf5::{File, Group, H5Type};
use mpi::traits::Communicator;
use pfem_partition::Comm;

use super::error::OutputError;
use super::field::Field;
use crate::case_file::ffi::write_collective;
use crate::case_file::{estimate_bytes, write_hdf5, CaseError, Lockstep};

/// Value of the root attribute `format`.
pub(crate) const FORMAT: &str = "pfem-mpi fields";
/// Value of the root attribute `format_version`.
pub(crate) const FORMAT_VERSION: u32 = 1;
/// Group holding one dataset per field.
pub(crate) const POINT_DATA: &str = "point_data";

/// This rank's block of a dataset: rows `first..first + count` of `total`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rows {
    pub first: usize,
    pub total: usize,
}

/// Everything one rank writes into a frame file.
pub(crate) struct Contents<'a> {
    pub step: u64,
    pub time: f64,
    pub points: Rows,
    pub triangles: Rows,
    pub gid: &'a [i64],
    pub position: &'a [[f64; 2]],
    /// Three rows of the file's particles per owned triangle.
    pub connectivity: &'a [i64],
    pub fields: &'a [Field<'a>],
}

/// Creates dataset `name` of `total` rows of `width` values (a 1-D array for width 1) and writes
/// `data`, whole rows, from row `first` (collective).
fn write_rows<T: H5Type>(
    group: &Group,
    name: &str,
    width: usize,
    at: Rows,
    data: &[T],
) -> hdf5::Result<()> {
    let rows = at.first..at.first + data.len() / width;
    if width == 1 {
        let ds = group.new_dataset::<T>().shape(at.total).create(name)?;
        let space = ds.space()?.select(rows)?;
        write_collective(&ds, &space, data)
    } else {
        let ds = group
            .new_dataset::<T>()
            .shape((at.total, width))
            .create(name)?;
        let space = ds.space()?.select((rows, ..))?;
        write_collective(&ds, &space, data)
    }
}

fn put<T: H5Type>(file: &File, name: &str, value: T) -> hdf5::Result<()> {
    file.new_attr::<T>().create(name)?.write_scalar(&value)
}

/// Collective. The whole frame, one agreed step per attribute and dataset.
fn write_contents(
    file: &File,
    step: &Lockstep<'_>,
    ranks: u32,
    c: &Contents<'_>,
) -> Result<(), CaseError> {
    let format: hdf5::Result<VarLenUnicode> = FORMAT
        .parse()
        .map_err(|e| hdf5::Error::Internal(format!("attribute format: {e}")));
    step.step(
        "attributes",
        format.and_then(|format| {
            file.new_attr::<VarLenUnicode>()
                .create("format")?
                .write_scalar(&format)?;
            put(file, "format_version", FORMAT_VERSION)?;
            put(file, "step", c.step)?;
            put(file, "time", c.time)?;
            put(file, "ranks", ranks)
        }),
    )?;
    let geometry = c.position.as_flattened();
    step.step(
        "dataset /geometry",
        write_rows(file, "geometry", 2, c.points, geometry),
    )?;
    step.step(
        "dataset /connectivity",
        write_rows(file, "connectivity", 3, c.triangles, c.connectivity),
    )?;
    step.step("dataset /gid", write_rows(file, "gid", 1, c.points, c.gid))?;
    let group = step.step(
        &format!("group /{POINT_DATA}"),
        file.create_group(POINT_DATA),
    )?;
    for f in c.fields {
        step.step(
            &format!("dataset /{POINT_DATA}/{}", f.name()),
            write_rows(
                &group,
                f.name(),
                f.kind().components(),
                c.points,
                &f.stored(),
            ),
        )?;
    }
    Ok(())
}

/// Collective. Writes the frame file `path` through `path.tmp` and a rename (replacing any file
/// of that name only once the new one is complete), its disk space reserved first. Every rank
/// returns the same result.
pub(crate) fn write(comm: &Comm, path: &Path, c: &Contents<'_>) -> Result<(), OutputError> {
    let ranks = u32::try_from(comm.size()).unwrap_or(u32::MAX);
    let per_point: usize = 3 + c
        .fields
        .iter()
        .map(|f| f.kind().components())
        .sum::<usize>();
    let raw = 8 * (c.points.total * per_point + 3 * c.triangles.total) as u64;
    write_hdf5(comm, path, estimate_bytes(raw, 64), |file, step| {
        write_contents(file, step, ranks, c)
    })
    .map_err(|e| {
        let message = match &e.location {
            Some(at) => format!("{at}: {}", e.message),
            None => e.message,
        };
        OutputError::new(path, message)
    })
}
