//! Group `/gauss` of a checkpoint: the Gauss states of every triangle of the mesh the last step
//! solved on, keyed by the triangle's global ids, so a restart keeps them exactly instead of
//! re-deriving them from the particles. Absent in new cases.

use std::ops::Range;
use std::path::Path;

use hdf5::{File, H5Type};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

use super::collective::block_range;
use super::error::{CaseError, CaseErrorKind};
use super::ffi;

/// Values per triangle: 3 Gauss points x 9 state values.
pub const GAUSS_LEN: usize = 27;
const GROUP: &str = "gauss";

/// Triangles (smallest-gid vertex first, CCW) with their Gauss states.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GaussRecords {
    pub key: Vec<[u64; 3]>,
    pub state: Vec<[f64; GAUSS_LEN]>,
}

impl GaussRecords {
    pub fn len(&self) -> usize {
        self.key.len()
    }

    pub fn is_empty(&self) -> bool {
        self.key.is_empty()
    }
}

fn column<T: H5Type>(
    file: &File,
    name: &str,
    width: usize,
    n: usize,
    rows: Range<usize>,
    data: &[T],
) -> hdf5::Result<()> {
    let group = match file.group(GROUP) {
        Ok(g) => g,
        Err(_) => file.create_group(GROUP)?,
    };
    let ds = group.new_dataset::<T>().shape((n, width)).create(name)?;
    let selected = ds.space()?.select((rows, ..))?;
    ffi::write_collective(&ds, &selected, data)
}

/// Collective: every rank writes its rows `rows` of `n`.
pub fn write(file: &File, g: &GaussRecords, rows: Range<usize>, n: usize) -> hdf5::Result<()> {
    column(file, "key", 3, n, rows.clone(), g.key.as_flattened())?;
    column(file, "state", GAUSS_LEN, n, rows, g.state.as_flattened())
}

/// Collective: a contiguous block of the records per rank (all empty when the group is absent).
pub fn read(
    comm: &SimpleCommunicator,
    file: &File,
    path: &Path,
) -> Result<GaussRecords, CaseError> {
    let Ok(group) = file.group(GROUP) else {
        return Ok(GaussRecords::default());
    };
    let bad = |name: &str, m: String| {
        CaseError::new(path, CaseErrorKind::Malformed, m).at(format!("dataset /{GROUP}/{name}"))
    };
    let key = group
        .dataset("key")
        .map_err(|_| bad("key", "missing".into()))?;
    let state = group
        .dataset("state")
        .map_err(|_| bad("state", "missing".into()))?;
    let (ks, ss) = (key.shape(), state.shape());
    if ks.len() != 2 || ks[1] != 3 {
        return Err(bad("key", format!("expected shape (m, 3), found {ks:?}")));
    }
    if ss.len() != 2 || ss[1] != GAUSS_LEN || ss[0] != ks[0] {
        return Err(bad(
            "state",
            format!("expected shape ({}, {GAUSS_LEN}), found {ss:?}", ks[0]),
        ));
    }
    let block = block_range(ks[0] as u64, comm.size() as u64, comm.rank() as u64);
    let rows = block.start as usize..block.end as usize;
    let mut g = GaussRecords {
        key: vec![[0; 3]; rows.len()],
        state: vec![[0.0; GAUSS_LEN]; rows.len()],
    };
    let read = (|| {
        ffi::read_collective(
            &key,
            &key.space()?.select((rows.clone(), ..))?,
            g.key.as_flattened_mut(),
        )?;
        ffi::read_collective(
            &state,
            &state.space()?.select((rows, ..))?,
            g.state.as_flattened_mut(),
        )
    })();
    read.map_err(|e| bad("state", format!("cannot read: {e}")))?;
    Ok(g)
}
