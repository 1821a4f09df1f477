//! What a Gauss point (and a particle) stores: the Cauchy stress, common to every model, then the
//! internal variables the model declares by name. Storage, halo records, mapping, checkpoints and
//! output read their widths and column names from here, so a model that adds a variable changes
//! no other module.

use std::borrow::Cow;

/// Stress components at the start of every state row: `[xx, yy, zz, xy]` (tensor shear).
pub const STRESS_LEN: usize = 4;

/// Names of the stress columns, in row order.
pub const STRESS_COLUMNS: [&str; STRESS_LEN] = ["stress_xx", "stress_yy", "stress_zz", "stress_xy"];

/// How an internal variable transforms, which decides its width and whether an element that
/// rotates the stress must rotate it too.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarKind {
    /// One number, frame-independent (an equivalent plastic strain, a strength).
    Scalar,
    /// A symmetric strain tensor in Voigt form `[xx, yy, zz, xy]` with engineering shear: rotates
    /// with the material like the stress.
    Strain,
}

impl VarKind {
    pub fn width(self) -> usize {
        match self {
            VarKind::Scalar => 1,
            VarKind::Strain => 4,
        }
    }

    fn suffixes(self) -> &'static [&'static str] {
        match self {
            VarKind::Scalar => &[""],
            VarKind::Strain => &["_xx", "_yy", "_zz", "_xy"],
        }
    }
}

/// One internal variable of a model.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InternalVar {
    /// The name checkpoints and output use (`eps_q`, `plastic_strain`).
    pub name: Cow<'static, str>,
    pub kind: VarKind,
}

impl InternalVar {
    pub const fn scalar(name: &'static str) -> InternalVar {
        InternalVar {
            name: Cow::Borrowed(name),
            kind: VarKind::Scalar,
        }
    }

    pub const fn strain(name: &'static str) -> InternalVar {
        InternalVar {
            name: Cow::Borrowed(name),
            kind: VarKind::Strain,
        }
    }
}

/// The layout of one state row: stress, then the internal variables in declaration order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct StateLayout {
    vars: Vec<InternalVar>,
}

impl StateLayout {
    pub fn new(vars: &[InternalVar]) -> StateLayout {
        StateLayout {
            vars: vars.to_vec(),
        }
    }

    /// Scalars in a row (stress included).
    pub fn len(&self) -> usize {
        STRESS_LEN + self.internal_len()
    }

    /// Never: the stress is always there. (For clippy's `len_without_is_empty`.)
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Scalars after the stress.
    pub fn internal_len(&self) -> usize {
        internal_len(&self.vars)
    }

    pub fn vars(&self) -> &[InternalVar] {
        &self.vars
    }

    /// One name per column: the stress's, then each variable's (a tensor's with its component
    /// suffix, `plastic_strain_xy`).
    pub fn columns(&self) -> Vec<String> {
        let mut out: Vec<String> = STRESS_COLUMNS.iter().map(|s| s.to_string()).collect();
        for v in &self.vars {
            for s in v.kind.suffixes() {
                out.push(format!("{}{s}", v.name));
            }
        }
        out
    }

    /// Row offset and kind of the variable `name`.
    pub fn find(&self, name: &str) -> Option<(usize, VarKind)> {
        let mut at = STRESS_LEN;
        for v in &self.vars {
            if v.name == name {
                return Some((at, v.kind));
            }
            at += v.kind.width();
        }
        None
    }
}

/// Scalars that `vars` take in a row.
pub fn internal_len(vars: &[InternalVar]) -> usize {
    vars.iter().map(|v| v.kind.width()).sum()
}

/// Applies `f` to every strain-tensor variable of `internal` (laid out as `vars`).
pub fn for_each_strain(vars: &[InternalVar], internal: &mut [f64], mut f: impl FnMut(&mut [f64])) {
    let mut at = 0;
    for v in vars {
        let w = v.kind.width();
        if v.kind == VarKind::Strain {
            f(&mut internal[at..at + w]);
        }
        at += w;
    }
}

