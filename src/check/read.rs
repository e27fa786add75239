//! Reading a file for the judge: its own OBJ reader (and the construction's format readers for
//! OFF, PLY and STL, as raw polygons), triangulating and welding by position.

use super::*;

/// A mesh read with identical positions welded (-0 and 0 alike), before any welding is undone.
pub(super) struct Welded {
    /// The mesh.
    pub(super) mesh: Mesh3,
    /// The file's own vertex of each corner of its triangles, and what else it says of them.
    pub(super) file_corners: FileVertices,
    /// The positions of its vertices that no face uses (in file order, each once).
    pub(super) strays: Vec<DVec3>,
    /// How the file numbers the mesh's vertices and faces.
    pub(super) naming: Naming,
}

/// The file's own vertices of a [`Welded`] mesh: which one each corner of its triangles is,
/// and, for a file that gives a vertex one record per attribute value (OFF and PLY with
/// texture coordinates, normals, colours or other vertex properties), a hash of each one's
/// values, which tells seam copies (whose values differ) from copies at a cut.
pub(super) struct FileVertices {
    /// The file vertex of each corner of the mesh's triangles.
    pub(super) corners: Vec<[u32; 3]>,
    /// A hash of each file vertex's attribute values; empty where the file gives none, or is
    /// not an OFF or PLY file.
    pub(super) looks: Vec<u64>,
}

impl FileVertices {
    /// Whether the file vertices `a` and `b`, at one position, may be copies of one vertex
    /// that a seam made: the same vertex, or two with different attribute values.
    pub(super) fn seam_copies(&self, a: u32, b: u32) -> bool {
        a == b || (!self.looks.is_empty() && self.looks[a as usize] != self.looks[b as usize])
    }
}

/// A hash of each vertex's attribute values in `raw` (the first corner's, per channel; a
/// vertex of OFF or PLY has one); empty when `raw` has none.
fn attribute_looks(raw: &RawMesh) -> Vec<u64> {
    use std::hash::Hasher;
    let channels: Vec<&crate::attributes::Channel> = raw.attributes.channels().map(|(_, c)| c).collect();
    if channels.is_empty() && raw.colors.is_none() {
        return Vec::new();
    }
    let mut first_corner = vec![u32::MAX; raw.positions.len()];
    for (c, &v) in raw.indices.iter().enumerate().rev() {
        first_corner[v as usize] = c as u32;
    }
    (0..raw.positions.len())
        .map(|v| {
            let mut h = crate::hash::FastHasher::default();
            if let Some(colors) = &raw.colors {
                colors[v].iter().for_each(|&x| h.write_u8(x));
            }
            let c = first_corner[v];
            if c != u32::MAX {
                for channel in &channels {
                    channel.corner(c as usize).iter().for_each(|x| h.write_u64(x.to_bits()));
                }
            }
            h.finish()
        })
        .collect()
}

/// Reads a mesh file as [`Welded`]: OBJ with [`weld_obj`]; OFF, PLY and STL (possibly
/// gzip-compressed) with the readers of [`crate::io::formats`].
pub(super) fn read_welded(path: &Path) -> Result<Welded, CheckError> {
    read_file(path, |path, bytes, format| read_welded_as(path, bytes, format, false)).map(|(welded, _)| welded)
}

/// [`read_welded`], and with `keep_raw` the file as it lists its vertices and faces too (as
/// [`read_raw`] reads it, which the weld was made from).
pub(super) fn read_welded_keeping(
    path: &Path,
    keep_raw: bool,
) -> Result<(Welded, Option<(RawMesh, bool)>), CheckError> {
    read_file(path, |path, bytes, format| {
        read_welded_as(path, bytes, format, keep_raw)
    })
}

/// A mesh file as it lists its vertices and faces, nothing welded or triangulated (for the
/// maps, which number them so: [`maps`]), and whether its faces share vertices by index (not
/// an STL, whose facets list their own corners).
pub fn read_raw(path: &Path) -> Result<(RawMesh, bool), CheckError> {
    read_file(path, |path, bytes, format| {
        let raw = match format {
            None => obj_raw(path, bytes)?,
            Some(format) => foreign_raw(path, bytes, format)?,
        };
        Ok((raw, format != Some(crate::io::formats::Format::Stl)))
    })
}

