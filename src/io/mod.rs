//! Reading and writing meshes.
//!
//! Formats: OBJ (delmesh's own reader, [`obj`]), OFF, PLY (ASCII and binary,
//! either endianness) and STL (ASCII and binary) ([`formats`]), chosen by the
//! file's extension or, where that says nothing, by its content; any of them
//! may be gzip-compressed. Every reader produces a [`RawMesh`] of polygons;
//! [`finish`] turns it into the [`InputMesh`] the algorithm takes: polygons
//! fan-triangulated (from the first corner that sees the whole polygon:
//! [`polygon`]), bit-identical positions welded, unused vertices dropped,
//! and every refusal of SPEC §6 naming the file and the offending line, face
//! or vertex. With `--repair` ([`crate::repair`]) the refusable defects are
//! fixed instead.
//!
//! Writing is atomic: a temporary file in the target's directory, renamed
//! over the target only once it is complete.

pub mod formats;
pub mod number;
pub mod obj;
pub mod polygon;
pub mod temporary;

use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use glam::DVec3;

pub use formats::{Format, FormatError, Numbering, OriginKind, PlyColumn, RawMesh};

use crate::attributes::{
    properties_named, AttributeCuts, Attributes, Channel, Kind, PerVertex, Tolerances, ValueType, NO_VALUE,
};
use crate::error::{Error, Result};
use crate::geometry;
use crate::mesh::{room_for_splits, NoCuts, RegionCuts, Surface, Topology, TopologyError};
use crate::repair::{self, RepairOptions, RepairReport};

/// The largest decompressed size accepted from a `.gz` input (16 GiB).
const MAX_DECOMPRESSED: u64 = 16 << 30;

/// The largest coordinate magnitude accepted: beyond it, the products of four
/// coordinates that the geometry computes would overflow an f64.
pub const MAX_COORDINATE: f64 = 1e75;

/// Whether every coordinate of `p` is finite and within ±[`MAX_COORDINATE`].
#[inline]
pub fn in_supported_range(p: DVec3) -> bool {
    // (`max_element` passes NaN over: finiteness is asked first.)
    p.is_finite() & (p.abs().max_element() <= MAX_COORDINATE)
}

/// The shortest edge accepted: below it, those products would underflow.
pub const MIN_EDGE: f64 = 1e-75;

/// Whether every edge of the triangle `a b c` is at least [`MIN_EDGE`]
/// long: what the readers, [`build_surface_with`] and
/// [`crate::Surface::new`] require of every triangle.
#[inline]
pub fn edges_in_supported_scale(a: DVec3, b: DVec3, c: DVec3) -> bool {
    // Compared squared (no root per edge): MIN_EDGE² is a normal number.
    let shortest = (b - a)
        .length_squared()
        .min((c - b).length_squared())
        .min((a - c).length_squared());
    shortest >= MIN_EDGE * MIN_EDGE
}

/// The message for a triangle with an edge shorter than [`MIN_EDGE`],
/// after the name of its face.
pub(crate) fn short_edge_text() -> String {
    format!("has an edge shorter than {MIN_EDGE:e}, below the supported scale")
}

/// Appended to refusals that `--repair` would fix.
const REPAIR_HINT: &str = " (--repair would fix this)";

/// A mesh as read from a file, ready for [`build_surface`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InputMesh {
    /// Vertex positions: welded, each used by some face, in file order.
    pub positions: Vec<DVec3>,
    /// Triangles (polygons fan-triangulated), indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Where the face of each triangle is in the file: a 1-based line for
    /// text formats, a record number for binary ones (see `origin_kind`).
    pub triangle_origin: Vec<u32>,
    /// 1-based number of each vertex in the file (its first definition).
    pub vertex_number: Vec<u32>,
    /// The face of the file each triangle was cut from, numbered from 0
    /// (the triangles of one face are consecutive), when the file has
    /// attributes: its polygons are then flipped inside whatever their
    /// values ([`crate::mesh::RegionCuts::polygon`]). Empty otherwise, and
    /// in a mesh made by a caller: each triangle a face of its own.
    pub triangle_polygon: Vec<u32>,
    /// How `triangle_origin` counts.
    pub origin_kind: OriginKind,
    /// How the file numbers its vertices and faces, for messages.
    pub numbering: Numbering,
    /// Faces in the file (before triangulation).
    pub faces_in_file: usize,
    /// Vertices merged into an earlier one at the bit-identical position.
    pub welded: usize,
    /// Vertices no face uses (dropped).
    pub unreferenced: usize,
    /// What `--repair` fixed, if it ran.
    pub repair: Option<RepairReport>,
    /// Texture coordinates, normals, colours per corner of `triangles`;
    /// groups per triangle; material libraries.
    pub attributes: Attributes,
    /// What the reader ignored or read otherwise than the file says, and
    /// why attributes of the file were left out (one line each).
    pub notes: Vec<String>,
    /// The connectivity of `triangles`, when reading built it on the way
    /// (`--repair` builds it to learn that a mesh needs no more than welding
    /// and dropping degenerate faces: [`repair::repair_with_topology`]);
    /// [`build_surface`] takes it instead of building it again.
    pub topology: Option<Topology>,
}

impl InputMesh {
    /// Vertex `v` (an index into `positions`) as a message names it: by its
    /// number in the file, counted as the format counts
    /// ([`Numbering::vertex`]).
    pub fn vertex_name(&self, v: u32) -> String {
        let in_file = self.vertex_number.get(v as usize).map_or(v, |&n| n.saturating_sub(1));
        let at = self.positions.get(v as usize).map_or([f64::NAN; 3], |p| p.to_array());
        self.numbering.vertex(in_file, at)
    }
}

/// How to read an input.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReadOptions {
    /// Repair instead of refusing defects (`--repair`).
    pub repair: Option<RepairOptions>,
    /// Leave texture coordinates, normals, colours and groups out, and
    /// their notes (`--drop-attributes`); the reader's other notes stay.
    pub drop_attributes: bool,
}

type FxMap<K, V> = crate::hash::FastMap<K, V>;

/// The format of `path`: by extension (looking through `.gz`), else by content.
pub fn detect_format(path: &Path, bytes: &[u8]) -> Option<Format> {
    path.file_name()
        .and_then(|n| n.to_str())
        .and_then(formats::format_from_name)
        .or_else(|| formats::sniff_format(bytes))
}

/// Reads a mesh file of any supported format with default options (no repair).
pub fn read_obj(path: &Path) -> Result<InputMesh> {
    read_mesh(path, &ReadOptions::default())
}

/// Reads a mesh file of any supported format.
pub fn read_mesh(path: &Path, options: &ReadOptions) -> Result<InputMesh> {
    let raw = read_raw(path)?;
    finish(raw, path, options)
}

/// `raw` without its attributes and their notes if `options` drop them.
fn without_attributes_if_dropped(mut raw: RawMesh, options: &ReadOptions) -> RawMesh {
    if options.drop_attributes {
        raw.attributes = Attributes::default();
        raw.colors = None;
        raw.attribute_notes.clear();
    }
    raw
}

/// Reads a mesh file into polygons, without welding or validation.
pub fn read_raw(path: &Path) -> Result<RawMesh> {
    let bytes = read_bytes(path).map_err(|source| Error::Read {
        path: path.to_owned(),
        source,
    })?;
    let named = path.to_str().and_then(formats::format_from_name);
    let bytes = formats::gunzip_judged(&bytes, MAX_DECOMPRESSED, named).map_err(|e| format_error(path, e))?;
    let format = detect_format(path, &bytes).unwrap_or(Format::Obj);
    let read = |format| match format {
        Format::Obj => obj::parse_obj(&bytes),
        Format::Off => formats::read_off(&bytes),
        Format::Ply => formats::read_ply(&bytes),
        Format::Stl => formats::read_stl(&bytes),
    };
    read(format).map_err(|e| match misnamed(named, &bytes, read) {
        Some(what) => Error::Mesh {
            path: path.to_owned(),
            what,
        },
        None => format_error(path, e),
    })
}

/// Why a file that its name's format (`named`) refuses is misnamed: its
/// content is a file of another format, which that format's reader
/// (`read`) takes. The named reader's own reason says nothing useful then
/// (a binary PLY named `.obj` had lines ending in a carriage return alone,
/// any text named `.stl` a header declaring a billion facets).
fn misnamed(
    named: Option<Format>,
    bytes: &[u8],
    read: impl Fn(Format) -> std::result::Result<RawMesh, formats::FormatError>,
) -> Option<String> {
    let named = named?;
    let content = formats::sniff_format(bytes).filter(|&f| f != named)?;
    read(content).ok()?;
    Some(format!(
        "not {} {} file: {}",
        if named == Format::Ply { "a" } else { "an" },
        named.name(),
        content.misnamed_reason()
    ))
}

/// The bytes of the file `path`, or of standard input to its end if `path`
/// names it ([`is_standard_input`]). What is not a regular file (a pipe,
/// a device) is read to its end only if its first bytes may start a mesh
/// (see `formats::judge_start`): `/dev/zero` is refused at once.
pub fn read_bytes(path: &Path) -> std::io::Result<Vec<u8>> {
    let named = path.to_str().and_then(formats::format_from_name);
    if is_standard_input(path) {
        return read_stream(std::io::stdin().lock(), named);
    }
    let file = std::fs::File::open(path)?;
    match file.metadata() {
        Ok(m) if m.is_file() => {
            let mut bytes = Vec::with_capacity(usize::try_from(m.len()).unwrap_or(0).saturating_add(1));
            (&file).read_to_end(&mut bytes)?;
            Ok(bytes)
        }
        _ => read_stream(file, named),
    }
}

