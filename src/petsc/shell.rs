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

/// Prints `lines` to `viewer`, then runs `nested` (the inner solvers' views) one tab in: a
/// shell preconditioner's view. Only a text viewer takes lines; any other gets nothing.
///
/// # Safety
/// `viewer` must be live.
pub(super) unsafe fn view_nested(
    viewer: ffi::PetscViewer,
    lines: &[String],
    nested: impl FnOnce() -> Result<(), PetscError>,
) -> Result<(), PetscError> {
    // SAFETY: as the caller promises; the strings outlive the calls.
    unsafe {
        if !super::has_type(viewer as ffi::PetscObject, "ascii")? {
            return Ok(());
        }
        let format = super::init::cstring("%s\n")?;
        for line in lines {
            let line = super::init::cstring(line)?;
            check(
                ffi::PetscViewerASCIIPrintf(viewer, format.as_ptr(), line.as_ptr()),
                "PetscViewerASCIIPrintf",
            )?;
        }
        check(
            ffi::PetscViewerASCIIPushTab(viewer),
            "PetscViewerASCIIPushTab",
        )?;
        let viewed = nested();
        check(
            ffi::PetscViewerASCIIPopTab(viewer),
            "PetscViewerASCIIPopTab",
        )?;
        viewed
    }
}

/// A shell preconditioner's destroy callback: reclaims its context, a `Box<T>` leaked when the
/// shell was made, and hands it to `release`.
///
/// # Safety
/// `pc`'s context must be null or a leaked `Box<T>`; PETSc calls destroy once.
pub(super) unsafe fn reclaim<T>(pc: ffi::PC, release: unsafe fn(T)) -> ffi::PetscErrorCode {
    let mut raw: *mut c_void = std::ptr::null_mut();
    // SAFETY: as the caller promises.
    unsafe {
        let code = ffi::PCShellGetContext(pc, &mut raw as *mut *mut c_void as *mut c_void);
        if code != 0 {
            return code;
        }
        if !raw.is_null() {
            release(*Box::from_raw(raw as *mut T));
        }
    }
    0
}

/// Runs a shell preconditioner's callback body `f` on its context, a `T` (see
/// [`run_callback`]), or fails when `pc` is not the shell named `name` (`what` names it in
/// messages).
///
/// # Safety
/// `pc` must be live, and a shell named `name` must have a `T` as its context.
pub(super) unsafe fn with_shell<T>(
    pc: ffi::PC,
    name: &str,
    what: &str,
    f: impl FnOnce(&mut T) -> Result<(), PetscError>,
) -> ffi::PetscErrorCode {
    run_callback(what, || {
        // SAFETY: as the caller promises.
        match unsafe { super::shell_context(pc, name) }? {
            Some(raw) => f(unsafe { &mut *(raw as *mut T) }),
            None => Err(not_shell(what)),
        }
    })
}

/// The error of a call that needs the shell `what` on a preconditioner that is not it.
pub(super) fn not_shell(what: &str) -> PetscError {
    PetscError {
        code: PETSC_ERR_USER,
        message: format!("the preconditioner is not the {what}"),
    }
}

/// The callbacks of a shell preconditioner.
pub(super) struct ShellOps {
    pub setup: unsafe extern "C" fn(ffi::PC) -> ffi::PetscErrorCode,
    pub apply: unsafe extern "C" fn(ffi::PC, ffi::Vec, ffi::Vec) -> ffi::PetscErrorCode,
    pub view: unsafe extern "C" fn(ffi::PC, ffi::PetscViewer) -> ffi::PetscErrorCode,
    pub destroy: unsafe extern "C" fn(ffi::PC) -> ffi::PetscErrorCode,
}

/// Collective. Makes `pc` a PCSHELL named `name` with `ops` and the context `context`, taken
/// over: `ops.destroy` hands it to `release` ([`reclaim`]), or this does if the shell cannot
/// be made. Returns the context, owned by the preconditioner.
///
/// # Safety
/// `pc` must be live; `ops.destroy` must reclaim a `Box<T>` with `release`.
pub(super) unsafe fn make_shell<T>(
    pc: ffi::PC,
    context: T,
    name: &str,
    release: unsafe fn(T),
    ops: ShellOps,
) -> Result<*mut T, PetscError> {
    let (kind, name) = match (super::init::cstring("shell"), super::init::cstring(name)) {
        (Ok(kind), Ok(name)) => (kind, name),
        (Err(e), _) | (_, Err(e)) => {
            // SAFETY: the caller's context is released as it would be on destroy.
            unsafe { release(context) };
            return Err(e);
        }
    };
    let raw = Box::into_raw(Box::new(context));
    // SAFETY: `pc` is live; the context is a leaked Box that the destroy callback reclaims
    // exactly once; until that callback is registered, a failure reclaims it here.
    unsafe {
        let registered = check(ffi::PCSetType(pc, kind.as_ptr()), "PCSetType(shell)")
            .and_then(|()| {
                check(
                    ffi::PCShellSetContext(pc, raw as *mut c_void),
                    "PCShellSetContext",
                )
            })
            .and_then(|()| {
                check(
                    ffi::PCShellSetDestroy(pc, Some(ops.destroy)),
                    "PCShellSetDestroy",
                )
            });
        if let Err(e) = registered {
            release(*Box::from_raw(raw));
            return Err(e);
        }
        check(ffi::PCShellSetName(pc, name.as_ptr()), "PCShellSetName")?;
        check(ffi::PCShellSetSetUp(pc, Some(ops.setup)), "PCShellSetSetUp")?;
        check(ffi::PCShellSetApply(pc, Some(ops.apply)), "PCShellSetApply")?;
        check(ffi::PCShellSetView(pc, Some(ops.view)), "PCShellSetView")?;
    }
    Ok(raw)
}
