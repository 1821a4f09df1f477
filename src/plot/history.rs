//! Reading `history.csv`, whose header tells the scene kind (columns as in `crate::history`).

use std::path::Path;

use super::PlotError;

/// Scene kind of a history, told by its columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Cantilever,
    Footing,
    Block,
}

impl Kind {
    const ALL: [Kind; 3] = [Kind::Cantilever, Kind::Footing, Kind::Block];

    /// The header of this kind's file, column by column.
    fn columns(self) -> &'static [&'static str] {
        match self {
            Kind::Cantilever => &["step", "lambda", "u_over_L", "v_over_L"],
            Kind::Footing => &["step", "z_over_B", "q_over_cu"],
            Kind::Block => &["step", "strain", "stress_over_cu", "volume_ratio"],
        }
    }
}

/// The rows of a history file.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct History {
    pub kind: Kind,
    /// One row per step, every column of [`Kind::columns`], `step` included.
    pub rows: Vec<Vec<f64>>,
}

impl History {
    /// The curve of column `y` against column `x` (names of [`Kind::columns`]), in file order.
    /// Points with a non-finite value (a step that diverged writes NaN) are left out.
    pub fn curve(&self, x: &str, y: &str) -> Vec<(f64, f64)> {
        let index = |name: &str| self.kind.columns().iter().position(|c| *c == name);
        let (Some(ix), Some(iy)) = (index(x), index(y)) else {
            return Vec::new();
        };
        self.rows
            .iter()
            .map(|r| (r[ix], r[iy]))
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .collect()
    }
}

/// Reads the history file `path`. A file with a header and no rows is valid (a run stopped
/// before its first step).
pub(crate) fn read(path: &Path) -> Result<History, PlotError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| PlotError::new(path, format!("cannot read: {e}")))?;
    parse(&text).map_err(|m| PlotError::new(path, m))
}

fn parse(text: &str) -> Result<History, String> {
    let mut lines = text.lines().enumerate();
    let header = lines
        .next()
        .map(|(_, h)| h.trim())
        .ok_or("empty file, expected a header line")?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let kind = Kind::ALL
        .into_iter()
        .find(|k| k.columns() == names.as_slice())
        .ok_or_else(|| {
            let known: Vec<String> = Kind::ALL
                .iter()
                .map(|k| format!("\"{}\"", k.columns().join(",")))
                .collect();
            format!(
                "unknown columns \"{header}\"; expected one of {}",
                known.join(", ")
            )
        })?;
    let columns = kind.columns();
    let mut rows = Vec::new();
    for (index, line) in lines {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let number = index + 1;
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != columns.len() {
            return Err(format!(
                "line {number}: {} values for {} columns",
                cells.len(),
                columns.len()
            ));
        }
        let row = cells
            .iter()
            .zip(columns)
            .map(|(cell, name)| {
                cell.parse::<f64>().map_err(|_| {
                    format!("line {number}: \"{cell}\" in column {name} is not a number")
                })
            })
            .collect::<Result<Vec<f64>, String>>()?;
        rows.push(row);
    }
    Ok(History { kind, rows })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_are_told_by_their_columns() {
        let h = parse("step,z_over_B,q_over_cu\r\n1,0.01,2.5\r\n2,0.02,NaN\r\n\r\n").unwrap();
        assert_eq!(h.kind, Kind::Footing);
        assert_eq!(h.rows.len(), 2);
        assert_eq!(h.curve("z_over_B", "q_over_cu"), vec![(0.01, 2.5)]);
        assert!(h.curve("lambda", "q_over_cu").is_empty());
        let h = parse("step, strain, stress_over_cu, volume_ratio\n").unwrap();
        assert_eq!(h.kind, Kind::Block);
        assert!(h.rows.is_empty());
    }

    #[test]
    fn malformed_files_say_where() {
        assert!(parse("").unwrap_err().contains("empty file"));
        assert!(parse("step,x\n").unwrap_err().contains("unknown columns"));
        let e = parse("step,z_over_B,q_over_cu\n1,0.1\n").unwrap_err();
        assert!(e.contains("line 2: 2 values for 3 columns"), "{e}");
        let e = parse("step,z_over_B,q_over_cu\n1,0.1,2\n2,x,3\n").unwrap_err();
        assert!(e.contains("line 3: \"x\" in column z_over_B"), "{e}");
    }
}