/// Rows of equal width in one flat vector: the states of particles (one row each) or of triangles
/// (one row of three Gauss points each). One allocation however many rows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rows {
    width: usize,
    data: Vec<f64>,
}

impl Rows {
    /// No rows of `width` (> 0) scalars.
    pub fn new(width: usize) -> Rows {
        assert!(width > 0, "a state row has at least the stress");
        Rows {
            width,
            data: Vec::new(),
        }
    }

    /// `n` rows of zeros.
    pub fn zeros(width: usize, n: usize) -> Rows {
        assert!(width > 0, "a state row has at least the stress");
        Rows {
            width,
            data: vec![0.0; width * n],
        }
    }

    /// From a flat vector whose length is a multiple of `width`.
    pub fn from_flat(width: usize, data: Vec<f64>) -> Rows {
        assert!(width > 0 && data.len().is_multiple_of(width));
        Rows { width, data }
    }

    pub fn with_capacity(width: usize, n: usize) -> Rows {
        assert!(width > 0, "a state row has at least the stress");
        Rows {
            width,
            data: Vec::with_capacity(width * n),
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn len(&self) -> usize {
        self.data.len().checked_div(self.width).unwrap_or(0)
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.width..(i + 1) * self.width]
    }

    pub fn row_mut(&mut self, i: usize) -> &mut [f64] {
        &mut self.data[i * self.width..(i + 1) * self.width]
    }

    /// Appends one row (`row.len()` must be the width).
    pub fn push(&mut self, row: &[f64]) {
        assert_eq!(row.len(), self.width, "state row of the wrong width");
        self.data.extend_from_slice(row);
    }

    /// Keeps the first `n` rows.
    pub fn truncate(&mut self, n: usize) {
        self.data.truncate(n * self.width);
    }

    /// Removes the last row.
    pub fn pop(&mut self) {
        let n = self.len();
        self.truncate(n.saturating_sub(1));
    }

    /// Appends a row of zeros.
    pub fn push_zeros(&mut self) {
        self.data.resize(self.data.len() + self.width, 0.0);
    }

    pub fn iter_mut(&mut self) -> std::slice::ChunksExactMut<'_, f64> {
        self.data.chunks_exact_mut(self.width.max(1))
    }

    pub fn iter(&self) -> std::slice::ChunksExact<'_, f64> {
        self.data.chunks_exact(self.width.max(1))
    }

    pub fn as_flat(&self) -> &[f64] {
        &self.data
    }

    pub fn as_flat_mut(&mut self) -> &mut [f64] {
        &mut self.data
    }

    pub fn into_flat(self) -> Vec<f64> {
        self.data
    }

    /// Moves all rows of `other` (same width) to the end.
    pub fn append(&mut self, other: &mut Rows) {
        assert_eq!(self.width, other.width, "appending rows of another width");
        self.data.append(&mut other.data);
    }

    /// The rows at `range`, copied.
    pub fn slice(&self, range: std::ops::Range<usize>) -> Rows {
        Rows {
            width: self.width,
            data: self.data[range.start * self.width..range.end * self.width].to_vec(),
        }
    }

    /// The rows in the order `order` (indices into self).
    pub fn permuted(&self, order: &[usize]) -> Rows {
        let mut out = Rows::with_capacity(self.width, order.len());
        for &i in order {
            out.data.extend_from_slice(self.row(i));
        }
        out
    }

    /// Keeps the rows whose flag in `keep` is true.
    pub fn retain(&mut self, keep: &[bool]) {
        let w = self.width;
        let mut k = 0;
        for (i, &kept) in keep.iter().enumerate() {
            if kept {
                self.data.copy_within(i * w..(i + 1) * w, k * w);
                k += 1;
            }
        }
        self.data.truncate(k * w);
    }
}

