//! Files of kinds delmesh does not read: other 3D formats (glTF, FBX,
//! Blender, COLLADA, USD, ...), images, documents, archives and other
//! compressions than gzip, and binary data in general.
//!
//! Asked only of a file that its reader refused, to replace that reader's
//! reason, which says nothing useful then: the OBJ reader took a GLB's
//! binary chunks for text whose "lines end in a carriage return alone".
//! Known kinds are told by their first bytes (their magic numbers), else by
//! the file's extension; anything else whose start is not text is "binary
//! data". A file that a reader takes is never judged here, nor one whose
//! content looks like a mesh of a format delmesh reads.

/// What the user can do with a file of one kind.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Remedy {
    /// Another mesh or scene format: convert it.
    Convert,
    /// Compressed by another program than gzip: decompress it (the command).
    Decompress(&'static str),
    /// An archive: take the mesh out of it.
    Extract,
    /// Not a mesh at all (an image, a document, a program).
    NotAMesh,
}

/// A kind of file, as a sentence names it ("a binary glTF file (GLB)").
type Kind = (&'static str, Remedy);

/// Kinds told by the bytes a file starts with.
const MAGIC: &[(&[u8], Kind)] = &[
    (b"glTF", ("a binary glTF file (GLB)", Remedy::Convert)),
    (b"Kaydara FBX Binary", ("a binary FBX file", Remedy::Convert)),
    (b"; FBX ", ("an ASCII FBX file", Remedy::Convert)),
    (b"BLENDER", ("a Blender file (.blend)", Remedy::Convert)),
    (b"PXR-USDC", ("a binary USD file (.usdc)", Remedy::Convert)),
    (b"#usda", ("a USD text file (.usda)", Remedy::Convert)),
    (b"DRACO", ("a Draco-compressed mesh", Remedy::Convert)),
    (b"Ogawa", ("an Alembic file (.abc)", Remedy::Convert)),
    (b"# vtk DataFile", ("a VTK file", Remedy::Convert)),
    (b"#VRML", ("a VRML file", Remedy::Convert)),
    (b"$MeshFormat", ("a Gmsh mesh file (.msh)", Remedy::Convert)),
    (b"MeshVersionFormatted", ("a Medit mesh file (.mesh)", Remedy::Convert)),
    (
        b"ISO-10303-21",
        ("a STEP file (a CAD model, not a mesh)", Remedy::Convert),
    ),
    (b"\x89HDF\r\n\x1a\n", ("an HDF5 file", Remedy::Convert)),
    (b"\x93NUMPY", ("a NumPy array file (.npy)", Remedy::Convert)),
    (b"MATLAB 5.0 MAT-file", ("a MATLAB file (.mat)", Remedy::Convert)),
    (b"BZh", ("bzip2-compressed data", Remedy::Decompress("bunzip2"))),
    (b"\xfd7zXZ\x00", ("xz-compressed data", Remedy::Decompress("unxz"))),
    (
        b"\x28\xb5\x2f\xfd",
        ("zstd-compressed data", Remedy::Decompress("unzstd")),
    ),
    (
        b"\x04\x22\x4d\x18",
        ("LZ4-compressed data", Remedy::Decompress("unlz4")),
    ),
    (
        b"PK\x03\x04",
        ("a ZIP archive (as 3MF and USDZ files are)", Remedy::Extract),
    ),
    (b"7z\xbc\xaf\x27\x1c", ("a 7-Zip archive", Remedy::Extract)),
    (b"Rar!\x1a\x07", ("a RAR archive", Remedy::Extract)),
    (b"\x89PNG\r\n\x1a\n", ("a PNG image", Remedy::NotAMesh)),
    (b"\xff\xd8\xff", ("a JPEG image", Remedy::NotAMesh)),
    (b"GIF8", ("a GIF image", Remedy::NotAMesh)),
    (b"%PDF-", ("a PDF document", Remedy::NotAMesh)),
    (b"\x7fELF", ("a program (an ELF executable)", Remedy::NotAMesh)),
];

/// Kinds told by a file's extension (lower case), when its bytes tell none.
const EXTENSIONS: &[(&str, Kind)] = &[
    ("glb", ("a binary glTF file (GLB)", Remedy::Convert)),
    ("gltf", ("a glTF file", Remedy::Convert)),
    ("fbx", ("an FBX file", Remedy::Convert)),
    ("blend", ("a Blender file (.blend)", Remedy::Convert)),
    ("dae", ("a COLLADA file (.dae)", Remedy::Convert)),
    ("3ds", ("a 3D Studio file (.3ds)", Remedy::Convert)),
    ("3mf", ("a 3MF file", Remedy::Convert)),
    ("usd", ("a USD file", Remedy::Convert)),
    ("usda", ("a USD text file (.usda)", Remedy::Convert)),
    ("usdc", ("a binary USD file (.usdc)", Remedy::Convert)),
    ("usdz", ("a USDZ file", Remedy::Convert)),
    ("abc", ("an Alembic file (.abc)", Remedy::Convert)),
    ("x3d", ("an X3D file", Remedy::Convert)),
    ("wrl", ("a VRML file", Remedy::Convert)),
    ("vtk", ("a VTK file", Remedy::Convert)),
    ("vtp", ("a VTK polygon data file (.vtp)", Remedy::Convert)),
    ("vtu", ("a VTK unstructured grid file (.vtu)", Remedy::Convert)),
    ("msh", ("a Gmsh mesh file (.msh)", Remedy::Convert)),
    ("mesh", ("a Medit mesh file (.mesh)", Remedy::Convert)),
    ("step", ("a STEP file (a CAD model, not a mesh)", Remedy::Convert)),
    ("stp", ("a STEP file (a CAD model, not a mesh)", Remedy::Convert)),
    ("iges", ("an IGES file (a CAD model, not a mesh)", Remedy::Convert)),
    ("igs", ("an IGES file (a CAD model, not a mesh)", Remedy::Convert)),
    ("dxf", ("a DXF drawing", Remedy::Convert)),
    ("las", ("a LAS point cloud", Remedy::Convert)),
    ("laz", ("a LAZ point cloud", Remedy::Convert)),
    ("pcd", ("a PCD point cloud", Remedy::Convert)),
    ("e57", ("an E57 point cloud", Remedy::Convert)),
];

/// How many bytes of a file's start are looked at for the XML and JSON
/// kinds and for binary data.
const HEAD: usize = 4096;

/// Why the file `name` (its path or name, if it has one) with content
/// `bytes` is none of the meshes delmesh reads, if it is of a kind this
/// module knows: one sentence for the end of `FILE: `, naming the kind and
/// what to do. `text` says that it was read as a text format (OBJ or
/// OFF): only then is binary data of no known kind called so (the binary
/// PLY and STL readers say better what is wrong with theirs). `bytes` are
/// the file's content after gzip.
pub fn foreign_reason(name: Option<&str>, bytes: &[u8], text: bool) -> Option<String> {
    // Content that looks like a mesh delmesh reads (an OBJ with an error,
    // named `.mesh`) keeps its reader's reason.
    if super::sniff_format(bytes).is_some() {
        return None;
    }
    let (kind, remedy) = kind_of(name, bytes).or_else(|| {
        let binary = text && is_binary(&bytes[..bytes.len().min(HEAD)]);
        binary.then_some(("binary data of no known mesh format", Remedy::NotAMesh))
    })?;
    let reads = "delmesh reads OBJ, OFF, PLY and STL";
    Some(match remedy {
        Remedy::Convert => format!("this is {kind}; {reads}: convert it first"),
        Remedy::Decompress(tool) => format!("this is {kind}; delmesh inflates gzip only: decompress it first ({tool})"),
        Remedy::Extract => format!("this is {kind}; {reads}: extract the mesh first"),
        Remedy::NotAMesh => format!("this is {kind}, not a mesh ({reads})"),
    })
}

/// The kind of a file by its first bytes, else by its extension.
fn kind_of(name: Option<&str>, bytes: &[u8]) -> Option<Kind> {
    let start = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    if let Some(&(_, kind)) = MAGIC.iter().find(|(magic, _)| start.starts_with(magic)) {
        return Some(kind);
    }
    let head = &start[..start.len().min(HEAD)];
    if start.starts_with(b"MZ") && is_binary(head) {
        return Some(("a program (a Windows executable)", Remedy::NotAMesh));
    }
    if bytes.get(257..262) == Some(b"ustar") {
        return Some(("a tar archive", Remedy::Extract));
    }
    let text = head.trim_ascii_start();
    let has = |word: &[u8]| head.windows(word.len()).any(|w| w == word);
    if text.starts_with(b"<") {
        return Some(if has(b"<COLLADA") {
            ("a COLLADA file (.dae)", Remedy::Convert)
        } else if has(b"<X3D") {
            ("an X3D file", Remedy::Convert)
        } else if has(b"<VTKFile") {
            ("a VTK XML file", Remedy::Convert)
        } else if has(b"<html") || has(b"<HTML") || has(b"<!DOCTYPE html") {
            ("a web page (HTML)", Remedy::NotAMesh)
        } else {
            ("an XML file", Remedy::Convert)
        });
    }
    if text.starts_with(b"{") && has(b"\"asset\"") {
        return Some(("a glTF file", Remedy::Convert));
    }
    let extension = name?
        .rsplit(['/', '\\'])
        .next()?
        .rsplit_once('.')?
        .1
        .to_ascii_lowercase();
    EXTENSIONS.iter().find(|(e, _)| *e == extension).map(|&(_, kind)| kind)
}

/// Whether `head`, a file's first bytes, is not text: it holds a zero byte,
/// or it is not UTF-8 and more than one byte in 20 is a control character
/// other than the blanks and line ends that text has (random bytes: one in
/// nine). Text in a legacy 8-bit encoding has few control characters, and
/// UTF-8 text with escape sequences is still text.
fn is_binary(head: &[u8]) -> bool {
    if head.contains(&0) {
        return true;
    }
    // A character cut at the end of `head` is no sign of binary data.
    let utf8 = std::str::from_utf8(head).map_or_else(|e| e.error_len().is_none(), |_| true);
    let control = head
        .iter()
        .filter(|&&b| b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r' | 0x0b | 0x0c) || b == 0x7f)
        .count();
    !utf8 && control * 20 > head.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_kinds_are_told_by_their_first_bytes_whatever_the_name() {
        let glb = [b"glTF\x02\x00\x00\x00".as_slice(), &[0xA5; 64]].concat();
        let reason = foreign_reason(Some("model.obj"), &glb, true).unwrap();
        assert_eq!(
            reason,
            "this is a binary glTF file (GLB); delmesh reads OBJ, OFF, PLY and STL: convert it first"
        );
        let xz = b"\xfd7zXZ\x00\x00\x04";
        assert!(foreign_reason(None, xz, false)
            .unwrap()
            .contains("decompress it first (unxz)"));
        let zip = b"PK\x03\x04\x14\x00";
        assert!(foreign_reason(Some("part.3mf"), zip, true)
            .unwrap()
            .contains("a ZIP archive"));
        let png = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR";
        assert_eq!(
            foreign_reason(Some("a.stl"), png, false).unwrap(),
            "this is a PNG image, not a mesh (delmesh reads OBJ, OFF, PLY and STL)"
        );
        let dae = b"<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"x\">";
        assert!(foreign_reason(None, dae, true).unwrap().contains("a COLLADA file"));
        let gltf = b"{\n  \"asset\": {\"version\": \"2.0\"}";
        assert!(foreign_reason(None, gltf, true).unwrap().contains("a glTF file"));
    }

    #[test]
    fn extensions_tell_a_kind_that_the_bytes_do_not() {
        let reason = foreign_reason(Some("/data/Part.FBX"), b"garbled text\n", true).unwrap();
        assert!(reason.starts_with("this is an FBX file;"), "{reason}");
        assert_eq!(foreign_reason(Some("bunny.obj"), b"garbled text\n", true), None);
        assert_eq!(foreign_reason(Some("noextension"), b"garbled text\n", true), None);
        // An OBJ with an error, whatever its name, is an OBJ with an error.
        let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 x\n";
        assert_eq!(foreign_reason(Some("part.mesh"), obj, true), None);
        assert_eq!(foreign_reason(Some("part.fbx"), obj, true), None);
    }

    #[test]
    fn binary_data_is_called_so_only_when_read_as_text() {
        let noise: Vec<u8> = (0u32..2000)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect();
        let reason = foreign_reason(Some("noise.obj"), &noise, true).unwrap();
        assert!(
            reason.starts_with("this is binary data of no known mesh format, not a mesh"),
            "{reason}"
        );
        assert_eq!(foreign_reason(Some("noise.stl"), &noise, false), None);
        // Text with a stray control character or a CRLF is text.
        assert!(!is_binary(b"v 0 0 0\r\nv 1 0 0\x1a\r\nf 1 2 3\r\n"));
        assert!(is_binary(b"v 0 0 0\x00"));
        assert!(!is_binary(b"\x1b]0;title\x07\x1b[31mred\nv 0 0 0\n"));
        assert!(!is_binary(b"g caf\xe9\nv 0 0 0\n"));
        assert!(is_binary(b"\x80\x81\xff\x12\x0a\x13"));
    }
}
