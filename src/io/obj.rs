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
///
/// A byte cursor over text validated once: tokens are runs of non-blank
/// bytes, `#` ends a line, coordinates go through `str::parse::<f64>` (exact)
/// and indices are parsed by hand.
pub fn parse_obj(bytes: &[u8]) -> Result<RawMesh, FormatError> {
    let lossy;
    let text = match std::str::from_utf8(bytes) {
        Ok(t) => t,
        Err(_) => {
            // Bytes that are not UTF-8 are fine inside comments (Latin-1
            // comments exist); anywhere else the file is not OBJ text.
            for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
                let code = line.split(|&b| b == b'#').next().unwrap_or(&[]);
                if std::str::from_utf8(code).is_err() {
                    return Err(error(i + 1, "not text: this is not an OBJ file".into()));
                }
            }
            lossy = String::from_utf8_lossy(bytes);
            &lossy
        }
    };
    let mut raw = RawMesh {
        origin_kind: OriginKind::Line,
        ..RawMesh::default()
    };
    // About 30 bytes per vertex line and 25 per face line in typical files.
    raw.positions.reserve(bytes.len() / 64);
    raw.indices.reserve(bytes.len() / 24);
    let mut line_no = 0usize;
    let mut tokens = Tokens { s: text, i: 0 };
    while tokens.i < text.len() {
        line_no += 1;
        let Some(keyword) = tokens.next() else { continue };
        match keyword {
            "v" => {
                let mut xyz = [0.0f64; 3];
                for (k, c) in xyz.iter_mut().enumerate() {
                    let tok = tokens
                        .next()
                        .ok_or_else(|| error(line_no, format!("vertex has {k} coordinates, needs 3")))?;
                    *c = tok
                        .parse()
                        .map_err(|_| error(line_no, format!("vertex coordinate '{tok}' is not a number")))?;
                    if !c.is_finite() {
                        let v = raw.positions.len() + 1;
                        return Err(error(
                            line_no,
                            format!("vertex {v} has a non-finite coordinate '{tok}'"),
                        ));
                    }
                }
                raw.positions.push(xyz);
                raw.vertex_origin.push(line_no as u32);
            }
            "f" => {
                if raw.face_start.is_empty() {
                    raw.face_start.push(0);
                }
                let start = raw.indices.len();
                while let Some(tok) = tokens.next() {
                    let value = parse_index(tok)
                        .ok_or_else(|| error(line_no, format!("face index '{tok}' is not an integer")))?;
                    let resolved = match value {
                        0 => return Err(error(line_no, "face index 0 (OBJ indices start at 1)".into())),
                        v if v > 0 => v - 1,
                        v => raw.positions.len() as i64 + v,
                    };
                    if resolved < 0 || resolved >= u32::MAX as i64 {
                        return Err(error(line_no, format!("face index {value} is out of range")));
                    }
                    raw.indices.push(resolved as u32);
                }
                let count = raw.indices.len() - start;
                if count < 3 {
                    return Err(error(line_no, format!("face has {count} vertices, needs at least 3")));
                }
                raw.face_start.push(raw.indices.len() as u32);
                raw.face_origin.push(line_no as u32);
            }
            k if IGNORED.contains(&k) => {}
            k => {
                let shown: String = k.chars().take(20).collect();
                return Err(error(
                    line_no,
                    format!("unknown statement '{shown}': this is not an OBJ file"),
                ));
            }
        }
        tokens.start_line();
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

/// Blank-separated tokens of the current line of `s` (blank: space, tab,
/// CR, form feed); a `#` ends the line. `i` is the cursor in `s`.
struct Tokens<'a> {
    s: &'a str,
    i: usize,
}

impl<'a> Tokens<'a> {
    /// Moves the cursor to the start of the next line if it is inside one
    /// (tokens left unread), past that line's newline.
    fn start_line(&mut self) {
        let b = self.s.as_bytes();
        while self.i > 0 && self.i < b.len() && b[self.i - 1] != b'\n' {
            self.i += 1;
        }
    }

    /// The next token of the current line, or `None` at its end; the cursor
    /// then rests at the start of the next line (a comment is skipped whole).
    #[inline]
    fn next(&mut self) -> Option<&'a str> {
        let b = self.s.as_bytes();
        while self.i < b.len() && matches!(b[self.i], b' ' | b'\t' | b'\r' | 0x0c | 0x0b) {
            self.i += 1;
        }
        if self.i < b.len() && b[self.i] == b'#' {
            while self.i < b.len() && b[self.i] != b'\n' {
                self.i += 1;
            }
        }
        if self.i == b.len() {
            return None;
        }
        if b[self.i] == b'\n' {
            self.i += 1;
            return None;
        }
        let start = self.i;
        while self.i < b.len() && !matches!(b[self.i], b' ' | b'\t' | b'\r' | 0x0c | 0x0b | b'\n' | b'#') {
            self.i += 1;
        }
        // Both ends are at ASCII bytes (or the end of the text): char boundaries.
        self.s.get(start..self.i)
    }
}

