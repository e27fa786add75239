//! Reading a mesh file of any format into the [`InputMesh`] the algorithm
//! takes ([`finish`]: triangulated, welded, every refusal of SPEC §6), and
//! building its [`Surface`] ([`build_surface`]).

use std::io::Read;
use std::path::Path;

use glam::DVec3;

use crate::attributes::{AttributeCuts, Attributes, Tolerances, NO_VALUE};
use crate::error::{Error, Result};
use crate::geometry;
use crate::mesh::{component_is_orientable, room_for_splits, NoCuts, RegionCuts, Surface, Topology, TopologyError};
use crate::repair::{self, RepairOptions, RepairReport};

use super::*;

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
    /// (the triangles of one face are consecutive; a face `--repair` dropped
    /// has none), when the file has attributes (its polygons are then
    /// flipped inside whatever their values:
    /// [`crate::mesh::RegionCuts::polygon`]) or [`ReadOptions::face_numbers`]
    /// asks (`--face-map` names them). Empty otherwise, and in a mesh made
    /// by a caller: each triangle a face of its own.
    pub triangle_polygon: Vec<u32>,
    /// How `triangle_origin` counts.
    pub origin_kind: OriginKind,
    /// How the file numbers its vertices and faces, for messages.
    pub numbering: Numbering,
    /// Faces in the file (before triangulation).
    pub faces_in_file: usize,
    /// Vertices merged into an earlier one at the same position (bit for
    /// bit, but -0 and 0 alike).
    pub welded: usize,
    /// The vertices (indices into `positions`) that other vertices of the
    /// file were welded into, in increasing order: where a file keeps
    /// vertices apart at one position on purpose (a mesh `--repair` cut),
    /// welding is what makes it non-manifold, and a refusal says so. Empty
    /// when none was, after `--repair`, and in an STL (every vertex of
    /// which is found by welding).
    pub welded_into: Vec<u32>,
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
    /// Number every triangle's face of the file
    /// ([`InputMesh::triangle_polygon`]) even when the file has no
    /// attributes (`--face-map`): 4 bytes per triangle.
    pub face_numbers: bool,
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
        None if formats::is_utf16_text(&bytes) => Error::Mesh {
            path: path.to_owned(),
            what: formats::UTF16_REASON.to_owned(),
        },
        None => match formats::foreign_reason(path.to_str(), &bytes, format != Format::Stl) {
            Some(what) => Error::Mesh {
                path: path.to_owned(),
                what,
            },
            None => format_error(path, e),
        },
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
        return finish_repaired(&raw, path, &repair_options, options.face_numbers);
    }
    // Weld identical positions onto their first occurrence (-0 and 0 alike).
    let mut first: FxMap<[u64; 3], u32> = FxMap::default();
    first.reserve(raw.positions.len());
    let welded_to: Vec<u32> = (0..raw.positions.len())
        .map(|i| {
            *first
                .entry(crate::hash::position_key(raw.positions[i]))
                .or_insert(i as u32)
        })
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
    // (Not in an STL, whose every vertex is found by welding: no message names it so.)
    let welded_into: Vec<u32> = if welded == 0 || raw.numbering == Numbering::Stl {
        Vec::new()
    } else {
        let mut into = vec![false; positions.len()];
        for (i, &to) in welded_to.iter().enumerate() {
            if i as u32 != to && used[to as usize] {
                into[new_index[to as usize] as usize] = true;
            }
        }
        (0..positions.len() as u32).filter(|&v| into[v as usize]).collect()
    };
    // Fan-triangulate, refusing repeated vertices and zero-area triangles.
    let mut triangles = Vec::with_capacity(raw.indices.len().saturating_sub(2 * n_faces));
    let mut triangle_origin = Vec::with_capacity(triangles.capacity());
    let mut raw_corners = Vec::new();
    let keep_attributes = !raw.attributes.is_empty();
    let number_faces = keep_attributes || options.face_numbers;
    let mut triangle_face = Vec::with_capacity(if number_faces { triangles.capacity() } else { 0 });
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
            if number_faces {
                triangle_face.push(f as u32);
            }
            if keep_attributes {
                let s = raw.face_start[f];
                raw_corners.push(corner.map(|c| s + c as u32));
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
        welded_into,
        unreferenced,
        repair: None,
        attributes,
        notes,
        topology: None,
    })
}

