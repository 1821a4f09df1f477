//! Matrices that PETSc applies through our callbacks (MATSHELL): operators cheaper to apply
//! than to store.

use super::error::{check, PetscError, PETSC_ERR_USER};
use super::ffi;
use super::matrix::{to_int, Mat};
use super::vector::VecRef;
use mpi::raw::AsRaw;
use mpi::topology::SimpleCommunicator;
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// A linear operator A from a column layout to a row layout, applied by PETSc through a shell
/// matrix ([`Mat::shell`]). Each method is collective when the operator communicates.
pub trait LinearOperator {
    /// y = A x.
    fn mult(&self, x: VecRef<'_>, y: VecRef<'_>) -> Result<(), PetscError>;
    /// y = y + A x.
    fn mult_add(&self, x: VecRef<'_>, y: VecRef<'_>) -> Result<(), PetscError>;
    /// x = Aᵀ y.
    fn mult_transpose(&self, y: VecRef<'_>, x: VecRef<'_>) -> Result<(), PetscError>;
}

/// The context PETSc keeps: a thin pointer to the operator.
type Context = Box<dyn LinearOperator>;

impl Mat {
    /// Collective. A shell matrix with `local` (rows, columns) sizes that applies `op`. PETSc
    /// owns `op` from here on and drops it with the matrix's last reference
    /// (`MatShellSetContextDestroy`): a solver that keeps the matrix keeps its operator.
    pub fn shell(
        comm: &SimpleCommunicator,
        local: [usize; 2],
        op: Box<dyn LinearOperator>,
    ) -> Result<Mat, PetscError> {
        let (rows, cols) = (
            to_int(local[0], "shell rows")?,
            to_int(local[1], "shell columns")?,
        );
        let ctx = Box::into_raw(Box::new(op)) as *mut c_void;
        let mut raw: ffi::Mat = std::ptr::null_mut();
        let decide = ffi::PETSC_DETERMINE as ffi::PetscInt;
        // SAFETY: `ctx` is a leaked Box that the destroy callback reclaims exactly once; until
        // the callback is registered, a failure reclaims it here.
        unsafe {
            let created = check(
                ffi::MatCreateShell(comm.as_raw(), rows, cols, decide, decide, ctx, &mut raw),
                "MatCreateShell",
            )
            .and_then(|()| {
                check(
                    ffi::MatShellSetContextDestroy(raw, Some(destroy_cb)),
                    "MatShellSetContextDestroy",
                )
            });
            if let Err(e) = created {
                drop(Box::from_raw(ctx as *mut Context));
                if !raw.is_null() {
                    ffi::MatDestroy(&mut raw);
                }
                return Err(e);
            }
            let mat = Mat { raw };
            type Op = unsafe extern "C" fn();
            type Binary = unsafe extern "C" fn(ffi::Mat, ffi::Vec, ffi::Vec) -> ffi::PetscErrorCode;
            type Ternary =
                unsafe extern "C" fn(ffi::Mat, ffi::Vec, ffi::Vec, ffi::Vec) -> ffi::PetscErrorCode;
            for (op, f) in [
                (ffi::MatOperation_MATOP_MULT, mult_cb as Binary),
                (ffi::MatOperation_MATOP_MULT_TRANSPOSE, mult_transpose_cb),
            ] {
                // SAFETY: PETSc calls the operation back with the signature it was given.
                let f = std::mem::transmute::<Binary, Op>(f);
                check(
                    ffi::MatShellSetOperation(raw, op, Some(f)),
                    "MatShellSetOperation",
                )?;
            }
            let f = std::mem::transmute::<Ternary, Op>(mult_add_cb as Ternary);
            check(
                ffi::MatShellSetOperation(raw, ffi::MatOperation_MATOP_MULT_ADD, Some(f)),
                "MatShellSetOperation",
            )?;
            Ok(mat)
        }
    }
}

/// Runs `f` on the shell's operator; an error or panic is printed on this rank (PETSc's error
/// code alone would lose the message) and becomes PETSc's user-error code.
unsafe fn with_operator(
    a: ffi::Mat,
    f: impl FnOnce(&dyn LinearOperator) -> Result<(), PetscError>,
) -> ffi::PetscErrorCode {
    let mut ctx: *mut c_void = std::ptr::null_mut();
    // SAFETY: `a` is a shell made by `Mat::shell`, whose context is a live `Context`.
    let code = unsafe { ffi::MatShellGetContext(a, &mut ctx as *mut *mut c_void as *mut c_void) };
    if code != 0 {
        return code;
    }
    let op: &Context = unsafe { &*(ctx as *const Context) };
    run_callback("shell matrix", || f(op.as_ref()))
}

/// Runs a PETSc callback's body `f`: an error or panic is printed on this rank under `what`
/// (PETSc's error code alone would lose the message) and becomes PETSc's user-error code, so
/// that no panic unwinds into C.
pub(super) fn run_callback(
    what: &str,
    f: impl FnOnce() -> Result<(), PetscError>,
) -> ffi::PetscErrorCode {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => 0,
        Ok(Err(e)) => {
            eprintln!("pfem-mpi: {what}: {e}");
            PETSC_ERR_USER
        }
        Err(_) => {
            eprintln!("pfem-mpi: {what}: panicked");
            PETSC_ERR_USER
        }
    }
}

unsafe extern "C" fn mult_cb(a: ffi::Mat, x: ffi::Vec, y: ffi::Vec) -> ffi::PetscErrorCode {
    // SAFETY: PETSc keeps the vectors alive during the callback.
    unsafe { with_operator(a, |op| op.mult(VecRef::lent(x), VecRef::lent(y))) }
}

unsafe extern "C" fn mult_add_cb(
    a: ffi::Mat,
    x: ffi::Vec,
    y: ffi::Vec,
    z: ffi::Vec,
) -> ffi::PetscErrorCode {
    // SAFETY: as in `mult_cb`; z = y + A x, in place when PETSc passes z = y.
    unsafe {
        with_operator(a, |op| {
            if z != y {
                check(ffi::VecCopy(y, z), "VecCopy")?;
            }
            op.mult_add(VecRef::lent(x), VecRef::lent(z))
        })
    }
}

unsafe extern "C" fn mult_transpose_cb(
    a: ffi::Mat,
    y: ffi::Vec,
    x: ffi::Vec,
) -> ffi::PetscErrorCode {
    // SAFETY: as in `mult_cb`.
    unsafe { with_operator(a, |op| op.mult_transpose(VecRef::lent(y), VecRef::lent(x))) }
}

unsafe extern "C" fn destroy_cb(ctx: *mut c_void) -> ffi::PetscErrorCode {
    // SAFETY: the context `Mat::shell` leaked; PETSc calls this once, with the matrix.
    let dropped = catch_unwind(AssertUnwindSafe(|| unsafe {
        drop(Box::from_raw(ctx as *mut Context))
    }));
    if dropped.is_ok() {
        0
    } else {
        PETSC_ERR_USER
    }
}
