//! OME-TIFF files whose OME-XML is kept in another file (OME-TIFF specification, "multi-file
//! datasets" and "companion files"): the XML of each TIFF of such a set holds only a
//! `BinaryOnly` element whose `MetadataFile` names the file with the set's metadata, relative to
//! the TIFF's folder — a TIFF of the set that carries the whole XML (the "master"), or an XML
//! file of its own (`NAME.companion.ome`). The reader follows that pointer once, so that any file
//! of the set reads the whole set; a companion file given as the input opens the set through
//! the TIFF its first `TiffData` block names.

use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// Largest metadata file read (bytes): the XML of a set of many thousand planes stays far
/// below this; a larger file is refused before it is read.
pub const MAX_METADATA_BYTES: u64 = 256 << 20;

/// The `BinaryOnly` pointer of an OME-XML document: the metadata file and the UUID it states
/// for that file's document.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Pointer {
    pub(crate) metadata_file: String,
    pub(crate) uuid: Option<String>,
}

fn is_element(node: &roxmltree::Node, tag: &str) -> bool {
    node.is_element() && node.tag_name().name() == tag
}

/// The `BinaryOnly` pointer of `xml` (an `OME` root with a `BinaryOnly` child naming a
/// `MetadataFile`), or `None` for any other document.
pub(crate) fn pointer(xml: &str) -> Option<Pointer> {
    if !xml.contains("BinaryOnly") {
        return None;
    }
    let doc = roxmltree::Document::parse(xml).ok()?;
    let root = doc.root_element();
    if !is_element(&root, "OME") {
        return None;
    }
    let binary = root.children().find(|n| is_element(n, "BinaryOnly"))?;
    Some(Pointer {
        metadata_file: binary.attribute("MetadataFile")?.trim().to_string(),
        uuid: binary.attribute("UUID").map(|u| u.trim().to_string()),
    })
}

/// Bytes at the start of a file that [`looks_like_ome_xml`] reads.
pub const HEAD_BYTES: usize = 4096;

/// Whether the first bytes of a file (up to [`HEAD_BYTES`]) are those of an OME-XML document
/// (a companion file): XML text, after an optional byte-order mark and white space, with an
/// `OME` element among them.
pub fn looks_like_ome_xml(head: &[u8]) -> bool {
    let head = head.strip_prefix(&[0xef, 0xbb, 0xbf]).unwrap_or(head);
    let start = head
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(head.len());
    let text = &head[start..];
    (text.starts_with(b"<?xml") || text.starts_with(b"<OME"))
        && text.windows(4).any(|w| w == b"<OME")
}

/// `name`, a file named by a set's metadata, as a path beside `beside` (a file of the set). A
/// name that is absolute or has a folder in it is refused: the OME-TIFF specification names a
/// set's files relative to the file naming them, and a set is read from one folder.
pub(crate) fn beside(beside: &Path, name: &str) -> Result<PathBuf, String> {
    let relative = Path::new(name);
    let mut parts = relative.components();
    let plain = matches!(parts.next(), Some(Component::Normal(_))) && parts.next().is_none();
    if !plain {
        return Err(format!(
            "it names {name:?}, not a file beside it (a set's files are read from one folder)"
        ));
    }
    Ok(beside.parent().unwrap_or(Path::new("")).join(relative))
}

/// The OME-XML of `file`: a TIFF's first ImageDescription, or the text of an XML file. Checked
/// to be an OME document whose `UUID` is `uuid` where both state one.
pub(crate) fn read_document(file: &Path, uuid: Option<&str>) -> Result<String, String> {
    let size = std::fs::metadata(file)
        .map_err(|e| format!("{}: {e}", file.display()))?
        .len();
    if size > MAX_METADATA_BYTES {
        return Err(format!(
            "{} is {size} bytes, more than the {MAX_METADATA_BYTES} read as metadata",
            file.display()
        ));
    }
    let mut head = [0u8; 4];
    let n = std::fs::File::open(file)
        .and_then(|mut f| f.read(&mut head))
        .map_err(|e| format!("{}: {e}", file.display()))?;
    let xml = if crate::microscopy::detect(&head[..n])
        == Some(crate::microscopy::MicroscopyFormat::Tiff)
    {
        super::read::first_description(file)
            .map_err(|e| e.to_string())?
            .ok_or_else(|| format!("{} has no ImageDescription", file.display()))?
    } else {
        let bytes = std::fs::read(file).map_err(|e| format!("{}: {e}", file.display()))?;
        String::from_utf8(bytes).map_err(|_| format!("{} is not UTF-8 text", file.display()))?
    };
    let doc = roxmltree::Document::parse(&xml)
        .map_err(|e| format!("{} is not readable XML: {e}", file.display()))?;
    let root = doc.root_element();
    if !is_element(&root, "OME") {
        return Err(format!("{} is not an OME-XML document", file.display()));
    }
    if root.children().any(|n| is_element(&n, "BinaryOnly")) {
        return Err(format!(
            "{} only points to another metadata file in turn",
            file.display()
        ));
    }
    if let (Some(wanted), Some(stated)) = (uuid, root.attribute("UUID")) {
        if wanted != stated.trim() {
            return Err(format!(
                "{} is the document {stated}, not the {wanted} the pointer names",
                file.display()
            ));
        }
    }
    Ok(xml)
}

