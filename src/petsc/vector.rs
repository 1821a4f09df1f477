use super::error::{check, PetscError};
use super::ffi;
use super::{Int, Scalar};
use mpi::raw::AsRaw;
use mpi::topology::SimpleCommunicator;
use std::marker::PhantomData;

/// A PETSc vector we own; destroyed on drop.
pub struct PVec {
    pub(crate) raw: ffi::Vec,
}

/// A vector borrowed for `'a`: from a `PVec` we own, or lent by PETSc for the length of a
/// callback; never destroyed through this handle, and the lifetime keeps it from outliving its
/// owner.
#[derive(Clone, Copy)]
pub struct VecRef<'a> {
    pub(crate) raw: ffi::Vec,
    _owner: PhantomData<&'a ()>,
}

impl PVec {
    /// Collective. Distributed vector with `n_local` entries on this rank.
    pub fn mpi(comm: &SimpleCommunicator, n_local: usize) -> Result<PVec, PetscError> {
        let mut raw: ffi::Vec = std::ptr::null_mut();
        // SAFETY: out-pointer to a fresh handle.
        check(
            unsafe {
                ffi::VecCreateMPI(
                    comm.as_raw(),
                    super::matrix::to_int(n_local, "vector length")?,
                    ffi::PETSC_DETERMINE as Int,
                    &mut raw,
                )
            },
            "VecCreateMPI",
        )?;
        Ok(PVec { raw })
    }

    /// Sequential vector of length `n` on this rank alone.
    pub fn seq(n: usize) -> Result<PVec, PetscError> {
        let mut raw: ffi::Vec = std::ptr::null_mut();
        // SAFETY: out-pointer to a fresh handle; PETSC_COMM_SELF is MPI_COMM_SELF.
        check(
            unsafe {
                ffi::VecCreateSeq(
                    mpi::ffi::RSMPI_COMM_SELF,
                    super::matrix::to_int(n, "vector length")?,
                    &mut raw,
                )
            },
            "VecCreateSeq",
        )?;
        Ok(PVec { raw })
    }

    /// Collective. Same layout, uninitialised values.
    pub fn duplicate(&self) -> Result<PVec, PetscError> {
        self.as_ref().duplicate()
    }

    pub fn as_ref(&self) -> VecRef<'_> {
        VecRef {
            raw: self.raw,
            _owner: PhantomData,
        }
    }
}

impl Drop for PVec {
    fn drop(&mut self) {
        // SAFETY: we own the handle; VecDestroy nulls it.
        unsafe {
            ffi::VecDestroy(&mut self.raw);
        }
    }
}

impl VecRef<'_> {
    /// A handle PETSc lends to a callback.
    ///
    /// # Safety
    /// `raw` must be a live vector for as long as the returned borrow is used.
    pub(crate) unsafe fn lent<'a>(raw: ffi::Vec) -> VecRef<'a> {
        VecRef {
            raw,
            _owner: PhantomData,
        }
    }

    /// Collective. A new vector of the same layout, uninitialised values.
    pub fn duplicate(&self) -> Result<PVec, PetscError> {
        let mut raw: ffi::Vec = std::ptr::null_mut();
        // SAFETY: self.raw is a live vector.
        check(
            unsafe { ffi::VecDuplicate(self.raw, &mut raw) },
            "VecDuplicate",
        )?;
        Ok(PVec { raw })
    }

    /// The locally owned entries, read-only.
    pub fn read<R>(&self, f: impl FnOnce(&[Scalar]) -> R) -> Result<R, PetscError> {
        let n = self.local_size()?;
        let mut ptr: *const Scalar = std::ptr::null();
        // SAFETY: PETSc hands out the local array until the matching restore call.
        check(
            unsafe { ffi::VecGetArrayRead(self.raw, &mut ptr) },
            "VecGetArrayRead",
        )?;
        let slice = if n == 0 {
            &[][..]
        } else {
            unsafe { std::slice::from_raw_parts(ptr, n) }
        };
        let out = f(slice);
        check(
            unsafe { ffi::VecRestoreArrayRead(self.raw, &mut ptr) },
            "VecRestoreArrayRead",
        )?;
        Ok(out)
    }

    /// The locally owned entries, writable.
    pub fn write<R>(&self, f: impl FnOnce(&mut [Scalar]) -> R) -> Result<R, PetscError> {
        let n = self.local_size()?;
        let mut ptr: *mut Scalar = std::ptr::null_mut();
        // SAFETY: as in `read`; no other borrow of this array exists while `f` runs.
        check(
            unsafe { ffi::VecGetArray(self.raw, &mut ptr) },
            "VecGetArray",
        )?;
        let slice = if n == 0 {
            &mut [][..]
        } else {
            unsafe { std::slice::from_raw_parts_mut(ptr, n) }
        };
        let out = f(slice);
        check(
            unsafe { ffi::VecRestoreArray(self.raw, &mut ptr) },
            "VecRestoreArray",
        )?;
        Ok(out)
    }

    pub fn local_size(&self) -> Result<usize, PetscError> {
        let mut n: Int = 0;
        // SAFETY: live vector.
        check(
            unsafe { ffi::VecGetLocalSize(self.raw, &mut n) },
            "VecGetLocalSize",
        )?;
        usize::try_from(n).map_err(|_| PetscError {
            code: -1,
            message: format!("VecGetLocalSize: negative size {n}"),
        })
    }
}

