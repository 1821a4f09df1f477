//! The command line (a public interface, documented in the README).

use std::path::PathBuf;

const USAGE: &str = "\
usage:
  pfem-mpi new <NAME|scene.toml> -o case.h5 [--set key=value ...]   write a case file
  pfem-mpi info FILE.h5                                             summarise a case or checkpoint
  pfem-mpi mesh FILE.h5                                             mesh it once, print its fingerprint
  pfem-mpi plot DIR [--window x0,y0,x1,y1]                          draw DIR/plots/*.png from a run's output
  pfem-mpi schema                                                   print the scene reference (Markdown)
  mpirun -n N pfem-mpi FILE.h5 [--out DIR] [--until-step K] [--progress auto|lines|json]
                         [--verbose] [-- PETSc options]             run (or continue) an analysis
built-in scenes:";

/// The usage text, ending with every built-in scene's name.
pub fn usage() -> String {
    format!("{USAGE} {}", crate::scene::builtin_names())
}

#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    New {
        scene: String,
        out: PathBuf,
        sets: Vec<String>,
    },
    Info {
        file: PathBuf,
    },
    Mesh {
        file: PathBuf,
    },
    Plot {
        dir: PathBuf,
        /// The part of the plane the contour pictures show (metres); None: where each varies.
        window: Option<crate::plot::Window>,
    },
    Run {
        case: PathBuf,
        out: Option<PathBuf>,
        until_step: Option<u64>,
        progress: ProgressMode,
        verbose: bool,
        petsc: Vec<String>,
    },
    /// Print the scene reference generated from the schema.
    Schema,
    Help,
    Version,
}

/// What a run shows on stdout while it steps (`--progress`); `DIR/run.log` gets every step's
/// full line whatever the mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ProgressMode {
    /// A progress bar when stdout is a terminal, the per-step lines otherwise.
    #[default]
    Auto,
    /// The per-step lines, also on a terminal.
    Lines,
    /// One JSON object per step (and one at the end), nothing else, on stdout.
    Json,
}

impl ProgressMode {
    fn parse(v: &str) -> Result<ProgressMode, String> {
        match v {
            "auto" => Ok(ProgressMode::Auto),
            "lines" => Ok(ProgressMode::Lines),
            "json" => Ok(ProgressMode::Json),
            _ => Err(format!(
                "--progress: {v:?} is not a progress mode; give auto, lines or json"
            )),
        }
    }
}

/// Parses the arguments after the program name.
pub fn parse(args: &[String]) -> Result<Command, String> {
    let (ours, petsc) = match args.iter().position(|a| a == "--") {
        Some(i) => (&args[..i], args[i + 1..].to_vec()),
        None => (args, Vec::new()),
    };
    let first = ours.first().ok_or("no case file or command given")?;
    match first.as_str() {
        "-h" | "--help" | "help" => Ok(Command::Help),
        "-V" | "--version" => Ok(Command::Version),
        "schema" => match &ours[1..] {
            [] => Ok(Command::Schema),
            _ => Err("schema: takes no arguments".into()),
        },
        "new" => {
            let mut scene = None;
            let mut out = None;
            let mut sets = Vec::new();
            let mut it = ours[1..].iter();
            while let Some(a) = it.next() {
                match a.as_str() {
                    "-o" | "--output" => {
                        out = Some(PathBuf::from(it.next().ok_or("-o needs a file name")?))
                    }
                    "--set" => sets.push(it.next().ok_or("--set needs key=value")?.clone()),
                    s if s.starts_with('-') => return Err(format!("new: unknown option {s}")),
                    s if scene.is_none() => scene = Some(s.to_string()),
                    s => return Err(format!("new: unexpected argument {s}")),
                }
            }
            Ok(Command::New {
                scene: scene.ok_or("new: name a built-in scene or a scene .toml file")?,
                out: out.ok_or("new: give the case file to write with -o case.h5")?,
                sets,
            })
        }
        "plot" => {
            let mut dir = None;
            let mut window = None;
            let mut it = ours[1..].iter();
            while let Some(a) = it.next() {
                match a.as_str() {
                    "--window" => {
                        let w = it.next().ok_or("--window needs x0,y0,x1,y1 (metres)")?;
                        window = Some(crate::plot::Window::parse(w)?);
                    }
                    s if s.starts_with('-') => return Err(format!("plot: unknown option {s}")),
                    s if dir.is_none() => dir = Some(PathBuf::from(s)),
                    _ => return Err("plot: give exactly one run output folder".into()),
                }
            }
            Ok(Command::Plot {
                dir: dir.ok_or("plot: give exactly one run output folder")?,
                window,
            })
        }
        "info" | "mesh" => {
            let [file] = &ours[1..] else {
                return Err(format!("{first}: give exactly one .h5 file"));
            };
            let file = PathBuf::from(file);
            Ok(if first == "info" {
                Command::Info { file }
            } else {
                Command::Mesh { file }
            })
        }
        _ => {
            let mut case = None;
            let mut out = None;
            let mut until_step = None;
            let mut progress = ProgressMode::Auto;
            let mut verbose = false;
            let mut it = ours.iter();
            while let Some(a) = it.next() {
                match a.as_str() {
                    "--out" => {
                        out = Some(PathBuf::from(it.next().ok_or("--out needs a directory")?))
                    }
                    "--until-step" => {
                        let v = it.next().ok_or("--until-step needs a step number")?;
                        until_step =
                            Some(v.parse().map_err(|_| {
                                format!("--until-step: {v:?} is not a step number")
                            })?);
                    }
                    "--progress" => {
                        progress = ProgressMode::parse(
                            it.next().ok_or("--progress needs auto, lines or json")?,
                        )?
                    }
                    "--verbose" => verbose = true,
                    s if s.starts_with('-') => {
                        return Err(format!("unknown option {s} (PETSc options go after --)"))
                    }
                    s if case.is_none() => case = Some(PathBuf::from(s)),
                    s => return Err(format!("unexpected argument {s}")),
                }
            }
            if verbose && progress == ProgressMode::Json {
                return Err(
                    "--verbose: stdout carries only JSON under --progress json; \
                            the per-step lines are in DIR/run.log"
                        .into(),
                );
            }
            Ok(Command::Run {
                case: case.ok_or("no case file given")?,
                out,
                until_step,
                progress,
                verbose,
                petsc,
            })
        }
    }
}

/// Default output folder: the case's name with `.out` (`runs/case.h5` -> `runs/case.out`); a
/// checkpoint `X.out/checkpoints/step_N.h5` continues in `X.out` (`checkpoints/step_N.h5`, given
/// from inside the run folder, in `.`: an empty path would name no folder in messages).
pub fn default_out_dir(case: &std::path::Path) -> PathBuf {
    if let Some(dir) = case
        .parent()
        .filter(|d| d.file_name().is_some_and(|n| n == "checkpoints"))
    {
        if let Some(run_dir) = dir.parent() {
            if run_dir.as_os_str().is_empty() {
                return PathBuf::from(".");
            }
            return run_dir.to_path_buf();
        }
    }
    case.with_extension("out")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(s: &str) -> Vec<String> {
        s.split_whitespace().map(String::from).collect()
    }

    #[test]
    fn usage_lists_every_built_in_scene() {
        for (name, _) in crate::scene::BUILTINS {
            assert!(usage().contains(name), "{name} missing from the usage text");
        }
    }

    #[test]
    fn run_with_petsc_options() {
        let c = parse(&args("case.h5 --out r -- -snes_monitor -pc_type lu")).unwrap();
        assert_eq!(
            c,
            Command::Run {
                case: "case.h5".into(),
                out: Some("r".into()),
                until_step: None,
                progress: ProgressMode::Auto,
                verbose: false,
                petsc: args("-snes_monitor -pc_type lu")
            }
        );
    }

    #[test]
    fn plot_with_a_window() {
        let c = parse(&args("plot out --window 0,0.3,0.2,0.6")).unwrap();
        let Command::Plot { dir, window } = c else {
            panic!("{c:?}")
        };
        assert_eq!(dir, PathBuf::from("out"));
        assert_eq!(window.map(|w| (w.x0, w.y1)), Some((0.0, 0.6)));
        assert!(matches!(
            parse(&args("plot out")),
            Ok(Command::Plot { window: None, .. })
        ));
        for bad in [
            "plot out --window",
            "plot out --window 1,1,0,0",
            "plot out --window a",
        ] {
            assert!(parse(&args(bad)).unwrap_err().contains("--window"), "{bad}");
        }
        assert!(parse(&args("plot a b")).is_err());
    }

    #[test]
    fn run_with_progress_modes() {
        let c = parse(&args("case.h5 --progress json --until-step 3")).unwrap();
        assert!(matches!(
            c,
            Command::Run {
                progress: ProgressMode::Json,
                verbose: false,
                until_step: Some(3),
                ..
            }
        ));
        let c = parse(&args("case.h5 --verbose --progress lines")).unwrap();
        assert!(matches!(
            c,
            Command::Run {
                progress: ProgressMode::Lines,
                verbose: true,
                ..
            }
        ));
        for bad in ["case.h5 --progress", "case.h5 --progress bar"] {
            assert!(
                parse(&args(bad)).unwrap_err().contains("--progress"),
                "{bad}"
            );
        }
        let e = parse(&args("case.h5 --progress json --verbose")).unwrap_err();
        assert!(e.contains("--verbose") && e.contains("run.log"), "{e}");
    }

    #[test]
    fn new_with_sets() {
        let c = parse(&args(
            "new cantilever -o c.h5 --set mesh.h=0.25 --set steps.count=5",
        ))
        .unwrap();
        assert_eq!(
            c,
            Command::New {
                scene: "cantilever".into(),
                out: "c.h5".into(),
                sets: args("mesh.h=0.25 steps.count=5")
            }
        );
    }

    #[test]
    fn errors_name_the_problem() {
        assert!(parse(&args("new cantilever")).unwrap_err().contains("-o"));
        assert!(parse(&args("case.h5 --until-step x"))
            .unwrap_err()
            .contains("--until-step"));
        assert!(parse(&args("case.h5 -snes_monitor"))
            .unwrap_err()
            .contains("after --"));
    }

    #[test]
    fn out_dir_of_case_and_checkpoint() {
        assert_eq!(
            default_out_dir("a/case.h5".as_ref()),
            PathBuf::from("a/case.out")
        );
        assert_eq!(
            default_out_dir("a/case.out/checkpoints/step_000010.h5".as_ref()),
            PathBuf::from("a/case.out")
        );
        assert_eq!(
            default_out_dir("checkpoints/step_000010.h5".as_ref()),
            PathBuf::from(".")
        );
    }
}
