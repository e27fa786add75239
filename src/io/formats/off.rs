//! Reading and writing OFF (with the `[ST][C][N][4][n]OFF` keywords' colours,
//! normals and texture coordinates).

use super::*;
use crate::io::lines::{
    push_decimal, push_face, write_numbered_lines, write_vertex_and_face_lines, xyz_line, VertexLines,
};
use crate::io::number::unreadable_integer;

/// What the prefixes of an OFF keyword say (`[ST][C][N][4][n]OFF`): the
/// vertex lines give texture coordinates (`ST`), a colour (`C`) and a
/// normal (`N`) after x y z, in the order normal, colour, texture
/// coordinates.
#[derive(Clone, Copy, Default)]
pub(super) struct OffKeyword {
    four: bool,
    ndim: bool,
    texcoords: bool,
    color: bool,
    normal: bool,
}

pub(super) fn off_keyword(tok: &[u8]) -> Option<OffKeyword> {
    if tok == b"off" {
        return Some(OffKeyword::default());
    }
    let mut rest = tok.strip_suffix(b"OFF")?;
    let mut kw = OffKeyword::default();
    let (mut st, mut c, mut n) = (false, false, false);
    while !rest.is_empty() {
        let (flag, len) = if rest.starts_with(b"ST") {
            (&mut st, 2)
        } else {
            match rest[0] {
                b'C' => (&mut c, 1),
                b'N' => (&mut n, 1),
                b'4' => (&mut kw.four, 1),
                b'n' => (&mut kw.ndim, 1),
                _ => return None,
            }
        };
        if *flag {
            return None;
        }
        *flag = true;
        rest = &rest[len..];
    }
    (kw.texcoords, kw.color, kw.normal) = (st, c, n);
    Some(kw)
}

/// The attributes of an OFF file as they are read: the vertices' normals,
/// colours and texture coordinates its keyword announces, and the faces'
/// colours (numbers after a face's indices).
#[derive(Default)]
struct OffAttributes {
    /// Per vertex, if the keyword announces them: 3, 3 or 4, and 2 numbers.
    normals: Option<Vec<f64>>,
    colors: Option<Vec<f64>>,
    texcoords: Option<Vec<f64>>,
    /// Colour components per vertex (3 or 4), from the first vertex.
    color_dim: usize,
    /// The first defect of normals, colours, texture coordinates and face
    /// colours: that attribute is dropped, with a note.
    defects: [Option<String>; 4],
    /// The faces' colours, 3 or 4 numbers each (from the first face that
    /// has one), and how many faces have none.
    face_colors: Vec<f64>,
    face_color_dim: usize,
    faces_without: usize,
}

