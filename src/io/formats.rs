//! Readers and writers for OFF, PLY and STL meshes, and gzip input.
//!
//! # Why hand-written parsers
//! No format crate is used. `ply-rs` is unmaintained since 2020, builds a
//! property map per element (slow on million-face scans) and trusts header
//! counts; STL crates read coordinates as `f32` and weld vertices themselves.
//! The parsers here are small, work on an in-memory byte slice, keep the
//! origin of every vertex and face for error messages, and are written so that
//! hostile input cannot make them panic, hang or allocate without bound:
//!
//! - a header count is never trusted for allocation: before an element is read,
//!   its declared count is checked against the bytes actually left (at least one
//!   byte per binary property, two per ASCII value), so a PLY header claiming
//!   2^40 vertices is refused at once, and reservations are bounded by the input;
//! - every list length is checked against the bytes left before it is read;
//! - elements without properties are skipped in O(1), so no loop runs more times
//!   than there are bytes in the input; nothing recurses;
//! - truncated data, non-numbers, non-finite coordinates (NaN, inf, or decimal
//!   text that overflows `f64`), faces with fewer than 3 vertices, negative and
//!   out-of-range indices are all errors naming the element (and the line, for
//!   text); trailing bytes after the last element are ignored.
//!
//! Dependencies: `flate2` (pure-Rust `zlib-rs` backend) for `.gz`
//! input and `zmij` for shortest round-trip formatting of `f64`, so that
//! positions survive OFF and ASCII PLY round trips bit for bit.
//!
//! # Numbers in messages
//! Vertices, faces and facets are numbered from 0, as PLY and OFF indices are;
//! lines are numbered from 1. Text coordinates are parsed as `f64` exactly as
//! written, even when a PLY header types them `float`; but an ASCII PLY
//! value that its declared type cannot hold (`300` as `uchar`, `1.5` as
//! `int`, `1e39` as `float`) is refused in a coordinate, face index or list
//! length, and drops its attribute with a note in a colour, texture
//! coordinate or normal.

use std::borrow::Cow;
use std::fmt;
use std::io::{self, BufWriter, Read, Write};

use crate::attributes::{Attributes, Channel, FaceProperty, Kind, ValueType, VertexProperty, MAX_VERTEX_PROPERTIES};
use crate::hash::FastMap;

/// A mesh as read from a file, before welding and triangulation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RawMesh {
    /// Vertex positions, in file order (for STL: three per facet).
    pub positions: Vec<[f64; 3]>,
    /// Polygons, flattened: face f is `indices[face_start[f] as usize .. face_start[f+1] as usize]`;
    /// `face_start.len() == faces + 1` (or empty when no faces).
    pub face_start: Vec<u32>,
    /// Vertex indices of all faces, 0-based, each `< positions.len()` (checked by the reader).
    pub indices: Vec<u32>,
    /// Optional per-vertex colour (PLY red/green/blue, as read, u8 or scaled to u8), None if absent.
    pub colors: Option<Vec<[u8; 3]>>,
    /// Where each face came from: for text formats the 1-based line, for binary formats the 0-based record number.
    pub face_origin: Vec<u32>,
    /// Where each vertex came from: for text formats the 1-based line, for binary formats the 0-based
    /// record number (for binary STL, the facet's record number).
    pub vertex_origin: Vec<u32>,
    /// Whether `face_origin` and `vertex_origin` hold lines or record numbers.
    pub origin_kind: OriginKind,
    /// How the format numbers vertices and faces, for messages.
    pub numbering: Numbering,
    /// Texture coordinates, normals, colours (one value per entry of
    /// `indices`, [`crate::attributes::NO_VALUE`] where the file gives none),
    /// groups (one per face) and material libraries.
    pub attributes: Attributes,
    /// What the reader ignored or read otherwise than the file says (data
    /// after what a header declares, a wrong count), one line each.
    pub notes: Vec<String>,
    /// Why attributes of the file were left out, or read with a change
    /// (one line each): not said when attributes are not wanted.
    pub attribute_notes: Vec<String>,
}

/// What the origins of a [`RawMesh`] count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OriginKind {
    /// 1-based line numbers (text formats).
    #[default]
    Line,
    /// 0-based record numbers (binary formats).
    Record,
}

/// How a format numbers its vertices and faces, so that a message names
/// them as the user's other tools do: OBJ counts from 1, OFF and PLY from 0,
/// and STL has no vertex list (a vertex is named by its position).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Numbering {
    /// OBJ: vertex and face 1 are the first.
    #[default]
    FromOne,
    /// OFF, PLY: vertex and face 0 are the first.
    FromZero,
    /// STL: facet 0 is the first; a vertex is where facets' corners meet.
    Stl,
}

impl Numbering {
    /// The vertex at 0-based position `i` of the file's vertex list, at
    /// `position`, as a message names it.
    pub fn vertex(self, i: u32, position: [f64; 3]) -> String {
        match self {
            Numbering::FromOne => format!("vertex {}", u64::from(i) + 1),
            Numbering::FromZero => format!("vertex {i}"),
            Numbering::Stl => format!("the vertex at {}", super::number::point_text(position)),
        }
    }

    /// The face at 0-based position `f` of the file's faces, as a message
    /// names it.
    pub fn face(self, f: usize) -> String {
        match self {
            Numbering::FromOne => format!("face {}", f as u64 + 1),
            Numbering::FromZero => format!("face {f}"),
            Numbering::Stl => format!("facet {f}"),
        }
    }
}

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (read elsewhere).
    Obj,
    /// Object File Format (Geomview).
    Off,
    /// Polygon File Format (Stanford).
    Ply,
    /// Stereolithography, ASCII or binary.
    Stl,
}

