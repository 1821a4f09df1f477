//! Case files: the complete state of an analysis (scene, progress, particles) in one HDF5 file,
//! used both to start a case and as a checkpoint to restart from.
//!
//! Format version 2 (version 1 files are read too). Root attributes:
//!
//! | name | type | meaning |
//! |---|---|---|
//! | `format` | string | always `"pfem-mpi case"` |
//! | `format_version` | u32 | 2 |
//! | `code_version` | string | version of the pfem-mpi that wrote the file |
//! | `scene` | string | the full resolved scene as TOML (overrides and defaults applied) |
//! | `scene_source` | string | scene file name or built-in name |
//! | `step` | u64 | completed load steps |
//! | `load_factor` | f64 | load factor reached |
//! | `time` | f64 | analysis time reached |
//! | `next_gid` | u64 | first global id not yet used |
//! | `ranks` | u32 | number of MPI ranks that wrote the file |
//! | `tracked_gids` | u64 array | particle tracked by each `[[point_load]]`, in order |
//! | `collapse_reference` | f64, optional | `steps.until_collapse`: the first increment's largest displacement per unit load factor |
//!
//! Datasets in group `/particles`, n = global particle count, one row per particle:
//! `gid` (u64, n), `position` (f64, n x 2, current), `displacement` (f64, n x 2, total since the
//! start), `h` (f64, n), `state` (f64, n x w), `flags` (u32, n), `increment` (f64, n x 2, the
//! last step's displacement increment). `state` holds one row of the material's layout per
//! particle: w = 4 stress components plus the model's internal variables, named column by
//! column in its string-array attribute `names` (`state_columns.rs`; version 1 had no attribute
//! and w = 9 for every model: stress, plastic strain, `eps_q`). A reader matches the columns by
//! name against the scene's material.
//!
//! Group `/gauss` (checkpoints): see `case_file/gauss.rs`. Every dataset carries an attribute
//! `checksum` (u64, `case_file/checksum.rs`), checked on reading; files written before it have
//! none and are read unchecked (no version change: older programs ignore the attribute).
//!
//! The file is written collectively by all ranks (each writes its own rows, placed by rank
//! order) and can be read back by any number of ranks, each getting a contiguous block. Besides
//! types and shapes, what is read must satisfy the rules of `case_file/validate.rs` (the scene's
//! own, and the format's invariants); a file that breaks one is an error naming the dataset or
//! attribute, in runs and in `pfem-mpi info`.

#[path = "case_file/checksum.rs"]
mod checksum;
#[path = "case_file/collective.rs"]
mod collective;
#[path = "case_file/datasets.rs"]
mod datasets;
#[path = "case_file/destination.rs"]
mod destination;
#[path = "case_file/error.rs"]
mod error;
#[path = "case_file/ffi.rs"]
pub(crate) mod ffi;
#[path = "case_file/gauss.rs"]
mod gauss;
#[path = "case_file/header.rs"]
mod header;
#[path = "case_file/lockstep.rs"]
mod lockstep;
#[path = "case_file/particles.rs"]
mod particles;
#[path = "case_file/state_columns.rs"]
mod state_columns;
#[path = "case_file/summary.rs"]
mod summary;
#[path = "case_file/validate.rs"]
pub mod validate;
#[path = "case_file/validate_blocks.rs"]
mod validate_blocks;
#[path = "case_file/write.rs"]
mod write;

use std::io::{Read, Seek, SeekFrom};
use std::ops::Range;
use std::path::{Path, PathBuf};

use hdf5::{Dataset, File, H5Type};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

pub use collective::block_range;
pub use error::{CaseError, CaseErrorKind};
pub use gauss::{GaussRecords, BULGE_LEN, CONTACT_LEN, GAUSS_POINTS, NODE_LEN};
pub use particles::ParticleSet;
pub use write::{write_case, write_checkpoint};

use crate::scene::{generate_particles, lattice, Scene};
use collective::agree;
pub(crate) use lockstep::{estimate as estimate_bytes, write_hdf5, Lockstep};

