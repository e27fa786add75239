//! Readers and writers for OFF (`off.rs`), PLY (`ply.rs`) and STL (`stl.rs`)
//! meshes, and gzip input; here what they share: the mesh as read
//! ([`RawMesh`]), errors, format detection, tokenizing.
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
use crate::io::lines::push_xyz;

/// Reads `N` bytes (`s.len()` must be `N`, which the callers guarantee) in the given byte order
/// (binary PLY and STL).
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

mod foreign;
mod off;
mod ply;
mod stl;

pub use foreign::foreign_reason;
pub use off::{color_byte, read_off, write_off, write_off_after, write_off_with, ColorText, OffColors, OffExtras};
use off::{glued_vertex_count, off_keyword};
use ply::VertexChannels;
pub use ply::{read_ply, write_ply_ascii, write_ply_binary, write_ply_binary_columns, PlyColumn};
pub(crate) use ply::{write_ply_binary_records, VertexRecords};
use stl::{binary_stl_size, starts_with_solid};
pub use stl::{read_stl, write_stl_binary};

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
    pub(crate) fn new(what: impl Into<String>) -> Self {
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
        Start::Refused(_) if is_utf16_text(out) => return Ok(Some(UTF16_REASON.to_owned())),
        Start::Refused(what) => {
            // A known kind is named; other binary data keeps this reason.
            let why = foreign_reason(None, out, false)
                .unwrap_or_else(|| format!("not {what}: its first 64 KiB cannot start one"));
            return Ok(Some(why));
        }
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

/// What to add to "is not a number" for a word `tok` with commas in it: for
/// a number written with a decimal comma (`0,5`, as some locales' exporters
/// write numbers) or numbers separated by commas (`1.5,2,3`), a hint; else
/// nothing.
pub(crate) fn decimal_comma_hint(tok: &[u8]) -> &'static str {
    let digits = |w: &[u8]| !w.is_empty() && w.iter().all(u8::is_ascii_digit);
    let unsigned = tok.strip_prefix(b"-").or_else(|| tok.strip_prefix(b"+")).unwrap_or(tok);
    match unsigned.iter().position(|&b| b == b',') {
        Some(k) if digits(&unsigned[..k]) && digits(&unsigned[k + 1..]) => {
            " (a decimal comma? numbers need a decimal point: 0.5, not 0,5)"
        }
        Some(_) if tok.split(|&b| b == b',').all(|w| parse_f64(w).is_some()) => {
            " (numbers separated by commas? separate them by spaces)"
        }
        _ => "",
    }
}

/// Why a file of UTF-16 text is refused, and what to do ([`is_utf16_text`]).
pub const UTF16_REASON: &str = "the file is UTF-16 text (as Windows PowerShell's `>` writes it), and delmesh \
     reads ASCII or UTF-8 text: convert it first, e.g. `iconv -f UTF-16 -t UTF-8 FILE > NEW`";