impl Format {
    /// The format's name in messages (`"OFF"`).
    pub fn name(self) -> &'static str {
        match self {
            Format::Obj => "OBJ",
            Format::Off => "OFF",
            Format::Ply => "PLY",
            Format::Stl => "STL",
        }
    }

    /// Why a file named as another format is refused when its content is
    /// of this one, as the construction and `check` both say it.
    pub fn misnamed_reason(self) -> String {
        format!(
            "its content is {} (name it .{}: the name's extension decides the format)",
            self.name(),
            self.name().to_ascii_lowercase()
        )
    }
}

/// Why a file could not be read.
#[derive(Debug, Clone, PartialEq)]
pub struct FormatError {
    /// The 1-based line for text formats, None otherwise.
    pub line: Option<u64>,
    /// One human sentence naming the element, record or property at fault.
    pub what: String,
}

impl FormatError {
    fn new(what: impl Into<String>) -> Self {
        FormatError {
            line: None,
            what: what.into(),
        }
    }

    fn at(line: u64, what: impl Into<String>) -> Self {
        FormatError {
            line: Some(line),
            what: what.into(),
        }
    }

    fn maybe_at(line: Option<u64>, what: impl Into<String>) -> Self {
        FormatError {
            line,
            what: what.into(),
        }
    }
}

impl fmt::Display for FormatError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "line {line}: {}", self.what),
            None => f.write_str(&self.what),
        }
    }
}

impl std::error::Error for FormatError {}

// ---------------------------------------------------------------------------
// Format detection and gzip
// ---------------------------------------------------------------------------

/// Decompresses if the bytes start with the gzip magic (1f 8b); limit the decompressed size to `max_bytes`
/// (error if larger). Concatenated gzip members are decompressed one after the other, as `gzip -d` does;
/// bytes after the last that are no gzip member are an error that says so. Other bytes are returned as
/// they are, but the first byte of the magic alone (a `.gz` file cut after one byte), which is truncated
/// gzip data.
pub fn maybe_gunzip(bytes: &[u8], max_bytes: u64) -> Result<Cow<'_, [u8]>, FormatError> {
    gunzip_judged(bytes, max_bytes, None)
}

/// [`maybe_gunzip`] for a file whose name gives the format `named`: the
/// decompressing stops, refused, after [`STREAM_PREFIX`] bytes if those
/// are refused whatever follows ([`judge_start`]), so that a small
/// file of compressed zeros is not inflated to the limit first.
pub(crate) fn gunzip_judged(bytes: &[u8], max_bytes: u64, named: Option<Format>) -> Result<Cow<'_, [u8]>, FormatError> {
    // A binary STL's 80-byte header is free text, and may start with the
    // gzip magic too: a file named STL whose size is exactly the one its
    // facet count gives is taken as one (gzip data of a size that matches
    // its bytes 80..84 so has a chance of 2^-32).
    // (The same for the decompressed bytes: gzip data inside is a file
    // compressed twice, unless it is such an STL.)
    let exact_stl = |data: &[u8]| {
        named == Some(Format::Stl) && binary_stl_size(data).is_some_and(|(_, size)| size == data.len() as u64)
    };
    if bytes == [0x1f] {
        return Err(FormatError::new(
            "the gzip data is truncated (the file has 1 byte, the first of the gzip magic)",
        ));
    }
    if !bytes.starts_with(&[0x1f, 0x8b]) || exact_stl(bytes) {
        return Ok(Cow::Borrowed(bytes));
    }
    // A gzip member ends with its decompressed size modulo 2^32: exact for the usual single
    // member under 4 GiB, so the output is usually allocated once, not grown by copying. Not
    // believed beyond what deflate can expand to (1032 times), nor past the limit.
    let compressed = bytes.len() as u64;
    let footer = bytes.last_chunk::<4>().map(|size| u32::from_le_bytes(*size));
    let stated = footer
        .map_or(0, |size| u64::from(size) + 1)
        .min(compressed.saturating_mul(1032));
    let guess = compressed
        .saturating_mul(4)
        .max(stated)
        .min(max_bytes.saturating_add(1))
        .min(1 << 30);
    let mut out = Vec::with_capacity(usize::try_from(guess).unwrap_or(0));
    let mut decoder = GzMembers(flate2::bufread::GzDecoder::new(bytes)).take(max_bytes.saturating_add(1));
    let corrupt = |e: io::Error| match e.get_ref().and_then(|e| e.downcast_ref::<TrailingBytes>()) {
        Some(TrailingBytes(n)) => FormatError::new(format!(
            "the gzip data is followed by {n} bytes that are not gzip data (appended to the file?)"
        )),
        None => FormatError::new(format!("the gzip data is corrupt or truncated ({e})")),
    };
    if let Some(why) = read_judged(&mut decoder, named, &mut out).map_err(corrupt)? {
        return Err(FormatError::new(format!(
            "the gzip data is {why} (decompressing stopped there)"
        )));
    }
    if out.len() as u64 > max_bytes {
        return Err(FormatError::new(format!(
            "the gzip data decompresses to more than the limit of {max_bytes} bytes"
        )));
    }
    if out.starts_with(&[0x1f, 0x8b]) && !exact_stl(&out) {
        return Err(FormatError::new(
            "the gzip data decompresses to gzip data (the file was compressed twice): decompress it once first (gunzip)",
        ));
    }
    Ok(Cow::Owned(out))
}

/// The gzip members of some bytes, decompressed one after the other (as
/// `gzip -d` reads concatenated files); after the last, bytes that do not
/// start another member are an error holding [`TrailingBytes`].
struct GzMembers<'a>(flate2::bufread::GzDecoder<&'a [u8]>);

/// How many bytes after the last gzip member are not gzip data.
#[derive(Debug)]
struct TrailingBytes(usize);

