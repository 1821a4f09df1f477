use super::error::{check, PetscError};
use super::ffi;
use super::index_set::IndexSet;
use super::nullspace::NullSpace;
use super::{Int, Scalar};
use mpi::raw::AsRaw;
use mpi::topology::SimpleCommunicator;
use std::marker::PhantomData;

/// A distributed AIJ matrix we own, preallocated exactly; destroyed on drop.
pub struct Mat {
    pub(crate) raw: ffi::Mat,
}

impl Mat {
    /// Collective. MPIAIJ (SeqAIJ on one rank) with `n_local` owned rows and columns, block size
    /// `block` (rows of one node's displacement come in pairs: AMG then coarsens nodes, not
    /// scalar dofs), and exact per-row counts of nonzeros in the diagonal (`d_nnz`) and
    /// off-diagonal (`o_nnz`) blocks. Only owned rows may be set, and a value outside the
    /// preallocated pattern is an error: both catch a wrong sparsity pattern instead of silently
    /// slowing down.
    pub fn aij(
        comm: &SimpleCommunicator,
        n_local: usize,
        block: usize,
        d_nnz: &[usize],
        o_nnz: &[usize],
    ) -> Result<Mat, PetscError> {
        Mat::aij_rect(comm, [n_local, n_local], block, d_nnz, o_nnz)
    }

    /// Collective. As [`Mat::aij`], with `local[0]` owned rows and `local[1]` owned columns;
    /// rows and columns share the block size.
    pub fn aij_rect(
        comm: &SimpleCommunicator,
        local: [usize; 2],
        block: usize,
        d_nnz: &[usize],
        o_nnz: &[usize],
    ) -> Result<Mat, PetscError> {
        let n_local = local[0];
        assert_eq!(d_nnz.len(), n_local, "one diagonal count per owned row");
        assert_eq!(o_nnz.len(), n_local, "one off-diagonal count per owned row");
        let d_nnz = to_ints(d_nnz, "nonzeros per row")?;
        let o_nnz = to_ints(o_nnz, "nonzeros per row")?;
        let mat = Mat::create(comm, local, "aij")?;
        let raw = mat.raw;
        // SAFETY: live handle; the nnz arrays have n_local entries and are copied by PETSc.
        // The block size must be set before preallocation, which fixes it.
        unsafe {
            check(
                ffi::MatSetBlockSize(raw, to_int(block, "block size")?),
                "MatSetBlockSize",
            )?;
            check(
                ffi::MatSeqAIJSetPreallocation(raw, 0, d_nnz.as_ptr()),
                "MatSeqAIJSetPreallocation",
            )?;
            check(
                ffi::MatMPIAIJSetPreallocation(raw, 0, d_nnz.as_ptr(), 0, o_nnz.as_ptr()),
                "MatMPIAIJSetPreallocation",
            )?;
            strict_assembly(raw)?;
            Ok(mat)
        }
    }

    /// Collective. MPIBAIJ (SeqBAIJ on one rank) with `n_local` owned rows and columns in
    /// blocks of `block`, from the same per-row counts as [`Mat::aij`] (rows of a block must
    /// share their counts). A block's values are stored together under one column index: for
    /// 2 × 2 blocks 9 bytes a nonzero instead of 12, and a faster product. For operators that
    /// are only multiplied and read on the diagonal (PCMG's smoothed fine level); GAMG and the
    /// factorisations want AIJ.
    pub fn baij(
        comm: &SimpleCommunicator,
        n_local: usize,
        block: usize,
        d_nnz: &[usize],
        o_nnz: &[usize],
    ) -> Result<Mat, PetscError> {
        assert_eq!(d_nnz.len(), n_local, "one diagonal count per owned row");
        assert_eq!(o_nnz.len(), n_local, "one off-diagonal count per owned row");
        assert_eq!(n_local % block, 0, "whole blocks of rows");
        let blocks = |v: &[usize]| {
            v.chunks(block)
                .map(|c| {
                    debug_assert!(c.iter().all(|&k| k == c[0]), "a block's rows share counts");
                    to_int(c[0].div_ceil(block), "blocks per row")
                })
                .collect::<Result<Vec<Int>, _>>()
        };
        Mat::blocked(
            comm,
            n_local,
            block,
            [blocks(d_nnz)?, blocks(o_nnz)?],
            false,
        )
    }

