//! Preconditioners that PETSc applies through our callbacks (PCSHELL): a Rust value that
//! implements [`ShellPreconditioner`], owned by the PC from then on.

use super::error::{check, PetscError, PETSC_ERR_USER};
use super::ffi;
use super::init::cstring;
use super::pc::PcRef;
use super::shell::run_callback;
use super::vector::VecRef;
use super::viewer::ViewerRef;
use std::any::Any;
use std::cell::RefCell;
use std::ffi::c_void;

/// A preconditioner of our own. PETSc calls it back with its PC (whose operators it may read);
/// an error or panic inside a callback is printed on this rank and fails the PETSc call.
pub trait ShellPreconditioner: Any {
    /// Collective. A new operator (or the first).
    fn set_up(&mut self, pc: PcRef<'_>) -> Result<(), PetscError>;
    /// Collective. x = M⁻¹ b.
    fn apply(&mut self, pc: PcRef<'_>, b: VecRef<'_>, x: VecRef<'_>) -> Result<(), PetscError>;
    /// What `-ksp_view` prints of it.
    fn view(&self, viewer: ViewerRef<'_>) -> Result<(), PetscError>;
}

/// Object-safe access to a shell as itself and as `Any` (to find it again by type).
trait Erased {
    fn shell(&mut self) -> &mut dyn ShellPreconditioner;
    fn any(&mut self) -> &mut dyn Any;
}

impl<T: ShellPreconditioner> Erased for T {
    fn shell(&mut self) -> &mut dyn ShellPreconditioner {
        self
    }
    fn any(&mut self) -> &mut dyn Any {
        self
    }
}

/// What the PC's context points to. The cell turns a re-entrant use (a callback reaching its
/// own shell) into an error instead of two mutable borrows.
type Context = RefCell<Box<dyn Erased>>;

impl PcRef<'_> {
    /// Collective. Makes this PC the shell `shell`, which `-ksp_view` names `name`; the PC
    /// owns it from here on and drops it when destroyed.
    pub fn set_shell<T: ShellPreconditioner>(
        &self,
        name: &str,
        shell: T,
    ) -> Result<(), PetscError> {
        let (kind, name) = (cstring("shell")?, cstring(name)?);
        let context: Box<Context> = Box::new(RefCell::new(Box::new(shell)));
        let raw = Box::into_raw(context);
        // SAFETY: live PC; the context is a leaked Box that the destroy callback reclaims
        // exactly once; until that callback is registered, a failure reclaims it here.
        unsafe {
            let registered = check(ffi::PCSetType(self.raw, kind.as_ptr()), "PCSetType(shell)")
                .and_then(|()| {
                    check(
                        ffi::PCShellSetContext(self.raw, raw as *mut c_void),
                        "PCShellSetContext",
                    )
                })
                .and_then(|()| {
                    check(
                        ffi::PCShellSetDestroy(self.raw, Some(destroy_cb)),
                        "PCShellSetDestroy",
                    )
                });
            if let Err(e) = registered {
                drop(Box::from_raw(raw));
                return Err(e);
            }
            check(
                ffi::PCShellSetName(self.raw, name.as_ptr()),
                "PCShellSetName",
            )?;
            check(
                ffi::PCShellSetSetUp(self.raw, Some(setup_cb)),
                "PCShellSetSetUp",
            )?;
            check(
                ffi::PCShellSetApply(self.raw, Some(apply_cb)),
                "PCShellSetApply",
            )?;
            check(
                ffi::PCShellSetView(self.raw, Some(view_cb)),
                "PCShellSetView",
            )
        }
    }

    /// Runs `f` on this PC's shell if it is a `T` of ours; `None` if it is not (the command
    /// line may have made it something else).
    pub fn with_shell<T: ShellPreconditioner, R>(
        &self,
        f: impl FnOnce(&mut T) -> R,
    ) -> Result<Option<R>, PetscError> {
        // SAFETY: live PC.
        let Some(context) = (unsafe { context(self.raw) })? else {
            return Ok(None);
        };
        let mut shell = context.try_borrow_mut().map_err(|_| busy())?;
        Ok(shell.any().downcast_mut::<T>().map(f))
    }
}

/// The context of `pc` if it is a shell of ours. Only [`PcRef::set_shell`] sets a shell's
/// context; a shell made otherwise (`-pc_type shell`) has none.
///
/// # Safety
/// `pc` must be live; the reference must not outlive its shell.
unsafe fn context<'a>(pc: ffi::PC) -> Result<Option<&'a Context>, PetscError> {
    // SAFETY: as the caller promises.
    unsafe {
        if !super::has_type(pc as ffi::PetscObject, "shell")? {
            return Ok(None);
        }
        let mut raw: *mut c_void = std::ptr::null_mut();
        check(
            ffi::PCShellGetContext(pc, &mut raw as *mut *mut c_void as *mut c_void),
            "PCShellGetContext",
        )?;
        Ok((!raw.is_null()).then(|| &*(raw as *const Context)))
    }
}

fn busy() -> PetscError {
    PetscError {
        code: PETSC_ERR_USER,
        message: "a shell preconditioner reached itself from inside its own callback".into(),
    }
}

/// Runs `f` on the shell behind `pc` in a callback.
///
/// # Safety
/// `pc` must be live.
unsafe fn with_context(
    pc: ffi::PC,
    what: &str,
    f: impl FnOnce(&mut dyn ShellPreconditioner) -> Result<(), PetscError>,
) -> ffi::PetscErrorCode {
    run_callback(what, || {
        // SAFETY: as the caller promises; PETSc calls back with a shell of ours.
        let context = unsafe { context(pc) }?.ok_or_else(|| PetscError {
            code: PETSC_ERR_USER,
            message: "a shell preconditioner without its context".into(),
        })?;
        let mut shell = context.try_borrow_mut().map_err(|_| busy())?;
        f(shell.shell())
    })
}

unsafe extern "C" fn setup_cb(pc: ffi::PC) -> ffi::PetscErrorCode {
    // SAFETY: PETSc calls back with the live PC.
    unsafe {
        with_context(pc, "shell preconditioner set-up", |s| {
            s.set_up(PcRef::lent(pc))
        })
    }
}

unsafe extern "C" fn apply_cb(pc: ffi::PC, b: ffi::Vec, x: ffi::Vec) -> ffi::PetscErrorCode {
    // SAFETY: PETSc keeps the PC and the vectors alive during the callback.
    unsafe {
        with_context(pc, "shell preconditioner", |s| {
            s.apply(PcRef::lent(pc), VecRef::lent(b), VecRef::lent(x))
        })
    }
}

unsafe extern "C" fn view_cb(pc: ffi::PC, viewer: ffi::PetscViewer) -> ffi::PetscErrorCode {
    // SAFETY: PETSc keeps the viewer alive during the callback.
    unsafe {
        with_context(pc, "shell preconditioner view", |s| {
            s.view(ViewerRef::lent(viewer))
        })
    }
}

unsafe extern "C" fn destroy_cb(pc: ffi::PC) -> ffi::PetscErrorCode {
    run_callback("shell preconditioner destroy", || {
        let mut raw: *mut c_void = std::ptr::null_mut();
        // SAFETY: the context is the Box `set_shell` leaked; PETSc calls destroy once.
        unsafe {
            check(
                ffi::PCShellGetContext(pc, &mut raw as *mut *mut c_void as *mut c_void),
                "PCShellGetContext",
            )?;
            if !raw.is_null() {
                drop(Box::from_raw(raw as *mut Context));
            }
        }
        Ok(())
    })
}