impl fmt::Display for TrailingBytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} bytes after the gzip data are not gzip data", self.0)
    }
}

impl std::error::Error for TrailingBytes {}

impl Read for GzMembers<'_> {
    fn read(&mut self, into: &mut [u8]) -> io::Result<usize> {
        loop {
            let n = self.0.read(into)?;
            // A member ended (its check passed): its bytes are consumed.
            let rest: &[u8] = self.0.get_ref();
            if n > 0 || into.is_empty() || rest.is_empty() {
                return Ok(n);
            }
            if !rest.starts_with(&[0x1f, 0x8b]) {
                return Err(io::Error::new(io::ErrorKind::InvalidData, TrailingBytes(rest.len())));
            }
            self.0 = flate2::bufread::GzDecoder::new(rest);
        }
    }
}

/// The format from a file name: .obj .off .ply .stl (case-insensitive), looking through a trailing .gz;
/// None when the extension says nothing.
pub fn format_from_name(name: &str) -> Option<Format> {
    let base = name.rsplit(['/', '\\']).next().unwrap_or(name);
    let lower = base.to_ascii_lowercase();
    let stem = lower.strip_suffix(".gz").unwrap_or(&lower);
    let (_, ext) = stem.rsplit_once('.')?;
    match ext {
        "obj" => Some(Format::Obj),
        "off" => Some(Format::Off),
        "ply" => Some(Format::Ply),
        "stl" => Some(Format::Stl),
        _ => None,
    }
}

/// Where an OFF line's comment starts: at its first `#`, except one glued
/// to a number as Windows prints NaN and infinity (`1.#QNAN`, `-1.#IND`,
/// `1.#INF`), which stays in the number so that the number is refused
/// rather than read as 1.
fn comment_start(line: &[u8]) -> Option<usize> {
    (0..line.len()).find(|&i| line[i] == b'#' && !is_windows_special(line, i))
}

/// Whether the `#` at `b[i]` continues a number as Windows' C library
/// prints NaN and infinity: `1.#QNAN`, `-1.#IND`, `1.#INF`, `1.#SNAN`.
pub(crate) fn is_windows_special(b: &[u8], i: usize) -> bool {
    if b[i] != b'#' {
        return false;
    }
    let after = &b[i + 1..];
    let starts = |word: &[u8]| after.len() >= word.len() && after[..word.len()].eq_ignore_ascii_case(word);
    i > 0
        && (b[i - 1].is_ascii_digit() || b[i - 1] == b'.')
        && (starts(b"INF") || starts(b"IND") || starts(b"QNAN") || starts(b"SNAN"))
}

/// Sniff the format from content: the "ply" first line, "OFF"/"COFF"/"NOFF"... header, the word
/// "solid" first for STL, binary STL by size == 84 + 50*n, OBJ by 'v '/'f ' lines; None if unknown
/// (including gzip data: decompress first with [`maybe_gunzip`]).
pub fn sniff_format(bytes: &[u8]) -> Option<Format> {
    let text = strip_bom(bytes);
    if starts_with_ply_magic(text) {
        return Some(Format::Ply);
    }
    let window = &text[..text.len().min(SNIFF_WINDOW)];
    if let Some((_, line)) = Lines::new(window).next_meaningful() {
        let head = words(line).next().unwrap_or(b"");
        if off_keyword(head).is_some() || glued_vertex_count(head).is_some() {
            return Some(Format::Off);
        }
    }
    // No other format starts with the word `solid`: an ASCII STL, or a
    // binary one whose header says so (`read_stl` tells them apart), even
    // without a facet in its first 64 KiB (cut short: read as an STL, it
    // says so, not that `solid` is no OBJ statement).
    if starts_with_solid(text) {
        return Some(Format::Stl);
    }
    if binary_stl_size(bytes).is_some_and(|(_, need)| need == bytes.len() as u64) {
        return Some(Format::Stl);
    }
    if looks_like_obj(text) {
        return Some(Format::Obj);
    }
    None
}

/// How many bytes of a file the text sniffers look at.
const SNIFF_WINDOW: usize = 64 * 1024;

/// How many bytes of an input that is not a regular file (a pipe, a
/// device) are read before [`judge_start`] judges them: the text
/// sniffers' window, after a byte order mark.
pub(crate) const STREAM_PREFIX: usize = SNIFF_WINDOW + 3;

/// Reads all of `reader` into `out`, unless its first [`STREAM_PREFIX`]
/// bytes say it is no mesh ([`judge_start`]): then it stops there, or past
/// the one size it could be read at, and returns why (`not an OBJ file:
/// ...`).
pub(crate) fn read_judged(
    mut reader: impl Read,
    named: Option<Format>,
    out: &mut Vec<u8>,
) -> io::Result<Option<String>> {
    (&mut reader).take(STREAM_PREFIX as u64).read_to_end(out)?;
    if out.len() < STREAM_PREFIX {
        return Ok(None);
    }
    match judge_start(named, out) {
        Start::Refused(what) => return Ok(Some(format!("not {what}: its first 64 KiB cannot start one"))),
        Start::AtMost(limit, what) => {
            // Only a binary STL of the size its header says is left.
            let more = (limit + 1).saturating_sub(out.len() as u64);
            (&mut reader).take(more).read_to_end(out)?;
            if out.len() as u64 > limit {
                return Ok(Some(format!(
                    "not {what}: longer than the binary STL its header would make it, and no other kind"
                )));
            }
        }
        Start::Unsure => {}
    }
    reader.read_to_end(out)?;
    Ok(None)
}

