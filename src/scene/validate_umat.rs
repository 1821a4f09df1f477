//! The keys of `model = "umat"`: where the library is, that it holds a UMAT, and that the
//! properties and state variables are what the scene says.

use std::path::{Path, PathBuf};

use super::field_path::FieldPath;
use super::schema::{Material, MaterialModel, Scene};
use super::validate::Invalid;
use crate::material::layout::STRESS_COLUMNS;
use crate::material::umat;

/// Makes every relative `library` absolute, relative to the scene file's directory (to the
/// working directory for a built-in scene), so that the case file `new` writes finds it from
/// wherever the run starts.
pub fn resolve_libraries(scene: &mut Scene, source: &str) {
    let base: PathBuf = match super::scene_file(source).and_then(Path::parent) {
        Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let base = match base.is_absolute() {
        true => base,
        // Without a working directory the path stays relative, and opening it reports it.
        false => std::env::current_dir().map_or(base.clone(), |cwd| cwd.join(&base)),
    };
    for m in scene.material.0.iter_mut() {
        if let Some(lib) = &mut m.library {
            if Path::new(lib.as_str()).is_relative() {
                let joined = base.join(lib.as_str());
                // `./x` and `a/../x` spelled out, so that messages show the file meant.
                let clean: PathBuf = joined.components().collect();
                *lib = clean.display().to_string();
            }
        }
    }
}

fn fail<T>(path: FieldPath, message: String) -> Result<T, Invalid> {
    Err((path, message))
}

/// The UMAT keys of material `m` at `mat`: required and consistent for `"umat"`, absent for
/// the other models. Opens the library, so that `new` reports a missing one or a missing symbol.
pub fn check(m: &Material, mat: &FieldPath) -> Result<(), Invalid> {
    if m.model != MaterialModel::Umat {
        let given = [
            ("library", m.library.is_some()),
            ("props", !m.props.is_empty()),
            ("nprops", m.nprops.is_some()),
            ("state_variables", m.state_variables != 0),
            ("state_names", !m.state_names.is_empty()),
        ];
        return match given.iter().find(|(_, g)| *g) {
            Some((key, _)) => fail(
                mat.join(key),
                format!(
                    "is a key of model \"umat\", not of \"{}\"",
                    m.model.as_str()
                ),
            ),
            None => Ok(()),
        };
    }
    let Some(lib) = &m.library else {
        return fail(
            mat.join("library"),
            "is required for model \"umat\": the shared library holding `umat_`".to_string(),
        );
    };
    if let Some(n) = m.nprops {
        if n != m.props.len() {
            return fail(
                mat.join("props"),
                format!(
                    "has {} values but nprops = {n}: the UMAT reads {n} properties",
                    m.props.len()
                ),
            );
        }
    }
    if let Some((i, p)) = m.props.iter().enumerate().find(|(_, p)| !p.is_finite()) {
        return fail(mat.join("props").at(i), format!("must be finite (got {p})"));
    }
    let names = &m.state_names;
    if !names.is_empty() && names.len() != m.state_variables {
        return fail(
            mat.join("state_names"),
            format!(
                "names {} variables but state_variables = {}",
                names.len(),
                m.state_variables
            ),
        );
    }
    for (i, n) in names.iter().enumerate() {
        let ok = !n.is_empty() && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        let taken =
            STRESS_COLUMNS.contains(&n.as_str()) || n == umat::STRAN || names[..i].contains(n);
        if !ok || taken {
            return fail(
                mat.join("state_names").at(i),
                format!(
                    "\"{n}\" must be a new name of letters, digits and `_` (not a stress \
                     column, `{}` or a repeat)",
                    umat::STRAN
                ),
            );
        }
    }
    umat::check_library(Path::new(lib)).map_err(|e| (mat.join("library"), e))
}
