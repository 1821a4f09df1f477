//! Domain decomposition for pfem-mpi.
//!
//! This crate moves plain data between MPI ranks by global id: it decides who owns which item
//! (METIS k-way on a gathered graph), moves items to their new owners, builds geometric halos
//! and exchanges fixed-stride records over them. It deliberately knows nothing about what the
//! records mean.
//!
//! Every function documented as "Collective." must be called by all ranks of the communicator,
//! in the same order, including ranks that hold no items. Collective functions that return a
//! `Result` return the *same* error on every rank (see [`PartitionError::OnRank`]), so a caller
//! can bail out everywhere without deadlocking the others.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub use mpi;

/// The communicator type used throughout the crate (MPI_COMM_WORLD or a duplicate of it).
pub type Comm = mpi::topology::SimpleCommunicator;

pub mod comm;
mod error;
mod geom;
pub mod halo;
pub mod metis_part;
pub mod migrate;
pub mod reduce;

pub use comm::{
    abort_job_on_panic, agree_on_error, agree_on_error_or_abort, alltoallv, exscan_u64, fetch,
    gather_to_root,
};
pub use error::PartitionError;
pub use halo::Halo;
pub use metis_part::{imbalance, partition_graph};
pub use migrate::{block_range, migrate, try_migrate, Items};
pub use reduce::{allgather_u64, fetch_pairs, locate, max_f64, sum_f64};
