//! `history.csv`: one row per step with the scene's normalised load–displacement measures.
//! The column names are a public interface (README, "Output").

use crate::scene::{HistoryKind, Measure, Scene};
use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};

/// The header of `history.csv`: `step`, the kind's columns, then the declared ones.
pub fn header(scene: &Scene) -> Vec<String> {
    let mut h: Vec<String> = match scene.history.kind {
        Some(kind) => columns(kind).iter().map(|c| c.to_string()).collect(),
        None => vec!["step".to_string()],
    };
    h.extend(scene.history.columns.iter().map(|c| c.name.clone()));
    h
}

pub fn columns(kind: HistoryKind) -> &'static [&'static str] {
    match kind {
        HistoryKind::Cantilever => &["step", "lambda", "u_over_L", "v_over_L"],
        HistoryKind::Footing => &["step", "z_over_B", "q_over_cu"],
        HistoryKind::Block => &["step", "strain", "stress_over_cu", "volume_ratio"],
    }
}

/// Global measurements of a step, gathered by the driver.
#[derive(Debug, Clone, Default)]
pub struct Measures {
    pub load_factor: f64,
    pub time: f64,
    /// Total displacement of each `[[probe]]` particle, in scene order.
    pub probes: Vec<[f64; 2]>,
    /// Displacement and force (soil on body) of each `[[rigid]]` body, in scene order.
    pub rigid_displacement: Vec<[f64; 2]>,
    pub rigid_force: Vec<[f64; 2]>,
    /// Reaction on each `[[fixed]]` entry, then each `[[prescribed]]` entry, in scene order.
    pub set_reactions: Vec<[f64; 2]>,
    /// Total displacement of the first tracked particle.
    pub tracked_displacement: [f64; 2],
    /// Force on the particles of the first `[[prescribed]]` entry (footing, top platen).
    pub reaction: [f64; 2],
    /// Area of the body (m² per metre).
    pub area: f64,
    /// Current horizontal extent of the particles of the first `[[prescribed]]` entry.
    pub driven_width: f64,
    /// Current right end of that extent.
    pub driven_right: f64,
}

/// Normalised values of a row (after `step`): the kind's, then the declared columns.
pub fn row(scene: &Scene, m: &Measures) -> Result<Vec<f64>, String> {
    let mut values = match scene.history.kind {
        Some(kind) => kind_row(scene, kind, m)?,
        None => Vec::new(),
    };
    // A declared value that is not a number is a result no one can use: the run stops on it.
    // (The legacy kinds' columns stay as they were: `block`'s stress over cu is infinite for
    // an elastic block, cu = 0, by its definition.)
    for (i, c) in scene.history.columns.iter().enumerate() {
        let v = declared(scene, m, &c.measure)?;
        let value = c.scale * v;
        if !value.is_finite() {
            return Err(format!(
                "history.csv column {} would be {value}: history.columns[{i}].scale = {:e} times \
                 {} = {v:e}; give a scale that keeps it finite",
                c.name, c.scale, c.measure
            ));
        }
        values.push(value);
    }
    Ok(values)
}

/// Value of a declared measure (validated names; a missing entry is an error, not a zero).
fn declared(scene: &Scene, m: &Measures, measure: &str) -> Result<f64, String> {
    let find = |list: Vec<Option<&String>>, name: &str| {
        list.iter().position(|n| n.is_some_and(|n| n == name))
    };
    let missing = || format!("history measure \"{measure}\" names nothing in the scene");
    Ok(match Measure::parse(measure)? {
        Measure::LoadFactor => m.load_factor,
        Measure::Time => m.time,
        Measure::Area => m.area,
        Measure::Probe(name, c) => {
            let i = scene
                .probe
                .iter()
                .position(|p| p.name == name)
                .ok_or_else(missing)?;
            m.probes.get(i).ok_or_else(missing)?[c]
        }
        Measure::RigidDisplacement(name, c) => {
            let i = scene
                .rigid
                .iter()
                .position(|r| r.name == name)
                .ok_or_else(missing)?;
            m.rigid_displacement.get(i).ok_or_else(missing)?[c]
        }
        Measure::RigidForce(names, c) => {
            let mut sum = 0.0;
            for name in names {
                let i = scene
                    .rigid
                    .iter()
                    .position(|r| r.name == name)
                    .ok_or_else(missing)?;
                sum += m.rigid_force.get(i).ok_or_else(missing)?[c];
            }
            sum
        }
        Measure::Reaction(name, c) => {
            let names: Vec<Option<&String>> = scene
                .fixed
                .iter()
                .map(|f| f.name.as_ref())
                .chain(scene.prescribed.iter().map(|p| p.name.as_ref()))
                .collect();
            let i = find(names, &name).ok_or_else(missing)?;
            m.set_reactions.get(i).ok_or_else(missing)?[c]
        }
    })
}