/// Value of the `format` attribute.
pub const FORMAT: &str = "pfem-mpi case";
/// Format version written by this program, and the newest it reads.
pub const FORMAT_VERSION: u32 = 2;

/// Everything in a case file except the particles.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseHeader {
    /// Format version of the file read; [`write_case`] always writes [`FORMAT_VERSION`].
    pub format_version: u32,
    /// Version of the pfem-mpi that wrote (or will write) the file.
    pub code_version: String,
    /// The resolved scene as TOML; [`Scene::from_toml`] reads it back.
    pub scene_toml: String,
    /// Scene file name or built-in name the case was created from.
    pub scene_source: String,
    pub step: u64,
    pub load_factor: f64,
    pub time: f64,
    /// First global particle id not yet used.
    pub next_gid: u64,
    /// Rank count that wrote the file; [`write_case`] records the writing communicator's size.
    pub ranks: u32,
    /// Global id of the particle tracked by each `[[point_load]]`, in scene order.
    pub tracked_gids: Vec<u64>,
    /// Particles written by each rank, in rank order ([`write_case`] records them). A reader
    /// with the same rank count takes the same blocks, so a restart keeps the partition.
    pub rank_counts: Vec<u64>,
    /// The name of each column of a state row (the scene's material's layout): what the `names`
    /// attribute of the state datasets holds. A read case has been conformed to its scene.
    pub state_columns: Vec<String>,
    /// Under `steps.until_collapse`: the largest displacement per unit load factor of the first
    /// increment, against which a mechanism is told (`steps.collapse_compliance`).
    pub collapse_reference: Option<f64>,
}

/// A new case at step 0: the scene's particle lattice and, for each point load, the particle
/// nearest to its `at` point (ties go to the smaller gid).
pub fn new_case(scene: &Scene, source: &str) -> (CaseHeader, ParticleSet) {
    let mut particles = generate_particles(scene);
    // Point loads' particles, then the probes' (on their boundary, if named).
    let boundaries = crate::model::named_boundaries(scene);
    let on = |name: Option<&str>, x: [f64; 2]| {
        name.is_none_or(|n| crate::model::on_boundary(&boundaries, n, x, scene.mesh.h))
    };
    let tracked_gids = scene
        .point_load
        .iter()
        .map(|p| (p.at, None))
        .chain(scene.probe.iter().map(|p| (p.at, p.on.as_deref())))
        .filter_map(|(at, name)| {
            lattice::nearest_of(&particles, at, |x| on(name, x)).map(|(gid, _)| gid)
        })
        .collect();
    // A scene that fails here fails again, with its message, when the case is loaded.
    if let Ok(materials) = crate::model::materials_of(scene) {
        let points = particles.position.iter().zip(&particles.material);
        for ((x, &m), state) in points.zip(particles.state.iter_mut()) {
            if let Some(material) = materials.get(m as usize) {
                material.initial_internal(*x, &mut state[crate::material::STRESS_LEN..]);
            }
        }
    }
    if let Some(g) = &scene.geostatic {
        let gamma = scene.material.density * scene.gravity.g[0].hypot(scene.gravity.g[1]);
        let shapes = crate::scene::zones::shapes(scene).unwrap_or_default();
        for (x, state) in particles.position.iter().zip(particles.state.iter_mut()) {
            // Compression negative; the Gauss-state layout starts with σxx, σyy, σzz, σxy.
            let [sh, sv] = if shapes.is_empty() {
                let sv = -(g.surcharge + gamma * (g.surface - x[1]).max(0.0));
                [g.k0 * sv, sv]
            } else {
                crate::scene::zones::geostatic(scene, &shapes, *x, g)
            };
            state[0] = sh;
            state[1] = sv;
            state[2] = sh;
        }
    }
    let header = CaseHeader {
        format_version: FORMAT_VERSION,
        code_version: env!("CARGO_PKG_VERSION").to_string(),
        scene_toml: scene.to_toml(),
        scene_source: source.to_string(),
        step: 0,
        load_factor: 0.0,
        time: 0.0,
        next_gid: particles.len() as u64,
        ranks: 1,
        tracked_gids,
        state_columns: crate::model::state_layout(scene).columns(),
        collapse_reference: None,
        rank_counts: Vec::new(),
    };
    (header, particles)
}

