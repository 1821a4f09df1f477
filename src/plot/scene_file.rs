//! The scene a run wrote next to its history, `DIR/scene.toml` (`Scene::to_toml`): it tells
//! which history picture to draw and holds the declared columns' reference lines.

use std::io::ErrorKind;
use std::path::Path;

use crate::scene::Scene;

/// The scene of the run folder `dir`, or `None` when there is none to use.
///
/// Folders of runs from before the scene was written have no `scene.toml`: that is no error.
/// A `scene.toml` that cannot be read or parsed (say, written by another version of the
/// schema) is not an error either, since the history alone still makes a picture; a warning
/// says why its reference lines are missing.
pub(crate) fn read(dir: &Path) -> Option<Scene> {
    let path = dir.join("scene.toml");
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == ErrorKind::NotFound => return None,
        Err(e) => {
            warn(&format!("{}: cannot read: {e}", path.display()));
            return None;
        }
    };
    match parse(&text, &path) {
        Ok(scene) => Some(scene),
        Err(e) => {
            warn(&e);
            None
        }
    }
}

/// Parses the text of `path`, a `scene.toml`; the error names the file.
pub(crate) fn parse(text: &str, path: &Path) -> Result<Scene, String> {
    Scene::from_toml(text, &path.display().to_string(), &[]).map_err(|e| e.to_string())
}

/// `message` names the file.
fn warn(message: &str) {
    eprintln!("pfem-mpi: warning: {message}; history.png is drawn without the scene");
}
