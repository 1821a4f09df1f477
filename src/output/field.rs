//! Per-particle fields of an output frame, and how each kind is laid out on disk.

use std::borrow::Cow;

/// One per-particle field of a frame: one value per owned particle, in the frame's `gid` order.
///
/// Names become HDF5 dataset names and XDMF attribute names, so they are restricted to ASCII
/// letters, digits, `_` and `-`, must be unique within a frame and must not be `gid` (written
/// for every frame). The owned and borrowed variants are written identically; borrow when the
/// values already sit in a slice.
#[derive(Debug, Clone, PartialEq)]
pub enum Field<'a> {
    /// A scalar.
    Scalar(Name, Vec<f64>),
    /// An in-plane vector `[x, y]`, written with z = 0 (see [`crate::output`] for why).
    Vector(Name, Vec<[f64; 2]>),
    /// A symmetric plane-strain tensor in Voigt order `[xx, yy, zz, xy]` with the TENSOR xy
    /// component (halve an engineering shear strain before passing it), written as the full
    /// 3 x 3 tensor.
    Tensor(Name, Vec<[f64; 4]>),
    /// A borrowed [`Field::Scalar`].
    ScalarRef(Name, &'a [f64]),
    /// A borrowed [`Field::Vector`].
    VectorRef(Name, &'a [[f64; 2]]),
}

/// A field's name: a literal for the fixed fields, owned for those a material's layout names.
pub type Name = Cow<'static, str>;

/// What a field holds, which fixes its components on disk and its XDMF attribute type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Scalar,
    Vector,
    Tensor,
}

impl Kind {
    /// Values stored per particle.
    pub(crate) fn components(self) -> usize {
        match self {
            Kind::Scalar => 1,
            Kind::Vector => 3,
            Kind::Tensor => 9,
        }
    }

    /// The XDMF `AttributeType`.
    pub(crate) fn attribute_type(self) -> &'static str {
        match self {
            Kind::Scalar => "Scalar",
            Kind::Vector => "Vector",
            Kind::Tensor => "Tensor",
        }
    }

    fn code(self) -> u8 {
        self as u8
    }
}

/// Name and kind of a field: all the series file needs to know about it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct FieldDesc {
    pub name: Name,
    pub kind: Kind,
}

/// Name reserved for the particle ids written with every frame.
pub(crate) const GID: &str = "gid";

impl Field<'_> {
    /// The field's name.
    pub fn name(&self) -> &str {
        match self {
            Field::Scalar(n, _)
            | Field::Vector(n, _)
            | Field::Tensor(n, _)
            | Field::ScalarRef(n, _)
            | Field::VectorRef(n, _) => n,
        }
    }

    /// Number of particles the field has values for.
    pub fn len(&self) -> usize {
        match self {
            Field::Scalar(_, v) => v.len(),
            Field::Vector(_, v) => v.len(),
            Field::Tensor(_, v) => v.len(),
            Field::ScalarRef(_, v) => v.len(),
            Field::VectorRef(_, v) => v.len(),
        }
    }

    /// True when the field has no values (a rank owning no particles).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub(crate) fn kind(&self) -> Kind {
        match self {
            Field::Scalar(..) | Field::ScalarRef(..) => Kind::Scalar,
            Field::Vector(..) | Field::VectorRef(..) => Kind::Vector,
            Field::Tensor(..) => Kind::Tensor,
        }
    }

    pub(crate) fn desc(&self) -> FieldDesc {
        FieldDesc {
            name: Name::Owned(self.name().to_string()),
            kind: self.kind(),
        }
    }

    /// The values as stored: `len() * kind().components()` numbers, row by row.
    pub(crate) fn stored(&self) -> Cow<'_, [f64]> {
        match self {
            Field::Scalar(_, v) => Cow::Borrowed(v),
            Field::ScalarRef(_, v) => Cow::Borrowed(v),
            Field::Vector(_, v) => Cow::Owned(pad_vectors(v)),
            Field::VectorRef(_, v) => Cow::Owned(pad_vectors(v)),
            Field::Tensor(_, v) => Cow::Owned(full_tensors(v)),
        }
    }
}