/// The lower bound of a scalar internal variable, by its name. Names mean one quantity across
/// models (the layout of a scene with several materials merges variables by name), so the bound
/// goes with the name: `eps_q` and `xi` are sums of non-negative increments (an accumulated
/// equivalent, and an accumulated engineering, plastic shear strain). Others: none.
pub fn lower_bound(name: &str) -> Option<f64> {
    match name {
        "eps_q" | "xi" => Some(0.0),
        _ => None,
    }
}

/// Raises every scalar variable of `internal` (laid out as `vars`) that is below its
/// [`lower_bound`] (or NaN) to it; whether any changed.
pub fn clamp_to_bounds(vars: &[InternalVar], internal: &mut [f64]) -> bool {
    let mut at = 0;
    let mut changed = false;
    for v in vars {
        if let (VarKind::Scalar, Some(lo)) = (v.kind, lower_bound(&v.name)) {
            if let Some(x) = internal.get_mut(at) {
                if (*x).partial_cmp(&lo).is_none_or(|o| o.is_lt()) {
                    *x = lo;
                    changed = true;
                }
            }
        }
        at += v.kind.width();
    }
    changed
}

/// The von Mises equivalent of a plastic strain increment (engineering shear in slot 3),
/// √(2/3 Δεp:Δεp): what the `eps_q` variable of the plastic models accumulates.
pub fn equivalent_plastic_strain(dep: &[f64]) -> f64 {
    let sq = dep[0] * dep[0] + dep[1] * dep[1] + dep[2] * dep[2] + 0.5 * dep[3] * dep[3];
    (2.0 / 3.0 * sq).sqrt()
}

/// Whether the variable at `at` (a plastic model's `eps_q`) grew from `before` to `after`:
/// how those models tell that a point yielded.
pub fn grew(before: &super::GaussState, after: &super::GaussState, at: usize) -> bool {
    let q = |s: &super::GaussState| s.internal.get(at).copied().unwrap_or(0.0);
    q(after) > q(before)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_follow_the_declared_variables() {
        let l = StateLayout::new(&[
            InternalVar::strain("plastic_strain"),
            InternalVar::scalar("eps_q"),
        ]);
        assert_eq!(l.len(), 9);
        assert_eq!(l.columns()[4], "plastic_strain_xx");
        assert_eq!(l.columns()[8], "eps_q");
        assert_eq!(l.find("eps_q"), Some((8, VarKind::Scalar)));
        assert_eq!(l.find("cu"), None);
        assert_eq!(StateLayout::default().columns().len(), 4);
    }

    #[test]
    fn accumulated_strains_are_clamped_at_zero_and_nothing_else_is() {
        let vars = [
            InternalVar::strain("plastic_strain"),
            InternalVar::scalar("eps_q"),
            InternalVar::scalar("xi"),
            InternalVar::scalar("cu"),
        ];
        let mut x = [-1.0, 2.0, 0.0, -3.0, -0.5, -1e-3, -7.0];
        assert!(clamp_to_bounds(&vars, &mut x));
        assert_eq!(x, [-1.0, 2.0, 0.0, -3.0, 0.0, 0.0, -7.0]);
        assert!(!clamp_to_bounds(&vars, &mut x), "admissible: unchanged");
        let mut nan = [0.0, 0.0, 0.0, 0.0, f64::NAN, 1.0, 1.0];
        assert!(clamp_to_bounds(&vars, &mut nan) && nan[4] == 0.0);
    }

    #[test]
    fn rows_keep_their_width_through_edits() {
        let mut r = Rows::from_flat(2, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(r.len(), 3);
        assert_eq!(r.permuted(&[2, 0]).as_flat(), &[4.0, 5.0, 0.0, 1.0]);
        r.retain(&[true, false, true]);
        assert_eq!(r.as_flat(), &[0.0, 1.0, 4.0, 5.0]);
        assert_eq!(r.slice(1..2).as_flat(), &[4.0, 5.0]);
        let mut m = Rows::zeros(2, 1);
        r.append(&mut m);
        assert_eq!(r.len(), 3);
        assert_eq!(r.row(2), &[0.0, 0.0]);
    }
}