const HDF5_SIGNATURE: [u8; 8] = [0x89, b'H', b'D', b'F', b'\r', b'\n', 0x1a, b'\n'];

/// Checks that `path` is a readable HDF5 file before handing it to the library. The signature
/// is at offset 0 or, after a user block, at 512, 1024, 2048, ...
fn sniff(path: &Path) -> Result<(), CaseError> {
    let io =
        |e: std::io::Error| CaseError::new(path, CaseErrorKind::Io, format!("cannot read: {e}"));
    let mut f = std::fs::File::open(path).map_err(io)?;
    let len = f.metadata().map_err(io)?.len();
    let mut offset = 0u64;
    while offset + 8 <= len {
        let mut sig = [0u8; 8];
        f.seek(SeekFrom::Start(offset)).map_err(io)?;
        f.read_exact(&mut sig).map_err(io)?;
        if sig == HDF5_SIGNATURE {
            return Ok(());
        }
        offset = if offset == 0 { 512 } else { offset * 2 };
    }
    Err(CaseError::new(
        path,
        CaseErrorKind::NotHdf5,
        "not an HDF5 file",
    ))
}

fn open_error(path: &Path, e: hdf5::Error) -> CaseError {
    let text = e.to_string();
    if text.contains("truncated") {
        CaseError::new(
            path,
            CaseErrorKind::Malformed,
            format!("truncated file ({text})"),
        )
    } else {
        CaseError::new(path, CaseErrorKind::Io, format!("cannot open: {text}"))
    }
}

fn tmp_path(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".tmp");
    PathBuf::from(name)
}

pub(crate) fn mpio_file(
    comm: &SimpleCommunicator,
    path: &Path,
    create: bool,
) -> hdf5::Result<File> {
    let mut builder = File::with_options();
    builder.with_fapl(|p| p.mpio(comm.as_raw(), None));
    if create {
        builder.create(path)
    } else {
        builder.open(path)
    }
}

/// Reads rows `rows` of `ds` into `out` (collective).
fn read_column<T: H5Type>(
    ds: &Dataset,
    width: usize,
    rows: Range<usize>,
    out: &mut [T],
) -> hdf5::Result<()> {
    let space = ds.space()?;
    let selected = if width == 0 {
        space.select(rows)?
    } else {
        space.select((rows, ..))?
    };
    ffi::read_collective(ds, &selected, out)
}

/// Collective. Refuses, on every rank, an output `path` that is not a regular file (or absent)
/// or that is the file `input` being read; rank 0 looks, as rank 0 renames.
pub fn check_output(
    comm: &SimpleCommunicator,
    path: &Path,
    input: Option<&Path>,
) -> Result<(), CaseError> {
    let checked = if comm.rank() == 0 {
        destination::check_destination(path, input)
    } else {
        Ok(())
    };
    agree(comm, path, checked)
}

/// The header, this rank's block of particles, its first row and the particle count.
type Block = (CaseHeader, ParticleSet, usize, u64);