/// The OME-XML a `BinaryOnly` TIFF at `path` points to, and the file it was read from.
pub(crate) fn follow(path: &Path, pointer: &Pointer) -> Result<(PathBuf, String), String> {
    let file = beside(path, &pointer.metadata_file)?;
    if !file.is_file() {
        return Err(format!(
            "{} is not there; copy the set's files together",
            pointer.metadata_file
        ));
    }
    let xml = read_document(&file, pointer.uuid.as_deref())?;
    Ok((file, xml))
}

/// The TIFF through which the set of a companion file is read (the file named by the first
/// `TiffData` block of the first image; any file of the set reads the whole set), and the
/// companion's XML.
pub(crate) fn anchor(companion: &Path) -> Result<(PathBuf, String), String> {
    let xml = read_document(companion, None)?;
    let doc = roxmltree::Document::parse(&xml).map_err(|e| e.to_string())?;
    let pixels = doc
        .descendants()
        .find(|n| is_element(n, "Pixels"))
        .ok_or("its OME-XML has no Pixels element")?;
    let first = pixels
        .children()
        .filter(|n| is_element(n, "TiffData"))
        .find_map(|block| {
            block
                .children()
                .find(|u| is_element(u, "UUID"))
                .and_then(|u| u.attribute("FileName"))
                .map(str::to_string)
        })
        .ok_or("its first image names no TIFF file (TiffData with UUID FileName)")?;
    let file = beside(companion, &first)?;
    if !file.is_file() {
        return Err(format!(
            "its planes are stored in {first}, which is not beside it; copy the set's files \
             together"
        ));
    }
    Ok((file, xml))
}

#[cfg(test)]
mod tests {
    use super::*;

    const NS: &str = "http://www.openmicroscopy.org/Schemas/OME/2016-06";

    #[test]
    fn a_binary_only_document_points_to_its_metadata_file() {
        let xml = format!(
            r#"<?xml version="1.0"?><OME xmlns="{NS}" UUID="urn:uuid:1"><BinaryOnly MetadataFile="set.companion.ome" UUID="urn:uuid:2"/></OME>"#
        );
        assert_eq!(
            pointer(&xml),
            Some(Pointer {
                metadata_file: "set.companion.ome".into(),
                uuid: Some("urn:uuid:2".into())
            })
        );
        // A full document, and one whose BinaryOnly names no file, point nowhere.
        let full = format!(r#"<OME xmlns="{NS}"><Image ID="Image:0"/></OME>"#);
        assert_eq!(pointer(&full), None);
        let nameless = format!(r#"<OME xmlns="{NS}"><BinaryOnly UUID="urn:uuid:2"/></OME>"#);
        assert_eq!(pointer(&nameless), None);
    }

    #[test]
    fn metadata_files_sit_beside_the_file_naming_them() {
        let tiff = Path::new("/data/set/a.ome.tif");
        assert_eq!(
            beside(tiff, "set.companion.ome").unwrap(),
            Path::new("/data/set/set.companion.ome")
        );
        for name in ["../x.ome", "/etc/x.ome", "sub/x.ome", "", "."] {
            assert!(beside(tiff, name).is_err(), "{name:?}");
        }
    }

    #[test]
    fn ome_xml_text_is_told_from_other_files() {
        assert!(looks_like_ome_xml(b"<?xml version=\"1.0\"?>\n<OME"));
        assert!(looks_like_ome_xml(b"\xef\xbb\xbf\n  <OME xmlns"));
        assert!(!looks_like_ome_xml(b"II*\0"));
        assert!(!looks_like_ome_xml(b"<html>"));
        // XML of another kind (an instrument's export) is not a companion file.
        assert!(!looks_like_ome_xml(b"<?xml version=\"1.0\"?><Scan>"));
    }

    #[test]
    fn a_metadata_document_is_checked() {
        let tmp = tempfile::tempdir().unwrap();
        let file = tmp.path().join("set.companion.ome");
        let write = |text: &str| std::fs::write(&file, text).unwrap();
        write(&format!(
            r#"<OME xmlns="{NS}" UUID="urn:uuid:2"><Image ID="Image:0"/></OME>"#
        ));
        assert!(read_document(&file, Some("urn:uuid:2")).is_ok());
        let e = read_document(&file, Some("urn:uuid:3")).unwrap_err();
        assert!(e.contains("urn:uuid:3"), "{e}");
        write(&format!(
            r#"<OME xmlns="{NS}"><BinaryOnly MetadataFile="other.ome"/></OME>"#
        ));
        assert!(read_document(&file, None).unwrap_err().contains("in turn"));
        write("<html></html>");
        assert!(read_document(&file, None)
            .unwrap_err()
            .contains("not an OME-XML"));
        std::fs::write(&file, [0xff, 0xfe, 0x00]).unwrap();
        assert!(read_document(&file, None).unwrap_err().contains("UTF-8"));
    }
}