    /// Collective. MPISBAIJ (SeqSBAIJ on one rank), a symmetric matrix of which only the upper
    /// triangle is stored, in 2 × 2 blocks, with `n_local` owned rows and columns and, per owned
    /// block row, `d_blocks` blocks in the owned columns on or right of the diagonal and
    /// `o_blocks` in other ranks' columns right of it. Entries left of the diagonal are ignored
    /// on insertion, so a caller adds whole element matrices. Half the memory of BAIJ, for
    /// symmetric operators that are only multiplied and read on the diagonal.
    pub fn sbaij(
        comm: &SimpleCommunicator,
        n_local: usize,
        d_blocks: &[usize],
        o_blocks: &[usize],
    ) -> Result<Mat, PetscError> {
        const BS: usize = 2;
        assert_eq!(n_local % BS, 0, "whole blocks of rows");
        assert_eq!(
            d_blocks.len(),
            n_local / BS,
            "one count per owned block row"
        );
        assert_eq!(
            o_blocks.len(),
            n_local / BS,
            "one count per owned block row"
        );
        let blocks = [
            to_ints(d_blocks, "blocks per row")?,
            to_ints(o_blocks, "blocks per row")?,
        ];
        Mat::blocked(comm, n_local, BS, blocks, true)
    }

    /// Collective. BAIJ, or SBAIJ (upper triangle only, the lower ignored on insertion) if
    /// `symmetric`, with per block row `blocks[0]` blocks in owned columns and `blocks[1]` in
    /// other ranks' columns.
    fn blocked(
        comm: &SimpleCommunicator,
        n_local: usize,
        block: usize,
        blocks: [Vec<Int>; 2],
        symmetric: bool,
    ) -> Result<Mat, PetscError> {
        let [d_nnz, o_nnz] = blocks;
        let bs = to_int(block, "block size")?;
        let kind = if symmetric { "sbaij" } else { "baij" };
        let mat = Mat::create(comm, [n_local, n_local], kind)?;
        let raw = mat.raw;
        // SAFETY: live handle; the block counts have n_local / block entries and are copied
        // by PETSc.
        unsafe {
            let (seq, mpi, names) = if symmetric {
                (
                    ffi::MatSeqSBAIJSetPreallocation as SeqPreallocation,
                    ffi::MatMPISBAIJSetPreallocation as MpiPreallocation,
                    ["MatSeqSBAIJSetPreallocation", "MatMPISBAIJSetPreallocation"],
                )
            } else {
                (
                    ffi::MatSeqBAIJSetPreallocation as SeqPreallocation,
                    ffi::MatMPIBAIJSetPreallocation as MpiPreallocation,
                    ["MatSeqBAIJSetPreallocation", "MatMPIBAIJSetPreallocation"],
                )
            };
            // Each applies only to its own matrix type (Seq on one rank, MPI on several).
            check(seq(raw, bs, 0, d_nnz.as_ptr()), names[0])?;
            check(mpi(raw, bs, 0, d_nnz.as_ptr(), 0, o_nnz.as_ptr()), names[1])?;
            strict_assembly(raw)?;
            if symmetric {
                check(
                    ffi::MatSetOption(
                        raw,
                        ffi::MatOption_MAT_IGNORE_LOWER_TRIANGULAR,
                        ffi::PetscBool_PETSC_TRUE,
                    ),
                    "MatSetOption(MAT_IGNORE_LOWER_TRIANGULAR)",
                )?;
            }
            Ok(mat)
        }
    }

    /// Collective. An empty matrix of type `kind` with `local[0]` owned rows and `local[1]`
    /// owned columns.
    fn create(comm: &SimpleCommunicator, local: [usize; 2], kind: &str) -> Result<Mat, PetscError> {
        let n = to_int(local[0], "matrix rows")?;
        let m = to_int(local[1], "matrix columns")?;
        let det = ffi::PETSC_DETERMINE as Int;
        let kind = super::init::cstring(kind)?;
        let mut raw: ffi::Mat = std::ptr::null_mut();
        // SAFETY: out-pointer to a fresh handle, owned by `mat` from the next line on.
        unsafe {
            check(ffi::MatCreate(comm.as_raw(), &mut raw), "MatCreate")?;
            let mat = Mat { raw };
            check(ffi::MatSetSizes(raw, n, m, det, det), "MatSetSizes")?;
            check(ffi::MatSetType(raw, kind.as_ptr()), "MatSetType")?;
            Ok(mat)
        }
    }