/// What the first bytes of an input say of it ([`judge_start`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Start {
    /// Sure to be refused: not this (`an OBJ file`).
    Refused(&'static str),
    /// Read only if it has exactly this many bytes (a binary STL, by its
    /// header's count, for an input without a name): refused once longer.
    AtMost(u64, &'static str),
    /// It may be a mesh.
    Unsure,
}

/// What an input whose first bytes are `prefix` (at least [`STREAM_PREFIX`]
/// of them, more to follow) is sure not to be, whatever follows, if it is
/// sure ([`Start::Refused`]); `named` is the format its name gives. An
/// endless input (`/dev/zero`, `/dev/urandom`) is then stopped instead of
/// read to the end. Without a name, text no OBJ reader takes is read on
/// only as far as the binary STL its first bytes would make it
/// ([`Start::AtMost`]). Says nothing of gzip data.
pub(crate) fn judge_start(named: Option<Format>, prefix: &[u8]) -> Start {
    let obj = || super::obj::refused_from_start(prefix);
    let solid = || starts_with_solid(strip_bom(prefix));
    let what = match named {
        Some(Format::Obj) => "an OBJ file",
        Some(Format::Off) => "an OFF file",
        Some(Format::Ply) => "a PLY file",
        Some(Format::Stl) => "an STL file",
        None => "a mesh (OBJ, OFF, PLY or STL)",
    };
    if named.is_none() && !prefix.starts_with(&[0x1f, 0x8b]) {
        if let (None | Some(Format::Obj), Some((_, need))) = (sniff_format(prefix), binary_stl_size(prefix)) {
            if obj() && !solid() && !binary_stl_refused(prefix, true) {
                return Start::AtMost(need, what);
            }
        }
    }
    let refused = match named {
        _ if prefix.starts_with(&[0x1f, 0x8b]) => false,
        Some(Format::Obj) => obj(),
        Some(Format::Stl) => !solid() && binary_stl_refused(prefix, false),
        Some(Format::Ply) => !starts_with_ply_magic(strip_bom(prefix)),
        Some(Format::Off) => off_refused(prefix),
        // Read as OBJ unless its size is exactly a binary STL's.
        None => match sniff_format(prefix) {
            None | Some(Format::Obj) => obj() && !solid() && binary_stl_refused(prefix, true),
            Some(_) => false,
        },
    };
    if refused {
        Start::Refused(what)
    } else {
        Start::Unsure
    }
}

/// Whether an OFF file starting with `prefix` (more to follow) is sure to
/// be refused: its first line is neither a header nor counts.
fn off_refused(prefix: &[u8]) -> bool {
    let text = strip_bom(prefix);
    let Some((_, first)) = Lines::new(text).next_meaningful() else {
        return false;
    };
    let head = words(first).next().unwrap_or(b"");
    // A word running to the end of the prefix may go on: unsure if short.
    if head.as_ptr_range().end == text.as_ptr_range().end && head.len() <= 32 {
        return false;
    }
    glued_vertex_count(head).is_none() && off_keyword(head).is_none() && parse_int(head).is_none()
}

/// Whether a binary STL starting with `prefix` (more to follow) is sure
/// to be refused: it declares no facets and holds only zeros, or one of
/// its first facets has a coordinate that is not finite; or, if `exact` (read as STL only when
/// its size is what the header declares), it declares fewer bytes than
/// `prefix` has, so the whole input cannot be that size.
fn binary_stl_refused(prefix: &[u8], exact: bool) -> bool {
    let Some((n, need)) = binary_stl_size(prefix) else {
        return false;
    };
    let finite = |rec: &[u8]| {
        rec[12..48]
            .chunks_exact(4)
            .all(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]).is_finite())
    };
    // Declaring no facets, a file is read by its size if that is a whole
    // number of them: zeros (`/dev/zero`) are still refused at once.
    let zeros = || prefix[84..].iter().all(|&b| b == 0);
    (n == 0 && zeros())
        || (exact && need < prefix.len() as u64)
        || !prefix[84..].chunks_exact(50).take(n as usize).all(finite)
}

/// `bytes` without a leading UTF-8 byte order mark.
pub(crate) fn strip_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

/// Whether `line` (without its line feed) is a PLY file's first line:
/// `ply`, less trailing spaces, tabs and a carriage return, as the header's
/// other lines are read (their words may be padded freely).
fn is_ply_magic(line: &[u8]) -> bool {
    line.trim_ascii_end() == b"ply"
}

/// Whether `text` starts with a PLY file's first line ([`is_ply_magic`]).
fn starts_with_ply_magic(text: &[u8]) -> bool {
    text.iter()
        .position(|&c| c == b'\n')
        .is_some_and(|end| is_ply_magic(&text[..end]))
}

/// Why text is refused whose lines end in a carriage return alone
/// ([`lone_cr_line`]).
pub(crate) const LONE_CR: &str =
    "lines end in a carriage return alone (classic Mac OS text): convert them to line feeds";

/// The 1-based line (counted by line feeds) of the first carriage return
/// in `text` that ends a line by itself, as classic Mac OS text does: one
/// followed by something other than blanks before the next line feed. The
/// text readers take a carriage return for a blank, so such a line would
/// be read joined to the next (in a comment, the next statement lost); a
/// carriage return before a line feed, or before blanks and then one (or
/// the end), is the usual CRLF line end. One scan for the byte in text
/// without any (most files).
pub(crate) fn lone_cr_line(text: &[u8]) -> Option<u64> {
    if !text.contains(&b'\r') {
        return None;
    }
    let mut i = 0;
    while let Some(cr) = text[i..].iter().position(|&b| b == b'\r').map(|k| i + k) {
        let after = &text[cr + 1..];
        let blanks = after
            .iter()
            .position(|&b| !matches!(b, b' ' | b'\t' | b'\r' | 0x0b | 0x0c))
            .unwrap_or(after.len());
        if after.get(blanks).is_some_and(|&b| b != b'\n') {
            return Some(1 + text[..cr].iter().filter(|&&b| b == b'\n').count() as u64);
        }
        i = cr + 1 + blanks;
    }
    None
}