/// The numbers among the rest of a line's words, without allocating: the
/// first `N` (`N` at most 32), which of those are not numbers (and their
/// words), how many words there are, and the first word that is not a
/// number, with its place.
struct LineNumbers<'a, const N: usize> {
    values: [f64; N],
    words: [&'a [u8]; N],
    /// Bit k: word k is not a number.
    not_numbers: u32,
    count: usize,
    bad: Option<(usize, &'a [u8])>,
}

impl<'a, const N: usize> LineNumbers<'a, N> {
    fn read(words: impl Iterator<Item = &'a [u8]>) -> Self {
        let mut numbers = LineNumbers {
            values: [f64::NAN; N],
            words: [b""; N],
            not_numbers: 0,
            count: 0,
            bad: None,
        };
        for (k, w) in words.enumerate() {
            numbers.count += 1;
            let x = parse_f64(w);
            if x.is_none() {
                numbers.bad.get_or_insert((k, w));
            }
            if k < N {
                numbers.words[k] = w;
                match x {
                    Some(x) => numbers.values[k] = x,
                    None => numbers.not_numbers |= 1 << k,
                }
            }
        }
        numbers
    }
}

impl OffAttributes {
    fn new(kw: OffKeyword) -> OffAttributes {
        let has = |x: bool| x.then(Vec::new);
        OffAttributes {
            normals: has(kw.normal),
            colors: has(kw.color),
            texcoords: has(kw.texcoords),
            ..OffAttributes::default()
        }
    }

    /// Notes the first defect of attribute `slot` (see `defects`).
    fn defect(&mut self, slot: usize, line: u64, what: impl FnOnce() -> String) {
        self.defects[slot].get_or_insert_with(|| format!("line {line}: {}", what()));
    }

    /// Whether vertices have nothing to read after their coordinates.
    fn vertex_channels_none(&self) -> bool {
        self.normals.is_none() && self.colors.is_none() && self.texcoords.is_none()
    }

    /// Reads what follows vertex `i`'s coordinates on its line.
    fn vertex<'a>(&mut self, rest: impl Iterator<Item = &'a [u8]>, i: usize, line: u64) {
        if self.vertex_channels_none() {
            return;
        }
        // At most a normal, an RGBA colour and texture coordinates.
        let numbers = LineNumbers::<16>::read(rest);
        let mut at = 0;
        if self.normals.is_some() {
            self.take(0, &numbers, at..at + 3, i, line, "normal (NOFF: 3 numbers after x y z)");
            at += 3;
        }
        let texcoords = usize::from(self.texcoords.is_some()) * 2;
        if self.colors.is_some() {
            let n = numbers.count.saturating_sub(at + texcoords);
            if self.color_dim == 0 && (3..=4).contains(&n) {
                self.color_dim = n;
            }
            if n > 0 && n == self.color_dim {
                self.take(1, &numbers, at..at + n, i, line, "colour");
            } else {
                let dim = self.color_dim;
                self.defect(1, line, || match dim {
                    0 => format!("vertex {i} has {n} colour components (3 or 4 expected)"),
                    _ => format!("vertex {i} has {n} colour components, the vertices before it {dim}"),
                });
            }
            at += n;
        }
        if self.texcoords.is_some() {
            self.take(
                2,
                &numbers,
                at..at + 2,
                i,
                line,
                "texture coordinates (STOFF: 2 numbers)",
            );
        }
    }

    /// Appends `numbers[span]`, of vertex `i`'s line, to the values of
    /// attribute `slot` (0 normals, 1 colours, 2 texture coordinates), or
    /// notes its defect: the line has no such numbers, or a word there is
    /// not a number.
    fn take<const N: usize>(
        &mut self,
        slot: usize,
        numbers: &LineNumbers<N>,
        span: std::ops::Range<usize>,
        i: usize,
        line: u64,
        what: &str,
    ) {
        if span.end > numbers.count.min(N) {
            return self.defect(slot, line, || format!("vertex {i} has no {what}"));
        }
        if let Some(k) = span.clone().find(|&k| numbers.not_numbers & (1 << k) != 0) {
            let w = numbers.words[k];
            return self.defect(slot, line, || {
                format!(
                    "vertex {i} {what} `{}` is not a number{}",
                    show(w),
                    super::decimal_comma_hint(w)
                )
            });
        }
        let values = [&mut self.normals, &mut self.colors, &mut self.texcoords][slot].get_or_insert_with(Vec::new);
        values.extend_from_slice(&numbers.values[span]);
    }

    /// Reads what follows face `f`'s indices on its line: a colour (3 or 4
    /// numbers) or nothing.
    fn face<'a>(&mut self, rest: impl Iterator<Item = &'a [u8]>, f: usize, line: u64) {
        let c = LineNumbers::<4>::read(rest);
        match (c.count, c.bad) {
            (0, _) => self.faces_without += 1,
            (_, Some((_, w))) => self.defect(3, line, || {
                format!(
                    "face {f}: `{}` after its indices is not a number (a colour is 3 or 4)",
                    show(w)
                )
            }),
            (n @ 3..=4, None) if self.face_color_dim == 0 || n == self.face_color_dim => {
                self.face_color_dim = n;
                self.face_colors.extend_from_slice(&c.values[..n]);
            }
            (n @ 3..=4, None) => {
                let dim = self.face_color_dim;
                self.defect(3, line, || {
                    format!("face {f} has a colour of {n} numbers, the faces before it of {dim}")
                })
            }
            (1, None) => self.defect(3, line, || {
                format!("face {f} gives a colour map index, which delmesh does not read")
            }),
            (n, None) => self.defect(3, line, || {
                format!("face {f} has {n} numbers after its indices (a colour is 3 or 4)")
            }),
        }
    }

    /// Moves the attributes into `m`, each with a defect or a non-finite
    /// value dropped with a note. Face colours become the face properties
    /// `red green blue [alpha]`: `uchar` if they are whole numbers up to
    /// 255 (as most files write them), else `float`.
    fn finish(self, m: &mut RawMesh) {
        let [n, c, t, fc] = self.defects;
        let vertex_channels = [
            (Kind::Normal, self.normals, 3, n),
            (Kind::Color, self.colors, self.color_dim, c),
            (Kind::TexCoord, self.texcoords, 2, t),
        ];
        for (kind, values, dim, defect) in vertex_channels {
            let Some(mut values) = values else {
                continue;
            };
            let why = match defect {
                Some(d) => Some(d),
                None if values.iter().any(|x| !x.is_finite()) => Some("a vertex has a non-finite one".to_owned()),
                None => None,
            };
            match why {
                // (A vertex line without a colour of 3 or 4 numbers leaves
                // no colour dimension, but has its defect noted: said too.)
                Some(why) => m.attribute_notes.push(format!("{} dropped: {why}", kind.name())),
                // No colour dimension and no defect: no vertex.
                None if dim == 0 => {}
                None => {
                    // Bytes (`off_colors_are_bytes`) are scaled to 0..1, as
                    // the OFF format says, and typed `uchar`, so that an
                    // output writes them as bytes again. Others are kept as
                    // they are.
                    if kind == Kind::Color && off_colors_are_bytes(&values) {
                        values.iter_mut().for_each(|x| *x /= 255.0);
                        m.attributes.color_type = Some(ValueType::U8);
                    }
                    *m.attributes.channel_mut(kind) = Some(Channel {
                        dim,
                        values,
                        corners: m.indices.clone(),
                    })
                }
            }
        }
        if self.face_colors.is_empty() && fc.is_none() {
            return;
        }
        let faces = m.face_start.len().saturating_sub(1);
        let why = match fc {
            Some(d) => Some(d),
            None if self.faces_without > 0 => Some(format!(
                "{} of {faces} faces {} none",
                self.faces_without,
                if self.faces_without == 1 { "has" } else { "have" }
            )),
            None if self.face_colors.iter().any(|x| !x.is_finite()) => Some("a face has a non-finite one".to_owned()),
            None => None,
        };
        if let Some(why) = why {
            m.attribute_notes.push(format!("face colours dropped: {why}"));
            return;
        }
        // (Beyond a float's range, as no colour is, they are kept as
        // doubles: a float would make them infinite.)
        let ty = if off_colors_are_bytes(&self.face_colors) {
            ValueType::U8
        } else if self.face_colors.iter().all(|&x| (x as f32).is_finite()) {
            ValueType::F32
        } else {
            ValueType::F64
        };
        let dim = self.face_color_dim;
        for (k, name) in ["red", "green", "blue", "alpha"].into_iter().enumerate().take(dim) {
            m.attributes.face_properties.push(FaceProperty {
                name: name.to_owned(),
                ty,
                values: self.face_colors.iter().skip(k).step_by(dim).copied().collect(),
            });
        }
    }
}