/// All of `reader`, unless its first bytes say it is no mesh (then an
/// `InvalidData` error saying why: [`formats::read_judged`]).
fn read_stream(reader: impl Read, named: Option<Format>) -> std::io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    match formats::read_judged(reader, named, &mut bytes)? {
        None => Ok(bytes),
        Some(why) => Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("{why} (reading stopped there)"),
        )),
    }
}

/// Parses OBJ text; `path` only names the file in errors.
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<InputMesh> {
    let raw = obj::parse_obj(bytes).map_err(|e| format_error(path, e))?;
    finish(raw, path, &ReadOptions::default())
}

fn format_error(path: &Path, e: FormatError) -> Error {
    match e.line {
        Some(line) => Error::Syntax {
            path: path.to_owned(),
            line: line as usize,
            what: e.what,
        },
        None => Error::Mesh {
            path: path.to_owned(),
            what: e.what,
        },
    }
}

/// Error about face `f` of `raw`, located by line or record.
fn face_error(path: &Path, raw: &RawMesh, f: usize, what: String) -> Error {
    let origin = raw.face_origin.get(f).copied().unwrap_or(f as u32);
    match raw.origin_kind {
        OriginKind::Line => Error::Syntax {
            path: path.to_owned(),
            line: origin as usize,
            what,
        },
        OriginKind::Record => Error::Mesh {
            path: path.to_owned(),
            what: format!("face record {origin}: {what}"),
        },
    }
}

/// The first vertex that occurs twice in `ids`, if any: a linear scan for
/// small polygons, sorting for large ones (a face may have millions of
/// vertices in a hostile file).
fn repeated_vertex(mut ids: impl ExactSizeIterator<Item = u32>, scratch: &mut Vec<u32>) -> Option<u32> {
    if ids.len() == 3 {
        // A triangle (nearly every face): as the scan below, in three
        // comparisons.
        let [i, j, k] = [(); 3].map(|()| ids.next().expect("three ids"));
        return if i == j {
            Some(j)
        } else {
            (k == i || k == j).then_some(k)
        };
    }
    scratch.clear();
    scratch.extend(ids);
    if scratch.len() <= 16 {
        return scratch
            .iter()
            .enumerate()
            .find(|(i, w)| scratch[..*i].contains(w))
            .map(|(_, &w)| w);
    }
    scratch.sort_unstable();
    scratch.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
}

/// Turns polygons into the algorithm's input: see the module documentation.
pub fn finish(raw: RawMesh, path: &Path, options: &ReadOptions) -> Result<InputMesh> {
    if let Some(repair) = &options.repair {
        repair.validate()?;
    }
    let raw = without_attributes_if_dropped(raw, options);
    let n_faces = raw.face_start.len().saturating_sub(1);
    if n_faces == 0 {
        return Err(Error::Mesh {
            path: path.to_owned(),
            what: "no faces".into(),
        });
    }
    if let Some(v) = raw
        .positions
        .iter()
        .position(|p| p.iter().any(|c| c.abs() > MAX_COORDINATE))
    {
        let what = format!(
            "{} has a coordinate beyond ±{MAX_COORDINATE:e}, the supported range",
            raw.numbering.vertex(v as u32, raw.positions[v])
        );
        let origin = raw.vertex_origin.get(v).copied().unwrap_or(0);
        return Err(match raw.origin_kind {
            OriginKind::Line => Error::Syntax {
                path: path.to_owned(),
                line: origin as usize,
                what,
            },
            OriginKind::Record => Error::Mesh {
                path: path.to_owned(),
                what,
            },
        });
    }
    let poly = |f: usize| &raw.indices[raw.face_start[f] as usize..raw.face_start[f + 1] as usize];
    if let Some(repair_options) = options.repair {
        return finish_repaired(&raw, path, &repair_options);
    }
    // Weld bit-identical positions onto their first occurrence.
    let mut first: FxMap<[u64; 3], u32> = FxMap::default();
    first.reserve(raw.positions.len());
    let welded_to: Vec<u32> = (0..raw.positions.len())
        .map(|i| *first.entry(raw.positions[i].map(f64::to_bits)).or_insert(i as u32))
        .collect();
    let welded = raw.positions.len() - first.len();
    drop(first);
    // Keep used vertices, in file order.
    let mut used = vec![false; raw.positions.len()];
    for &c in &raw.indices {
        used[welded_to[c as usize] as usize] = true;
    }
    let mut new_index = vec![u32::MAX; raw.positions.len()];
    let mut positions = Vec::new();
    let mut vertex_number = Vec::new();
    for (i, p) in raw.positions.iter().enumerate() {
        if used[i] {
            new_index[i] = positions.len() as u32;
            positions.push(DVec3::from_array(*p));
            vertex_number.push(i as u32 + 1);
        }
    }
    let unreferenced = raw.positions.len() - welded - positions.len();
    // Fan-triangulate, refusing repeated vertices and zero-area triangles.
    let mut triangles = Vec::with_capacity(raw.indices.len().saturating_sub(2 * n_faces));
    let mut triangle_origin = Vec::with_capacity(triangles.capacity());
    let mut triangle_face = Vec::new();
    let mut raw_corners = Vec::new();
    let keep_attributes = !raw.attributes.is_empty();
    let mut scratch = Vec::new();
    let mut pieces = Vec::new();
    let mut unseen_polygons = 0;
    // Coordinates checked once for the whole mesh, not per triangle.
    let collinear = geometry::collinear_for(&positions);
    for f in 0..n_faces {
        let p = poly(f);
        let origin = raw.face_origin.get(f).copied().unwrap_or(f as u32);
        if let Some(w) = repeated_vertex(p.iter().map(|&v| welded_to[v as usize]), &mut scratch) {
            let what = format!(
                "{} repeats {} (after welding equal positions){REPAIR_HINT}",
                raw.numbering.face(f),
                raw.numbering.vertex(w, raw.positions[w as usize])
            );
            return Err(face_error(path, &raw, f, what));
        }
        // A fan from the first corner that sees the whole polygon (0 for
        // triangles and convex polygons), or its ears (`polygon::triangulate`).
        unseen_polygons += !polygon::triangulate(p.len(), |i| raw.positions[p[i] as usize], &mut pieces) as usize;
        for &corner in &pieces {
            let t = corner.map(|c| new_index[welded_to[p[c] as usize] as usize]);
            let [a, b, c] = t.map(|v| positions[v as usize]);
            // Below the supported scale first: the Delaunay test's products of
            // lengths would underflow (the exact predicates would not).
            if !edges_in_supported_scale(a, b, c) {
                let what = format!("{} {}", raw.numbering.face(f), short_edge_text());
                return Err(face_error(path, &raw, f, what));
            }
            if collinear(a, b, c) {
                return Err(face_error(
                    path,
                    &raw,
                    f,
                    format!("{} has zero area{REPAIR_HINT}", raw.numbering.face(f)),
                ));
            }
            triangles.push(t);
            triangle_origin.push(origin);
            if keep_attributes {
                let s = raw.face_start[f];
                raw_corners.push(corner.map(|c| s + c as u32));
                triangle_face.push(f as u32);
            }
        }
    }
    let (attributes, mut notes) = triangle_attributes(&raw, &raw_corners, &triangle_face);
    if unseen_polygons > 0 {
        notes.push(unseen_note(unseen_polygons));
    }
    Ok(InputMesh {
        positions,
        triangles,
        triangle_origin,
        triangle_polygon: triangle_face,
        vertex_number,
        origin_kind: raw.origin_kind,
        numbering: raw.numbering,
        faces_in_file: n_faces,
        welded,
        unreferenced,
        repair: None,
        attributes,
        notes,
        topology: None,
    })
}