impl VecRef<'_> {
    /// A reference of our own to this vector, which keeps it alive.
    pub fn shared(&self) -> Result<PVec, PetscError> {
        // SAFETY: live vector.
        check(
            unsafe { ffi::PetscObjectReference(self.raw as ffi::PetscObject) },
            "PetscObjectReference",
        )?;
        Ok(PVec { raw: self.raw })
    }

    /// Collective. self = a ∘ b, entry by entry (self may be a or b).
    pub fn pointwise_mult(&self, a: VecRef<'_>, b: VecRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live vectors of one layout (PETSc checks).
        check(
            unsafe { ffi::VecPointwiseMult(self.raw, a.raw, b.raw) },
            "VecPointwiseMult",
        )
    }

    /// self = alpha self.
    pub fn scale(&self, alpha: Scalar) -> Result<(), PetscError> {
        // SAFETY: live vector.
        check(unsafe { ffi::VecScale(self.raw, alpha) }, "VecScale")
    }

    /// self = x + alpha self.
    pub fn aypx(&self, alpha: Scalar, x: VecRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live vectors of one layout.
        check(unsafe { ffi::VecAYPX(self.raw, alpha, x.raw) }, "VecAYPX")
    }

    /// self = self + alpha x.
    pub fn axpy(&self, alpha: Scalar, x: VecRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live vectors of one layout.
        check(unsafe { ffi::VecAXPY(self.raw, alpha, x.raw) }, "VecAXPY")
    }

    /// Every entry inverted; a zero entry stays zero.
    pub fn reciprocal(&self) -> Result<(), PetscError> {
        // SAFETY: live vector.
        check(unsafe { ffi::VecReciprocal(self.raw) }, "VecReciprocal")
    }

    /// self = x.
    pub fn copy_from(&self, x: VecRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live vectors of one layout.
        check(unsafe { ffi::VecCopy(x.raw, self.raw) }, "VecCopy")
    }

    /// Every entry `value`.
    pub fn set_all(&self, value: Scalar) -> Result<(), PetscError> {
        // SAFETY: live vector.
        check(unsafe { ffi::VecSet(self.raw, value) }, "VecSet")
    }

    /// Collective. Adds `values` at the global entries `indices` (any rank's) and assembles.
    pub fn add_at(&self, indices: &[Int], values: &[Scalar]) -> Result<(), PetscError> {
        assert_eq!(indices.len(), values.len(), "one value per index");
        let n = super::matrix::to_int(indices.len(), "entries")?;
        // SAFETY: live vector; the arrays are valid for `n` entries and copied.
        unsafe {
            check(
                ffi::VecSetValues(
                    self.raw,
                    n,
                    indices.as_ptr(),
                    values.as_ptr(),
                    ffi::InsertMode_ADD_VALUES,
                ),
                "VecSetValues",
            )?;
            check(ffi::VecAssemblyBegin(self.raw), "VecAssemblyBegin")?;
            check(ffi::VecAssemblyEnd(self.raw), "VecAssemblyEnd")
        }
    }

    /// The global index of this rank's first entry.
    pub fn first_owned(&self) -> Result<Int, PetscError> {
        let (mut first, mut end): (Int, Int) = (0, 0);
        // SAFETY: live vector.
        check(
            unsafe { ffi::VecGetOwnershipRange(self.raw, &mut first, &mut end) },
            "VecGetOwnershipRange",
        )?;
        Ok(first)
    }

    /// Collective. Runs `f` on the entries `is` of this vector, as a vector of their own
    /// (PETSc's sub-vector, restored after).
    pub fn with_sub_vector<R>(
        &self,
        is: &super::IndexSet,
        f: impl FnOnce(VecRef<'_>) -> Result<R, PetscError>,
    ) -> Result<R, PetscError> {
        let mut sub: ffi::Vec = std::ptr::null_mut();
        // SAFETY: live handles; the sub-vector lives until restored, after `f`.
        unsafe {
            check(
                ffi::VecGetSubVector(self.raw, is.raw, &mut sub),
                "VecGetSubVector",
            )?;
            let out = f(VecRef::lent(sub));
            check(
                ffi::VecRestoreSubVector(self.raw, is.raw, &mut sub),
                "VecRestoreSubVector",
            )?;
            out
        }
    }
}