/// Whether an OFF file's colour numbers `values` are bytes, 0..255, as
/// most COFF files write them: all whole numbers in that range and one
/// beyond 1 (else, as Geomview reads them, numbers in 0..1).
fn off_colors_are_bytes(values: &[f64]) -> bool {
    values.iter().all(|&x| x.fract() == 0.0 && (0.0..=255.0).contains(&x)) && values.iter().any(|&x| x > 1.0)
}

/// The vertex count glued to the keyword of a header such as `OFF490 518 0` (written so by the
/// tool that made the ModelNet datasets): the digits after `OFF`, if nothing else follows it.
pub(super) fn glued_vertex_count(head: &[u8]) -> Option<&[u8]> {
    let digits = head.strip_prefix(b"OFF")?;
    (!digits.is_empty() && digits.iter().all(u8::is_ascii_digit)).then_some(digits)
}

/// Reads an OFF file (`OFF`, `COFF`, `NOFF`, `CNOFF`, `STOFF`... and headerless files starting with the
/// counts; also `OFF490 518 0`, the keyword glued to the counts as in the ModelNet datasets). Vertex
/// lines give x y z first, then what the keyword announces: a normal (`N`), a colour of 3 or 4
/// numbers (`C`) and texture coordinates (`ST`), read as attributes. Face lines are `n i1 .. in
/// [colour]`, the colours read as the face properties `red green blue [alpha]`. An attribute with a
/// defect is dropped with a note. `#` starts a comment. Binary OFF and 4OFF/nOFF are refused.
pub fn read_off(bytes: &[u8]) -> Result<RawMesh, FormatError> {
    read_off_with(bytes, true)
}

