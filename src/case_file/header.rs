//! Root attributes of a case file: writing them, and reading them back with a type check on
//! each so that a foreign or damaged file is reported by attribute name.

use std::path::Path;

use hdf5::types::{TypeDescriptor, VarLenAscii, VarLenUnicode};
use hdf5::{Attribute, File, H5Type};

use super::error::{CaseError, CaseErrorKind};
use super::{CaseHeader, FORMAT, FORMAT_VERSION};

fn put_str(file: &File, name: &str, value: &str) -> hdf5::Result<()> {
    let v: VarLenUnicode = value
        .parse()
        .map_err(|e| hdf5::Error::Internal(format!("attribute {name}: {e}")))?;
    file.new_attr::<VarLenUnicode>()
        .create(name)?
        .write_scalar(&v)
}

fn put<T: H5Type>(file: &File, name: &str, value: T) -> hdf5::Result<()> {
    file.new_attr::<T>().create(name)?.write_scalar(&value)
}

/// Writes the root attributes. Collective under MPI-IO: every rank passes the same values.
/// `format_version` is always this program's [`FORMAT_VERSION`] and `ranks` the writer's rank
/// count, whatever `h` says.
pub fn write_header(file: &File, h: &CaseHeader, ranks: u32) -> hdf5::Result<()> {
    put_str(file, "format", FORMAT)?;
    put(file, "format_version", FORMAT_VERSION)?;
    put_str(file, "code_version", &h.code_version)?;
    put_str(file, "scene", &h.scene_toml)?;
    put_str(file, "scene_source", &h.scene_source)?;
    put(file, "step", h.step)?;
    put(file, "load_factor", h.load_factor)?;
    put(file, "time", h.time)?;
    put(file, "next_gid", h.next_gid)?;
    put(file, "ranks", ranks)?;
    if let Some(c) = h.collapse_reference {
        put(file, "collapse_reference", c)?;
    }
    file.new_attr::<u64>()
        .shape(h.tracked_gids.len())
        .create("tracked_gids")?
        .write_raw(&h.tracked_gids)?;
    file.new_attr::<u64>()
        .shape(h.rank_counts.len())
        .create("rank_counts")?
        .write_raw(&h.rank_counts)
}

struct Reader<'a> {
    file: &'a File,
    path: &'a Path,
}

