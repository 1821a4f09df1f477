//! Reading `history.csv`: a header of column names, `step` first (`crate::history::header`),
//! then one row of numbers per step.

use std::path::Path;

use crate::scene::HistoryKind;

use super::PlotError;

/// The legacy kinds, whose headers are fixed (`crate::history::columns`).
const KINDS: [HistoryKind; 3] = [
    HistoryKind::Cantilever,
    HistoryKind::Footing,
    HistoryKind::Block,
];

/// Largest magnitude drawn. A value beyond it is a step that blew up, not a result to read off a
/// chart; and drawing it would fail: plotters computes axis ticks forever on an infinite range
/// (1e308 - -1e308 overflows) and its line rasteriser overflows on points far off the chart.
pub(crate) const DRAWABLE: f64 = 1e100;

/// Whether `v` can be drawn: finite and within [`DRAWABLE`].
pub(crate) fn drawable(v: f64) -> bool {
    v.is_finite() && v.abs() <= DRAWABLE
}

/// The columns and rows of a history file.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct History {
    /// Column names, `step` first.
    pub names: Vec<String>,
    /// One row per step, a value for every column, `step` included.
    pub rows: Vec<Vec<f64>>,
}

impl History {
    /// The legacy kind whose columns are exactly this header's, if any. A scene that declares
    /// columns of the same names writes the same header, so this alone does not tell which
    /// picture to draw (see `history_picture`).
    pub fn legacy_kind(&self) -> Option<HistoryKind> {
        KINDS
            .into_iter()
            .find(|&k| crate::history::columns(k).iter().eq(self.names.iter()))
    }

    /// Index of the column `name`.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// Every value of column `index`, in file order.
    pub fn column(&self, index: usize) -> Vec<f64> {
        self.rows.iter().map(|r| r[index]).collect()
    }

    /// The curve of column `y` against column `x` (by name), in file order.
    pub fn curve(&self, x: &str, y: &str) -> Vec<(f64, f64)> {
        match (self.index(x), self.index(y)) {
            (Some(ix), Some(iy)) => self.curve_at(ix, iy),
            _ => Vec::new(),
        }
    }

    /// The curve of column `iy` against column `ix`, in file order. Points with a value that
    /// cannot be [`drawable`] (a step that diverged writes NaN) are left out.
    pub fn curve_at(&self, ix: usize, iy: usize) -> Vec<(f64, f64)> {
        self.rows
            .iter()
            .map(|r| (r[ix], r[iy]))
            .filter(|&(a, b)| drawable(a) && drawable(b))
            .collect()
    }

    /// How many finite values lie beyond [`DRAWABLE`], and the first of them as
    /// `line L, column C = V`, for the warning that they are left out of the picture.
    pub fn undrawable(&self) -> Option<(usize, String)> {
        let mut found = self.rows.iter().enumerate().flat_map(|(r, row)| {
            row.iter()
                .enumerate()
                .filter(|(_, v)| v.is_finite() && !drawable(**v))
                .map(move |(c, v)| (r, c, *v))
        });
        let (r, c, v) = found.next()?;
        // The header is line 1; blank lines are not counted, so this is the row's place.
        let first = format!("row {}, column {} = {v:e}", r + 1, self.names[c]);
        Some((1 + found.count(), first))
    }
}

/// Reads the history file `path`. A file with a header and no rows is valid (a run stopped
/// before its first step).
pub(crate) fn read(path: &Path) -> Result<History, PlotError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| PlotError::new(path, format!("cannot read: {e}")))?;
    parse(&text).map_err(|m| PlotError::new(path, m))
}

pub(crate) fn parse(text: &str) -> Result<History, String> {
    let mut lines = text.lines().enumerate();
    let header = lines
        .next()
        .map(|(_, h)| h.trim())
        .ok_or("empty file, expected a header line")?;
    let names: Vec<String> = header.split(',').map(|n| n.trim().to_string()).collect();
    // Every history this code writes starts with `step`; anything else is not one of ours.
    if names[0] != "step" {
        return Err(format!(
            "unknown columns \"{header}\"; expected \"step\" first, then the scene's columns"
        ));
    }
    if let Some(k) = names.iter().position(String::is_empty) {
        return Err(format!("column {} of the header has no name", k + 1));
    }
    let mut rows = Vec::new();
    for (index, line) in lines {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let number = index + 1;
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != names.len() {
            return Err(format!(
                "line {number}: {} values for {} columns",
                cells.len(),
                names.len()
            ));
        }
        let row = cells
            .iter()
            .zip(&names)
            .map(|(cell, name)| {
                cell.parse::<f64>().map_err(|_| {
                    format!("line {number}: \"{cell}\" in column {name} is not a number")
                })
            })
            .collect::<Result<Vec<f64>, String>>()?;
        rows.push(row);
    }
    Ok(History { names, rows })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn legacy_kinds_are_told_by_their_columns() {
        let h = parse("step,z_over_B,q_over_cu\r\n1,0.01,2.5\r\n2,0.02,NaN\r\n\r\n").unwrap();
        assert_eq!(h.legacy_kind(), Some(HistoryKind::Footing));
        assert_eq!(h.rows.len(), 2);
        assert_eq!(h.curve("z_over_B", "q_over_cu"), vec![(0.01, 2.5)]);
        assert!(h.curve("lambda", "q_over_cu").is_empty());
        let h = parse("step, strain, stress_over_cu, volume_ratio\n").unwrap();
        assert_eq!(h.legacy_kind(), Some(HistoryKind::Block));
        assert!(h.rows.is_empty());
        let h = parse("step,lambda,u_over_L,v_over_L\n").unwrap();
        assert_eq!(h.legacy_kind(), Some(HistoryKind::Cantilever));
        // A legacy header with a declared column after it is no legacy kind.
        let h = parse("step,z_over_B,q_over_cu,area\n").unwrap();
        assert_eq!(h.legacy_kind(), None);
    }

    #[test]
    fn declared_headers_are_read_by_name() {
        let h = parse(
            "step,uy_over_D,ux_over_D,V_over_Dcu,H_over_Dcu\n\
             1,0.01,0,0.9,0\n2,0.02,0,1.7,-0.5e-3\n",
        )
        .unwrap();
        assert_eq!(
            h.names,
            ["step", "uy_over_D", "ux_over_D", "V_over_Dcu", "H_over_Dcu"]
        );
        assert_eq!(h.legacy_kind(), None);
        assert_eq!(h.index("V_over_Dcu"), Some(3));
        assert_eq!(h.column(4), [0.0, -0.5e-3]);
        assert_eq!(
            h.curve("uy_over_D", "V_over_Dcu"),
            [(0.01, 0.9), (0.02, 1.7)]
        );
        // `step` alone is a history too: a scene that records no columns.
        assert_eq!(parse("step\n1\n").unwrap().names, ["step"]);
    }

    #[test]
    fn malformed_files_say_where() {
        assert!(parse("").unwrap_err().contains("empty file"));
        assert!(parse("time,x\n").unwrap_err().contains("unknown columns"));
        assert!(parse("step,,x\n").unwrap_err().contains("column 2"));
        let e = parse("step,z_over_B,q_over_cu\n1,0.1\n").unwrap_err();
        assert!(e.contains("line 2: 2 values for 3 columns"), "{e}");
        let e = parse("step,w_over_D,Nc\n1,0.1,2\n2,x,3\n").unwrap_err();
        assert!(e.contains("line 3: \"x\" in column w_over_D"), "{e}");
    }
}
