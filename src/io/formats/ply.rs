//! Reading and writing PLY (ASCII and binary, both byte orders), with vertex
//! and face properties.

use super::*;
use crate::io::lines::{push_decimal, push_face, write_numbered_lines};
use crate::io::number::unreadable_integer;
use std::sync::atomic::{AtomicBool, Ordering};

/// A PLY scalar type: the attributes' [`ValueType`], which a carried
/// property keeps.
type Scalar = ValueType;

/// What reading a PLY file asks of its types.
impl ValueType {
    fn from_name(name: &str) -> Option<Scalar> {
        Some(match name.to_ascii_lowercase().as_str() {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn is_float(self) -> bool {
        !self.is_integer()
    }

    /// The type's name in messages (PLY's own; a header may use the sized
    /// alias, `uint8` for `uchar`, which the range in the message shows).
    fn name(self) -> &'static str {
        self.ply_name()
    }

    /// The least and greatest values of an integer type; `None` for floats.
    fn int_range(self) -> Option<(i64, i64)> {
        Some(match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
            Scalar::U8 => (0, u8::MAX.into()),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
            Scalar::U16 => (0, u16::MAX.into()),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
            Scalar::U32 => (0, u32::MAX.into()),
            Scalar::F32 | Scalar::F64 => return None,
        })
    }

    /// Why the integer `n`, read from text, does not fit this integer type,
    /// if it does not.
    fn int_misfit(self, n: i64) -> Option<String> {
        let (lo, hi) = self.int_range()?;
        (n < lo || n > hi).then(|| self.misfit_text())
    }

    /// Why `x`, read from text, does not fit this type, if it does not: an
    /// integer type holds only integers within its range, and `float` only
    /// values within its range (beyond it, one stored as `float` would be
    /// infinite; below, it is kept as written, as every value is). A value
    /// that is not finite is left to the caller, which refuses it as such.
    fn misfit(self, x: f64) -> Option<String> {
        if !x.is_finite() {
            return None;
        }
        let fits = match self.int_range() {
            Some((lo, hi)) => x.fract() == 0.0 && x >= lo as f64 && x <= hi as f64,
            None => self == Scalar::F64 || (x as f32).is_finite(),
        };
        (!fits).then(|| self.misfit_text())
    }

    /// The end of a message about a value that does not fit this type.
    fn misfit_text(self) -> String {
        match self.int_range() {
            Some((lo, hi)) => format!(
                "does not fit its declared type {} (an integer from {lo} to {hi})",
                self.name()
            ),
            None => format!(
                "does not fit its declared type {} (beyond ±{:e})",
                self.name(),
                f32::MAX
            ),
        }
    }
}

/// A binary scalar as f64; `s.len() == t.size()`.
fn get_f64(t: Scalar, s: &[u8], big: bool) -> f64 {
    match t {
        Scalar::F32 => f64::from(decode!(f32, s, big)),
        Scalar::F64 => decode!(f64, s, big),
        _ => get_int(t, s, big) as f64,
    }
}

/// A binary scalar as i64 (floats truncated); `s.len() == t.size()`.
fn get_int(t: Scalar, s: &[u8], big: bool) -> i64 {
    match t {
        Scalar::I8 => i64::from(decode!(i8, s, big)),
        Scalar::U8 => i64::from(decode!(u8, s, big)),
        Scalar::I16 => i64::from(decode!(i16, s, big)),
        Scalar::U16 => i64::from(decode!(u16, s, big)),
        Scalar::I32 => i64::from(decode!(i32, s, big)),
        Scalar::U32 => i64::from(decode!(u32, s, big)),
        Scalar::F32 => decode!(f32, s, big) as i64,
        Scalar::F64 => decode!(f64, s, big) as i64,
    }
}

/// A colour channel: integers as read (clamped; 16-bit scaled), floats 0..1 scaled to 0..255.
fn color_channel(v: f64, t: Scalar) -> u8 {
    let v = match t {
        Scalar::F32 | Scalar::F64 => v * 255.0,
        Scalar::U16 => v / 257.0,
        _ => v,
    };
    // `as` saturates and maps NaN to 0.
    v.round().clamp(0.0, 255.0) as u8
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PropType {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct PlyProperty {
    name: String,
    ty: PropType,
    /// The header line declaring it (1-based), for messages.
    line: u64,
}

#[derive(Debug)]
struct PlyElement {
    name: String,
    count: u64,
    props: Vec<PlyProperty>,
    line: u64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PlyEncoding {
    Ascii,
    Binary { big: bool },
}

struct PlyHeader {
    encoding: PlyEncoding,
    elements: Vec<PlyElement>,
    /// The names of `comment TextureFile NAME` lines (MeshLab's), in order.
    texture_files: Vec<String>,
    /// Offset of the first data byte.
    data_start: usize,
    /// Line of the first data byte.
    data_line: u64,
}

/// What a property is read for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    Skip,
    Coord(usize),
    /// Red, green, blue (0–2) or alpha (3).
    Color(usize),
    TexCoord(usize),
    Normal(usize),
    Indices,
    /// A triangle strip's vertices (`element tristrips`), -1 ending a strip.
    StripIndices,
    /// A face's texture coordinates, two per corner (MeshLab's wedge
    /// texture coordinates: `property list uchar float texcoord`).
    WedgeTexCoords,
    /// Which of the `TextureFile`s a face's texture coordinates are in.
    TexNumber,
    /// Another vertex property, carried: column `.0` of
    /// [`VertexChannels::properties`].
    Property(usize),
    /// A face property, carried: column `.0` of
    /// [`VertexChannels::face_properties`].
    FaceProperty(usize),
}

/// The names of the vertex properties that have roles of their own (or are
/// part of one: a colour without its blue).
const KNOWN_VERTEX_PROPERTIES: &[&str] = &[
    "x",
    "y",
    "z",
    "red",
    "green",
    "blue",
    "alpha",
    "diffuse_red",
    "diffuse_green",
    "diffuse_blue",
    "diffuse_alpha",
    "u",
    "v",
    "s",
    "t",
    "texture_u",
    "texture_v",
    "texture_s",
    "texture_t",
    "nx",
    "ny",
    "nz",
];

/// The names of the face properties that have roles of their own.
const KNOWN_FACE_PROPERTIES: &[&str] = &["vertex_indices", "vertex_index", "texcoord", "texcoords", "texnumber"];

/// Gives each scalar property of the vertex or face element `el` that
/// nothing else reads a role of its own (a column of `columns`), so that
/// it is carried to the output: MeshLab's `quality` and `flags`, a scan's
/// `confidence`, face colours, a segmentation's labels. Returns a note on
/// what of the element is left out: lists, a name used twice, a known name
/// without its partners (`red` without `green`), vertex properties beyond
/// [`MAX_VERTEX_PROPERTIES`], and other elements' records.
fn carried_properties(
    el: &PlyElement,
    kind: ElementKind,
    roles: &mut [Role],
    columns: &mut Vec<PropertyColumn>,
) -> Option<String> {
    if kind == ElementKind::Other {
        return (el.count > 0 && !el.props.is_empty()).then(|| {
            format!(
                "element {} ({} record{}) left out: delmesh reads vertices and faces",
                el.name,
                el.count,
                if el.count == 1 { "" } else { "s" }
            )
        });
    }
    let known = match kind {
        ElementKind::Vertex => KNOWN_VERTEX_PROPERTIES,
        _ => KNOWN_FACE_PROPERTIES,
    };
    // (Counted once: a header may declare very many properties.)
    let mut declared: FastMap<&str, usize> = FastMap::default();
    for p in &el.props {
        *declared.entry(p.name.as_str()).or_default() += 1;
    }
    let (mut lists, mut twice, mut partial, mut beyond) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut unwritable = Vec::new();
    for (i, p) in el.props.iter().enumerate() {
        if roles[i] != Role::Skip {
            continue;
        }
        let unique = declared[p.name.as_str()] == 1;
        match p.ty {
            PropType::Scalar(_) if !ply_name_is_one_word(&p.name) => unwritable.push(p.name.as_str()),
            // Vertex properties are numbered by `Kind::Property`'s u16.
            PropType::Scalar(_)
                if unique
                    && !known.contains(&p.name.as_str())
                    && kind == ElementKind::Vertex
                    && columns.len() >= MAX_VERTEX_PROPERTIES =>
            {
                beyond.push(p.name.as_str())
            }
            PropType::Scalar(ty) if unique && !known.contains(&p.name.as_str()) => {
                roles[i] = match kind {
                    ElementKind::Vertex => Role::Property(columns.len()),
                    _ => Role::FaceProperty(columns.len()),
                };
                columns.push(PropertyColumn {
                    name: p.name.clone(),
                    ty,
                    values: Vec::new(),
                    defect: None,
                });
            }
            // MeshLab's texture number goes with its texture coordinates;
            // other faces' lists than the corners and texture coordinates.
            PropType::Scalar(_) if p.name == "texnumber" => {}
            PropType::List { .. } => lists.push(p.name.as_str()),
            PropType::Scalar(_) if !unique => twice.push(p.name.as_str()),
            PropType::Scalar(_) => partial.push(p.name.as_str()),
        }
    }
    // Each name once, in the header's order.
    let mut seen = std::collections::HashSet::new();
    twice.retain(|name| seen.insert(*name));
    let said = |names: &[&str], why: &str| {
        let named = crate::attributes::properties_named(&el.name, names).unwrap_or_default();
        format!("{named} left out: {why}")
    };
    let mut notes = Vec::new();
    if !lists.is_empty() {
        notes.push(said(&lists, "delmesh carries single numbers, not lists"));
    }
    if !twice.is_empty() {
        notes.push(said(
            &twice,
            if twice.len() == 1 {
                "it is declared twice"
            } else {
                "each is declared twice"
            },
        ));
    }
    if !partial.is_empty() {
        notes.push(said(
            &partial,
            "part of a colour, texture coordinates or normal without the rest",
        ));
    }
    if let Some(first) = unwritable.first() {
        notes.push(format!(
            "{} {} propert{} left out ({first:?}{}): a property name must be one word, without control characters",
            unwritable.len(),
            el.name,
            if unwritable.len() == 1 { "y" } else { "ies" },
            if unwritable.len() > 1 { " and others" } else { "" }
        ));
    }
    if let Some(first) = beyond.first() {
        notes.push(format!(
            "{} more {} propert{} left out (from {first} on): delmesh carries at most {MAX_VERTEX_PROPERTIES}",
            beyond.len(),
            el.name,
            if beyond.len() == 1 { "y" } else { "ies" }
        ));
    }
    (!notes.is_empty()).then(|| notes.join("; "))
}

/// The values of a carried vertex or face property, as they are read.
#[derive(Clone, Debug)]
struct PropertyColumn {
    name: String,
    ty: Scalar,
    /// One per vertex or face.
    values: Vec<f64>,
    /// The first defect (in ASCII data: a value that is no number, or does
    /// not fit its type): the property is dropped, with a note.
    defect: Option<String>,
}

impl PropertyColumn {
    /// The column, if it can be carried: one with a defect or a value that
    /// is not finite is dropped, with a note in `notes` (`element`:
    /// `vertex` or `face`).
    fn carried(self, element: &str, notes: &mut Vec<String>) -> Option<Self> {
        let why = match &self.defect {
            Some(defect) => defect.clone(),
            None if self.values.iter().any(|x| !x.is_finite()) => format!("a {element} has a non-finite value"),
            None => return Some(self),
        };
        notes.push(format!("{element} property {} dropped: {why}", self.name));
        None
    }

    /// Appends a value read as `value`; a defect (`Err(what)`, on `line`)
    /// is noted, and a NaN takes the value's place.
    fn push(&mut self, value: Result<f64, String>, line: u64) {
        match value {
            Ok(x) => self.values.push(x),
            Err(what) => {
                self.defect.get_or_insert_with(|| format!("line {line}: {what}"));
                self.values.push(f64::NAN);
            }
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ElementKind {
    Vertex,
    Face,
    /// Triangle strips (`element tristrips`): each strip's triangles are
    /// faces, after those read before.
    Strips,
    Other,
}

/// The first word of a header line, before it must be text.
fn first_word(line: &[u8]) -> &[u8] {
    words(line).next().unwrap_or(b"")
}

fn parse_ply_header(bytes: &[u8]) -> Result<PlyHeader, FormatError> {
    let mut pos = 0usize;
    let mut line = 0u64;
    let mut encoding = None;
    let mut elements: Vec<PlyElement> = Vec::new();
    let (mut seen_vertex, mut seen_face) = (false, false);
    let mut texture_files = Vec::new();
    loop {
        if pos >= bytes.len() {
            return Err(FormatError::at(line, "the PLY header has no end_header line"));
        }
        let rest = &bytes[pos..];
        let end = rest.iter().position(|&c| c == b'\n').unwrap_or(rest.len());
        let raw = &rest[..end];
        pos += (end + 1).min(rest.len());
        line += 1;
        if lone_cr_line(raw).is_some() {
            return Err(FormatError::at(line, LONE_CR));
        }
        if line == 1 {
            if !is_ply_magic(raw) {
                return Err(FormatError::at(1, "not a PLY file: the first line is not `ply`"));
            }
            continue;
        }
        let keyword = first_word(raw);
        if keyword == b"comment" {
            texture_files.extend(texture_file(raw));
            continue;
        }
        if keyword == b"obj_info" || keyword.is_empty() {
            continue;
        }
        let text = std::str::from_utf8(raw)
            .map_err(|_| FormatError::at(line, "the PLY header line is not text (missing end_header?)"))?;
        let mut ws = text
            .split(|c: char| u8::try_from(c).is_ok_and(is_space))
            .filter(|w| !w.is_empty())
            .skip(1);
        let mut word = |what: &str| {
            ws.next()
                .ok_or_else(|| FormatError::at(line, format!("the PLY header line lacks the {what}")))
        };
        match keyword {
            b"format" => {
                let name = word("format name")?;
                encoding = Some(match name {
                    "ascii" => PlyEncoding::Ascii,
                    "binary_little_endian" => PlyEncoding::Binary { big: false },
                    "binary_big_endian" => PlyEncoding::Binary { big: true },
                    other => {
                        return Err(FormatError::at(
                            line,
                            format!("unknown PLY format `{}`", show(other.as_bytes())),
                        ));
                    }
                });
            }
            b"element" => {
                let name = word("element name")?.to_owned();
                let count = word("element count")?;
                let count = count.parse::<u64>().map_err(|_| {
                    FormatError::at(
                        line,
                        format!(
                            "PLY element {} count `{}` is not a non-negative integer",
                            show(name.as_bytes()),
                            show(count.as_bytes())
                        ),
                    )
                })?;
                let twice = match name.as_str() {
                    "vertex" => std::mem::replace(&mut seen_vertex, true),
                    "face" => std::mem::replace(&mut seen_face, true),
                    _ => false,
                };
                if twice {
                    return Err(FormatError::at(
                        line,
                        format!("the PLY header declares element {name} twice"),
                    ));
                }
                elements.push(PlyElement {
                    name,
                    count,
                    props: Vec::new(),
                    line,
                });
            }
            b"property" => {
                let ty_name = word("property type")?;
                let ty = if ty_name == "list" {
                    let count = word("list count type")?;
                    let item = word("list item type")?;
                    let count = scalar_type(count, line)?;
                    if count.is_float() {
                        return Err(FormatError::at(line, "a PLY list count type must be an integer type"));
                    }
                    PropType::List {
                        count,
                        item: scalar_type(item, line)?,
                    }
                } else {
                    PropType::Scalar(scalar_type(ty_name, line)?)
                };
                let name = word("property name")?.to_owned();
                let Some(element) = elements.last_mut() else {
                    return Err(FormatError::at(line, "a PLY property comes before any element"));
                };
                element.props.push(PlyProperty { name, ty, line });
            }
            b"end_header" => break,
            other => {
                return Err(FormatError::at(
                    line,
                    format!("unknown PLY header keyword `{}`", show(other)),
                ));
            }
        }
    }
    let encoding = encoding.ok_or_else(|| FormatError::at(line, "the PLY header has no format line"))?;
    Ok(PlyHeader {
        encoding,
        elements,
        texture_files,
        data_start: pos,
        data_line: line + 1,
    })
}

/// The name in a `comment TextureFile NAME` header line (the rest of the
/// line, as MeshLab writes and reads it), if it is one.
fn texture_file(line: &[u8]) -> Option<String> {
    let line = std::str::from_utf8(line).ok()?.trim_end_matches(['\r', '\n']);
    let rest = line.trim_start().strip_prefix("comment")?.trim_start();
    let name = rest.strip_prefix("TextureFile")?;
    // (A space after the keyword, not `TextureFiles`.)
    let name = name.strip_prefix(|c: char| c.is_ascii_whitespace())?.trim();
    (!name.is_empty()).then(|| name.to_owned())
}

fn scalar_type(name: &str, line: u64) -> Result<Scalar, FormatError> {
    Scalar::from_name(name)
        .ok_or_else(|| FormatError::at(line, format!("unknown PLY property type `{}`", show(name.as_bytes()))))
}

/// What each property of an element is read for.
fn element_roles(el: &PlyElement) -> Result<(ElementKind, Vec<Role>), FormatError> {
    let mut roles = vec![Role::Skip; el.props.len()];
    match el.name.as_str() {
        "vertex" => {
            // x y z, red green blue alpha, u v, nx ny nz.
            let mut found = [None; 12];
            for (i, p) in el.props.iter().enumerate() {
                let slot = match p.name.as_str() {
                    "x" => 0,
                    "y" => 1,
                    "z" => 2,
                    "red" | "diffuse_red" => 3,
                    "green" | "diffuse_green" => 4,
                    "blue" | "diffuse_blue" => 5,
                    "alpha" | "diffuse_alpha" => 6,
                    "u" | "s" | "texture_u" | "texture_s" => 7,
                    "v" | "t" | "texture_v" | "texture_t" => 8,
                    "nx" => 9,
                    "ny" => 10,
                    "nz" => 11,
                    _ => continue,
                };
                if found[slot].is_some() {
                    if slot < 3 {
                        return Err(FormatError::at(
                            p.line,
                            format!("the PLY vertex element has two `{}` properties", p.name),
                        ));
                    }
                    continue;
                }
                if matches!(p.ty, PropType::List { .. }) {
                    if slot < 3 {
                        return Err(FormatError::at(
                            p.line,
                            format!("PLY vertex property {} is a list", p.name),
                        ));
                    }
                    continue;
                }
                found[slot] = Some(i);
            }
            for (axis, name) in ["x", "y", "z"].iter().enumerate() {
                match found[axis] {
                    Some(i) => roles[i] = Role::Coord(axis),
                    None => {
                        return Err(FormatError::at(
                            el.line,
                            format!("the PLY vertex element has no `{name}` property"),
                        ));
                    }
                }
            }
            if let [Some(r), Some(g), Some(b)] = [found[3], found[4], found[5]] {
                roles[r] = Role::Color(0);
                roles[g] = Role::Color(1);
                roles[b] = Role::Color(2);
                if let Some(a) = found[6] {
                    roles[a] = Role::Color(3);
                }
            }
            if let [Some(u), Some(v)] = [found[7], found[8]] {
                roles[u] = Role::TexCoord(0);
                roles[v] = Role::TexCoord(1);
            }
            if let [Some(x), Some(y), Some(z)] = [found[9], found[10], found[11]] {
                roles[x] = Role::Normal(0);
                roles[y] = Role::Normal(1);
                roles[z] = Role::Normal(2);
            }
            Ok((ElementKind::Vertex, roles))
        }
        "face" => {
            let list = el.props.iter().position(|p| {
                matches!(p.ty, PropType::List { .. }) && (p.name == "vertex_indices" || p.name == "vertex_index")
            });
            match list {
                Some(i) => {
                    if let PropType::List { item, .. } = el.props[i].ty {
                        if item.is_float() {
                            return Err(FormatError::at(
                                el.props[i].line,
                                format!("PLY face property {} has a non-integer item type", el.props[i].name),
                            ));
                        }
                    }
                    roles[i] = Role::Indices;
                    // MeshLab's per-face texture coordinates and texture
                    // number (the first of each name).
                    let named = |name: &[&str]| el.props.iter().position(|p| name.contains(&p.name.as_str()));
                    if let Some(k) = named(&["texcoord", "texcoords"]) {
                        if matches!(el.props[k].ty, PropType::List { .. }) {
                            roles[k] = Role::WedgeTexCoords;
                        }
                    }
                    if let Some(k) = named(&["texnumber"]) {
                        if matches!(el.props[k].ty, PropType::Scalar(_)) {
                            roles[k] = Role::TexNumber;
                        }
                    }
                    Ok((ElementKind::Face, roles))
                }
                None if el.count == 0 => Ok((ElementKind::Other, roles)),
                None => Err(FormatError::at(
                    el.line,
                    "the PLY face element has no vertex_indices list property",
                )),
            }
        }
        "tristrips" if el.count > 0 => {
            let list =
                (el.props.iter()).position(|p| matches!(p.ty, PropType::List { .. }) && p.name == "vertex_indices");
            match list.map(|i| (i, el.props[i].ty)) {
                Some((i, PropType::List { item, .. })) if !item.is_float() => {
                    roles[i] = Role::StripIndices;
                    Ok((ElementKind::Strips, roles))
                }
                Some((i, _)) => Err(FormatError::at(
                    el.props[i].line,
                    "PLY tristrips property vertex_indices has a non-integer item type",
                )),
                None => Err(FormatError::at(
                    el.line,
                    "the PLY tristrips element has no vertex_indices list property",
                )),
            }
        }
        _ => Ok((ElementKind::Other, roles)),
    }
}

/// How messages call the instances of an element ("vertices", "faces", "`edge` elements").
fn plural(name: &str) -> String {
    match name {
        "vertex" => "vertices".to_owned(),
        "face" => "faces".to_owned(),
        other => format!("`{}` elements", show(other.as_bytes())),
    }
}

fn too_many(el: &PlyElement, remaining: usize) -> FormatError {
    FormatError::at(
        el.line,
        format!(
            "PLY header declares {} {} but the file has only {remaining} bytes of data left for them",
            el.count,
            plural(&el.name)
        ),
    )
}

/// Reads a PLY file: ASCII, binary little or big endian, any scalar types, x/y/z anywhere among other
/// vertex properties, optional red/green/blue, faces from the `vertex_indices` (or `vertex_index`) list;
/// other elements and properties are skipped. For ASCII data, a record's origin is the line of its first
/// value.
pub fn read_ply(bytes: &[u8]) -> Result<RawMesh, FormatError> {
    read_ply_with(bytes, true, PARALLEL_FACES_BYTES)
}

/// [`read_ply`], with the one-scan reading of plain ASCII records
/// (`plain_records`, see [`read_plain_record`]) or without it: every record
/// the general way, which the tests compare it with. With plain records,
/// ASCII data of `faces_from` bytes or more has its faces read ahead on
/// another thread where threads are allowed ([`FacesAhead`]).
fn read_ply_with(bytes: &[u8], plain_records: bool, faces_from: usize) -> Result<RawMesh, FormatError> {
    // A byte order mark (a text editor's) before `ply`, as the other readers allow.
    let bytes = strip_bom(bytes);
    if bytes.is_empty() {
        return Err(FormatError::new("the file is empty (no PLY header)"));
    }
    let header = parse_ply_header(bytes)?;
    let mut plans = Vec::with_capacity(header.elements.len());
    let mut has_vertex = false;
    let mut has_colors = false;
    let mut channels = VertexChannels::default();
    let mut left_out = Vec::new();
    let mut vertex_seen = false;
    for el in &header.elements {
        let (kind, mut roles) = element_roles(el)?;
        has_vertex |= kind == ElementKind::Vertex;
        has_colors |= roles.iter().any(|r| matches!(r, Role::Color(_)));
        if kind == ElementKind::Vertex && !vertex_seen {
            vertex_seen = true;
            channels = VertexChannels {
                wedge: std::mem::take(&mut channels.wedge),
                face_properties: std::mem::take(&mut channels.face_properties),
                ..VertexChannels::new(&roles)
            };
            left_out.extend(carried_properties(el, kind, &mut roles, &mut channels.properties));
            channels.color_type = el.props.iter().zip(&roles).find_map(|(p, r)| match (p.ty, r) {
                (PropType::Scalar(ty), Role::Color(0)) => Some(ty),
                _ => None,
            });
        } else if kind == ElementKind::Face && channels.face_properties.is_empty() {
            left_out.extend(carried_properties(el, kind, &mut roles, &mut channels.face_properties));
        } else if kind == ElementKind::Strips {
            if el.props.len() > 1 {
                left_out.push("properties of the tristrips element other than vertex_indices left out".into());
            }
        } else {
            left_out.extend(carried_properties(el, ElementKind::Other, &mut roles, &mut Vec::new()));
        }
        if kind == ElementKind::Face && roles.contains(&Role::WedgeTexCoords) {
            channels.wedge = Some(WedgeTexCoords::default());
        }
        plans.push((kind, roles));
    }
    if !has_vertex {
        return Err(FormatError::new("the PLY header declares no vertex element"));
    }
    let ascii = header.encoding == PlyEncoding::Ascii;
    let mut trailing = None;
    let mut b = Builder::new(
        if ascii { OriginKind::Line } else { OriginKind::Record },
        Numbering::FromZero,
    );
    if has_colors {
        b.m.colors = Some(Vec::new());
    }
    b.channels = channels;
    match header.encoding {
        PlyEncoding::Ascii => {
            if let Some(line) = lone_cr_line(&bytes[header.data_start..]) {
                return Err(FormatError::at(header.data_line - 1 + line, LONE_CR));
            }
            let mut tokens = Tokens::new(bytes, header.data_start, header.data_line);
            // A big file's faces, if they come last and in plain records (as
            // in nearly every big file), are read on another thread while
            // this one reads the vertices; taken only if they start where
            // the vertices turn out to end.
            let ahead =
                (plain_records && bytes.len() - header.data_start >= faces_from && crate::parallel::threads() > 1)
                    .then(|| FacesAhead::plan(&header, &plans))
                    .flatten();
            let stop = AtomicBool::new(false);
            std::thread::scope(|scope| {
                let mut ahead = ahead.and_then(|(e, form, skip)| {
                    let (el, (kind, roles)) = (&header.elements[e], &plans[e]);
                    let (data, at, stop) = (bytes, (header.data_start, header.data_line), &stop);
                    let read = move || FacesAhead::read(data, at, skip, el, roles, *kind, form, stop);
                    Some((e, crate::parallel::try_spawn(scope, read)?))
                });
                for (e, (el, (kind, roles))) in header.elements.iter().zip(&plans).enumerate() {
                    let read_ahead = ahead.take_if(|(at, _)| *at == e).map(|(_, thread)| thread);
                    let result = read_ascii_element(&mut tokens, el, roles, *kind, &mut b, plain_records, read_ahead);
                    if result.is_err() {
                        // (The thread's work is of no use now.)
                        stop.store(true, Ordering::Relaxed);
                    }
                    result?;
                }
                if let Some((_, line)) = tokens.next() {
                    trailing = Some(format!("line {line}: data"));
                }
                Ok::<_, FormatError>(())
            })?;
        }
        PlyEncoding::Binary { big } => {
            let mut reader = BinReader {
                data: bytes,
                pos: header.data_start,
                big,
            };
            for (el, (kind, roles)) in header.elements.iter().zip(&plans) {
                read_binary_element(&mut reader, el, roles, *kind, &mut b)?;
            }
            // Room for another record of the last element (a few stray
            // bytes, such as a final newline, are not worth a word).
            if let Some(last) = header.elements.iter().rev().find(|e| !e.props.is_empty()) {
                let record = min_record_size(last);
                if record > 0 && reader.remaining() as u64 >= record {
                    trailing = Some(format!("{} bytes", reader.remaining()));
                }
            }
        }
    }
    let channels = std::mem::take(&mut b.channels);
    let mut m = b.finish()?;
    channels.finish(&mut m);
    m.attribute_notes.extend(left_out);
    // The texture image goes with the texture coordinates.
    if m.attributes.texcoords.is_some() {
        m.attributes.texture_files = header.texture_files;
    }
    // Data after the declared elements is ignored, as other readers do; but
    // the header's counts may be wrong, and the mesh then has holes: said.
    if let Some(what) = trailing {
        m.notes.push(format!(
            "{what} after the elements the PLY header declares ignored (if its counts are wrong, faces are missing)"
        ));
    }
    Ok(m)
}

/// The per-vertex attributes of a PLY file, as they are read.
#[derive(Clone, Debug, Default)]
pub(super) struct VertexChannels {
    /// Texture coordinates, normals, colours: `Some` when the file has them.
    texcoords: Option<Vec<f64>>,
    normals: Option<Vec<f64>>,
    colors: Option<Vec<f64>>,
    /// Colours have an alpha.
    alpha: bool,
    /// The declared type of `red` (which a PLY output keeps if it is a
    /// float or 16-bit type).
    color_type: Option<Scalar>,
    /// The first defect of texture coordinates, normals and colours (in
    /// ASCII data: a value that is no number, or does not fit its type).
    defects: [Option<String>; 3],
    /// The faces' texture coordinates (`texcoord` lists), if the face
    /// element has them.
    wedge: Option<WedgeTexCoords>,
    /// The other vertex properties, carried.
    properties: Vec<PropertyColumn>,
    /// The face properties, carried.
    face_properties: Vec<PropertyColumn>,
}

/// The per-face (wedge) texture coordinates of a PLY file, as they are read:
/// a value per face corner, so seams are kept as in OBJ.
#[derive(Clone, Debug, Default)]
struct WedgeTexCoords {
    /// Two numbers per corner, the corners in the order of `indices`.
    values: Vec<f64>,
    /// The first defect (a value that is no number, a list whose length is
    /// not twice the face's corners): they are dropped, with a note.
    defect: Option<String>,
    /// The first face's `texnumber`, and whether another face has another.
    texnumber: Option<i64>,
    several_textures: bool,
}

impl VertexChannels {
    fn new(roles: &[Role]) -> VertexChannels {
        let has = |f: fn(&Role) -> bool| roles.iter().any(f).then(Vec::new);
        VertexChannels {
            texcoords: has(|r| matches!(r, Role::TexCoord(_))),
            normals: has(|r| matches!(r, Role::Normal(_))),
            colors: has(|r| matches!(r, Role::Color(_))),
            alpha: roles.contains(&Role::Color(3)),
            color_type: None,
            defects: Default::default(),
            wedge: None,
            properties: Vec::new(),
            face_properties: Vec::new(),
        }
    }

    /// Notes the first defect of attribute `kind`, on `line`: the
    /// attribute is dropped, with a note ([`VertexChannels::finish`]).
    fn defect(&mut self, kind: Kind, line: u64, what: impl FnOnce() -> String) {
        // (Vertex properties keep their own: [`PropertyColumn::push`].)
        let Some(i) = kind.fixed_index() else { return };
        let slot = &mut self.defects[i];
        if slot.is_none() {
            *slot = Some(format!("{} dropped: line {line}: {}", kind.name(), what()));
        }
    }

    /// Appends the attributes of one vertex.
    fn push(&mut self, v: &VertexValues) {
        if let Some(t) = &mut self.texcoords {
            t.extend_from_slice(&v.texcoord);
        }
        if let Some(n) = &mut self.normals {
            n.extend_from_slice(&v.normal);
        }
        if let Some(c) = &mut self.colors {
            c.extend_from_slice(&v.color[..if self.alpha { 4 } else { 3 }]);
        }
    }

    /// Appends the texture coordinates of the face just ended (`v.wedge`),
    /// which has `corners` corners, if the faces have them.
    fn push_face(&mut self, v: &VertexValues, corners: usize, face: usize, origin: u64, lines: bool) {
        let Some(w) = &mut self.wedge else { return };
        if w.defect.is_some() {
            return;
        }
        if let Some(n) = v.texnumber {
            w.several_textures |= w.texnumber.is_some_and(|first| first != n);
            w.texnumber.get_or_insert(n);
        }
        if let Some(why) = &v.wedge_defect {
            w.defect = Some(why.clone());
        } else if v.wedge.len() != 2 * corners {
            let at = if lines {
                format!("line {origin}: ")
            } else {
                String::new()
            };
            w.defect = Some(format!(
                "{at}face {face} has {} texcoord values for its {corners} corners (2 each)",
                v.wedge.len()
            ));
        } else {
            w.values.extend_from_slice(&v.wedge);
        }
    }

    /// Moves the attributes into `m` (per vertex: each corner takes its
    /// vertex's value; the faces' texture coordinates: each corner its own);
    /// a channel with a defect or a non-finite value is dropped with a note.
    fn finish(self, m: &mut RawMesh) {
        if let Some(w) = &self.wedge {
            wedge_finish(w, self.texcoords.is_some(), m);
        }
        let color_dim = if self.alpha { 4 } else { 3 };
        let channels = [
            (Kind::TexCoord, self.texcoords, 2),
            (Kind::Normal, self.normals, 3),
            (Kind::Color, self.colors, color_dim),
        ];
        let mut defects = self.defects.into_iter();
        for (kind, values, dim) in channels {
            let defect = defects.next().flatten();
            let Some(values) = values else { continue };
            if let Some(note) = defect {
                m.attribute_notes.push(note);
                if kind == Kind::Color {
                    m.colors = None;
                }
                continue;
            }
            if values.iter().any(|x| !x.is_finite()) {
                m.attribute_notes
                    .push(format!("{} dropped: a vertex has a non-finite one", kind.name()));
                continue;
            }
            if kind == Kind::Color {
                m.attributes.color_type = self.color_type;
            }
            *m.attributes.channel_mut(kind) = Some(Channel {
                dim,
                values,
                corners: m.indices.clone(),
            });
        }
        for p in self.properties {
            if let Some(p) = p.carried("vertex", &mut m.attribute_notes) {
                m.attributes.properties.push(VertexProperty {
                    name: p.name,
                    ty: p.ty,
                    channel: Some(Channel {
                        dim: 1,
                        values: p.values,
                        corners: m.indices.clone(),
                    }),
                });
            }
        }
        let faces = m.face_start.len().saturating_sub(1);
        for p in self.face_properties {
            if p.values.len() != faces && p.defect.is_none() {
                // The faces of triangle strips, after those of the face element, have none.
                m.attribute_notes.push(format!(
                    "face property {} left out: the faces of the triangle strips (element tristrips) have none",
                    p.name
                ));
                continue;
            }
            if let Some(p) = p.carried("face", &mut m.attribute_notes) {
                m.attributes.face_properties.push(FaceProperty {
                    name: p.name,
                    ty: p.ty,
                    values: p.values,
                });
            }
        }
    }
}

/// Moves the faces' texture coordinates `w` into `m` as a channel with a
/// value per corner, unless the vertices have texture coordinates
/// (`vertex_texcoords`: those are read), or they have a defect, a
/// non-finite value, or the faces use several textures: then with a note.
fn wedge_finish(w: &WedgeTexCoords, vertex_texcoords: bool, m: &mut RawMesh) {
    const WHAT: &str = "texture coordinates of the faces (PLY face property texcoord)";
    let why = if vertex_texcoords {
        Some("the vertices' are read instead".to_owned())
    } else if let Some(defect) = &w.defect {
        Some(defect.clone())
    } else if w.several_textures {
        Some("the faces use several textures (face property texnumber), which delmesh does not carry".to_owned())
    } else if w.values.iter().any(|x| !x.is_finite()) {
        Some("a face has a non-finite one".to_owned())
    } else if w.values.len() != 2 * m.indices.len() {
        Some("some faces have none".to_owned())
    } else {
        None
    };
    match why {
        Some(why) => m.attribute_notes.push(format!("{WHAT} dropped: {why}")),
        None => {
            m.attributes.texcoords = Some(Channel {
                dim: 2,
                values: w.values.clone(),
                corners: (0..m.indices.len() as u32).collect(),
            })
        }
    }
}

/// A colour channel in 0..1: integers scaled by their type's maximum (255
/// for all but 16-bit ones), floats as they are.
fn color_unit(v: f64, t: Scalar) -> f64 {
    match t {
        Scalar::F32 | Scalar::F64 => v,
        Scalar::U16 => v / 65535.0,
        _ => v / 255.0,
    }
}

/// The values of one vertex record.
#[derive(Default)]
struct VertexValues {
    p: [f64; 3],
    rgb: [u8; 3],
    /// Colour in 0..1 (alpha 1 unless given).
    color: [f64; 4],
    texcoord: [f64; 2],
    normal: [f64; 3],
    /// A face's texture coordinates (its `texcoord` list).
    wedge: Vec<f64>,
    /// Why they cannot be read, if so.
    wedge_defect: Option<String>,
    /// A face's `texnumber`.
    texnumber: Option<i64>,
}

impl VertexValues {
    /// Sets colour channel `c` (3: alpha) read as `value` of type `t`.
    fn set_color(&mut self, c: usize, value: f64, t: Scalar) {
        if let Some(x) = self.rgb.get_mut(c) {
            *x = color_channel(value, t);
        }
        self.color[c] = color_unit(value, t);
    }
}

#[inline]
fn finish_record(
    b: &mut Builder,
    kind: ElementKind,
    v: &VertexValues,
    i: usize,
    origin: u64,
) -> Result<(), FormatError> {
    match kind {
        ElementKind::Vertex => {
            b.vertex(v.p, origin, || format!("vertex {i}"))?;
            if let Some(colors) = &mut b.m.colors {
                colors.push(v.rgb);
            }
            b.channels.push(v);
            Ok(())
        }
        ElementKind::Face => {
            let start = b.m.face_start.last().copied().unwrap_or(0) as usize;
            let corners = b.m.indices.len() - start;
            b.end_face(origin)?;
            let lines = b.m.origin_kind == OriginKind::Line;
            b.channels.push_face(v, corners, i, origin, lines);
            Ok(())
        }
        ElementKind::Strips | ElementKind::Other => Ok(()),
    }
}

/// Appends the triangles of the strips in `indices` (-1 ends a strip) as
/// faces from `origin`: triangle k of a strip is its vertices k, k + 1,
/// k + 2, every other one reversed (so that all face one way), and those
/// that repeat a vertex (the joins and turns that strips use) left out.
/// Another negative index is refused; `strip` numbers the record.
fn push_strips(
    b: &mut Builder,
    indices: &[i64],
    strip: usize,
    origin: u64,
    line: Option<u64>,
) -> Result<(), FormatError> {
    let n = b.m.positions.len();
    if let Some(&i) = indices.iter().find(|&&i| i < -1) {
        return Err(FormatError::maybe_at(
            line,
            format!("tristrips {strip} index {i} is negative (only -1, which ends a strip, may be)"),
        ));
    }
    if let Some(&i) = indices.iter().find(|&&i| i > i64::from(u32::MAX)) {
        return Err(FormatError::maybe_at(
            line,
            format!("tristrips {strip} index {i} is out of range ({n} vertices)"),
        ));
    }
    for run in indices.split(|&i| i == -1) {
        for (k, w) in run.windows(3).enumerate() {
            let [a, c, d] = [w[0], w[1], w[2]].map(|i| i as u32);
            if a == c || c == d || a == d {
                continue;
            }
            b.start_face();
            for i in if k % 2 == 0 { [a, c, d] } else { [c, a, d] } {
                b.index(i);
            }
            b.end_face(origin)?;
        }
    }
    Ok(())
}

/// Reads the records of element `el` at the cursor `t` into `b`; those
/// that another thread has read ahead (`read_ahead`, [`FacesAhead`]) are
/// taken from it if they start where `t` is.
fn read_ascii_element(
    t: &mut Tokens,
    el: &PlyElement,
    roles: &[Role],
    kind: ElementKind,
    b: &mut Builder,
    plain_records: bool,
    read_ahead: Option<std::thread::ScopedJoinHandle<Option<FacesAhead>>>,
) -> Result<(), FormatError> {
    if el.count == 0 || el.props.is_empty() {
        return Ok(());
    }
    // Every value takes at least one character and one separator.
    let remaining = t.remaining();
    let per_record = 2 * el.props.len() as u64;
    if el.count > (remaining as u64 + 1) / per_record {
        return Err(too_many(el, remaining));
    }
    let count = el.count as usize;
    // (A panic there is a bug, raised here as the OBJ reader's tail does.)
    let joined = read_ahead.map(|thread| thread.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
    let first = match joined.flatten() {
        Some(ahead) => ahead.take(t, b),
        None => 0,
    };
    // Reserve for the shortest real records ("0 0 0\n"; faces below).
    match kind {
        _ if first > 0 => {}
        ElementKind::Vertex => b.reserve_vertices(count.min(remaining / 6 + 1)),
        ElementKind::Face => reserve_face_records(b, count, remaining),
        ElementKind::Strips | ElementKind::Other => {}
    }
    let name = &el.name;
    let plain = plain_records.then(|| PlainForm::of(el, roles, kind)).flatten();
    for i in first..count {
        if let Some(form) = plain {
            if read_plain_record(t, form, el, roles, kind, i, b)? {
                continue;
            }
        }
        let mut v = VertexValues::default();
        let mut origin = t.line;
        let start = (t.pos, t.line);
        for (k, (p, role)) in el.props.iter().zip(roles).enumerate() {
            let truncated =
                |line| FormatError::at(line, format!("the PLY data ends inside {name} {i} (truncated file?)"));
            let Some((tok, line)) = t.next() else {
                return Err(truncated(t.line));
            };
            if k == 0 {
                origin = line;
            }
            match p.ty {
                PropType::Scalar(ty) => {
                    if *role == Role::Skip {
                        continue;
                    }
                    // A number that the declared type holds; else why not.
                    let value = match parse_f64(tok) {
                        Some(x) => ty.misfit(x).map_or(Ok(x), Err),
                        None => Err(format!("is not a number{}", super::decimal_comma_hint(tok))),
                    };
                    let what = |why: String| format!("{name} {i} property {}: `{}` {why}", p.name, show(tok));
                    match (*role, value) {
                        (role, Ok(x)) => apply_value(role, x, ty, line, &mut v, b),
                        (Role::Property(j), value) => b.channels.properties[j].push(value.map_err(what), line),
                        (Role::FaceProperty(j), value) => b.channels.face_properties[j].push(value.map_err(what), line),
                        (Role::Coord(_), Err(why)) => return Err(FormatError::at(line, what(why))),
                        // A defect in an attribute drops it, with a note.
                        (Role::Color(_), Err(why)) => b.channels.defect(Kind::Color, line, || what(why)),
                        (Role::TexCoord(_), Err(why)) => b.channels.defect(Kind::TexCoord, line, || what(why)),
                        (Role::Normal(_), Err(why)) => b.channels.defect(Kind::Normal, line, || what(why)),
                        _ => {}
                    }
                }
                PropType::List { count: count_ty, item } => {
                    let n = parse_int(tok).ok_or_else(|| {
                        FormatError::at(
                            line,
                            format!("{name} {i} list {} length `{}` is not an integer", p.name, show(tok)),
                        )
                    })?;
                    if n < 0 {
                        return Err(FormatError::at(
                            line,
                            format!("{name} {i} list {} has a negative length ({n})", p.name),
                        ));
                    }
                    if let Some(why) = count_ty.int_misfit(n) {
                        return Err(FormatError::at(
                            line,
                            format!("{name} {i} list {} length `{}` {why}", p.name, show(tok)),
                        ));
                    }
                    if n as u64 > (t.remaining() as u64).div_ceil(2) {
                        return Err(FormatError::at(
                            line,
                            format!(
                                "{name} {i} list {} claims {n} entries but only {} bytes of data remain",
                                p.name,
                                t.remaining()
                            ),
                        ));
                    }
                    if *role == Role::Indices {
                        if n < 3 {
                            return Err(FormatError::at(
                                line,
                                format!("face {i} has {n} vertices (at least 3 needed)"),
                            ));
                        }
                        b.start_face();
                        for _ in 0..n {
                            let Some((tok, line)) = t.next() else {
                                return Err(truncated(t.line));
                            };
                            let index = parse_int(tok).ok_or_else(|| {
                                let why = unreadable_integer(tok);
                                FormatError::at(line, format!("face {i} index `{}` {why}", show(tok)))
                            })?;
                            let index = checked_index(index, i, Some(line), b.m.positions.len())?;
                            if let Some(why) = item.int_misfit(index.into()) {
                                return Err(FormatError::at(line, format!("face {i} index `{}` {why}", show(tok))));
                            }
                            b.index(index);
                        }
                    } else if *role == Role::StripIndices {
                        let mut strip = Vec::with_capacity(n as usize);
                        for _ in 0..n {
                            let Some((tok, line)) = t.next() else {
                                return Err(truncated(t.line));
                            };
                            let index = parse_int(tok).ok_or_else(|| {
                                let why = unreadable_integer(tok);
                                FormatError::at(line, format!("tristrips {i} index `{}` {why}", show(tok)))
                            })?;
                            // (-1 ends a strip, whatever the declared type.)
                            if let Some(why) = item.int_misfit(index).filter(|_| index != -1) {
                                return Err(FormatError::at(
                                    line,
                                    format!("tristrips {i} index `{}` {why}", show(tok)),
                                ));
                            }
                            strip.push(index);
                        }
                        push_strips(b, &strip, i, origin, Some(line))?;
                    } else if *role == Role::WedgeTexCoords {
                        v.wedge.reserve(n as usize);
                        for _ in 0..n {
                            let Some((tok, line)) = t.next() else {
                                return Err(truncated(t.line));
                            };
                            match parse_f64(tok) {
                                Some(x) => v.wedge.push(x),
                                None => {
                                    v.wedge_defect.get_or_insert_with(|| {
                                        format!("line {line}: face {i} texcoord `{}` is not a number", show(tok))
                                    });
                                }
                            }
                        }
                    } else {
                        for _ in 0..n {
                            if t.next().is_none() {
                                return Err(truncated(t.line));
                            }
                        }
                    }
                }
            }
        }
        // One record per line: values left on it mean the header declares
        // fewer properties than the lines hold (read on, every later value
        // would be taken for the wrong property). A record that went on
        // past its first line took them from the next: its line is short.
        if !t.line_is_done() {
            if t.line != origin {
                return Err(short_record(t.data, start, origin, t.pos, name, i));
            }
            return Err(FormatError::at(
                t.line,
                format!(
                    "more values on the line of {name} {i} than the PLY header declares ({} propert{})",
                    el.props.len(),
                    if el.props.len() == 1 { "y" } else { "ies" }
                ),
            ));
        }
        finish_record(b, kind, &v, i, origin)?;
    }
    Ok(())
}

/// Where a value `x` read for a property of type `ty` and role `role` goes
/// (on `line`): into the record's values `v`, or a carried property's
/// column. The one place both ways of reading ASCII records put values.
#[inline]
fn apply_value(role: Role, x: f64, ty: Scalar, line: u64, v: &mut VertexValues, b: &mut Builder) {
    match role {
        Role::Coord(axis) => v.p[axis] = x,
        Role::Color(c) => v.set_color(c, x, ty),
        Role::TexCoord(k) => v.texcoord[k] = x,
        Role::Normal(k) => v.normal[k] = x,
        Role::TexNumber => v.texnumber = Some(x as i64),
        Role::Property(j) => b.channels.properties[j].push(Ok(x), line),
        Role::FaceProperty(j) => b.channels.face_properties[j].push(Ok(x), line),
        Role::Skip | Role::Indices | Role::StripIndices | Role::WedgeTexCoords => {}
    }
}

/// The forms of element that nearly every ASCII PLY file is made of, whose
/// records [`read_plain_record`] reads in one scan each.
#[derive(Clone, Copy)]
enum PlainForm {
    /// Vertices of scalar properties only (at most [`PLAIN_VALUES`]).
    Vertex,
    /// Faces whose one property is their list of vertex indices, of at
    /// most `count_max` entries (its length type's greatest value), each at
    /// most `index_max` (its item type's greatest value, and 2^32 − 1).
    Face { count_max: i64, index_max: i64 },
}

/// The most properties a plain vertex record has (values kept on the stack
/// until the record is known to be plain).
const PLAIN_VALUES: usize = 16;

impl PlainForm {
    /// The plain form of element `el` (of `kind`, its properties' `roles`),
    /// if it has one.
    fn of(el: &PlyElement, roles: &[Role], kind: ElementKind) -> Option<PlainForm> {
        match (kind, &el.props[..], roles) {
            (ElementKind::Vertex, props, _)
                if props.len() <= PLAIN_VALUES && props.iter().all(|p| matches!(p.ty, PropType::Scalar(_))) =>
            {
                Some(PlainForm::Vertex)
            }
            (ElementKind::Face, [p], [Role::Indices]) => match p.ty {
                // (Both are non-negative here, and every type's least value
                // at most 0: `int_misfit` refuses exactly those above these.)
                PropType::List { count, item } => Some(PlainForm::Face {
                    count_max: count.int_range().map_or(i64::MAX, |r| r.1),
                    index_max: item.int_range().map_or(i64::MAX, |r| r.1).min(u32::MAX.into()),
                }),
                PropType::Scalar(_) => None,
            },
            _ => None,
        }
    }
}

/// Reads record `i` of element `el` at the cursor in one scan if it is in
/// its plain form, and says `true`; otherwise changes nothing and says
/// `false`, and the general way reads it (refusing it, if it must, with its
/// own message). Plain: on one line, followed by nothing but blanks; every
/// scalar a short decimal (see [`crate::io::number::short_decimal_prefix`])
/// that fits its declared type, or skipped; a face's length and indices
/// plain digits (at most 10), at least 3 indices, each below 2^32 and
/// fitting its type. The values, the calls on the builder and where the
/// cursor is left are those of the general way (the same number parser,
/// the same token ends).
#[inline]
fn read_plain_record(
    t: &mut Tokens,
    form: PlainForm,
    el: &PlyElement,
    roles: &[Role],
    kind: ElementKind,
    i: usize,
    b: &mut Builder,
) -> Result<bool, FormatError> {
    let d = t.data;
    // To the first token, across line ends, as `Tokens::next`.
    let (mut p, mut origin) = (t.pos, t.line);
    while p < d.len() {
        match d[p] {
            b'\n' => origin += 1,
            b' ' | b'\t' | b'\r' | 0x0b | 0x0c => {}
            _ => break,
        }
        p += 1;
    }
    // To the next token on the same line (`None` at a line end: the record
    // goes on past its line, which the general way sorts out).
    let next_on_line = |p: usize| {
        let p = skip_blanks(d, p);
        (p < d.len() && d[p] != b'\n').then_some(p)
    };
    match form {
        PlainForm::Vertex => {
            let mut values = [0.0f64; PLAIN_VALUES];
            for (k, p_ty) in el.props.iter().enumerate() {
                if k > 0 {
                    let Some(q) = next_on_line(p) else { return Ok(false) };
                    p = q;
                }
                if p == d.len() {
                    return Ok(false);
                }
                let PropType::Scalar(ty) = p_ty.ty else {
                    return Ok(false);
                };
                if roles[k] == Role::Skip {
                    while p < d.len() && !is_space(d[p]) {
                        p += 1;
                    }
                    continue;
                }
                let Some((x, len)) = crate::io::number::short_decimal_prefix(&d[p..]) else {
                    return Ok(false);
                };
                // (A short decimal always fits a float type.)
                if d.get(p + len).is_some_and(|&c| !is_space(c)) || (!ty.is_float() && ty.misfit(x).is_some()) {
                    return Ok(false);
                }
                values[k] = x;
                p += len;
            }
            if !line_is_blank(d, p) {
                return Ok(false);
            }
            let mut v = VertexValues::default();
            for (k, (p_ty, &role)) in el.props.iter().zip(roles).enumerate() {
                if let (PropType::Scalar(ty), false) = (p_ty.ty, role == Role::Skip) {
                    apply_value(role, values[k], ty, origin, &mut v, b);
                }
            }
            t.pos = p;
            t.line = origin;
            finish_record(b, kind, &v, i, origin)?;
        }
        PlainForm::Face { count_max, index_max } => {
            let Some((n, len)) = plain_digits(&d[p..]) else {
                return Ok(false);
            };
            p += len;
            // (The general way's order of checks: any of these refuses.)
            if n > count_max || n < 3 || n as u64 > ((d.len() - p) as u64).div_ceil(2) {
                return Ok(false);
            }
            let start = b.m.indices.len();
            let undo = |b: &mut Builder| {
                b.m.indices.truncate(start);
                Ok(false)
            };
            for _ in 0..n {
                let Some(q) = next_on_line(p) else { return undo(b) };
                let Some((index, len)) = plain_digits(&d[q..]) else {
                    return undo(b);
                };
                if index > index_max {
                    return undo(b);
                }
                b.index(index as u32);
                p = q + len;
            }
            if !line_is_blank(d, p) {
                return undo(b);
            }
            b.start_face();
            t.pos = p;
            t.line = origin;
            finish_record(b, kind, &NO_VALUES, i, origin)?;
        }
    }
    Ok(true)
}

/// The values of a record that has none but its face's indices.
static NO_VALUES: VertexValues = VertexValues {
    p: [0.0; 3],
    rgb: [0; 3],
    color: [0.0; 4],
    texcoord: [0.0; 2],
    normal: [0.0; 3],
    wedge: Vec::new(),
    wedge_defect: None,
    texnumber: None,
};

/// The size of ASCII PLY data from which [`read_ply`] reads the faces on
/// another thread ([`FacesAhead`]). Below it the thread's start and its
/// scan for the faces' first line would cost about what it saves.
const PARALLEL_FACES_BYTES: usize = 4 << 20;

/// The faces of an ASCII PLY file read on another thread while the reader's
/// own reads the vertices before them: the plain records ([`PlainForm`])
/// from the start of the line that follows one line per earlier record,
/// where the faces start if every earlier record takes one line. The reader
/// takes them only if its own cursor, after the earlier records, reaches
/// the same first token ([`FacesAhead::take`]); the records are then those
/// it would have read itself, the same calls on the same builder vectors
/// (they depend only on the text from that token and its line number), and
/// it reads the rest from where the thread stopped.
///
/// ```text
///   end_header
///   0.1 0.2 0.3        \
///   ...                 } N records of the earlier elements, one a line
///   0.4 0.5 0.6        /
///   3 0 1 2            <- the thread starts here (line data_line + N)
///   ...
/// ```
struct FacesAhead {
    /// The first token's position.
    start: usize,
    /// The records read (all of them, or up to the first that is not plain).
    records: usize,
    /// The cursor after them.
    end: (usize, u64),
    /// What they push on the builder's face vectors.
    indices: Vec<u32>,
    face_start: Vec<u32>,
    face_origin: Vec<u32>,
}

impl FacesAhead {
    /// Which element to read ahead, its plain form, and the number of
    /// records before it: the last element with records, if it is the one
    /// face element, of plain form, and some records come before it.
    fn plan(header: &PlyHeader, plans: &[(ElementKind, Vec<Role>)]) -> Option<(usize, PlainForm, u64)> {
        let has_records = |el: &PlyElement| el.count > 0 && !el.props.is_empty();
        let e = header.elements.iter().rposition(has_records)?;
        let (kind, roles) = &plans[e];
        let faces = plans
            .iter()
            .filter(|(k, _)| matches!(k, ElementKind::Face | ElementKind::Strips));
        if *kind != ElementKind::Face || faces.count() != 1 {
            return None;
        }
        let form = PlainForm::of(&header.elements[e], roles, *kind)?;
        let before = header.elements[..e]
            .iter()
            .filter(|el| has_records(el))
            .try_fold(0u64, |n, el| n.checked_add(el.count))?;
        (before > 0).then_some((e, form, before))
    }

    /// Reads element `el` ahead from the start of the line `skip` lines
    /// after `at` (a position and its line), as far as its records are
    /// plain; `None` if there is no such line, the first record is not
    /// plain, or `stop` is set.
    #[allow(clippy::too_many_arguments)]
    fn read(
        data: &[u8],
        at: (usize, u64),
        skip: u64,
        el: &PlyElement,
        roles: &[Role],
        kind: ElementKind,
        form: PlainForm,
        stop: &AtomicBool,
    ) -> Option<FacesAhead> {
        let from = nth_line_end(data, at.0, skip)? + 1;
        let mut t = Tokens::new(data, from, at.1 + skip);
        let start = first_token(data, from);
        let mut b = Builder::new(OriginKind::Line, Numbering::FromZero);
        // As the reader reserves (from its cursor, a few blanks earlier).
        let count = el.count as usize;
        reserve_face_records(&mut b, count, t.remaining());
        let mut records = 0;
        while records < count {
            if records % 4096 == 0 && stop.load(Ordering::Relaxed) {
                return None;
            }
            match read_plain_record(&mut t, form, el, roles, kind, records, &mut b) {
                Ok(true) => records += 1,
                Ok(false) => break,
                // (Only the faces' 2^32 indices in all: the reader says so.)
                Err(_) => return None,
            }
        }
        (records > 0).then_some(FacesAhead {
            start,
            records,
            end: (t.pos, t.line),
            indices: b.m.indices,
            face_start: b.m.face_start,
            face_origin: b.m.face_origin,
        })
    }

    /// Puts the records read ahead on `b` and moves `t` past them if they
    /// start at the first token from `t` (and `b` has no faces yet);
    /// returns how many (0: none taken).
    fn take(self, t: &mut Tokens, b: &mut Builder) -> usize {
        let m = &mut b.m;
        if first_token(t.data, t.pos) != self.start
            || !m.indices.is_empty()
            || !m.face_start.is_empty()
            || b.channels.wedge.is_some()
        {
            return 0;
        }
        (m.indices, m.face_start, m.face_origin) = (self.indices, self.face_start, self.face_origin);
        (t.pos, t.line) = self.end;
        self.records
    }
}

/// Room on `b` for `count` face records in `remaining` bytes of data, at
/// most as many as fit if they are as short as real ones can be
/// (`3 0 1 2\n`): the reader's, and [`FacesAhead::read`]'s alike.
fn reserve_face_records(b: &mut Builder, count: usize, remaining: usize) {
    b.reserve_faces(count.min(remaining / 8 + 1), count.saturating_mul(3).min(remaining / 2));
}

/// Where the first token at or after position `p` of `d` starts, across
/// line ends, as [`Tokens::next`] finds it (`d.len()` if none).
fn first_token(d: &[u8], p: usize) -> usize {
    p + d[p..].iter().position(|&c| !is_space(c)).unwrap_or(d.len() - p)
}

/// The position of the `n`th line feed (n ≥ 1) from `from` in `data`.
fn nth_line_end(data: &[u8], from: usize, n: u64) -> Option<usize> {
    let mut left = n;
    let mut at = from;
    // Whole blocks counted at once, in pieces of 128 bytes whose counts fit
    // a byte (a loop the compiler turns into vector compares: five times
    // the speed of counting with `filter`), then the one that holds it
    // searched.
    for block in data[from..].chunks(4096) {
        let here: u64 = block
            .chunks(128)
            .map(|piece| u64::from(piece.iter().fold(0u8, |n, &c| n + u8::from(c == b'\n'))))
            .sum();
        if here >= left {
            let k = block
                .iter()
                .enumerate()
                .filter(|&(_, &c)| c == b'\n')
                .nth(left as usize - 1)?
                .0;
            return Some(at + k);
        }
        left -= here;
        at += block.len();
    }
    None
}

/// The error for record `i` of element `name`, read from `start` (a
/// position and its line) to `end`, which ran past its first line `origin`
/// and left values on its last: the first line is short of values (rather
/// than the last holding too many).
fn short_record(data: &[u8], start: (usize, u64), origin: u64, end: usize, name: &str, i: usize) -> FormatError {
    let mut again = Tokens::new(data, start.0, start.1);
    let (mut on_line, mut needed) = (0, 0);
    while again.pos < end {
        let Some((_, line)) = again.next() else { break };
        on_line += usize::from(line == origin);
        needed += 1;
    }
    FormatError::at(
        origin,
        format!("{name} {i} has {on_line} values on its line, fewer than the {needed} its record needs (a short line)"),
    )
}

/// A cursor over binary PLY data.
struct BinReader<'a> {
    data: &'a [u8],
    pos: usize,
    big: bool,
}

impl<'a> BinReader<'a> {
    fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let end = self.pos.checked_add(n)?;
        let s = self.data.get(self.pos..end)?;
        self.pos = end;
        Some(s)
    }
}

fn read_binary_element(
    r: &mut BinReader,
    el: &PlyElement,
    roles: &[Role],
    kind: ElementKind,
    b: &mut Builder,
) -> Result<(), FormatError> {
    if el.count == 0 || el.props.is_empty() {
        return Ok(());
    }
    let min_size = min_record_size(el);
    let remaining = r.remaining();
    if el.count > remaining as u64 / min_size {
        return Err(too_many(el, remaining));
    }
    // The count is now bounded by the input size.
    let count = el.count as usize;
    let has_list = el.props.iter().any(|p| matches!(p.ty, PropType::List { .. }));
    if kind == ElementKind::Other && !has_list {
        r.pos += count * min_size as usize;
        return Ok(());
    }
    match kind {
        ElementKind::Vertex => b.reserve_vertices(count),
        ElementKind::Face => {
            let item = el.props.iter().zip(roles).find_map(|(p, role)| match (p.ty, role) {
                (PropType::List { item, .. }, Role::Indices) => Some(item.size()),
                _ => None,
            });
            b.reserve_faces(count, count.saturating_mul(3).min(remaining / item.unwrap_or(1)));
        }
        ElementKind::Strips | ElementKind::Other => {}
    }
    let name = &el.name;
    let big = r.big;
    let truncated = |i: usize| FormatError::new(format!("the PLY data ends inside {name} {i} (truncated file?)"));
    for i in 0..count {
        let mut v = VertexValues::default();
        for (p, role) in el.props.iter().zip(roles) {
            match p.ty {
                PropType::Scalar(ty) => {
                    let s = r.take(ty.size()).ok_or_else(|| truncated(i))?;
                    match *role {
                        Role::Coord(axis) => v.p[axis] = get_f64(ty, s, big),
                        Role::Color(c) => v.set_color(c, get_f64(ty, s, big), ty),
                        Role::TexCoord(k) => v.texcoord[k] = get_f64(ty, s, big),
                        Role::Normal(k) => v.normal[k] = get_f64(ty, s, big),
                        Role::TexNumber => v.texnumber = Some(get_f64(ty, s, big) as i64),
                        Role::Property(j) => b.channels.properties[j].values.push(get_f64(ty, s, big)),
                        Role::FaceProperty(j) => b.channels.face_properties[j].values.push(get_f64(ty, s, big)),
                        _ => {}
                    }
                }
                PropType::List { count: count_ty, item } => {
                    let s = r.take(count_ty.size()).ok_or_else(|| truncated(i))?;
                    let n = get_int(count_ty, s, big);
                    if n < 0 {
                        return Err(FormatError::new(format!(
                            "{name} {i} list {} has a negative length ({n})",
                            p.name
                        )));
                    }
                    let bytes = u64::try_from(n).ok().and_then(|n| n.checked_mul(item.size() as u64));
                    let Some(s) = bytes
                        .and_then(|len| usize::try_from(len).ok())
                        .and_then(|len| r.take(len))
                    else {
                        return Err(FormatError::new(format!(
                            "{name} {i} list {} claims {n} entries but only {} bytes of data remain",
                            p.name,
                            r.remaining()
                        )));
                    };
                    if *role == Role::Indices {
                        if n < 3 {
                            return Err(FormatError::new(format!(
                                "face {i} has {n} vertices (at least 3 needed)"
                            )));
                        }
                        b.start_face();
                        for chunk in s.chunks_exact(item.size()) {
                            let index = get_int(item, chunk, big);
                            b.index(checked_index(index, i, None, b.m.positions.len())?);
                        }
                    } else if *role == Role::StripIndices {
                        // -1 ends a strip; an unsigned type writes it as its largest value.
                        let restart = item.int_range().filter(|&(lo, _)| lo == 0).map(|(_, hi)| hi);
                        let strip: Vec<i64> = (s.chunks_exact(item.size()))
                            .map(|x| get_int(item, x, big))
                            .map(|x| if Some(x) == restart { -1 } else { x })
                            .collect();
                        push_strips(b, &strip, i, i as u64, None)?;
                    } else if *role == Role::WedgeTexCoords {
                        v.wedge
                            .extend(s.chunks_exact(item.size()).map(|x| get_f64(item, x, big)));
                    }
                }
            }
        }
        finish_record(b, kind, &v, i, i as u64)?;
    }
    Ok(())
}

/// The fewest bytes a binary record of `el` takes (its lists empty).
fn min_record_size(el: &PlyElement) -> u64 {
    el.props
        .iter()
        .map(|p| match p.ty {
            PropType::Scalar(t) => t.size() as u64,
            PropType::List { count, .. } => count.size() as u64,
        })
        .sum()
}

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------

/// Writes the header of a PLY that delmesh writes: `format` (`ascii` or
/// `binary_little_endian`), a comment naming delmesh and then `comments`,
/// the vertex element (`double x y z` then `vertex_properties`, each a
/// type's PLY name and a property name) and the face element (the list
/// `vertex_indices` then `face_properties`). Names are not checked here.
fn write_ply_header<'a>(
    w: &mut dyn Write,
    format: &str,
    comments: &[String],
    vertices: usize,
    vertex_properties: impl IntoIterator<Item = (&'a str, &'a str)>,
    triangles: usize,
    face_properties: impl IntoIterator<Item = (&'a str, &'a str)>,
) -> io::Result<()> {
    write!(w, "ply\nformat {format} 1.0\ncomment written by delmesh\n")?;
    for c in comments {
        writeln!(w, "comment {c}")?;
    }
    writeln!(w, "element vertex {vertices}")?;
    w.write_all(b"property double x\nproperty double y\nproperty double z\n")?;
    for (ty, name) in vertex_properties {
        writeln!(w, "property {ty} {name}")?;
    }
    write!(w, "element face {triangles}\nproperty list uchar uint vertex_indices\n")?;
    for (ty, name) in face_properties {
        writeln!(w, "property {ty} {name}")?;
    }
    w.write_all(b"end_header\n")
}

/// The header of [`write_ply_binary`] and [`write_ply_ascii`]: positions,
/// optional `uchar red green blue`, faces.
fn ply_header(w: &mut dyn Write, format: &str, vertices: usize, triangles: usize, colors: bool) -> io::Result<()> {
    let rgb = [("uchar", "red"), ("uchar", "green"), ("uchar", "blue")];
    let rgb = if colors { &rgb[..] } else { &[] };
    write_ply_header(w, format, &[], vertices, rgb.iter().copied(), triangles, [])
}

/// Writes a binary little-endian PLY 1.0: double x y z, optional uchar red green blue, face list uchar
/// uint vertex_indices. Positions are exact. Non-finite coordinates, out-of-range indices and a colour
/// count other than the vertex count are refused (`InvalidInput`).
pub fn write_ply_binary(
    w: &mut dyn Write,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colors: Option<&[[u8; 3]]>,
) -> io::Result<()> {
    check_for_writing(positions, triangles, colors)?;
    let mut w = BufWriter::new(w);
    ply_header(
        &mut w,
        "binary_little_endian",
        positions.len(),
        triangles.len(),
        colors.is_some(),
    )?;
    let mut record = Vec::with_capacity(27);
    for (i, p) in positions.iter().enumerate() {
        record.clear();
        for c in p {
            record.extend_from_slice(&c.to_le_bytes());
        }
        if let Some(rgb) = colors.and_then(|c| c.get(i)) {
            record.extend_from_slice(rgb);
        }
        w.write_all(&record)?;
    }
    for t in triangles {
        record.clear();
        record.push(3);
        for i in t {
            record.extend_from_slice(&i.to_le_bytes());
        }
        w.write_all(&record)?;
    }
    w.flush()
}

/// Whether `name` can name a property in a PLY header: one word, without
/// spaces or control characters (the reader leaves out a property whose
/// name is not, with a note, so that every property read can be written).
fn ply_name_is_one_word(name: &str) -> bool {
    !name.is_empty() && !name.bytes().any(|b| b.is_ascii_whitespace() || b.is_ascii_control())
}

/// One more vertex or face property for [`write_ply_binary_columns`]: a
/// name, the type it is written as, and one value per vertex or face.
#[derive(Clone, Debug, PartialEq)]
pub struct PlyColumn {
    /// The property name (`s`, `nx`, `red`, `quality`...): one word.
    pub name: String,
    /// Its type: values are rounded to it ([`ValueType::put_le`]).
    pub ty: ValueType,
    /// One value per vertex or face.
    pub values: Vec<f64>,
}

/// Writes a binary little-endian PLY 1.0: double x y z, then
/// `columns`, face list uchar uint vertex_indices, then `face_columns`;
/// each of `comments` on a `comment` line of the header. Positions and
/// `double` columns are exact. Refuses what [`write_ply_binary`] refuses, a
/// column whose length is not the vertex (or face) count or whose name is
/// not one word, and a comment with a line break.
pub fn write_ply_binary_columns(
    w: &mut dyn Write,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    columns: &[PlyColumn],
    face_columns: &[PlyColumn],
    comments: &[String],
) -> io::Result<()> {
    check_column_lengths(columns, positions.len(), "vertices")?;
    let properties: Vec<(&str, ValueType)> = columns.iter().map(|c| (c.name.as_str(), c.ty)).collect();
    let records = VertexRecords {
        count: positions.len(),
        properties: &properties,
        record: &|i, record: &mut Vec<u8>| {
            for c in &positions[i] {
                record.extend_from_slice(&c.to_le_bytes());
            }
            for c in columns {
                c.ty.put_le(c.values[i], record);
            }
        },
    };
    write_ply_binary_records(w, positions, triangles, &records, face_columns, comments)
}

/// Refuses a column whose length is not `n`, the count of `what`
/// (`vertices`, `faces`) it gives a value each.
fn check_column_lengths(columns: &[PlyColumn], n: usize, what: &str) -> io::Result<()> {
    match columns.iter().find(|c| c.values.len() != n) {
        Some(c) => Err(invalid(format!(
            "{} values of {} for {n} {what}",
            c.values.len(),
            c.name
        ))),
        None => Ok(()),
    }
}

/// The vertices of a binary PLY as [`write_ply_binary_records`] writes
/// them: made record by record as the file is written, instead of gathered
/// in columns first (on a textured million-face output, the columns and a
/// copy of the positions were 110 MB).
pub(crate) struct VertexRecords<'a> {
    /// How many vertices the file holds.
    pub count: usize,
    /// The properties after `x y z`, in order: name and type.
    pub properties: &'a [(&'a str, ValueType)],
    /// Appends vertex `i`'s record: `x y z` as little-endian doubles, then
    /// each property as [`ValueType::put_le`] writes it.
    pub record: &'a dyn Fn(usize, &mut Vec<u8>),
}

/// [`write_ply_binary_columns`] with the vertices' records made as they
/// are written (`vertices`); every vertex is at one of `positions` (which
/// are checked as [`write_ply_binary`] checks them), `triangles` index the
/// file's vertices.
pub(crate) fn write_ply_binary_records(
    w: &mut dyn Write,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    vertices: &VertexRecords,
    face_columns: &[PlyColumn],
    comments: &[String],
) -> io::Result<()> {
    if let Some(c) = comments.iter().find(|c| c.contains(['\n', '\r'])) {
        return Err(invalid(format!("a PLY comment cannot hold a line break: {c:?}")));
    }
    check_positions_for_writing(positions)?;
    let n = vertices.count;
    check_indices_for_writing(n, triangles)?;
    check_column_lengths(face_columns, triangles.len(), "faces")?;
    let names = (vertices.properties.iter().map(|&(name, _)| name)).chain(face_columns.iter().map(|c| c.name.as_str()));
    if let Some(name) = names.into_iter().find(|name| !ply_name_is_one_word(name)) {
        return Err(invalid(format!("a PLY property name must be one word: {name:?}")));
    }
    let mut w = BufWriter::new(w);
    write_ply_header(
        &mut w,
        "binary_little_endian",
        comments,
        n,
        vertices.properties.iter().map(|&(name, ty)| (ty.ply_name(), name)),
        triangles.len(),
        face_columns.iter().map(|c| (c.ty.ply_name(), c.name.as_str())),
    )?;
    let mut record = Vec::with_capacity(24 + 8 * vertices.properties.len().max(face_columns.len()));
    for i in 0..n {
        record.clear();
        (vertices.record)(i, &mut record);
        w.write_all(&record)?;
    }
    for (f, t) in triangles.iter().enumerate() {
        record.clear();
        record.push(3);
        for i in t {
            record.extend_from_slice(&i.to_le_bytes());
        }
        for c in face_columns {
            c.ty.put_le(c.values[f], &mut record);
        }
        w.write_all(&record)?;
    }
    w.flush()
}

/// Writes an ASCII PLY 1.0 with the same properties as [`write_ply_binary`]; coordinates in shortest
/// round-trip form, so that [`read_ply`] gives them back bit for bit.
pub fn write_ply_ascii(
    w: &mut dyn Write,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colors: Option<&[[u8; 3]]>,
) -> io::Result<()> {
    check_for_writing(positions, triangles, colors)?;
    let mut header = Vec::new();
    ply_header(&mut header, "ascii", positions.len(), triangles.len(), colors.is_some())?;
    w.write_all(&header)?;
    // Each kind of line on both cores ([`write_numbered_lines`]), in order.
    write_numbered_lines(w, positions.len(), |i, line| {
        push_xyz(line, &mut zmij::Buffer::new(), &positions[i]);
        if let Some(rgb) = colors.and_then(|c| c.get(i)) {
            for &x in rgb {
                line.push(b' ');
                push_decimal(line, u64::from(x));
            }
        }
        line.push(b'\n');
    })?;
    write_numbered_lines(w, triangles.len(), |f, line| {
        push_face(line, b'3', &triangles[f], 0);
        line.push(b'\n');
    })?;
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The column writer gives back what the reader reads (positions
    /// exact, each property in its type, the comments), and refuses a
    /// column of the wrong length, a name of two words and a comment with a
    /// line break, writing nothing.
    #[test]
    fn columns_read_back_and_bad_columns_are_refused() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.1]];
        let triangles = [[0, 1, 2]];
        let column = |name: &str, ty, values: Vec<f64>| PlyColumn {
            name: name.into(),
            ty,
            values,
        };
        let quality = column("quality", ValueType::F32, vec![0.5, 1.25, -3.0]);
        let label = column("label", ValueType::U8, vec![7.0]);
        let comments = ["TextureFile a.png".to_string()];
        let mut bytes = Vec::new();
        write_ply_binary_columns(
            &mut bytes,
            &positions,
            &triangles,
            std::slice::from_ref(&quality),
            std::slice::from_ref(&label),
            &comments,
        )
        .unwrap();
        let read = read_ply(&bytes).unwrap();
        assert_eq!(read.positions, positions);
        assert_eq!(read.indices, [0, 1, 2]);
        let property = &read.attributes.properties[0];
        assert_eq!((property.name.as_str(), property.ty), ("quality", ValueType::F32));
        let values = property.channel.as_ref().unwrap();
        let by_corner: Vec<f64> = (0..3).map(|c| values.corner(c)[0]).collect();
        assert_eq!(by_corner, quality.values);
        assert_eq!(read.attributes.face_properties[0].values, [7.0]);
        assert!(String::from_utf8_lossy(&bytes).contains("comment TextureFile a.png\n"));