impl Reader<'_> {
    fn err(&self, name: &str, message: String) -> CaseError {
        CaseError::new(self.path, CaseErrorKind::Malformed, message).at(format!("attribute {name}"))
    }

    fn open(&self, name: &str) -> Result<(Attribute, TypeDescriptor), CaseError> {
        let attr = self
            .file
            .attr(name)
            .map_err(|_| self.err(name, "missing".to_string()))?;
        let desc = attr
            .dtype()
            .and_then(|t| t.to_descriptor())
            .map_err(|e| self.err(name, format!("unreadable type: {e}")))?;
        Ok((attr, desc))
    }

    fn scalar<T: H5Type + Copy>(&self, name: &str) -> Result<T, CaseError> {
        let (attr, desc) = self.open(name)?;
        let want = T::type_descriptor();
        if desc != want {
            return Err(self.err(name, format!("expected type {want}, found {desc}")));
        }
        if attr.size() != 1 {
            return Err(self.err(
                name,
                format!("expected one value, found shape {:?}", attr.shape()),
            ));
        }
        let values = attr
            .read_raw::<T>()
            .map_err(|e| self.err(name, format!("cannot read: {e}")))?;
        values
            .first()
            .copied()
            .ok_or_else(|| self.err(name, "has no value".to_string()))
    }

    fn string(&self, name: &str) -> Result<String, CaseError> {
        let (attr, desc) = self.open(name)?;
        if attr.size() != 1 {
            return Err(self.err(
                name,
                format!("expected one string, found shape {:?}", attr.shape()),
            ));
        }
        let read_err = |e: hdf5::Error| self.err(name, format!("cannot read: {e}"));
        let text = match desc {
            // The bytes are checked here: the HDF5 string types trust the file, and a flipped
            // byte would reach the TOML parser as a `str` that is not UTF-8.
            TypeDescriptor::VarLenUnicode => attr
                .read_raw::<VarLenUnicode>()
                .map_err(read_err)?
                .first()
                .map(|s| self.utf8(name, s.as_bytes()))
                .transpose()?,
            TypeDescriptor::VarLenAscii => attr
                .read_raw::<VarLenAscii>()
                .map_err(read_err)?
                .first()
                .map(|s| self.utf8(name, s.as_bytes()))
                .transpose()?,
            other => return Err(self.err(name, format!("expected a string, found {other}"))),
        };
        text.ok_or_else(|| self.err(name, "has no value".to_string()))
    }

    fn utf8(&self, name: &str, bytes: &[u8]) -> Result<String, CaseError> {
        std::str::from_utf8(bytes).map(str::to_string).map_err(|e| {
            self.err(
                name,
                format!(
                    "is not valid UTF-8 (at byte {}): the file is damaged",
                    e.valid_up_to()
                ),
            )
        })
    }

    fn u64_array(&self, name: &str) -> Result<Vec<u64>, CaseError> {
        let (attr, desc) = self.open(name)?;
        let want = u64::type_descriptor();
        if desc != want {
            return Err(self.err(name, format!("expected type {want}, found {desc}")));
        }
        if attr.ndim() > 1 {
            return Err(self.err(
                name,
                format!("expected a 1-D array, found shape {:?}", attr.shape()),
            ));
        }
        attr.read_raw::<u64>()
            .map_err(|e| self.err(name, format!("cannot read: {e}")))
    }
}

/// Reads and checks the root attributes. A missing or different `format` means the file is not
/// a case; a larger `format_version` means a newer program wrote it.
pub fn read_header(file: &File, path: &Path) -> Result<CaseHeader, CaseError> {
    let r = Reader { file, path };
    let not_case = |why: String| {
        CaseError::new(
            path,
            CaseErrorKind::NotACase,
            format!("not a pfem-mpi case file ({why})"),
        )
    };
    if !file
        .attr_names()
        .unwrap_or_default()
        .iter()
        .any(|n| n == "format")
    {
        return Err(not_case("no attribute format".to_string()));
    }
    let format = r.string("format")?;
    if format != FORMAT {
        return Err(not_case(format!("attribute format is \"{format}\"")));
    }
    let format_version: u32 = r.scalar("format_version")?;
    if format_version > FORMAT_VERSION {
        return Err(CaseError::new(
            path,
            CaseErrorKind::TooNew,
            format!(
                "format_version {format_version} is newer than this pfem-mpi ({FORMAT_VERSION})"
            ),
        ));
    }
    if format_version == 0 {
        return Err(r.err("format_version", "0 is not a valid version".to_string()));
    }
    Ok(CaseHeader {
        format_version,
        code_version: r.string("code_version")?,
        scene_toml: r.string("scene")?,
        scene_source: r.string("scene_source")?,
        step: r.scalar("step")?,
        load_factor: r.scalar("load_factor")?,
        time: r.scalar("time")?,
        next_gid: r.scalar("next_gid")?,
        ranks: r.scalar("ranks")?,
        tracked_gids: r.u64_array("tracked_gids")?,
        rank_counts: if file
            .attr_names()
            .unwrap_or_default()
            .iter()
            .any(|n| n == "rank_counts")
        {
            r.u64_array("rank_counts")?
        } else {
            Vec::new()
        },
        // Read from the state datasets' `names` attribute with the particles.
        state_columns: Vec::new(),
        collapse_reference: if file
            .attr_names()
            .unwrap_or_default()
            .iter()
            .any(|n| n == "collapse_reference")
        {
            Some(r.scalar("collapse_reference")?)
        } else {
            None
        },
    })
}