/// Reads the file `path` (inflated when compressed) with `read_as`, given its format as its
/// name or content says (OBJ when neither does); a file it cannot read is said to be of
/// another format, UTF-16 text or of another kind where it is.
fn read_file<T>(
    path: &Path,
    read_as: impl Fn(&Path, &[u8], Option<crate::io::formats::Format>) -> Result<T, CheckError>,
) -> Result<T, CheckError> {
    use crate::io::formats;
    let bytes = crate::io::read_bytes(path).map_err(|source| CheckError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let named = path.to_str().and_then(formats::format_from_name);
    let bytes = formats::gunzip_judged(&bytes, 16 << 30, named).map_err(|e| CheckError::Parse {
        path: path.to_path_buf(),
        format: "gzip",
        reason: e.to_string(),
    })?;
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let from_name = formats::format_from_name(name);
    let format = from_name.or_else(|| formats::sniff_format(&bytes));
    let read = |format| read_as(path, &bytes, format);
    read(format).map_err(|e| {
        // A file whose content is another format than its name's, and reads as that: said
        // so, as the main command says it (the named reader's reason would mislead).
        let content = formats::sniff_format(&bytes).filter(|&c| from_name.is_some_and(|n| n != c));
        // A file of another kind (a GLB, an image, binary data): said so, as the main command does.
        let foreign = formats::foreign_reason(path.to_str(), &bytes, format != Some(formats::Format::Stl));
        match (e, content) {
            (CheckError::Parse { path, format, .. }, Some(content)) if read(Some(content)).is_ok() => {
                CheckError::Parse {
                    path,
                    format,
                    reason: content.misnamed_reason(),
                }
            }
            (CheckError::Parse { path, .. } | CheckError::NoFaces { path }, _) if formats::is_utf16_text(&bytes) => {
                CheckError::Parse {
                    path,
                    format: format.map_or("OBJ", |f| f.name()),
                    reason: formats::UTF16_REASON.to_owned(),
                }
            }
            (CheckError::Parse { path, format, .. }, _) if foreign.is_some() => CheckError::Parse {
                path,
                format,
                reason: foreign.unwrap_or_default(),
            },
            (e, _) => e,
        }
    })
}

/// [`read_welded`] of the file `path`'s (inflated) `bytes`, read as `format` (OBJ if `None`).
/// With `keep_raw`, the raw mesh the weld was made from is handed back too, with whether its
/// faces share vertices by index (see [`read_raw`]).
fn read_welded_as(
    path: &Path,
    bytes: &[u8],
    format: Option<crate::io::formats::Format>,
    keep_raw: bool,
) -> Result<(Welded, Option<(RawMesh, bool)>), CheckError> {
    use crate::io::formats;
    let format = match format {
        None | Some(formats::Format::Obj) => {
            let raw = obj_raw(path, bytes)?;
            let welded = weld_obj(path, &raw)?;
            return Ok((welded, keep_raw.then_some((raw, true))));
        }
        Some(format) => format,
    };
    let parse_error = |reason: String| CheckError::Parse {
        path: path.to_path_buf(),
        format: format.name(),
        reason,
    };
    let raw = foreign_raw(path, bytes, format)?;
    // OFF and PLY share vertices between faces by index; STL has none to
    // share (every facet lists its own corners), so there its vertices are
    // only ever welded.
    let shares_vertices = format != formats::Format::Stl;
    // (OFF and PLY copy a vertex at seams.)
    let welded = weld(&raw, shares_vertices, shares_vertices)
        .map_err(parse_error)?
        .ok_or_else(|| CheckError::NoFaces {
            path: path.to_path_buf(),
        })?;
    Ok((welded, keep_raw.then_some((raw, shares_vertices))))
}

/// A file's (inflated) `bytes`, read as `format`, as the file lists its vertices and faces.
fn foreign_raw(path: &Path, bytes: &[u8], format: crate::io::formats::Format) -> Result<RawMesh, CheckError> {
    use crate::io::formats;
    match format {
        formats::Format::Obj => return obj_raw(path, bytes),
        formats::Format::Off => formats::read_off(bytes),
        formats::Format::Ply => formats::read_ply(bytes),
        formats::Format::Stl => formats::read_stl(bytes),
    }
    .map_err(|e| CheckError::Parse {
        path: path.to_path_buf(),
        format: format.name(),
        reason: e.to_string(),
    })
}

/// The file vertices of `mesh` that welding joined at one position and that are not copies a
/// seam made ([`FileVertices::seam_copies`]): how many welded vertices have such, and the first
/// `limit` of them as (welded vertex, two of its file vertices).
pub(super) fn copies_apart(mesh: &Mesh3, files: &FileVertices, limit: usize) -> (usize, Vec<(u32, u32, u32)>) {
    // Nearly every vertex has one file vertex: those with several are found in one pass, and
    // only they are looked at closer.
    let mut first = vec![u32::MAX; mesh.positions.len()];
    let mut several = vec![false; mesh.positions.len()];
    let mut any = false;
    for (t, corners) in mesh.triangles.iter().zip(&files.corners) {
        for (&v, &f) in t.iter().zip(corners) {
            let seen = &mut first[v as usize];
            if *seen == u32::MAX {
                *seen = f;
            } else if *seen != f {
                several[v as usize] = true;
                any = true;
            }
        }
    }
    if !any {
        return (0, Vec::new());
    }
    let mut pairs: Vec<(u32, u32)> = (mesh.triangles.iter().zip(&files.corners))
        .flat_map(|(t, corners)| t.iter().copied().zip(corners.iter().copied()))
        .filter(|&(v, _)| several[v as usize])
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    let (mut count, mut found) = (0, Vec::new());
    for group in pairs.chunk_by(|a, b| a.0 == b.0) {
        let apart = (0..group.len())
            .flat_map(|i| (i + 1..group.len()).map(move |j| (i, j)))
            .find(|&(i, j)| !files.seam_copies(group[i].1, group[j].1));
        if let Some((i, j)) = apart {
            count += 1;
            if found.len() < limit {
                found.push((group[i].0, group[i].1, group[j].1));
            }
        }
    }
    (count, found)
}

/// Triangulates the polygons of `raw` and welds its identical positions (-0 and 0 alike), keeping the
/// vertices some face uses in file order; `None` when it has no faces. With
/// `shares_vertices`, a corner's file vertex is its index in the file's vertex list (OFF,
/// PLY, OBJ); without (STL), its welded vertex. With `seam_copies`, [`FileVertices::looks`]
/// are found where welding joins file vertices.
pub(super) fn weld(raw: &RawMesh, shares_vertices: bool, seam_copies: bool) -> Result<Option<Welded>, String> {
    // (Sized for every position at once, as growing the table rehashes all it holds; but
    // not for STL, whose facets repeat each position about six times.)
    let mut welder = Welder::with_capacity(if shares_vertices { raw.positions.len() } else { 0 });
    let ids: Vec<u32> = raw
        .positions
        .iter()
        .map(|p| welder.insert(DVec3::from_array(*p)))
        .collect::<Result<_, _>>()?;
    // (At least one triangle per face.)
    let faces = raw.face_start.len().saturating_sub(1);
    let mut triangles = Vec::with_capacity(faces);
    // The file's own vertex of each corner, and the file's face of every triangle (a
    // polygon gives several).
    let mut file_corners = Vec::with_capacity(faces);
    let mut face_of = Vec::with_capacity(faces);
    let mut pieces = Vec::new();
    for f in 0..raw.face_start.len().saturating_sub(1) {
        let poly = &raw.indices[raw.face_start[f] as usize..raw.face_start[f + 1] as usize];
        triangulate(poly.len(), |i| raw.positions[poly[i] as usize], &mut pieces);
        for &[a, b, c] in &pieces {
            let corners = [poly[a], poly[b], poly[c]];
            triangles.push(corners.map(|v| ids[v as usize]));
            file_corners.push(if shares_vertices {
                corners
            } else {
                corners.map(|v| ids[v as usize])
            });
            face_of.push(f as u32);
        }
    }
    if triangles.is_empty() {
        return Ok(None);
    }
    let looks = if seam_copies && welder.positions.len() < raw.positions.len() {
        attribute_looks(raw)
    } else {
        Vec::new()
    };
    // Keep only used vertices, in file order (welded ids are already in first-seen order).
    let mut used = vec![false; welder.positions.len()];
    triangles.iter().flatten().for_each(|&v| used[v as usize] = true);
    // The file's (first) vertex of every welded one.
    let mut first_in_file = vec![u32::MAX; welder.positions.len()];
    for (i, &id) in ids.iter().enumerate().rev() {
        first_in_file[id as usize] = i as u32;
    }
    let (positions, file_vertex, strays, triangles) = if used.contains(&false) {
        drop_unused(welder.positions, &used, &first_in_file, triangles)
    } else {
        // (Every vertex used, as in every file delmesh writes: nothing to renumber.)
        (welder.positions, first_in_file, Vec::new(), triangles)
    };
    let naming = Naming {
        numbering: raw.numbering,
        vertex: identity_or(file_vertex),
        face: identity_or(face_of),
        vertex_origin: raw.vertex_origin.clone(),
        face_origin: raw.face_origin.clone(),
        origin_kind: raw.origin_kind,
    };
    Ok(Some(Welded {
        mesh: Mesh3 { positions, triangles },
        file_corners: FileVertices {
            corners: file_corners,
            looks,
        },
        strays,
        naming,
    }))
}

/// The welded `positions` that `used` marks, in order, with their first file vertex (of
/// `first_in_file`), the others (the strays), and the `triangles` renumbered to the former.
fn drop_unused(
    positions: Vec<DVec3>,
    used: &[bool],
    first_in_file: &[u32],
    triangles: Vec<[u32; 3]>,
) -> (Vec<DVec3>, Vec<u32>, Vec<DVec3>, Vec<[u32; 3]>) {
    let mut new_id = vec![u32::MAX; used.len()];
    let mut kept = Vec::new();
    let mut file_vertex = Vec::new();
    let mut strays = Vec::new();
    for (i, p) in positions.iter().enumerate() {
        if used[i] {
            new_id[i] = kept.len() as u32;
            kept.push(*p);
            file_vertex.push(first_in_file[i]);
        } else {
            strays.push(*p);
        }
    }
    let triangles = triangles.iter().map(|t| t.map(|v| new_id[v as usize])).collect();
    (kept, file_vertex, strays, triangles)
}

/// An OBJ file's bytes as the file lists its vertices and faces.
pub(super) fn obj_raw(path: &Path, bytes: &[u8]) -> Result<RawMesh, CheckError> {
    let parse_error = |reason: String| CheckError::Parse {
        path: path.to_path_buf(),
        format: "OBJ",
        reason,
    };
    // A UTF-8 byte order mark (some Windows exporters write one) is no
    // statement, as for the construction's readers.
    let bytes = crate::io::formats::strip_bom(bytes);
    // Lines ended by a carriage return alone (all of them, or one among line
    // feeds): refused as the construction's reader refuses them.
    if let Some((line, reason)) = crate::io::obj::lone_cr(bytes) {
        return Err(parse_error(format!("line {line}: {reason}")));
    }
    // OBJ's line continuations joined as the construction's reader joins
    // them (a shared piece of reading, like the polygon rule).
    let joined = crate::io::obj::join_continued_lines(bytes);
    if let Some(line) = first_binary_line(&joined) {
        return Err(parse_error(format!("line {line} is not text: this is not an OBJ file")));
    }
    obj_surface(&joined).map_err(parse_error)
}

/// An OBJ file's `raw` mesh (of [`obj_raw`]) welded as [`Mesh3::read_obj`] describes, before
/// any welding is undone, as [`Welded`].
pub(super) fn weld_obj(path: &Path, raw: &RawMesh) -> Result<Welded, CheckError> {
    let parse_error = |reason: String| CheckError::Parse {
        path: path.to_path_buf(),
        format: "OBJ",
        reason,
    };
    // (Texture coordinates and normals are the corners', but a colour is the vertex's: OBJ
    // copies a vertex at a colour seam.)
    let welded = weld(raw, true, true)
        .map_err(parse_error)?
        .ok_or_else(|| CheckError::NoFaces {
            path: path.to_path_buf(),
        })?;
    if let Some(i) = welded.mesh.positions.iter().position(|p| !p.is_finite()) {
        let names = Names::new("", &welded.mesh, &welded.naming);
        return Err(parse_error(format!(
            "{}{} has a non-finite coordinate",
            names.vertex_at(i as u32),
            names.vertex(i as u32)
        )));
    }
    Ok(welded)
}

/// Where the comment of an OBJ line starts (its length if none): at the
/// first `#`, except one glued to a number as Windows prints NaN and
/// infinity (`1.#QNAN`, `-1.#IND`, `1.#INF`), which stays in the number so
/// that the number is refused rather than read as 1.
fn comment_start(line: &[u8]) -> usize {
    // (A `#` is rare: search for it first, and look at its neighbours only when found.)
    let windows_special = |i: usize| {
        let rest = &line[i + 1..];
        i > 0
            && (line[i - 1].is_ascii_digit() || line[i - 1] == b'.')
            && ["INF", "IND", "QNAN", "SNAN"]
                .iter()
                .any(|w| rest.len() >= w.len() && rest[..w.len()].eq_ignore_ascii_case(w.as_bytes()))
    };
    (0..line.len())
        .find(|&i| line[i] == b'#' && !windows_special(i))
        .unwrap_or(line.len())
}

/// The surface an OBJ file describes, from its `v` and `f` lines alone: every `v` line's
/// position (`x y z`; `x y z w` divided by `w`; the colour of `x y z r g b` dropped), and
/// every `f` line's polygon of vertex indices (`7/3/2` is vertex 7; from 1, or counted back
/// from the vertices before the line when negative; a later `v` line may be named). Comments
/// (`#` anywhere on a line) and every other statement are skipped: the judge compares
/// geometry only, so texture coordinates, normals, groups and materials, and their defects,
/// are not its business (the construction drops a defective attribute with a note, and must
/// not be failed by a reader that refuses it). Numbers are read with Rust's own `f64` and
/// `i64` parsers, not the construction's.
///
/// Errors (`line N: ...`) on the first line that cannot be read: a `v` line without 3
/// numbers, of 5 or more than 6 values, or of weight 0; an `f` line of fewer than 3 corners,
/// or with an index that is not an integer, is 0, or names no vertex of the file.
fn obj_surface(bytes: &[u8]) -> Result<RawMesh, String> {
    let mut raw = RawMesh {
        numbering: Numbering::FromOne,
        origin_kind: OriginKind::Line,
        ..RawMesh::default()
    };
    raw.face_start.push(0);
    // The words of the current line (reused: no allocation per line).
    let mut words: Vec<&[u8]> = Vec::new();
    // Indices past the vertices read so far, which only the whole file can decide: (line,
    // index).
    let mut forward: Vec<(usize, i64)> = Vec::new();
    // The vertices' colours, 3 numbers each, once a `v` line has one.
    let mut colors: Option<Vec<f64>> = None;
    for (i, line) in bytes.split(|&c| c == b'\n').enumerate() {
        let line_number = i + 1;
        let separator = |c: &u8| matches!(c, b' ' | b'\t' | b'\r' | 0x0b | 0x0c);
        let statement = &line[line.iter().position(|c| !separator(c)).unwrap_or(line.len())..];
        let kind = match statement.first() {
            Some(b'v') => b'v',
            Some(b'f') => b'f',
            _ => continue,
        };
        words.clear();
        words.extend(
            statement[..comment_start(statement)]
                .split(separator)
                .filter(|w| !w.is_empty()),
        );
        let Some((&keyword, values)) = words.split_first() else {
            continue;
        };
        if keyword != [kind] {
            continue; // (`vt`, `vn`, `fo`, ...)
        }
        let error = |why: String| format!("line {line_number}: {why}");
        let vertices = raw.positions.len() as i64;
        if kind == b'v' {
            let number = |w: &[u8]| std::str::from_utf8(w).ok().and_then(|t| t.parse::<f64>().ok());
            // Nearly every line is `x y z` (or `x y z r g b`) of three numbers: each is read
            // once; any other line is judged by `vertex_syntax_error` first.
            let plain = match values {
                [x, y, z] | [x, y, z, _, _, _] => number(x).zip(number(y)).zip(number(z)),
                _ => None,
            };
            let p = match plain {
                Some(((x, y), z)) => [x, y, z],
                None => {
                    if let Some(why) = vertex_syntax_error(values, vertices + 1) {
                        return Err(error(why));
                    }
                    let mut p = [0.0; 3];
                    for (c, w) in p.iter_mut().zip(values) {
                        *c = number(w).unwrap_or(f64::NAN);
                    }
                    if values.len() == 4 {
                        let w = number(values[3]).unwrap_or(f64::NAN);
                        p = p.map(|c| c / w);
                    }
                    p
                }
            };
            raw.positions.push(p);
            raw.vertex_origin.push(line_number as u32);
            // A vertex colour (`v x y z r g b`): a vertex with two colours is written as two
            // vertices, copies at a seam that `looks` tells apart (NaN: none, or unreadable).
            if let [_, _, _, r, g, b] = values {
                let colors = colors.get_or_insert_with(|| vec![f64::NAN; 3 * (raw.positions.len() - 1)]);
                colors.extend([r, g, b].map(|w| number(w).unwrap_or(f64::NAN)));
            } else if let Some(colors) = &mut colors {
                colors.extend([f64::NAN; 3]);
            }
            continue;
        }
        if values.len() < 3 {
            let n = values.len();
            let noun = if n == 1 { "vertex" } else { "vertices" };
            return Err(error(format!("face has {n} {noun}, needs at least 3")));
        }
        for &corner in values {
            // (A corner without a vertex index, `/3`, is refused whole.)
            let vertex = corner.split(|&c| c == b'/').next().unwrap_or(&[]);
            let text = if vertex.is_empty() { corner } else { vertex };
            let index = parse_index(text);
            let resolved = match index {
                None => {
                    let why = crate::io::number::unreadable_integer(text);
                    return Err(error(format!("face index '{}' {why}", show(text))));
                }
                Some(0) => return Err(error("face index 0 (OBJ indices start at 1)".to_string())),
                Some(v) if v < 0 && vertices + v < 0 => {
                    return Err(error(format!(
                        "face index {v} is out of range (counted back from the {vertices} vertices before it)"
                    )))
                }
                Some(v) if v < 0 => vertices + v,
                Some(v) => {
                    if v > vertices {
                        forward.push((line_number, v));
                    }
                    v - 1
                }
            };
            // (An index past every vertex is refused once all are read.)
            raw.indices.push(u32::try_from(resolved).unwrap_or(u32::MAX));
        }
        let end =
            u32::try_from(raw.indices.len()).map_err(|_| error("too many face corners (more than 2^32)".into()))?;
        raw.face_start.push(end);
        raw.face_origin.push(line_number as u32);
    }
    // Indices that name a later `v` line are allowed; past the last one, not.
    let vertices = raw.positions.len() as i64;
    if let Some((line, v)) = forward.into_iter().find(|&(_, v)| v > vertices) {
        return Err(format!(
            "line {line}: face index {v} is out of range (the file has {vertices} vertices)"
        ));
    }
    if raw.face_start.len() == 1 {
        raw.face_start.clear();
    }
    if let Some(values) = colors {
        // (Each corner's value is its vertex's.)
        raw.attributes.colors = Some(Channel {
            dim: 3,
            values,
            corners: raw.indices.clone(),
        });
    }
    Ok(raw)
}

/// `text` read as an `i64`, as `str::parse` reads it (an optional sign, then decimal digits):
/// directly when it has at most 18 digits (every face index of a real file), else by `parse`.
pub(super) fn parse_index(text: &[u8]) -> Option<i64> {
    let (negative, digits) = match text.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, text),
    };
    if (1..=18).contains(&digits.len()) && digits.iter().all(u8::is_ascii_digit) {
        let value = digits.iter().fold(0, |v, &d| v * 10 + i64::from(d - b'0'));
        return Some(if negative { -value } else { value });
    }
    std::str::from_utf8(text).ok().and_then(|t| t.parse().ok())
}