/// Whether the complete lines of the first [`SNIFF_WINDOW`] bytes are OBJ statements, at least one a
/// `v` or `f` line.
fn looks_like_obj(text: &[u8]) -> bool {
    let mut window = &text[..text.len().min(SNIFF_WINDOW)];
    if window.len() < text.len() {
        // Only complete lines: the last one may be cut.
        match window.iter().rposition(|&c| c == b'\n') {
            Some(end) => window = &window[..end],
            None => return false,
        }
    }
    if window.contains(&0) {
        return false;
    }
    const KEYWORDS: &[&[u8]] = &[
        b"v", b"vn", b"vt", b"vp", b"f", b"o", b"g", b"s", b"l", b"p", b"mtllib", b"usemtl", b"cstype", b"deg",
        b"curv", b"curv2", b"surf", b"parm", b"trim", b"hole", b"end", b"call", b"csh", b"bmat", b"step",
    ];
    let mut lines = Lines::new(window);
    let mut found = false;
    while let Some((_, line)) = lines.next_meaningful() {
        let Some(keyword) = words(line).next() else { continue };
        if !KEYWORDS.contains(&keyword) {
            return false;
        }
        found |= keyword == b"v" || keyword == b"f";
    }
    found
}

// ---------------------------------------------------------------------------
// Shared building blocks
// ---------------------------------------------------------------------------

/// Builds a [`RawMesh`], keeping `face_start`/`face_origin` consistent.
struct Builder {
    m: RawMesh,
    /// PLY per-vertex attributes.
    channels: VertexChannels,
}

impl Builder {
    fn new(kind: OriginKind, numbering: Numbering) -> Self {
        Builder {
            m: RawMesh {
                origin_kind: kind,
                numbering,
                ..RawMesh::default()
            },
            channels: VertexChannels::default(),
        }
    }

    fn line_of(&self, origin: u64) -> Option<u64> {
        (self.m.origin_kind == OriginKind::Line).then_some(origin)
    }

    fn reserve_vertices(&mut self, n: usize) {
        self.m.positions.reserve(n);
        self.m.vertex_origin.reserve(n);
        if let Some(colors) = &mut self.m.colors {
            colors.reserve(n);
        }
    }

    fn reserve_faces(&mut self, faces: usize, indices: usize) {
        self.m.face_start.reserve(faces.saturating_add(1));
        self.m.face_origin.reserve(faces);
        self.m.indices.reserve(indices);
    }

    /// Adds a vertex after checking that it is finite; `name` is how messages call it ("vertex 3").
    fn vertex(&mut self, p: [f64; 3], origin: u64, name: impl FnOnce() -> String) -> Result<(), FormatError> {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(FormatError::maybe_at(
                self.line_of(origin),
                format!("{} has a non-finite coordinate", name()),
            ));
        }
        if self.m.positions.len() >= u32::MAX as usize {
            return Err(FormatError::maybe_at(
                self.line_of(origin),
                "the file has more than 2^32 - 1 vertices",
            ));
        }
        self.m.positions.push(p);
        self.m.vertex_origin.push(origin32(origin));
        Ok(())
    }

    fn start_face(&mut self) {
        if self.m.face_start.is_empty() {
            self.m.face_start.push(0);
        }
    }

    fn index(&mut self, i: u32) {
        self.m.indices.push(i);
    }

    fn end_face(&mut self, origin: u64) -> Result<(), FormatError> {
        let end = u32::try_from(self.m.indices.len()).map_err(|_| {
            FormatError::maybe_at(self.line_of(origin), "the faces have more than 2^32 - 1 indices in all")
        })?;
        self.m.face_start.push(end);
        self.m.face_origin.push(origin32(origin));
        Ok(())
    }

    /// Checks every index against the vertex count and returns the mesh.
    fn finish(self) -> Result<RawMesh, FormatError> {
        let m = self.m;
        let n = m.positions.len();
        if m.indices.iter().all(|&i| (i as usize) < n) {
            return Ok(m);
        }
        for (f, range) in m.face_start.windows(2).enumerate() {
            let face = m.indices.get(range[0] as usize..range[1] as usize).unwrap_or(&[]);
            if let Some(&bad) = face.iter().find(|&&i| i as usize >= n) {
                let origin = m.face_origin.get(f).copied().unwrap_or(0);
                let line = (m.origin_kind == OriginKind::Line).then_some(u64::from(origin));
                return Err(FormatError::maybe_at(
                    line,
                    format!("face {f} index {bad} is out of range ({n} vertices)"),
                ));
            }
        }
        Err(FormatError::new(format!("a face index is out of range ({n} vertices)")))
    }
}

fn origin32(origin: u64) -> u32 {
    u32::try_from(origin).unwrap_or(u32::MAX)
}

/// Whitespace of the text formats (a newline is whitespace too).
fn is_space(c: u8) -> bool {
    matches!(c, b' ' | b'\t' | b'\r' | b'\n' | 0x0b | 0x0c)
}

/// A token as it can be shown in a message: lossy UTF-8, at most 40 characters.
/// A token of the file as an error message quotes it: at most 40
/// characters (then `…`), control characters escaped (`\u{1b}`), so that
/// a file cannot fill or drive the terminal the message goes to.
pub(crate) fn show(tok: &[u8]) -> String {
    let s = String::from_utf8_lossy(tok);
    let mut shown = String::new();
    for (i, c) in s.chars().enumerate() {
        if i == 40 {
            shown.push('…');
            break;
        }
        if c.is_control() {
            shown.extend(c.escape_debug());
        } else {
            shown.push(c);
        }
    }
    shown
}

fn parse_f64(tok: &[u8]) -> Option<f64> {
    super::number::parse_f64(tok)
}