fn kind_row(scene: &Scene, kind: HistoryKind, m: &Measures) -> Result<Vec<f64>, String> {
    match kind {
        HistoryKind::Cantilever => {
            let beam = scene
                .body
                .rectangles
                .first()
                .ok_or("body.rectangles: empty")?;
            let load = scene
                .point_load
                .first()
                .ok_or("history.kind = \"cantilever\" needs a [[point_load]]")?;
            let (l, d) = (beam.size[0], beam.size[1]);
            let ei = scene.material.young * d.powi(3) / 12.0;
            let p = (load.force[0].powi(2) + load.force[1].powi(2)).sqrt();
            Ok(vec![
                m.load_factor * p * l * l / ei,
                -m.tracked_displacement[0] / l,
                -m.tracked_displacement[1] / l,
            ])
        }
        HistoryKind::Footing => {
            // Half model: the footing runs from the symmetry plane (the body's left side) to the
            // prescribed region's right end. q is the mean pressure F / B on the full footing,
            // with B its current width: the smooth footing's particles spread sideways as the soil
            // under it flows out, and the force is carried over their current extent.
            let p = scene
                .prescribed
                .first()
                .ok_or("history.kind = \"footing\" needs a [[prescribed]]")?;
            let [[x0, _], [x1, _]] = scene.bounding_box();
            let half = p.region.interval(crate::scene::Axis::X).1.min(x1) - x0;
            let b = 2.0 * half;
            let z = -m.load_factor * p.total[1];
            let half_now = if m.driven_right > x0 {
                m.driven_right - x0
            } else {
                half
            };
            Ok(vec![z / b, -m.reaction[1] / half_now / scene.material.cu])
        }
        HistoryKind::Block => {
            let [[_, y0], [_, y1]] = scene.bounding_box();
            let h0 = y1 - y0;
            let closing: f64 = scene.prescribed.iter().map(|p| p.total[1].abs()).sum();
            let area0: f64 = scene
                .body
                .rectangles
                .iter()
                .map(|r| r.size[0] * r.size[1])
                .sum();
            let stress = -m.reaction[1] / m.driven_width;
            Ok(vec![
                m.load_factor * closing / h0,
                stress / scene.material.cu,
                m.area / area0,
            ])
        }
    }
}

/// Appends rows to `DIR/history.csv`; on a restart from step k it keeps rows up to k.
pub struct HistoryFile {
    file: File,
    pub path: PathBuf,
    /// Bytes of whole rows in the file.
    len: u64,
}

impl HistoryFile {
    pub fn open(dir: &Path, scene: &Scene, restart_step: u64) -> Result<HistoryFile, String> {
        let path = dir.join("history.csv");
        let header = header(scene).join(",");
        let mut kept = vec![header.clone()];
        if restart_step > 0 && path.exists() {
            let f = File::open(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            let mut lines = BufReader::new(f).lines();
            match lines.next() {
                Some(Ok(h)) if h == header => {}
                _ => {
                    return Err(format!(
                        "{}: columns differ from {header:?}; move it away to restart here",
                        path.display()
                    ))
                }
            }
            for line in lines {
                let line = line.map_err(|e| format!("{}: {e}", path.display()))?;
                let step: Option<u64> = line.split(',').next().and_then(|s| s.trim().parse().ok());
                if matches!(step, Some(s) if s <= restart_step) {
                    kept.push(line);
                }
            }
        }
        let text = kept.join("\n") + "\n";
        crate::output::replace_file(&path, text.as_bytes())
            .map_err(|m| format!("{}: {m}", path.display()))?;
        let file = OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(HistoryFile {
            file,
            path,
            len: text.len() as u64,
        })
    }

    /// Appends the row of `step`. A row that cannot be written whole is cut off again, so the
    /// file never ends in a partial row.
    pub fn append(&mut self, step: u64, values: &[f64]) -> Result<(), String> {
        let mut line = step.to_string();
        for v in values {
            // Shortest representation that reads back to the same f64: runs compare bit for bit.
            line.push_str(&format!(",{v:e}"));
        }
        line.push('\n');
        match self.file.write_all(line.as_bytes()) {
            Ok(()) => {
                self.len += line.len() as u64;
                Ok(())
            }
            Err(e) => {
                let cut = match self.file.set_len(self.len) {
                    Ok(()) => String::new(),
                    Err(c) => format!(" (and the partial row could not be cut off: {c})"),
                };
                Err(format!(
                    "{}: cannot append the row of step {step}: {e}{cut}",
                    self.path.display()
                ))
            }
        }
    }
}
