//! Wavefront OBJ: delmesh's own reader (line numbers for every vertex and
//! face, exact `f64` parsing) and writer (shortest round-trip floats).
//!
//! Every object and group of the file goes into one mesh; texture
//! coordinates, normals, groups and materials are read past.

use std::io::Write;

use super::formats::{FormatError, OriginKind, RawMesh};

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

fn error(line: usize, what: String) -> FormatError {
    FormatError {
        line: Some(line as u64),
        what,
    }
}

/// Parses OBJ text into polygons (indices checked, nothing welded).
pub fn parse_obj(bytes: &[u8]) -> Result<RawMesh, FormatError> {
    let mut raw = RawMesh {
        origin_kind: OriginKind::Line,
        ..RawMesh::default()
    };
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let n = i + 1;
        let line = std::str::from_utf8(line).map_err(|_| error(n, "not text: this is not an OBJ file".into()))?;
        let line = line.split('#').next().unwrap_or("");
        let mut tokens = line.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else { continue };
        match keyword {
            "v" => {
                let mut xyz = [0.0f64; 3];
                for (k, c) in xyz.iter_mut().enumerate() {
                    let tok = tokens
                        .next()
                        .ok_or_else(|| error(n, format!("vertex has {k} coordinates, needs 3")))?;
                    *c = tok
                        .parse()
                        .map_err(|_| error(n, format!("vertex coordinate '{tok}' is not a number")))?;
                    if !c.is_finite() {
                        let v = raw.positions.len() + 1;
                        return Err(error(n, format!("vertex {v} has a non-finite coordinate '{tok}'")));
                    }
                }
                raw.positions.push(xyz);
                raw.vertex_origin.push(n as u32);
            }
            "f" => {
                if raw.face_start.is_empty() {
                    raw.face_start.push(0);
                }
                let start = raw.indices.len();
                for tok in tokens {
                    let index = tok.split('/').next().unwrap_or("");
                    let value: i64 = index
                        .parse()
                        .map_err(|_| error(n, format!("face index '{tok}' is not an integer")))?;
                    let resolved = match value {
                        0 => return Err(error(n, "face index 0 (OBJ indices start at 1)".into())),
                        v if v > 0 => v - 1,
                        v => raw.positions.len() as i64 + v,
                    };
                    if resolved < 0 || resolved >= u32::MAX as i64 {
                        return Err(error(n, format!("face index {value} is out of range")));
                    }
                    raw.indices.push(resolved as u32);
                }
                let count = raw.indices.len() - start;
                if count < 3 {
                    return Err(error(n, format!("face has {count} vertices, needs at least 3")));
                }
                raw.face_start.push(raw.indices.len() as u32);
                raw.face_origin.push(n as u32);
            }
            k if IGNORED.contains(&k) => {}
            k => {
                let shown: String = k.chars().take(20).collect();
                return Err(error(
                    n,
                    format!("unknown statement '{shown}': this is not an OBJ file"),
                ));
            }
        }
    }
    // Out-of-range indices (forward references are allowed, so only now).
    let nv = raw.positions.len();
    for f in 0..raw.face_origin.len() {
        let poly = &raw.indices[raw.face_start[f] as usize..raw.face_start[f + 1] as usize];
        if let Some(&bad) = poly.iter().find(|&&c| c as usize >= nv) {
            let what = format!(
                "face index {} is out of range (the file has {nv} vertices)",
                bad as u64 + 1
            );
            return Err(error(raw.face_origin[f] as usize, what));
        }
    }
    Ok(raw)
}

/// Writes a triangle mesh as OBJ: `v` lines in shortest round-trip form,
/// then `f` lines.
pub fn write_obj(w: &mut dyn Write, positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> std::io::Result<()> {
    let mut fmt = ryu::Buffer::new();
    let mut line = Vec::with_capacity(96);
    for p in positions {
        line.clear();
        line.push(b'v');
        for &c in p {
            line.push(b' ');
            line.extend_from_slice(fmt.format_finite(c).as_bytes());
        }
        line.push(b'\n');
        w.write_all(&line)?;
    }
    let mut int = DecimalBuf::default();
    for t in triangles {
        line.clear();
        line.push(b'f');
        for &v in t {
            line.push(b' ');
            line.extend_from_slice(int.format(v as u64 + 1));
        }
        line.push(b'\n');
        w.write_all(&line)?;
    }
    Ok(())
}

/// Decimal digits of a `u64`, written backwards into a fixed buffer (no
/// allocation).
#[derive(Default)]
struct DecimalBuf([u8; 20]);

impl DecimalBuf {
    fn format(&mut self, mut x: u64) -> &[u8] {
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
