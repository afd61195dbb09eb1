//! Reading a MusicXML file's text: the root score of a compressed `.mxl` zip (through its
//! `META-INF/container.xml`), or the file itself, decoded from its byte-order mark or
//! declared encoding; parse errors placed at their line and column.

use super::*;

/// The score's XML text: the root file of a `.mxl` zip, or the file itself, decoded from
/// its byte-order mark or declared encoding (UTF-8 by default).
pub(super) fn score_text(
    path: &Path,
    bytes: &[u8],
    notices: &mut Notices,
) -> Result<String, MusicXmlError> {
    if bytes.starts_with(b"PK\x03\x04") || bytes.starts_with(b"PK\x05\x06") {
        let (name, inner) = unzip_root(path, bytes, notices)?;
        let shown = PathBuf::from(format!("{}:{name}", path.display()));
        return decode(&shown, &inner);
    }
    let is_mxl = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mxl"));
    if is_mxl {
        // Uncompressed MusicXML under a compressed file's name: read as what it is.
        let text = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
        let looks_xml = text.trim_ascii_start().starts_with(b"<")
            || bytes.starts_with(b"\xff\xfe")
            || bytes.starts_with(b"\xfe\xff");
        if !looks_xml {
            return Err(archive_error(
                path,
                "the file is not a zip archive (nor uncompressed MusicXML)".into(),
            ));
        }
        notices.push_text(
            "named .mxl (compressed MusicXML) but holds uncompressed MusicXML: read as it is"
                .into(),
        );
    }
    decode(path, bytes)
}

/// The root score of a `.mxl` archive: (its name in the archive, its bytes).
pub(super) fn unzip_root(
    path: &Path,
    bytes: &[u8],
    notices: &mut Notices,
) -> Result<(String, Vec<u8>), MusicXmlError> {
    let archive_err = |message: String| archive_error(path, message);
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes))
        .map_err(|e| archive_err(format!("corrupt zip: {e}")))?;
    let names: Vec<String> = zip
        .file_names()
        .map(|n| n.map(|n| n.into_owned()))
        .collect::<Result<_, _>>()
        .map_err(|e| archive_err(format!("unreadable file name: {e}")))?;
    const CONTAINER: &str = "META-INF/container.xml";
    if names.iter().any(|n| n == CONTAINER) {
        let container = read_entry(path, &mut zip, CONTAINER)?;
        let shown = PathBuf::from(format!("{}:{CONTAINER}", path.display()));
        let text = decode(&shown, &container)?;
        let doc = Document::parse(&text).map_err(|e| xml_error(&shown, &text, &e))?;
        let root_file = doc
            .descendants()
            .filter(|n| n.has_tag_name("rootfile"))
            .filter(|n| {
                n.attribute("media-type")
                    .is_none_or(|m| m.contains("musicxml"))
            })
            .find_map(|n| n.attribute("full-path"))
            .ok_or_else(|| {
                archive_err(format!(
                    "{CONTAINER} names no MusicXML <rootfile full-path=…>"
                ))
            })?
            .to_string();
        let inner = read_entry(path, &mut zip, &root_file)?;
        return Ok((root_file, inner));
    }
    let fallback = names
        .iter()
        .find(|n| !n.starts_with("META-INF/") && (n.ends_with(".xml") || n.ends_with(".musicxml")))
        .cloned()
        .ok_or_else(|| {
            archive_err(format!(
                "no {CONTAINER} and no .xml or .musicxml file inside"
            ))
        })?;
    notices.push_text(format!(
        "the archive has no {CONTAINER}; read {fallback}, its first MusicXML file"
    ));
    let inner = read_entry(path, &mut zip, &fallback)?;
    Ok((fallback, inner))
}