fn read_contents(comm: &SimpleCommunicator, file: &File, path: &Path) -> Result<Block, CaseError> {
    let mut header = agree(comm, path, header::read_header(file, path))?;
    let (ds, n, width) = agree(comm, path, datasets::open_all(file, path))?;
    header.state_columns = agree(
        comm,
        path,
        stored_columns(&header, &ds[4], path, "particles"),
    )?;
    let block = same_blocks(&header, n, comm)
        .unwrap_or_else(|| block_range(n, comm.size() as u64, comm.rank() as u64));
    let rows = block.start as usize..block.end as usize;
    let count = rows.len();
    let mut p = ParticleSet {
        gid: vec![0; count],
        position: vec![[0.0; 2]; count],
        displacement: vec![[0.0; 2]; count],
        increment: vec![[0.0; 2]; count],
        h: vec![0.0; count],
        state: crate::material::Rows::zeros(width, count),
        flags: vec![0; count],
        material: vec![0; count],
    };
    let [gid, position, displacement, h, state, flags, increment] = datasets::columns(width);
    let read = (|| {
        read_column(
            &ds[6],
            increment.width,
            rows.clone(),
            p.increment.as_flattened_mut(),
        )?;
        read_column(&ds[0], gid.width, rows.clone(), &mut p.gid)?;
        read_column(
            &ds[1],
            position.width,
            rows.clone(),
            p.position.as_flattened_mut(),
        )?;
        read_column(
            &ds[2],
            displacement.width,
            rows.clone(),
            p.displacement.as_flattened_mut(),
        )?;
        read_column(&ds[3], h.width, rows.clone(), &mut p.h)?;
        read_column(&ds[4], state.width, rows.clone(), p.state.as_flat_mut())?;
        read_column(&ds[5], flags.width, rows, &mut p.flags)
    })()
    .map_err(|e| {
        CaseError::new(
            path,
            CaseErrorKind::Malformed,
            format!("cannot read particles: {e}"),
        )
    });
    agree(comm, path, read)?;
    let first = block.start as usize;
    let sums = [
        (&gid, checksum::verify(comm, &ds[0], first, 0, &p.gid)),
        (
            &position,
            checksum::verify(comm, &ds[1], first, 2, p.position.as_flattened()),
        ),
        (
            &displacement,
            checksum::verify(comm, &ds[2], first, 2, p.displacement.as_flattened()),
        ),
        (&h, checksum::verify(comm, &ds[3], first, 0, &p.h)),
        (
            &state,
            checksum::verify(comm, &ds[4], first, width, p.state.as_flat()),
        ),
        (&flags, checksum::verify(comm, &ds[5], first, 0, &p.flags)),
        (
            &increment,
            checksum::verify(comm, &ds[6], first, 2, p.increment.as_flattened()),
        ),
    ];
    // Every rank has the same outcomes (each checksum is a total over all ranks).
    let material = datasets::material_column();
    let sums = sums.into_iter().chain(
        read_materials(
            comm,
            file,
            path,
            block.start as usize..block.end as usize,
            n,
            &mut p.material,
        )?
        .map(|o| (&material, o)),
    );
    for (c, outcome) in sums {
        outcome.map_err(|m| {
            CaseError::new(path, CaseErrorKind::Malformed, m).at(format!(
                "dataset /{}/{}",
                datasets::GROUP,
                c.name
            ))
        })?;
    }
    Ok((header, p, block.start as usize, n))
}

/// The block this rank wrote, when the file was written by as many ranks as read it.
/// Collective. The optional `/particles/material` rows `rows` of `n` into `out` (left zero
/// without the dataset), and its checksum's outcome.
fn read_materials(
    comm: &SimpleCommunicator,
    file: &File,
    path: &Path,
    rows: Range<usize>,
    n: u64,
    out: &mut [u32],
) -> Result<Option<Result<(), String>>, CaseError> {
    let Ok(ds) = file
        .group(datasets::GROUP)
        .and_then(|g| g.dataset("material"))
    else {
        return Ok(None);
    };
    let bad = |m: String| {
        CaseError::new(path, CaseErrorKind::Malformed, m).at("dataset /particles/material")
    };
    let shape = ds.shape();
    let dtype = ds.dtype().and_then(|t| t.to_descriptor());
    let checked = if shape != [n as usize] {
        Err(bad(format!("expected shape ({n}), found {shape:?}")))
    } else if dtype.as_ref().ok() != Some(&u32::type_descriptor()) {
        Err(bad("expected type u32".to_string()))
    } else {
        Ok(())
    };
    agree(comm, path, checked)?;
    let read = read_column(&ds, 0, rows.clone(), out).map_err(|e| bad(format!("cannot read: {e}")));
    agree(comm, path, read)?;
    Ok(Some(checksum::verify(comm, &ds, rows.start, 0, out)))
}