/// An integer, also written as an integral decimal ("3.0").
fn parse_int(tok: &[u8]) -> Option<i64> {
    if let Some(v) = super::number::short_integer(tok) {
        return Some(v);
    }
    let s = std::str::from_utf8(tok).ok()?;
    if let Ok(v) = s.parse::<i64>() {
        return Some(v);
    }
    let f: f64 = s.parse().ok()?;
    (f.is_finite() && f.fract() == 0.0 && f.abs() < 9.0e15).then_some(f as i64)
}

/// A whitespace-separated token reader over text that keeps the line number.
struct Tokens<'a> {
    data: &'a [u8],
    pos: usize,
    /// The 1-based line of `pos`.
    line: u64,
}

impl<'a> Tokens<'a> {
    fn new(data: &'a [u8], pos: usize, line: u64) -> Self {
        Tokens {
            data,
            pos: pos.min(data.len()),
            line,
        }
    }

    /// The next token and its line, or None at the end.
    fn next(&mut self) -> Option<(&'a [u8], u64)> {
        let d = self.data;
        let mut p = self.pos;
        while p < d.len() {
            match d[p] {
                b'\n' => self.line += 1,
                b' ' | b'\t' | b'\r' | 0x0b | 0x0c => {}
                _ => break,
            }
            p += 1;
        }
        let start = p;
        while p < d.len() && !is_space(d[p]) {
            p += 1;
        }
        self.pos = p;
        (p > start).then(|| (&d[start..p], self.line))
    }

    /// Whether nothing but blanks is left on the current line.
    fn line_is_done(&self) -> bool {
        let rest = &self.data[self.pos..];
        let end = rest.iter().position(|&c| c == b'\n').unwrap_or(rest.len());
        rest[..end].iter().all(|&c| is_space(c))
    }

    /// Skips past the end of the current line.
    fn skip_line(&mut self) {
        match self.data[self.pos..].iter().position(|&c| c == b'\n') {
            Some(i) => {
                self.pos += i + 1;
                self.line += 1;
            }
            None => self.pos = self.data.len(),
        }
    }

    fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }
}

/// A line reader for OFF (and sniffing): strips `#` comments and skips blank lines.
struct Lines<'a> {
    data: &'a [u8],
    pos: usize,
    /// Lines read so far (the 1-based number of the last one).
    line: u64,
}

impl<'a> Lines<'a> {
    fn new(data: &'a [u8]) -> Self {
        Lines { data, pos: 0, line: 0 }
    }

    /// The next line with something other than whitespace and comments, and its number.
    fn next_meaningful(&mut self) -> Option<(u64, &'a [u8])> {
        while self.pos < self.data.len() {
            let rest = &self.data[self.pos..];
            let end = rest.iter().position(|&c| c == b'\n').unwrap_or(rest.len());
            self.pos += (end + 1).min(rest.len());
            self.line += 1;
            let mut line = &rest[..end];
            if let Some(hash) = comment_start(line) {
                line = &line[..hash];
            }
            if !line.iter().all(|&c| is_space(c)) {
                return Some((self.line, line));
            }
        }
        None
    }

    fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }
}

fn words(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|&c| is_space(c)).filter(|w| !w.is_empty())
}

// ---------------------------------------------------------------------------
// OFF
// ---------------------------------------------------------------------------

/// What the prefixes of an OFF keyword say (`[ST][C][N][4][n]OFF`): the
/// vertex lines give texture coordinates (`ST`), a colour (`C`) and a
/// normal (`N`) after x y z, in the order normal, colour, texture
/// coordinates.
#[derive(Clone, Copy, Default)]
struct OffKeyword {
    four: bool,
    ndim: bool,
    texcoords: bool,
    color: bool,
    normal: bool,
}

