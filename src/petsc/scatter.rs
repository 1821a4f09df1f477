use super::error::{check, PetscError};
use super::ffi;
use super::vector::{PVec, VecRef};

/// Gathers chosen global entries of a distributed vector into a sequential local vector: the
/// ghost values one rank's elements need (owned values are read from the vector in place).
pub struct Scatter {
    raw: ffi::VecScatter,
    local: PVec,
}

impl Scatter {
    /// Collective. `global_indices[i]` of `template`'s layout lands in local entry i.
    pub fn new(template: &PVec, global_indices: &[usize]) -> Result<Scatter, PetscError> {
        let local = PVec::seq(global_indices.len())?;
        let from = global_indices
            .iter()
            .map(|&g| super::matrix::to_int(g, "scatter index"))
            .collect::<Result<Vec<_>, _>>()?;
        let mut is_from: ffi::IS = std::ptr::null_mut();
        let mut raw: ffi::VecScatter = std::ptr::null_mut();
        // SAFETY: the index array is copied by PETSc (PETSC_COPY_VALUES); IS destroyed right after use.
        unsafe {
            check(
                ffi::ISCreateGeneral(
                    mpi::ffi::RSMPI_COMM_SELF,
                    super::matrix::to_int(from.len(), "scatter length")?,
                    from.as_ptr(),
                    ffi::PetscCopyMode_PETSC_COPY_VALUES,
                    &mut is_from,
                ),
                "ISCreateGeneral",
            )?;
            let made = check(
                ffi::VecScatterCreate(
                    template.raw,
                    is_from,
                    local.raw,
                    std::ptr::null_mut(),
                    &mut raw,
                ),
                "VecScatterCreate",
            );
            ffi::ISDestroy(&mut is_from);
            made?;
        }
        Ok(Scatter { raw, local })
    }

    /// Collective. Fetches the values and hands them to `f`.
    pub fn gather<R>(
        &self,
        from: VecRef<'_>,
        f: impl FnOnce(&[super::Scalar]) -> R,
    ) -> Result<R, PetscError> {
        // SAFETY: both vectors are live and match the layouts the scatter was built for.
        unsafe {
            check(
                ffi::VecScatterBegin(
                    self.raw,
                    from.raw,
                    self.local.raw,
                    ffi::InsertMode_INSERT_VALUES,
                    ffi::ScatterMode_SCATTER_FORWARD,
                ),
                "VecScatterBegin",
            )?;
            check(
                ffi::VecScatterEnd(
                    self.raw,
                    from.raw,
                    self.local.raw,
                    ffi::InsertMode_INSERT_VALUES,
                    ffi::ScatterMode_SCATTER_FORWARD,
                ),
                "VecScatterEnd",
            )?;
        }
        self.local.as_ref().read(f)
    }

    /// Collective. The reverse of [`Self::gather`]: `f` fills one value per local entry, which
    /// is added to its global entry of `into` (several ranks may add to one entry).
    pub fn add_back(
        &self,
        into: VecRef<'_>,
        f: impl FnOnce(&mut [super::Scalar]) -> Result<(), PetscError>,
    ) -> Result<(), PetscError> {
        self.local.as_ref().write(f)??;
        // SAFETY: both vectors are live and match the layouts the scatter was built for.
        unsafe {
            check(
                ffi::VecScatterBegin(
                    self.raw,
                    self.local.raw,
                    into.raw,
                    ffi::InsertMode_ADD_VALUES,
                    ffi::ScatterMode_SCATTER_REVERSE,
                ),
                "VecScatterBegin",
            )?;
            check(
                ffi::VecScatterEnd(
                    self.raw,
                    self.local.raw,
                    into.raw,
                    ffi::InsertMode_ADD_VALUES,
                    ffi::ScatterMode_SCATTER_REVERSE,
                ),
                "VecScatterEnd",
            )
        }
    }
}

impl Drop for Scatter {
    fn drop(&mut self) {
        // SAFETY: we own the scatter.
        unsafe {
            ffi::VecScatterDestroy(&mut self.raw);
        }
    }
}

/// Moves the entries `is` of a distributed vector to every entry of another (made for them)
/// and back: made once, applied many times (a sub-vector of an arbitrary index set would
/// build its scatter at every use).
pub struct IndexScatter {
    raw: ffi::VecScatter,
}

impl IndexScatter {
    /// Collective. From the entries `is` of vectors laid out as `from` to vectors laid out as
    /// `to`.
    pub fn new(
        from: VecRef<'_>,
        is: &super::IndexSet,
        to: VecRef<'_>,
    ) -> Result<IndexScatter, PetscError> {
        let mut raw: ffi::VecScatter = std::ptr::null_mut();
        // SAFETY: live handles; the scatter is ours.
        check(
            unsafe {
                ffi::VecScatterCreate(from.raw, is.raw, to.raw, std::ptr::null_mut(), &mut raw)
            },
            "VecScatterCreate",
        )?;
        Ok(IndexScatter { raw })
    }

    /// Collective. to = from[is].
    pub fn forward(&self, from: VecRef<'_>, to: VecRef<'_>) -> Result<(), PetscError> {
        self.run(
            from,
            to,
            ffi::InsertMode_INSERT_VALUES,
            ffi::ScatterMode_SCATTER_FORWARD,
        )
    }

    /// Collective. into[is] = from, or into[is] += from with `add`.
    pub fn reverse(&self, from: VecRef<'_>, into: VecRef<'_>, add: bool) -> Result<(), PetscError> {
        let mode = if add {
            ffi::InsertMode_ADD_VALUES
        } else {
            ffi::InsertMode_INSERT_VALUES
        };
        self.run(from, into, mode, ffi::ScatterMode_SCATTER_REVERSE)
    }

    fn run(
        &self,
        x: VecRef<'_>,
        y: VecRef<'_>,
        insert: ffi::InsertMode,
        mode: ffi::ScatterMode,
    ) -> Result<(), PetscError> {
        // SAFETY: live handles of the layouts the scatter was made for (PETSc checks).
        unsafe {
            check(
                ffi::VecScatterBegin(self.raw, x.raw, y.raw, insert, mode),
                "VecScatterBegin",
            )?;
            check(
                ffi::VecScatterEnd(self.raw, x.raw, y.raw, insert, mode),
                "VecScatterEnd",
            )
        }
    }
}

impl Drop for IndexScatter {
    fn drop(&mut self) {
        // SAFETY: we own the scatter.
        unsafe {
            ffi::VecScatterDestroy(&mut self.raw);
        }
    }
}