/// [`read_off`], with the one-scan reading of plain vertex and face lines
/// (`plain_lines`, see [`plain_vertex_line`] and [`plain_face_line`]) or
/// without it: every line the general way, which the tests compare it with.
fn read_off_with(bytes: &[u8], plain_lines: bool) -> Result<RawMesh, FormatError> {
    let text = strip_bom(bytes);
    if let Some(line) = lone_cr_line(text) {
        return Err(FormatError::at(line, LONE_CR));
    }
    let mut lines = Lines::new(text);
    let Some((first_line, first)) = lines.next_meaningful() else {
        return Err(FormatError::new("the file is empty (no OFF header)"));
    };
    let mut first_words = words(first);
    let head = first_words.next().unwrap_or(b"");
    let mut attributes = OffAttributes::default();
    let (counts_line, counts): (u64, Vec<&[u8]>) = if let Some(n_vertices) = glued_vertex_count(head) {
        // `OFF490 518 0`: the keyword and the counts on one line with no
        // space between them, as in many files of the ModelNet datasets.
        (
            first_line,
            std::iter::once(n_vertices).chain(first_words.take(3)).collect(),
        )
    } else if let Some(kw) = off_keyword(head) {
        if kw.four || kw.ndim {
            return Err(FormatError::at(
                first_line,
                format!(
                    "OFF variant `{}` (4D or n-dimensional vertices) is not supported",
                    show(head)
                ),
            ));
        }
        attributes = OffAttributes::new(kw);
        let rest: Vec<&[u8]> = first_words.take(4).collect();
        if rest.first().is_some_and(|w| w.eq_ignore_ascii_case(b"BINARY")) {
            return Err(FormatError::at(first_line, "binary OFF is not supported"));
        }
        if rest.is_empty() {
            match lines.next_meaningful() {
                Some((line, text)) => (line, words(text).take(4).collect()),
                None => return Err(FormatError::at(first_line, "the OFF file ends before its counts line")),
            }
        } else {
            (first_line, rest)
        }
    } else if parse_int(head).is_some() {
        (first_line, words(first).take(4).collect())
    } else {
        return Err(FormatError::at(
            first_line,
            format!("not an OFF file: it starts with `{}`", show(head)),
        ));
    };
    if !(2..=3).contains(&counts.len()) {
        return Err(FormatError::at(
            counts_line,
            "the OFF counts line must be `vertices faces edges`",
        ));
    }
    let count = |i: usize, what: &str| -> Result<u64, FormatError> {
        let w = counts[i];
        std::str::from_utf8(w)
            .ok()
            .and_then(|s| s.parse::<u64>().ok())
            .ok_or_else(|| {
                FormatError::at(
                    counts_line,
                    format!("the OFF {what} count `{}` is not a non-negative integer", show(w)),
                )
            })
    };
    let (nv, nf) = (count(0, "vertex")?, count(1, "face")?);
    if counts.len() == 3 {
        count(2, "edge")?;
    }

    // Every vertex or face takes a line of at least two bytes: refuse absurd counts at once. Reservations
    // assume the shortest real lines: 6 bytes for a vertex ("0 0 0\n"), 8 for a face ("3 0 1 2\n").
    let remaining = lines.remaining() as u64;
    if nv.saturating_add(nf).saturating_mul(2) > remaining.saturating_add(1) {
        return Err(FormatError::at(
            counts_line,
            format!("the OFF header declares {nv} vertices and {nf} faces but only {remaining} bytes follow"),
        ));
    }
    // Both counts are now bounded by the input size.
    let (nv, nf) = (nv as usize, nf as usize);
    let mut b = Builder::new(OriginKind::Line, Numbering::FromZero);
    b.reserve_vertices(nv.min(remaining as usize / 6));
    b.reserve_faces(
        nf.min(remaining as usize / 8),
        nf.saturating_mul(3).min(remaining as usize / 2),
    );

    // Plain vertex lines only where nothing but the position follows it
    // (a NOFF, COFF or STOFF vertex has more to read).
    let plain_vertices = plain_lines && attributes.vertex_channels_none();
    for i in 0..nv {
        if plain_vertices {
            if let Some((line, p)) = plain_vertex_line(&mut lines) {
                b.vertex(p, line, || format!("vertex {i}"))?;
                continue;
            }
        }
        let Some((line, text)) = lines.next_meaningful() else {
            return Err(FormatError::at(
                lines.line,
                format!("the OFF file ends after {i} of {nv} vertices"),
            ));
        };
        let mut p = [0.0; 3];
        let mut ws = words(text);
        for (k, c) in p.iter_mut().enumerate() {
            let w = ws
                .next()
                .ok_or_else(|| FormatError::at(line, format!("vertex {i} has {k} coordinates (3 needed)")))?;
            *c = parse_f64(w).ok_or_else(|| {
                let hint = super::decimal_comma_hint(w);
                FormatError::at(
                    line,
                    format!("vertex {i} coordinate `{}` is not a number{hint}", show(w)),
                )
            })?;
        }
        b.vertex(p, line, || format!("vertex {i}"))?;
        attributes.vertex(ws, i, line);
    }

    for f in 0..nf {
        if plain_lines {
            if let Some(line) = plain_face_line(&mut lines, &mut b.m.indices) {
                b.start_face();
                b.end_face(line)?;
                attributes.face(std::iter::empty(), f, line);
                continue;
            }
        }
        let Some((line, text)) = lines.next_meaningful() else {
            return Err(FormatError::at(
                lines.line,
                format!("the OFF file ends after {f} of {nf} faces"),
            ));
        };
        let mut ws = words(text);
        let head = ws.next().unwrap_or(b"");
        let n = parse_int(head).ok_or_else(|| {
            FormatError::at(
                line,
                format!("face {f} vertex count `{}` is not an integer", show(head)),
            )
        })?;
        if n < 3 {
            return Err(FormatError::at(
                line,
                format!("face {f} has {n} vertices (at least 3 needed)"),
            ));
        }
        b.start_face();
        for k in 0..n {
            let Some(w) = ws.next() else {
                return Err(FormatError::at(
                    line,
                    format!("face {f} declares {n} vertices but its line has only {k} indices"),
                ));
            };
            let i = parse_int(w).ok_or_else(|| {
                FormatError::at(line, format!("face {f} index `{}` {}", show(w), unreadable_integer(w)))
            })?;
            b.index(checked_index(i, f, Some(line), nv)?);
        }
        b.end_face(line)?;
        attributes.face(ws, f, line);
    }
    // More after the declared faces is ignored, as other readers do; but
    // the header's counts may be wrong, and the mesh then has holes: said.
    let after = lines.next_meaningful().map(|(line, _)| line);
    let mut m = b.finish()?;
    attributes.finish(&mut m);
    if let Some(line) = after {
        let faces = if nf == 1 { "face" } else { "faces" };
        m.notes.push(format!(
            "line {line}: data after the {nf} {faces} the OFF header declares ignored (if its counts are wrong, faces are \
             missing)"
        ));
    }
    Ok(m)
}

