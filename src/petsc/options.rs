//! PETSc's options database: reading an option, setting a default the command line may
//! override, and registering options in a block that `-help` lists.

use super::error::{check, PetscError, PETSC_ERR_USER};
use super::ffi;
use super::init::cstring;
use mpi::raw::AsRaw;
use mpi::topology::SimpleCommunicator;
use std::ffi::CString;

/// The value of option `name` in PETSc's options database, if given (an option given without a
/// value reads as the empty string).
pub fn string(name: &str) -> Result<Option<String>, PetscError> {
    let n = cstring(name)?;
    let mut buf = [0 as std::os::raw::c_char; 256];
    let mut given = ffi::PetscBool_PETSC_FALSE;
    // SAFETY: nul-terminated name; PETSc writes at most `buf.len()` bytes, nul-terminated; the
    // global options database is live between PetscInitialize and PetscFinalize.
    unsafe {
        check(
            ffi::PetscOptionsGetString(
                std::ptr::null_mut(),
                std::ptr::null(),
                n.as_ptr(),
                buf.as_mut_ptr(),
                buf.len(),
                &mut given,
            ),
            "PetscOptionsGetString",
        )?;
        if given == ffi::PetscBool_PETSC_FALSE {
            return Ok(None);
        }
        let value = std::ffi::CStr::from_ptr(buf.as_ptr());
        Ok(Some(value.to_string_lossy().into_owned()))
    }
}

/// Whether option `name` is in the database.
pub fn given(name: &str) -> Result<bool, PetscError> {
    let n = cstring(name)?;
    let mut given = ffi::PetscBool_PETSC_FALSE;
    // SAFETY: nul-terminated name; the global options database is live.
    check(
        unsafe {
            ffi::PetscOptionsHasName(
                std::ptr::null_mut(),
                std::ptr::null(),
                n.as_ptr(),
                &mut given,
            )
        },
        "PetscOptionsHasName",
    )?;
    Ok(given == ffi::PetscBool_PETSC_TRUE)
}

/// Option `name` as a boolean (`true`/`false`, `1`/`0`, ...), or `default`.
pub fn flag(name: &str, default: bool) -> Result<bool, PetscError> {
    let n = cstring(name)?;
    let mut on = if default {
        ffi::PetscBool_PETSC_TRUE
    } else {
        ffi::PetscBool_PETSC_FALSE
    };
    // SAFETY: nul-terminated name; the global options database is live.
    check(
        unsafe {
            ffi::PetscOptionsGetBool(
                std::ptr::null_mut(),
                std::ptr::null(),
                n.as_ptr(),
                &mut on,
                std::ptr::null_mut(),
            )
        },
        "PetscOptionsGetBool",
    )?;
    Ok(on == ffi::PetscBool_PETSC_TRUE)
}

/// Puts `name value` into PETSc's options database unless the command line gave `name`: a
/// default for an object that reads its options later.
pub fn set_default(name: &str, value: &str) -> Result<(), PetscError> {
    if given(name)? {
        return Ok(());
    }
    let (n, v) = (cstring(name)?, cstring(value)?);
    // SAFETY: nul-terminated strings; the global options database is live.
    check(
        unsafe { ffi::PetscOptionsSetValue(std::ptr::null_mut(), n.as_ptr(), v.as_ptr()) },
        "PetscOptionsSetValue",
    )
}

/// A block of related options, registered as PETSc's own objects register theirs
/// (`PetscOptionsBegin` … `PetscOptionsEnd`): each option read through it is listed by `-help`
/// under the block's title, once per run. Not published to SAWs (the block runs once).
pub struct OptionsBlock {
    items: Box<ffi::PetscOptionItems>,
    open: bool,
}

impl OptionsBlock {
    /// Collective. Opens a block titled `title`.
    pub fn begin(comm: &SimpleCommunicator, title: &str) -> Result<OptionsBlock, PetscError> {
        let title = cstring(title)?;
        // SAFETY: PETSc's macro zeroes the struct (plain data) and runs the block once with
        // count 1 when not publishing; Begin copies the title.
        let mut block = OptionsBlock {
            items: Box::new(unsafe { std::mem::zeroed() }),
            open: false,
        };
        block.items.count = 1;
        check(
            unsafe {
                ffi::PetscOptionsBegin_Private(
                    &mut *block.items,
                    comm.as_raw(),
                    std::ptr::null(),
                    title.as_ptr(),
                    std::ptr::null(),
                )
            },
            "PetscOptionsBegin",
        )?;
        block.open = true;
        Ok(block)
    }