/// The attributes of `raw` on its triangles, given the raw corners and the
/// face of each triangle. A channel may leave whole faces without values
/// ([`Channel::is_partial`]); one that leaves some corners of a face
/// without, or refers to values it lacks, is dropped with a note. The
/// notes: the reader's, then those on attributes.
fn triangle_attributes(raw: &RawMesh, raw_corners: &[[u32; 3]], triangle_face: &[u32]) -> (Attributes, Vec<String>) {
    let mut notes = raw.notes.clone();
    notes.extend_from_slice(&raw.attribute_notes);
    let (properties, mut face_properties) = raw.attributes.property_names();
    for (p, out) in raw.attributes.face_properties.iter().zip(&mut face_properties) {
        out.values = triangle_face
            .iter()
            .map(|&f| p.values.get(f as usize).copied().unwrap_or(0.0))
            .collect();
    }
    let mut a = Attributes {
        mtllib: raw.attributes.mtllib.clone(),
        properties,
        face_properties,
        ..Attributes::default()
    };
    if !raw.attributes.face_group.is_empty() {
        a.groups = raw.attributes.groups.clone();
        a.face_group = triangle_face
            .iter()
            .map(|&f| raw.attributes.face_group.get(f as usize).copied().unwrap_or(0))
            .collect();
    }
    for (kind, channel) in raw.attributes.channels() {
        let corners: Vec<u32> = raw_corners
            .iter()
            .flatten()
            .map(|&c| channel.corners.get(c as usize).copied().unwrap_or(NO_VALUE))
            .collect();
        if corners
            .iter()
            .any(|&i| i != NO_VALUE && i as usize >= channel.n_values())
        {
            notes.push(format!(
                "{} dropped: some faces refer to values the file lacks",
                raw.attributes.name_of(kind)
            ));
            continue;
        }
        // Faces without values (an object with none) keep none, and the
        // others keep theirs; a face with values at some corners only is a
        // defect of the file.
        let mut without = 0usize;
        let mut some = false;
        for t in corners.chunks_exact(3) {
            match t.iter().filter(|&&i| i == NO_VALUE).count() {
                0 => {}
                3 => without += 1,
                _ => some = true,
            }
        }
        if some {
            notes.push(format!(
                "{} dropped: some faces have them at some corners only",
                raw.attributes.name_of(kind)
            ));
            continue;
        }
        if without == corners.len() / 3 {
            continue;
        }
        *a.channel_mut(kind) = Some(crate::attributes::Channel {
            dim: channel.dim,
            values: channel.values.clone(),
            corners,
        });
    }
    if a.texcoords.is_some() {
        a.texture_files = raw.attributes.texture_files.clone();
    }
    if a.colors.is_some() {
        a.color_type = raw.attributes.color_type;
    }
    (a, notes)
}

/// The note for polygons whose fan cannot draw them (see [`polygon`]).
fn unseen_note(count: usize) -> String {
    format!(
        "{count} polygon(s) could not be cut into triangles within their outline (it crosses or folds onto itself, \
         or is too warped; or it has more than {} corners and no corner sees it whole): each is read as the fan \
         from its first corner, whose triangles overlap; triangulate them beforehand to keep their shape",
        polygon::MAX_EAR_CLIPPED
    )
}

/// Whether polygon `p` has two corners at the same position (what `finish`
/// refuses as a repeated vertex, and `--repair` reads as the outline the
/// polygon traces): bit-identical coordinates, as `finish` welds.
fn passes_a_point_twice(p: &[u32], positions: &[[f64; 3]], scratch: &mut Vec<[u64; 3]>) -> bool {
    scratch.clear();
    scratch.extend(p.iter().map(|&v| positions[v as usize].map(f64::to_bits)));
    scratch.sort_unstable();
    scratch.windows(2).any(|w| w[0] == w[1])
}

/// The corners of polygon `p` in `out`, less each one at the position of
/// the corner kept before it (bit-identical coordinates; around the
/// outline, so also a last corner at the first one's position).
fn without_repeated_corners(p: &[u32], positions: &[[f64; 3]], out: &mut Vec<u32>) {
    let bits = |v: u32| positions[v as usize].map(f64::to_bits);
    out.clear();
    for &v in p {
        if out.last().is_none_or(|&last| bits(last) != bits(v)) {
            out.push(v);
        }
    }
    while out.len() > 1 && bits(out[0]) == bits(out[out.len() - 1]) {
        out.pop();
    }
}

/// `finish` with `--repair`: triangulate everything, then let
/// [`repair::repair`] weld, drop and cut until the mesh is a manifold.
fn finish_repaired(raw: &RawMesh, path: &Path, options: &RepairOptions) -> Result<InputMesh> {
    let n_faces = raw.face_start.len() - 1;
    let mut triangles = Vec::with_capacity(n_faces);
    let mut triangle_face = Vec::with_capacity(n_faces);
    let mut pieces = Vec::new();
    let mut unseen_polygons = 0;
    let mut keyhole_polygons = 0;
    let mut repeated_corners = 0;
    let mut scratch = Vec::new();
    let mut outline = Vec::new();
    for f in 0..n_faces {
        let mut p = &raw.indices[raw.face_start[f] as usize..raw.face_start[f + 1] as usize];
        if let &[a, b, c] = p {
            triangles.push([a, b, c]);
            triangle_face.push(f);
            continue;
        }
        // A corner at the position of the one before it (`f 1 2 2 3`, or
        // two vertex lines at one point) adds nothing to the outline, but
        // its zero-length side keeps every corner from seeing the polygon
        // whole: its fan from the first corner then overlaps itself.
        without_repeated_corners(p, &raw.positions, &mut outline);
        if outline.len() < p.len() && outline.len() >= 3 {
            repeated_corners += p.len() - outline.len();
            p = &outline;
        }
        keyhole_polygons += passes_a_point_twice(p, &raw.positions, &mut scratch) as usize;
        unseen_polygons += !polygon::triangulate(p.len(), |i| raw.positions[p[i] as usize], &mut pieces) as usize;
        for &[a, b, c] in &pieces {
            triangles.push([p[a], p[b], p[c]]);
            triangle_face.push(f);
        }
    }
    let (mut fixed, topology) = repair::repair_with_topology(&raw.positions, &triangles, options);
    fixed.report.keyhole_polygons = keyhole_polygons;
    fixed.report.repeated_corners = repeated_corners;
    if fixed.triangles.is_empty() {
        let r = &fixed.report;
        // A weld wider than the faces collapses them all.
        let why = if options.weld_tolerance > 0.0 && r.welded_vertices > 0 {
            format!(
                ": the weld (--weld-tolerance {}) joined {} vertices and left every face with a repeated vertex or no \
                 area; a smaller distance keeps them",
                options.weld_tolerance, r.welded_vertices
            )
        } else {
            String::new()
        };
        return Err(Error::Mesh {
            path: path.to_owned(),
            what: format!("no faces left after repair{why}"),
        });
    }
    for (i, t) in fixed.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|v| DVec3::from_array(fixed.positions[v as usize]));
        if !edges_in_supported_scale(a, b, c) {
            let f = triangle_face[fixed.source_triangle[i] as usize];
            let what = format!("{} {}", raw.numbering.face(f), short_edge_text());
            return Err(face_error(path, raw, f, what));
        }
    }
    let origin_of = |f: usize| raw.face_origin.get(f).copied().unwrap_or(f as u32);
    Ok(InputMesh {
        positions: fixed.positions.iter().map(|p| DVec3::from_array(*p)).collect(),
        triangle_origin: fixed
            .source_triangle
            .iter()
            .map(|&t| origin_of(triangle_face[t as usize]))
            .collect(),
        vertex_number: fixed.source_vertex.iter().map(|&v| v + 1).collect(),
        triangles: fixed.triangles,
        // (No attributes after a repair.)
        triangle_polygon: Vec::new(),
        origin_kind: raw.origin_kind,
        numbering: raw.numbering,
        faces_in_file: n_faces,
        welded: fixed.report.welded_vertices,
        unreferenced: fixed.report.unreferenced_vertices,
        repair: Some(fixed.report),
        attributes: Attributes::default(),
        notes: {
            // The reader's notes (data it ignored) first, as without repair.
            let mut notes = raw.notes.clone();
            // What the file has, named as an STL output's note names it.
            if let Some((lost, them)) = attributes_format_cannot_hold(&raw.attributes, Format::Stl) {
                notes.push(format!("{lost} dropped: --repair does not carry {them}"));
            }
            if unseen_polygons > 0 {
                notes.push(unseen_note(unseen_polygons));
            }
            notes
        },
        topology,
    })
}

/// Builds the refinable mesh of an input, turning topology errors into
/// messages that name the file, line and vertices. Planar regions are cut
/// where the input's attributes could not survive a flip, with the default
/// [`Tolerances`] ([`build_surface_with`]).
///
/// Takes the connectivity the reader built ([`InputMesh::topology`]), if any.
pub fn build_surface(input: &mut InputMesh, path: &Path) -> Result<Surface> {
    build_surface_with(input, path, Tolerances::default())
}