        let refused = |columns: &[PlyColumn], faces: &[PlyColumn], comments: &[String]| {
            let mut bytes = Vec::new();
            let error = write_ply_binary_columns(&mut bytes, &positions, &triangles, columns, faces, comments)
                .unwrap_err()
                .to_string();
            assert!(bytes.is_empty(), "{error}");
            error
        };
        let short = column("quality", ValueType::F32, vec![0.5]);
        assert_eq!(refused(&[short], &[], &[]), "1 values of quality for 3 vertices");
        let long = column("label", ValueType::U8, vec![1.0, 2.0]);
        assert_eq!(refused(&[], &[long], &[]), "2 values of label for 1 faces");
        let blank = column("my quality", ValueType::F32, vec![0.0; 3]);
        assert!(refused(&[blank], &[], &[]).contains("one word"));
        assert!(refused(&[], &[], &["two\nlines".into()]).contains("line break"));
    }

    /// A random ASCII PLY text near the plain forms: vertex elements of
    /// float, integer and colour properties (sometimes a list, which is not
    /// plain), face elements of one index list (sometimes with another
    /// property), and records that are mostly plain, some with a token or a
    /// blank swapped for an odd piece, values missing or left over, records
    /// broken over lines, blank lines between them, CRLF line ends.
    fn near_plain_ply(rng: &mut crate::test_rng::Rng) -> String {
        let pick = |rng: &mut crate::test_rng::Rng, from: &[&'static str]| from[rng.below(from.len() as u64) as usize];
        let vertex_props: Vec<(&str, &str)> = match rng.below(5) {
            0 => vec![("float", "x"), ("float", "y"), ("float", "z")],
            1 => vec![
                ("double", "x"),
                ("double", "y"),
                ("double", "z"),
                ("float", "confidence"),
            ],
            2 => vec![
                ("float", "x"),
                ("float", "y"),
                ("float", "z"),
                ("uchar", "red"),
                ("uchar", "green"),
                ("uchar", "blue"),
            ],
            3 => vec![
                ("int", "x"),
                ("short", "y"),
                ("float", "z"),
                ("float", "nx"),
                ("float", "ny"),
                ("float", "nz"),
            ],
            _ => vec![
                ("float", "x"),
                ("float", "y"),
                ("float", "z"),
                ("list uchar float", "w"),
            ],
        };
        let face_props: Vec<(&str, &str)> = match rng.below(4) {
            0 | 1 => vec![("list uchar int", "vertex_indices")],
            2 => vec![("list int uint", "vertex_index")],
            _ => vec![("list uchar int", "vertex_indices"), ("uchar", "flags")],
        };
        let (n_vertices, n_faces) = (1 + rng.below(6), rng.below(6));
        let mut text = format!("ply\nformat ascii 1.0\nelement vertex {n_vertices}\n");
        for (ty, name) in &vertex_props {
            text += &format!("property {ty} {name}\n");
        }
        text += &format!("element face {n_faces}\n");
        for (ty, name) in &face_props {
            text += &format!("property {ty} {name}\n");
        }
        text += "end_header\n";
        let line_end = pick(rng, &["\n", "\n", "\r\n", " \n", "\t\n"]);
        let record = |rng: &mut crate::test_rng::Rng, words: Vec<String>, text: &mut String| {
            push_odd_line(rng, words, text, line_end, (12, false, true));
        };
        for _ in 0..n_vertices {
            let words = vertex_props
                .iter()
                .map(|(ty, _)| match *ty {
                    "uchar" => rng.below(256).to_string(),
                    "int" | "short" => (rng.below(200) as i64 - 100).to_string(),
                    "list uchar float" => "2 0.5 1".into(),
                    _ => pick(rng, &["0.25", "-1.5", "3", "1e-3", "12.0625"]).into(),
                })
                .collect();
            record(rng, words, &mut text);
        }
        for _ in 0..n_faces {
            // (Sometimes a face of 2: refused, whichever way it is read.)
            let n = if rng.below(8) == 0 { 2 } else { 3 + rng.below(3) };
            let mut words = vec![n.to_string()];
            words.extend((0..n).map(|_| rng.below(n_vertices).to_string()));
            if face_props.len() > 1 {
                words.push("1".into());
            }
            record(rng, words, &mut text);
        }
        text
    }

    #[test]
    fn plain_records_read_in_one_scan_as_the_general_way_reads_them() {
        let mut rng = crate::test_rng::Rng(0x91a1_2ec0);
        let (mut plain, mut refused) = (0, 0);
        for _ in 0..6000 {
            if read_alike(&near_plain_ply(&mut rng), |text, plain| {
                read_ply_with(text, plain, usize::MAX)
            }) {
                plain += 1;
            } else {
                refused += 1;
            }
        }
        // Both outcomes are exercised, not only one.
        assert!(plain > 1000 && refused > 1000, "{plain} read, {refused} refused");
    }

    #[test]
    fn the_nth_line_end_is_found_as_by_counting_one_by_one() {
        let mut rng = crate::test_rng::Rng(0x11e_e4d5);
        for _ in 0..200 {
            // Up to three blocks, line feeds dense or sparse.
            let density = 1 + rng.below(300);
            let data: Vec<u8> = (0..rng.below(3 * 4096 + 100))
                .map(|_| if rng.below(density) == 0 { b'\n' } else { b'x' })
                .collect();
            let from = rng.below(data.len() as u64 + 1) as usize;
            let ends: Vec<usize> = (from..data.len()).filter(|&i| data[i] == b'\n').collect();
            for n in 1..=ends.len() as u64 + 1 {
                assert_eq!(nth_line_end(&data, from, n), ends.get(n as usize - 1).copied());
            }
        }
        // Nothing but line feeds: every piece's count at its most (128).
        let feeds = vec![b'\n'; 3 * 4096 + 7];
        assert_eq!(nth_line_end(&feeds, 5, 4096), Some(4100));
    }

    #[test]
    fn faces_read_ahead_are_those_the_reader_reads() {
        let mut rng = crate::test_rng::Rng(0x5eed_face);
        let (mut taken, mut partly) = (0, 0);
        for _ in 0..3000 {
            let text = near_plain_ply(&mut rng);
            // Whether the thread's records are taken, and all of them.
            let bytes = text.as_bytes();
            if let Ok(header) = parse_ply_header(bytes) {
                let plans: Option<Vec<_>> = header.elements.iter().map(|el| element_roles(el).ok()).collect();
                let plan = plans
                    .as_ref()
                    .and_then(|plans| FacesAhead::plan(&header, plans).map(|p| (p, plans)));
                if let Some(((e, form, skip), plans)) = plan {
                    let (el, (kind, roles)) = (&header.elements[e], &plans[e]);
                    let at = (header.data_start, header.data_line);
                    if let Some(ahead) =
                        FacesAhead::read(bytes, at, skip, el, roles, *kind, form, &AtomicBool::new(false))
                    {
                        let mut t = Tokens::new(bytes, at.0, at.1);
                        for el in &header.elements[..e] {
                            for _ in 0..el.count * el.props.len() as u64 {
                                t.next();
                            }
                        }
                        let records = ahead.records;
                        if ahead.take(&mut t, &mut Builder::new(OriginKind::Line, Numbering::FromZero)) > 0 {
                            taken += 1;
                            partly += usize::from(records < el.count as usize);
                        }
                    }
                }
            }
            let (threaded, alone) =
                crate::parallel::threaded_and_alone(2, || format!("{:?}", read_ply_with(bytes, true, 0)));
            let general = format!("{:?}", read_ply_with(bytes, false, usize::MAX));
            assert_eq!(threaded, general, "{text:?}");
            assert_eq!(alone, general, "{text:?}");
        }
        // Taken in many files, all records or only the first ones; not in all.
        assert!(
            (300..2500).contains(&taken) && partly > 50,
            "{taken} taken, {partly} partly"
        );
    }
}
