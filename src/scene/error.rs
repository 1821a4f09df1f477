//! The one error type of scene loading: every failure says which scene, which `--set` argument
//! (if one is responsible) and which field.

use std::fmt;

/// Why a scene could not be loaded. Displays as
/// `scene 'cantilever.toml': field mesh.h: must be > 0 (got -1)`, with
/// `--set mesh.h=-1: ` inserted before the field when an override caused it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneError {
    /// Where the scene came from: the file path as given, or the built-in name.
    pub scene: String,
    /// The `--set` argument at fault, as given.
    pub set: Option<String>,
    /// Path of the field at fault, e.g. `mesh.h` or `fixed[0].where`.
    pub field: Option<String>,
    pub message: String,
}

impl SceneError {
    pub(crate) fn new(scene: &str, message: impl Into<String>) -> Self {
        SceneError {
            scene: scene.to_string(),
            set: None,
            field: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "scene '{}': ", self.scene)?;
        if let Some(set) = &self.set {
            write!(f, "--set {set}: ")?;
        }
        if let Some(field) = &self.field {
            write!(f, "field {field}: ")?;
        }
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for SceneError {}
