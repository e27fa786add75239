//! Tests of the OFF, PLY and STL readers and writers.

use std::borrow::Cow;
use std::io::Write;
use std::time::{Duration, Instant};

use delmesh::io::formats::{
    format_from_name, is_utf16_text, maybe_gunzip, read_off, read_ply, read_stl, sniff_format, write_off,
    write_off_with, write_ply_ascii, write_ply_binary, write_stl_binary, ColorText, Format, FormatError, Numbering,
    OffColors, OffExtras, OriginKind, RawMesh,
};

// ---------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------

/// The faces of a mesh as vectors of indices.
fn faces(m: &RawMesh) -> Vec<Vec<u32>> {
    m.face_start
        .windows(2)
        .map(|r| m.indices[r[0] as usize..r[1] as usize].to_vec())
        .collect()
}

/// Checks the invariants every reader promises.
fn check_invariants(m: &RawMesh) {
    let nf = m.face_start.len().saturating_sub(1);
    assert_eq!(m.face_origin.len(), nf);
    assert_eq!(m.vertex_origin.len(), m.positions.len());
    if nf == 0 {
        assert!(m.face_start.is_empty());
        assert!(m.indices.is_empty());
    } else {
        assert_eq!(m.face_start[0], 0);
        assert_eq!(*m.face_start.last().unwrap() as usize, m.indices.len());
    }
    for f in faces(m) {
        assert!(f.len() >= 3);
    }
    assert!(m.indices.iter().all(|&i| (i as usize) < m.positions.len()));
    assert!(m.positions.iter().all(|p| p.iter().all(|c| c.is_finite())));
    if let Some(c) = &m.colors {
        assert_eq!(c.len(), m.positions.len());
    }
}

fn bits(p: &[[f64; 3]]) -> Vec<[u64; 3]> {
    p.iter().map(|v| v.map(f64::to_bits)).collect()
}

/// Coordinates that stress shortest round-trip printing.
fn tricky_positions() -> Vec<[f64; 3]> {
    vec![
        [0.1, 0.2, 0.3],
        [-0.0, 1.0 / 3.0, std::f64::consts::PI],
        [1e308, -1e308, 1e-300],
        [5e-324, f64::MIN_POSITIVE, f64::MAX],
        [-f64::MAX, 0.1 + 0.2, -2.5e-17],
        [1.0, 2.0, 3.0],
    ]
}

fn tricky_triangles() -> Vec<[u32; 3]> {
    vec![[0, 1, 2], [2, 3, 4], [4, 5, 0], [1, 3, 5]]
}

/// Little or big endian binary writer for hand-made PLY data.
struct Bytes {
    big: bool,
    buf: Vec<u8>,
}

impl Bytes {
    fn new(big: bool, header: &str) -> Self {
        Bytes {
            big,
            buf: header.as_bytes().to_vec(),
        }
    }
    fn put(&mut self, le: &[u8], be: &[u8]) -> &mut Self {
        self.buf.extend_from_slice(if self.big { be } else { le });
        self
    }
    fn u8(&mut self, v: u8) -> &mut Self {
        self.buf.push(v);
        self
    }
    fn i8(&mut self, v: i8) -> &mut Self {
        self.buf.push(v as u8);
        self
    }
    fn i16(&mut self, v: i16) -> &mut Self {
        self.put(&v.to_le_bytes(), &v.to_be_bytes())
    }
    fn u16(&mut self, v: u16) -> &mut Self {
        self.put(&v.to_le_bytes(), &v.to_be_bytes())
    }
    fn i32(&mut self, v: i32) -> &mut Self {
        self.put(&v.to_le_bytes(), &v.to_be_bytes())
    }
    fn u32(&mut self, v: u32) -> &mut Self {
        self.put(&v.to_le_bytes(), &v.to_be_bytes())
    }
    fn f32(&mut self, v: f32) -> &mut Self {
        self.put(&v.to_le_bytes(), &v.to_be_bytes())
    }
    fn f64(&mut self, v: f64) -> &mut Self {
        self.put(&v.to_le_bytes(), &v.to_be_bytes())
    }
}

/// A small deterministic PRNG (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn gzip(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

/// Runs bytes through every reader and the detectors; none may panic.
fn run_all_readers(bytes: &[u8]) {
    for m in [read_off(bytes), read_ply(bytes), read_stl(bytes)]
        .into_iter()
        .flatten()
    {
        check_invariants(&m);
    }
    let _ = sniff_format(bytes);
    if let Ok(Cow::Owned(data)) = maybe_gunzip(bytes, 1 << 20) {
        let _ = read_ply(&data);
    }
}

fn err_of(r: Result<RawMesh, FormatError>) -> FormatError {
    match r {
        Ok(m) => panic!("expected an error, got a mesh with {} vertices", m.positions.len()),
        Err(e) => e,
    }
}

/// Asserts that `f` fails within a second and returns the error.
fn fails_fast(f: impl FnOnce() -> Result<RawMesh, FormatError>) -> FormatError {
    let t = Instant::now();
    let e = err_of(f());
    assert!(t.elapsed() < Duration::from_secs(1), "took {:?}", t.elapsed());
    e
}

// ---------------------------------------------------------------------------
// Round trips
// ---------------------------------------------------------------------------

#[test]
fn ply_binary_round_trip_is_bit_exact() {
    let (p, t) = (tricky_positions(), tricky_triangles());
    let colors: Vec<[u8; 3]> = (0..p.len() as u8).map(|i| [i, 255 - i, i * 40]).collect();
    for c in [None, Some(colors.as_slice())] {
        let mut buf = Vec::new();
        write_ply_binary(&mut buf, &p, &t, c).unwrap();
        assert_eq!(sniff_format(&buf), Some(Format::Ply));
        let m = read_ply(&buf).unwrap();
        check_invariants(&m);
        assert_eq!(bits(&m.positions), bits(&p));
        assert_eq!(faces(&m), t.iter().map(|f| f.to_vec()).collect::<Vec<_>>());
        assert_eq!(m.colors.as_deref(), c);
        assert_eq!(m.origin_kind, OriginKind::Record);
        assert_eq!(m.vertex_origin, (0..p.len() as u32).collect::<Vec<_>>());
        assert_eq!(m.face_origin, (0..t.len() as u32).collect::<Vec<_>>());
    }
}

#[test]
fn ply_ascii_round_trip_is_bit_exact() {
    let (p, t) = (tricky_positions(), tricky_triangles());
    let colors: Vec<[u8; 3]> = (0..p.len() as u8).map(|i| [i, 7, 255]).collect();
    for c in [None, Some(colors.as_slice())] {
        let mut buf = Vec::new();
        write_ply_ascii(&mut buf, &p, &t, c).unwrap();
        let m = read_ply(&buf).unwrap();
        check_invariants(&m);
        assert_eq!(bits(&m.positions), bits(&p));
        assert_eq!(faces(&m), t.iter().map(|f| f.to_vec()).collect::<Vec<_>>());
        assert_eq!(m.colors.as_deref(), c);
        assert_eq!(m.origin_kind, OriginKind::Line);
        let header_lines = if c.is_some() { 13 } else { 10 };
        assert_eq!(m.vertex_origin[0], header_lines + 1);
        assert_eq!(m.face_origin[0], header_lines + 1 + p.len() as u32);
    }
}

#[test]
fn off_round_trip_is_bit_exact() {
    let (p, t) = (tricky_positions(), tricky_triangles());
    let mut buf = Vec::new();
    write_off(&mut buf, &p, &t).unwrap();
    assert_eq!(sniff_format(&buf), Some(Format::Off));
    let m = read_off(&buf).unwrap();
    check_invariants(&m);
    assert_eq!(bits(&m.positions), bits(&p));
    assert_eq!(faces(&m), t.iter().map(|f| f.to_vec()).collect::<Vec<_>>());
    assert_eq!(m.vertex_origin, (3..3 + p.len() as u32).collect::<Vec<_>>());
    assert_eq!(m.colors, None);
}

#[test]
fn stl_binary_round_trip_within_f32() {
    let p = vec![[0.1, 0.2, 0.3], [1.1, 0.2, 0.3], [0.1, 1.2, 0.3], [0.1, 0.2, 1.3]];
    let t = vec![[0, 1, 2], [0, 3, 1], [0, 0, 0]];
    let mut buf = Vec::new();
    write_stl_binary(&mut buf, &p, &t).unwrap();
    assert_eq!(buf.len(), 84 + 50 * t.len());
    assert!(!buf.starts_with(b"solid"));
    assert_eq!(sniff_format(&buf), Some(Format::Stl));
    // A text that starts with `solid` is an STL even cut short (read as
    // one, it says what is missing).
    assert_eq!(sniff_format(b"solid x\n"), Some(Format::Stl));
    assert!(read_stl(b"solid x\n").unwrap_err().to_string().contains("endsolid"));
    let m = read_stl(&buf).unwrap();
    check_invariants(&m);
    assert_eq!(m.positions.len(), 9);
    assert_eq!(faces(&m), vec![vec![0, 1, 2], vec![3, 4, 5], vec![6, 7, 8]]);
    for (f, tri) in t.iter().enumerate() {
        for k in 0..3 {
            let want = p[tri[k] as usize].map(|c| c as f32 as f64);
            assert_eq!(m.positions[3 * f + k], want);
        }
    }
    assert_eq!(m.origin_kind, OriginKind::Record);
    assert_eq!(m.face_origin, vec![0, 1, 2]);
    assert_eq!(m.vertex_origin, vec![0, 0, 0, 1, 1, 1, 2, 2, 2]);
    // Normal of the first facet: +z; of the degenerate one: zero.
    let normal = |f: usize| -> [f32; 3] {
        let at = 84 + 50 * f;
        [0, 1, 2].map(|k| f32::from_le_bytes(buf[at + 4 * k..at + 4 * k + 4].try_into().unwrap()))
    };
    assert_eq!(normal(0), [0.0, 0.0, 1.0]);
    assert_eq!(normal(2), [0.0, 0.0, 0.0]);
}

#[test]
fn round_trips_through_files() {
    let dir = tempfile::tempdir().unwrap();
    let (p, t) = (tricky_positions(), tricky_triangles());
    let path = dir.path().join("mesh.ply");
    let mut file = std::fs::File::create(&path).unwrap();
    write_ply_binary(&mut file, &p, &t, None).unwrap();
    drop(file);
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(format_from_name(path.to_str().unwrap()), Some(Format::Ply));
    assert_eq!(bits(&read_ply(&bytes).unwrap().positions), bits(&p));

    let path = dir.path().join("mesh.off");
    let mut file = std::fs::File::create(&path).unwrap();
    write_off(&mut file, &p, &t).unwrap();
    drop(file);
    assert_eq!(
        bits(&read_off(&std::fs::read(&path).unwrap()).unwrap().positions),
        bits(&p)
    );
}