/// The column names of a state dataset: its `names` attribute, or version 1's fixed nine.
fn stored_columns(
    header: &CaseHeader,
    ds: &Dataset,
    path: &Path,
    group: &str,
) -> Result<Vec<String>, CaseError> {
    let bad = |m: String| {
        CaseError::new(path, CaseErrorKind::Malformed, m).at(format!(
            "attribute {} of dataset /{group}/state",
            state_columns::ATTR
        ))
    };
    match state_columns::stored(ds) {
        Some(names) => names.map_err(|e| bad(format!("unreadable: {e}"))),
        None if header.format_version == 1 => Ok(state_columns::version_1()),
        None => Err(bad("missing".to_string())),
    }
}

/// The state rows of a read block rearranged to the layout of the scene's material
/// (`state_columns::conform`); `header.state_columns` then names the scene's columns. A scene
/// that does not parse is left for the header checks to report.
fn conform_states(
    header: &mut CaseHeader,
    particles: &mut ParticleSet,
    gauss: Option<(&mut GaussRecords, Vec<String>)>,
    path: &Path,
) -> Result<(), CaseError> {
    let Ok(scene) = Scene::from_toml(&header.scene_toml, &path.display().to_string(), &[]) else {
        return Ok(());
    };
    let to = crate::model::state_layout(&scene).columns();
    let fill = header.format_version == 1;
    let at = |group: &str, m: String| {
        CaseError::new(path, CaseErrorKind::Malformed, m).at(format!("dataset /{group}/state"))
    };
    let rows = std::mem::take(&mut particles.state);
    particles.state = state_columns::conform(rows, 1, &header.state_columns, &to, fill)
        .map_err(|m| at("particles", m))?;
    if let Some((g, from)) = gauss {
        let rows = std::mem::take(&mut g.state);
        g.state = state_columns::conform(rows, 3, &from, &to, fill).map_err(|m| at("gauss", m))?;
    }
    header.state_columns = to;
    Ok(())
}

fn same_blocks(header: &CaseHeader, n: u64, comm: &SimpleCommunicator) -> Option<Range<u64>> {
    let counts = &header.rank_counts;
    if counts.len() != comm.size() as usize || counts.iter().sum::<u64>() != n {
        return None;
    }
    let r = comm.rank() as usize;
    let start: u64 = counts[..r].iter().sum();
    Some(start..start + counts[r])
}

/// Collective. [`read_case`] plus a block of the stored Gauss states (empty for a new case),
/// with every rule of [`validate`] checked across all ranks: a case that breaks one is an error
/// naming the dataset or attribute, the same on every rank.
pub fn read_checkpoint(
    comm: &SimpleCommunicator,
    path: &Path,
) -> Result<(CaseHeader, ParticleSet, GaussRecords), CaseError> {
    let (mut header, mut particles, first, n) = read_block(comm, path)?;
    let opened = mpio_file(comm, path, false).map_err(|e| open_error(path, e));
    let file = agree(comm, path, opened)?;
    let records = agree(comm, path, gauss::read(comm, &file, path));
    let gauss_columns = match file.group("gauss").and_then(|g| g.dataset("state")) {
        Ok(ds) => stored_columns(&header, &ds, path, "gauss"),
        Err(_) => Ok(header.state_columns.clone()),
    };
    let gauss_columns = agree(comm, path, gauss_columns);
    let verified = match &records {
        Ok(g) => {
            let (first, _) = pfem_partition::exscan_u64(comm, g.len() as u64);
            gauss::verify(comm, &file, path, g, first as usize)
        }
        Err(_) => Ok(()),
    };
    let closed = file
        .close()
        .map_err(|e| CaseError::new(path, CaseErrorKind::Io, format!("cannot close: {e}")));
    let records = records.and_then(|g| verified.map(|_| g));
    let mut records = agree(comm, path, records.and_then(|g| closed.map(|_| g)))?;
    let conformed = gauss_columns.and_then(|from| {
        conform_states(
            &mut header,
            &mut particles,
            Some((&mut records, from)),
            path,
        )
    });
    agree(comm, path, conformed)?;
    validate_blocks::validate_blocks(comm, path, &header, &particles, first, n, &records)?;
    Ok((header, particles, records))
}

