//! Reading and writing meshes.
//!
//! The OBJ reader is delmesh's own: it keeps the line number of every vertex
//! and face, so that each refusal of SPEC §6 can name the offending line, and
//! it parses coordinates exactly (`str::parse::<f64>`). Every object and group
//! of the file goes into one mesh; polygons are fan-triangulated; vertices
//! with bit-identical positions are welded; vertices no face uses are
//! dropped. Texture coordinates, normals, groups and materials are read past.
//!
//! Writing is atomic: a temporary file in the target's directory, renamed
//! over the target only once it is complete.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::error::{Error, Result};
use crate::geometry;
use crate::mesh::{Surface, TopologyError};

/// A mesh as read from a file, before any refinement.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InputMesh {
    /// Vertex positions: welded, each used by some face, in file order.
    pub positions: Vec<DVec3>,
    /// Triangles (polygons fan-triangulated), indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// 1-based line of the face each triangle comes from (0 if not from a file).
    pub triangle_line: Vec<u32>,
    /// 1-based number of each vertex in the file (its first `v` line's rank).
    pub vertex_number: Vec<u32>,
    /// Faces in the file (before triangulation).
    pub faces_in_file: usize,
    /// Vertices merged into an earlier one at the bit-identical position.
    pub welded: usize,
    /// Vertices no face uses (dropped).
    pub unreferenced: usize,
}

/// A fast hasher for bit patterns of coordinates (FxHash's mixing step):
/// the welding map is built once per vertex, and SipHash would dominate it.
#[derive(Default)]
struct FxHasher(u64);

impl Hasher for FxHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

type FxMap<K, V> = HashMap<K, V, BuildHasherDefault<FxHasher>>;

/// Statements of the OBJ format that carry nothing delmesh needs.
const IGNORED: &[&str] = &[
    "vt",
    "vn",
    "vp",
    "l",
    "p",
    "o",
    "g",
    "s",
    "usemtl",
    "mtllib",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "mg",
    "lod",
    "usemap",
    "maplib",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "bevel",
    "c_interp",
    "d_interp",
];

/// Reads an OBJ file. See the module documentation for what is kept.
pub fn read_obj(path: &Path) -> Result<InputMesh> {
    let bytes = std::fs::read(path).map_err(|source| Error::Read {
        path: path.to_owned(),
        source,
    })?;
    parse_obj(&bytes, path)
}

