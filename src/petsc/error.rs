use super::ffi;
use std::ffi::CStr;
use std::fmt;

/// PETSc's `PETSC_ERR_USER`: the code our callbacks return, and our own failures carry.
pub(crate) const PETSC_ERR_USER: ffi::PetscErrorCode = 83;

/// A PETSc call that returned a non-zero error code, or a callback of ours that failed.
#[derive(Debug, Clone)]
pub struct PetscError {
    pub code: ffi::PetscErrorCode,
    pub message: String,
}

impl fmt::Display for PetscError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "PETSc error {}: {}", self.code, self.message)
    }
}

impl std::error::Error for PetscError {}

impl PetscError {
    /// Adds the command line's PETSc options to a failure to read them, since PETSc's own text
    /// often gives only the value (`Input string abc has no integer value`).
    pub(crate) fn naming_user_options(mut self) -> Self {
        let given = super::init::user_options();
        if !given.is_empty() {
            self.message
                .push_str(&format!("; PETSc options given after --: {given}"));
        }
        self
    }
}

/// Turns a PETSc error code into a `Result`, with PETSc's own text for the code and the message
/// of the error's origin (e.g. `Unknown PC type nosuch`, which names the option at fault).
pub fn check(code: ffi::PetscErrorCode, call: &str) -> Result<(), PetscError> {
    if code == 0 {
        return Ok(());
    }
    let mut text: *const std::os::raw::c_char = std::ptr::null();
    let mut specific: *mut std::os::raw::c_char = std::ptr::null_mut();
    // SAFETY: PetscErrorMessage only writes pointers: to a static string table entry, and to
    // PETSc's static buffer of the last initial error's message.
    let described = unsafe { ffi::PetscErrorMessage(code, &mut text, &mut specific) };
    let what = if described == 0 && !text.is_null() {
        // SAFETY: PETSc returns a nul-terminated static string.
        unsafe { CStr::from_ptr(text) }
            .to_string_lossy()
            .into_owned()
    } else {
        "unknown error".to_string()
    };
    let origin = if described == 0 && !specific.is_null() {
        // SAFETY: the buffer is nul-terminated (PETSc copies at most its size - 1 into it), and
        // writable. It keeps the message of the last error that began in PETSc, so it is emptied
        // here: an error that begins in our own callback must not repeat an old message.
        unsafe {
            let origin = CStr::from_ptr(specific)
                .to_string_lossy()
                .trim()
                .to_string();
            *specific = 0;
            origin
        }
    } else {
        String::new()
    };
    let message = if origin.is_empty() {
        format!("{call}: {what}")
    } else {
        format!("{call}: {what} ({origin})")
    };
    Err(PetscError { code, message })
}
