use super::error::{check, PetscError};
use super::ffi;
use mpi::raw::AsRaw;
use mpi::topology::SimpleCommunicator;

/// A distributed AIJ matrix we own, preallocated exactly; destroyed on drop.
pub struct Mat {
    pub(crate) raw: ffi::Mat,
}

impl Mat {
    /// Collective. MPIAIJ (SeqAIJ on one rank) with `n_local` owned rows and columns and exact
    /// per-row counts of nonzeros in the diagonal (`d_nnz`) and off-diagonal (`o_nnz`) blocks.
    /// Only owned rows may be set, and a value outside the preallocated pattern is an error: both
    /// catch a wrong sparsity pattern instead of silently slowing down.
    pub fn aij(
        comm: &SimpleCommunicator,
        n_local: usize,
        d_nnz: &[i32],
        o_nnz: &[i32],
    ) -> Result<Mat, PetscError> {
        let mut raw: ffi::Mat = std::ptr::null_mut();
        let n = n_local as ffi::PetscInt;
        let det = ffi::PETSC_DETERMINE as ffi::PetscInt;
        // SAFETY: nnz arrays have n_local entries and are copied by PETSc.
        unsafe {
            check(
                ffi::MatCreateAIJ(
                    comm.as_raw(),
                    n,
                    n,
                    det,
                    det,
                    0,
                    d_nnz.as_ptr(),
                    0,
                    o_nnz.as_ptr(),
                    &mut raw,
                ),
                "MatCreateAIJ",
            )?;
            let mat = Mat { raw };
            check(
                ffi::MatSetOption(
                    mat.raw,
                    ffi::MatOption_MAT_NO_OFF_PROC_ENTRIES,
                    ffi::PetscBool_PETSC_TRUE,
                ),
                "MatSetOption(MAT_NO_OFF_PROC_ENTRIES)",
            )?;
            check(
                ffi::MatSetOption(
                    mat.raw,
                    ffi::MatOption_MAT_NEW_NONZERO_ALLOCATION_ERR,
                    ffi::PetscBool_PETSC_TRUE,
                ),
                "MatSetOption(MAT_NEW_NONZERO_ALLOCATION_ERR)",
            )?;
            Ok(mat)
        }
    }

    pub fn as_ref(&self) -> MatRef {
        MatRef { raw: self.raw }
    }
}

impl Drop for Mat {
    fn drop(&mut self) {
        // SAFETY: we own the handle.
        unsafe {
            ffi::MatDestroy(&mut self.raw);
        }
    }
}

/// A matrix lent to us by PETSc inside a Jacobian callback.
#[derive(Clone, Copy)]
pub struct MatRef {
    pub(crate) raw: ffi::Mat,
}

impl MatRef {
    pub fn zero_entries(&self) -> Result<(), PetscError> {
        // SAFETY: live matrix.
        check(unsafe { ffi::MatZeroEntries(self.raw) }, "MatZeroEntries")
    }

    /// Adds a dense block `vals` (row-major, rows.len() x cols.len()) at global `rows` x `cols`.
    pub fn add_values(&self, rows: &[i32], cols: &[i32], vals: &[f64]) -> Result<(), PetscError> {
        debug_assert_eq!(vals.len(), rows.len() * cols.len());
        // SAFETY: slices are valid for the stated lengths; PETSc copies the values.
        check(
            unsafe {
                ffi::MatSetValues(
                    self.raw,
                    rows.len() as ffi::PetscInt,
                    rows.as_ptr(),
                    cols.len() as ffi::PetscInt,
                    cols.as_ptr(),
                    vals.as_ptr(),
                    ffi::InsertMode_ADD_VALUES,
                )
            },
            "MatSetValues",
        )
    }

    /// Collective. Final assembly.
    pub fn assemble(&self) -> Result<(), PetscError> {
        // SAFETY: live matrix.
        unsafe {
            check(
                ffi::MatAssemblyBegin(self.raw, ffi::MatAssemblyType_MAT_FINAL_ASSEMBLY),
                "MatAssemblyBegin",
            )?;
            check(
                ffi::MatAssemblyEnd(self.raw, ffi::MatAssemblyType_MAT_FINAL_ASSEMBLY),
                "MatAssemblyEnd",
            )
        }
    }
}
