//! Our preconditioners and how a [`super::linear_path::LinearPath`] is applied to PETSc's
//! Krylov solver: the recipe ([`configure`]), the shells ([`two_level`], [`yield_zone`]) and
//! what they take from every Jacobian ([`hooks`]). Safe Rust over the binding in
//! `crate::petsc`.

pub mod configure;
pub mod hooks;
pub mod two_level;
pub mod yield_zone;

pub use configure::{configure, Parts};
pub use hooks::{Hooked, Hooks, JacobianProducts};

use crate::petsc::PetscError;

/// The error of a call that needs the shell `what` on a preconditioner that is not it.
fn not_shell(what: &str) -> PetscError {
    PetscError {
        code: crate::petsc::error::PETSC_ERR_USER,
        message: format!("the preconditioner is not the {what}"),
    }
}