    pub fn as_ref(&self) -> MatRef<'_> {
        MatRef {
            raw: self.raw,
            _owner: PhantomData,
        }
    }

    /// Collective. The vectors an algebraic multigrid should interpolate exactly (the rigid-body
    /// modes of elasticity); PETSc keeps its own reference.
    pub fn set_near_null_space(&self, space: &NullSpace) -> Result<(), PetscError> {
        // SAFETY: both handles are live.
        check(
            unsafe { ffi::MatSetNearNullSpace(self.raw, space.raw) },
            "MatSetNearNullSpace",
        )
    }

    /// Collective. The product `self * x` into `y`.
    pub fn mult(&self, x: super::VecRef, y: super::VecRef) -> Result<(), PetscError> {
        self.as_ref().mult(x, y)
    }

    /// Collective. The rows and columns `is` of this matrix (a block of a block system).
    pub fn sub_matrix(&self, is: &IndexSet) -> Result<Mat, PetscError> {
        self.as_ref().sub_matrix(is)
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

/// Only owned rows may be set, and a value outside the preallocated pattern is an error.
///
/// # Safety
/// `raw` must be a live matrix.
unsafe fn strict_assembly(raw: ffi::Mat) -> Result<(), PetscError> {
    for (option, name) in [
        (
            ffi::MatOption_MAT_NO_OFF_PROC_ENTRIES,
            "MatSetOption(MAT_NO_OFF_PROC_ENTRIES)",
        ),
        (
            ffi::MatOption_MAT_NEW_NONZERO_ALLOCATION_ERR,
            "MatSetOption(MAT_NEW_NONZERO_ALLOCATION_ERR)",
        ),
    ] {
        // SAFETY: live matrix (the caller's promise).
        check(
            unsafe { ffi::MatSetOption(raw, option, ffi::PetscBool_PETSC_TRUE) },
            name,
        )?;
    }
    Ok(())
}

/// A matrix borrowed for `'a`: from a `Mat` we own, or lent by PETSc for the length of a
/// callback. The lifetime keeps the handle from outliving its owner.
#[derive(Clone, Copy)]
pub struct MatRef<'a> {
    pub(crate) raw: ffi::Mat,
    _owner: PhantomData<&'a ()>,
}

