//! The `/particles` datasets: their names, element types and widths, creation for writing,
//! and the checks made before any particle data is read.

use std::path::Path;

use hdf5::types::TypeDescriptor;
use hdf5::{Dataset, File, Group, H5Type};

use super::error::{CaseError, CaseErrorKind};
use crate::material::STRESS_LEN;

pub const GROUP: &str = "particles";

/// One dataset: `width` 0 means a 1-D array of n values, otherwise an n x width matrix.
pub struct Column {
    pub name: &'static str,
    pub width: usize,
    pub dtype: TypeDescriptor,
}

/// The particle datasets, in the order they are written and checked, with state rows of
/// `state_width` (the material's layout).
pub fn columns(state_width: usize) -> [Column; 7] {
    let col = |name, width, dtype| Column { name, width, dtype };
    [
        col("gid", 0, u64::type_descriptor()),
        col("position", 2, f64::type_descriptor()),
        col("displacement", 2, f64::type_descriptor()),
        col("h", 0, f64::type_descriptor()),
        col("state", state_width, f64::type_descriptor()),
        col("flags", 0, u32::type_descriptor()),
        col("increment", 2, f64::type_descriptor()),
    ]
}

/// `/particles/material` (u32, n): each particle's index in the scene's `[[material]]` list.
/// Written by every version-2 program; a file without it (version 1) has one material.
pub fn material_column() -> Column {
    Column {
        name: "material",
        width: 0,
        dtype: u32::type_descriptor(),
    }
}

/// Bytes of raw data per particle over all datasets.
pub fn bytes_per_particle(state_width: usize) -> u64 {
    columns(state_width)
        .iter()
        .chain([&material_column()])
        .map(|c| (c.width.max(1) * c.dtype.size()) as u64)
        .sum()
}

/// Creates the (contiguous, fixed-size) dataset of `c` for `n` particles.
pub fn create<T: H5Type>(group: &Group, c: &Column, n: usize) -> hdf5::Result<Dataset> {
    if c.width == 0 {
        group.new_dataset::<T>().shape(n).create(c.name)
    } else {
        group.new_dataset::<T>().shape((n, c.width)).create(c.name)
    }
}

fn shape_text(shape: &[usize]) -> String {
    let parts: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    format!("({})", parts.join(", "))
}

/// Opens every particle dataset and checks type and shape; returns them in `columns()` order
/// with the particle count and the width of the state rows (the writer's layout, at least the
/// stress).
pub fn open_all(file: &File, path: &Path) -> Result<(Vec<Dataset>, u64, usize), CaseError> {
    let bad = |name: &str, message: String| {
        CaseError::new(path, CaseErrorKind::Malformed, message)
            .at(format!("dataset /{GROUP}/{name}"))
    };
    let group = file.group(GROUP).map_err(|_| {
        CaseError::new(path, CaseErrorKind::Malformed, "missing").at(format!("group /{GROUP}"))
    })?;
    let width = match group.dataset("state").map(|d| d.shape()) {
        Ok(s) if s.len() == 2 && s[1] >= STRESS_LEN => s[1],
        Ok(s) => {
            return Err(bad(
                "state",
                format!(
                    "expected shape (n, >= {STRESS_LEN}), found {}",
                    shape_text(&s)
                ),
            ))
        }
        Err(_) => return Err(bad("state", "missing".to_string())),
    };
    let mut out = Vec::new();
    let mut n: Option<u64> = None;
    for c in columns(width) {
        let ds = group
            .dataset(c.name)
            .map_err(|_| bad(c.name, "missing".to_string()))?;
        let found = ds
            .dtype()
            .and_then(|t| t.to_descriptor())
            .map_err(|e| bad(c.name, format!("unreadable type: {e}")))?;
        if found != c.dtype {
            return Err(bad(
                c.name,
                format!("expected type {}, found {found}", c.dtype),
            ));
        }
        let shape = ds.shape();
        let ok = if c.width == 0 {
            shape.len() == 1
        } else {
            shape.len() == 2 && shape[1] == c.width
        };
        if !ok {
            let expected = if c.width == 0 {
                "(n)".to_string()
            } else {
                format!("(n, {})", c.width)
            };
            return Err(bad(
                c.name,
                format!("expected shape {expected}, found {}", shape_text(&shape)),
            ));
        }
        let rows = shape[0] as u64;
        match n {
            None => n = Some(rows),
            Some(n0) if n0 != rows => {
                return Err(bad(
                    c.name,
                    format!("has {rows} particles but /{GROUP}/gid has {n0}"),
                ));
            }
            Some(_) => {}
        }
        let need = rows * (c.width.max(1) * c.dtype.size()) as u64;
        if ds.storage_size() < need {
            return Err(bad(
                c.name,
                format!(
                    "holds {} of {need} bytes: the file was not completely written",
                    ds.storage_size()
                ),
            ));
        }
        out.push(ds);
    }
    let n = n.unwrap_or(0);
    let file_len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(u64::MAX);
    let need = n.saturating_mul(bytes_per_particle(width));
    if need > file_len {
        return Err(CaseError::new(
            path,
            CaseErrorKind::Malformed,
            format!("truncated: {n} particles need {need} bytes but the file has {file_len}"),
        ));
    }
    Ok((out, n, width))
}
