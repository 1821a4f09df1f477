//! The `names` attribute of `/particles/state` and `/gauss/state`: one name per column of a
//! state row, as the material lays it out ([`crate::material::StateLayout::columns`]). A reader
//! matches columns by name, so a file keeps its meaning whatever layout the program has now.
//! Version-1 files have no attribute: their rows are the nine scalars every model stored then.

use hdf5::types::VarLenUnicode;
use hdf5::Dataset;

use crate::material::Rows;

/// Name of the attribute on the state datasets.
pub const ATTR: &str = "names";

/// The columns of every state row of a version-1 file (stress, plastic strain, `eps_q`).
pub fn version_1() -> Vec<String> {
    [
        "stress_xx",
        "stress_yy",
        "stress_zz",
        "stress_xy",
        "plastic_strain_xx",
        "plastic_strain_yy",
        "plastic_strain_zz",
        "plastic_strain_xy",
        "eps_q",
    ]
    .map(String::from)
    .to_vec()
}

/// Writes the names (collective under MPI-IO: every rank passes the same names).
pub fn put(ds: &Dataset, names: &[String]) -> hdf5::Result<()> {
    let values = names
        .iter()
        .map(|n| {
            n.parse::<VarLenUnicode>()
                .map_err(|e| hdf5::Error::Internal(format!("attribute {ATTR}: {e}")))
        })
        .collect::<hdf5::Result<Vec<_>>>()?;
    ds.new_attr::<VarLenUnicode>()
        .shape(values.len())
        .create(ATTR)?
        .write(&values)
}

/// The stored names, None when the attribute is absent.
pub fn stored(ds: &Dataset) -> Option<hdf5::Result<Vec<String>>> {
    let attr = ds.attr(ATTR).ok()?;
    Some(
        attr.read_raw::<VarLenUnicode>()
            .map(|v| v.iter().map(|s| s.as_str().to_string()).collect()),
    )
}

/// Rows whose points (`points` per row) are laid out as `from`, rearranged to `to`: each column
/// taken by name. A column of `to` that `from` lacks is an error, unless `fill` (a version-1
/// file, whose models had no other variables): it then starts at zero. A column of `from` that
/// `to` lacks must be zero everywhere (an elastic scene's unused plastic fields in a version-1
/// file); anything else would lose state, which is an error naming the column.
pub fn conform(
    rows: Rows,
    points: usize,
    from: &[String],
    to: &[String],
    fill: bool,
) -> Result<Rows, String> {
    if rows.is_empty() {
        return Ok(Rows::new(points * to.len()));
    }
    if rows.width() != points * from.len() {
        return Err(format!(
            "has {} columns but its `{ATTR}` attribute names {} per point ({} points a row)",
            rows.width(),
            from.len(),
            points
        ));
    }
    if from == to {
        return Ok(rows);
    }
    let mut source = Vec::with_capacity(to.len());
    for name in to {
        match from.iter().position(|f| f == name) {
            Some(k) => source.push(Some(k)),
            None if fill => source.push(None),
            None => {
                return Err(format!(
                    "has no column `{name}`, which the scene's material keeps (columns: {})",
                    from.join(", ")
                ))
            }
        }
    }
    for (k, name) in from.iter().enumerate() {
        if to.contains(name) {
            continue;
        }
        let nonzero = rows
            .iter()
            .any(|r| (0..points).any(|q| r[q * from.len() + k] != 0.0));
        if nonzero {
            return Err(format!(
                "column `{name}` is not zero, but the scene's material does not keep it"
            ));
        }
    }
    let mut out = Rows::with_capacity(points * to.len(), rows.len());
    let mut row = vec![0.0; points * to.len()];
    for r in rows.iter() {
        for q in 0..points {
            for (j, s) in source.iter().enumerate() {
                row[q * to.len() + j] = s.map_or(0.0, |k| r[q * from.len() + k]);
            }
        }
        out.push(&row);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(n: &[&str]) -> Vec<String> {
        n.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn an_elastic_scene_drops_the_zero_plastic_columns_of_version_1() {
        let v1 = version_1();
        let mut row = [0.0; 9];
        row[..4].copy_from_slice(&[1.0, 2.0, 3.0, 4.0]);
        let rows = Rows::from_flat(9, row.to_vec());
        let to = names(&["stress_xx", "stress_yy", "stress_zz", "stress_xy"]);
        let out = conform(rows.clone(), 1, &v1, &to, true).unwrap();
        assert_eq!(out.as_flat(), &[1.0, 2.0, 3.0, 4.0]);
        let mut plastic = rows.into_flat();
        plastic[8] = 1e-3;
        let e = conform(Rows::from_flat(9, plastic), 1, &v1, &to, true).unwrap_err();
        assert!(e.contains("eps_q"), "{e}");
    }

    #[test]
    fn columns_are_matched_by_name_per_point() {
        let from = names(&["stress_xx", "stress_yy", "stress_zz", "stress_xy", "a", "b"]);
        let to = names(&["stress_xx", "stress_yy", "stress_zz", "stress_xy", "b", "a"]);
        let flat: Vec<f64> = (0..12).map(f64::from).collect();
        let out = conform(Rows::from_flat(12, flat), 2, &from, &to, false).unwrap();
        assert_eq!(
            out.as_flat(),
            &[0.0, 1.0, 2.0, 3.0, 5.0, 4.0, 6.0, 7.0, 8.0, 9.0, 11.0, 10.0]
        );
        let more = names(&["stress_xx", "stress_yy", "stress_zz", "stress_xy", "c"]);
        let e = conform(Rows::zeros(6, 1), 1, &from, &more, false).unwrap_err();
        assert!(e.contains("`c`"), "{e}");
        let e = conform(Rows::zeros(5, 1), 1, &from, &to, false).unwrap_err();
        assert!(e.contains("5 columns"), "{e}");
    }
}