#[test]
fn writers_refuse_what_no_reader_takes_back() {
    let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, f64::NAN, 0.0]];
    let mut buf = Vec::new();
    assert!(write_off(&mut buf, &p, &[[0, 1, 2]]).is_err());
    assert!(write_ply_ascii(&mut buf, &p[..2], &[[0, 1, 2]], None).is_err());
    assert!(write_ply_binary(&mut buf, &p[..2], &[], Some(&[[0, 0, 0]])).is_err());
    assert!(write_stl_binary(&mut buf, &[[1e300, 0.0, 0.0]], &[[0, 0, 0]]).is_err());
    // OBJ alike (it wrote `f 1 2 4` for three vertices, and NaN as a
    // number), with and without attributes; through `write_mesh`, no file.
    use delmesh::io::obj::{write_obj, write_obj_with_attributes};
    let attributes = delmesh::attributes::Attributes {
        groups: vec![Default::default()],
        face_group: vec![0],
        ..Default::default()
    };
    for (p, t) in [(&p[..], [0, 1, 2]), (&p[..2], [0, 1, 2]), (&p[..2], [0, 1, 9])] {
        assert!(write_obj(&mut buf, p, &[t]).is_err());
        assert!(write_obj_with_attributes(&mut buf, p, &[t], &attributes).is_err());
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.obj");
    let positions: Vec<glam::DVec3> = p[..2].iter().map(|c| glam::DVec3::from_array(*c)).collect();
    let e = delmesh::io::write_mesh(&path, &positions, &[[0, 1, 2]]).unwrap_err();
    assert!(
        e.to_string()
            .contains("triangle 0 has an index out of range (2 vertices)"),
        "{e}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn empty_mesh_round_trips() {
    let mut buf = Vec::new();
    write_ply_binary(&mut buf, &[], &[], None).unwrap();
    assert_eq!(
        read_ply(&buf).unwrap(),
        RawMesh {
            origin_kind: OriginKind::Record,
            numbering: Numbering::FromZero,
            ..RawMesh::default()
        }
    );
    buf.clear();
    write_off(&mut buf, &[], &[]).unwrap();
    assert_eq!(
        read_off(&buf).unwrap(),
        RawMesh {
            numbering: Numbering::FromZero,
            ..RawMesh::default()
        }
    );
    buf.clear();
    write_stl_binary(&mut buf, &[], &[]).unwrap();
    assert_eq!(read_stl(&buf).unwrap().positions.len(), 0);
}

// ---------------------------------------------------------------------------
// PLY variants
// ---------------------------------------------------------------------------

#[test]
fn ply_ascii_with_extra_properties_and_skipped_elements() {
    let text = "ply\n\
format ascii 1.0\n\
comment made by hand\n\
obj_info scanner 1\n\
element vertex 4\n\
property float nx\n\
property float ny\n\
property double x\n\
property float confidence\n\
property uchar red\n\
property double y\n\
property list uchar float uv\n\
property uchar green\n\
property double z\n\
property float intensity\n\
property uchar blue\n\
element edge 2\n\
property int vertex1\n\
property list uchar int more\n\
property int vertex2\n\
element face 2\n\
property uchar flags\n\
property list uchar int vertex_indices\n\
property list uchar float texcoord\n\
element material 1\n\
property list ushort uchar name\n\
end_header\n\
0 0 0.5 1 10 1.5 2 0.1 0.2 20 2.5 0.9 30\n\
0 0 -1 1 11 -2 0 21 -3 0.9 31\n\
\n\
0 0 1e308 1 12 1e-300 1 7 22 0 0.9 32\n\
0 0 4 1 13 5 3 1 2 3 23 6 0.9 33\n\
0 3 1 2 3 1\n\
2 0 3\n\
7 3 0 1 2 0\n\
1 4 0 1 2 3 2 0.5 0.5\n\
3 65 66 67\n\
trailing garbage is ignored\n";
    assert_eq!(sniff_format(text.as_bytes()), Some(Format::Ply));
    let m = read_ply(text.as_bytes()).unwrap();
    check_invariants(&m);
    assert!(
        m.notes
            .iter()
            .any(|n| n.starts_with("line 38: data after the elements")),
        "{:?}",
        m.notes
    );
    assert_eq!(
        m.positions,
        vec![
            [0.5, 1.5, 2.5],
            [-1.0, -2.0, -3.0],
            [1e308, 1e-300, 0.0],
            [4.0, 5.0, 6.0]
        ]
    );
    assert_eq!(
        m.colors,
        Some(vec![[10, 20, 30], [11, 21, 31], [12, 22, 32], [13, 23, 33]])
    );
    assert_eq!(faces(&m), vec![vec![0, 1, 2], vec![0, 1, 2, 3]]);
    assert_eq!(m.vertex_origin, vec![28, 29, 31, 32]);
    assert_eq!(m.face_origin, vec![35, 36]);
}

#[test]
fn ply_ascii_dragon_style_confidence_intensity() {
    let text = "ply\r\nformat ascii 1.0\r\ncomment zipper output\r\nelement vertex 3\r\nproperty float x\r\n\
property float y\r\nproperty float z\r\nproperty float confidence\r\nproperty float intensity\r\n\
element face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n\
-0.0378297 0.12794 0.00447467 0.850855 0.5 \r\n-0.0447794 0.128887 0.00190497 0.900159 0.5 \r\n\
-0.0680095 0.151244 0.0371953 0.398443 0.5 \r\n3 0 1 2 \r\n";
    let m = read_ply(text.as_bytes()).unwrap();
    check_invariants(&m);
    assert_eq!(m.positions[1], [-0.0447794, 0.128887, 0.00190497]);
    assert_eq!(faces(&m), vec![vec![0, 1, 2]]);
    assert_eq!(m.colors, None);
    assert_eq!(m.vertex_origin, vec![13, 14, 15]);
}

/// A binary PLY with mixed types and aliases, x/y/z among other properties, and skipped elements.
fn handmade_binary_ply(big: bool) -> Vec<u8> {
    let header = format!(
        "ply\nformat {} 1.0\ncomment types and aliases\n\
element vertex 4\nproperty char flag\nproperty float64 x\nproperty ushort id\nproperty float32 y\n\
property list uint8 int16 neighbours\nproperty int32 z\nproperty uint8 red\nproperty uchar green\n\
property uint8 blue\nproperty uint confidence\n\
element edge 2\nproperty int vertex1\nproperty list uchar double weights\nproperty int vertex2\n\
element face 2\nproperty uchar flags\nproperty list uint8 uint32 vertex_indices\nproperty list ushort float texcoord\n\
element material 3\nproperty uchar r\nproperty double shininess\n\
end_header\n",
        if big {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        }
    );
    let mut b = Bytes::new(big, &header);
    let verts: [(f64, f32, i32); 4] = [
        (0.1, 1.5, -3),
        (1e308, -2.25, 7),
        (1e-300, 0.0, 0),
        (-5.0, 1e30, 2_000_000_000),
    ];
    for (i, (x, y, z)) in verts.iter().enumerate() {
        b.i8(-1).f64(*x).u16(999).f32(*y);
        b.u8(2).i16(-7).i16(8);
        b.i32(*z)
            .u8(i as u8)
            .u8(100 + i as u8)
            .u8(200 + i as u8)
            .u32(0xdead_beef);
    }
    for _ in 0..2 {
        b.i32(0).u8(3).f64(1.0).f64(2.0).f64(3.0).i32(1);
    }
    b.u8(9).u8(3).u32(0).u32(1).u32(2).u16(2).f32(0.5).f32(0.25);
    b.u8(9).u8(4).u32(3).u32(2).u32(1).u32(0).u16(0);
    for _ in 0..3 {
        b.u8(1).f64(0.5);
    }
    b.buf.extend_from_slice(b"trailing bytes");
    b.buf
}

#[test]
fn ply_binary_little_and_big_endian_handwritten() {
    for big in [false, true] {
        let bytes = handmade_binary_ply(big);
        assert_eq!(sniff_format(&bytes), Some(Format::Ply));
        let m = read_ply(&bytes).unwrap_or_else(|e| panic!("big={big}: {e}"));
        check_invariants(&m);
        assert!(
            m.notes.iter().any(|n| n.starts_with("14 bytes after the elements")),
            "{:?}",
            m.notes
        );
        assert_eq!(
            m.positions,
            vec![
                [0.1, 1.5, -3.0],
                [1e308, -2.25, 7.0],
                [1e-300, 0.0, 0.0],
                [-5.0, 1e30f32 as f64, 2e9]
            ]
        );
        assert_eq!(
            m.colors,
            Some(vec![[0, 100, 200], [1, 101, 201], [2, 102, 202], [3, 103, 203]])
        );
        assert_eq!(faces(&m), vec![vec![0, 1, 2], vec![3, 2, 1, 0]]);
        assert_eq!(m.origin_kind, OriginKind::Record);
        assert_eq!(m.face_origin, vec![0, 1]);
    }
}

#[test]
fn ply_binary_truncated_at_every_length_is_an_error() {
    let bytes = handmade_binary_ply(false);
    let data_end = bytes.len() - b"trailing bytes".len();
    for len in 0..data_end {
        let e = err_of(read_ply(&bytes[..len]));
        assert!(!e.what.is_empty());
    }
    assert!(read_ply(&bytes[..data_end]).is_ok());
}

#[test]
fn ply_float_colors_are_scaled_and_vertex_index_name() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
property float red\nproperty float green\nproperty float blue\nproperty float alpha\n\
element face 1\nproperty list int ushort vertex_index\nend_header\n\
0 0 0 0 0.5 1 1\n1 0 0 1 2 -1 1\n0 1 0 0.2 0.4 0.6 1\n3 2 1 0\n";
    let m = read_ply(text.as_bytes()).unwrap();
    assert_eq!(m.colors, Some(vec![[0, 128, 255], [255, 255, 0], [51, 102, 153]]));
    assert_eq!(faces(&m), vec![vec![2, 1, 0]]);
}

#[test]
fn ply_without_faces_or_colours_is_a_point_cloud() {
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\n\
end_header\n1 2 3\n4 5 6";
    let m = read_ply(text.as_bytes()).unwrap();
    assert_eq!(m.positions, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
    assert!(m.face_start.is_empty() && m.indices.is_empty() && m.colors.is_none());
}

#[test]
fn ply_header_errors_are_clear() {
    let cases: &[(&str, &str)] = &[
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n",
            "`z`",
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n",
            "quad",
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
            "end_header",
        ),
        ("ply\nformat xml 1.0\nend_header\n", "xml"),
        ("ply\nelement vertex 0\nend_header\n", "format"),
        ("ply\nformat ascii 1.0\nelement vertex -1\nend_header\n", "-1"),
        (
            "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
            "before any element",
        ),
        ("ply\nformat ascii 1.0\nbogus\nend_header\n", "bogus"),
        (
            "ply\nformat ascii 1.0\nelement face 0\nend_header\n",
            "no vertex element",
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n\
element face 1\nproperty list uchar float vertex_indices\nend_header\n3 0 0 0\n",
            "non-integer",
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n\
element face 1\nproperty list float int vertex_indices\nend_header\n3 0 0 0\n",
            "count type",
        ),
        ("plyx\nformat ascii 1.0\nend_header\n", "ply"),
    ];
    for (text, needle) in cases {
        let e = err_of(read_ply(text.as_bytes()));
        assert!(e.to_string().contains(needle), "{text:?}: {e}");
    }
}

// ---------------------------------------------------------------------------
// OFF variants
// ---------------------------------------------------------------------------