/// Whether `bytes` look like UTF-16 text: ASCII characters each with a
/// zero byte after it (little-endian) or before it (big-endian), after a
/// UTF-16 byte order mark if there is one. Asked only of a file that a
/// reader refused, to say why in terms its writer can act on.
pub fn is_utf16_text(bytes: &[u8]) -> bool {
    let text = bytes
        .strip_prefix(b"\xFF\xFE")
        .or_else(|| bytes.strip_prefix(b"\xFE\xFF"))
        .unwrap_or(bytes);
    let head = &text[..text.len().min(64) & !1];
    if head.len() < 4 {
        return false;
    }
    let ascii = |b: u8| matches!(b, b'\t' | b'\n' | b'\r' | 0x20..=0x7e);
    let mut pairs = head.chunks_exact(2);
    pairs.clone().all(|p| ascii(p[0]) && p[1] == 0) || pairs.all(|p| p[0] == 0 && ascii(p[1]))
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

/// A token of plain digits at the start of `bytes`, at most 10 of them (any
/// value below 2^32), followed by a blank, a line end or the end: its value
/// and length, the value [`parse_int`] gives it: an index or count of a
/// plain record or line (ASCII PLY, OFF). More digits, a sign or anything
/// else: `None`, for the reader's general way.
#[inline(always)]
fn plain_digits(bytes: &[u8]) -> Option<(i64, usize)> {
    let mut v: i64 = 0;
    let mut len = 0;
    while let Some(&c) = bytes.get(len) {
        let digit = c.wrapping_sub(b'0');
        if digit > 9 {
            break;
        }
        if len == 10 {
            return None;
        }
        v = v * 10 + i64::from(digit);
        len += 1;
    }
    (len > 0 && bytes.get(len).is_none_or(|&c| is_space(c))).then_some((v, len))
}

/// The first position from `p` on that is not a blank of a line (a line
/// end, a token or the end of `d`): the plain paths' step between tokens.
#[inline]
fn skip_blanks(d: &[u8], mut p: usize) -> usize {
    while p < d.len() && matches!(d[p], b' ' | b'\t' | b'\r' | 0x0b | 0x0c) {
        p += 1;
    }
    p
}

/// Whether nothing but blanks follows position `p` of `d` on its line (as
/// `Tokens::line_is_done`): the end of a plain record or line.
#[inline]
fn line_is_blank(d: &[u8], p: usize) -> bool {
    let p = skip_blanks(d, p);
    p == d.len() || d[p] == b'\n'
}

/// What the text readers' tests put among plain values, lines and
/// records: blanks, line ends, numbers in the forms the one-scan paths must
/// read as the general way does or leave to it (signs, points, exponents,
/// Windows' specials, padded, long, past 2^31, 2^32 and 2^53), comments
/// and words.
#[cfg(test)]
pub(crate) const ODD_TEXT_PIECES: &[&str] = &[
    " ",
    "\t",
    "\r",
    "\x0c",
    "\n",
    "",
    "#",
    "# c",
    "1",
    "-2.5",
    "+0.125",
    "7.",
    ".5",
    "-.5",
    "0",
    "-0",
    "-1",
    "2",
    "3",
    "3.0",
    "1.5",
    "1e3",
    "1.#INF",
    "nan",
    "inf",
    "x",
    "255",
    "256",
    "65536",
    "2147483648",
    "4294967295",
    "4294967296",
    "00000000003",
    "0000000003",
    "123456789012345678",
    "1234567890123456789",
    "12345678901234567890",
    "9007199254740993",
    "0.1234567890123456789012",
];

/// Appends `words` to `text` as a line made a little odd, for the
/// readers' tests: one time in `one_in` a word swapped for one of
/// [`ODD_TEXT_PIECES`], one time in `2 * one_in` one added, and as often
/// the last dropped; the words separated by random blanks (with `breaks`,
/// a line end one time in 40, so that a record runs over two lines; with
/// `lead`, a blank before the first one time in 10); then `line_end`, or
/// one time in 30 a blank line, nothing or CRLF.
#[cfg(test)]
pub(crate) fn push_odd_line(
    rng: &mut crate::test_rng::Rng,
    mut words: Vec<String>,
    text: &mut String,
    line_end: &str,
    (one_in, lead, breaks): (u64, bool, bool),
) {
    let pick = |rng: &mut crate::test_rng::Rng, from: &[&'static str]| from[rng.below(from.len() as u64) as usize];
    if rng.below(one_in) == 0 {
        let k = rng.below(words.len() as u64) as usize;
        words[k] = pick(rng, ODD_TEXT_PIECES).into();
    }
    if rng.below(2 * one_in) == 0 {
        words.push(pick(rng, ODD_TEXT_PIECES).into());
    }
    if rng.below(2 * one_in) == 0 {
        words.pop();
    }
    for (k, w) in words.iter().enumerate() {
        if k > 0 || (lead && rng.below(10) == 0) {
            let line_break = breaks && k > 0 && rng.below(40) == 0;
            text.push_str(if line_break {
                "\n"
            } else {
                pick(rng, &[" ", " ", " ", "\t", "  ", "\x0b"])
            });
        }
        text.push_str(w);
    }
    text.push_str(if rng.below(30) == 0 {
        pick(rng, &["\n\n", "", "\r\n"])
    } else {
        line_end
    });
}

/// Reads `text` both ways, `read(text, true)` (with a reader's one-scan
/// path) and `read(text, false)` (the general way alone), asserts the same
/// outcome (compared as `Debug`, so that NaN and the sign of zero count),
/// and says whether the file was read (not refused).
#[cfg(test)]
pub(crate) fn read_alike<T: std::fmt::Debug, E: std::fmt::Debug>(
    text: &str,
    read: impl Fn(&[u8], bool) -> Result<T, E>,
) -> bool {
    let (fast, general) = (read(text.as_bytes(), true), read(text.as_bytes(), false));
    assert_eq!(format!("{fast:?}"), format!("{general:?}"), "{text:?}");
    fast.is_ok()
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

    /// Moves the cursor past the end of the line that position `p` is on
    /// (counting it), as [`Lines::next_meaningful`] does past a line.
    #[inline]
    fn skip_line_at(&mut self, p: usize) {
        let end = p + self.data[p..]
            .iter()
            .position(|&c| c == b'\n')
            .unwrap_or(self.data.len() - p);
        self.pos = (end + 1).min(self.data.len());
        self.line += 1;
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
// What the writers share
// ---------------------------------------------------------------------------

/// The error of a writer asked to write what no reader would take back.
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
    check_positions_for_writing(positions)?;
    let n = positions.len();
    check_indices_for_writing(n, triangles)?;
    if let Some(c) = colors {
        if c.len() != n {
            return Err(invalid(format!("{} colours for {n} vertices", c.len())));
        }
    }
    Ok(())
}

/// The positions part of [`check_for_writing`]: every coordinate finite.
pub(crate) fn check_positions_for_writing(positions: &[[f64; 3]]) -> io::Result<()> {
    let finite = positions.iter().flatten().fold(true, |ok, c| ok & c.is_finite());
    if !finite {
        let i = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
            .unwrap_or(0);
        return Err(invalid(format!("vertex {i} has a non-finite coordinate")));
    }
    Ok(())
}

/// The indices part of [`check_for_writing`]: `n`, the count of vertices
/// written, at most what 32-bit indices address, and every index of
/// `triangles` below it.
pub(crate) fn check_indices_for_writing(n: usize, triangles: &[[u32; 3]]) -> io::Result<()> {
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
    Ok(())
}
