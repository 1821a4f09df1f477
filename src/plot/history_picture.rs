//! Which picture `history.png` is: a legacy kind's (fixed columns, with the reference solutions
//! of `docs/reference.md`) or the scene's declared columns' (with the scene's own reference
//! lines).

use std::path::Path;

use crate::scene::{HistoryKind, Scene};

use super::history::History;
use super::{declared, legacy, PlotError};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Choice {
    Legacy(HistoryKind),
    Declared,
}

/// The legacy picture when the header is exactly a legacy kind's and the run's scene asked for
/// that kind. The header alone cannot tell: a scene may declare columns of the same names (the
/// rigid-body `footing` writes `step,z_over_B,q_over_cu`, as the legacy footing kind does) and
/// then its own reference lines belong on the picture. Without a scene — folders of runs from
/// before `scene.toml` was written, when only the legacy kinds existed — the header decides.
pub(crate) fn choose(history: &History, scene: Option<&Scene>) -> Choice {
    match (history.legacy_kind(), scene) {
        (Some(kind), None) => Choice::Legacy(kind),
        (Some(kind), Some(s)) if s.history.kind == Some(kind) => Choice::Legacy(kind),
        _ => Choice::Declared,
    }
}

/// Writes `history.png` of `history` to `path`, as [`choose`] picks.
pub(crate) fn draw(history: &History, scene: Option<&Scene>, path: &Path) -> Result<(), PlotError> {
    match choose(history, scene) {
        Choice::Legacy(kind) => legacy::draw(history, kind, path),
        Choice::Declared => declared::draw(history, scene, path),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::history::parse;
    use crate::scene::load_scene;

    fn scene(name: &str) -> Scene {
        load_scene(name, &[]).unwrap().0
    }

    #[test]
    fn legacy_needs_the_header_and_the_scene_kind() {
        let footing = parse("step,z_over_B,q_over_cu\n1,0.01,1\n").unwrap();
        // Old run folder: no scene, the header decides.
        assert_eq!(choose(&footing, None), Choice::Legacy(HistoryKind::Footing));
        // The legacy footing scene asks for the kind.
        let shallow = scene("footing-shallow");
        assert_eq!(shallow.history.kind, Some(HistoryKind::Footing));
        assert_eq!(
            choose(&footing, Some(&shallow)),
            Choice::Legacy(HistoryKind::Footing)
        );
        // The rigid-body footing writes the same header from declared columns.
        let rigid = scene("footing");
        assert_eq!(rigid.history.kind, None);
        assert_eq!(choose(&footing, Some(&rigid)), Choice::Declared);
        // A scene of another kind does not make a footing header legacy.
        assert_eq!(
            choose(&footing, Some(&scene("cantilever"))),
            Choice::Declared
        );

        let tbar = parse("step,w_over_D,Nc\n").unwrap();
        assert_eq!(choose(&tbar, None), Choice::Declared);
        assert_eq!(choose(&tbar, Some(&scene("tbar-smooth"))), Choice::Declared);
    }

    /// `plot_run` reads `scene.toml` next to the history: the rigid-body footing's picture is
    /// not the legacy one, the legacy footing scene's is, byte for byte.
    #[test]
    fn plot_run_reads_the_scene_next_to_the_history() {
        let dir = std::env::temp_dir().join(format!("pfem-plot-choice-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let rows: String = (1..=50)
            .map(|k| format!("{k},{},{}\n", 0.02 * f64::from(k), 0.1 * f64::from(k)))
            .collect();
        std::fs::write(
            dir.join("history.csv"),
            format!("step,z_over_B,q_over_cu\n{rows}"),
        )
        .unwrap();
        let picture = |scene: Option<&str>| {
            match scene {
                Some(name) => std::fs::write(dir.join("scene.toml"), self::scene(name).to_toml()),
                None => std::fs::remove_file(dir.join("scene.toml")).or(Ok(())),
            }
            .unwrap();
            let written = crate::plot::plot_run(&dir).unwrap();
            assert_eq!(written, [dir.join("plots/history.png")]);
            std::fs::read(&written[0]).unwrap()
        };
        let old = picture(None);
        assert_eq!(picture(Some("footing-shallow")), old);
        assert_ne!(picture(Some("footing")), old);
        // A scene.toml that does not parse is left aside with a warning: the legacy picture.
        std::fs::write(dir.join("scene.toml"), "name = ").unwrap();
        assert_eq!(
            std::fs::read(&crate::plot::plot_run(&dir).unwrap()[0]).unwrap(),
            old
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