/// Why the values of a `v` line (vertex `number` of the file) cannot be read, if they cannot.
fn vertex_syntax_error(values: &[&[u8]], number: i64) -> Option<String> {
    let number_of = |w: &[u8]| std::str::from_utf8(w).ok().and_then(|t| t.parse::<f64>().ok());
    if values.len() < 3 {
        return Some(format!("vertex has {} coordinates, needs 3", values.len()));
    }
    if let Some(w) = values[..3].iter().find(|w| number_of(w).is_none()) {
        let hint = crate::io::formats::decimal_comma_hint(w);
        return Some(format!("vertex coordinate '{}' is not a number{hint}", show(w)));
    }
    match values.len() {
        3 | 6 => None,
        4 => match number_of(values[3]) {
            None => Some(format!("vertex weight '{}' is not a number", show(values[3]))),
            Some(0.0) => Some(format!("vertex {number} has weight 0 (x y z are divided by it)")),
            Some(_) => None,
        },
        n => Some(format!(
            "vertex line has {n} values: expected x y z, x y z w or x y z r g b"
        )),
    }
}

/// The first line (from 1) whose statement, before any comment, holds
/// bytes that are not UTF-8, unless it names a group, object or material
/// (old exporters write Latin-1 names): the construction's reader refuses
/// such a file as not text (a binary file, UTF-16 with its byte order
/// mark), where reading only its `v` and `f` lines would find no faces in
/// it, or lose the lines it cannot read. (The same rule as that reader's:
/// the judge must read every file the construction reads.)
fn first_binary_line(bytes: &[u8]) -> Option<usize> {
    if std::str::from_utf8(bytes).is_ok() {
        return None; // (every file delmesh writes: one fast pass)
    }
    bytes
        .split(|&b| b == b'\n')
        .position(|line| {
            // (Cut at the first `#`, as that reader cuts.)
            let code = line.split(|&b| b == b'#').next().unwrap_or(&[]);
            let text = std::str::from_utf8(code).is_ok();
            let keyword = code
                .split(|c| matches!(c, b' ' | b'\t' | b'\r' | 0x0b | 0x0c))
                .find(|w| !w.is_empty());
            !text && !matches!(keyword, Some(b"g" | b"o" | b"usemtl" | b"mtllib"))
        })
        .map(|i| i + 1)
}

