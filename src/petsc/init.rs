use super::error::{check, PetscError};
use super::ffi;
use mpi::raw::AsRaw;
use mpi::topology::SimpleCommunicator;
use std::ffi::{c_char, c_int, CString};
use std::sync::OnceLock;

/// The PETSc options of the command line, for messages about options PETSc rejected.
static USER_OPTIONS: OnceLock<String> = OnceLock::new();

/// The PETSc options given on the command line (after `--`), space-separated; empty if none.
pub(crate) fn user_options() -> &'static str {
    USER_OPTIONS.get().map_or("", String::as_str)
}

/// PETSc's lifetime. Create after rsmpi initialised MPI, drop before rsmpi's `Universe`: PETSc then
/// neither initialises nor finalises MPI itself.
pub struct Petsc {
    // PETSc keeps pointers into argv for its whole life.
    _args: Vec<CString>,
    _argv: Vec<*mut c_char>,
}

impl Petsc {
    /// Collective. `options` are PETSc command-line options (e.g. `-snes_monitor`), passed through
    /// unchanged so every PETSc option works at run time.
    pub fn initialize(world: &SimpleCommunicator, options: &[String]) -> Result<Petsc, PetscError> {
        let _ = USER_OPTIONS.set(options.join(" "));
        let mut args = vec![CString::new("pfem-mpi").unwrap_or_default()];
        for o in options {
            args.push(CString::new(o.as_str()).map_err(|_| PetscError {
                code: -1,
                message: format!("PETSc option {o:?} contains a NUL byte"),
            })?);
        }
        let mut argv: Vec<*mut c_char> = args.iter().map(|a| a.as_ptr() as *mut c_char).collect();
        argv.push(std::ptr::null_mut());
        let mut argc = args.len() as c_int;
        let mut argv_ptr = argv.as_mut_ptr();
        // SAFETY: MPI is initialised by rsmpi; PETSC_COMM_WORLD must be set before PetscInitialize,
        // and argv outlives PETSc because `Petsc` owns it.
        unsafe {
            ffi::PETSC_COMM_WORLD = world.as_raw();
            check(
                ffi::PetscInitialize(&mut argc, &mut argv_ptr, std::ptr::null(), std::ptr::null()),
                "PetscInitialize",
            )?;
            // Errors come back as codes and are reported once by us, not as PETSc tracebacks.
            check(
                ffi::PetscPushErrorHandler(
                    Some(ffi::PetscReturnErrorHandler),
                    std::ptr::null_mut(),
                ),
                "PetscPushErrorHandler",
            )?;
        }
        Ok(Petsc {
            _args: args,
            _argv: argv,
        })
    }
}

impl Drop for Petsc {
    fn drop(&mut self) {
        // SAFETY: every PETSc object is an RAII wrapper borrowed from `Petsc`'s scope, so they are
        // destroyed before this runs.
        unsafe {
            ffi::PetscFinalize();
        }
    }
}

pub(crate) fn cstring(s: &str) -> Result<CString, PetscError> {
    CString::new(s).map_err(|_| PetscError {
        code: -1,
        message: format!("string {s:?} contains a NUL byte"),
    })
}
