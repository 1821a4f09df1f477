//! What an axisymmetric scene must be: a meridian section at r = x ≥ 0, loaded and moved
//! symmetrically about the axis. A body reaching x < 0 would be a ring of negative radius, a
//! radial gravity or a rigid body moving sideways would break the symmetry the analysis
//! assumes; each is an error naming the field rather than a run that means nothing.

use super::field_path::FieldPath;
use super::schema::{MaterialModel, Scene};
use super::validate::Invalid;

/// Checks an axisymmetric scene (nothing for plane strain).
pub fn check(s: &Scene) -> Result<(), Invalid> {
    if !s.analysis.has_hoop() {
        return Ok(());
    }
    let tol = s.tolerance();
    let [lo, _] = s.bounding_box();
    if lo[0] < -tol {
        return Err((
            FieldPath::key("body"),
            format!(
                "reaches x = {} but `analysis = \"axisymmetric\"` takes x as the radius: \
                 draw the meridian section at x >= 0, with the axis at x = 0",
                lo[0]
            ),
        ));
    }
    if s.gravity.g[0] != 0.0 {
        return Err((
            FieldPath::key("gravity").join("g"),
            format!(
                "has a radial component {} in an axisymmetric scene: gravity must be along \
                 the axis (g = [0, gy])",
                s.gravity.g[0]
            ),
        ));
    }
    let all = s.material.all();
    for (i, m) in all.iter().enumerate() {
        if m.model == MaterialModel::TrescaSoftening {
            let at = if all.len() == 1 {
                FieldPath::key("material")
            } else {
                FieldPath::key("material").at(i)
            };
            return Err((
                at.join("model"),
                "\"tresca-softening\" judges the largest in-plane shear (plane strain) and is not \
                 yet written in full principal stresses, which axisymmetry needs (the hoop stress \
                 can be the largest or the smallest): use \"tresca\" or a plane-strain scene"
                    .to_string(),
            ));
        }
    }
    for (i, body) in s.rigid.iter().enumerate() {
        for (j, stage) in body.stages.iter().enumerate() {
            if stage.to[0] != 0.0 {
                return Err((
                    FieldPath::key("rigid")
                        .at(i)
                        .join("stages")
                        .at(j)
                        .join("to"),
                    format!(
                        "moves the body {} radially: in an axisymmetric scene a rigid body \
                         of revolution moves along the axis only (to = [0, dy])",
                        stage.to[0]
                    ),
                ));
            }
        }
    }
    Ok(())
}