/// The line at the cursor of `lines` if it is a plain vertex line (it
/// starts with three short decimals, see
/// [`crate::io::number::short_decimal_prefix`], separated by blanks): its
/// number and the position, the cursor moved past it, as
/// [`Lines::next_meaningful`] would. `None`, the cursor unmoved, for any
/// other line (a comment, a blank line, fewer numbers, another form of
/// number): the general way reads it. Only for vertices that have nothing
/// more to read.
#[inline]
fn plain_vertex_line(lines: &mut Lines) -> Option<(u64, [f64; 3])> {
    let d = lines.data;
    let mut p = lines.pos;
    let mut xyz = [0.0; 3];
    for c in &mut xyz {
        p = skip_blanks(d, p);
        let (x, len) = crate::io::number::short_decimal_prefix(&d[p..])?;
        if d.get(p + len).is_some_and(|&c| !is_space(c)) {
            return None;
        }
        *c = x;
        p += len;
    }
    // The rest of the line is ignored, as the general way ignores it where
    // vertices have nothing more to read (a comment, extra numbers).
    lines.skip_line_at(p);
    Some((lines.line, xyz))
}

/// The line at the cursor of `lines` if it is a plain face line (a count
/// of at least 3 and as many indices, plain digits below 2^32, see
/// [`plain_digits`], separated and surrounded by blanks only): its indices
/// appended to `indices`, the cursor moved past it, and its number. `None`,
/// with `indices` and the cursor unchanged, for any other line.
#[inline]
fn plain_face_line(lines: &mut Lines, indices: &mut Vec<u32>) -> Option<u64> {
    let d = lines.data;
    let mut p = skip_blanks(d, lines.pos);
    let (n, len) = plain_digits(&d[p..])?;
    if n < 3 {
        return None;
    }
    p += len;
    let start = indices.len();
    for _ in 0..n {
        p = skip_blanks(d, p);
        match plain_digits(&d[p..]) {
            Some((index, len)) if index <= i64::from(u32::MAX) => {
                indices.push(index as u32);
                p += len;
            }
            _ => {
                indices.truncate(start);
                return None;
            }
        }
    }
    if !line_is_blank(d, p) {
        indices.truncate(start);
        return None;
    }
    lines.skip_line_at(p);
    Some(lines.line)
}

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------

