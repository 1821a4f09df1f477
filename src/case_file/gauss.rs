//! Group `/gauss` of a checkpoint: the Gauss states of every triangle of the mesh the last step
//! solved on, keyed by the triangle's global ids, so a restart keeps them exactly instead of
//! re-deriving them from the particles, and the last increment's values at the triangle's six
//! nodes (the next step's Newton predictor). Absent in new cases; `nodes` is optional.

use std::ops::Range;
use std::path::Path;

use hdf5::{Dataset, File, H5Type};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

use super::checksum::{self, Word};
use super::collective::block_range;
use super::error::{CaseError, CaseErrorKind};
use super::ffi;
use super::lockstep::Lockstep;
use super::state_columns;
use crate::material::{Rows, STRESS_LEN};

/// Gauss points per triangle: a state row of `/gauss/state` holds this many rows of the
/// material's layout.
pub const GAUSS_POINTS: usize = 3;
/// Node values per triangle: 6 nodes (vertices in key order, then the midside nodes of edges
/// 01, 12, 20) x (displacement increment per whole step x, y; pressure, NaN if none). A node
/// the run did not keep is NaN throughout: a P2 vertex (its particle's increment is the same)
/// and, before a first solve, every node; a midside node's pressure is 0.
pub const NODE_LEN: usize = 18;
/// Contact values per triangle: 6 nodes (as in `nodes`) x (rigid body index, contact pressure,
/// shear stress), NaN where the node touched no body.
pub const CONTACT_LEN: usize = 18;
/// Curve values per triangle: the relative midside offset (`mesh::curved::bulge`, ends in gid
/// order) of its edges 01, 12, 20 where the edge was a boundary edge at the end of the last
/// increment, NaN elsewhere. The next remesh curves those edges again.
pub const BULGE_LEN: usize = 3;
const GROUP: &str = "gauss";

/// Triangles (smallest-gid vertex first, CCW) with their Gauss states.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GaussRecords {
    pub key: Vec<[u64; 3]>,
    /// [`GAUSS_POINTS`] state rows of the material's layout per triangle.
    pub state: Rows,
    /// NaN where unknown (a file without `nodes`).
    pub nodes: Vec<[f64; NODE_LEN]>,
    /// NaN where no contact (or a file without `contact`).
    pub contact: Vec<[f64; CONTACT_LEN]>,
    /// NaN where no curve (or a file without `bulge`).
    pub bulge: Vec<[f64; BULGE_LEN]>,
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
) -> hdf5::Result<Dataset> {
    let group = match file.group(GROUP) {
        Ok(g) => g,
        Err(_) => file.create_group(GROUP)?,
    };
    let ds = group.new_dataset::<T>().shape((n, width)).create(name)?;
    let selected = ds.space()?.select((rows, ..))?;
    ffi::write_collective(&ds, &selected, data)?;
    Ok(ds)
}

/// Collective. Dataset `name` and its checksum, each an agreed step.
fn column_step<T: H5Type + Word>(
    step: &Lockstep<'_>,
    file: &File,
    name: &str,
    width: usize,
    (n, rows): (usize, Range<usize>),
    data: &[T],
) -> Result<Dataset, CaseError> {
    let what = format!("dataset /{GROUP}/{name}");
    let ds = step.step(&what, column(file, name, width, n, rows.clone(), data))?;
    let sum = step.total(checksum::rows_sum(rows.start, width, data));
    step.step(&what, checksum::put(&ds, sum))?;
    Ok(ds)
}