/// [`build_surface`], with planar regions cut where the input's attributes
/// could not survive a flip within `tolerances` ([`AttributeCuts`]). Adds
/// to `input.notes` a line when some flat regions are flipped as a whole
/// though their attributes are affine only within the tolerances.
///
/// Refuses, as the readers do (an `InputMesh` may have been made or edited
/// by the caller): tolerances that are NaN, negative, infinite or above 1
/// ([`Tolerances::validate`]), a mesh without triangles, a coordinate that
/// is not finite or beyond ±[`MAX_COORDINATE`], an edge shorter than
/// [`MIN_EDGE`], and triangles that do not make a manifold, consistently
/// oriented mesh. (Unused vertices and zero-area triangles, which the
/// readers refuse too, are not looked for again: [`Surface::new`] does.)
pub fn build_surface_with(input: &mut InputMesh, path: &Path, tolerances: Tolerances) -> Result<Surface> {
    tolerances.validate()?;
    if input.triangles.is_empty() {
        return Err(Error::Mesh {
            path: path.to_owned(),
            what: "no faces".into(),
        });
    }
    // The readers refuse such coordinates; an input edited since is refused
    // here (one pass, without a branch per value).
    if !input.positions.iter().fold(true, |ok, &p| ok & in_supported_range(p)) {
        let v = input
            .positions
            .iter()
            .position(|&p| !in_supported_range(p))
            .unwrap_or(0);
        return Err(Error::Mesh {
            path: path.to_owned(),
            what: format!(
                "{} has a coordinate that is not finite or beyond ±{MAX_COORDINATE:e}, the supported range",
                input.vertex_name(v as u32)
            ),
        });
    }
    // Indices first: the edge test below reads the corners' positions.
    let n = input.positions.len();
    if let Some(face) = input.triangles.iter().position(|t| t.iter().any(|&v| v as usize >= n)) {
        return Err(Error::Mesh {
            path: path.to_owned(),
            what: format!("triangle {face} uses a vertex beyond the vertex count ({n})"),
        });
    }
    let corners = |t: &[u32; 3]| t.map(|v| input.positions[v as usize]);
    if let Some(face) = (input.triangles.iter().map(corners)).position(|[a, b, c]| !edges_in_supported_scale(a, b, c)) {
        // Where the file has it (a mesh made by the caller may say nothing).
        let at = match (input.triangle_origin.get(face), input.origin_kind) {
            (Some(line), OriginKind::Line) => format!("line {line}: "),
            (Some(record), OriginKind::Record) => format!("face record {record}: "),
            (None, _) => String::new(),
        };
        return Err(Error::Mesh {
            path: path.to_owned(),
            what: format!("{at}triangle {face} {}", short_edge_text()),
        });
    }
    let topology = input.topology.take();
    let attribute_cuts = AttributeCuts::new(&input.attributes, &input.positions, &input.triangles, tolerances)
        .with_polygons(&input.triangle_polygon);
    let cuts: &dyn RegionCuts = if input.attributes.is_empty() {
        &NoCuts
    } else {
        &attribute_cuts
    };
    // With room for the splits to come (no copy when the surface reserves it).
    let mut positions = Vec::with_capacity(input.positions.len() + room_for_splits(input.triangles.len()));
    positions.extend_from_slice(&input.positions);
    let surface = match topology {
        Some(topology) => Ok(topology),
        None => Topology::from_triangles(positions.len(), &input.triangles),
    }
    .map(|topology| Surface::with_topology(positions, topology, cuts));
    let notes = [attribute_cuts.note(), attribute_cuts.polygon_note()];
    input.notes.extend(notes.into_iter().flatten());
    let input = &*input;
    surface.map_err(|e| {
        let at = |face: usize| {
            let origin = input.triangle_origin.get(face).copied().unwrap_or(0);
            match input.origin_kind {
                OriginKind::Line => format!("line {origin}"),
                OriginKind::Record => format!("face record {origin}"),
            }
        };
        let v = |i: u32| input.vertex_name(i);
        let what = match e {
            TopologyError::EdgeWithMoreThanTwoFaces { face, a, b } => format!(
                "{}: edge between {} and {} has more than two faces, this one the third (non-manifold edge){REPAIR_HINT}",
                at(face),
                v(a),
                v(b)
            ),
            TopologyError::InconsistentOrientation { face, a, b } => {
                // The other face along a -> b; if it has the same corners,
                // this is a repeated face, not an orientation problem.
                let runs_along = |t: &[u32; 3]| (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b);
                let mut corners = input.triangles[face];
                corners.sort_unstable();
                let twin = (0..input.triangles.len()).find(|&f| {
                    let mut other = input.triangles[f];
                    other.sort_unstable();
                    f != face && other == corners && runs_along(&input.triangles[f])
                });
                match twin {
                    Some(first) => format!(
                        "{}: face repeats the one at {} (duplicate face){REPAIR_HINT}",
                        at(face),
                        at(first)
                    ),
                    None => format!(
                        "{}: face runs along the edge from {} to {} in the same direction as another face (inconsistent orientation){REPAIR_HINT}",
                        at(face),
                        v(a),
                        v(b)
                    ),
                }
            }
            TopologyError::NonManifoldVertex { vertex } => format!(
                "{}: its faces form more than one fan (non-manifold vertex){REPAIR_HINT}",
                v(vertex)
            ),
            TopologyError::IndexOutOfRange { face, index } => {
                format!("{}: vertex index {} out of range", at(face), index as u64 + 1)
            }
            TopologyError::RepeatedVertex { face, vertex } => {
                format!("{}: face repeats {}{REPAIR_HINT}", at(face), v(vertex))
            }
            TopologyError::SameThreeVertices { first, face } => format!(
                "{}: face uses the same three vertices as the face at {} (a two-face pillow){REPAIR_HINT}",
                at(face),
                at(first)
            ),
        };
        Error::Mesh { path: path.to_owned(), what }
    })
}

/// Whether [`write_atomic`] flushes each file to the disk before renaming
/// it (`--sync`); off by default.
static SYNC_WRITES: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Makes [`write_atomic`] call `fsync` on each file before its rename (the
/// CLI's `--sync`). Without it a write is still atomic for every reader and
/// against delmesh being killed or crashing (the output is the old file or
/// the whole new one); with it that also holds across a power loss or an
/// operating system crash, at the cost of waiting for the disk (4.5 ms for
/// the armadillo's output here, 65 ms for the dragon's).
pub fn set_sync_writes(sync: bool) {
    SYNC_WRITES.store(sync, std::sync::atomic::Ordering::Relaxed);
}

/// Whether `path` names something that exists and is neither a regular
/// file nor a folder (following symbolic links): a device such as
/// `/dev/null`, a terminal or pipe such as `/dev/stdout`, a FIFO. Such a
/// target is written into, never replaced.
pub fn is_stream(path: &Path) -> bool {
    standard_stream(path).is_some() || std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Which standard stream an output `path` names, 1 (stdout: `-` or its
/// usual names) or 2 (stderr): written through the process's own
/// descriptor, so that `--stats-json /dev/stdout > log` appends to `log`
/// instead of opening the file again at its start (or replacing it).
pub fn standard_stream(path: &Path) -> Option<u8> {
    let name = path.to_str()?;
    match name {
        "-" | "/dev/stdout" | "/dev/fd/1" | "/proc/self/fd/1" => Some(1),
        "/dev/stderr" | "/dev/fd/2" | "/proc/self/fd/2" => Some(2),
        _ => None,
    }
}

/// Whether an input `path` names standard input: `-` or its usual names.
/// It is read through the process's own descriptor (to its end), never
/// opened again by name: `/dev/stdin` redirected from a file would
/// otherwise name that file, and a run without `-o` rewrite it in place.
pub fn is_standard_input(path: &Path) -> bool {
    matches!(
        path.to_str(),
        Some("-" | "/dev/stdin" | "/dev/fd/0" | "/proc/self/fd/0")
    )
}

/// A regular file, as the system knows it: its device and inode numbers,
/// the same whatever name (a hard or symbolic link, `/dev/fd/3`) or open
/// descriptor (standard input redirected from it) reaches it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FileId {
    device: u64,
    inode: u64,
}

impl FileId {
    /// The identity of what `metadata` describes, if a regular file.
    fn of(metadata: &std::fs::Metadata) -> Option<FileId> {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            metadata.is_file().then(|| FileId {
                device: metadata.dev(),
                inode: metadata.ino(),
            })
        }
        #[cfg(not(unix))]
        {
            let _ = metadata;
            None
        }
    }

    /// The regular file `path` names (symbolic links followed); `None` for
    /// a file that does not exist, a folder, a device or a pipe.
    pub fn of_path(path: &Path) -> Option<FileId> {
        FileId::of(&std::fs::metadata(path).ok()?)
    }

    /// The regular file open as standard input (0), output (1) or error
    /// (2), if one is (`< m.obj`, `>> log`).
    pub fn of_standard(fd: u8) -> Option<FileId> {
        #[cfg(unix)]
        {
            use std::os::fd::AsFd;
            let fd = match fd {
                0 => std::io::stdin().as_fd().try_clone_to_owned(),
                1 => std::io::stdout().as_fd().try_clone_to_owned(),
                _ => std::io::stderr().as_fd().try_clone_to_owned(),
            };
            FileId::of(&std::fs::File::from(fd.ok()?).metadata().ok()?)
        }
        #[cfg(not(unix))]
        {
            let _ = fd;
            None
        }
    }

    /// The regular file an input `path` reads: standard input's for `-`
    /// and its names ([`is_standard_input`]).
    pub fn of_input(path: &Path) -> Option<FileId> {
        if is_standard_input(path) {
            FileId::of_standard(0)
        } else {
            FileId::of_path(path)
        }
    }

    /// The regular file an output `path` writes, if it exists: standard
    /// output's or error's for their names ([`standard_stream`]).
    pub fn of_output(path: &Path) -> Option<FileId> {
        match standard_stream(path) {
            Some(fd) => FileId::of_standard(fd),
            None => FileId::of_path(path),
        }
    }
}

/// The file a write to `path` replaces, and the folder its temporary file
/// goes in: a symbolic link is followed (the file it points to is
/// replaced, or created if the link dangles; the link kept), anything else
/// is `path` itself. A link that leads nowhere (a loop of links: `Too many
/// levels of symbolic links`) is an error, never replaced by a file.
pub fn write_target(path: &Path) -> std::io::Result<(PathBuf, PathBuf)> {
    let is_link = |p: &Path| std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_symlink());
    let target = if is_link(path) {
        match std::fs::canonicalize(path) {
            Ok(target) => target,
            Err(e) => dangling_link_target(path).ok_or(e)?,
        }
    } else {
        path.to_owned()
    };
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
        _ => PathBuf::from("."),
    };
    Ok((target, dir))
}

