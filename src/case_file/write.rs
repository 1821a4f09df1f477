//! Writing a case file or checkpoint: every rank its own rows, in agreed steps
//! ([`super::lockstep`]), each dataset with its checksum.

use std::ops::Range;
use std::path::Path;

use hdf5::{Dataset, File, Group, H5Type};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

use super::checksum::{self, Word};
use super::collective::agree;
use super::datasets::{self, Column};
use super::error::{CaseError, CaseErrorKind};
use super::lockstep::{self, Lockstep};
use super::state_columns;
use super::{check_output, ffi, gauss, header, CaseHeader, GaussRecords, ParticleSet};
use super::{BULGE_LEN, CONTACT_LEN, GAUSS_POINTS, NODE_LEN};

/// Writes this rank's rows `rows` of column `c` (collective).
fn write_column<T: H5Type>(
    group: &Group,
    c: &Column,
    n: usize,
    rows: Range<usize>,
    data: &[T],
) -> hdf5::Result<Dataset> {
    let ds = datasets::create::<T>(group, c, n)?;
    let space = ds.space()?;
    let selected = if c.width == 0 {
        space.select(rows)?
    } else {
        space.select((rows, ..))?
    };
    ffi::write_collective(&ds, &selected, data)?;
    Ok(ds)
}

/// Collective. Column `c` and its checksum, each an agreed step.
fn column_step<T: H5Type + Word>(
    step: &Lockstep<'_>,
    group: &Group,
    c: &Column,
    n: usize,
    rows: Range<usize>,
    data: &[T],
) -> Result<Dataset, CaseError> {
    let what = format!("dataset /{}/{}", datasets::GROUP, c.name);
    let ds = step.step(&what, write_column(group, c, n, rows.clone(), data))?;
    let sum = step.total(checksum::rows_sum(rows.start, c.width, data));
    step.step(&what, checksum::put(&ds, sum))?;
    Ok(ds)
}

/// Collective. The whole file, one agreed step per attribute set and dataset.
#[allow(clippy::too_many_arguments)]
fn write_contents(
    file: &File,
    step: &Lockstep<'_>,
    header: &CaseHeader,
    ranks: u32,
    local: &ParticleSet,
    rows: Range<usize>,
    n: usize,
    gauss: &GaussRecords,
    gauss_rows: (Range<usize>, usize),
) -> Result<(), CaseError> {
    step.step("attributes", header::write_header(file, header, ranks))?;
    let names = &header.state_columns;
    gauss::write(file, step, gauss, gauss_rows.0, gauss_rows.1, names)?;
    let group = step.step("group /particles", file.create_group(datasets::GROUP))?;
    let [gid, position, displacement, h, state, flags, increment] = datasets::columns(names.len());
    let (g, r) = (&group, rows);
    column_step(step, g, &gid, n, r.clone(), &local.gid)?;
    column_step(
        step,
        g,
        &increment,
        n,
        r.clone(),
        local.increment.as_flattened(),
    )?;
    column_step(
        step,
        g,
        &position,
        n,
        r.clone(),
        local.position.as_flattened(),
    )?;
    let displacements = local.displacement.as_flattened();
    column_step(step, g, &displacement, n, r.clone(), displacements)?;
    column_step(step, g, &h, n, r.clone(), &local.h)?;
    let ds = column_step(step, g, &state, n, r.clone(), local.state.as_flat())?;
    let what = format!(
        "attribute {} of dataset /particles/state",
        state_columns::ATTR
    );
    step.step(&what, state_columns::put(&ds, names))?;
    column_step(step, g, &flags, n, r.clone(), &local.flags)?;
    column_step(step, g, &datasets::material_column(), n, r, &local.material).map(drop)
}

/// Collective. Writes a case file: every rank passes its own particles (any count, zero
/// included), which are stored in rank order. The file is written as `path.tmp` and renamed to
/// `path` by rank 0 once every rank has closed it, so an interrupted write never leaves a
/// partial file under the final name. Its disk space is reserved first, so a full disk is an
/// error before anything is written. On error every rank returns the same error, the temporary
/// is removed, and a file already at `path` is left as it was.
pub fn write_case(
    comm: &SimpleCommunicator,
    path: &Path,
    header: &CaseHeader,
    local: &ParticleSet,
) -> Result<(), CaseError> {
    write_checkpoint(comm, path, header, local, &GaussRecords::default())
}

/// Collective. [`write_case`] plus the Gauss states of this rank's owned triangles (group
/// `/gauss`), so a restart continues exactly where the run stopped.
pub fn write_checkpoint(
    comm: &SimpleCommunicator,
    path: &Path,
    header: &CaseHeader,
    local: &ParticleSet,
    gauss: &GaussRecords,
) -> Result<(), CaseError> {
    let width = header.state_columns.len();
    let checked = local
        .check_lengths()
        .and_then(|_| {
            let widths = [
                (local.state.width(), width, "particle"),
                (gauss.state.width(), GAUSS_POINTS * width, "Gauss"),
            ];
            match widths.iter().find(|(w, want, _)| *w != *want && *w != 0) {
                Some((w, want, what)) => Err(format!(
                    "{what} state rows of {w} values where the layout's columns make {want}"
                )),
                None => Ok(()),
            }
        })
        .map_err(|m| CaseError::new(path, CaseErrorKind::InvalidInput, m));
    agree(comm, path, checked)?;
    check_output(comm, path, None)?;

    let count = local.len() as u64;
    let mut inclusive = 0u64;
    comm.scan_into(
        &count,
        &mut inclusive,
        mpi::collective::SystemOperation::sum(),
    );
    let mut total = 0u64;
    comm.all_reduce_into(&count, &mut total, mpi::collective::SystemOperation::sum());
    let start = (inclusive - count) as usize;
    let rows = start..start + local.len();
    let mut counts = vec![0u64; comm.size() as usize];
    comm.all_gather_into(&count, &mut counts[..]);
    let mut header = header.clone();
    header.rank_counts = counts;
    let gcount = gauss.len() as u64;
    let mut ginclusive = 0u64;
    comm.scan_into(
        &gcount,
        &mut ginclusive,
        mpi::collective::SystemOperation::sum(),
    );
    let mut gtotal = 0u64;
    comm.all_reduce_into(
        &gcount,
        &mut gtotal,
        mpi::collective::SystemOperation::sum(),
    );
    let gstart = (ginclusive - gcount) as usize;
    let gauss_rows = (gstart..gstart + gauss.len(), gtotal as usize);

    let ranks = comm.size() as u32;
    let raw = total * datasets::bytes_per_particle(width)
        + gtotal * (8 * (3 + GAUSS_POINTS * width + NODE_LEN + CONTACT_LEN + BULGE_LEN)) as u64
        + 8 * (header.tracked_gids.len() + header.rank_counts.len()) as u64;
    let text =
        (header.scene_toml.len() + header.scene_source.len() + header.code_version.len()) as u64;
    lockstep::write_hdf5(comm, path, lockstep::estimate(raw, text), |file, step| {
        write_contents(
            file,
            step,
            &header,
            ranks,
            local,
            rows,
            total as usize,
            gauss,
            gauss_rows,
        )
    })
}