/// Writes an OFF file; coordinates in shortest round-trip form, so that [`read_off`] gives them back bit
/// for bit. Non-finite coordinates and out-of-range indices are refused (`InvalidInput`).
pub fn write_off(w: &mut dyn Write, positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> io::Result<()> {
    write_off_after(w, &VertexLines::default(), positions, triangles)
}

/// [`write_off`], with the lines of the first vertices given already
/// formatted (`done`, made by [`VertexLines::new`] from those positions for
/// [`Format::Off`]; OBJ's lines are not used). The other vertices' lines and the
/// faces' are formatted in one run of lines, so both kinds at once on
/// several cores.
pub fn write_off_after(
    w: &mut dyn Write,
    done: &VertexLines,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
) -> io::Result<()> {
    check_for_writing(positions, triangles, None)?;
    let (count, text) = done.text_for(Format::Off);
    write!(w, "OFF\n{} {} 0\n", positions.len(), triangles.len())?;
    crate::io::lines::write_in_pieces(w, text)?;
    let rest = &positions[count.min(positions.len())..];
    write_vertex_and_face_lines(w, rest, triangles, xyz_line, off_face_line)?;
    w.flush()
}

/// Appends the face line of `t` (`3 i j k`, indices from 0).
#[inline]
fn off_face_line(t: &[u32; 3], line: &mut Vec<u8>) {
    push_face(line, b'3', t, 0);
    line.push(b'\n');
}

/// How [`write_off_with`] writes colour components.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorText {
    /// Whole numbers 0..255 (each value rounded and clamped to that range):
    /// 8-bit colours, as most COFF files hold them, and as MeshLab, Open3D
    /// and libigl write and read them.
    Bytes,
    /// Numbers in shortest round-trip form, always with a decimal point
    /// (`1.0`, not `1`): MeshLab tells floats in 0..1 from bytes by it.
    Floats,
}

/// Colours for [`write_off_with`]: `dim` (3 or 4) numbers per vertex or
/// face, written as `text` says.
#[derive(Clone, Debug, PartialEq)]
pub struct OffColors {
    /// Numbers per colour: 3 (RGB) or 4 (RGBA).
    pub dim: usize,
    /// How they are written.
    pub text: ColorText,
    /// `dim` numbers per vertex or face (for [`ColorText::Bytes`], in 0..255).
    pub values: Vec<f64>,
}

/// The byte an OFF file holds for a colour number `x` in 0..255 written as
/// [`ColorText::Bytes`].
pub fn color_byte(x: f64) -> u8 {
    // (`as` saturates; the values are finite.)
    x.round().clamp(0.0, 255.0) as u8
}

/// What an OFF file holds besides positions and faces, for
/// [`write_off_with`]: per vertex, in the order of its line, a normal, a
/// colour and texture coordinates (announced by the keyword's `N`, `C` and
/// `ST`); per face, a colour after its indices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OffExtras {
    /// 3 numbers per vertex.
    pub normals: Option<Vec<f64>>,
    /// A colour per vertex.
    pub colors: Option<OffColors>,
    /// 2 numbers per vertex.
    pub texcoords: Option<Vec<f64>>,
    /// A colour per face.
    pub face_colors: Option<OffColors>,
}