/// Where the chain of symbolic links from `path` ends, when it ends at a
/// name that does not exist (a dangling link: writing through it creates
/// that file, as a shell's `>` does); `None` for a loop of links.
fn dangling_link_target(path: &Path) -> Option<PathBuf> {
    let mut p = path.to_owned();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&p).ok()?;
                p = match p.parent() {
                    Some(dir) if to.is_relative() => dir.join(to),
                    _ => to,
                };
            }
            Ok(_) => return None, // exists: `canonicalize` failed for another reason
            Err(_) => return Some(p),
        }
    }
    None
}

/// Writes what `fill` produces to `path` atomically: into a temporary file
/// in the same directory, renamed over `path` only when complete (flushed
/// to the disk first with [`set_sync_writes`]). On any error `path` is
/// untouched and the temporary file removed. A symbolic link is followed
/// and kept; a target that is not a regular file ([`is_stream`]: a device,
/// a pipe) is written into directly, there being no file to replace.
pub fn write_atomic(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    stage(path, fill)?.commit()
}

/// The first half of [`write_atomic`]: what `fill` produces, complete in a
/// temporary file beside `path` (or written into `path` if it is a stream,
/// which has no second half), to be renamed into place by
/// [`Staged::commit`] once whatever must come first has succeeded: a run
/// writes its side files, and checks its output, before it replaces its
/// input. The temporary file's name ends in `path`'s extension, so that a
/// reader takes it for the same format.
pub fn stage(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<Staged> {
    let err = |source| Error::Write {
        path: path.to_owned(),
        source,
    };
    let streamed = || Staged {
        path: path.to_owned(),
        file: None,
    };
    if let Some(fd) = standard_stream(path) {
        let mut w: Box<dyn Write> = if fd == 1 {
            Box::new(std::io::stdout().lock())
        } else {
            Box::new(std::io::stderr().lock())
        };
        fill_compressed_if_gz(path, &mut w, fill).map_err(err)?;
        w.flush().map_err(err)?;
        return Ok(streamed());
    }
    if is_stream(path) {
        let file = std::fs::OpenOptions::new().write(true).open(path).map_err(err)?;
        let mut w = BufWriter::with_capacity(1 << 16, file);
        fill_compressed_if_gz(path, &mut w, fill).map_err(err)?;
        w.flush().map_err(err)?;
        return Ok(streamed());
    }
    let (target, dir) = write_target(path).map_err(err)?;
    let path = target.as_path();
    let mut tmp =
        temporary::TempFile::create_in(&dir, ".delmesh-", &format!(".tmp{}", extensions(path))).map_err(err)?;
    // Removed by the signal handler if the run is interrupted; unregistered
    // when renamed into place, or removed (the `Staged` dropped).
    let registered = temporary::register(tmp.path());
    {
        // Small: the OBJ writer hands over blocks of about a megabyte, which
        // a buffer this size passes straight to the file instead of copying.
        let mut w = BufWriter::with_capacity(1 << 16, tmp.as_file_mut());
        fill_compressed_if_gz(path, &mut w, fill).map_err(err)?;
        w.flush().map_err(err)?;
    }
    if SYNC_WRITES.load(std::sync::atomic::Ordering::Relaxed) {
        tmp.as_file().sync_all().map_err(err)?;
    }
    // Keep the permissions of a file being replaced, and its owner and
    // group where allowed (a run as root rewriting a user's file in place
    // leaves it the user's); a new file gets 0644.
    let perms = match std::fs::metadata(path) {
        Ok(m) => {
            #[cfg(unix)]
            {
                use std::os::unix::fs::MetadataExt;
                // Refused (and harmless) unless root or a group change
                // to one of the caller's groups.
                let _ = std::os::unix::fs::fchown(tmp.as_file(), Some(m.uid()), Some(m.gid()));
            }
            m.permissions()
        }
        Err(_) => default_permissions(&dir),
    };
    tmp.as_file().set_permissions(perms).map_err(err)?;
    Ok(Staged {
        path: target,
        file: Some((tmp, registered)),
    })
}

/// A file written by [`stage`], not yet in place; dropped uncommitted, its
/// temporary file is removed and the target left untouched.
#[must_use = "a staged file is removed unless committed"]
#[derive(Debug)]
pub struct Staged {
    /// The file the write is for (a symbolic link followed).
    path: PathBuf,
    /// The complete temporary file; `None` for a stream, written already.
    file: Option<(temporary::TempFile, temporary::Registration)>,
}

impl Staged {
    /// Where the complete bytes are now: the temporary file, or the stream.
    pub fn path(&self) -> &Path {
        self.file.as_ref().map_or(&self.path, |(tmp, _)| tmp.path())
    }

    /// Whether the bytes are where they were asked for already (a stream).
    pub fn is_in_place(&self) -> bool {
        self.file.is_none()
    }

    /// Renames the temporary file over the target (nothing for a stream).
    pub fn commit(self) -> Result<()> {
        self.commit_as(None)
    }

    /// Renames the temporary file to `other` instead of the target: where
    /// a run puts an output that failed its check.
    pub fn commit_to(self, other: &Path) -> Result<()> {
        self.commit_as(Some(other))
    }

    fn commit_as(self, other: Option<&Path>) -> Result<()> {
        let Some((tmp, _registered)) = self.file else {
            return Ok(());
        };
        let to = other.unwrap_or(&self.path);
        tmp.persist(to).map_err(|source| Error::Write {
            path: to.to_owned(),
            source,
        })?;
        Ok(())
    }
}

/// The extensions of `path`'s name that say its format (`.obj`,
/// `.ply.gz`), or nothing if it has none short enough.
fn extensions(path: &Path) -> String {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    match split_extensions(name) {
        (_, Some(ext)) if ext.len() <= 12 => format!(".{ext}"),
        _ => String::new(),
    }
}

/// A file name's stem and the extensions that say its format: `n.ply.gz`
/// gives `n` and `ply.gz`, `n.gz` gives `n` and `gz`, `n` and `.n` no
/// extension.
pub fn split_extensions(name: &str) -> (&str, Option<&str>) {
    let last = |n: &str| n.rfind('.').filter(|&i| i > 0);
    let Some(dot) = last(name) else {
        return (name, None);
    };
    let at = match last(&name[..dot]) {
        Some(inner) if name[dot + 1..].eq_ignore_ascii_case("gz") => inner,
        _ => dot,
    };
    (&name[..at], Some(&name[at + 1..]))
}

/// `fill(w)`, gzip-compressed if `path` ends in `.gz` (as the readers
/// accept it).
fn fill_compressed_if_gz(
    path: &Path,
    w: &mut dyn Write,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gz")) {
        return fill(w);
    }
    let mut gz = flate2::write::GzEncoder::new(w, flate2::Compression::default());
    fill(&mut gz)?;
    gz.finish()?;
    Ok(())
}

#[cfg(unix)]
fn default_permissions(_dir: &Path) -> std::fs::Permissions {
    use std::os::unix::fs::PermissionsExt;
    std::fs::Permissions::from_mode(0o644)
}

#[cfg(not(unix))]
fn default_permissions(dir: &Path) -> std::fs::Permissions {
    let mut p = std::fs::metadata(dir)
        .map(|m| m.permissions())
        .unwrap_or_else(|_| unreachable!());
    p.set_readonly(false);
    p
}

/// The output format for `path`, by extension; OBJ when it says nothing.
pub fn output_format(path: &Path) -> Format {
    path.file_name()
        .and_then(|n| n.to_str())
        .and_then(formats::format_from_name)
        .unwrap_or(Format::Obj)
}

/// What of `attributes` a file of `format` cannot hold, as a note names it
/// (`"normals, groups and materials"`), and the pronoun for it (`it` for a
/// single property, else `them`); `None` if it holds all.
/// OBJ holds every attribute but a PLY file's other vertex and face
/// properties; PLY all but groups and materials, and channels that only
/// some faces have; OFF texture coordinates, normals, colours and face
/// colours ([`off_face_colors`]), not channels that only some faces have;
/// STL positions only.
fn attributes_format_cannot_hold(attributes: &Attributes, format: Format) -> Option<(String, &'static str)> {
    let groups = !attributes.face_group.is_empty() || !attributes.mtllib.is_empty();
    let mut lost: Vec<String> = Vec::new();
    let mut properties: Vec<&str> = Vec::new();
    for (kind, channel) in attributes.channels() {
        // PLY and OFF store values per vertex: they have no "none" for the
        // vertices of faces without.
        let partial = matches!(format, Format::Ply | Format::Off) && channel.is_partial();
        let lose = match kind {
            Kind::Property(_) => format != Format::Ply,
            _ => format == Format::Stl || partial,
        };
        if !lose {
            continue;
        }
        match kind {
            Kind::Property(i) => properties.push(&attributes.properties[i as usize].name),
            _ if partial => lost.push(format!("{} of only some faces", kind.name())),
            _ => lost.push(kind.name().to_owned()),
        }
    }
    lost.extend(properties_named("vertex", &properties));
    let held = match format {
        Format::Ply => (0..attributes.face_properties.len()).collect(),
        Format::Off => off_face_colors(attributes).map_or_else(Vec::new, |(held, _)| held),
        Format::Obj | Format::Stl => Vec::new(),
    };
    let face_properties: Vec<&str> = (attributes.face_properties.iter().enumerate())
        .filter(|(i, _)| !held.contains(i))
        .map(|(_, p)| p.name.as_str())
        .collect();
    lost.extend(properties_named("face", &face_properties));
    if groups && format != Format::Obj {
        lost.extend(["groups".to_owned(), "materials".to_owned()]);
    }
    let (last, rest) = lost.split_last()?;
    Some(if rest.is_empty() {
        let single_property = properties.len() + face_properties.len() == 1;
        (last.to_string(), if single_property { "it" } else { "them" })
    } else {
        (format!("{} and {last}", rest.join(", ")), "them")
    })
}

