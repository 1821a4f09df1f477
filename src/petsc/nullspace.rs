use super::error::{check, PetscError};
use super::ffi;
use super::vector::PVec;
use super::Scalar;
use mpi::raw::AsRaw;
use mpi::topology::SimpleCommunicator;

/// A (near-)null space: vectors an operator maps to (almost) zero; destroyed on drop.
pub struct NullSpace {
    pub(crate) raw: ffi::MatNullSpace,
}

impl NullSpace {
    /// Collective. The span of `vectors`, each this rank's `n_local` owned entries of a
    /// distributed vector; they must be orthonormal (PETSc relies on it to project).
    pub fn new(
        comm: &SimpleCommunicator,
        n_local: usize,
        vectors: &[Vec<Scalar>],
    ) -> Result<NullSpace, PetscError> {
        let mut owned = Vec::with_capacity(vectors.len());
        for v in vectors {
            assert_eq!(v.len(), n_local, "one entry per owned row");
            let p = PVec::mpi(comm, n_local)?;
            p.as_ref().write(|a| a.copy_from_slice(v))?;
            owned.push(p);
        }
        let mut raws: Vec<ffi::Vec> = owned.iter().map(|p| p.raw).collect();
        let mut raw: ffi::MatNullSpace = std::ptr::null_mut();
        // SAFETY: the vectors are live; PETSc takes its own references, so ours are released
        // when `owned` drops.
        check(
            unsafe {
                ffi::MatNullSpaceCreate(
                    comm.as_raw(),
                    ffi::PetscBool_PETSC_FALSE,
                    super::matrix::to_int(raws.len(), "null space vectors")?,
                    raws.as_mut_ptr(),
                    &mut raw,
                )
            },
            "MatNullSpaceCreate",
        )?;
        Ok(NullSpace { raw })
    }
}

impl Drop for NullSpace {
    fn drop(&mut self) {
        // SAFETY: we own the handle.
        unsafe {
            ffi::MatNullSpaceDestroy(&mut self.raw);
        }
    }
}