/// The vertex index of a face token `i`, `i/t`, `i//n` or `i/t/n`: a
/// non-zero decimal integer, possibly negative; `None` if malformed or huge.
#[inline]
fn parse_index(tok: &str) -> Option<i64> {
    let b = tok.as_bytes();
    let end = b.iter().position(|&c| c == b'/').unwrap_or(b.len());
    let (negative, digits) = match b[..end].split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, &b[..end]),
    };
    if digits.is_empty() || digits.len() > 18 {
        return None;
    }
    let mut v: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        v = v * 10 + (d - b'0') as i64;
    }
    Some(if negative { -v } else { v })
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The obvious reader: split lines, cut comments, split on whitespace.
    fn reference(text: &str) -> (Vec<[f64; 3]>, Vec<u32>, Vec<u32>, Vec<u32>) {
        let (mut pos, mut idx, mut starts, mut lines) = (Vec::new(), Vec::new(), vec![0u32], Vec::new());
        for (n, line) in text.split('\n').enumerate() {
            let code = line.split('#').next().unwrap_or("");
            let mut t = code.split_ascii_whitespace();
            match t.next() {
                Some("v") => {
                    let v: Vec<f64> = t.take(3).map(|x| x.parse().unwrap()).collect();
                    pos.push([v[0], v[1], v[2]]);
                }
                Some("f") => {
                    for tok in t {
                        let i: i64 = tok.split('/').next().unwrap().parse().unwrap();
                        idx.push(if i > 0 {
                            i as u32 - 1
                        } else {
                            (pos.len() as i64 + i) as u32
                        });
                    }
                    starts.push(idx.len() as u32);
                    lines.push(n as u32 + 1);
                }
                _ => {}
            }
        }
        (pos, idx, starts, lines)
    }

    #[test]
    fn fast_reader_agrees_with_the_obvious_one() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        };
        let blanks = [" ", "  ", "\t", " \t "];
        for _ in 0..300 {
            let mut text = String::new();
            let mut nv = 0;
            let eol = if rnd(3) == 0 { "\r\n" } else { "\n" };
            for _ in 0..rnd(30) + 1 {
                let b = blanks[rnd(4) as usize];
                match rnd(9) {
                    0 => text.push_str("# a comment v 1 2 3"),
                    1 => {}
                    2 => text.push_str(&format!("vt{b}0.5 0.25")),
                    3 => text.push_str(&format!("g{b}group{b}# trailing")),
                    4..=6 => {
                        nv += 1;
                        let extra = if rnd(3) == 0 { " 1.0" } else { "" };
                        let c = if rnd(4) == 0 { " # c" } else { "" };
                        text.push_str(&format!(
                            "{b}v{b}{}{b}-{}e-3 {}{extra}{c}",
                            rnd(1000) as f64 / 7.0,
                            rnd(99),
                            rnd(5)
                        ));
                    }
                    _ if nv >= 3 => {
                        let k = 3 + rnd(3);
                        let mut f = String::from("f");
                        for _ in 0..k {
                            let i = rnd(nv) as i64;
                            let tok = match rnd(3) {
                                0 => format!("{}", i + 1),
                                1 => format!("{}/{}", i + 1, i + 1),
                                _ => format!("{}//7", i - nv as i64),
                            };
                            f.push_str(b);
                            f.push_str(&tok);
                        }
                        text.push_str(&f);
                    }
                    _ => {}
                }
                text.push_str(eol);
            }
            if rnd(2) == 0 {
                text.truncate(text.trim_end_matches(['\r', '\n']).len());
            }
            let (pos, idx, starts, lines) = reference(&text);
            match parse_obj(text.as_bytes()) {
                Ok(raw) => {
                    assert_eq!(raw.positions, pos, "{text:?}");
                    assert_eq!(raw.indices, idx, "{text:?}");
                    if !lines.is_empty() {
                        assert_eq!(raw.face_start, starts, "{text:?}");
                    }
                    assert_eq!(raw.face_origin, lines, "{text:?}");
                }
                Err(e) => panic!("{e}: {text:?}"),
            }
        }
    }
}