/// The face properties an OFF file holds, as its face colours: `red`,
/// `green` and `blue` (as the OFF reader names them, and as PLY files
/// do), all `uchar` (written as whole numbers 0..255) or all `float` or
/// `double` (written as they are), and `alpha` if it is of the same kind.
/// Their places in [`Attributes::face_properties`], in that order, and how
/// they are written; `None` if there are none such.
fn off_face_colors(attributes: &Attributes) -> Option<(Vec<usize>, formats::ColorText)> {
    let properties = &attributes.face_properties;
    let find = |name: &str| properties.iter().position(|p| p.name == name);
    let text = |i: usize| match properties[i].ty {
        ValueType::U8 => Some(formats::ColorText::Bytes),
        ValueType::F32 | ValueType::F64 => Some(formats::ColorText::Floats),
        _ => None,
    };
    let mut held = vec![find("red")?, find("green")?, find("blue")?];
    let kind = text(held[0])?;
    if held.iter().any(|&i| text(i) != Some(kind)) {
        return None;
    }
    held.extend(find("alpha").filter(|&i| text(i) == Some(kind)));
    Some((held, kind))
}

/// Leaves out of `input` the attributes that a file of `format` cannot hold
/// (STL: all of them; PLY: groups and materials, and texture coordinates,
/// normals or colours that only some faces have; OFF: those, a PLY file's
/// other vertex properties and its face properties but the face colours;
/// OBJ: a PLY file's other vertex and face properties), before its surface
/// is built: an attribute that will not be written must not keep flat
/// regions apart or cost splits (when OFF could not hold normals, a
/// smooth-shaded oval cylinder written as OFF got 21,256 added vertices for
/// normals it did not keep, and none without them). Returns the note that
/// says so, if anything was left out; `refining`: whether the note adds
/// that the mesh is refined without them (not under `--no-refine`).
pub fn drop_attributes_format_cannot_hold(input: &mut InputMesh, format: Format, refining: bool) -> Option<String> {
    let (lost, them) = attributes_format_cannot_hold(&input.attributes, format)?;
    let held_face_colors = off_face_colors(&input.attributes).map_or_else(Vec::new, |(held, _)| held);
    let a = &mut input.attributes;
    match format {
        Format::Stl => *a = Attributes::default(),
        Format::Ply | Format::Off => {
            for channel in [&mut a.texcoords, &mut a.normals, &mut a.colors] {
                if channel.as_ref().is_some_and(Channel::is_partial) {
                    *channel = None;
                }
            }
            if a.texcoords.is_none() {
                a.texture_files = Vec::new();
            }
            a.face_group = Vec::new();
            a.groups = Vec::new();
            a.mtllib = Vec::new();
            if format == Format::Off {
                a.properties = Vec::new();
                a.face_properties = (std::mem::take(&mut a.face_properties).into_iter().enumerate())
                    .filter_map(|(i, p)| held_face_colors.contains(&i).then_some(p))
                    .collect();
            }
        }
        Format::Obj => {
            a.properties = Vec::new();
            a.face_properties = Vec::new();
        }
    }
    let name = format.name();
    Some(if refining {
        format!("{lost} left out: {name} cannot hold {them} (the mesh is refined as without {them})")
    } else {
        format!("{lost} left out: {name} cannot hold {them}")
    })
}

/// Writes a triangle mesh atomically, in the format of `path`'s extension
/// (OBJ, OFF, PLY binary, STL binary; OBJ when the extension says nothing).
pub fn write_mesh(path: &Path, positions: &[DVec3], triangles: &[[u32; 3]]) -> Result<()> {
    write_mesh_after(path, &obj::VertexLines::default(), positions, triangles)
}