/// Parses OBJ text; `path` only names the file in errors.
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<InputMesh> {
    let syntax = |line: usize, what: String| Error::Syntax {
        path: path.to_owned(),
        line,
        what,
    };
    let mut raw: Vec<DVec3> = Vec::new();
    let mut raw_line: Vec<u32> = Vec::new();
    // Faces: flattened raw 0-based indices, with (start, line) per face.
    let mut corners: Vec<u32> = Vec::new();
    let mut faces: Vec<(usize, u32)> = Vec::new();
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let n = i + 1;
        let line = std::str::from_utf8(line).map_err(|_| syntax(n, "not text: this is not an OBJ file".into()))?;
        let line = line.split('#').next().unwrap_or("");
        let mut tokens = line.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        match keyword {
            "v" => {
                let mut xyz = [0.0f64; 3];
                for (k, c) in xyz.iter_mut().enumerate() {
                    let tok = tokens
                        .next()
                        .ok_or_else(|| syntax(n, format!("vertex has {k} coordinates, needs 3")))?;
                    *c = tok
                        .parse()
                        .map_err(|_| syntax(n, format!("vertex coordinate '{tok}' is not a number")))?;
                    if !c.is_finite() {
                        return Err(syntax(
                            n,
                            format!("vertex {} has a non-finite coordinate '{tok}'", raw.len() + 1),
                        ));
                    }
                }
                raw.push(DVec3::from_array(xyz));
                raw_line.push(n as u32);
            }
            "f" => {
                let start = corners.len();
                for tok in tokens {
                    let index = tok.split('/').next().unwrap_or("");
                    let value: i64 = index
                        .parse()
                        .map_err(|_| syntax(n, format!("face index '{tok}' is not an integer")))?;
                    let resolved = match value {
                        0 => return Err(syntax(n, "face index 0 (OBJ indices start at 1)".into())),
                        v if v > 0 => v - 1,
                        v => raw.len() as i64 + v,
                    };
                    if resolved < 0 || resolved >= u32::MAX as i64 {
                        return Err(syntax(n, format!("face index {value} is out of range")));
                    }
                    corners.push(resolved as u32);
                }
                if corners.len() - start < 3 {
                    return Err(syntax(
                        n,
                        format!("face has {} vertices, needs at least 3", corners.len() - start),
                    ));
                }
                faces.push((start, n as u32));
            }
            k if IGNORED.contains(&k) => {}
            k => {
                let shown: String = k.chars().take(20).collect();
                return Err(syntax(
                    n,
                    format!("unknown statement '{shown}': this is not an OBJ file"),
                ));
            }
        }
    }
    if faces.is_empty() {
        return Err(Error::Mesh {
            path: path.to_owned(),
            what: "no faces".into(),
        });
    }
    // Out-of-range indices (forward references are allowed).
    for (f, &(start, line)) in faces.iter().enumerate() {
        let end = faces.get(f + 1).map_or(corners.len(), |x| x.0);
        if let Some(&bad) = corners[start..end].iter().find(|&&c| c as usize >= raw.len()) {
            return Err(syntax(
                line as usize,
                format!(
                    "face index {} is out of range (the file has {} vertices)",
                    bad as u64 + 1,
                    raw.len()
                ),
            ));
        }
    }
    // Weld bit-identical positions onto their first occurrence.
    let mut first: FxMap<[u64; 3], u32> = FxMap::default();
    first.reserve(raw.len());
    let mut welded_to: Vec<u32> = Vec::with_capacity(raw.len());
    for (i, p) in raw.iter().enumerate() {
        let key = p.to_array().map(f64::to_bits);
        welded_to.push(*first.entry(key).or_insert(i as u32));
    }
    let welded = raw.len() - first.len();
    // Keep used vertices, in file order.
    let mut used = vec![false; raw.len()];
    for c in corners.iter_mut() {
        *c = welded_to[*c as usize];
        used[*c as usize] = true;
    }
    let mut new_index = vec![u32::MAX; raw.len()];
    let mut positions = Vec::new();
    let mut vertex_number = Vec::new();
    for i in 0..raw.len() {
        if used[i] {
            new_index[i] = positions.len() as u32;
            positions.push(raw[i]);
            vertex_number.push(i as u32 + 1);
        }
    }
    let unreferenced = raw.len() - welded - positions.len();
    // Fan-triangulate, refusing repeated vertices and zero-area triangles.
    let mut triangles = Vec::with_capacity(corners.len().saturating_sub(2 * faces.len()));
    let mut triangle_line = Vec::with_capacity(triangles.capacity());
    for (f, &(start, line)) in faces.iter().enumerate() {
        let end = faces.get(f + 1).map_or(corners.len(), |x| x.0);
        let poly = &corners[start..end];
        for (i, &v) in poly.iter().enumerate() {
            if poly[..i].contains(&v) {
                return Err(syntax(
                    line as usize,
                    format!(
                        "face {} repeats vertex {} (after welding equal positions)",
                        f + 1,
                        v + 1
                    ),
                ));
            }
        }
        for i in 1..poly.len() - 1 {
            let t = [poly[0], poly[i], poly[i + 1]].map(|v| new_index[v as usize]);
            let [a, b, c] = t.map(|v| positions[v as usize]);
            if geometry::collinear(a, b, c) {
                return Err(syntax(line as usize, format!("face {} has zero area", f + 1)));
            }
            triangles.push(t);
            triangle_line.push(line);
        }
    }
    Ok(InputMesh {
        positions,
        triangles,
        triangle_line,
        vertex_number,
        faces_in_file: faces.len(),
        welded,
        unreferenced,
    })
}

