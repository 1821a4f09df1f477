//! Viewers that PETSc lends to a view callback.

use super::error::{check, PetscError};
use super::ffi;
use super::init::cstring;
use std::marker::PhantomData;

/// A viewer borrowed for the length of a view callback.
#[derive(Clone, Copy)]
pub struct ViewerRef<'a> {
    pub(super) raw: ffi::PetscViewer,
    _owner: PhantomData<&'a ()>,
}

impl<'a> ViewerRef<'a> {
    /// # Safety
    /// `raw` must be a live viewer for as long as the returned borrow is used.
    pub(super) unsafe fn lent(raw: ffi::PetscViewer) -> ViewerRef<'a> {
        ViewerRef {
            raw,
            _owner: PhantomData,
        }
    }

    /// Prints `lines`, then runs `nested` (inner solvers' views) one tab in: a shell
    /// preconditioner's view. Only a text viewer takes lines; any other gets nothing.
    pub fn nested(
        &self,
        lines: &[String],
        nested: impl FnOnce() -> Result<(), PetscError>,
    ) -> Result<(), PetscError> {
        // SAFETY: live viewer; the strings outlive the calls.
        unsafe {
            if !super::has_type(self.raw as ffi::PetscObject, "ascii")? {
                return Ok(());
            }
            let format = cstring("%s\n")?;
            for line in lines {
                let line = cstring(line)?;
                check(
                    ffi::PetscViewerASCIIPrintf(self.raw, format.as_ptr(), line.as_ptr()),
                    "PetscViewerASCIIPrintf",
                )?;
            }
            check(
                ffi::PetscViewerASCIIPushTab(self.raw),
                "PetscViewerASCIIPushTab",
            )?;
            let viewed = nested();
            check(
                ffi::PetscViewerASCIIPopTab(self.raw),
                "PetscViewerASCIIPopTab",
            )?;
            viewed
        }
    }
}
