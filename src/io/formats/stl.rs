//! Reading (ASCII and binary) and writing (binary) STL.

use super::*;

/// Whether the text starts (after whitespace) with the word `solid`.
pub(super) fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes.iter().position(|&c| !is_space(c)).unwrap_or(bytes.len());
    let rest = &bytes[start..];
    rest.len() >= 5 && rest[..5].eq_ignore_ascii_case(b"solid") && rest.get(5).is_none_or(|&c| is_space(c))
}

/// For a binary STL: the facet count and the file size it implies, or None if shorter than 84 bytes.
pub(super) fn binary_stl_size(bytes: &[u8]) -> Option<(u32, u64)> {
    let n = u32::from_le_bytes(bytes.get(80..84)?.try_into().ok()?);
    Some((n, 84 + 50 * u64::from(n)))
}

/// Reads an STL file, ASCII or binary, decided by content: a file that starts with `solid` is read as
/// ASCII, unless that fails (or leaves non-whitespace behind) and its size fits a binary STL with the
/// facet count at byte 80, as for binary files whose 80-byte header starts with "solid". A binary file
/// whose size after the header is a whole number of facets more than its count says is read by its
/// size, with a note (exporters write wrong counts, and 0); fewer is a file cut short, refused. Bytes after the last facet are ignored
/// (with a note when whole facets would fit there). STL has no shared vertices: each facet gives 3 positions (more for an ASCII
/// `outer loop` with more vertices). Binary origins are facet record numbers.
pub fn read_stl(bytes: &[u8]) -> Result<RawMesh, FormatError> {
    if bytes.is_empty() {
        return Err(FormatError::new("the file is empty"));
    }
    let size = binary_stl_size(bytes);
    let fits_binary = size.is_some_and(|(_, need)| need <= bytes.len() as u64);
    let text = strip_bom(bytes);
    if starts_with_solid(text) {
        match read_stl_ascii(text) {
            Ok((mesh, end)) => {
                let exact_binary = size.is_some_and(|(_, need)| need == bytes.len() as u64);
                let clean_end = text.get(end..).unwrap_or(&[]).iter().all(|&c| is_space(c));
                // An empty solid followed by binary bytes is the header of
                // a binary STL (cut short, if it does not fit one).
                let header_only = mesh.face_start.is_empty() && !clean_end && looks_binary(bytes);
                if (!exact_binary || clean_end) && !header_only {
                    return Ok(mesh);
                }
            }
            // Text never holds a NUL byte; a binary STL's facet count and
            // attribute words nearly always do: one whose header starts
            // with `solid` but that is cut short is called truncated (by
            // the binary reader), not text that fails to parse.
            Err(e) if !fits_binary && !looks_binary(bytes) => return Err(e),
            Err(_) => {}
        }
    }
    read_stl_binary(bytes)
}

/// Whether `bytes` hold a NUL byte in their first 64 KiB, as no text does.
fn looks_binary(bytes: &[u8]) -> bool {
    bytes[..bytes.len().min(1 << 16)].contains(&0)
}

fn read_stl_binary(bytes: &[u8]) -> Result<RawMesh, FormatError> {
    let Some((n, need)) = binary_stl_size(bytes) else {
        return Err(FormatError::new(format!(
            "the file has {} bytes: too short for a binary STL (84 at least) and it does not start with `solid`",
            bytes.len()
        )));
    };
    // Many exporters write a wrong count, or 0: where the file's size is
    // the header and a whole number of facets (one at least), those are
    // read, with a note (if its bytes are binary: text never holds a NUL,
    // and a file of text is no binary STL whatever its size).
    let len = bytes.len() as u64;
    let by_size = (len - 84) / 50;
    let whole = by_size > 0 && (len - 84) % 50 == 0;
    // (A count above what the size holds is a file cut short: refused.)
    let (n, trailing) = if u64::from(n) < by_size && whole && looks_binary(bytes) {
        let read = u32::try_from(by_size).unwrap_or(u32::MAX);
        let note = format!(
            "the binary STL header declares {n} facets, but the file's size holds {by_size}: all {by_size} read (the header's count is wrong)"
        );
        (read, Some(note))
    } else {
        if need > len {
            return Err(FormatError::new(format!(
                "the binary STL header declares {n} facets ({need} bytes) but the file has only {len} bytes (truncated file?)"
            )));
        }
        // Bytes after the declared facets are ignored, as other readers do;
        // but room for whole facets there may mean a wrong count, and
        // holes: said.
        let extra = len - need;
        let trailing = (extra >= 50).then(|| {
            format!(
                "{extra} bytes after the {n} facets the binary STL header declares ignored (room for {} more: if its count is wrong, facets are missing)",
                extra / 50
            )
        });
        (n, trailing)
    };
    let n = n as usize;
    if n > u32::MAX as usize / 3 {
        return Err(FormatError::new(format!(
            "the binary STL has {n} facets, more than 2^32 vertices"
        )));
    }
    let mut b = Builder::new(OriginKind::Record, Numbering::Stl);
    b.reserve_vertices(3 * n);
    b.reserve_faces(n, 3 * n);
    for (f, rec) in bytes[84..].chunks_exact(50).take(n).enumerate() {
        b.start_face();
        for k in 0..3 {
            let mut p = [0.0; 3];
            for (axis, c) in p.iter_mut().enumerate() {
                let at = 12 + 12 * k + 4 * axis;
                *c = f64::from(decode!(f32, &rec[at..at + 4], false));
            }
            b.vertex(p, f as u64, || format!("facet {f} vertex {k}"))?;
            b.index((3 * f + k) as u32);
        }
        b.end_face(f as u64)?;
    }
    let mut m = b.finish()?;
    m.notes.extend(trailing);
    Ok(m)
}