/// Writes an OFF file with vertex normals, colours and texture coordinates
/// and face colours (Geomview's `[ST][C][N]OFF`: the vertex line is `x y z
/// [nx ny nz] [r g b [a]] [s t]`, the face line `3 i j k [r g b [a]]`);
/// numbers in shortest round-trip form, so that [`read_off`] gives them
/// back bit for bit (colours written as bytes: the bytes). Refuses what
/// [`write_off`] refuses, and extras whose count does not match the vertex
/// or face count, colours of other than 3 or 4 numbers and non-finite
/// values (`InvalidInput`). Without extras, the same file as [`write_off`].
pub fn write_off_with(
    w: &mut dyn Write,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    extras: &OffExtras,
) -> io::Result<()> {
    if *extras == OffExtras::default() {
        return write_off(w, positions, triangles);
    }
    check_for_writing(positions, triangles, None)?;
    let (n, nf) = (positions.len(), triangles.len());
    fn colors(c: &Option<OffColors>) -> Option<(&[f64], usize)> {
        c.as_ref().map(|c| (&c.values[..], c.dim))
    }
    let columns = [
        ("normals", extras.normals.as_deref().map(|v| (v, 3)), n),
        ("colours", colors(&extras.colors), n),
        ("texture coordinates", extras.texcoords.as_deref().map(|v| (v, 2)), n),
        ("face colours", colors(&extras.face_colors), nf),
    ];
    for (what, column, count) in columns {
        let Some((values, dim)) = column else { continue };
        if what.ends_with("colours") && !(3..=4).contains(&dim) {
            return Err(invalid(format!("{what} of {dim} numbers (3 or 4)")));
        }
        if values.len() != dim * count {
            return Err(invalid(format!(
                "{} numbers of {what} for {count} × {dim}",
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|x| !x.is_finite()) {
            return Err(invalid(format!("{what}: number {i} is not finite")));
        }
    }
    let keyword = [
        (extras.texcoords.is_some(), "ST"),
        (extras.colors.is_some(), "C"),
        (extras.normals.is_some(), "N"),
    ];
    let mut header = Vec::new();
    for (has, prefix) in keyword {
        if has {
            header.extend_from_slice(prefix.as_bytes());
        }
    }
    writeln!(header, "OFF\n{n} {nf} 0")?;
    w.write_all(&header)?;
    // Each kind of line on both cores ([`write_numbered_lines`]), in order.
    write_numbered_lines(w, n, |i, line| {
        let mut num = zmij::Buffer::new();
        push_xyz(line, &mut num, &positions[i]);
        if let Some(normals) = &extras.normals {
            push_numbers(line, &mut num, &normals[3 * i..3 * i + 3]);
        }
        if let Some(c) = &extras.colors {
            push_color(line, &mut num, c, i);
        }
        if let Some(st) = &extras.texcoords {
            push_numbers(line, &mut num, &st[2 * i..2 * i + 2]);
        }
        line.push(b'\n');
    })?;
    write_numbered_lines(w, nf, |f, line| {
        push_face(line, b'3', &triangles[f], 0);
        if let Some(c) = &extras.face_colors {
            push_color(line, &mut zmij::Buffer::new(), c, f);
        }
        line.push(b'\n');
    })?;
    w.flush()
}

/// Appends " a b ..." in shortest round-trip form (the numbers are finite).
fn push_numbers(line: &mut Vec<u8>, num: &mut zmij::Buffer, values: &[f64]) {
    for &x in values {
        line.push(b' ');
        line.extend_from_slice(num.format_finite(x).as_bytes());
    }
}

/// Appends `" r g b [a]"`, colour `i` of `c`.
fn push_color(line: &mut Vec<u8>, num: &mut zmij::Buffer, c: &OffColors, i: usize) {
    for &x in &c.values[c.dim * i..c.dim * (i + 1)] {
        line.push(b' ');
        match c.text {
            // (`as` saturates; the values are finite.)
            ColorText::Bytes => push_decimal(line, u64::from(color_byte(x))),
            ColorText::Floats => {
                let text = num.format_finite(x);
                // A float as a float: with a point (1.0, 1.0e-5).
                match text.find(['.', 'e', 'E']) {
                    Some(at) if text.as_bytes()[at] == b'.' => line.extend_from_slice(text.as_bytes()),
                    Some(at) => {
                        line.extend_from_slice(&text.as_bytes()[..at]);
                        line.extend_from_slice(b".0");
                        line.extend_from_slice(&text.as_bytes()[at..]);
                    }
                    None => {
                        line.extend_from_slice(text.as_bytes());
                        line.extend_from_slice(b".0");
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_lines_read_in_one_scan_as_the_general_way_reads_them() {
        // Files near the plain forms: OFF, NOFF and COFF headers, lines of
        // plain numbers, some with a word or a blank swapped for an odd
        // piece (signs, exponents, Windows' specials, comments, counts below
        // 3, indices beyond 2^32, 11 digits), numbers missing or left over
        // (face colours), blank and comment lines, CRLF line ends.
        let pick = |rng: &mut crate::test_rng::Rng, from: &[&'static str]| from[rng.below(from.len() as u64) as usize];
        let mut rng = crate::test_rng::Rng(0x0ff_5ca9);
        let (mut read, mut refused) = (0, 0);
        for _ in 0..6000 {
            let (nv, nf) = (1 + rng.below(6), rng.below(6));
            let keyword = pick(&mut rng, &["OFF", "OFF", "OFF", "NOFF", "COFF", ""]);
            let extra = match keyword {
                "NOFF" => 3,
                "COFF" => 3,
                _ => 0,
            };
            let line_end = pick(&mut rng, &["\n", "\n", "\r\n", " \n", "\t\n"]);
            let mut text = format!("{keyword}{line_end}{nv} {nf} 0{line_end}");
            let line = |rng: &mut crate::test_rng::Rng, words: Vec<String>, text: &mut String| {
                if rng.below(20) == 0 {
                    text.push_str(pick(rng, &["\n", "# comment\n", "  \n"]));
                }
                push_odd_line(rng, words, text, line_end, (10, true, false));
            };
            for _ in 0..nv {
                let n = 3 + extra;
                let words = (0..n)
                    .map(|_| pick(&mut rng, &["0.25", "-1.5", "3", "12.0625", "0"]).to_string())
                    .collect();
                line(&mut rng, words, &mut text);
            }
            for _ in 0..nf {
                // (Sometimes a face of 2: refused, whichever way it is read.)
                let n = if rng.below(8) == 0 { 2 } else { 3 + rng.below(3) };
                let mut words = vec![n.to_string()];
                words.extend((0..n).map(|_| rng.below(nv).to_string()));
                if rng.below(6) == 0 {
                    words.extend(["255", "0", "0"].map(String::from));
                }
                line(&mut rng, words, &mut text);
            }
            if read_alike(&text, read_off_with) {
                read += 1;
            } else {
                refused += 1;
            }
        }
        // Both outcomes are exercised, not only one.
        assert!(read > 1000 && refused > 1000, "{read} read, {refused} refused");
    }

    #[test]
    fn lines_formatted_ahead_give_the_same_file() {
        // The CLI formats the input's vertex lines while refining; the
        // refined mesh has more vertices after them. Enough lines for the
        // writer's threads (2^15 and more); OBJ's lines are not taken.
        let n = 40_000u32;
        let positions: Vec<[f64; 3]> = (0..n)
            .map(|i| [i as f64 / 3.0, -0.1 * i as f64, 1e-300 * i as f64])
            .collect();
        let triangles: Vec<[u32; 3]> = (0..n - 2).map(|i| [i, i + 1, i + 2]).collect();
        let mut whole = Vec::new();
        write_off(&mut whole, &positions, &triangles).unwrap();
        let back = read_off(&whole).unwrap();
        assert!(back.positions == positions);
        let corners: Vec<u32> = triangles.iter().flatten().copied().collect();
        assert_eq!(back.indices, corners);
        // Line by line: the header, `x y z` in shortest round-trip form,
        // `3 i j k`.
        let mut num = zmij::Buffer::new();
        let mut expected = format!("OFF\n{n} {} 0\n", n - 2);
        for p in &positions {
            let xyz: Vec<String> = p.iter().map(|&c| num.format_finite(c).to_string()).collect();
            expected += &xyz.join(" ");
            expected.push('\n');
        }
        for t in &triangles {
            expected += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
        }
        assert!(whole == expected.as_bytes());
        for ahead in [0, 1, 20, 33_000, n as usize] {
            for done in [
                VertexLines::new(&positions[..ahead], Format::Off),
                VertexLines::new(&positions[..ahead], Format::Obj),
            ] {
                let mut after = Vec::new();
                write_off_after(&mut after, &done, &positions, &triangles).unwrap();
                assert!(after == whole, "{ahead} lines formatted ahead");
            }
        }
    }
}