fn off_keyword(tok: &[u8]) -> Option<OffKeyword> {
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

    /// Reads what follows vertex `i`'s coordinates on its line.
    fn vertex<'a>(&mut self, rest: impl Iterator<Item = &'a [u8]>, i: usize, line: u64) {
        if self.normals.is_none() && self.colors.is_none() && self.texcoords.is_none() {
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
                format!("vertex {i} {what} `{}` is not a number", show(w))
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
pub(crate) fn off_colors_are_bytes(values: &[f64]) -> bool {
    values.iter().all(|&x| x.fract() == 0.0 && (0.0..=255.0).contains(&x)) && values.iter().any(|&x| x > 1.0)
}

/// The vertex count glued to the keyword of a header such as `OFF490 518 0` (written so by the
/// tool that made the ModelNet datasets): the digits after `OFF`, if nothing else follows it.
fn glued_vertex_count(head: &[u8]) -> Option<&[u8]> {
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

    for i in 0..nv {
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
            *c = parse_f64(w)
                .ok_or_else(|| FormatError::at(line, format!("vertex {i} coordinate `{}` is not a number", show(w))))?;
        }
        b.vertex(p, line, || format!("vertex {i}"))?;
        attributes.vertex(ws, i, line);
    }

    for f in 0..nf {
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
            let i = parse_int(w)
                .ok_or_else(|| FormatError::at(line, format!("face {f} index `{}` is not an integer", show(w))))?;
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
        m.notes.push(format!(
            "line {line}: data after the {nf} faces the OFF header declares ignored (if its counts are wrong, faces are missing)"
        ));
    }
    Ok(m)
}

/// An index read from a file as u32: negative or too large is an error naming face `f`.
fn checked_index(i: i64, f: usize, line: Option<u64>, vertices: usize) -> Result<u32, FormatError> {
    if i < 0 {
        return Err(FormatError::maybe_at(line, format!("face {f} index {i} is negative")));
    }
    u32::try_from(i).map_err(|_| {
        FormatError::maybe_at(
            line,
            format!("face {f} index {i} is out of range ({vertices} vertices)"),
        )
    })
}

// ---------------------------------------------------------------------------
// PLY
// ---------------------------------------------------------------------------

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

/// Reads `N` bytes (`s.len()` must be `N`, which the callers guarantee) in the given byte order.
macro_rules! decode {
    ($ty:ty, $s:expr, $big:expr) => {{
        let mut a = [0u8; std::mem::size_of::<$ty>()];
        a.copy_from_slice($s);
        if $big {
            <$ty>::from_be_bytes(a)
        } else {
            <$ty>::from_le_bytes(a)
        }
    }};
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
        "tristrips" if el.count > 0 => Err(FormatError::at(
            el.line,
            "PLY triangle strips (element tristrips) are not supported",
        )),
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
            for (el, (kind, roles)) in header.elements.iter().zip(&plans) {
                read_ascii_element(&mut tokens, el, roles, *kind, &mut b)?;
            }
            if let Some((_, line)) = tokens.next() {
                trailing = Some(format!("line {line}: data"));
            }
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
struct VertexChannels {
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
        for p in self.face_properties {
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
        ElementKind::Other => Ok(()),
    }
}

fn read_ascii_element(
    t: &mut Tokens,
    el: &PlyElement,
    roles: &[Role],
    kind: ElementKind,
    b: &mut Builder,
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
    // Reserve for the shortest real records: "0 0 0\n" and "3 0 1 2\n".
    match kind {
        ElementKind::Vertex => b.reserve_vertices(count.min(remaining / 6 + 1)),
        ElementKind::Face => b.reserve_faces(count.min(remaining / 8 + 1), count.saturating_mul(3).min(remaining / 2)),
        ElementKind::Other => {}
    }
    let name = &el.name;
    for i in 0..count {
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
                        None => Err("is not a number".to_owned()),
                    };
                    let what = |why: String| format!("{name} {i} property {}: `{}` {why}", p.name, show(tok));
                    match (*role, value) {
                        (Role::Coord(axis), Ok(x)) => v.p[axis] = x,
                        (Role::Color(c), Ok(x)) => v.set_color(c, x, ty),
                        (Role::TexCoord(k), Ok(x)) => v.texcoord[k] = x,
                        (Role::Normal(k), Ok(x)) => v.normal[k] = x,
                        (Role::TexNumber, Ok(x)) => v.texnumber = Some(x as i64),
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
                                FormatError::at(line, format!("face {i} index `{}` is not an integer", show(tok)))
                            })?;
                            let index = checked_index(index, i, Some(line), b.m.positions.len())?;
                            if let Some(why) = item.int_misfit(index.into()) {
                                return Err(FormatError::at(line, format!("face {i} index `{}` {why}", show(tok))));
                            }
                            b.index(index);
                        }
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
        ElementKind::Other => {}
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

// ---------------------------------------------------------------------------
// STL
// ---------------------------------------------------------------------------

/// Whether the text starts (after whitespace) with the word `solid`.
fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes.iter().position(|&c| !is_space(c)).unwrap_or(bytes.len());
    let rest = &bytes[start..];
    rest.len() >= 5 && rest[..5].eq_ignore_ascii_case(b"solid") && rest.get(5).is_none_or(|&c| is_space(c))
}

/// For a binary STL: the facet count and the file size it implies, or None if shorter than 84 bytes.
fn binary_stl_size(bytes: &[u8]) -> Option<(u32, u64)> {
    let n = u32::from_le_bytes(bytes.get(80..84)?.try_into().ok()?);
    Some((n, 84 + 50 * u64::from(n)))
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
                            format!("facet {facet} vertex {k} coordinate `{}` is not a number", show(tok)),
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
// Writers
// ---------------------------------------------------------------------------

fn invalid(what: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, what)
}

/// Refuses what no reader would take back: non-finite positions, out-of-range indices, a colour count
/// that is not the vertex count. (Every writer's first step: one pass over the arrays without a branch
/// per value, then a search for the culprit only if there is one.)
pub(crate) fn check_for_writing(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colors: Option<&[[u8; 3]]>,
) -> io::Result<()> {
    let finite = positions.iter().flatten().fold(true, |ok, c| ok & c.is_finite());
    if !finite {
        let i = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
            .unwrap_or(0);
        return Err(invalid(format!("vertex {i} has a non-finite coordinate")));
    }
    let n = positions.len();
    if n > u32::MAX as usize {
        return Err(invalid(format!(
            "{n} vertices are more than 32-bit indices can address"
        )));
    }
    let largest = triangles.iter().flatten().fold(0u32, |m, &i| m.max(i));
    if !triangles.is_empty() && largest as usize >= n {
        let f = triangles
            .iter()
            .position(|t| t.iter().any(|&i| i as usize >= n))
            .unwrap_or(0);
        return Err(invalid(format!(
            "triangle {f} has an index out of range ({n} vertices)"
        )));
    }
    if let Some(c) = colors {
        if c.len() != n {
            return Err(invalid(format!("{} colours for {n} vertices", c.len())));
        }
    }
    Ok(())
}