/// Collective. Reads the header on every rank and a contiguous block of the particles on each
/// (`block_range(n, size, rank)`); the file may have been written by any number of ranks. On
/// error every rank returns the same error; a damaged or foreign file is an error, never a
/// panic. Checks the format (types, shapes, lengths), not the contents: [`read_checkpoint`]
/// does both.
pub fn read_case(
    comm: &SimpleCommunicator,
    path: &Path,
) -> Result<(CaseHeader, ParticleSet), CaseError> {
    let (mut h, mut p, _, _) = read_block(comm, path)?;
    let conformed = conform_states(&mut h, &mut p, None, path);
    agree(comm, path, conformed)?;
    Ok((h, p))
}

fn read_block(comm: &SimpleCommunicator, path: &Path) -> Result<Block, CaseError> {
    agree(comm, path, sniff(path))?;
    let opened = mpio_file(comm, path, false).map_err(|e| open_error(path, e));
    let file = agree(comm, path, opened)?;
    let contents = read_contents(comm, &file, path);
    let closed = file
        .close()
        .map_err(|e| CaseError::new(path, CaseErrorKind::Io, format!("cannot close: {e}")));
    let outcome = contents.and_then(|c| closed.map(|_| c));
    agree(comm, path, outcome)
}

/// Human-readable summary of a case file (format, scene, progress, particles, extent), for
/// `pfem-mpi info`. Reads and checks the whole file like a run on one rank does, so a file
/// `info` accepts is one a run accepts. Needs MPI initialised (it reads on MPI_COMM_SELF).
pub fn summarize(path: &Path) -> Result<String, CaseError> {
    sniff(path)?;
    let comm = SimpleCommunicator::self_comm();
    let (header, p, _) = read_checkpoint(&comm, path)?;
    Ok(summary::render(
        path,
        &header,
        p.len() as u64,
        &p.gid,
        &p.position,
        &p.displacement,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene;

    #[test]
    fn cantilever_tracks_the_particle_at_the_loaded_tip() {
        let (scene, resolved) = load_scene("cantilever", &[]).unwrap();
        let (header, particles) = new_case(&scene, "cantilever");
        assert_eq!(header.tracked_gids.len(), 1);
        let gid = header.tracked_gids[0];
        let i = particles.gid.iter().position(|&g| g == gid).unwrap();
        assert_eq!(particles.position[i], [10.0, 0.5]);
        assert_eq!(gid, 4 * 81 + 80);
        assert_eq!(header.next_gid, 729);
        assert_eq!(header.scene_toml, resolved);
        assert_eq!(header.step, 0);
    }

    #[test]
    fn sniff_rejects_non_hdf5_and_missing_files() {
        let dir = std::env::temp_dir().join(format!("pfem-case-sniff-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let text = dir.join("notes.h5");
        std::fs::write(&text, b"just some text, long enough to be read").unwrap();
        let e = sniff(&text).unwrap_err();
        assert_eq!(e.kind, CaseErrorKind::NotHdf5);
        assert_eq!(
            e.to_string(),
            format!("{}: not an HDF5 file", text.display())
        );
        let e = summarize(&text).unwrap_err();
        assert_eq!(e.kind, CaseErrorKind::NotHdf5);
        let e = summarize(&dir.join("absent.h5")).unwrap_err();
        assert_eq!(e.kind, CaseErrorKind::Io);
        assert!(e.to_string().contains("absent.h5: cannot read"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn tmp_path_appends_suffix() {
        assert_eq!(
            tmp_path(Path::new("out/case.h5")),
            PathBuf::from("out/case.h5.tmp")
        );
    }
}