#[test]
fn off_with_comments_and_counts_on_the_header_line() {
    let text = "# a comment first\nOFF 3 1 0 # counts here\n\n0 0 0 # origin\n# between\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(sniff_format(text.as_bytes()), Some(Format::Off));
    let m = read_off(text.as_bytes()).unwrap();
    check_invariants(&m);
    assert_eq!(m.positions, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    assert_eq!(faces(&m), vec![vec![0, 1, 2]]);
    assert_eq!(m.vertex_origin, vec![4, 6, 7]);
    assert_eq!(m.face_origin, vec![8]);
    assert_eq!(m.origin_kind, OriginKind::Line);
}

/// ModelNet's OFF files often glue the vertex count to the keyword
/// (`OFF3 1 0`): read as `OFF 3 1 0`; a keyword glued to anything else
/// (`OFFa`, `COFF3`) is still not OFF.
#[test]
fn off_with_the_vertex_count_glued_to_the_keyword() {
    let text = "OFF3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(sniff_format(text.as_bytes()), Some(Format::Off));
    let m = read_off(text.as_bytes()).unwrap();
    check_invariants(&m);
    assert_eq!(m.positions, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    assert_eq!(faces(&m), vec![vec![0, 1, 2]]);
    let same = read_off(b"OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").unwrap();
    assert_eq!(m.positions, same.positions);
    assert_eq!(faces(&m), faces(&same));
    for bad in ["OFFa 1 0\n", "OFF3a 1 0\n", "COFF3 1 0\n"] {
        let e = read_off(bad.as_bytes()).unwrap_err().to_string();
        assert!(e.contains("not an OFF file"), "{bad}: {e}");
        assert_eq!(sniff_format(bad.as_bytes()), None, "{bad}");
    }
}

#[test]
fn off_variants_skip_their_extra_fields() {
    let body =
        |extra: &str| format!("0 0 0{extra}\n1 0 0{extra}\n1 1 0{extra}\n0 1 0{extra}\n4 0 1 2 3 255 0 0\n3 0 2 1\n");
    for (keyword, extra) in [
        ("OFF", ""),
        ("COFF", " 0.5 0.5 0.5 1"),
        ("COFF", " 255 128 0"),
        ("NOFF", " 0 0 1"),
        ("CNOFF", " 0 0 1 0.1 0.2 0.3 1"),
        ("STOFF", " 0.25 0.75"),
        ("off", ""),
    ] {
        let text = format!("{keyword}\r\n4 2 5\r\n{}", body(extra).replace('\n', "\r\n"));
        let m = read_off(text.as_bytes()).unwrap_or_else(|e| panic!("{keyword}: {e}"));
        check_invariants(&m);
        assert_eq!(m.positions[2], [1.0, 1.0, 0.0], "{keyword}");
        assert_eq!(faces(&m), vec![vec![0, 1, 2, 3], vec![0, 2, 1]], "{keyword}");
    }
    // Headerless: the counts come first.
    let m = read_off(format!("4 2 0\n{}", body("")).as_bytes()).unwrap();
    assert_eq!(m.positions.len(), 4);
    // Two counts only.
    assert!(read_off(format!("OFF\n4 2\n{}", body("")).as_bytes()).is_ok());
}

#[test]
fn off_refused_variants_say_why() {
    for (text, needle) in [
        ("4OFF\n1 0 0\n0 0 0 1\n", "4D"),
        ("nOFF\n4\n1 0 0\n0 0 0 1\n", "n-dimensional"),
        ("OFF BINARY\n", "binary"),
        ("OFX\n1 0 0\n", "not an OFF file"),
        ("OFF\n1 0 0 0\n", "counts line"),
        ("OFF\n1 x 0\n", "face count"),
        ("OFF\n", "counts line"),
    ] {
        let e = err_of(read_off(text.as_bytes()));
        assert!(e.to_string().contains(needle), "{text:?}: {e}");
    }
}

// ---------------------------------------------------------------------------
// STL variants
// ---------------------------------------------------------------------------

const ASCII_STL: &str = "solid cube part\n\
  facet normal 0 0 -1\n    outer loop\n      vertex 0 0 0\n      vertex 1 1 0\n      vertex 1 0 0\n    endloop\n  endfacet\n\
  facet normal 0 0 -1\n    outer loop\n      vertex 0 0 0\n      vertex 0 1 0\n      vertex 1 1 0.5e-3\n    endloop\n  endfacet\n\
endsolid cube part\n";

#[test]
fn stl_ascii_basic() {
    assert_eq!(sniff_format(ASCII_STL.as_bytes()), Some(Format::Stl));
    let m = read_stl(ASCII_STL.as_bytes()).unwrap();
    check_invariants(&m);
    assert_eq!(m.positions.len(), 6);
    assert_eq!(m.positions[5], [1.0, 1.0, 0.5e-3]);
    assert_eq!(faces(&m), vec![vec![0, 1, 2], vec![3, 4, 5]]);
    assert_eq!(m.face_origin, vec![2, 9]);
    assert_eq!(m.vertex_origin, vec![4, 5, 6, 11, 12, 13]);
    assert_eq!(m.origin_kind, OriginKind::Line);
    assert_eq!(m.colors, None);
}

#[test]
fn stl_ascii_tolerates_case_crlf_whitespace_no_name_and_several_solids() {
    let text = "SOLID\r\n\tFACET NORMAL 0 0 1\r\nOUTER LOOP\r\n  VERTEX  0   0 0\r\nVERTEX 1 0 0\r\n\
VERTEX 0 1 0\r\nENDLOOP ENDFACET\r\nENDSOLID\r\nsolid second\n facet normal\n outer loop vertex 0 0 1 vertex 1 0 1 \
vertex 0 1 1 vertex 1 1 1 endloop endfacet endsolid\n\n   some trailing text\n";
    let m = read_stl(text.as_bytes()).unwrap();
    check_invariants(&m);
    assert_eq!(faces(&m), vec![vec![0, 1, 2], vec![3, 4, 5, 6]]);
    assert_eq!(m.positions[6], [1.0, 1.0, 1.0]);
}

/// A binary STL with the given 80-byte header start and facets.
fn binary_stl(header: &[u8], facets: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![b' '; 80];
    b[..header.len()].copy_from_slice(header);
    b.extend_from_slice(&(facets.len() as u32).to_le_bytes());
    for f in facets {
        b.extend_from_slice(&[0u8; 12]);
        for v in f {
            for c in v {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

fn two_facets() -> Vec<[[f32; 3]; 3]> {
    vec![
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [[0.0, 0.0, 1.5], [1.0, 0.0, 1.5], [0.0, 0.1, 1.5]],
    ]
}

#[test]
fn stl_binary_handwritten() {
    let bytes = binary_stl(b"made by hand", &two_facets());
    assert_eq!(sniff_format(&bytes), Some(Format::Stl));
    let m = read_stl(&bytes).unwrap();
    check_invariants(&m);
    assert_eq!(m.positions[5], [0.0, 0.1f32 as f64, 1.5]);
    assert_eq!(faces(&m), vec![vec![0, 1, 2], vec![3, 4, 5]]);
}

#[test]
fn binary_stl_whose_header_starts_with_solid() {
    for header in [
        &b"solid part exported by CAD"[..],
        b"solid",
        b"solid x\nendsolid x\n",
        b"solid x\nfacet normal",
    ] {
        let bytes = binary_stl(header, &two_facets());
        assert_eq!(sniff_format(&bytes), Some(Format::Stl));
        let m = read_stl(&bytes).unwrap_or_else(|e| panic!("{:?}: {e}", String::from_utf8_lossy(header)));
        assert_eq!(
            m.origin_kind,
            OriginKind::Record,
            "{:?}",
            String::from_utf8_lossy(header)
        );
        assert_eq!(m.positions.len(), 6);
        assert_eq!(m.positions[4], [1.0, 0.0, 1.5]);
        // Cut short, even after a whole facet, it is called a truncated
        // binary STL (not text that fails to parse, quoting binary bytes).
        for cut in [1, 30, 50, 99] {
            let e = read_stl(&bytes[..bytes.len() - cut]).unwrap_err().to_string();
            assert!(
                e.starts_with("the binary STL header declares 2 facets (184 bytes) but the file has only")
                    && e.ends_with("(truncated file?)"),
                "{:?}, {cut} bytes short: {e}",
                String::from_utf8_lossy(header)
            );
        }
    }
}

#[test]
fn binary_stl_whose_header_starts_with_the_gzip_magic() {
    // Named STL and of exactly its facets' size: read as it is, not inflated.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("part.stl");
    std::fs::write(&path, binary_stl(&[0x1f, 0x8b, 8, 0], &two_facets())).unwrap();
    let m = delmesh::io::read_raw(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.positions.len(), 6);
    // Not named STL, it is taken for gzip data (and refused as such).
    let other = dir.path().join("part.bin");
    std::fs::copy(&path, &other).unwrap();
    assert!(delmesh::io::read_raw(&other).unwrap_err().to_string().contains("gzip"));
}

#[test]
fn stl_errors() {
    let bytes = binary_stl(b"x", &two_facets());
    for len in 0..bytes.len() {
        // (Cut after its first facet, that is read, with a note.)
        if len != 84 + 50 {
            fails_fast(|| read_stl(&bytes[..len]));
        }
    }
    let mut nan = two_facets();
    nan[1][2][1] = f32::NAN;
    let e = err_of(read_stl(&binary_stl(b"x", &nan)));
    assert_eq!(
        e,
        FormatError {
            line: None,
            what: "facet 1 vertex 2 has a non-finite coordinate".into()
        }
    );
    let e = err_of(read_stl(ASCII_STL.replace("vertex 0 1 0", "vertex 0 NaN 0").as_bytes()));
    assert_eq!(e.line, Some(12));
    assert!(e.what.contains("facet 1 vertex 1"), "{e}");
    let e = err_of(read_stl(ASCII_STL.replace("endsolid cube part\n", "").as_bytes()));
    assert!(e.what.contains("endsolid"), "{e}");
    let e = err_of(read_stl(ASCII_STL.replace("      vertex 1 0 0\n", "").as_bytes()));
    assert!(e.what.contains("2 vertices"), "{e}");
    err_of(read_stl(
        b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 2\nendloop\nendfacet\nendsolid\n",
    ));
    err_of(read_stl(b"hello"));
}

// ---------------------------------------------------------------------------
// gzip, names, sniffing
// ---------------------------------------------------------------------------

#[test]
fn gzip_input() {
    let mut ply = Vec::new();
    write_ply_binary(&mut ply, &tricky_positions(), &tricky_triangles(), None).unwrap();
    let gz = gzip(&ply);
    assert_eq!(sniff_format(&gz), None);
    let data = maybe_gunzip(&gz, 1 << 20).unwrap();
    assert!(matches!(data, Cow::Owned(_)));
    assert_eq!(&*data, &ply[..]);
    assert_eq!(bits(&read_ply(&data).unwrap().positions), bits(&tricky_positions()));
    // Exactly at the limit is fine, one byte less is not.
    assert!(maybe_gunzip(&gz, ply.len() as u64).is_ok());
    assert!(maybe_gunzip(&gz, ply.len() as u64 - 1)
        .unwrap_err()
        .what
        .contains("limit"));
    // Plain bytes are borrowed, whatever the limit.
    assert!(matches!(maybe_gunzip(&ply, 10).unwrap(), Cow::Borrowed(_)));
    // Concatenated members.
    let mut two = gzip(b"OFF\n3 1 0\n0 0 0\n1 0 0\n");
    two.extend_from_slice(&gzip(b"0 1 0\n3 0 1 2\n"));
    assert_eq!(read_off(&maybe_gunzip(&two, 1000).unwrap()).unwrap().positions.len(), 3);
    // Corrupt and truncated data.
    for len in 2..gz.len() {
        assert!(maybe_gunzip(&gz[..len], 1 << 20).is_err(), "prefix of {len} bytes");
    }
    let mut bad = gz.clone();
    bad[15] ^= 0xff;
    let _ = maybe_gunzip(&bad, 1 << 20);
    // The size in the footer only sizes the first allocation: a false one is an error
    // (the member's own check), too small or too large, never a crash.
    for size in [0u32, 1, ply.len() as u32 - 1, ply.len() as u32 + 1, u32::MAX] {
        let mut lying = gz.clone();
        let at = lying.len() - 4;
        lying[at..].copy_from_slice(&size.to_le_bytes());
        assert!(maybe_gunzip(&lying, 1 << 20).is_err(), "footer size {size}");
    }
}

/// Bytes after the last gzip member that start no other member are called
/// what they are (they were "corrupt or truncated (unexpected end of
/// file)"); more members are read, as `gzip -d` reads them. A file cut
/// after the first byte of the magic is truncated gzip data (it was read as
/// text, and refused as an unknown statement '\u{1f}').
#[test]
fn gzip_followed_by_other_bytes_or_cut_after_one_byte_says_so() {
    let off = gzip(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    for (members, extra) in [(1, &b"garbage"[..]), (2, b"\0"), (1, b"\x1f")] {
        let mut bytes = off.repeat(members);
        bytes.extend_from_slice(extra);
        let e = maybe_gunzip(&bytes, 1 << 20).unwrap_err();
        let expected = format!(
            "the gzip data is followed by {} bytes that are not gzip data (appended to the file?)",
            extra.len()
        );
        assert_eq!(e.what, expected);
    }
    let mut two = off.clone();
    two.extend_from_slice(&gzip(b"# more\n"));
    assert!(maybe_gunzip(&two, 1 << 20).unwrap().ends_with(b"3 0 1 2\n# more\n"));
    // A second member cut short is truncated, not trailing bytes.
    two.truncate(two.len() - 3);
    assert!(maybe_gunzip(&two, 1 << 20)
        .unwrap_err()
        .what
        .contains("corrupt or truncated"));
    assert_eq!(
        maybe_gunzip(&off[..1], 1 << 20).unwrap_err().what,
        "the gzip data is truncated (the file has 1 byte, the first of the gzip magic)"
    );
}

/// A file compressed twice (`m.obj.gz.gz`, or gzip data inside a `.gz`)
/// says so; it was read as text, and refused for "lines end in a carriage
/// return alone".
#[test]
fn gzip_inside_gzip_says_so() {
    let off = gzip(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    let e = maybe_gunzip(&gzip(&off), 1 << 20).unwrap_err();
    assert_eq!(
        e.what,
        "the gzip data decompresses to gzip data (the file was compressed twice): decompress it once first (gunzip)"
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.off.gz.gz");
    std::fs::write(&path, gzip(&off)).unwrap();
    let e = delmesh::io::read_obj(&path).unwrap_err().to_string();
    assert!(e.contains("m.off.gz.gz") && e.contains("compressed twice"), "{e}");
}

#[test]
fn gzip_bomb_is_limited() {
    let gz = gzip(&vec![b'0'; 50 << 20]);
    assert!(gz.len() < 1 << 20);
    let t = Instant::now();
    let e = maybe_gunzip(&gz, 1 << 20).unwrap_err();
    assert!(e.what.contains("limit"), "{e}");
    assert!(t.elapsed() < Duration::from_secs(1));
}

#[test]
fn format_from_name_cases() {
    for (name, want) in [
        ("bunny.obj", Some(Format::Obj)),
        ("dir.stl/mesh.OFF", Some(Format::Off)),
        ("C:\\scans\\Dragon_VRIP.PLY.GZ", Some(Format::Ply)),
        ("part.Stl", Some(Format::Stl)),
        ("mesh.ply.gz", Some(Format::Ply)),
        ("mesh.gz", None),
        ("mesh.txt", None),
        ("mesh", None),
        ("", None),
        ("a.b/mesh", None),
    ] {
        assert_eq!(format_from_name(name), want, "{name}");
    }
}

/// A first line `ply` padded with spaces or a tab is read, as the header's
/// other lines are; it was
/// refused as "not a PLY file", and a file without a name (standard input,
/// `.dat`) was not taken for PLY at all.
#[test]
fn ply_first_line_may_end_in_spaces() {
    let body = "format ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    for first in ["ply ", "ply\t", "ply  \r"] {
        let text = format!("{first}\n{body}");
        assert_eq!(sniff_format(text.as_bytes()), Some(Format::Ply), "{first:?}");
        let m = read_ply(text.as_bytes()).unwrap();
        assert_eq!((m.positions.len(), m.face_start.len() - 1), (3, 1), "{first:?}");
    }
    // Other words on it are still not PLY.
    for first in ["ply x", "plyx", " ply"] {
        let text = format!("{first}\n{body}");
        assert!(
            err_of(read_ply(text.as_bytes())).to_string().contains("not a PLY file"),
            "{first:?}"
        );
    }
}

#[test]
fn sniff_format_cases() {
    let cases: &[(&[u8], Option<Format>)] = &[
        (b"ply\nformat ascii 1.0\n", Some(Format::Ply)),
        (b"ply\r\nformat ascii 1.0\r\n", Some(Format::Ply)),
        (b"OFF\n", Some(Format::Off)),
        (b"# c\nCOFF\n1 0 0\n", Some(Format::Off)),
        (b"NOFF 3 1 0\n", Some(Format::Off)),
        (b"\xEF\xBB\xBFOFF\n", Some(Format::Off)),
        (b"solid x\n facet normal 0 0 1\n", Some(Format::Stl)),
        (b"solid x\nendsolid x\n", Some(Format::Stl)),
        (
            b"# OBJ\nmtllib a.mtl\no cube\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            Some(Format::Obj),
        ),
        (b"v 1 2 3\n", Some(Format::Obj)),
        (b"solidarity\n", None),
        (b"hello world\n", None),
        (b"", None),
        (b"\x1f\x8b\x08\x00", None),
    ];
    for (bytes, want) in cases {
        assert_eq!(sniff_format(bytes), *want, "{:?}", String::from_utf8_lossy(bytes));
    }
}

#[test]
fn error_display_names_the_line() {
    let e = err_of(read_off(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n"));
    assert_eq!(
        e,
        FormatError {
            line: Some(6),
            what: "face 0 index 5 is out of range (3 vertices)".into()
        }
    );
    assert_eq!(e.to_string(), "line 6: face 0 index 5 is out of range (3 vertices)");
    let boxed: Box<dyn std::error::Error> = Box::new(e);
    assert!(boxed.to_string().starts_with("line 6"));
}

// ---------------------------------------------------------------------------
// Hostile input
// ---------------------------------------------------------------------------

const XYZ_HEADER: &str = "property float x\nproperty float y\nproperty float z\n";

#[test]
fn ply_header_claiming_2_pow_40_vertices() {
    for format in ["binary_little_endian", "binary_big_endian", "ascii"] {
        let mut bytes =
            format!("ply\nformat {format} 1.0\nelement vertex 1099511627776\n{XYZ_HEADER}end_header\n").into_bytes();
        bytes.extend_from_slice(&[b'1'; 120]);
        let e = fails_fast(|| read_ply(&bytes));
        assert!(
            e.what.contains("declares 1099511627776 vertices") && e.what.contains("120 bytes"),
            "{e}"
        );
    }
    // An element of another name too, and u64::MAX.
    let text = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex 0\n{XYZ_HEADER}element junk 18446744073709551615\n\
property uchar a\nend_header\n"
    );
    fails_fast(|| read_ply(text.as_bytes()));
}

#[test]
fn ply_elements_without_properties_are_skipped_quickly() {
    for format in ["binary_little_endian", "ascii"] {
        let text = format!(
            "ply\nformat {format} 1.0\nelement junk 18446744073709551615\nelement vertex 0\n{XYZ_HEADER}end_header\n"
        );
        let t = Instant::now();
        assert_eq!(read_ply(text.as_bytes()).unwrap().positions.len(), 0);
        assert!(t.elapsed() < Duration::from_secs(1));
    }
}

fn one_triangle_ply(big: bool, count_ty: &str, item_ty: &str) -> Bytes {
    let header = format!(
        "ply\nformat {} 1.0\nelement vertex 3\n{XYZ_HEADER}element face 1\nproperty list {count_ty} {item_ty} vertex_indices\nend_header\n",
        if big { "binary_big_endian" } else { "binary_little_endian" }
    );
    let mut b = Bytes::new(big, &header);
    for v in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0f32]] {
        b.f32(v[0]).f32(v[1]).f32(v[2]);
    }
    b
}

#[test]
fn ply_face_list_count_of_4e9() {
    for big in [false, true] {
        let mut b = one_triangle_ply(big, "uint", "int");
        b.u32(4_000_000_000).i32(0).i32(1).i32(2);
        let e = fails_fast(|| read_ply(&b.buf));
        assert!(
            e.what.contains("face 0 list vertex_indices claims 4000000000 entries"),
            "{e}"
        );
    }
    let mut b = one_triangle_ply(false, "int", "int");
    b.i32(-3).i32(0).i32(1).i32(2);
    let e = fails_fast(|| read_ply(&b.buf));
    assert!(
        e.what.contains("face 0 list vertex_indices has a negative length (-3)"),
        "{e}"
    );
    let text = format!(
        "ply\nformat ascii 1.0\nelement vertex 3\n{XYZ_HEADER}element face 1\nproperty list int int vertex_indices\n\
end_header\n0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n"
    );
    let e = fails_fast(|| read_ply(text.as_bytes()));
    assert!(e.what.contains("has a negative length (-3)"), "{e}");
    let text = format!(
        "ply\nformat ascii 1.0\nelement vertex 3\n{XYZ_HEADER}element face 1\nproperty list uint int vertex_indices\n\
end_header\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n"
    );
    let e = fails_fast(|| read_ply(text.as_bytes()));
    assert_eq!(e.line, Some(13));
    assert!(e.what.contains("claims 4000000000 entries"), "{e}");
}

#[test]
fn negative_and_out_of_range_indices() {
    let mut b = one_triangle_ply(false, "uchar", "int");
    b.u8(3).i32(0).i32(-1).i32(2);
    let e = err_of(read_ply(&b.buf));
    assert_eq!(
        e,
        FormatError {
            line: None,
            what: "face 0 index -1 is negative".into()
        }
    );
    let mut b = one_triangle_ply(true, "uchar", "uint");
    b.u8(3).u32(0).u32(3).u32(2);
    let e = err_of(read_ply(&b.buf));
    assert_eq!(
        e,
        FormatError {
            line: None,
            what: "face 0 index 3 is out of range (3 vertices)".into()
        }
    );
    let mut b = one_triangle_ply(true, "uchar", "uint");
    b.u8(3).u32(0).u32(u32::MAX).u32(2);
    err_of(read_ply(&b.buf));
    let mut b = one_triangle_ply(false, "ushort", "char");
    b.u16(3).i8(0).i8(1).i8(2);
    assert!(read_ply(&b.buf).is_ok());

    let ply_ascii = format!(
        "ply\nformat ascii 1.0\nelement vertex 3\n{XYZ_HEADER}element face 2\nproperty list uchar int vertex_indices\n\
end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 -2\n"
    );
    let e = err_of(read_ply(ply_ascii.as_bytes()));
    assert_eq!(
        e,
        FormatError {
            line: Some(14),
            what: "face 1 index -2 is negative".into()
        }
    );
    let e = err_of(read_ply(ply_ascii.replace("-2", "3").as_bytes()));
    assert_eq!(
        e,
        FormatError {
            line: Some(14),
            what: "face 1 index 3 is out of range (3 vertices)".into()
        }
    );

    let off = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n";
    let e = err_of(read_off(off.as_bytes()));
    assert_eq!(
        e,
        FormatError {
            line: Some(6),
            what: "face 0 index -1 is negative".into()
        }
    );
    let e = err_of(read_off(off.replace("-1", "99999999999").as_bytes()));
    assert!(e.what.contains("out of range"), "{e}");
}

#[test]
fn faces_with_fewer_than_three_vertices() {
    let e = err_of(read_off(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"));
    assert_eq!(
        e,
        FormatError {
            line: Some(6),
            what: "face 0 has 2 vertices (at least 3 needed)".into()
        }
    );
    let mut b = one_triangle_ply(false, "uchar", "int");
    b.u8(2).i32(0).i32(1);
    assert!(err_of(read_ply(&b.buf)).what.contains("face 0 has 2 vertices"));
    let e = err_of(read_off(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n"));
    assert!(
        e.what.contains("declares 4000000000 vertices but its line has only 3"),
        "{e}"
    );
}

#[test]
fn non_finite_coordinates_are_reported() {
    for bad in ["nan", "NaN", "inf", "-infinity", "1e400"] {
        let off = format!("OFF\n3 1 0\n0 0 0\n1 {bad} 0\n0 1 0\n3 0 1 2\n");
        let e = err_of(read_off(off.as_bytes()));
        assert_eq!(
            e,
            FormatError {
                line: Some(4),
                what: "vertex 1 has a non-finite coordinate".into()
            }
        );
        let ply = format!("ply\nformat ascii 1.0\nelement vertex 2\n{XYZ_HEADER}end_header\n0 0 0\n0 0 {bad}\n");
        let e = err_of(read_ply(ply.as_bytes()));
        assert_eq!(
            e,
            FormatError {
                line: Some(9),
                what: "vertex 1 has a non-finite coordinate".into()
            }
        );
    }
    for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let header = "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty double x\n\
property double y\nproperty double z\nend_header\n";
        let mut b = Bytes::new(true, header);
        b.f64(0.0).f64(0.0).f64(0.0).f64(1.0).f64(v).f64(0.0);
        let e = err_of(read_ply(&b.buf));
        assert_eq!(
            e,
            FormatError {
                line: None,
                what: "vertex 1 has a non-finite coordinate".into()
            }
        );
    }
    let mut b = one_triangle_ply(false, "uchar", "int");
    let n = b.buf.len();
    b.buf[n - 4..].copy_from_slice(&f32::INFINITY.to_le_bytes());
    b.u8(3).i32(0).i32(1).i32(2);
    assert!(err_of(read_ply(&b.buf)).what.contains("vertex 2 has a non-finite"));
}

#[test]
fn huge_and_tiny_finite_coordinates_are_fine() {
    let off = "OFF\n3 1 0\n1e308 -1e308 1e-300\n-1.7976931348623157e308 5e-324 0\n0 1 0\n3 0 1 2\n";
    let m = read_off(off.as_bytes()).unwrap();
    assert_eq!(m.positions[0], [1e308, -1e308, 1e-300]);
    assert_eq!(m.positions[1], [-f64::MAX, 5e-324, 0.0]);
}

#[test]
fn text_count_claims_beyond_the_data() {
    let e = fails_fast(|| read_off(b"OFF\n1099511627776 1 0\n0 0 0\n"));
    assert!(e.what.contains("1099511627776 vertices"), "{e}");
    let e = fails_fast(|| read_off(b"OFF\n3 1000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
    assert!(e.what.contains("1000000 faces"), "{e}");
    let e = fails_fast(|| read_off(b"OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
    assert!(e.what.contains("ends after 1 of 2 faces"), "{e}");
    let e = fails_fast(|| read_off(b"OFF 3 1 0\n0 0 0\n1 0 0\n0 1\n3 0 1 2\n"));
    assert_eq!(
        e,
        FormatError {
            line: Some(4),
            what: "vertex 2 has 2 coordinates (3 needed)".into()
        }
    );
    let e = fails_fast(|| read_stl(b"solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n"));
    assert!(e.what.contains("ends inside facet 0"), "{e}");
}

#[test]
fn empty_files_are_errors() {
    for bytes in [&b""[..], b"\n\n  \n", b"# only a comment\n"] {
        err_of(read_off(bytes));
        err_of(read_ply(bytes));
        err_of(read_stl(bytes));
        assert_eq!(sniff_format(bytes), None);
    }
}

/// Iterations of each fuzz loop: 2000, or `FORMATS_FUZZ_ITERS` for longer runs.
fn fuzz_iterations() -> usize {
    std::env::var("FORMATS_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000)
}

/// Valid files of every variant, as seeds for mutation.
fn seed_files() -> Vec<Vec<u8>> {
    let (p, t) = (tricky_positions(), tricky_triangles());
    let colors = vec![[1, 2, 3]; p.len()];
    let mut seeds = Vec::new();
    let mut buf = Vec::new();
    write_ply_binary(&mut buf, &p, &t, Some(&colors)).unwrap();
    seeds.push(std::mem::take(&mut buf));
    write_ply_ascii(&mut buf, &p, &t, Some(&colors)).unwrap();
    seeds.push(std::mem::take(&mut buf));
    write_off(&mut buf, &p, &t).unwrap();
    seeds.push(std::mem::take(&mut buf));
    write_stl_binary(
        &mut buf,
        &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[[0, 1, 2], [2, 1, 0]],
    )
    .unwrap();
    seeds.push(std::mem::take(&mut buf));
    seeds.push(handmade_binary_ply(false));
    seeds.push(handmade_binary_ply(true));
    seeds.push(ASCII_STL.as_bytes().to_vec());
    seeds.push(binary_stl(b"solid x", &two_facets()));
    seeds.push(
        b"COFF 4 2 0\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n1 1 0 1 1 1 1\n0 1 0 1 1 1 1\n4 0 1 2 3\n3 0 2 1 1 0 0\n".to_vec(),
    );
    let ascii = seeds[1].clone();
    seeds.push(gzip(&ascii));
    seeds
}

#[test]
fn random_bytes_never_panic() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let prefixes: [&[u8]; 8] = [
        b"",
        b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n",
        b"ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\nproperty list uint uint stuff\nend_header\n",
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n",
        b"OFF\n",
        b"solid ",
        b"\x1f\x8b",
        b"ply\n",
    ];
    let t = Instant::now();
    for i in 0..fuzz_iterations() {
        let mut bytes = prefixes[i % prefixes.len()].to_vec();
        let len = rng.below(600);
        let textual = rng.below(2) == 0;
        for _ in 0..len {
            const TEXT: &[u8] = b"0123456789 -.e\n\r#3 nanNf";
            let b = if textual {
                TEXT[rng.below(TEXT.len())]
            } else {
                rng.next() as u8
            };
            bytes.push(b);
        }
        run_all_readers(&bytes);
    }
    assert!(
        t.elapsed() < Duration::from_secs(20) || fuzz_iterations() > 2000,
        "took {:?}",
        t.elapsed()
    );
}

#[test]
fn mutations_of_valid_files_never_panic() {
    let seeds = seed_files();
    for s in &seeds {
        run_all_readers(s);
    }
    let mut rng = Rng(42);
    let t = Instant::now();
    for seed in &seeds {
        for _ in 0..fuzz_iterations() {
            let mut b = seed.clone();
            for _ in 0..1 + rng.below(4) {
                let at = rng.below(b.len());
                match rng.below(7) {
                    0 => b[at] ^= 1 << rng.below(8),
                    1 => b[at] = rng.next() as u8,
                    2 => b[at] = b"0123456789-. \n"[rng.below(14)],
                    3 => b.truncate(at),
                    4 => {
                        let end = (at + rng.below(16)).min(b.len());
                        b.drain(at..end);
                    }
                    5 => {
                        let digits: Vec<u8> = (0..rng.below(12)).map(|_| b'0' + rng.below(10) as u8).collect();
                        b.splice(at..at, digits);
                    }
                    _ => {
                        let v = [0xff, 0xff, 0xff, 0x7f];
                        let end = (at + 4).min(b.len());
                        b.splice(at..end, v);
                    }
                }
                if b.is_empty() {
                    break;
                }
            }
            run_all_readers(&b);
        }
    }
    assert!(
        t.elapsed() < Duration::from_secs(30) || fuzz_iterations() > 2000,
        "took {:?}",
        t.elapsed()
    );
}

/// The Stanford dragon (871,414 faces) through `maybe_gunzip` + `read_ply`: run with
/// `FORMATS_DRAGON=/path/to/dragon_vrip.ply.gz cargo test --release -- --ignored --nocapture dragon`.
#[test]
#[ignore]
fn dragon_timing() {
    let Ok(path) = std::env::var("FORMATS_DRAGON") else {
        eprintln!("FORMATS_DRAGON not set; skipped");
        return;
    };
    let gz = std::fs::read(path).unwrap();
    let t0 = Instant::now();
    let data = maybe_gunzip(&gz, 1 << 32).unwrap();
    let t1 = Instant::now();
    let m = read_ply(&data).unwrap();
    let t2 = Instant::now();
    check_invariants(&m);
    println!(
        "dragon: {} vertices, {} faces; gunzip {:?}, read_ply {:?}, total {:?}",
        m.positions.len(),
        m.face_start.len() - 1,
        t1 - t0,
        t2 - t1,
        t2 - t0
    );
    assert_eq!(m.face_start.len() - 1, 871_414);

    // The same mesh as binary PLY and as OFF.
    let triangles: Vec<[u32; 3]> = faces(&m).iter().map(|f| [f[0], f[1], f[2]]).collect();
    let mut binary = Vec::new();
    write_ply_binary(&mut binary, &m.positions, &triangles, None).unwrap();
    let t = Instant::now();
    let b = read_ply(&binary).unwrap();
    println!(
        "dragon as binary PLY ({} bytes): read_ply {:?}",
        binary.len(),
        t.elapsed()
    );
    assert_eq!(bits(&b.positions), bits(&m.positions));
    let mut off = Vec::new();
    write_off(&mut off, &m.positions, &triangles).unwrap();
    let t = Instant::now();
    let o = read_off(&off).unwrap();
    println!("dragon as OFF ({} bytes): read_off {:?}", off.len(), t.elapsed());
    assert_eq!(bits(&o.positions), bits(&m.positions));
}

/// Windows' C library prints NaN and infinity as `1.#QNAN`, `-1.#IND`,
/// `1.#INF`: read as a number and a comment they would silently be ±1.
/// OBJ and OFF (whose comments start at `#`) refuse them, and so does the
/// judge; a `#` after a blank, or glued to anything else, still starts a
/// comment.
#[test]
fn windows_nan_and_infinity_are_refused_not_read_as_one() {
    use delmesh::io::obj::parse_obj;
    for bad in ["1.#QNAN", "-1.#IND00", "1.#INF00", "1.#qnan", "-1.#SNAN"] {
        let obj = format!("v 0 0 0\nv 1 0 0\nv 0 1 {bad}\nf 1 2 3\n");
        let e = err_of(parse_obj(obj.as_bytes()));
        assert_eq!(e.line, Some(3), "{bad}: {e}");
        assert!(e.what.contains(&format!("non-finite coordinate '{bad}'")), "{e}");
        let off = format!("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 {bad}\n3 0 1 2\n");
        let e = err_of(read_off(off.as_bytes()));
        assert_eq!(e.line, Some(5), "{bad}: {e}");
        assert!(e.what.contains(bad), "{e}");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("w.obj");
        std::fs::write(&path, &obj).unwrap();
        assert!(delmesh::check::Mesh3::read_obj(&path).is_err(), "the judge read {bad}");
    }
    for fine in ["1 #QNAN", "1#comment", "1.5#", "x#INF"] {
        let obj = format!("v 0 0 0\nv 1 0 0\nv 0 1 {fine}\nf 1 2 3\n");
        let expected = fine.starts_with('x');
        assert_eq!(parse_obj(obj.as_bytes()).is_err(), expected, "{fine}");
    }
    let raw = parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 1.5#c\nf 1 2 3#INF\n");
    assert!(raw.is_err(), "a face index glued to #INF is not an index");
    let raw = parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 1.5#c\nf 1 2 3#c\n").unwrap();
    assert_eq!(raw.positions[2], [0.0, 1.0, 1.5]);
}

/// Names that are not UTF-8 (a Latin-1 group name, as old European
/// exporters write) no longer make the file "not text": they are read with
/// U+FFFD, with a note. A bad byte in a vertex line still refuses the file.
#[test]
fn latin1_names_are_read_with_a_note() {
    use delmesh::io::obj::parse_obj;
    let obj = b"# caf\xe9\ng gr\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let raw = parse_obj(obj).unwrap();
    assert_eq!(raw.positions.len(), 3);
    assert!(
        raw.attribute_notes
            .iter()
            .any(|n| n.contains("line 2: names") && n.contains("U+FFFD")),
        "{:?}",
        raw.attribute_notes
    );
    let e = err_of(parse_obj(b"v 0 0 0\nv 1 0 \xe9\nv 0 1 0\nf 1 2 3\n"));
    assert_eq!(e.line, Some(2));
}

/// A header that declares fewer faces than its file holds (or trailing
/// data that could be more faces) is read as other readers read it, by its
/// counts, but no longer silently: a note says what was ignored, since the
/// mesh then has holes. A few stray bytes (a final newline) say nothing.
#[test]
fn data_after_the_declared_faces_gets_a_note() {
    let off = "OFF\n4 3 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
    let m = read_off(off.as_bytes()).unwrap();
    assert_eq!(m.face_start.len() - 1, 3);
    assert_eq!(
        m.notes,
        vec!["line 10: data after the 3 faces the OFF header declares ignored (if its counts are wrong, faces are missing)"]
    );
    assert!(read_off(off.rsplit_once("3 0 3 2\n").unwrap().0.as_bytes())
        .unwrap()
        .notes
        .is_empty());
    let tetra = [
        [[0.0f32, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]],
    ];
    // (A whole number of facets after them is read: see the next test.)
    let mut stl = binary_stl(b"x", &tetra);
    stl[80..84].copy_from_slice(&3u32.to_le_bytes());
    stl.extend_from_slice(b"\n\n");
    let m = read_stl(&stl).unwrap();
    assert_eq!(m.face_start.len() - 1, 3);
    assert_eq!(m.notes.len(), 1, "{:?}", m.notes);
    assert!(m.notes[0].starts_with("52 bytes after the 3 facets"), "{:?}", m.notes);
    stl.truncate(84 + 3 * 50 + 2);
    assert!(read_stl(&stl).unwrap().notes.is_empty());
}

/// A binary STL whose header's facet count is below what its size holds,
/// when that size is the header and a whole number of facets, is read by
/// its size, with a note: many exporters write a wrong count, or 0 (a count
/// of 10 before 320 facets was read as 10 facets and refused as
/// non-manifold; a count of 0, as having no faces). A count above it is a
/// file cut short, refused; a size that is not a whole number of facets is
/// still read by the count, and a text file of such a size is no binary STL.
#[test]
fn binary_stl_whose_count_disagrees_with_its_size_is_read_by_its_size() {
    let tetra = [
        [[0.0f32, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]],
    ];
    let good = binary_stl(b"x", &tetra);
    for (count, why) in [(0u32, "wrong"), (1, "wrong"), (3, "wrong")] {
        let mut stl = good.clone();
        stl[80..84].copy_from_slice(&count.to_le_bytes());
        let m = read_stl(&stl).unwrap();
        assert_eq!(m.positions, read_stl(&good).unwrap().positions, "{count}");
        assert_eq!(m.face_start.len() - 1, 4);
        let note = format!(
            "the binary STL header declares {count} facets, but the file's size holds 4: all 4 read (the header's count is {why})"
        );
        assert_eq!(m.notes, [note]);
        // Not a whole number of facets: read by the count if it fits.
        stl.push(0);
        match count {
            0 => assert!(read_stl(&stl).unwrap().face_start.is_empty()),
            _ => assert_eq!(read_stl(&stl).unwrap().face_start.len() - 1, count as usize),
        }
    }
    // A count above what the size holds is a file cut short, refused.
    for count in [5, u32::MAX] {
        let mut stl = good.clone();
        stl[80..84].copy_from_slice(&count.to_le_bytes());
        assert!(err_of(read_stl(&stl)).what.ends_with("(truncated file?)"), "{count}");
    }
    assert!(read_stl(&good).unwrap().notes.is_empty());
    // Text of that size (84 + 50 bytes), named STL, is not read as facets.
    let text = format!("{}\n", "v 0 0 0".repeat(19));
    assert_eq!(text.len(), 134);
    assert!(err_of(read_stl(text.as_bytes())).what.ends_with("(truncated file?)"));
}

/// A carriage return that ends a line by itself (classic Mac OS text, or
/// one such line end among line feeds, also inside a comment, where read as
/// a blank it would swallow the next statement) is refused in every text
/// format with one message naming its line; CRLF line ends, blanks or more
/// carriage returns before a line feed, and one at the end are fine.
#[test]
fn lone_carriage_returns_are_refused_naming_their_line() {
    use delmesh::io::obj::parse_obj;
    const MESSAGE: &str = "lines end in a carriage return alone (classic Mac OS text): convert them to line feeds";
    let tetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
    let obj = |text: &str| parse_obj(text.as_bytes());
    for (text, line) in [
        (tetra.replace('\n', "\r"), 1),
        (tetra.replace("4\nf 3", "4 # c\rf 3"), 7),
        (tetra.replace("4\nf 3", "4\r f 3"), 7),
        (format!("# header\rv 9 9 9\n{tetra}"), 1),
        ("v 0 0 0\r\nv 1 0 0\nv 0 1 0\rf 1 2 3\n".into(), 3),
    ] {
        let e = err_of(obj(&text));
        assert_eq!((e.line, e.what.as_str()), (Some(line), MESSAGE), "{text:?}");
    }
    for text in [
        tetra.replace('\n', "\r\n"),
        tetra.replace('\n', "\r\r\n"),
        tetra.replace('\n', " \r \t\n"),
        format!("{tetra}\r"),
    ] {
        assert_eq!(obj(&text).unwrap().face_start.len(), 5, "{text:?}");
    }
    let off = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
               element face 4\nproperty list uchar int vertex_indices\nend_header\n\
               0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
    let stl = "solid x\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\n\
               endsolid x\nsolid y\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\n\
               endloop\nendfacet\nendsolid y\n";
    type Reader = fn(&[u8]) -> Result<RawMesh, FormatError>;
    let readers: [(&str, Reader, &str); 3] = [
        (off, read_off, "0 1 0"),
        (ply, read_ply, "0 1 0"),
        (stl, read_stl, "endsolid x"),
    ];
    for (text, read, at) in readers {
        // Every line end a carriage return; one, on line 5 or 10; a CRLF file.
        let e = err_of(read(text.replace('\n', "\r").as_bytes()));
        assert_eq!((e.line, e.what.as_str()), (Some(1), MESSAGE), "{text:?}");
        let mixed = text.replacen(&format!("{at}\n"), &format!("{at}\r"), 1);
        let line = 1 + text[..text.find(&format!("{at}\n")).unwrap()].matches('\n').count() as u64;
        let e = err_of(read(mixed.as_bytes()));
        assert_eq!((e.line, e.what.as_str()), (Some(line), MESSAGE), "{mixed:?}");
        let crlf = read(text.replace('\n', "\r\n").as_bytes()).unwrap();
        assert_eq!(
            crlf.face_start.len() - 1,
            read(text.as_bytes()).unwrap().face_start.len() - 1
        );
    }
    // In a PLY header too.
    let e = err_of(read_ply(ply.replacen("float y\n", "float y\r", 1).as_bytes()));
    assert_eq!((e.line, e.what.as_str()), (Some(5), MESSAGE));
}

/// An ASCII PLY line with too few values for its record is named, and
/// called short: the record reads on into the next line, which then has
/// values left over, and that next line was blamed for holding more values
/// than declared. A line with too many is still named so; a record that
/// goes on over two lines and ends at the end of one is read, as before.
#[test]
fn ply_ascii_short_line_is_named_as_short() {
    let ply = |rows: &str| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
             element face 4\nproperty list uchar int vertex_indices\nend_header\n{rows}"
        )
    };
    let faces = "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
    for (rows, line, what) in [
        (
            format!("0 0\n1 0 0\n0 1 0\n0 0 1\n{faces}"),
            10,
            "vertex 0 has 2 values on its line, fewer than the 3 its record needs (a short line)",
        ),
        (
            format!("0 0\n0 1 0 0\n0 1 0\n0 0 1\n{faces}"),
            10,
            "vertex 0 has 2 values on its line, fewer than the 3 its record needs (a short line)",
        ),
        (
            format!("0 0 0\n1 0 0\n0 1 0\n0 0\n{faces}"),
            13,
            "vertex 3 has 2 values on its line, fewer than the 3 its record needs (a short line)",
        ),
        (
            format!("0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2\n{}", &faces[8..]),
            14,
            "face 0 has 3 values on its line, fewer than the 4 its record needs (a short line)",
        ),
        (
            format!("0 0 0 0\n1 0 0\n0 1 0\n0 0 1\n{faces}"),
            10,
            "more values on the line of vertex 0 than the PLY header declares (3 properties)",
        ),
    ] {
        let e = err_of(read_ply(ply(&rows).as_bytes()));
        assert_eq!((e.line, e.what.as_str()), (Some(line), what), "{rows}");
    }
    let wrapped = read_ply(ply(&format!("0 0\n0\n1 0 0\n0 1 0\n0 0 1\n{faces}")).as_bytes()).unwrap();
    assert_eq!(wrapped.positions[0], [0.0; 3]);
    assert_eq!(wrapped.face_start.len(), 5);
}

/// ASCII PLY values are held to their declared types: a coordinate, face
/// index or list length that the type cannot hold (`300` as `uchar`, `1.5`
/// as `int`, `1e39` as `float`, infinite there) is refused naming its line;
/// in a colour, texture coordinate or normal such a value, or one that is
/// no number, drops that attribute with a note (a `uchar` colour of 999
/// was read as 3.92). Values within range are read exactly as written.
#[test]
fn ply_ascii_values_must_fit_their_declared_types() {
    let ply = |props: &str, list: &str, rows: &str, faces: &str| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex 4\n{props}element face 4\n\
             property list {list} vertex_indices\nend_header\n{rows}{faces}3 0 1 3\n3 1 2 3\n3 2 0 3\n"
        )
    };
    let xyz = |ty: &str| format!("property {ty} x\nproperty {ty} y\nproperty {ty} z\n");
    let rows = |x: &str| format!("0 0 0\n{x} 0 0\n0 1 0\n0 0 1\n");
    let face = "3 0 2 1\n";
    for (ty, x, why) in [
        (
            "uint8",
            "300",
            "does not fit its declared type uchar (an integer from 0 to 255)",
        ),
        (
            "uchar",
            "-1",
            "does not fit its declared type uchar (an integer from 0 to 255)",
        ),
        (
            "int",
            "1.5",
            "does not fit its declared type int (an integer from -2147483648 to 2147483647)",
        ),
        (
            "float",
            "1e39",
            "does not fit its declared type float (beyond ±3.4028235e38)",
        ),
        (
            "float32",
            "-4e38",
            "does not fit its declared type float (beyond ±3.4028235e38)",
        ),
    ] {
        let e = err_of(read_ply(ply(&xyz(ty), "uchar int", &rows(x), face).as_bytes()));
        let expected = format!("vertex 1 property x: `{x}` {why}");
        assert_eq!((e.line, e.what), (Some(11), expected), "{ty} {x}");
    }
    for (ty, x, value) in [
        ("uchar", "255", 255.0),
        ("int", "7.0", 7.0),
        ("float", "3.4e38", 3.4e38),
        ("float", "0.1", 0.1),
        ("float", "1e-50", 1e-50),
        ("double", "1e300", 1e300),
    ] {
        let m = read_ply(ply(&xyz(ty), "uchar int", &rows(x), face).as_bytes()).unwrap();
        assert_eq!(m.positions[1][0], value, "{ty} {x}");
    }
    let xyz = xyz("float");
    for (list, face, what) in [
        (
            "uchar uchar",
            "3 0 2 300\n",
            "face 0 index `300` does not fit its declared type uchar (an integer from 0 to 255)",
        ),
        (
            "uchar int",
            "300 0 2 1\n",
            "face 0 list vertex_indices length `300` does not fit its declared type uchar (an integer from 0 to 255)",
        ),
    ] {
        let e = err_of(read_ply(ply(&xyz, list, &rows("1"), face).as_bytes()));
        assert_eq!((e.line, e.what.as_str()), (Some(14), what), "{list}");
    }
    // Attributes: dropped with a note, the mesh read.
    let colours = format!("{xyz}property uchar red\nproperty uchar green\nproperty uchar blue\n");
    let rows = "0 0 0 255 0 0\n1 0 0 999 0 0\n0 1 0 0 0 0\n0 0 1 0 9 0\n";
    let m = read_ply(ply(&colours, "uchar int", rows, face).as_bytes()).unwrap();
    assert_eq!(
        m.attribute_notes,
        ["colours dropped: line 14: vertex 1 property red: `999` does not fit its declared type uchar (an integer from 0 to 255)"]
    );
    assert!(m.attributes.colors.is_none() && m.colors.is_none());
    assert_eq!(m.positions.len(), 4);
    let m = read_ply(ply(&colours, "uchar int", &rows.replace("999", "99"), face).as_bytes()).unwrap();
    assert!(
        m.attribute_notes.is_empty() && m.attributes.colors.is_some(),
        "{:?}",
        m.attribute_notes
    );
    let uv = format!("{xyz}property float u\nproperty float v\n");
    let rows = "0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 one\n0 0 1 1e39 1\n";
    let m = read_ply(ply(&uv, "uchar int", rows, face).as_bytes()).unwrap();
    assert_eq!(
        m.attribute_notes,
        ["texture coordinates dropped: line 14: vertex 2 property v: `one` is not a number"]
    );
    assert!(m.attributes.texcoords.is_none());
}

/// OBJ line and point elements (`l`, `p`) and free-form curves and surfaces
/// (`curv`, `surf`) are not faces: read past, with a note naming the first
/// one's line and how many there were.
#[test]
fn obj_line_and_point_elements_are_ignored_with_a_note() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nf 1 2 3\np 3\nl 2 3 1\n";
    let m = delmesh::io::obj::parse_obj(text.as_bytes()).unwrap();
    assert_eq!(faces(&m), [vec![0, 1, 2]]);
    assert_eq!(
        m.notes,
        ["line 4: 3 line or point elements (l, p) ignored: only faces are read and written"]
    );
    let m = delmesh::io::obj::parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert!(m.notes.is_empty(), "{:?}", m.notes);
    // Free-form geometry too, in a note of its own.
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvp 0.5\ncstype bspline\ndeg 1\ncurv 0 1 1 2\nparm u 0 0 1 1\nend\n\
                f 1 2 3\nsurf 0 1 0 1 1 2 3\nend\n";
    let m = delmesh::io::obj::parse_obj(text.as_bytes()).unwrap();
    assert_eq!(faces(&m), [vec![0, 1, 2]]);
    assert_eq!(
        m.notes,
        ["line 7: 2 free-form curves or surfaces (curv, surf) ignored: only faces are read and written"]
    );
}

/// A file whose content is of another format than its name's is refused
/// as misnamed, not with the named reader's reason: a binary PLY named
/// `.obj` or `.off` had "lines end in a carriage return alone (classic Mac
/// OS text)" at the first 0x0d of its data, and any text named `.stl` "the
/// binary STL header declares 1879730017 facets ... (truncated file?)". A
/// file its own format refuses keeps its reason.
#[test]
fn a_misnamed_file_is_refused_as_misnamed() {
    let dir = tempfile::tempdir().unwrap();
    let (p, t) = (tricky_positions(), tricky_triangles());
    let mut ply = Vec::new();
    write_ply_binary(&mut ply, &p, &t, None).unwrap();
    // Positions with 13 (a carriage return) among their bytes.
    let carriage: Vec<[f64; 3]> = p.iter().map(|q| q.map(|x| x + f64::from_bits(0x0d0d))).collect();
    let mut ply_cr = Vec::new();
    write_ply_binary(&mut ply_cr, &carriage, &t, None).unwrap();
    assert!(ply_cr.contains(&b'\r'));
    let mut off = Vec::new();
    write_off(&mut off, &p, &t).unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let mut stl = Vec::new();
    let tetrahedron = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    write_stl_binary(&mut stl, &tetrahedron, &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]).unwrap();
    let read = |name: &str, bytes: &[u8]| {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = delmesh::io::read_mesh(&path, &Default::default())
            .unwrap_err()
            .to_string();
        e.strip_prefix(&format!("{}: ", path.display()))
            .unwrap_or(&e)
            .to_owned()
    };
    let named = "the name's extension decides the format";
    for (name, bytes, expected) in [
        (
            "a.obj",
            &ply_cr[..],
            "not an OBJ file: its content is PLY (name it .ply",
        ),
        (
            "a.off",
            &ply_cr[..],
            "not an OFF file: its content is PLY (name it .ply",
        ),
        ("a.stl", &ply[..], "not an STL file: its content is PLY (name it .ply"),
        ("a.stl", &off[..], "not an STL file: its content is OFF (name it .off"),
        (
            "a.stl",
            obj.as_bytes(),
            "not an STL file: its content is OBJ (name it .obj",
        ),
        (
            "a.ply",
            obj.as_bytes(),
            "not a PLY file: its content is OBJ (name it .obj",
        ),
        (
            "a.obj.gz",
            &gzip(&off),
            "not an OBJ file: its content is OFF (name it .off",
        ),
        ("a.obj", &stl[..], "not an OBJ file: its content is STL (name it .stl"),
    ] {
        assert_eq!(read(name, bytes), format!("{expected}: {named})"), "{name}");
    }
    // Its own format's reasons.
    assert!(read("b.ply", b"ply\nformat ascii 1.0\nend\n").contains("PLY"));
    let e = read("c.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    assert!(e.contains("out of range"), "{e}");
}

/// A file where only some `v` lines give a colour drops colours with a
/// note naming the first vertex without one, whichever kind comes first.
#[test]
fn partial_obj_colours_are_named_at_the_first_vertex_without() {
    let note = |text: &str| delmesh::io::obj::parse_obj(text.as_bytes()).unwrap().attribute_notes;
    let expected = |line: usize| {
        vec![format!(
            "colours dropped: line {line}: only some vertices have a colour (not this one)"
        )]
    };
    assert_eq!(note("v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 1 0 0\nf 1 2 3\n"), expected(2));
    assert_eq!(note("v 0 0 0\nv 1 0 0\nv 0 1 0 1 0 0\nf 1 2 3\n"), expected(1));
}

/// An OFF file's announced vertex attributes (`C`: colour, `N`: normal,
/// `ST`: texture coordinates, in that line order: normal, colour, texture)
/// and its face colours (numbers after a face's indices) are read; a
/// defect drops that attribute alone, with a note.
#[test]
fn off_colours_normals_and_face_colours_are_read() {
    let text = "STCNOFF\n4 2 0\n\
                0 0 0  0 0 1  255 0 0 255  0 0\n\
                1 0 0  0 0 1  0 255 0 255  1 0\n\
                1 1 0  0 0 1  0 0 255 255  1 1\n\
                0 1 0  0 0 1  9 9 9 255  0 1\n\
                3 0 1 2 10 20 30\n3 0 2 3 40 50 60\n";
    let m = read_off(text.as_bytes()).unwrap();
    let a = &m.attributes;
    assert_eq!(a.normals.as_ref().unwrap().dim, 3);
    let colours = a.colors.as_ref().unwrap();
    assert_eq!(
        (colours.dim, colours.values[..4].to_vec()),
        (4, vec![1.0, 0.0, 0.0, 1.0])
    );
    assert_eq!(
        a.texcoords.as_ref().unwrap().values,
        vec![0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0]
    );
    let names: Vec<&str> = a.face_properties.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["red", "green", "blue"]);
    assert_eq!(a.face_properties[2].values, vec![30.0, 60.0]);
    assert_eq!(a.face_properties[0].ty, delmesh::attributes::ValueType::U8);
    assert!(m.attribute_notes.is_empty(), "{:?}", m.attribute_notes);

    // A bad colour drops the colours only; a face without a colour drops
    // the face colours; floats in 0..1 are kept as `float`.
    let text = "COFF\n4 2 0\n0 0 0 1 0 0\n1 0 0 0 x 0\n1 1 0 0 0 1\n0 1 0 1 1 1\n3 0 1 2 0.5 0.25 1\n3 0 2 3\n";
    let m = read_off(text.as_bytes()).unwrap();
    assert!(m.attributes.colors.is_none() && m.attributes.face_properties.is_empty());
    assert_eq!(
        m.attribute_notes,
        [
            "colours dropped: line 4: vertex 1 colour `x` is not a number",
            "face colours dropped: 1 of 2 faces has none"
        ]
    );
    let text = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 0.5 0.25 1\n3 0 2 3 1 1 0\n";
    let m = read_off(text.as_bytes()).unwrap();
    assert_eq!(m.attributes.face_properties[0].ty, delmesh::attributes::ValueType::F32);
    // Junk after the indices, or a colour map index: not a colour.
    for (tail, why) in [
        (
            "junk",
            "face 0: `junk` after its indices is not a number (a colour is 3 or 4)",
        ),
        ("7", "face 0 gives a colour map index, which delmesh does not read"),
        ("1 2", "face 0 has 2 numbers after its indices (a colour is 3 or 4)"),
    ] {
        let text = format!("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 {tail}\n");
        let m = read_off(text.as_bytes()).unwrap();
        assert_eq!(m.attribute_notes, [format!("face colours dropped: line 6: {why}")]);
    }
    // Faces whose colours differ in length: the later one is named as such.
    let text = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 1 0 0 1\n3 0 2 3 1 0 0\n";
    let m = read_off(text.as_bytes()).unwrap();
    assert_eq!(
        m.attribute_notes,
        ["face colours dropped: line 8: face 1 has a colour of 3 numbers, the faces before it of 4"]
    );
    // A COFF vertex line whose colour is not 3 or 4 numbers, from the first
    // vertex on, drops the colours with a note (they were dropped silently),
    // and so does one that differs from the vertices before it.
    for (lines, why) in [
        (
            ["0 0 0 1 0", "1 0 0 1 0", "0 1 0 1 0"],
            "line 3: vertex 0 has 2 colour components (3 or 4 expected)",
        ),
        (
            ["0 0 0", "1 0 0", "0 1 0"],
            "line 3: vertex 0 has 0 colour components (3 or 4 expected)",
        ),
        (
            ["0 0 0 1 0 0", "1 0 0 1 0 0 1", "0 1 0 1 0 0"],
            "line 4: vertex 1 has 4 colour components, the vertices before it 3",
        ),
    ] {
        let text = format!("COFF\n3 1 0\n{}\n3 0 1 2\n", lines.join("\n"));
        let m = read_off(text.as_bytes()).unwrap();
        assert!(m.attributes.colors.is_none());
        assert_eq!(m.attribute_notes, [format!("colours dropped: {why}")]);
    }
}

/// `write_off_with` writes Geomview's `[ST][C][N]OFF`: the keyword's
/// prefixes in that order, a vertex line `x y z nx ny nz r g b [a] s t`,
/// colours as bytes or as numbers with a decimal point, face colours after
/// the indices; `read_off` gives back what was written. Without extras it
/// writes what `write_off` writes; extras that do not fit are refused.
#[test]
fn off_with_attributes_is_written_in_geomview_order() {
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let t = [[0, 1, 2]];
    let extras = OffExtras {
        normals: Some(vec![0.0, 0.0, 1.0, 0.5, 0.0, 1.0, 0.0, 0.25, 1.0]),
        colors: Some(OffColors {
            dim: 4,
            text: ColorText::Floats,
            values: vec![1.0, 0.0, 1e-7, 0.5, 0.1, 0.2, 0.3, 1.0, 2.0, 0.0, 1.0, 1.0],
        }),
        texcoords: Some(vec![0.0, 0.0, 1.0, 0.0, 0.0, 1e20]),
        face_colors: Some(OffColors {
            dim: 3,
            text: ColorText::Bytes,
            values: vec![254.6, -3.0, 300.0],
        }),
    };
    let mut buf = Vec::new();
    write_off_with(&mut buf, &p, &t, &extras).unwrap();
    let text = String::from_utf8(buf.clone()).unwrap();
    assert_eq!(
        text,
        "STCNOFF\n3 1 0\n\
         0.0 0.0 0.0 0.0 0.0 1.0 1.0 0.0 1.0e-7 0.5 0.0 0.0\n\
         1.0 0.0 0.0 0.5 0.0 1.0 0.1 0.2 0.3 1.0 1.0 0.0\n\
         0.0 1.0 0.0 0.0 0.25 1.0 2.0 0.0 1.0 1.0 0.0 1e+20\n\
         3 0 1 2 255 0 255\n"
    );
    let m = read_off(&buf).unwrap();
    assert!(m.attribute_notes.is_empty(), "{:?}", m.attribute_notes);
    let a = &m.attributes;
    assert_eq!(a.normals.as_ref().unwrap().values, extras.normals.unwrap());
    assert_eq!(
        a.colors.as_ref().unwrap().values,
        extras.colors.as_ref().unwrap().values
    );
    assert_eq!(a.texcoords.as_ref().unwrap().values, extras.texcoords.unwrap());
    let face: Vec<f64> = a.face_properties.iter().map(|p| p.values[0]).collect();
    assert_eq!(face, [255.0, 0.0, 255.0]);

    let mut plain = Vec::new();
    write_off_with(&mut plain, &p, &t, &OffExtras::default()).unwrap();
    let mut expected = Vec::new();
    write_off(&mut expected, &p, &t).unwrap();
    assert_eq!(plain, expected);

    let colors = |dim: usize, values: Vec<f64>| {
        Some(OffColors {
            dim,
            text: ColorText::Bytes,
            values,
        })
    };
    for (bad, why) in [
        (
            OffExtras {
                normals: Some(vec![0.0; 8]),
                ..OffExtras::default()
            },
            "8 numbers of normals for 3 × 3",
        ),
        (
            OffExtras {
                colors: colors(2, vec![0.0; 6]),
                ..OffExtras::default()
            },
            "colours of 2 numbers (3 or 4)",
        ),
        (
            OffExtras {
                face_colors: colors(3, vec![0.0; 6]),
                ..OffExtras::default()
            },
            "6 numbers of face colours for 1 × 3",
        ),
        (
            OffExtras {
                texcoords: Some(vec![0.0, 0.0, 1.0, f64::NAN, 0.0, 1.0]),
                ..OffExtras::default()
            },
            "texture coordinates: number 3 is not finite",
        ),
    ] {
        let e = write_off_with(&mut Vec::new(), &p, &t, &bad).unwrap_err();
        assert_eq!(e.to_string(), why);
    }
}

/// UTF-16 text is told apart from other bytes a reader refuses: ASCII with
/// a zero byte after or before each character, a byte order mark or not;
/// not UTF-8 text, a binary PLY, zeros, a binary STL's header, or a few bytes.
#[test]
fn utf16_text_is_recognised() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let le: Vec<u8> = text.bytes().flat_map(|b| [b, 0]).collect();
    let be: Vec<u8> = text.bytes().flat_map(|b| [0, b]).collect();
    assert!(is_utf16_text(&le) && is_utf16_text(&be));
    assert!(is_utf16_text(&[&[0xff, 0xfe][..], &le].concat()));
    assert!(is_utf16_text(&[&[0xfe, 0xff][..], &be].concat()));
    assert!(!is_utf16_text(text.as_bytes()));
    assert!(!is_utf16_text(b"ply\nformat binary_little_endian 1.0\n"));
    assert!(!is_utf16_text(&[0; 100]));
    assert!(!is_utf16_text(&[&[0xff, 0xfe][..], &[0x80; 78][..]].concat()));
    assert!(!is_utf16_text(&le[..2]));
}

// ---------------------------------------------------------------------------
// PLY triangle strips
// ---------------------------------------------------------------------------

/// A 4 × 2 grid of quads as two strips (rows), the second written with a
/// degenerate start (its first vertex twice, as strippers join strips),
/// and -1 between them: the triangles of the grid, all facing +z, the
/// degenerate ones left out.
fn grid_strips() -> (Vec<[f64; 3]>, Vec<i64>) {
    let mut p = Vec::new();
    for j in 0..3 {
        for i in 0..5 {
            p.push([i as f64, j as f64, 0.0]);
        }
    }
    let at = |i: i64, j: i64| j * 5 + i;
    let mut strips = Vec::new();
    for j in 0..2 {
        if j == 1 {
            strips.push(-1);
        }
        for i in 0..5 {
            strips.push(at(i, j + 1));
            if j == 1 && i == 0 {
                // Repeated: two triangles with a repeated vertex, left out; the parity kept.
                strips.push(at(i, j + 1));
                strips.push(at(i, j + 1));
            }
            strips.push(at(i, j));
        }
    }
    (p, strips)
}

/// Checks that `m` holds the grid's 16 triangles, each facing +z.
fn assert_grid_faces(m: &RawMesh) {
    check_invariants(m);
    let fs = faces(m);
    assert_eq!(fs.len(), 16, "{fs:?}");
    for f in &fs {
        let [a, b, c] = [f[0], f[1], f[2]].map(|i| m.positions[i as usize]);
        let cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        assert!(cross > 0.0, "{f:?} faces down");
    }
    let mut covered: Vec<Vec<u32>> = fs
        .iter()
        .map(|f| {
            let mut f = f.clone();
            f.sort();
            f
        })
        .collect();
    covered.sort();
    covered.dedup();
    assert_eq!(covered.len(), 16, "a triangle twice");
}

#[test]
fn ply_triangle_strips_are_read_as_their_triangles() {
    let (p, strips) = grid_strips();
    // ASCII, then binary with int and with uint items (-1 as 0xFFFFFFFF).
    let mut ascii = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element tristrips 1\nproperty list int int vertex_indices\nend_header\n",
        p.len()
    );
    for v in &p {
        ascii += &format!("{} {} {}\n", v[0], v[1], v[2]);
    }
    ascii += &format!("{}", strips.len());
    for i in &strips {
        ascii += &format!(" {i}");
    }
    ascii += "\n";
    let m = read_ply(ascii.as_bytes()).unwrap();
    assert_grid_faces(&m);
    for item in ["int", "uint"] {
        let mut bin = format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
             property double z\nelement tristrips 1\nproperty list int {item} vertex_indices\nend_header\n",
            p.len()
        )
        .into_bytes();
        for v in &p {
            for c in v {
                bin.extend_from_slice(&c.to_le_bytes());
            }
        }
        bin.extend_from_slice(&(strips.len() as i32).to_le_bytes());
        for &i in &strips {
            bin.extend_from_slice(&(i as i32).to_le_bytes());
        }
        let m = read_ply(&bin).unwrap();
        assert_grid_faces(&m);
        assert_eq!(m.origin_kind, OriginKind::Record);
    }
    // A negative index other than -1, and an index beyond the vertices, are refused.
    let bad = ascii.replace(" -1 ", " -2 ");
    let e = read_ply(bad.as_bytes()).unwrap_err().to_string();
    assert!(e.contains("tristrips 0 index -2 is negative"), "{e}");
    let beyond = ascii.replacen(" 5 0 6", " 5 99 6", 1);
    assert_ne!(beyond, ascii);
    let e = read_ply(beyond.as_bytes()).unwrap_err().to_string();
    assert!(e.contains("99"), "{e}");
    // A tristrips element without its list is named.
    let no_list = ascii.replace("property list int int vertex_indices", "property int x");
    let e = read_ply(no_list.as_bytes()).unwrap_err().to_string();
    assert!(e.contains("tristrips element has no vertex_indices"), "{e}");
}

/// `obj::write_obj_with_attributes` says which vertices it wrote twice: a
/// vertex whose corners have two colours is written once per colour, the
/// copy after the mesh's own vertices, and the returned list names the
/// vertex each copy repeats.
#[test]
fn obj_writer_returns_the_copies_it_writes_for_colours() {
    use delmesh::attributes::{Attributes, Channel};
    use delmesh::io::obj::write_obj_with_attributes;
    // Two triangles sharing the edge 1-2, the first red, the second blue:
    // vertices 1 and 2 have a corner of each colour.
    let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    let triangles = [[0, 1, 2], [2, 1, 3]];
    let colors = Channel {
        dim: 3,
        values: vec![1.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        corners: vec![0, 0, 0, 1, 1, 1],
    };
    let attributes = Attributes {
        colors: Some(colors),
        ..Default::default()
    };
    let mut buf = Vec::new();
    let copies = write_obj_with_attributes(&mut buf, &positions, &triangles, &attributes).unwrap();
    let text = String::from_utf8(buf).unwrap();
    let vertices: Vec<&str> = text.lines().filter(|l| l.starts_with("v ")).collect();
    // Each is written once more, for its second colour.
    let mut sorted = copies.clone();
    sorted.sort_unstable();
    assert_eq!(sorted, vec![1, 2], "{text}");
    assert_eq!(vertices.len(), positions.len() + copies.len(), "{text}");
    for (i, &v) in copies.iter().enumerate() {
        let copy = vertices[positions.len() + i];
        let original = vertices[v as usize];
        // The same position, another colour.
        let xyz = |l: &str| {
            l.split_whitespace()
                .skip(1)
                .take(3)
                .map(String::from)
                .collect::<Vec<_>>()
        };
        assert_eq!(xyz(copy), xyz(original), "{text}");
        assert_ne!(copy, original, "{text}");
    }
    // Without colours nothing is copied.
    let mut buf = Vec::new();
    let none = write_obj_with_attributes(&mut buf, &positions, &triangles, &Attributes::default()).unwrap();
    assert!(none.is_empty());
}