/// Builds the refinable mesh of an input, turning topology errors into
/// messages that name the file, line and vertices.
pub fn build_surface(input: &InputMesh, path: &Path) -> Result<Surface> {
    Surface::new(input.positions.clone(), &input.triangles).map_err(|e| {
        let line = |face: usize| input.triangle_line.get(face).copied().unwrap_or(0);
        let v = |i: u32| input.vertex_number.get(i as usize).copied().unwrap_or(i + 1);
        let what = match e {
            TopologyError::EdgeWithMoreThanTwoFaces { face, a, b } => format!(
                "line {}: edge between vertices {} and {} has more than two faces (non-manifold edge)",
                line(face),
                v(a),
                v(b)
            ),
            TopologyError::InconsistentOrientation { face, a, b } => format!(
                "line {}: face runs along edge {} -> {} in the same direction as another face (inconsistent orientation)",
                line(face),
                v(a),
                v(b)
            ),
            TopologyError::NonManifoldVertex { vertex } => format!(
                "vertex {}: its faces form more than one fan (non-manifold vertex)",
                v(vertex)
            ),
            TopologyError::IndexOutOfRange { face, index } => {
                format!("line {}: vertex index {} out of range", line(face), index as u64 + 1)
            }
            TopologyError::RepeatedVertex { face, vertex } => {
                format!("line {}: face repeats vertex {}", line(face), v(vertex))
            }
        };
        Error::Mesh { path: path.to_owned(), what }
    })
}

