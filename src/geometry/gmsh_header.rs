//! The two parts of an MSH file that `mshio` does not give us: the version as written (so a
//! wrong version is reported as such, not as a parse failure) and `$PhysicalNames`, which is
//! plain text in ASCII and binary files alike.

use super::gmsh::GmshErrorKind;

/// The non-empty lines of the text before the first binary section could start.
fn lines(bytes: &[u8]) -> impl Iterator<Item = String> + '_ {
    bytes
        .split(|&b| b == b'\n')
        .map(|l| String::from_utf8_lossy(l).trim().to_string())
        .filter(|l| !l.is_empty())
}

/// Checks that the file starts with an MSH 4.1 `$MeshFormat` header.
pub(super) fn check_version(bytes: &[u8]) -> Result<(), GmshErrorKind> {
    let mut it = lines(bytes);
    if it.next().as_deref() != Some("$MeshFormat") {
        return Err(GmshErrorKind::Damaged {
            detail: "the file does not start with a $MeshFormat section".into(),
        });
    }
    let Some(format) = it.next() else {
        return Err(GmshErrorKind::Damaged {
            detail: "the $MeshFormat section is empty".into(),
        });
    };
    let fields: Vec<&str> = format.split_whitespace().collect();
    let found = fields.first().copied().unwrap_or("").to_string();
    if found.parse::<f64>().ok() != Some(4.1) {
        return Err(GmshErrorKind::Version { found });
    }
    // Checked here because mshio unwraps these two fields and would panic on bad ones.
    let file_type_ok = matches!(fields.get(1).copied(), Some("0" | "1"));
    let size_ok = matches!(fields.get(2).copied(), Some("4" | "8"));
    if !(file_type_ok && size_ok && fields.len() == 3) {
        return Err(GmshErrorKind::Damaged {
            detail: format!("bad $MeshFormat line {format:?} (expected \"4.1 <0|1> <4|8>\")"),
        });
    }
    Ok(())
}

/// `(dimension, tag, name)` of every named physical group, from `$PhysicalNames` (empty if
/// the file has none).
pub(super) fn physical_names(bytes: &[u8]) -> Result<Vec<(i32, i32, String)>, GmshErrorKind> {
    // Gmsh writes $PhysicalNames right after $MeshFormat, before any binary section, so only
    // the text up to the first $Entities or $Nodes is searched.
    let end = ["\n$Entities", "\n$Nodes"]
        .iter()
        .filter_map(|tag| find(bytes, tag.as_bytes()))
        .min()
        .unwrap_or(bytes.len());
    let head = &bytes[..end];
    let Some(start) = find(head, b"\n$PhysicalNames") else {
        return Ok(Vec::new());
    };
    let damaged = |detail: String| GmshErrorKind::Damaged { detail };
    let mut it = lines(&head[start + 1..]).skip(1);
    let count: usize = it
        .next()
        .and_then(|l| l.parse().ok())
        .ok_or_else(|| damaged("$PhysicalNames has no valid count".into()))?;
    let mut out = Vec::new();
    for line in it.by_ref().take(count) {
        let entry = parse_name_line(&line)
            .ok_or_else(|| damaged(format!("bad $PhysicalNames line: {line:?}")))?;
        out.push(entry);
    }
    if out.len() != count || it.next().as_deref() != Some("$EndPhysicalNames") {
        return Err(damaged(format!(
            "$PhysicalNames announces {count} names but is cut short or not closed"
        )));
    }
    Ok(out)
}

fn parse_name_line(line: &str) -> Option<(i32, i32, String)> {
    let mut parts = line.splitn(3, char::is_whitespace);
    let dim = parts.next()?.parse().ok()?;
    let tag = parts.next()?.parse().ok()?;
    let name = parts.next()?.trim();
    let name = name.strip_prefix('"')?.strip_suffix('"')?;
    Some((dim, tag, name.to_string()))
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn versions() {
        assert_eq!(
            check_version(b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"),
            Ok(())
        );
        assert_eq!(
            check_version(b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"),
            Err(GmshErrorKind::Version {
                found: "2.2".into()
            })
        );
        assert!(matches!(
            check_version(b"hello"),
            Err(GmshErrorKind::Damaged { .. })
        ));
        assert!(matches!(
            check_version(b"$MeshFormat\n"),
            Err(GmshErrorKind::Damaged { .. })
        ));
        for bad in [
            "4.1 0 999999999999999999999",
            "4.1 2 8",
            "4.1 0",
            "4.1 0 8 x",
        ] {
            let text = format!("$MeshFormat\n{bad}\n$EndMeshFormat\n");
            assert!(
                matches!(
                    check_version(text.as_bytes()),
                    Err(GmshErrorKind::Damaged { .. })
                ),
                "{bad}"
            );
        }
    }

    #[test]
    fn names_with_spaces_and_damage() {
        let ok = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n1 3 \"sea bed\"\n2 1 \"clay\"\n$EndPhysicalNames\n$Nodes\n";
        assert_eq!(
            physical_names(ok).unwrap(),
            vec![(1, 3, "sea bed".to_string()), (2, 1, "clay".to_string())]
        );
        let short = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n3\n1 3 \"a\"\n$EndPhysicalNames\n";
        assert!(matches!(
            physical_names(short),
            Err(GmshErrorKind::Damaged { .. })
        ));
        let bad = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n1 x \"a\"\n$EndPhysicalNames\n";
        assert!(matches!(
            physical_names(bad),
            Err(GmshErrorKind::Damaged { .. })
        ));
        assert_eq!(
            physical_names(b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n").unwrap(),
            vec![]
        );
    }
}