fn pad_vectors(v: &[[f64; 2]]) -> Vec<f64> {
    v.iter().flat_map(|&[x, y]| [x, y, 0.0]).collect()
}

/// Row-major 3 x 3; symmetric, so column-major readers see the same tensor.
fn full_tensors(v: &[[f64; 4]]) -> Vec<f64> {
    v.iter()
        .flat_map(|&[xx, yy, zz, xy]| [xx, xy, 0.0, xy, yy, 0.0, 0.0, 0.0, zz])
        .collect()
}

/// Checks names (allowed characters, unique, not reserved) and lengths against `n` particles.
pub(crate) fn check_fields(fields: &[Field<'_>], n: usize) -> Result<(), String> {
    for (i, f) in fields.iter().enumerate() {
        let name = f.name();
        let allowed = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
        if name.is_empty() || !name.chars().all(allowed) {
            return Err(format!(
                "field name {name:?}: use only ASCII letters, digits, '_' and '-'"
            ));
        }
        if name == GID {
            return Err(format!(
                "field name {GID:?} is reserved for the particle ids"
            ));
        }
        if fields[..i].iter().any(|g| g.name() == name) {
            return Err(format!("field {name:?} is given twice"));
        }
        if f.len() != n {
            return Err(format!(
                "field {name:?} has {} values for {n} owned particles",
                f.len()
            ));
        }
    }
    Ok(())
}

/// Bytes identifying the field list, for checking that every rank passes the same one.
pub(crate) fn signature(fields: &[FieldDesc]) -> Vec<u8> {
    let mut out = Vec::new();
    for f in fields {
        out.push(f.kind.code());
        out.extend_from_slice(f.name.as_bytes());
        out.push(0);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_are_padded_and_tensors_expanded() {
        let v = Field::Vector("u".into(), vec![[1.0, 2.0], [3.0, 4.0]]);
        assert_eq!(&*v.stored(), &[1.0, 2.0, 0.0, 3.0, 4.0, 0.0]);
        let t = Field::Tensor("s".into(), vec![[1.0, 2.0, 3.0, 4.0]]);
        assert_eq!(&*t.stored(), &[1.0, 4.0, 0.0, 4.0, 2.0, 0.0, 0.0, 0.0, 3.0]);
        let s = [5.0, 6.0];
        assert_eq!(&*Field::ScalarRef("p".into(), &s).stored(), &s);
        assert_eq!(t.kind().components(), 9);
    }

    #[test]
    fn bad_names_and_lengths_are_rejected() {
        let ok = [
            Field::Scalar("p".into(), vec![0.0]),
            Field::Vector("u-1".into(), vec![[0.0; 2]]),
        ];
        assert!(check_fields(&ok, 1).is_ok());
        let e = check_fields(&ok, 2).unwrap_err();
        assert!(e.contains("\"p\" has 1 values for 2"), "{e}");
        for bad in ["", "a/b", "a:b", "a b", "é"] {
            assert!(
                check_fields(&[Field::Scalar(bad.into(), vec![])], 0).is_err(),
                "{bad}"
            );
        }
        assert!(check_fields(&[Field::Scalar("gid".into(), vec![])], 0).is_err());
        let twice = [
            Field::Scalar("p".into(), vec![]),
            Field::ScalarRef("p".into(), &[]),
        ];
        assert!(check_fields(&twice, 0).unwrap_err().contains("twice"));
    }

    #[test]
    fn signature_tells_kinds_and_names_apart() {
        let a = [Field::Scalar("p".into(), vec![]).desc()];
        let b = [Field::VectorRef("p".into(), &[]).desc()];
        let c = [Field::Scalar("q".into(), vec![]).desc()];
        assert_ne!(signature(&a), signature(&b));
        assert_ne!(signature(&a), signature(&c));
        assert_eq!(
            signature(&a),
            signature(&[Field::ScalarRef("p".into(), &[]).desc()])
        );
    }
}