/// Writes `bytes` produced by `fill` to `path` atomically: into a temporary
/// file in the same directory, renamed over `path` only when complete. On
/// any error `path` is untouched and the temporary file removed.
pub fn write_atomic(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    let err = |source| Error::Write {
        path: path.to_owned(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
        _ => PathBuf::from("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".delmesh-")
        .suffix(".tmp")
        .tempfile_in(&dir)
        .map_err(err)?;
    {
        let mut w = BufWriter::with_capacity(1 << 20, tmp.as_file_mut());
        fill(&mut w).map_err(err)?;
        w.flush().map_err(err)?;
    }
    tmp.as_file().sync_all().map_err(err)?;
    // Keep the permissions of a file being replaced; a new file gets 0644.
    let perms = match std::fs::metadata(path) {
        Ok(m) => m.permissions(),
        Err(_) => default_permissions(),
    };
    tmp.as_file().set_permissions(perms).map_err(err)?;
    tmp.persist(path).map_err(|e| err(e.error))?;
    Ok(())
}

#[cfg(unix)]
fn default_permissions() -> std::fs::Permissions {
    use std::os::unix::fs::PermissionsExt;
    std::fs::Permissions::from_mode(0o644)
}

#[cfg(not(unix))]
fn default_permissions() -> std::fs::Permissions {
    std::fs::metadata(".")
        .map(|m| m.permissions())
        .unwrap_or_else(|_| unreachable!())
}

/// Writes a triangle mesh as OBJ (`v` lines in shortest round-trip form,
/// then `f` lines), atomically.
pub fn write_obj(path: &Path, positions: &[DVec3], triangles: &[[u32; 3]]) -> Result<()> {
    write_atomic(path, |w| write_obj_to(w, positions, triangles))
}

/// Writes OBJ text to any writer.
pub fn write_obj_to(w: &mut dyn Write, positions: &[DVec3], triangles: &[[u32; 3]]) -> std::io::Result<()> {
    let mut fmt = ryu::Buffer::new();
    let mut line = Vec::with_capacity(96);
    for p in positions {
        line.clear();
        line.extend_from_slice(b"v");
        for c in p.to_array() {
            line.push(b' ');
            line.extend_from_slice(fmt.format_finite(c).as_bytes());
        }
        line.push(b'\n');
        w.write_all(&line)?;
    }
    let mut int = itoa_buf::Buf::default();
    for t in triangles {
        line.clear();
        line.push(b'f');
        for v in t {
            line.push(b' ');
            line.extend_from_slice(int.format(*v as u64 + 1));
        }
        line.push(b'\n');
        w.write_all(&line)?;
    }
    Ok(())
}

/// A minimal integer formatter (no allocation).
mod itoa_buf {
    /// Digits of a `u64`, written backwards into a fixed buffer.
    #[derive(Default)]
    pub struct Buf([u8; 20]);

    impl Buf {
        /// The decimal digits of `x`.
        pub fn format(&mut self, mut x: u64) -> &[u8] {
            let mut i = 20;
            loop {
                i -= 1;
                self.0[i] = b'0' + (x % 10) as u8;
                x /= 10;
                if x == 0 {
                    break;
                }
            }
            &self.0[i..]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<InputMesh> {
        parse_obj(text.as_bytes(), Path::new("t.obj"))
    }

    #[test]
    fn reads_polygons_groups_and_relative_indices() {
        let m = parse(
            "# a quad and a triangle\no a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\ng x\nf 1/1 2/1 3/1 4/1\nv 2 0 0\nf -4 -1 -3\n",
        )
        .unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]]);
        assert_eq!(m.triangle_line, vec![9, 9, 11]);
        assert_eq!(m.faces_in_file, 2);
    }

    #[test]
    fn welds_bit_identical_positions_and_drops_unused() {
        let m = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 5 6 3\n").unwrap();
        assert_eq!(m.welded, 1);
        assert_eq!(m.unreferenced, 1);
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        assert_eq!(m.vertex_number, vec![1, 2, 3, 6]);
    }

    #[test]
    fn refuses_bad_input_naming_the_line() {
        let cases = [
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no faces"),
            (
                "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
                ":1: vertex 1 has a non-finite",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
                ":4: face index 4 is out of range",
            ),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", ":4: face index 0"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n", ":4: face 1 repeats vertex 2"),
            ("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", ":4: face 1 has zero area"),
            ("ply\nformat ascii 1.0\n", ":1: unknown statement 'ply'"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 0\nf 1 2 3\nf 4 2 3 1\n",
                ":6: face 2 repeats vertex 1",
            ),
            ("v 0 x 0\n", ":1: vertex coordinate 'x'"),
        ];
        for (text, expected) in cases {
            let msg = parse(text).unwrap_err().to_string();
            assert!(msg.contains(expected), "{text:?}: {msg}");
        }
        let msg = parse_obj(b"v 0 0 0\n\xff\xfe\n", Path::new("t.obj"))
            .unwrap_err()
            .to_string();
        assert!(msg.contains(":2: not text"), "{msg}");
    }

    #[test]
    fn topology_errors_name_lines_and_vertices() {
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\n";
        let m = parse(&format!("{tri}f 1 2 3\nf 1 2 4\n")).unwrap();
        let msg = build_surface(&m, Path::new("t.obj")).unwrap_err().to_string();
        assert!(
            msg.contains("line 7") && msg.contains("inconsistent orientation"),
            "{msg}"
        );
        let m = parse(&format!("{tri}f 1 2 3\nf 2 1 4\nf 1 2 5\n")).unwrap();
        let msg = build_surface(&m, Path::new("t.obj")).unwrap_err().to_string();
        assert!(msg.contains("more than two faces"), "{msg}");
        let m = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n").unwrap();
        let msg = build_surface(&m, Path::new("t.obj")).unwrap_err().to_string();
        assert!(
            msg.contains("vertex 1:") && msg.contains("non-manifold vertex"),
            "{msg}"
        );
    }

    #[test]
    fn writes_shortest_round_trip_floats() {
        let p = vec![
            DVec3::new(0.1, -0.0, 1e-300),
            DVec3::new(1.0 / 3.0, 2.5, 1e22),
            DVec3::new(7.0, 8.0, 9.0),
        ];
        let mut out = Vec::new();
        write_obj_to(&mut out, &p, &[[0, 1, 2]]).unwrap();
        let text = String::from_utf8(out).unwrap();
        let back = parse(&text).unwrap();
        assert_eq!(back.positions, p);
        assert!(text.starts_with("v 0.1 -0.0 1e-300\n"), "{text}");
        assert!(text.ends_with("f 1 2 3\n"));
    }

    #[test]
    fn atomic_write_leaves_target_alone_on_failure() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.obj");
        std::fs::write(&target, "old").unwrap();
        let r = write_atomic(&target, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "temporary file left behind"
        );
        write_atomic(&target, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
    }
}