/// Collective: every rank writes its rows `rows` of `n`, one agreed step per dataset; the state
/// rows are laid out as `columns` names them.
pub(crate) fn write(
    file: &File,
    step: &Lockstep<'_>,
    g: &GaussRecords,
    rows: Range<usize>,
    n: usize,
    columns: &[String],
) -> Result<(), CaseError> {
    let at = || (n, rows.clone());
    column_step(step, file, "key", 3, at(), g.key.as_flattened())?;
    column_step(step, file, "nodes", NODE_LEN, at(), g.nodes.as_flattened())?;
    column_step(
        step,
        file,
        "contact",
        CONTACT_LEN,
        at(),
        g.contact.as_flattened(),
    )?;
    column_step(step, file, "bulge", BULGE_LEN, at(), g.bulge.as_flattened())?;
    let width = GAUSS_POINTS * columns.len();
    let ds = column_step(step, file, "state", width, at(), g.state.as_flat())?;
    let what = format!(
        "attribute {} of dataset /{GROUP}/state",
        state_columns::ATTR
    );
    step.step(&what, state_columns::put(&ds, columns))
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
    let width = ss.get(1).copied().unwrap_or(0);
    if ss.len() != 2
        || width < GAUSS_POINTS * STRESS_LEN
        || !width.is_multiple_of(GAUSS_POINTS)
        || ss[0] != ks[0]
    {
        return Err(bad(
            "state",
            format!(
                "expected shape ({}, {GAUSS_POINTS} x the state's width), found {ss:?}",
                ks[0]
            ),
        ));
    }
    let block = block_range(ks[0] as u64, comm.size() as u64, comm.rank() as u64);
    let rows = block.start as usize..block.end as usize;
    let mut g = GaussRecords {
        key: vec![[0; 3]; rows.len()],
        state: Rows::zeros(width, rows.len()),
        nodes: vec![[f64::NAN; NODE_LEN]; rows.len()],
        contact: vec![[f64::NAN; CONTACT_LEN]; rows.len()],
        bulge: vec![[f64::NAN; BULGE_LEN]; rows.len()],
    };
    // The optional per-triangle datasets: absent in older files, else one row per key.
    let optional = |name: &str, width: usize| -> Result<Option<Dataset>, CaseError> {
        let Ok(ds) = group.dataset(name) else {
            return Ok(None);
        };
        let shape = ds.shape();
        if shape.len() != 2 || shape[1] != width || shape[0] != ks[0] {
            return Err(bad(
                name,
                format!("expected shape ({}, {width}), found {shape:?}", ks[0]),
            ));
        }
        Ok(Some(ds))
    };
    let contact = optional("contact", CONTACT_LEN)?;
    let bulge = optional("bulge", BULGE_LEN)?;
    let nodes = optional("nodes", NODE_LEN)?;
    let read = (|| {
        ffi::read_collective(
            &key,
            &key.space()?.select((rows.clone(), ..))?,
            g.key.as_flattened_mut(),
        )?;
        if let Some(contact) = &contact {
            ffi::read_collective(
                contact,
                &contact.space()?.select((rows.clone(), ..))?,
                g.contact.as_flattened_mut(),
            )?;
        }
        if let Some(bulge) = &bulge {
            ffi::read_collective(
                bulge,
                &bulge.space()?.select((rows.clone(), ..))?,
                g.bulge.as_flattened_mut(),
            )?;
        }
        if let Some(nodes) = &nodes {
            ffi::read_collective(
                nodes,
                &nodes.space()?.select((rows.clone(), ..))?,
                g.nodes.as_flattened_mut(),
            )?;
        }
        ffi::read_collective(
            &state,
            &state.space()?.select((rows, ..))?,
            g.state.as_flat_mut(),
        )
    })();
    read.map_err(|e| bad("state", format!("cannot read: {e}")))?;
    Ok(g)
}

/// Collective. Checks the checksums of the records this rank read, rows `first..` (every rank
/// gets the same outcome: each checksum is a total over all ranks).
pub fn verify(
    comm: &SimpleCommunicator,
    file: &File,
    path: &Path,
    g: &GaussRecords,
    first: usize,
) -> Result<(), CaseError> {
    let Ok(group) = file.group(GROUP) else {
        return Ok(());
    };
    let bad = |name: &str, m: String| {
        CaseError::new(path, CaseErrorKind::Malformed, m).at(format!("dataset /{GROUP}/{name}"))
    };
    let check = |name: &str, width: usize, data: &[f64]| match group.dataset(name) {
        Ok(ds) => checksum::verify(comm, &ds, first, width, data).map_err(|m| bad(name, m)),
        Err(_) => Ok(()),
    };
    let key = group
        .dataset("key")
        .map_err(|_| bad("key", "missing".into()))?;
    checksum::verify(comm, &key, first, 3, g.key.as_flattened()).map_err(|m| bad("key", m))?;
    check("nodes", NODE_LEN, g.nodes.as_flattened())?;
    check("contact", CONTACT_LEN, g.contact.as_flattened())?;
    check("bulge", BULGE_LEN, g.bulge.as_flattened())?;
    check("state", g.state.width(), g.state.as_flat())
}