/// [`write_mesh`], with the OBJ lines of the first vertices formatted
/// already (used only if `path` names an OBJ file).
pub fn write_mesh_after(
    path: &Path,
    done: &obj::VertexLines,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> Result<()> {
    stage_mesh_after(path, done, positions, triangles)?.commit()
}

/// [`write_mesh_after`], staged ([`stage`]): not yet renamed into place.
pub fn stage_mesh_after(
    path: &Path,
    done: &obj::VertexLines,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> Result<Staged> {
    let positions: &[[f64; 3]] = bytemuck_positions(positions);
    let format = output_format(path);
    stage(path, |w| match format {
        Format::Obj => obj::write_obj_after(w, done, positions, triangles),
        Format::Off => formats::write_off(w, positions, triangles),
        Format::Ply => formats::write_ply_binary(w, positions, triangles, None),
        Format::Stl => formats::write_stl_binary(w, positions, triangles),
    })
}

/// Writes a triangle mesh with its attributes (per corner of `triangles`,
/// as [`crate::attributes::Transfer::apply`] gives them) atomically, in the
/// format of `path`'s extension. OBJ keeps everything but a PLY input's
/// `TextureFile` comments (a note says so); PLY keeps texture
/// coordinates (`s t`, the first two numbers, and the `comment
/// TextureFile` lines of a PLY input), normals (`nx ny nz`),
/// colours (`red green blue [alpha]`, 8-bit, or a PLY input's float or
/// 16-bit type) and a PLY input's other vertex and face properties (in
/// their types), a vertex with several values
/// written once per value at the same position, the copies last; OFF
/// keeps texture coordinates (`ST`), normals (`N`) and colours (`C`:
/// whole numbers 0..255 if 8-bit, as an OFF input's whole numbers and a PLY
/// input's integer types but `ushort` are, else numbers as they are, always
/// with a decimal point) per vertex, split at seams as in PLY, and face
/// colours (the face properties `red green blue [alpha]` of an OFF or PLY
/// input, `uchar` as whole numbers, `float` or `double` as they are) after
/// each face's indices; STL keeps positions only.
pub fn write_mesh_with_attributes(
    path: &Path,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    attributes: &Attributes,
) -> Result<Written> {
    let (written, staged) = stage_mesh_with_attributes(path, positions, triangles, attributes)?;
    staged.commit()?;
    Ok(written)
}

/// [`write_mesh_with_attributes`], staged ([`stage`]): not yet renamed
/// into place.
pub fn stage_mesh_with_attributes(
    path: &Path,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    attributes: &Attributes,
) -> Result<(Written, Staged)> {
    let format = output_format(path);
    let p = bytemuck_positions(positions);
    let mut notes = Vec::new();
    if let Some((lost, them)) = attributes_format_cannot_hold(attributes, format) {
        notes.push(format!("{lost} not written: {} cannot hold {them}", format.name()));
    }
    let mut copies_of = Vec::new();
    let staged = match format {
        Format::Obj => {
            if attributes.texcoords.is_some() && !attributes.texture_files.is_empty() {
                notes.push(format!(
                    "texture file {} (PLY comment TextureFile) not written: an OBJ names its textures in a \
                     material library (.mtl), which delmesh does not write; write PLY to keep it",
                    attributes.texture_files.join(", ")
                ));
            }
            stage(path, |w| obj::write_obj_with_attributes(w, p, triangles, attributes))?
        }
        Format::Ply => {
            let (channels, split) = split_per_vertex(attributes, positions.len(), triangles, |_| true);
            let mut columns = Vec::new();
            for ((kind, channel), index) in channels.iter().zip(&split.values) {
                let property = match kind {
                    Kind::Property(i) => attributes.properties.get(*i as usize),
                    _ => None,
                };
                let names: &[&str] = match (kind, property) {
                    (Kind::TexCoord, _) => &["s", "t"],
                    (Kind::Normal, _) => &["nx", "ny", "nz"],
                    (Kind::Color, _) => &["red", "green", "blue", "alpha"],
                    (Kind::Property(_), Some(p)) => &[p.name.as_str()],
                    (Kind::Property(_), None) => &[],
                };
                // Colours are written as bytes from 0..1; an OBJ that wrote
                // them in 0..255 (some do) would be clamped to white.
                let (scale, ty) = match (kind, property) {
                    // A PLY input's float or 16-bit colours keep their type.
                    (Kind::Color, _) => match attributes.color_type {
                        Some(ty @ (ValueType::F32 | ValueType::F64)) => (1.0, ty),
                        Some(ValueType::U16) => (65535.0, ValueType::U16),
                        _ if colors_in_bytes(channel) => {
                            notes.push(COLORS_IN_BYTES.into());
                            (1.0, ValueType::U8)
                        }
                        _ => (255.0, ValueType::U8),
                    },
                    (_, Some(p)) => (1.0, p.ty),
                    _ => (1.0, ValueType::F64),
                };
                // (Texture coordinates of one number get t = 0.)
                let dim = if *kind == Kind::TexCoord {
                    channel.dim.max(2)
                } else {
                    channel.dim
                };
                for (k, &name) in names.iter().enumerate().take(dim) {
                    columns.push(PlyColumn {
                        name: name.to_owned(),
                        ty,
                        values: index.iter().map(|&i| scale * component(channel, i, k)).collect(),
                    });
                }
            }
            let face_columns: Vec<PlyColumn> = (attributes.face_properties.iter())
                .map(|p| PlyColumn {
                    name: p.name.clone(),
                    ty: p.ty,
                    values: p.values.clone(),
                })
                .collect();
            let written: Vec<[f64; 3]> = split.source.iter().map(|&v| p[v as usize]).collect();
            copies_of = split.source[positions.len()..].to_vec();
            // The texture image with the texture coordinates, as MeshLab names it.
            let comments: Vec<String> = match attributes.texcoords {
                Some(_) => (attributes.texture_files.iter())
                    .map(|name| format!("TextureFile {name}"))
                    .collect(),
                None => Vec::new(),
            };
            stage(path, |w| {
                formats::write_ply_binary_columns(w, &written, &split.triangles, &columns, &face_columns, &comments)
            })?
        }
        Format::Off => {
            let (channels, split) = split_per_vertex(attributes, positions.len(), triangles, |kind| {
                !matches!(kind, Kind::Property(_))
            });
            let face_colors = off_face_colors(attributes);
            if channels.is_empty() && face_colors.is_none() {
                stage_mesh_after(path, &obj::VertexLines::default(), positions, triangles)?
            } else {
                if attributes.texcoords.is_some() && !attributes.texture_files.is_empty() {
                    notes.push(format!(
                        "texture file {} (PLY comment TextureFile) not written: OFF cannot name a texture; write PLY \
                         to keep it",
                        attributes.texture_files.join(", ")
                    ));
                }
                let mut extras = formats::OffExtras::default();
                for ((kind, channel), index) in channels.iter().zip(&split.values) {
                    // (Texture coordinates of one number get t = 0, of three
                    // lose the third, as in PLY.)
                    let dim = match kind {
                        Kind::TexCoord => 2,
                        _ => channel.dim,
                    };
                    let values = |scale: f64| -> Vec<f64> {
                        (index.iter())
                            .flat_map(|&i| (0..dim).map(move |k| scale * component(channel, i, k)))
                            .collect()
                    };
                    match kind {
                        Kind::TexCoord => extras.texcoords = Some(values(1.0)),
                        Kind::Normal => extras.normals = Some(values(1.0)),
                        Kind::Color => {
                            let (mut text, scale) = off_color_text(attributes.color_type, channel, &mut notes);
                            let mut written = values(scale);
                            // Bytes that are all 0 or 1 would read back as
                            // 0..1 (the OFF reader, as Geomview's, takes whole
                            // numbers for bytes only if one is above 1).
                            let largest = written.iter().fold(0.0f64, |m, &x| m.max(x.round()));
                            if text == formats::ColorText::Bytes && largest == 1.0 {
                                (text, written) = (formats::ColorText::Floats, values(1.0));
                            }
                            extras.colors = Some(formats::OffColors {
                                dim,
                                text,
                                values: written,
                            });
                        }
                        Kind::Property(_) => {}
                    }
                }
                extras.face_colors = face_colors.map(|(held, text)| formats::OffColors {
                    dim: held.len(),
                    text,
                    values: (0..triangles.len())
                        .flat_map(|f| {
                            (held.iter())
                                .map(move |&i| attributes.face_properties[i].values.get(f).copied().unwrap_or(0.0))
                        })
                        .collect(),
                });
                let written: Vec<[f64; 3]> = split.source.iter().map(|&v| p[v as usize]).collect();
                copies_of = split.source[positions.len()..].to_vec();
                stage(path, |w| {
                    formats::write_off_with(w, &written, &split.triangles, &extras)
                })?
            }
        }
        Format::Stl => stage_mesh_after(path, &obj::VertexLines::default(), positions, triangles)?,
    };
    Ok((Written { notes, copies_of }, staged))
}

/// The channels of `attributes` of the kinds `hold` takes that a format
/// storing values per vertex (PLY, OFF) can hold (not those that only some
/// faces have), and the vertices split so that each has one value of each
/// ([`PerVertex`]).
fn split_per_vertex<'a>(
    attributes: &'a Attributes,
    vertices: usize,
    triangles: &[[u32; 3]],
    hold: impl Fn(Kind) -> bool,
) -> (Vec<(Kind, &'a Channel)>, PerVertex) {
    let channels: Vec<_> = (attributes.channels())
        .filter(|&(kind, c)| hold(kind) && !c.is_partial())
        .collect();
    let split = PerVertex::new(
        vertices,
        triangles,
        &channels.iter().map(|(_, c)| *c).collect::<Vec<_>>(),
    );
    (channels, split)
}

/// Number `k` of value `i` of `channel` (0 where it has none).
fn component(channel: &Channel, i: u32, k: usize) -> f64 {
    channel.value(i).get(k).copied().unwrap_or(0.0)
}

/// The note on colours written as [`colors_in_bytes`] says.
const COLORS_IN_BYTES: &str = "colours above 1 taken as 0-255 (the file's scale), written as they are";

/// How an OFF output writes `colors` of `color_type`
/// ([`Attributes::color_type`]), and the factor they are written with:
/// 8-bit ones (an integer type but `ushort`, as an OFF input's whole
/// numbers are typed) as bytes, as most COFF files hold them; colours in
/// 0..255 ([`colors_in_bytes`]) as they are, rounded, with a note; others
/// (an OBJ's, an OFF's floats, a PLY's `float`, `double` or `ushort` ones)
/// as numbers in shortest round-trip form.
fn off_color_text(
    color_type: Option<ValueType>,
    colors: &Channel,
    notes: &mut Vec<String>,
) -> (formats::ColorText, f64) {
    match color_type {
        Some(ty) if ty.is_integer() && ty != ValueType::U16 => (formats::ColorText::Bytes, 255.0),
        _ if colors_in_bytes(colors) => {
            notes.push(COLORS_IN_BYTES.into());
            (formats::ColorText::Bytes, 1.0)
        }
        _ => (formats::ColorText::Floats, 1.0),
    }
}

/// What [`write_mesh_with_attributes`] wrote besides the mesh's own vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Written {
    /// A note for each attribute the format could not hold.
    pub notes: Vec<String>,
    /// The file's vertices after the mesh's own (which come first, in
    /// order): copies at attribute seams, as PLY and OFF write a vertex once
    /// per value; each entry is the mesh vertex the copy repeats. Empty for
    /// other formats and where no vertex has several values.
    pub copies_of: Vec<u32>,
}

/// Whether a colour channel holds values in 0..255 rather than 0..1: one
/// above 1 at least, none negative or above 255 (OBJ has no rule, and some
/// exporters write bytes).
fn colors_in_bytes(channel: &Channel) -> bool {
    let (lo, hi) = (channel.values.iter()).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
        (lo.min(x), hi.max(x))
    });
    hi > 1.0 && hi <= 255.0 && lo >= 0.0
}

/// Writes a triangle mesh as OBJ, atomically.
pub fn write_obj(path: &Path, positions: &[DVec3], triangles: &[[u32; 3]]) -> Result<()> {
    write_atomic(path, |w| obj::write_obj(w, bytemuck_positions(positions), triangles))
}

/// Writes OBJ text to any writer.
pub fn write_obj_to(w: &mut dyn Write, positions: &[DVec3], triangles: &[[u32; 3]]) -> std::io::Result<()> {
    obj::write_obj(w, bytemuck_positions(positions), triangles)
}