/// Welds positions by their bit patterns while models are appended: an open-addressing table
/// (linear probing, at most half full) of indices into `positions`, whose bits are the keys.
/// Four bytes a slot stay in cache far better than a map holding the 24-byte keys, where
/// inserting a million positions was mostly waiting for memory.
struct Welder {
    pub(super) positions: Vec<DVec3>,
    /// Indices into `positions`, or [`Welder::EMPTY`]; a power of two long.
    slots: Vec<u32>,
}

impl Welder {
    /// An unused slot.
    const EMPTY: u32 = u32::MAX;

    /// A welder with room for `n` positions.
    pub(super) fn with_capacity(n: usize) -> Welder {
        Welder {
            positions: Vec::with_capacity(n),
            slots: vec![Self::EMPTY; (2 * n).next_power_of_two().max(16)],
        }
    }

    /// Returns the welded index of `p`, adding it if new.
    pub(super) fn insert(&mut self, p: DVec3) -> Result<u32, String> {
        let next = u32::try_from(self.positions.len())
            .ok()
            .filter(|&next| next != Self::EMPTY)
            .ok_or_else(|| "too many vertices (more than 2^32)".to_string())?;
        if 2 * (self.positions.len() + 1) > self.slots.len() {
            self.grow();
        }
        let key = bits(p);
        let mask = self.slots.len() - 1;
        let mut i = position_hash(key) as usize & mask;
        loop {
            match self.slots[i] {
                Self::EMPTY => {
                    self.slots[i] = next;
                    self.positions.push(p);
                    return Ok(next);
                }
                s if bits(self.positions[s as usize]) == key => return Ok(s),
                _ => i = (i + 1) & mask,
            }
        }
    }

    /// Doubles the table, placing every position again.
    fn grow(&mut self) {
        self.slots = vec![Self::EMPTY; 2 * self.slots.len()];
        let mask = self.slots.len() - 1;
        for (k, p) in self.positions.iter().enumerate() {
            let mut i = position_hash(bits(*p)) as usize & mask;
            while self.slots[i] != Self::EMPTY {
                i = (i + 1) & mask;
            }
            self.slots[i] = k as u32;
        }
    }
}

/// A well-mixed hash of a position's bits (every bit of the key moves the low bits).
fn position_hash(key: [u64; 3]) -> u64 {
    let h = key[0].wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ key[1].wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ key[2].wrapping_mul(0x1656_67B1_9E37_79F9);
    let h = (h ^ (h >> 31)).wrapping_mul(0xD6E8_FEB8_6659_FD93);
    h ^ (h >> 32)
}