impl MatRef<'_> {
    /// A handle PETSc lends to a callback.
    ///
    /// # Safety
    /// `raw` must be a live matrix for as long as the returned borrow is used; callbacks pass
    /// it on only to code that cannot keep it (the borrow's lifetime ends with the callback).
    pub(crate) unsafe fn lent<'a>(raw: ffi::Mat) -> MatRef<'a> {
        MatRef {
            raw,
            _owner: PhantomData,
        }
    }

    /// A reference of our own to this matrix, which keeps it alive.
    pub fn shared(&self) -> Result<Mat, PetscError> {
        // SAFETY: live matrix.
        check(
            unsafe { ffi::PetscObjectReference(self.raw as ffi::PetscObject) },
            "PetscObjectReference",
        )?;
        Ok(Mat { raw: self.raw })
    }

    /// Collective. y = A x.
    pub fn mult(&self, x: super::VecRef<'_>, y: super::VecRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles with matching layouts (PETSc checks the sizes).
        check(unsafe { ffi::MatMult(self.raw, x.raw, y.raw) }, "MatMult")
    }

    /// Collective. x = Aᵀ y.
    pub fn mult_transpose(
        &self,
        y: super::VecRef<'_>,
        x: super::VecRef<'_>,
    ) -> Result<(), PetscError> {
        // SAFETY: live handles with matching layouts.
        check(
            unsafe { ffi::MatMultTranspose(self.raw, y.raw, x.raw) },
            "MatMultTranspose",
        )
    }

    /// Collective. z = y + A x (z may be y).
    pub fn mult_add(
        &self,
        x: super::VecRef<'_>,
        y: super::VecRef<'_>,
        z: super::VecRef<'_>,
    ) -> Result<(), PetscError> {
        // SAFETY: live handles with matching layouts.
        check(
            unsafe { ffi::MatMultAdd(self.raw, x.raw, y.raw, z.raw) },
            "MatMultAdd",
        )
    }

    /// The diagonal into `d`.
    pub fn diagonal(&self, d: super::VecRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles.
        check(
            unsafe { ffi::MatGetDiagonal(self.raw, d.raw) },
            "MatGetDiagonal",
        )
    }

    /// Collective. New vectors of the column layout and of the row layout.
    pub fn vectors(&self) -> Result<(super::PVec, super::PVec), PetscError> {
        let (mut right, mut left): (ffi::Vec, ffi::Vec) =
            (std::ptr::null_mut(), std::ptr::null_mut());
        // SAFETY: live matrix; both vectors are ours.
        check(
            unsafe { ffi::MatCreateVecs(self.raw, &mut right, &mut left) },
            "MatCreateVecs",
        )?;
        Ok((super::PVec { raw: right }, super::PVec { raw: left }))
    }

    /// Collective. A new vector of the column layout.
    pub fn right_vector(&self) -> Result<super::PVec, PetscError> {
        let mut right: ffi::Vec = std::ptr::null_mut();
        // SAFETY: live matrix; the vector is ours.
        check(
            unsafe { ffi::MatCreateVecs(self.raw, &mut right, std::ptr::null_mut()) },
            "MatCreateVecs",
        )?;
        Ok(super::PVec { raw: right })
    }

    /// Global rows.
    pub fn global_rows(&self) -> Result<Int, PetscError> {
        let mut rows: Int = 0;
        // SAFETY: live matrix.
        check(
            unsafe { ffi::MatGetSize(self.raw, &mut rows, std::ptr::null_mut()) },
            "MatGetSize",
        )?;
        Ok(rows)
    }

    /// Collective. The rows and columns `is` of this matrix.
    pub fn sub_matrix(&self, is: &IndexSet) -> Result<Mat, PetscError> {
        let mut raw: ffi::Mat = std::ptr::null_mut();
        // SAFETY: live handles; the new matrix is ours.
        check(
            unsafe {
                ffi::MatCreateSubMatrix(
                    self.raw,
                    is.raw,
                    is.raw,
                    ffi::MatReuse_MAT_INITIAL_MATRIX,
                    &mut raw,
                )
            },
            "MatCreateSubMatrix",
        )?;
        Ok(Mat { raw })
    }

    /// Collective. Drops the near-null space.
    pub fn clear_near_null_space(&self) -> Result<(), PetscError> {
        // SAFETY: live matrix.
        check(
            unsafe { ffi::MatSetNearNullSpace(self.raw, std::ptr::null_mut()) },
            "MatSetNearNullSpace",
        )
    }

    pub fn zero_entries(&self) -> Result<(), PetscError> {
        // SAFETY: live matrix.
        check(unsafe { ffi::MatZeroEntries(self.raw) }, "MatZeroEntries")
    }

    /// Adds a dense block `vals` (row-major, rows.len() x cols.len()) at global `rows` x `cols`.
    pub fn add_values(
        &self,
        rows: &[Int],
        cols: &[Int],
        vals: &[Scalar],
    ) -> Result<(), PetscError> {
        assert_eq!(
            vals.len(),
            rows.len() * cols.len(),
            "a dense block of values"
        );
        self.add_with(ffi::MatSetValues, "MatSetValues", rows, cols, vals)
    }

    /// Adds a dense block `vals` (row-major, 2 rows.len() x 2 cols.len()) at the 2 × 2 blocks
    /// `rows` x `cols` (block indices) of a matrix with block size 2: one search per block
    /// instead of one per entry.
    pub fn add_blocks(
        &self,
        rows: &[Int],
        cols: &[Int],
        vals: &[Scalar],
    ) -> Result<(), PetscError> {
        assert_eq!(
            vals.len(),
            4 * rows.len() * cols.len(),
            "a dense block of 2 x 2 blocks"
        );
        self.add_with(
            ffi::MatSetValuesBlocked,
            "MatSetValuesBlocked",
            rows,
            cols,
            vals,
        )
    }

    /// Adds `vals` at `rows` x `cols` through PETSc's point or blocked insertion `set`.
    fn add_with(
        &self,
        set: SetValues,
        name: &str,
        rows: &[Int],
        cols: &[Int],
        vals: &[Scalar],
    ) -> Result<(), PetscError> {
        // SAFETY: the callers checked that `vals` holds the dense block `rows` x `cols` names;
        // PETSc copies the values.
        check(
            unsafe {
                set(
                    self.raw,
                    to_int(rows.len(), "rows")?,
                    rows.as_ptr(),
                    to_int(cols.len(), "columns")?,
                    cols.as_ptr(),
                    vals.as_ptr(),
                    ffi::InsertMode_ADD_VALUES,
                )
            },
            name,
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

/// PETSc's Mat(Seq)(S)BAIJSetPreallocation: block size, default and per-row block counts.
type SeqPreallocation = unsafe extern "C" fn(ffi::Mat, Int, Int, *const Int) -> ffi::PetscErrorCode;
/// PETSc's MatMPI(S)BAIJSetPreallocation: block size, diagonal and off-diagonal block counts.
type MpiPreallocation =
    unsafe extern "C" fn(ffi::Mat, Int, Int, *const Int, Int, *const Int) -> ffi::PetscErrorCode;

/// PETSc's MatSetValues and MatSetValuesBlocked.
type SetValues = unsafe extern "C" fn(
    ffi::Mat,
    Int,
    *const Int,
    Int,
    *const Int,
    *const Scalar,
    ffi::InsertMode,
) -> ffi::PetscErrorCode;

/// Counts or indices as PETSc's integers (see [`to_int`]).
pub fn to_ints(v: &[usize], what: &str) -> Result<Vec<Int>, PetscError> {
    v.iter().map(|&k| to_int(k, what)).collect()
}

/// A count or index as PETSc's integer, or an error when it does not fit (a 32-bit PETSc build
/// and more than 2^31 unknowns).
pub fn to_int(v: usize, what: &str) -> Result<Int, PetscError> {
    Int::try_from(v).map_err(|_| PetscError {
        code: -1,
        message: format!(
            "{what}: {v} does not fit PETSc's {}-bit integer (PetscInt)",
            8 * std::mem::size_of::<Int>()
        ),
    })
}