/// Reads ASCII STL; returns the mesh and the offset just after the last `endsolid` line.
fn read_stl_ascii(bytes: &[u8]) -> Result<(RawMesh, usize), FormatError> {
    if let Some(line) = lone_cr_line(bytes) {
        return Err(FormatError::at(line, LONE_CR));
    }
    let mut t = Tokens::new(bytes, 0, 1);
    let mut b = Builder::new(OriginKind::Line, Numbering::Stl);
    let mut end = 0;
    let mut facet = 0usize;
    let is = |tok: &[u8], kw: &str| tok.eq_ignore_ascii_case(kw.as_bytes());
    while let Some((tok, line)) = t.next() {
        if !is(tok, "solid") {
            if end > 0 {
                break; // Trailing bytes after the last solid are ignored.
            }
            return Err(FormatError::at(
                line,
                format!("expected `solid`, found `{}`", show(tok)),
            ));
        }
        t.skip_line(); // The solid's name.
        loop {
            let Some((tok, facet_line)) = t.next() else {
                return Err(FormatError::at(
                    t.line,
                    "the ASCII STL ends without `endsolid` (truncated file?)",
                ));
            };
            if is(tok, "endsolid") {
                t.skip_line();
                end = t.pos;
                break;
            }
            if !is(tok, "facet") {
                return Err(FormatError::at(
                    facet_line,
                    format!("expected `facet` or `endsolid`, found `{}`", show(tok)),
                ));
            }
            let mut next = |what: &str| {
                t.next().ok_or_else(|| {
                    FormatError::at(
                        facet_line,
                        format!("the ASCII STL ends inside facet {facet} (expected {what})"),
                    )
                })
            };
            let (mut tok, mut line) = next("`normal` or `outer`")?;
            if is(tok, "normal") {
                // Up to three numbers; their values do not matter.
                let mut numbers = 0;
                loop {
                    (tok, line) = next("`outer`")?;
                    if numbers == 3 || parse_f64(tok).is_none() {
                        break;
                    }
                    numbers += 1;
                }
            }
            if !is(tok, "outer") {
                return Err(FormatError::at(
                    line,
                    format!("facet {facet}: expected `outer loop`, found `{}`", show(tok)),
                ));
            }
            let (tok, line) = next("`loop`")?;
            if !is(tok, "loop") {
                return Err(FormatError::at(
                    line,
                    format!("facet {facet}: expected `loop`, found `{}`", show(tok)),
                ));
            }
            b.start_face();
            let mut k = 0usize;
            loop {
                let (tok, line) = next("`vertex` or `endloop`")?;
                if is(tok, "endloop") {
                    break;
                }
                if !is(tok, "vertex") {
                    return Err(FormatError::at(
                        line,
                        format!("facet {facet}: expected `vertex` or `endloop`, found `{}`", show(tok)),
                    ));
                }
                let mut p = [0.0; 3];
                for c in &mut p {
                    let (tok, _) = next("a coordinate")?;
                    *c = parse_f64(tok).ok_or_else(|| {
                        FormatError::at(
                            line,
                            format!(
                                "facet {facet} vertex {k} coordinate `{}` is not a number{}",
                                show(tok),
                                super::decimal_comma_hint(tok)
                            ),
                        )
                    })?;
                }
                let index = b.m.positions.len() as u32;
                b.vertex(p, line, || format!("facet {facet} vertex {k}"))?;
                b.index(index);
                k += 1;
            }
            if k < 3 {
                return Err(FormatError::at(
                    facet_line,
                    format!("facet {facet} has {k} vertices (at least 3 needed)"),
                ));
            }
            let (tok, line) = next("`endfacet`")?;
            if !is(tok, "endfacet") {
                return Err(FormatError::at(
                    line,
                    format!("facet {facet}: expected `endfacet`, found `{}`", show(tok)),
                ));
            }
            b.end_face(facet_line)?;
            facet += 1;
        }
    }
    if end == 0 {
        return Err(FormatError::at(t.line, "the ASCII STL has no `solid`"));
    }
    Ok((b.finish()?, end))
}

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------

/// Writes a binary STL. The format stores `f32`, so positions lose their `f64` precision (and a
/// coordinate beyond the `f32` range is refused with `InvalidInput`); vertices are not shared. Each facet
/// normal is computed from its vertices (zero for a degenerate facet). The 80-byte header does not start
/// with "solid".
pub fn write_stl_binary(w: &mut dyn Write, positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> io::Result<()> {
    check_for_writing(positions, triangles, None)?;
    if let Some(i) = positions
        .iter()
        .position(|p| !p.iter().all(|&c| (c as f32).is_finite()))
    {
        return Err(invalid(format!(
            "vertex {i} has a coordinate beyond the f32 range of STL"
        )));
    }
    let count = u32::try_from(triangles.len()).map_err(|_| {
        invalid(format!(
            "{} triangles are more than binary STL can hold",
            triangles.len()
        ))
    })?;
    let mut w = BufWriter::new(w);
    let mut header = [b' '; 80];
    let text = b"binary STL written by delmesh (f32 coordinates)";
    header[..text.len()].copy_from_slice(text);
    w.write_all(&header)?;
    w.write_all(&count.to_le_bytes())?;
    let mut record = Vec::with_capacity(50);
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let n = if len > 0.0 && len.is_finite() {
            n.map(|x| x / len)
        } else {
            [0.0; 3]
        };
        record.clear();
        for p in [n, a, b, c] {
            for x in p {
                record.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        record.extend_from_slice(&[0, 0]);
        w.write_all(&record)?;
    }
    w.flush()
}