/// The bytes of the file `name` in the `.mxl` archive `zip` (read from `path`), read
/// through a reader that stops one byte past
/// [`MAX_MXL_ENTRY_BYTES`](crate::base::limits::MAX_MXL_ENTRY_BYTES): an entry that unpacks
/// to more is refused (a zip bomb), whatever size the archive declares for it.
fn read_entry(
    path: &Path,
    zip: &mut zip::ZipArchive<std::io::Cursor<&[u8]>>,
    name: &str,
) -> Result<Vec<u8>, MusicXmlError> {
    use crate::base::limits::MAX_MXL_ENTRY_BYTES;
    let archive_err = |message: String| archive_error(path, message);
    let entry = zip
        .by_name(name)
        .map_err(|e| archive_err(format!("cannot open {name}: {e}")))?;
    // The declared size only sizes the buffer, never past the limit.
    let mut out = Vec::with_capacity(entry.size().min(MAX_MXL_ENTRY_BYTES + 1) as usize);
    entry
        .take(MAX_MXL_ENTRY_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| archive_err(format!("corrupt entry {name}: {e}")))?;
    if out.len() as u64 > MAX_MXL_ENTRY_BYTES {
        return Err(MusicXmlError::EntryTooLarge {
            path: path.to_path_buf(),
            entry: name.to_string(),
        });
    }
    Ok(out)
}

/// A `.mxl` at `path` that cannot be read as one, and why.
fn archive_error(path: &Path, message: String) -> MusicXmlError {
    MusicXmlError::Archive {
        path: path.to_path_buf(),
        message,
    }
}

/// A parse error with its place (said once: roxmltree's text ends with it too).
/// A file that stops early is placed at its end.
pub(super) fn xml_error(path: &Path, xml: &str, e: &roxmltree::Error) -> MusicXmlError {
    let pos = e.pos();
    let text = e.to_string();
    let message = text
        .strip_suffix(&format!(" at {}:{}", pos.row, pos.col))
        .unwrap_or(&text)
        .to_string();
    let (line, column) = if matches!(e, roxmltree::Error::UnexpectedEndOfStream) {
        let line = xml.lines().count().max(1);
        let column = xml.lines().last().map_or(0, |l| l.chars().count()) + 1;
        (
            u32::try_from(line).unwrap_or(u32::MAX),
            u32::try_from(column).unwrap_or(u32::MAX),
        )
    } else {
        (pos.row, pos.col)
    };
    MusicXmlError::Xml {
        path: path.to_path_buf(),
        line,
        column,
        message,
    }
}

/// Decode XML bytes: a byte-order mark, else the declaration's `encoding`, else UTF-8.
pub(super) fn decode(path: &Path, bytes: &[u8]) -> Result<String, MusicXmlError> {
    let (encoding, skip) = encoding_rs::Encoding::for_bom(bytes).unwrap_or_else(|| {
        let head = &bytes[..bytes.len().min(200)];
        let declared = std::str::from_utf8(head)
            .ok()
            .or_else(|| {
                std::str::from_utf8(&head[..head.iter().rposition(|&b| b < 0x80).unwrap_or(0)]).ok()
            })
            .and_then(declared_encoding)
            .and_then(|label| encoding_rs::Encoding::for_label(label.as_bytes()))
            .unwrap_or(encoding_rs::UTF_8);
        (declared, 0)
    });
    let (text, had_errors) = encoding.decode_without_bom_handling(&bytes[skip..]);
    if had_errors {
        let good = match std::str::from_utf8(&bytes[skip..]) {
            Err(e) if encoding == encoding_rs::UTF_8 => e.valid_up_to(),
            _ => 0,
        };
        let line = 1 + bytes[skip..skip + good]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        return Err(MusicXmlError::Xml {
            path: path.to_path_buf(),
            line: u32::try_from(line).unwrap_or(u32::MAX),
            column: 1,
            message: format!("the text is not valid {}", encoding.name()),
        });
    }
    Ok(text.into_owned())
}

/// The `encoding` of an XML declaration at the start of `head`.
pub(super) fn declared_encoding(head: &str) -> Option<String> {
    let decl = head.strip_prefix("<?xml")?;
    let decl = &decl[..decl.find("?>")?];
    let at = decl.find("encoding")?;
    let rest = decl[at + "encoding".len()..]
        .trim_start()
        .strip_prefix('=')?
        .trim_start();
    let quote = rest.chars().next().filter(|c| *c == '"' || *c == '\'')?;
    let rest = &rest[1..];
    Some(rest[..rest.find(quote)?].to_string())
}
