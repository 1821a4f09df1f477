use super::ffi;
use std::ffi::CStr;
use std::fmt;

/// A PETSc call that returned a non-zero error code, or a callback of ours that failed.
#[derive(Debug, Clone)]
pub struct PetscError {
    pub code: i32,
    pub message: String,
}

impl fmt::Display for PetscError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "PETSc error {}: {}", self.code, self.message)
    }
}

impl std::error::Error for PetscError {}

impl PetscError {
    /// Newton ran but did not converge, as opposed to a failing call.
    pub fn is_divergence(&self) -> bool {
        self.code == super::snes::DIVERGED
    }
}

/// Turns a PETSc error code into a `Result`, with PETSc's own text for the code.
pub fn check(code: ffi::PetscErrorCode, call: &str) -> Result<(), PetscError> {
    if code == 0 {
        return Ok(());
    }
    let mut text: *const std::os::raw::c_char = std::ptr::null();
    // SAFETY: PetscErrorMessage only writes a pointer to a static string table entry.
    let described = unsafe { ffi::PetscErrorMessage(code, &mut text, std::ptr::null_mut()) };
    let what = if described == 0 && !text.is_null() {
        // SAFETY: PETSc returns a nul-terminated static string.
        unsafe { CStr::from_ptr(text) }
            .to_string_lossy()
            .into_owned()
    } else {
        "unknown error".to_string()
    };
    Err(PetscError {
        code,
        message: format!("{call}: {what}"),
    })
}