/// Writes an OFF file; coordinates in shortest round-trip form, so that [`read_off`] gives them back bit
/// for bit. Non-finite coordinates and out-of-range indices are refused (`InvalidInput`).
pub fn write_off(w: &mut dyn Write, positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> io::Result<()> {
    write_off_with(w, positions, triangles, &OffExtras::default())
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
    let mut w = BufWriter::new(w);
    let mut num = zmij::Buffer::new();
    let keyword = [
        (extras.texcoords.is_some(), "ST"),
        (extras.colors.is_some(), "C"),
        (extras.normals.is_some(), "N"),
    ];
    for (has, prefix) in keyword {
        if has {
            w.write_all(prefix.as_bytes())?;
        }
    }
    writeln!(w, "OFF\n{n} {nf} 0")?;
    for (i, p) in positions.iter().enumerate() {
        write_xyz(&mut w, &mut num, p)?;
        if let Some(normals) = &extras.normals {
            write_numbers(&mut w, &mut num, &normals[3 * i..3 * i + 3])?;
        }
        if let Some(c) = &extras.colors {
            write_color(&mut w, &mut num, c, i)?;
        }
        if let Some(st) = &extras.texcoords {
            write_numbers(&mut w, &mut num, &st[2 * i..2 * i + 2])?;
        }
        w.write_all(b"\n")?;
    }
    for (f, t) in triangles.iter().enumerate() {
        write!(w, "3 {} {} {}", t[0], t[1], t[2])?;
        if let Some(c) = &extras.face_colors {
            write_color(&mut w, &mut num, c, f)?;
        }
        w.write_all(b"\n")?;
    }
    w.flush()
}

/// Writes " a b ..." in shortest round-trip form (the numbers are finite).
fn write_numbers(w: &mut dyn Write, num: &mut zmij::Buffer, values: &[f64]) -> io::Result<()> {
    for &x in values {
        w.write_all(b" ")?;
        w.write_all(num.format_finite(x).as_bytes())?;
    }
    Ok(())
}

/// Writes " r g b [a]", colour `i` of `c`.
fn write_color(w: &mut dyn Write, num: &mut zmij::Buffer, c: &OffColors, i: usize) -> io::Result<()> {
    for &x in &c.values[c.dim * i..c.dim * (i + 1)] {
        match c.text {
            // (`as` saturates; the values are finite.)
            ColorText::Bytes => write!(w, " {}", x.round().clamp(0.0, 255.0) as u8)?,
            ColorText::Floats => {
                let text = num.format_finite(x);
                w.write_all(b" ")?;
                match text.find(['.', 'e', 'E']) {
                    Some(at) if text.as_bytes()[at] == b'.' => w.write_all(text.as_bytes())?,
                    Some(at) => write!(w, "{}.0{}", &text[..at], &text[at..])?,
                    None => write!(w, "{text}.0")?,
                }
            }
        }
    }
    Ok(())
}

/// Writes "x y z" in shortest round-trip form (the coordinates are finite).
fn write_xyz(w: &mut dyn Write, num: &mut zmij::Buffer, p: &[f64; 3]) -> io::Result<()> {
    for (k, &c) in p.iter().enumerate() {
        if k > 0 {
            w.write_all(b" ")?;
        }
        w.write_all(num.format_finite(c).as_bytes())?;
    }
    Ok(())
}

fn ply_header(w: &mut dyn Write, format: &str, vertices: usize, triangles: usize, colors: bool) -> io::Result<()> {
    write!(
        w,
        "ply\nformat {format} 1.0\ncomment written by delmesh\nelement vertex {vertices}\n"
    )?;
    w.write_all(b"property double x\nproperty double y\nproperty double z\n")?;
    if colors {
        w.write_all(b"property uchar red\nproperty uchar green\nproperty uchar blue\n")?;
    }
    write!(
        w,
        "element face {triangles}\nproperty list uchar uint vertex_indices\nend_header\n"
    )
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
    if let Some(c) = comments.iter().find(|c| c.contains(['\n', '\r'])) {
        return Err(invalid(format!("a PLY comment cannot hold a line break: {c:?}")));
    }
    check_for_writing(positions, triangles, None)?;
    for (columns, n, what) in [
        (columns, positions.len(), "vertices"),
        (face_columns, triangles.len(), "faces"),
    ] {
        if let Some(c) = columns.iter().find(|c| c.values.len() != n) {
            return Err(invalid(format!(
                "{} values of {} for {n} {what}",
                c.values.len(),
                c.name
            )));
        }
        if let Some(c) = columns.iter().find(|c| !ply_name_is_one_word(&c.name)) {
            return Err(invalid(format!("a PLY property name must be one word: {:?}", c.name)));
        }
    }
    let mut w = BufWriter::new(w);
    write!(w, "ply\nformat binary_little_endian 1.0\ncomment written by delmesh\n",)?;
    for c in comments {
        writeln!(w, "comment {c}")?;
    }
    writeln!(w, "element vertex {}", positions.len())?;
    w.write_all(b"property double x\nproperty double y\nproperty double z\n")?;
    for c in columns {
        writeln!(w, "property {} {}", c.ty.ply_name(), c.name)?;
    }
    write!(
        w,
        "element face {}\nproperty list uchar uint vertex_indices\n",
        triangles.len()
    )?;
    for c in face_columns {
        writeln!(w, "property {} {}", c.ty.ply_name(), c.name)?;
    }
    w.write_all(b"end_header\n")?;
    let mut record = Vec::with_capacity(24 + 8 * columns.len().max(face_columns.len()));
    for (i, p) in positions.iter().enumerate() {
        record.clear();
        for c in p {
            record.extend_from_slice(&c.to_le_bytes());
        }
        for c in columns {
            c.ty.put_le(c.values[i], &mut record);
        }
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
    let mut w = BufWriter::new(w);
    ply_header(&mut w, "ascii", positions.len(), triangles.len(), colors.is_some())?;
    let mut num = zmij::Buffer::new();
    for (i, p) in positions.iter().enumerate() {
        write_xyz(&mut w, &mut num, p)?;
        if let Some([r, g, b]) = colors.and_then(|c| c.get(i)) {
            write!(w, " {r} {g} {b}")?;
        }
        w.write_all(b"\n")?;
    }
    for t in triangles {
        writeln!(w, "3 {} {} {}", t[0], t[1], t[2])?;
    }
    w.flush()
}

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