    /// One of `choices` for option `name` (its index), or `None` if not given. A value not in
    /// the list is an error that names the option and the choices.
    pub fn choice(
        &mut self,
        name: &str,
        help: &str,
        choices: &[&str],
        default: &str,
    ) -> Result<Option<usize>, PetscError> {
        if let Some(value) = string(name)? {
            if !choices.contains(&value.as_str()) {
                return Err(PetscError {
                    code: PETSC_ERR_USER,
                    message: format!("{name} {value:?}: not one of {}", choices.join(", ")),
                });
            }
        }
        let owned = choices
            .iter()
            .map(|c| cstring(c))
            .collect::<Result<Vec<CString>, _>>()?;
        let list: Vec<*const std::os::raw::c_char> = owned.iter().map(|c| c.as_ptr()).collect();
        let (n, h, d) = (cstring(name)?, cstring(help)?, cstring(default)?);
        let mut index: ffi::PetscInt = 0;
        let mut set = ffi::PetscBool_PETSC_FALSE;
        // SAFETY: the block is open; every string outlives the call.
        check(
            unsafe {
                ffi::PetscOptionsEList_Private(
                    &mut *self.items,
                    n.as_ptr(),
                    h.as_ptr(),
                    std::ptr::null(),
                    list.as_ptr(),
                    super::matrix::to_int(list.len(), "choices")?,
                    d.as_ptr(),
                    &mut index,
                    &mut set,
                )
            },
            "PetscOptionsEList",
        )?;
        Ok((set == ffi::PetscBool_PETSC_TRUE).then_some(index.max(0) as usize))
    }

    /// Option `name` as a boolean (`true`/`false`, `1`/`0`, ...), or `default`.
    pub fn flag(&mut self, name: &str, help: &str, default: bool) -> Result<bool, PetscError> {
        let (n, h) = (cstring(name)?, cstring(help)?);
        let current = if default {
            ffi::PetscBool_PETSC_TRUE
        } else {
            ffi::PetscBool_PETSC_FALSE
        };
        let mut value = current;
        // SAFETY: the block is open; the strings outlive the call.
        check(
            unsafe {
                ffi::PetscOptionsBool_Private(
                    &mut *self.items,
                    n.as_ptr(),
                    h.as_ptr(),
                    std::ptr::null(),
                    current,
                    &mut value,
                    std::ptr::null_mut(),
                )
            },
            "PetscOptionsBool",
        )?;
        Ok(value == ffi::PetscBool_PETSC_TRUE)
    }

    /// Option `name` as a real number, or `default`.
    pub fn real(&mut self, name: &str, help: &str, default: f64) -> Result<f64, PetscError> {
        let (n, h) = (cstring(name)?, cstring(help)?);
        let mut value = default;
        // SAFETY: the block is open; the strings outlive the call.
        check(
            unsafe {
                ffi::PetscOptionsReal_Private(
                    &mut *self.items,
                    n.as_ptr(),
                    h.as_ptr(),
                    std::ptr::null(),
                    default,
                    &mut value,
                    std::ptr::null_mut(),
                )
            },
            "PetscOptionsReal",
        )?;
        Ok(value)
    }

    /// Collective. Closes the block.
    pub fn end(mut self) -> Result<(), PetscError> {
        self.open = false;
        // SAFETY: the block is open; End frees what Begin allocated.
        check(
            unsafe { ffi::PetscOptionsEnd_Private(&mut *self.items) },
            "PetscOptionsEnd",
        )
    }
}

impl Drop for OptionsBlock {
    fn drop(&mut self) {
        if self.open {
            // SAFETY: a block left open by an error: End frees what Begin allocated.
            unsafe {
                ffi::PetscOptionsEnd_Private(&mut *self.items);
            }
        }
    }
}
