//! The text of `pfem-mpi info FILE.h5`.

use std::fmt::Write;
use std::path::Path;

use super::{CaseHeader, FORMAT};
use crate::scene::Scene;

/// A number for people: plain decimals at ordinary magnitudes, exponent form otherwise.
fn num(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || (1e-3..1e6).contains(&a) {
        let s = format!("{x:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".to_string()
        } else {
            s.to_string()
        }
    } else {
        format!("{x:.4e}")
    }
}

fn pair(p: [f64; 2]) -> String {
    format!("({}, {})", num(p[0]), num(p[1]))
}

pub fn render(
    path: &Path,
    h: &CaseHeader,
    n: u64,
    gid: &[u64],
    position: &[[f64; 2]],
    displacement: &[[f64; 2]],
) -> String {
    let mut s = String::new();
    let mut line = |label: &str, text: String| {
        let _ = writeln!(s, "{label:<14}{text}");
    };
    line("file", path.display().to_string());
    line(
        "format",
        format!(
            "{FORMAT}, version {}, written by pfem-mpi {} on {} rank{}",
            h.format_version,
            h.code_version,
            h.ranks,
            if h.ranks == 1 { "" } else { "s" }
        ),
    );
    let scene = Scene::from_toml(&h.scene_toml, &h.scene_source, &[]);
    match &scene {
        Ok(sc) => {
            line("scene", format!("{} (from {})", sc.name, h.scene_source));
            line("analysis", sc.analysis.name().to_string());
            for m in sc.material.all() {
                let mut model = match &m.name {
                    Some(n) => format!("\"{n}\": "),
                    None => String::new(),
                };
                let _ = write!(
                    model,
                    "{}, E = {} Pa, nu = {}",
                    m.model.as_str(),
                    num(m.young),
                    num(m.poisson)
                );
                if m.model.undrained() {
                    let _ = write!(model, ", cu = {} Pa", num(m.cu));
                    if m.cu_gradient != 0.0 {
                        let level = m.reference_level.unwrap_or(f64::NAN);
                        let _ = write!(
                            model,
                            " growing {} Pa/m below y = {} m",
                            num(m.cu_gradient),
                            num(level)
                        );
                    }
                    if let Some(ratio) = m.young_over_cu {
                        let _ = write!(model, ", E = {} cu at every point", num(ratio));
                    }
                }
                if let (Some(c), Some(phi), Some(psi)) =
                    (m.cohesion, m.friction_angle, m.dilation_angle)
                {
                    let _ = write!(
                        model,
                        ", c = {} Pa, phi = {} deg, psi = {} deg",
                        num(c),
                        num(phi),
                        num(psi)
                    );
                }
                if let (Some(d), Some(x)) = (m.remoulded_ratio, m.xi95) {
                    let _ = write!(model, ", remoulded {} cu by xi95 = {}", num(d), num(x));
                    if let Some(h) = m.xi95_reference_spacing {
                        let _ = write!(model, " at h = {} m (scaled h_ref/h)", num(h));
                    }
                }
                if let (Some(mu), Some(r)) = (m.rate_parameter, m.reference_rate) {
                    let _ = write!(model, ", +{} per decade above {} 1/s", num(mu), num(r));
                }
                if let Some(t) = m.tension_cutoff {
                    let _ = write!(model, ", tension cut-off {} Pa", num(t));
                }
                if let Some(f) = m.cone_match {
                    let _ = write!(model, ", {f:?} match");
                }
                line("material", model);
            }
            let mut mesh = format!("h = {} m, alpha = {}", num(sc.mesh.h), num(sc.mesh.alpha));
            if let Some(a) = &sc.mesh.adapt {
                let _ = write!(
                    mesh,
                    ", adapted between h = {} and {} m after every {} step(s)",
                    num(a.h_min),
                    num(a.h_max),
                    a.every
                );
            }
            line("mesh", mesh);
            line(
                "progress",
                format!(
                    "step {} of {}, load factor {}, time {}",
                    h.step,
                    sc.steps.count,
                    num(h.load_factor),
                    num(h.time)
                ),
            );
        }
        Err(e) => {
            line(
                "scene",
                format!("from {} (cannot be read: {e})", h.scene_source),
            );
            line(
                "progress",
                format!(
                    "step {}, load factor {}, time {}",
                    h.step,
                    num(h.load_factor),
                    num(h.time)
                ),
            );
        }
    }
    line("particles", format!("{n} (next gid {})", h.next_gid));
    if let Some(first) = position.first() {
        let bb = position.iter().fold([*first, *first], |bb, p| {
            [
                [bb[0][0].min(p[0]), bb[0][1].min(p[1])],
                [bb[1][0].max(p[0]), bb[1][1].max(p[1])],
            ]
        });
        line(
            "bounding box",
            format!(
                "x {} .. {}, y {} .. {} (m, current positions)",
                num(bb[0][0]),
                num(bb[1][0]),
                num(bb[0][1]),
                num(bb[1][1])
            ),
        );
    }
    let largest = displacement
        .iter()
        .enumerate()
        .map(|(i, u)| (i, u[0].hypot(u[1])))
        .fold(None, |best: Option<(usize, f64)>, (i, m)| match best {
            Some((_, bm)) if bm >= m => best,
            _ => Some((i, m)),
        });
    if let Some((i, m)) = largest {
        line(
            "displacement",
            format!("max |u| = {} m at gid {}", num(m), gid[i]),
        );
    }
    for (k, g) in h.tracked_gids.iter().enumerate() {
        let text = match gid.iter().position(|x| x == g) {
            Some(i) => format!(
                "point_load[{k}]: gid {g} at {}, u = {}",
                pair(position[i]),
                pair(displacement[i])
            ),
            None => format!("point_load[{k}]: gid {g} (no longer present)"),
        };
        line("tracked", text);
    }
    s
}