/// Views positions as plain arrays without copying.
fn bytemuck_positions(p: &[DVec3]) -> &[[f64; 3]] {
    bytemuck::cast_slice(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An input whose positions were edited after reading into what a
    /// reader refuses is refused by the build too (it was built, and
    /// refined into an output `check` rejects).
    #[test]
    fn build_refuses_coordinates_no_reader_takes() {
        let cube = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj");
        for bad in [f64::NAN, f64::INFINITY, 1e300] {
            let mut input = read_mesh(&cube, &Default::default()).unwrap();
            input.topology = None;
            input.positions[2].y = bad;
            let Err(e) = build_surface(&mut input, &cube) else {
                panic!("{bad} was built");
            };
            assert!(
                e.to_string()
                    .contains("vertex 3 has a coordinate that is not finite or beyond"),
                "{e}"
            );
        }
    }

    /// The library refuses what the command line refuses, with typed
    /// errors: tolerances that are NaN, negative or infinite (they acted as
    /// 0, or flipped everything), a mesh without triangles and edges below
    /// the supported scale in an `InputMesh` made or edited by the caller.
    #[test]
    fn library_settings_and_meshes_the_command_line_refuses() {
        let cube = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj");
        let read = || read_mesh(&cube, &Default::default()).unwrap();
        for bad in [f64::NAN, -1.0, f64::INFINITY, 2.0] {
            for tolerances in [
                Tolerances::all(bad),
                Tolerances {
                    colors: bad,
                    ..Tolerances::default()
                },
            ] {
                let e = build_surface_with(&mut read(), &cube, tolerances).unwrap_err();
                assert!(matches!(e, Error::Setting { .. }), "{e:?}");
                assert!(
                    e.to_string()
                        .contains("is not a relative tolerance (a number from 0 to 1)"),
                    "{e}"
                );
            }
        }
        let e = build_surface_with(&mut read(), &cube, Tolerances::all(f64::NAN)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "texture coordinates tolerance NaN is not a relative tolerance (a number from 0 to 1)"
        );
        for weld_tolerance in [f64::NAN, -1.0, f64::NEG_INFINITY, f64::INFINITY] {
            let options = ReadOptions {
                repair: Some(RepairOptions { weld_tolerance }),
                ..ReadOptions::default()
            };
            let e = read_mesh(&cube, &options).unwrap_err();
            assert!(
                matches!(
                    e,
                    Error::Setting {
                        name: "weld tolerance",
                        ..
                    }
                ),
                "{e:?}"
            );
        }
        let options = ReadOptions {
            repair: Some(RepairOptions { weld_tolerance: 1e-9 }),
            ..ReadOptions::default()
        };
        assert!(read_mesh(&cube, &options).is_ok());
        // No triangles.
        let mut empty = InputMesh::default();
        let e = build_surface(&mut empty, &cube).unwrap_err();
        assert!(e.to_string().ends_with("cube.obj: no faces"), "{e}");
        // Scaled below the supported scale after reading.
        let mut tiny = read();
        tiny.topology = None;
        for p in &mut tiny.positions {
            *p *= 1e-80;
        }
        let e = build_surface(&mut tiny, &cube).unwrap_err();
        assert!(e.to_string().contains("has an edge shorter than 1e-75"), "{e}");
        // An index beyond the vertices, in a mesh the caller made.
        let mut made = InputMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            triangles: vec![[0, 1, 7]],
            ..InputMesh::default()
        };
        let e = build_surface(&mut made, &cube).unwrap_err();
        assert!(
            e.to_string()
                .contains("triangle 0 uses a vertex beyond the vertex count"),
            "{e}"
        );
    }

    #[test]
    fn a_triangles_repeated_vertex_is_the_one_the_scan_finds() {
        let mut scratch = Vec::new();
        for ids in (0..27u32).map(|n| [n % 3, n / 3 % 3, n / 9]) {
            // The scan: the first id that occurs earlier in the list.
            let scan = (1..3).find(|&i| ids[..i].contains(&ids[i])).map(|i| ids[i]);
            assert_eq!(repeated_vertex(ids.into_iter(), &mut scratch), scan, "{ids:?}");
        }
        assert_eq!(repeated_vertex([4, 5, 6, 5].into_iter(), &mut scratch), Some(5));
    }

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
        assert_eq!(m.triangle_origin, vec![9, 9, 11]);
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
        let mut m = parse(&format!("{tri}f 1 2 3\nf 1 2 4\n")).unwrap();
        let msg = build_surface(&mut m, Path::new("t.obj")).unwrap_err().to_string();
        assert!(
            msg.contains("line 7") && msg.contains("inconsistent orientation"),
            "{msg}"
        );
        assert!(msg.contains("--repair would fix this"), "{msg}");
        let mut m = parse(&format!("{tri}f 1 2 3\nf 2 1 4\nf 1 2 5\n")).unwrap();
        let msg = build_surface(&mut m, Path::new("t.obj")).unwrap_err().to_string();
        assert!(msg.contains("more than two faces"), "{msg}");
        let mut m = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n").unwrap();
        let msg = build_surface(&mut m, Path::new("t.obj")).unwrap_err().to_string();
        assert!(
            msg.contains("vertex 1:") && msg.contains("non-manifold vertex"),
            "{msg}"
        );
    }

    #[test]
    fn repair_fixes_what_is_refused() {
        let bowtie = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nv 1 0 0\nf 1 2 3\nf 1 4 5\nf 1 1 2\n";
        let raw = obj::parse_obj(bowtie.as_bytes()).unwrap();
        let opts = ReadOptions {
            repair: Some(RepairOptions::default()),
            ..Default::default()
        };
        let mut m = finish(raw, Path::new("t.obj"), &opts).unwrap();
        let report = m.repair.clone().unwrap();
        assert_eq!(report.non_manifold_vertices, 1);
        assert_eq!(report.welded_vertices, 1);
        assert!(report.repeated_vertex_faces >= 1);
        assert!(m.topology.is_none(), "a split vertex: repaired in full");
        let s = build_surface(&mut m, Path::new("t.obj")).unwrap();
        s.validate().unwrap();
        assert_eq!(s.topo.n_faces(), 2);
    }

    /// The reader's notes (data after what a header declares: faces may
    /// be missing) are kept with `--repair` too; they were dropped there.
    #[test]
    fn repair_keeps_the_readers_notes() {
        let off = "OFF\n4 3 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
        let raw = formats::read_off(off.as_bytes()).unwrap();
        let note = "line 10: data after the 3 faces the OFF header declares ignored (if its counts are wrong, faces are missing)";
        assert_eq!(raw.notes, [note]);
        for repair in [None, Some(RepairOptions::default())] {
            let m = finish(
                raw.clone(),
                Path::new("t.off"),
                &ReadOptions {
                    repair,
                    ..Default::default()
                },
            )
            .unwrap();
            assert_eq!(m.notes, [note], "{repair:?}");
        }
    }

    /// `--drop-attributes` leaves out the attributes and the notes on them,
    /// not the other notes (it cleared them all: data ignored after a
    /// header's counts, polygons read as a fan).
    #[test]
    fn dropping_attributes_keeps_the_other_notes() {
        // A bad texture coordinate and a polygon that crosses itself.
        let obj = "vt 0 x\nv 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1 4/1\n";
        let raw = obj::parse_obj(obj.as_bytes()).unwrap();
        let read = |drop_attributes| {
            let options = ReadOptions {
                drop_attributes,
                ..Default::default()
            };
            finish(raw.clone(), Path::new("t.obj"), &options).unwrap().notes
        };
        let unseen = unseen_note(1);
        let bad = "texture coordinates dropped: line 1: 'x' is not a finite number";
        assert_eq!(read(false), [bad, &unseen]);
        assert_eq!(read(true), [unseen]);
        let off = "OFF\n4 1 0\n0 0 0\n1 1 0\n1 0 0\n0 1 0\n4 0 1 2 3\n3 0 1 2\n";
        let raw = formats::read_off(off.as_bytes()).unwrap();
        let options = ReadOptions {
            drop_attributes: true,
            ..Default::default()
        };
        let notes = finish(raw, Path::new("t.off"), &options).unwrap().notes;
        assert_eq!(notes.len(), 2, "{notes:?}");
        assert!(notes[0].starts_with("line 8: data after the 1 faces"), "{notes:?}");
    }

    #[test]
    fn a_keyhole_polygon_is_refused_and_read_with_repair_as_its_outline() {
        // A 4 × 4 square with a 2 × 2 hole, one face joined by a bridge from
        // vertex 1 to vertex 5 that the outline passes twice.
        let keyhole = "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\nv 1 1 0\nv 1 3 0\nv 3 3 0\nv 3 1 0\n\
                       f 1 2 3 4 1 5 6 7 8 5\n";
        let read = |repair| {
            finish(
                obj::parse_obj(keyhole.as_bytes()).unwrap(),
                Path::new("k.obj"),
                &ReadOptions {
                    repair,
                    ..Default::default()
                },
            )
        };
        let refused = read(None).unwrap_err().to_string();
        assert!(refused.contains("face 1 repeats vertex 1"), "{refused}");
        let m = read(Some(RepairOptions::default())).unwrap();
        let report = m.repair.clone().unwrap();
        assert_eq!(
            report.lines(),
            ["read 1 polygon that passes through a point twice as the outline it traces"]
        );
        assert!(!report.is_clean());
        // The triangles cover the square less the hole: 16 - 4.
        let area: f64 = m
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| m.positions[v as usize]);
                (b - a).cross(c - a).z / 2.0
            })
            .sum();
        assert_eq!(area, 12.0);
    }

    #[test]
    fn repair_that_only_welds_hands_its_connectivity_to_the_surface() {
        // two triangles of a square, each with its own copy of the shared edge, and a
        // repeated-vertex face: welding and dropping are all the repair does
        let soup = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\nf 1 1 2\n";
        let opts = ReadOptions {
            repair: Some(RepairOptions::default()),
            ..Default::default()
        };
        let mut m = finish(obj::parse_obj(soup.as_bytes()).unwrap(), Path::new("t.obj"), &opts).unwrap();
        assert_eq!(m.welded, 2);
        assert!(m.topology.is_some());
        let fresh = Surface::new(m.positions.clone(), &m.triangles).unwrap();
        let s = build_surface(&mut m, Path::new("t.obj")).unwrap();
        assert!(m.topology.is_none(), "taken by build_surface");
        s.validate().unwrap();
        assert_eq!(s, fresh);
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
    fn every_output_format_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let p = vec![
            DVec3::new(0.1, 0.2, 0.3),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 1.0 / 3.0),
        ];
        for ext in ["obj", "off", "ply", "stl"] {
            let path = dir.path().join(format!("m.{ext}"));
            write_mesh(&path, &p, &[[0, 1, 2]]).unwrap();
            let back = read_obj(&path).unwrap();
            assert_eq!(back.triangles.len(), 1, "{ext}");
            if ext != "stl" {
                assert_eq!(back.positions, p, "{ext}");
            }
        }
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