/// The attributes of `raw` on its triangles, given the raw corners and the
/// face of each triangle. A channel may leave whole faces without values
/// ([`crate::attributes::Channel::is_partial`]); one that leaves some corners of a face
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
        // (Repair may have dropped every face of a group.)
        a.compact_groups();
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
/// polygon traces): identical coordinates, as `finish` welds.
fn passes_a_point_twice(p: &[u32], positions: &[[f64; 3]], scratch: &mut Vec<[u64; 3]>) -> bool {
    scratch.clear();
    scratch.extend(p.iter().map(|&v| crate::hash::position_key(positions[v as usize])));
    scratch.sort_unstable();
    scratch.windows(2).any(|w| w[0] == w[1])
}

/// `finish` with `--repair`: triangulate everything, then let
/// [`repair::repair`] weld, drop and cut until the mesh is a manifold.
fn finish_repaired(raw: &RawMesh, path: &Path, options: &RepairOptions, face_numbers: bool) -> Result<InputMesh> {
    let n_faces = raw.face_start.len() - 1;
    let mut triangles = Vec::with_capacity(n_faces);
    let mut triangle_face = Vec::with_capacity(n_faces);
    let mut pieces = Vec::new();
    let mut unseen_polygons = 0;
    let mut keyhole_polygons = 0;
    let mut repeated_corners = 0;
    let mut scratch = Vec::new();
    let mut outline = Vec::new();
    // Each triangle's corners as entries of `raw.indices`, where the attributes' values are.
    let keep_attributes = !raw.attributes.is_empty();
    let mut raw_corners: Vec<[u32; 3]> = Vec::new();
    let mut entries: Vec<u32> = Vec::new();
    for f in 0..n_faces {
        let start = raw.face_start[f];
        let polygon = &raw.indices[start as usize..raw.face_start[f + 1] as usize];
        let mut p = polygon;
        if let &[a, b, c] = p {
            triangles.push([a, b, c]);
            triangle_face.push(f);
            if keep_attributes {
                raw_corners.push([start, start + 1, start + 2]);
            }
            continue;
        }
        // A corner at the position of the one before it (`f 1 2 2 3`, or
        // two vertex lines at one point) adds nothing to the outline, but
        // its zero-length side keeps every corner from seeing the polygon
        // whole: its fan from the first corner then overlaps itself.
        polygon::without_repeated_corners(p, &raw.positions, &mut outline);
        if outline.len() < p.len() && outline.len() >= 3 {
            repeated_corners += p.len() - outline.len();
            p = &outline;
        }
        keyhole_polygons += passes_a_point_twice(p, &raw.positions, &mut scratch) as usize;
        unseen_polygons += !polygon::triangulate(p.len(), |i| raw.positions[p[i] as usize], &mut pieces) as usize;
        if keep_attributes {
            // Each corner of `p` as an entry of the polygon: `p` is the polygon, or its outline
            // (the polygon's corners in order, some left out), matched in one walk.
            entries.clear();
            let mut i = 0;
            for &v in p {
                while i + 1 < polygon.len() && polygon[i] != v {
                    i += 1;
                }
                entries.push(start + i.min(polygon.len() - 1) as u32);
                i += 1;
            }
        }
        for &[a, b, c] in &pieces {
            triangles.push([p[a], p[b], p[c]]);
            triangle_face.push(f);
            if keep_attributes {
                raw_corners.push([entries[a], entries[b], entries[c]]);
            }
        }
    }
    // Past the ids' room repair could not number the faces (and would panic).
    if let Err(e) = crate::mesh::refuse_beyond_ids(raw.positions.len(), triangles.len()) {
        return Err(Error::Mesh {
            path: path.to_owned(),
            what: e.to_string(),
        });
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
                super::number::number_text(options.weld_tolerance),
                r.welded_vertices
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
    // The attributes of the triangles kept, each corner's value where the file gives it (a
    // reoriented triangle's corners in its own order; copies at cuts keep their corners').
    let mut corners = Vec::new();
    let triangle_polygon: Vec<u32> = if keep_attributes || face_numbers {
        (fixed.source_triangle.iter())
            .map(|&t| triangle_face[t as usize] as u32)
            .collect()
    } else {
        Vec::new()
    };
    if keep_attributes {
        for (&t, &flipped) in fixed.source_triangle.iter().zip(&fixed.flipped) {
            let [a, b, c] = raw_corners[t as usize];
            corners.push(if flipped { [a, c, b] } else { [a, b, c] });
        }
    }
    let (attributes, mut notes) = triangle_attributes(raw, &corners, &triangle_polygon);
    if unseen_polygons > 0 {
        notes.push(unseen_note(unseen_polygons));
    }
    Ok(InputMesh {
        positions: fixed.positions.iter().map(|p| DVec3::from_array(*p)).collect(),
        triangle_origin: fixed
            .source_triangle
            .iter()
            .map(|&t| origin_of(triangle_face[t as usize]))
            .collect(),
        vertex_number: fixed.source_vertex.iter().map(|&v| v + 1).collect(),
        triangles: fixed.triangles,
        triangle_polygon,
        origin_kind: raw.origin_kind,
        numbering: raw.numbering,
        faces_in_file: n_faces,
        welded: fixed.report.welded_vertices,
        welded_into: Vec::new(),
        unreferenced: fixed.report.unreferenced_vertices,
        repair: Some(fixed.report),
        attributes,
        notes,
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
    let mut attribute_cuts = AttributeCuts::new(&input.attributes, &input.positions, &input.triangles, tolerances);
    if !input.attributes.is_empty() {
        attribute_cuts = attribute_cuts.with_polygons(&input.triangle_polygon);
    }
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
        // Where welding the file's vertices at one position made the fault
        // (a file that keeps them apart on purpose, as `--repair` writes a
        // mesh it cut), the message says so (`welded_into` is empty for an
        // STL, whose corners are always welded).
        let welded = |vertices: &[u32]| vertices.iter().all(|v| input.welded_into.binary_search(v).is_ok());
        let once_welded = |vertices: &[u32], kind: &str| {
            if welded(vertices) {
                (
                    format!(
                        " once the file's vertices at {} are welded",
                        if vertices.len() == 1 { "its position" } else { "their positions" }
                    ),
                    format!(" ({kind}; a file cut apart there, as --repair writes one, is read with --repair)"),
                )
            } else {
                (String::new(), format!(" ({kind}){REPAIR_HINT}"))
            }
        };
        let what = match e {
            TopologyError::EdgeWithMoreThanTwoFaces { face, a, b } => {
                let (once, hint) = once_welded(&[a, b], "non-manifold edge");
                format!(
                    "{}: edge between {} and {} has more than two faces{once}, this one the third{hint}",
                    at(face),
                    v(a),
                    v(b)
                )
            }
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
                    // Not a fault of this face alone: no orientation of the
                    // surface avoids it (a Möbius band), which --repair only
                    // mends by cutting the surface open.
                    None if !welded(&[a, b]) && !component_is_orientable(&input.triangles, face) => format!(
                        "{}: face runs along the edge from {} to {} in the same direction as another face, as some \
                         face must on this surface: it is not orientable (a Möbius band), and delmesh refines \
                         oriented surfaces only (--repair cuts it open where it must, leaving a seam)",
                        at(face),
                        v(a),
                        v(b)
                    ),
                    None => {
                        let (once, hint) = once_welded(&[a, b], "inconsistent orientation");
                        format!(
                            "{}: face runs along the edge from {} to {} in the same direction as another face{once}{hint}",
                            at(face),
                            v(a),
                            v(b)
                        )
                    }
                }
            }
            TopologyError::NonManifoldVertex { vertex } => {
                let (once, hint) = once_welded(&[vertex], "non-manifold vertex");
                format!("{}: its faces form more than one fan{once}{hint}", v(vertex))
            }
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
            TopologyError::TooLarge { .. } => e.to_string(),
        };
        Error::Mesh { path: path.to_owned(), what }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::attributes::Tolerances;
    use crate::error::Error;
    use std::path::Path;

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

    /// A file may write the same point's zero coordinates as `0` in one
    /// place and `-0` in another (a rotation, a `%g` of a tiny negative):
    /// welded all the same, keeping the first one's bits. Kept apart, they
    /// cut the surface open there without a word.
    #[test]
    fn welds_negative_zero_with_zero() {
        let m = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv -0 0 -0\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 5 4 3\n").unwrap();
        assert_eq!(m.welded, 1);
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles[3], [0, 3, 2]);
        assert!(m.positions[0].to_array().iter().all(|x| x.to_bits() == 0));
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
        assert!(notes[0].starts_with("line 8: data after the 1 face the"), "{notes:?}");
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
}
