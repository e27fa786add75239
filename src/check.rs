//! Independent judge of a delmesh result.
//!
//! Given the INPUT mesh and the OUTPUT mesh (Wavefront OBJ files, or meshes already read with
//! [`Mesh3::read_obj`]), [`check_files`] / [`check_meshes`] decide whether OUTPUT is a valid
//! Delaunay mesh of INPUT with exactly the same geometry. The module shares no geometry or
//! topology code with the construction: it has its own OBJ reader (numbers read by Rust's own
//! parsers, not the construction's), its own topology and its own geometry; it borrows only
//! the crate's hash map ([`crate::hash`]).
//!
//! # What is checked
//!
//! 1. Every input vertex appears in the output with identical coordinates (bit for bit, but
//!    -0 and 0 alike, as positions are welded).
//! 2. Every other output vertex lies on an input edge, strictly between its endpoints, within
//!    [`ON_EDGE_TOLERANCE`] (relative to the edge's coordinates). Candidate edges come from a
//!    spatial hash over pieces of the input edges, whose crowded cells (around a vertex of high
//!    valence) are refined by octrees where output vertices fall, so the search is near linear.
//!    An added vertex belongs to the regions of the input edges nearest to it (within roundoff of
//!    the nearest distance), not of every edge within the tolerance. (Where the output has more
//!    vertices than the input at an input vertex's position that also lies inside an input edge,
//!    the surface touching itself, each of them may be either: they belong to the regions of
//!    both.) A vertex no face uses must also be at an input vertex's position (used or not)
//!    or on an input edge; it is counted in [`CheckReport::unused_vertices`].
//! 3. Every output face lies inside one planar region of the input (input faces joined across
//!    exactly coplanar, unfolded edges, decided with exact predicates) and has the region's
//!    orientation, exactly: its projection along the region's main axis has the orientation of
//!    the region's faces and non-zero area (an exact `orient2d`, so that a valid needle face is
//!    never called degenerate and a folded one never passes).
//! 4. The area of every planar region is unchanged (relative [`AREA_TOLERANCE`], plus what
//!    rounding the added vertices on the region's border can do, [`AREA_ROUNDING`], and
//!    [`AREA_FLOOR`], far below any face). Face areas
//!    are computed at the corner opposite the longest edge from exact edge vectors, and summed
//!    with compensation, so that they stay accurate far from the origin and for needle faces.
//!    Regions that an output face fits equally (coplanar regions overlapping in a
//!    self-intersecting input) are checked together, on their total area. A face with a vertex
//!    off the input's edges (a failure of rule 2) counts in a region whose plane holds it, and
//!    proves no overlap; in the plane of no region at its other vertices, it lies on no input
//!    face, a failure of its own, and counts in no region.
//! 5. The topology is unchanged: the output is an oriented manifold, and its Euler characteristic,
//!    number of boundary loops and number of connected components equal the input's.
//! 6. Every interior output edge is Delaunay: `alpha + beta <= pi + DELAUNAY_TOLERANCE`.
//! 7. ([`check_files`] only.) The OUTPUT's file does not give one vertex two records that reading
//!    joins (not copies a seam made, nor distinct vertices rounded to one point, which reading
//!    keeps apart) unless the INPUT's file has such copies too: a reader that does not weld
//!    by position would see the surface cut there.
//!
//! The maps a run writes beside its output are judged by [`maps`].
//!
//! # How files are read
//!
//! Polygons are triangulated (by [`triangulate`]: a fan, or ears) and identical positions welded
//! (-0 and 0 alike), as the construction reads its input. Then what `delmesh --repair` cut apart on
//! purpose, by giving faces their own copies of vertices at one position, is kept apart: where
//! welding would put more than two faces on an edge or two faces along it the same way, the file's
//! own vertices at the edge's ends stay apart; a vertex whose faces form several fans becomes one
//! vertex per fan; and [`check_files`] keeps the OUTPUT's own vertices apart wherever, read so, it
//! has another count of vertices at one position than the INPUT ([`Mesh3::read_like`]), except the
//! copies a seam made (OFF and PLY give a vertex one record per attribute value, OBJ one per vertex
//! colour): where a seam meets a cut and the file leaves a choice of which copies go together, the
//! one that gives the INPUT's shape (then its counts) is taken. A mesh the construction accepts
//! without `--repair` is read welded, nothing kept apart.
//!
//! Failures are reported as human-readable lines (at most [`MAX_LINES_PER_KIND`] per kind).
//! [`check_files`] names vertices and faces as each file's format numbers them, as the
//! construction's messages do: OBJ from 1 (a vertex by its first `v` line at that position, a
//! triangle by the `f` line it comes from), OFF and PLY from 0, STL's vertices by position and
//! its facets from 0; a face or vertex that makes a file unreadable or an input invalid is named
//! with its line (or, in a binary file, its face record). [`check_meshes`] numbers the
//! [`Mesh3`]'s own vertices and triangles from 1. Nothing here panics on bad input: an
//! unreadable or invalid INPUT gives a [`CheckError`] (or a failure line from
//! [`check_meshes`]), anything wrong with OUTPUT gives failure lines.

pub mod maps;

use std::collections::HashSet;
use std::f64::consts::PI;
use std::fmt;
use std::path::{Path, PathBuf};

use crate::attributes::Channel;
use crate::hash::FastMap;
use crate::io::formats::{show, Numbering, OriginKind, RawMesh};
use crate::io::number::point_text;
use crate::io::polygon::triangulate;
use glam::DVec3;

/// An interior edge is Delaunay iff `alpha + beta <= pi + DELAUNAY_TOLERANCE` (radians), where
/// `alpha` and `beta` are the angles opposite the edge in its two faces.
pub const DELAUNAY_TOLERANCE: f64 = 1e-9;

/// Relative tolerance on the area of a planar region (relative to the region's input area).
pub const AREA_TOLERANCE: f64 = 1e-9;

/// Absolute floor of the area tolerance: differences below it are the rounding of areas near
/// the bottom of the f64 range, not geometry.
///
/// (Until the fifty-third session the floor was `1e-12` of the total input area, which let a
/// face far larger than the rest hide the others: beside a triangle 2e12 long, a face 0.05 in
/// area at the border of a grid could be dropped from the output and the check still passed,
/// its region's area being within the floor. A region's tolerance is now its own: relative to
/// its area, plus [`AREA_ROUNDING`] for its border.)
pub const AREA_FLOOR: f64 = 1e-300;

/// What rounding the positions of added vertices may do to a region's area, in units of
/// roundoff: each input edge on the region's border (a boundary edge, or an edge to another
/// region) that has added vertices on it adds `AREA_ROUNDING * f64::EPSILON * max(max|a_i|,
/// |b_i|) * |b - a|` to the region's area tolerance.
///
/// A vertex added on edge `(a, b)` is stored rounded: computed as `a + t (b - a)` in f64 it is
/// off the exact segment by at most about `4.3 * f64::EPSILON * max|coordinate|` (three
/// roundings per coordinate), and however many vertices an edge gets, moving each by at most `d`
/// off the line changes the area on either side by at most `d * |b - a|`; 8 is that bound with a
/// margin of 2. Relative to a region's area the allowance is about `f64::EPSILON *
/// max|coordinate| / width`: negligible for ordinary faces (1e-15 for a unit triangle near the
/// origin), but above [`AREA_TOLERANCE`] for a needle region 2 wide and 4e9 long, whose
/// vertices added near the middle of the long edge are in general rounded up to about 1e-7
/// off it (`regression_checker_needle_region_rounding` in tests/fuzz.rs).
pub const AREA_ROUNDING: f64 = 8.0;

/// Distance tolerance of the on-edge test, relative to the largest absolute coordinate of the
/// edge's endpoints: a point `p` is on input edge `(a, b)` iff its projection parameter `t` lies
/// in `(0, 1)` and `|p - (a + t (b - a))| <= ON_EDGE_TOLERANCE * max(1e-300, max|a_i|, |b_i|)`.
///
/// A point computed in f64 as `a + t * (b - a)` is off the exact segment by a few units in the
/// last place of the coordinates (about `4e-16` relative) and the test itself adds about as much,
/// so `1.6e-11` accepts every such point with a margin of more than 10^4, while still refusing a
/// point moved off the edge by `1e-9` relative (60 times the tolerance).
pub const ON_EDGE_TOLERANCE: f64 = 16e-12;

/// At most this many failure lines are reported per kind of failure; the rest are summarised
/// in one `... and N more` line.
pub const MAX_LINES_PER_KIND: usize = 20;

/// Files together at least this large are read on two threads at once (when allowed), and
/// meshes with at least [`PARALLEL_FACES`] faces together are examined so: below, starting a
/// thread costs about what it saves.
const PARALLEL_BYTES: u64 = 1 << 20;

/// See [`PARALLEL_BYTES`].
const PARALLEL_FACES: usize = 1 << 15;

/// A triangle mesh as the checker sees it: welded positions and triangles indexing them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh3 {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles as 0-based indices into `positions`, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// Why a check could not be run at all.
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    /// The file could not be read.
    #[error("{}: cannot read the file: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a readable mesh (syntax, bad index, non-finite coordinate, ...).
    #[error("{}: not a valid {format} mesh: {reason}", .path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// Its format as read ("OBJ", "OFF", "PLY", "STL"; "gzip" if it could not be inflated).
        format: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// The file has no triangle (after ignoring points and lines).
    #[error("{}: the mesh has no faces", .path.display())]
    NoFaces {
        /// The file.
        path: PathBuf,
    },
    /// The files cannot be judged as asked (an STL OUTPUT's maps: its coordinates are rounded
    /// to f32 and it has no vertex list).
    #[error("{}: {reason}", .path.display())]
    Unjudgeable {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// The INPUT mesh itself is not a valid input (non-manifold, inconsistently oriented,
    /// degenerate faces repeating a vertex), so no output can be judged against it.
    #[error("{}: the input mesh is invalid: {reason}", .path.display())]
    InvalidInput {
        /// The input file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
}

/// The outcome of a check: statistics and the list of failures.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckReport {
    /// Vertices of the input (referenced by a face).
    pub input_vertices: usize,
    /// Faces of the input.
    pub input_faces: usize,
    /// Planar regions of the input.
    pub input_regions: usize,
    /// Vertices of the output (referenced by a face).
    pub output_vertices: usize,
    /// Faces of the output.
    pub output_faces: usize,
    /// Output vertices that are not input vertices (valid or not).
    pub added_vertices: usize,
    /// Output vertices that no face uses (not counted in `output_vertices`): each must still
    /// be at an input vertex's position or on an input edge, but gives a Laplacian an empty
    /// row.
    pub unused_vertices: usize,
    /// Where the output stops beginning with the input's vertices in the input's order (0-based:
    /// output vertex `k` is not input vertex `k`, bit for bit but -0 and 0 alike); `None` when
    /// it does begin so, as delmesh writes it. Not a failure (the geometry does not depend on numbering), but the
    /// input's per-vertex data does not carry over by number. From files, vertices are
    /// numbered as [`Mesh3::read_obj`] says: identical positions welded, unused ones left out.
    pub first_reordered_vertex: Option<usize>,
    /// That vertex as the output's file and the input's file name it (`vertex 7` in OBJ, from
    /// 1; `vertex 6` in OFF and PLY, from 0; `vertex at (x, y, z)` in STL): the output's name,
    /// then the input's.
    pub first_reordered_vertex_names: Option<(String, String)>,
    /// Interior edges of the output (two faces, opposite directions).
    pub interior_edges: usize,
    /// Interior output edges with `alpha + beta > pi + DELAUNAY_TOLERANCE`.
    pub non_delaunay_edges: usize,
    /// `max(alpha + beta - pi)` over the interior output edges, in radians
    /// (`f64::NEG_INFINITY` when there is no interior edge).
    pub max_excess: f64,
    /// One human-readable line per failure, at most [`MAX_LINES_PER_KIND`] per kind plus one
    /// `... and N more` line per kind that overflowed. Empty iff the output is valid.
    pub failures: Vec<String>,
}

impl CheckReport {
    /// True iff the output is a valid result for the input (no failure).
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }

    /// [`CheckReport::max_excess`] for a printout: in radians, or `none`
    /// when the output has no interior edge (a mesh of separate triangles).
    pub fn max_excess_text(&self) -> String {
        if self.interior_edges == 0 {
            "none (no interior edge)".to_string()
        } else {
            format!("{:.3e} rad", self.max_excess)
        }
    }

    fn empty(input: &Mesh3, output: &Mesh3) -> CheckReport {
        CheckReport {
            input_vertices: 0,
            input_faces: input.triangles.len(),
            input_regions: 0,
            output_vertices: 0,
            output_faces: output.triangles.len(),
            added_vertices: 0,
            unused_vertices: 0,
            first_reordered_vertex: None,
            first_reordered_vertex_names: None,
            interior_edges: 0,
            non_delaunay_edges: 0,
            max_excess: f64::NEG_INFINITY,
            failures: Vec::new(),
        }
    }
}

impl fmt::Display for CheckReport {
    /// A multi-line summary followed by the failure lines.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "input: {} vertices, {} faces, {} planar regions",
            self.input_vertices, self.input_faces, self.input_regions
        )?;
        writeln!(
            f,
            "output: {} vertices ({} added), {} faces",
            self.output_vertices, self.added_vertices, self.output_faces
        )?;
        if self.unused_vertices > 0 {
            writeln!(f, "unused output vertices (in no face): {}", self.unused_vertices)?;
        }
        if let Some((output, _)) = &self.first_reordered_vertex_names {
            writeln!(f, "input vertices not first in input order: output {output} differs")?;
        }
        writeln!(
            f,
            "interior edges: {}, non-Delaunay: {}, max alpha+beta-pi: {}",
            self.interior_edges,
            self.non_delaunay_edges,
            self.max_excess_text()
        )?;
        if self.passed() {
            write!(f, "PASS")
        } else {
            write!(f, "FAIL")?;
            for line in &self.failures {
                write!(f, "\n  {line}")?;
            }
            Ok(())
        }
    }
}

/// Reads INPUT with [`Mesh3::read`] and OUTPUT with [`Mesh3::read_like`] it, and checks
/// OUTPUT against INPUT.
///
/// Errors when a file cannot be read, is not an OBJ mesh, has no faces, or when the input
/// is itself invalid (see [`CheckError::InvalidInput`]). Everything wrong with the output is
/// reported as failure lines in the [`CheckReport`].
pub fn check_files(input: &Path, output: &Path) -> Result<CheckReport, CheckError> {
    check_files_with(input, output, None::<fn(RawMesh, RawMesh, bool)>).map(|(report, _)| report)
}

/// [`check_files`], handing `also` the two files as they list their vertices and faces (as
/// [`read_raw`] reads them, for [`maps::check_maps_of`]: INPUT's, OUTPUT's, and whether
/// OUTPUT's faces share vertices by index) once both are read and before they are compared,
/// so that the maps' judge need not read them again; its result comes back beside the report
/// (`None` without `also`). Each file is still read once: the raw meshes are what the judge's
/// welding starts from.
pub fn check_files_with<T>(
    input: &Path,
    output: &Path,
    also: Option<impl FnOnce(RawMesh, RawMesh, bool) -> T>,
) -> Result<(CheckReport, Option<T>), CheckError> {
    // The two files are read at once when they are large enough to repay a thread (the input's
    // error, if any, is still the one reported first).
    let size = |path: &Path| std::fs::metadata(path).map_or(0, |m| m.len());
    let worth_it = size(input).saturating_add(size(output)) >= PARALLEL_BYTES;
    let keep_raw = also.is_some();
    let read_input = || {
        read_welded_keeping(input, keep_raw).map(|(mut welded, raw)| {
            // (Whether the input's file has copies of its own: then the output's are not judged.)
            let copies = copies_apart(&welded.mesh, &welded.file_corners, 0).0 > 0;
            let in_file = welded.mesh.positions.len();
            let Settled { mesh, around } = settle(welded.mesh, &welded.file_corners);
            drop(welded.file_corners);
            welded.naming.name_copies(&mesh.positions, in_file);
            // The vertices no face uses, after all the others (their own numbers are not the
            // file's): an output one must still be an input vertex or lie on an input edge.
            let mut mesh = mesh;
            let settled = mesh.positions.len();
            mesh.positions.extend(welded.strays);
            // (Validated while the output may still be read: its error, if any, is reported
            // only once both files are read.)
            let prepared = prepare_input(&mesh, Some(&around), &welded.naming);
            drop(around);
            (mesh, settled, welded.naming, in_file, prepared, copies, raw)
        })
    };
    let read_output = || read_welded_keeping(output, keep_raw);
    let (input_read, output_read) = crate::parallel::join(worth_it, read_input, read_output);
    let (input_mesh, input_settled, input_naming, input_in_file, input_prepared, input_copies, input_raw) = input_read?;
    let (mut welded, output_raw) = output_read?;
    let also = match (also, input_raw, output_raw) {
        (Some(also), Some(input_raw), Some((output_raw, shares_vertices))) => {
            Some(also(input_raw.0, output_raw, shares_vertices))
        }
        _ => None,
    };
    let output_in_file = welded.mesh.positions.len();
    let input_positions = &input_mesh.positions[..input_settled];
    let Settled {
        mesh: mut output_mesh,
        around: output_around,
    } = settle_like(
        welded.mesh,
        &welded.file_corners,
        &input_mesh,
        input_positions,
        input_in_file,
    );
    // Copies the output's file has at one position that reading joins (not kept apart as
    // distinct vertices that round to one point, nor a seam's), where the input's file has
    // none: a reader that does not weld by position (most do not) sees the surface cut there.
    let cracks = if input_copies {
        (0, Vec::new())
    } else {
        copies_apart(&output_mesh, &welded.file_corners, MAX_LINES_PER_KIND)
    };
    drop(welded.file_corners);
    let crack_lines: Vec<String> = (cracks.1.iter())
        .map(|&(v, a, b)| {
            let p = output_mesh.positions[v as usize];
            let numbering = welded.naming.numbering;
            let origin = |f: u32| match (welded.naming.origin_kind, welded.naming.vertex_origin.get(f as usize)) {
                (OriginKind::Line, Some(line)) => format!("line {line}"),
                _ => numbering.vertex(f, p.to_array()),
            };
            format!(
                "output {} and {} are at one position {} but apart in the file ({} and {}): a reader that does not weld positions sees a crack there (the input has no such copies)",
                numbering.vertex(a, p.to_array()),
                numbering.vertex(b, p.to_array()),
                point_text(p),
                origin(a),
                origin(b)
            )
        })
        .chain((cracks.0 > MAX_LINES_PER_KIND).then(|| format!("... and {} more crack failures", cracks.0 - MAX_LINES_PER_KIND)))
        .collect();
    welded.naming.name_copies(&output_mesh.positions, output_in_file);
    let output_naming = welded.naming;
    // Settling only appends vertices (copies where welding is undone): the first ones are still
    // the files' own, in file order.
    let reordered = first_reordered_vertex(&input_mesh.positions[..input_in_file], &output_mesh.positions);
    // (The output's vertices no face uses too, as the input's.)
    output_mesh.positions.extend(welded.strays);
    let meshes = Meshes {
        input: &input_mesh,
        output: &output_mesh,
        input_naming: &input_naming,
        output_naming: &output_naming,
        output_around: Some(&output_around),
    };
    let mut report = check_core(meshes, Some(input_prepared)).map_err(|reason| CheckError::InvalidInput {
        path: input.to_path_buf(),
        reason,
    })?;
    report.failures.extend(crack_lines);
    report.first_reordered_vertex = reordered;
    report.first_reordered_vertex_names = reordered.map(|k| {
        let name = |mesh: &Mesh3, naming: &Naming| Names::new("", mesh, naming).vertex_noun(k as u32);
        (name(&output_mesh, &output_naming), name(&input_mesh, &input_naming))
    });
    Ok((report, also))
}

/// The first index below `input.len()` where `output` does not have the input's vertex, bit
/// for bit (`output` shorter counts as a difference); `None` if `output` begins with `input`.
fn first_reordered_vertex(input: &[DVec3], output: &[DVec3]) -> Option<usize> {
    let same = |k: usize| output.get(k).is_some_and(|q| bits(*q) == bits(input[k]));
    (0..input.len()).find(|&k| !same(k))
}

/// Checks OUTPUT against INPUT, both already read. An invalid input is reported as a single
/// `input mesh is invalid: ...` failure line. An output vertex no face uses must still be at the
/// position of an input vertex (used by a face or not) or on an input edge, and is counted in
/// [`CheckReport::unused_vertices`]; unused input vertices are only such positions.
pub fn check_meshes(input: &Mesh3, output: &Mesh3) -> CheckReport {
    let naming = Naming::default();
    let meshes = Meshes {
        input,
        output,
        input_naming: &naming,
        output_naming: &naming,
        output_around: None,
    };
    let mut report = check_core(meshes, None).unwrap_or_else(|reason| {
        let mut report = CheckReport::empty(input, output);
        report.failures.push(format!("input mesh is invalid: {reason}"));
        report
    });
    report.first_reordered_vertex = first_reordered_vertex(&input.positions, &output.positions);
    report.first_reordered_vertex_names = report
        .first_reordered_vertex
        .map(|k| (format!("vertex {}", k + 1), format!("vertex {}", k + 1)));
    report
}

// ---------------------------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------------------------

impl Mesh3 {
    /// Reads a mesh file: OBJ with [`Mesh3::read_obj`]; OFF, PLY and STL (possibly
    /// gzip-compressed) with the readers of [`crate::io::formats`] — the one piece of reading
    /// code the judge shares with the construction, for formats its own reader does not read — followed
    /// by the same welding and pinch rule as OBJ.
    pub fn read(path: impl AsRef<Path>) -> Result<Mesh3, CheckError> {
        let welded = read_welded(path.as_ref())?;
        Ok(settle(welded.mesh, &welded.file_corners).mesh)
    }

    /// Reads the output of a run on `input` (read with [`Mesh3::read`]) as [`Mesh3::read`]
    /// does, except where that gives another count of vertices at a position than `input` has
    /// (a surface `--repair` cut apart there, whose refined copy need not keep the edges that
    /// tell where welding must be undone, see `split_welded_sheets`): there the file's own
    /// vertices are kept apart instead of welded, but for the copies a seam made.
    pub fn read_like(path: impl AsRef<Path>, input: &Mesh3) -> Result<Mesh3, CheckError> {
        let welded = read_welded(path.as_ref())?;
        Ok(settle_like(welded.mesh, &welded.file_corners, input, &input.positions, 0).mesh)
    }

    /// Reads a Wavefront OBJ file: all objects and groups merged into one mesh, polygons
    /// triangulated (by [`triangulate`]), points and lines ignored, vertices with identical
    /// positions welded (-0 and 0 alike),
    /// vertices referenced by no face dropped. Vertices are numbered in the order of their first
    /// `v` line. Material libraries are not read.
    ///
    /// Errors when the file cannot be read or parsed, a face index is out of range, a used
    /// coordinate is not finite, or there is no face.
    pub fn read_obj(path: impl AsRef<Path>) -> Result<Mesh3, CheckError> {
        let path = path.as_ref();
        let bytes = crate::io::read_bytes(path).map_err(|source| CheckError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Mesh3::read_obj_bytes(path, &bytes)
    }

    /// [`Mesh3::read_obj`] on bytes already read; `path` names the file in errors.
    pub fn read_obj_bytes(path: &Path, bytes: &[u8]) -> Result<Mesh3, CheckError> {
        let welded = weld_obj(path, &obj_raw(path, bytes)?)?;
        Ok(settle(welded.mesh, &welded.file_corners).mesh)
    }
}

// ---------------------------------------------------------------------------------------------
// Names of vertices and faces
// ---------------------------------------------------------------------------------------------

/// How failure lines name the vertices and faces of a mesh: as its file numbers them (OBJ from
/// 1, OFF and PLY from 0, STL's vertices by their positions and its facets from 0), with the
/// line (or, in a binary file, the face record) where the file says it. The default, for a
/// mesh given as a [`Mesh3`], numbers its own vertices and triangles from 1 and knows no lines.
#[derive(Clone, Debug, Default)]
struct Naming {
    /// How the file numbers its vertices and faces.
    numbering: Numbering,
    /// The file's vertex (from 0, in its vertex list) of every mesh vertex; where this is
    /// shorter than the mesh's vertices, a vertex is its own.
    vertex: Vec<u32>,
    /// The file's face (from 0) of every triangle (a polygon gives several); where this is
    /// shorter than the triangles, a triangle is its own.
    face: Vec<u32>,
    /// The line (or record) of every vertex of the file; empty: unknown.
    vertex_origin: Vec<u32>,
    /// The line (or record) of every face of the file; empty: unknown.
    face_origin: Vec<u32>,
    /// Whether the origins are lines or records.
    origin_kind: OriginKind,
}

/// `numbers`, or nothing when it is `0, 1, 2, ...` (a [`Naming`]'s map that changes nothing:
/// every triangle mesh whose file has no duplicated or unused vertex).
fn identity_or(numbers: Vec<u32>) -> Vec<u32> {
    if numbers.iter().enumerate().all(|(i, &n)| n as usize == i) {
        Vec::new()
    } else {
        numbers
    }
}

impl Naming {
    /// Names the vertices that reading appended to the first `before` of `positions` (copies
    /// where welding was undone) as the first vertex at their position.
    fn name_copies(&mut self, positions: &[DVec3], before: usize) {
        if positions.len() <= before {
            return;
        }
        if self.vertex.len() < before {
            let own = self.vertex.len() as u32..before as u32;
            self.vertex.extend(own);
        }
        let mut first: FastMap<[u64; 3], u32> = FastMap::default();
        for (v, p) in positions[..before].iter().enumerate().rev() {
            first.insert(bits(*p), self.vertex[v]);
        }
        self.vertex.truncate(before);
        for (v, p) in positions.iter().enumerate().skip(before) {
            let number = first.get(&bits(*p)).copied().unwrap_or(v as u32);
            self.vertex.push(number);
        }
    }
}

/// A mesh's [`Naming`] at work: `who` ("input" or "output") and the mesh, for failure lines.
#[derive(Clone, Copy)]
struct Names<'a> {
    who: &'a str,
    mesh: &'a Mesh3,
    naming: &'a Naming,
}

impl<'a> Names<'a> {
    /// The names of `mesh`'s vertices and faces, the mesh called `who`.
    fn new(who: &'a str, mesh: &'a Mesh3, naming: &'a Naming) -> Names<'a> {
        Names { who, mesh, naming }
    }

    /// The file's number of vertex `v`, as the file counts (from 1 or 0); its own index if the
    /// file's is unknown.
    fn vertex_number(&self, v: u32) -> u64 {
        let file = match self.naming.vertex.get(v as usize) {
            Some(&n) if n != u32::MAX => n,
            _ => v,
        };
        let file = u64::from(file);
        match self.naming.numbering {
            Numbering::FromOne => file + 1,
            Numbering::FromZero | Numbering::Stl => file,
        }
    }

    /// Vertex `v` in a list: `v7`, or in STL its position `(x, y, z)`.
    fn label(&self, v: u32) -> String {
        match (self.naming.numbering, self.mesh.positions.get(v as usize)) {
            (Numbering::Stl, Some(p)) => point_text(*p),
            _ => format!("v{}", self.vertex_number(v)),
        }
    }

    /// Vertex `v` on its own: `vertex 7`, or in STL `vertex at (x, y, z)`.
    fn vertex_noun(&self, v: u32) -> String {
        match (self.naming.numbering, self.mesh.positions.get(v as usize)) {
            (Numbering::Stl, Some(p)) => format!("vertex at {}", point_text(*p)),
            _ => format!("vertex {}", self.vertex_number(v)),
        }
    }

    /// Vertex `v` with its position: `vertex 7 (x, y, z)`, or in STL `vertex at (x, y, z)`.
    fn vertex(&self, v: u32) -> String {
        match (self.naming.numbering, self.mesh.positions.get(v as usize)) {
            (Numbering::Stl, _) | (_, None) => self.vertex_noun(v),
            (_, Some(p)) => format!("vertex {} {}", self.vertex_number(v), point_text(*p)),
        }
    }

    /// The file's face of triangle `f`: `face 4`, or in STL `facet 3`.
    fn face_noun(&self, f: usize) -> String {
        let file = self.naming.face.get(f).map_or(f as u64, |&x| u64::from(x));
        match self.naming.numbering {
            Numbering::FromOne => format!("face {}", file + 1),
            Numbering::FromZero => format!("face {file}"),
            Numbering::Stl => format!("facet {file}"),
        }
    }

    /// Triangle `f` with its corners: `face 4 (v1, v2, v3)` (the file's face, of which the
    /// triangle may be a piece).
    fn face(&self, f: usize) -> String {
        match self.mesh.triangles.get(f) {
            Some(t) => format!("{} {}", self.face_noun(f), self.corners(t)),
            None => self.face_noun(f),
        }
    }

    /// The corners of a triangle: `(v1, v2, v3)`.
    fn corners(&self, t: &[u32; 3]) -> String {
        format!("({}, {}, {})", self.label(t[0]), self.label(t[1]), self.label(t[2]))
    }

    /// Where in the file triangle `f` is, as a failure line begins with it: `line 17: ` or
    /// `face record 3: ` (empty when unknown).
    fn face_at(&self, f: usize) -> String {
        let file = self.naming.face.get(f).map_or(f, |&x| x as usize);
        self.origin(self.naming.face_origin.get(file), "face record")
    }

    /// Where in the file vertex `v` is, as [`Names::face_at`]: `line 7: ` (empty when unknown
    /// or in a binary file, whose vertex records are not faces).
    fn vertex_at(&self, v: u32) -> String {
        let file = self.naming.vertex.get(v as usize).copied().unwrap_or(v);
        match self.naming.origin_kind {
            OriginKind::Line => self.origin(self.naming.vertex_origin.get(file as usize), ""),
            OriginKind::Record => String::new(),
        }
    }

    /// `line N: ` or `{record} N: ` for an origin, if known.
    fn origin(&self, origin: Option<&u32>, record: &str) -> String {
        match (origin, self.naming.origin_kind) {
            (Some(line), OriginKind::Line) => format!("line {line}: "),
            (Some(n), OriginKind::Record) => format!("{record} {n}: "),
            (None, _) => String::new(),
        }
    }
}

/// [`Mesh3::read_like`] on a file already read by [`read_welded`], `input` being the
/// positions of the input's vertices (those of `input_mesh` that faces use). Only
/// `input[first_copy..]` may repeat a position of the input (0 for any mesh; a mesh read by
/// [`read_welded`] and [`settle`] has its copies last, after the file's welded vertices, and
/// usually none).
///
/// Where the output read as [`settle`] reads it has another count of vertices than the input
/// at a position the input has several at (or the output has), or closes a boundary edge the
/// input has at such a position ([`keeps_open`]), welding is undone there again ([`unweld`])
/// with the input's count as the aim. Where a seam meets a cut, which copies a
/// seam joins is a choice that the file alone does not settle: the first pairing that comes
/// out with the input's [`Shape`] and counts is kept, or the nearest found, shape first
/// (every combination of choices when there are few enough for the mesh's size, else one
/// choice changed at a time). Where the input has one vertex at each position, see
/// [`settle_aimed_at_shape`].
fn settle_like(
    welded: Mesh3,
    file_corners: &FileVertices,
    input_mesh: &Mesh3,
    input: &[DVec3],
    first_copy: usize,
) -> Settled {
    // How many vertices the input has at each position it has several at (usually none).
    let copies = input.get(first_copy..).unwrap_or_default();
    if copies.is_empty() {
        return settle_aimed_at_shape(welded, file_corners, input_mesh);
    }
    let mut count: FastMap<[u64; 3], i64> = FastMap::default();
    if first_copy == 0 {
        for p in input {
            *count.entry(bits(*p)).or_insert(0) += 1;
        }
    } else {
        // (Only the copies' positions can be repeated: count those alone.)
        count.extend(copies.iter().map(|p| (bits(*p), 0)));
        for p in input {
            if let Some(c) = count.get_mut(&bits(*p)) {
                *c += 1;
            }
        }
    }
    count.retain(|_, c| *c > 1);
    if count.is_empty() {
        return settle_aimed_at_shape(welded, file_corners, input_mesh);
    }
    let settled = settle(welded.clone(), file_corners);
    // The positions where the output has several vertices (its copies, last) count too, with
    // the input's count there: where welding was undone, it may have kept too many apart.
    let mut extra: FastMap<[u64; 3], i64> = FastMap::default();
    for p in &settled.mesh.positions[welded.positions.len().min(settled.mesh.positions.len())..] {
        if !count.contains_key(&bits(*p)) {
            extra.insert(bits(*p), 0);
        }
    }
    if !extra.is_empty() {
        for p in input {
            if let Some(c) = extra.get_mut(&bits(*p)) {
                *c += 1;
            }
        }
        count.extend(extra.into_iter().filter(|&(_, c)| c > 0));
    }
    let in_input = count.clone();
    for p in &settled.mesh.positions {
        if let Some(c) = count.get_mut(&bits(*p)) {
            *c -= 1;
        }
    }
    // Where the output has fewer vertices than the input, or more, the input's count is the
    // aim: there, and at every position the input has several at (a cut next to one where the
    // count came out right is undone with it). Right counts are not enough where the input
    // has boundary edges at such a position (an edge `--repair` cut): its two open
    // sides can look like a seam, and a reading that joins them can still come out with the
    // input's counts, having joined too few copies elsewhere.
    if count.values().all(|&c| c == 0) && keeps_open(&settled.mesh, input_mesh, &in_input) {
        return settled;
    }
    let differ: Vec<u32> = welded
        .positions
        .iter()
        .map(|p| in_input.get(&bits(*p)).map_or(0, |&c| c as u32))
        .collect();
    search_pairings(&welded, file_corners, input_mesh, &differ).settled
}

/// Whether `reading` keeps open the boundary edges of `input_mesh` at the positions of
/// `places` (where the input has several vertices; see [`settle_like`]): between every two
/// positions, one of them in `places`, where the input has boundary edges and `reading` has
/// edges at all (a boundary edge that the output split has none), `reading` has at least as
/// many boundary edges.
fn keeps_open(reading: &Mesh3, input_mesh: &Mesh3, places: &FastMap<[u64; 3], i64>) -> bool {
    let wanted = edges_at_places(input_mesh, places);
    if wanted.values().all(|&open| open == 0) {
        return true;
    }
    let found = edges_at_places(reading, places);
    wanted
        .iter()
        .all(|(key, &open)| found.get(key).is_none_or(|&found_open| found_open >= open))
}

/// [`edges_by_position`] of `mesh` at the vertices at a position of `places`.
fn edges_at_places(mesh: &Mesh3, places: &FastMap<[u64; 3], i64>) -> BoundaryByPosition {
    let at_place: Vec<bool> = mesh.positions.iter().map(|p| places.contains_key(&bits(*p))).collect();
    edges_by_position(mesh, |v| at_place[v as usize])
}

/// The best reading of `welded` with the file vertices at the vertices flagged in `differ`
/// (with the count aimed at) kept apart but for the seams joined ([`unweld`]), over the
/// choices of seam pairs: nearest the input's shape, then its vertex counts, then with the
/// fewest classes above the counts.
fn search_pairings(welded: &Mesh3, file_corners: &FileVertices, input_mesh: &Mesh3, differ: &[u32]) -> Attempt {
    // Where seams meet cuts, which copies a seam joins is a choice (see `join_seams`): the
    // pairings are tried until one comes out with the input's shape and counts (shape first).
    let target = Shape::of(input_mesh);
    let boundary = boundary_edges_by_position(input_mesh);
    let attempt = |choices: &[usize]| {
        let aim = Aim {
            choices,
            boundary: &boundary,
        };
        let (mesh, choices) = unweld(welded.clone(), file_corners, differ, Some(aim));
        let settled = settle(mesh, file_corners);
        let miss = (
            Shape::of(&settled.mesh).distance(&target),
            count_deviation(welded, &settled.mesh, differ),
            choices.excess,
        );
        Attempt { settled, choices, miss }
    };
    let mut best = attempt(&[]);
    // (Each attempt reads the mesh again: thousands on a small mesh, a few dozen on a large one.)
    let mut attempts = 4096.min(8 + (1 << 24) / (welded.triangles.len() + 1));
    // The welded edges with a choice, and their options, are the file's: the same in every
    // attempt. Every combination when there are few, else one choice changed at a time.
    let options = best.choices.options.clone();
    let combinations = options.iter().try_fold(1usize, |n, &o| n.checked_mul(o));
    if combinations.is_some_and(|n| n <= attempts) {
        for n in 1..combinations.unwrap_or(1) {
            if best.miss == (0, 0, 0) {
                break;
            }
            // (The `n`-th combination, in mixed radix.)
            let mut rest = n;
            let trial: Vec<usize> = options
                .iter()
                .map(|&o| {
                    let c = rest % o;
                    rest /= o;
                    c
                })
                .collect();
            let outcome = attempt(&trial);
            if outcome.miss < best.miss {
                best = outcome;
            }
        }
        return best;
    }
    let mut k = 0;
    while best.miss != (0, 0, 0) && k < options.len() && attempts > 0 {
        let mut improved = false;
        for c in (0..options[k]).filter(|&c| c != best.choices.chosen[k]) {
            if attempts == 0 {
                break;
            }
            attempts -= 1;
            let mut trial = best.choices.chosen.clone();
            trial[k] = c;
            let outcome = attempt(&trial);
            if outcome.miss < best.miss {
                (best, improved) = (outcome, true);
                break;
            }
        }
        // (After a change, the choices before it are worth another look.)
        k = if improved { 0 } else { k + 1 };
    }
    best
}

/// How far the vertex counts of `settled` (a reading of `welded`, whose extra vertices come
/// last, each at the position of a vertex of `welded`) are from the counts aimed at: at each
/// position, `differ`'s count at a vertex of `welded` flagged there, else one. Only positions
/// with several vertices on either side count (elsewhere both are one). Seam copies joined
/// too few show as vertices too many, also where [`settle`] then cut a pinched vertex apart,
/// which [`Choices::excess`] does not see.
fn count_deviation(welded: &Mesh3, settled: &Mesh3, differ: &[u32]) -> u64 {
    let n = welded.positions.len();
    // The welded vertex at each position that has copies, and how many vertices it has there.
    let mut at: FastMap<[u64; 3], (usize, u64)> = FastMap::default();
    for (v, p) in welded.positions.iter().enumerate() {
        if differ.get(v).is_some_and(|&c| c > 1) {
            at.insert(bits(*p), (v, 1));
        }
    }
    let mut deviation = 0;
    for p in settled.positions.get(n..).unwrap_or_default() {
        match at.get_mut(&bits(*p)) {
            Some((_, count)) => *count += 1,
            // (A copy at a position aimed at one vertex: one too many.)
            None => deviation += 1,
        }
    }
    deviation
        + (at.values())
            .map(|&(v, count)| count.abs_diff(u64::from(differ[v])))
            .sum::<u64>()
}

/// [`settle`], for an output whose input has one vertex at each position: if the file has seam
/// copies and welding was undone somewhere (several of the output's vertices at one place,
/// as where a polygon folding onto itself made distinct vertices meet at a seam), and the
/// reading does not have the input's shape, the pairings of seam copies there are searched as
/// in [`settle_like`], aiming at one vertex per place; the first reading is kept unless one
/// comes nearer the input's shape. (Usually welding is undone nowhere, and this is `settle`.)
fn settle_aimed_at_shape(welded: Mesh3, file_corners: &FileVertices, input_mesh: &Mesh3) -> Settled {
    let n = welded.positions.len();
    let settled = settle(welded, file_corners);
    if file_corners.looks.is_empty() || settled.mesh.positions.len() <= n {
        return settled;
    }
    let target = Shape::of(input_mesh);
    let first = Shape::of(&settled.mesh).distance(&target);
    if first == 0 {
        return settled;
    }
    let (welded, differ) = weld_again(&settled.mesh, n);
    let best = search_pairings(&welded, file_corners, input_mesh, &differ);
    if best.miss.0 < first {
        best.settled
    } else {
        settled
    }
}

/// The mesh that [`settle`] was given, from what it made of it (`n` vertices, each at a
/// position of its own, as welding leaves them; settling only adds vertices past them, at
/// their positions, and moves corners there): and, flagged 1, the vertices it had undone
/// welding at.
fn weld_again(settled: &Mesh3, n: usize) -> (Mesh3, Vec<u32>) {
    let mut first: FastMap<[u64; 3], u32> = settled.positions[n..].iter().map(|p| (bits(*p), u32::MAX)).collect();
    let mut differ = vec![0u32; n];
    for (v, p) in settled.positions[..n].iter().enumerate() {
        if let Some(slot) = first.get_mut(&bits(*p)) {
            *slot = v as u32;
            differ[v] = 1;
        }
    }
    let original = |v: u32| {
        if (v as usize) < n {
            v
        } else {
            first[&bits(settled.positions[v as usize])]
        }
    };
    let welded = Mesh3 {
        positions: settled.positions[..n].to_vec(),
        triangles: settled.triangles.iter().map(|t| t.map(original)).collect(),
    };
    (welded, differ)
}

/// What [`settle_like`] aims an attempt at: which seam pairs to try first at each welded
/// edge with a choice (see [`Seams::pair`]), and the input's boundary edges by position.
#[derive(Clone, Copy)]
struct Aim<'a> {
    choices: &'a [usize],
    boundary: &'a BoundaryByPosition,
}

/// How many boundary edges (edges with one face) a mesh has between each pair of positions,
/// the lower position's bits first; only pairs with some.
type BoundaryByPosition = FastMap<([u64; 3], [u64; 3]), usize>;

/// The boundary edges of `mesh` counted by their ends' positions ([`BoundaryByPosition`]).
/// Where `--repair` cut an edge, its copies can be two boundary edges at one place: the
/// output keeps them both open, and two open file edges there are no seam to join.
fn boundary_edges_by_position(mesh: &Mesh3) -> BoundaryByPosition {
    let mut out = edges_by_position(mesh, |_| true);
    out.retain(|_, open| *open > 0);
    out
}

/// The edges of `mesh` with an end at a vertex where `at` holds, counted by their ends'
/// positions (the lower position's bits first): how many of them are boundary edges (with one
/// face); unlike [`boundary_edges_by_position`], also the pairs with none (0), so that a pair
/// missing from it has no edge there at all.
fn edges_by_position(mesh: &Mesh3, at: impl Fn(u32) -> bool) -> BoundaryByPosition {
    let mut faces: FastMap<(u32, u32), u32> = FastMap::default();
    for t in &mesh.triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            if at(a) || at(b) {
                *faces.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
    }
    let mut out = BoundaryByPosition::default();
    for (&(a, b), &n) in &faces {
        let (pa, pb) = (bits(mesh.positions[a as usize]), bits(mesh.positions[b as usize]));
        *out.entry((pa.min(pb), pa.max(pb))).or_insert(0) += usize::from(n == 1);
    }
    out
}

/// One reading of an output in [`settle_like`]: the mesh, the seam choices made, and how far
/// it is from the input: the distance of [`Shape`]s, then how far its vertex counts are from
/// the input's ([`count_deviation`]), then the classes above the input's counts. (Shape
/// first: where seams meet a vertex `--repair` split, a valid output can need a copy kept
/// apart to have the input's shape, and no pairing has both. Counts next: two pairings can
/// both have the input's shape, one of them with a vertex too many.)
struct Attempt {
    settled: Settled,
    choices: Choices,
    miss: (u64, u64, u64),
}

/// What a mesh's refinement keeps, cheap to find: its connected components, Euler
/// characteristic and boundary loops (counted as cycles of the edges with one face, which is
/// the number of boundary loops on a manifold).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Shape {
    components: i64,
    euler: i64,
    boundary_loops: i64,
}

impl Shape {
    /// The shape of `mesh`, counting only the vertices some face uses.
    fn of(mesh: &Mesh3) -> Shape {
        let mut referenced = vec![false; mesh.positions.len()];
        mesh.triangles
            .iter()
            .flatten()
            .for_each(|&v| referenced[v as usize] = true);
        let mut edges: Vec<(u32, u32, bool)> = mesh
            .triangles
            .iter()
            .flat_map(|t| [0, 1, 2].map(|i| (t[i], t[(i + 1) % 3])))
            .map(|(a, b)| (a.min(b), a.max(b), a < b))
            .collect();
        edges.sort_unstable();
        let mut next: FastMap<u32, u32> = FastMap::default();
        let mut distinct = 0;
        for run in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            distinct += 1;
            if let [(lo, hi, forward)] = *run {
                let (a, b) = if forward { (lo, hi) } else { (hi, lo) };
                next.insert(a, b);
            }
        }
        let mut loops = 0;
        let mut seen: HashSet<u32> = HashSet::new();
        for &start in next.keys() {
            if seen.contains(&start) {
                continue;
            }
            loops += 1;
            let mut current = Some(start);
            while let Some(v) = current.filter(|v| seen.insert(*v)) {
                current = next.get(&v).copied();
            }
        }
        let vertices = referenced.iter().filter(|&&r| r).count() as i64;
        Shape {
            components: count_components(mesh, &referenced) as i64,
            euler: vertices - distinct + mesh.triangles.len() as i64,
            boundary_loops: loops,
        }
    }

    /// How far `self` is from `other`: the sum of the differences.
    fn distance(&self, other: &Shape) -> u64 {
        (self.components.abs_diff(other.components))
            + self.euler.abs_diff(other.euler)
            + self.boundary_loops.abs_diff(other.boundary_loops)
    }
}

/// A mesh read with identical positions welded (-0 and 0 alike), before any welding is undone.
struct Welded {
    /// The mesh.
    mesh: Mesh3,
    /// The file's own vertex of each corner of its triangles, and what else it says of them.
    file_corners: FileVertices,
    /// The positions of its vertices that no face uses (in file order, each once).
    strays: Vec<DVec3>,
    /// How the file numbers the mesh's vertices and faces.
    naming: Naming,
}

/// The file's own vertices of a [`Welded`] mesh: which one each corner of its triangles is,
/// and, for a file that gives a vertex one record per attribute value (OFF and PLY with
/// texture coordinates, normals, colours or other vertex properties), a hash of each one's
/// values, which tells seam copies (whose values differ) from copies at a cut.
struct FileVertices {
    /// The file vertex of each corner of the mesh's triangles.
    corners: Vec<[u32; 3]>,
    /// A hash of each file vertex's attribute values; empty where the file gives none, or is
    /// not an OFF or PLY file.
    looks: Vec<u64>,
}

impl FileVertices {
    /// Whether the file vertices `a` and `b`, at one position, may be copies of one vertex
    /// that a seam made: the same vertex, or two with different attribute values.
    fn seam_copies(&self, a: u32, b: u32) -> bool {
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
fn read_welded(path: &Path) -> Result<Welded, CheckError> {
    read_file(path, |path, bytes, format| read_welded_as(path, bytes, format, false)).map(|(welded, _)| welded)
}

/// [`read_welded`], and with `keep_raw` the file as it lists its vertices and faces too (as
/// [`read_raw`] reads it, which the weld was made from).
fn read_welded_keeping(path: &Path, keep_raw: bool) -> Result<(Welded, Option<(RawMesh, bool)>), CheckError> {
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
fn copies_apart(mesh: &Mesh3, files: &FileVertices, limit: usize) -> (usize, Vec<(u32, u32, u32)>) {
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
fn weld(raw: &RawMesh, shares_vertices: bool, seam_copies: bool) -> Result<Option<Welded>, String> {
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
fn obj_raw(path: &Path, bytes: &[u8]) -> Result<RawMesh, CheckError> {
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
fn weld_obj(path: &Path, raw: &RawMesh) -> Result<Welded, CheckError> {
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
fn parse_index(text: &[u8]) -> Option<i64> {
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

/// The last steps of reading a welded mesh: [`split_welded_sheets`], then
/// [`split_pinched_vertices`]; with the faces around every vertex of the result.
fn settle(mesh: Mesh3, file_corners: &FileVertices) -> Settled {
    split_pinched_vertices(split_welded_sheets(mesh, file_corners))
}

/// A mesh as read, with the faces around each of its vertices.
struct Settled {
    mesh: Mesh3,
    around: VertexFaces,
}

/// The faces around every vertex of a mesh (whose indices are valid), in increasing order: a
/// counting sort of the corners by vertex, made once and used by the pinch rule, the edges and
/// the fans (a face repeating a vertex is listed once per corner there). Vertices past those it
/// was made for (the ones no face uses, appended later) have no faces.
struct VertexFaces {
    start: Vec<usize>,
    faces: Vec<u32>,
}

impl VertexFaces {
    fn new(mesh: &Mesh3) -> VertexFaces {
        let corners = || (mesh.triangles.iter().enumerate()).flat_map(|(f, t)| t.map(|v| (v as usize, f as u32)));
        let (start, faces) = grouped(mesh.positions.len(), corners);
        VertexFaces { start, faces }
    }

    /// The faces around vertex `v`.
    fn of(&self, v: usize) -> &[u32] {
        match (self.start.get(v), self.start.get(v + 1)) {
            (Some(&a), Some(&b)) => &self.faces[a..b],
            _ => &[],
        }
    }
}

/// At every vertex flagged in `at` (not 0), the file vertices welded into it are kept apart
/// again, except those a seam joins: the class of the first file vertex (in corner order) keeps
/// the vertex and every other class gets a new vertex at the same position, in all its faces.
///
/// A PLY or OFF file gives a vertex one record per attribute value, so a vertex on a seam has
/// copies, and a seam's edge is open in the file on both sides:
///
/// ```text
///        f             face f's edge x1 -> y1 and face g's edge y2 -> x2: each open in
///   x1 -----> y1       the file (one face), at the same positions, running opposite
///   x2 <----- y2       ways; one edge of the surface, cut by a seam, so x1 and x2 are
///        g             one vertex, and y1 and y2 another
/// ```
///
/// So where a welded edge has exactly two faces whose file edges are open, running opposite
/// ways, and the file vertices at each end are seam copies ([`FileVertices::seam_copies`]:
/// the same, or with different attribute values, as a seam's copies are), those are one class
/// (whatever other faces the welded edge has: a seam on one of two sheets that meet along one
/// line). Where it has more (a seam on an edge that `--repair` cut), which pairs belong
/// together is not known: without `choices` they stay apart; with them (when the input's
/// counts are the aim, see [`settle_like`]), pairs are taken in order, each open file edge in
/// one at most, starting at the pair `choices` names (see [`join_seams`]), and which choices
/// were made is returned. A file with no copies (OBJ without vertex colours, STL, or PLY and
/// OFF without attributes) joins nothing: every file vertex is its own class, as welding found
/// it.
///
/// Copies that `delmesh --repair` makes where it cuts look the same, but have the same values,
/// and a seam is not joined where the edge it would make is not Delaunay (a seam of a
/// Delaunay mesh is a Delaunay edge; two cut boundaries folded onto each other make none), nor
/// where that would leave a vertex fewer classes than `at` asks for there (the input's count
/// of vertices at that position, where the output was found to have another), or crowd an
/// edge ([`joining_crowds`]): `--repair` cuts a single face off a non-manifold edge by giving
/// it a copy of one end only, and its other edges at that copy then look like a seam.
fn unweld(mut mesh: Mesh3, file: &FileVertices, at: &[u32], aim: Option<Aim>) -> (Mesh3, Choices) {
    debug_assert_eq!(mesh.triangles.len(), file.corners.len());
    let flagged = |v: u32| at.get(v as usize).is_some_and(|&c| c > 0);
    let file_count = file.corners.iter().flatten().max().map_or(0, |&m| m as usize + 1);
    let mut class = UnionFind::new(file_count);
    let choices = if file.looks.is_empty() {
        Choices::default()
    } else {
        join_seams(&mesh, file, at, aim, &mut class)
    };
    let mut first_class = vec![u32::MAX; mesh.positions.len()];
    let mut own: FastMap<u32, u32> = FastMap::default();
    for (t, f) in mesh.triangles.iter_mut().zip(&file.corners) {
        for (v, &fv) in t.iter_mut().zip(f) {
            if !flagged(*v) {
                continue;
            }
            let c = class.find(fv);
            let first = &mut first_class[*v as usize];
            if *first == u32::MAX {
                *first = c;
            }
            if *first != c {
                let p = mesh.positions[*v as usize];
                let next = mesh.positions.len() as u32;
                *v = *own.entry(c).or_insert(next);
                if *v == next {
                    mesh.positions.push(p);
                }
            }
        }
    }
    (mesh, choices)
}

/// Joins in `class` the file vertices at the flagged vertices of `mesh` (see [`unweld`]) that
/// a seam joins, one welded edge at a time, in order; returns what it chose.
///
/// Where a welded edge has more than two open file edges (a seam on an edge `--repair` cut,
/// or at a vertex it cut), which of them pair up is a choice: `choices` says which pair is
/// tried first at each such welded edge (see [`Seams::pair`]; past its end: the first, in
/// order), and [`settle_like`] tries others where the outcome is not the input's. Without
/// `choices` (no input to aim at), such edges' copies stay apart.
fn join_seams(mesh: &Mesh3, file: &FileVertices, at: &[u32], aim: Option<Aim>, class: &mut UnionFind) -> Choices {
    let flagged = |v: u32| at.get(v as usize).is_some_and(|&c| c > 0);
    let Some(seams) = Seams::new(mesh, file, &flagged) else {
        return Choices::default();
    };
    let mut pairing = seams.pair(file, at, aim);
    for (i, &f) in seams.files.iter().enumerate() {
        let root = pairing.class.find(i as u32);
        class.union(f, seams.files[root as usize]);
    }
    pairing.choices
}

/// The choices of one pass of [`join_seams`]: for each welded edge where one was made, how
/// many options it had and which was taken; and how many classes above `at` the flagged
/// vertices have in all.
#[derive(Clone, Debug, Default)]
struct Choices {
    options: Vec<usize>,
    chosen: Vec<usize>,
    excess: u64,
}

/// The corner edges at flagged vertices that [`join_seams`] pairs, with their file vertices
/// numbered among themselves (`files`), so that each attempt at a pairing is small.
struct Seams<'a> {
    /// The welded mesh's positions.
    positions: &'a [DVec3],
    /// The corner edges, as [`CornerEdge`] with file vertices as indices into `files`, sorted.
    edges: Vec<CornerEdge>,
    /// Which of `edges` touch each flagged vertex: a union there is checked against them.
    touching: FastMap<u32, Vec<usize>>,
    /// How many file vertices each flagged vertex has.
    classes: FastMap<u32, u32>,
    /// The file vertices `edges` name, in increasing order.
    files: Vec<u32>,
    /// Whether each welded vertex is flagged.
    flagged: Vec<bool>,
}

/// One pairing of [`Seams`]: its classes (of `Seams::files`) and its choices.
struct Pairing {
    class: UnionFind,
    choices: Choices,
}

impl Seams<'_> {
    fn new<'a>(mesh: &'a Mesh3, file: &FileVertices, flagged: &impl Fn(u32) -> bool) -> Option<Seams<'a>> {
        // The corners' edges at a flagged vertex, as [`CornerEdge`]s, grouped by welded edge.
        let mut edges: Vec<CornerEdge> = Vec::new();
        for (t, f) in mesh.triangles.iter().zip(&file.corners) {
            for i in 0..3 {
                let (a, b, j) = (t[i], t[(i + 1) % 3], (i + 1) % 3);
                if a != b && (flagged(a) || flagged(b)) {
                    let (fa, fb, c) = (f[i], f[j], t[(i + 2) % 3]);
                    edges.push(if a < b {
                        (a, b, fa, fb, true, c)
                    } else {
                        (b, a, fb, fa, false, c)
                    });
                }
            }
        }
        if edges.is_empty() {
            return None;
        }
        edges.sort_unstable();
        let mut files: Vec<u32> = edges.iter().flat_map(|e| [e.2, e.3]).collect();
        files.sort_unstable();
        files.dedup();
        let local = |f: u32| files.binary_search(&f).expect("listed") as u32;
        let mut touching: FastMap<u32, Vec<usize>> = FastMap::default();
        let mut at_flagged: Vec<(u32, u32)> = Vec::new();
        for (i, e) in edges.iter_mut().enumerate() {
            (e.2, e.3) = (local(e.2), local(e.3));
            for (v, f) in [(e.0, e.2), (e.1, e.3)].into_iter().filter(|&(v, _)| flagged(v)) {
                touching.entry(v).or_default().push(i);
                at_flagged.push((v, f));
            }
        }
        // How many classes each flagged vertex has at first: its file vertices.
        at_flagged.sort_unstable();
        at_flagged.dedup();
        let mut classes: FastMap<u32, u32> = FastMap::default();
        for &(v, _) in &at_flagged {
            *classes.entry(v).or_insert(0) += 1;
        }
        let flagged = (0..mesh.positions.len() as u32).map(flagged).collect();
        Some(Seams {
            positions: &mesh.positions,
            edges,
            touching,
            classes,
            files,
            flagged,
        })
    }

    /// Pairs the open file edges of each welded edge, in order: where some file edge could
    /// pair with several, the `choices[k]`-th of those pairs (for the `k`-th such welded
    /// edge; 0 if not given) is tried first, then the others in turn, leaving open as many as
    /// the input has boundary edges there. Without an aim (no input), only a welded edge with
    /// exactly two open file edges pairs them.
    fn pair(&self, file: &FileVertices, at: &[u32], aim: Option<Aim>) -> Pairing {
        let choices = aim.map(|a| a.choices);
        let flagged = |v: u32| self.flagged.get(v as usize).copied().unwrap_or(false);
        let mut class = UnionFind::new(self.files.len());
        let mut classes = self.classes.clone();
        let mut options = Vec::new();
        let mut chosen = Vec::new();
        let seam_copies = |a: u32, b: u32| file.seam_copies(self.files[a as usize], self.files[b as usize]);
        for group in self.edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            // (Sorted, so a file edge's faces are next to each other.)
            let open: Vec<CornerEdge> = group
                .chunk_by(|x, y| (x.2, x.3) == (y.2, y.3))
                .filter(|same| same.len() == 1)
                .map(|same| same[0])
                .collect();
            if choices.is_none() && open.len() != 2 {
                continue;
            }
            // Two open file edges running opposite ways, the copies at each end differing in
            // values: they may be one edge of the surface that a seam cut; but not one that
            // would be a non-Delaunay edge (as where two sheets' boundaries fold onto each
            // other), which no seam of a Delaunay mesh is.
            let delaunay = |p: CornerEdge, q: CornerEdge| {
                let at = |v: u32| self.positions[v as usize];
                excess(at(p.0), at(p.1), at(p.5), at(q.5)) <= DELAUNAY_TOLERANCE
            };
            let mut candidates: Vec<(usize, usize)> = Vec::new();
            for i in 0..open.len() {
                for j in i + 1..open.len() {
                    let (p, q) = (open[i], open[j]);
                    if p.4 != q.4 && seam_copies(p.2, q.2) && seam_copies(p.3, q.3) && delaunay(p, q) {
                        candidates.push((i, j));
                    }
                }
            }
            let shared = (0..open.len()).any(|i| candidates.iter().filter(|&&(a, b)| a == i || b == i).count() > 1);
            if shared {
                let c = choices.and_then(|c| c.get(options.len())).copied().unwrap_or(0) % candidates.len();
                candidates.rotate_left(c);
                options.push(candidates.len());
                chosen.push(c);
            }
            // The input's boundary edges at this place stay open: two of them folded onto each
            // other (an edge `--repair` cut) are no seam, however alike they look.
            let keep_open = aim.map_or(0, |aim| {
                let at = |v: u32| bits(self.positions[v as usize]);
                let (a, b) = (at(group[0].0), at(group[0].1));
                aim.boundary.get(&(a.min(b), a.max(b))).copied().unwrap_or(0)
            });
            let mut joins_left = open.len().saturating_sub(keep_open) / 2;
            let mut paired = vec![false; open.len()];
            for (i, j) in candidates {
                if joins_left == 0 {
                    break;
                }
                if paired[i] || paired[j] {
                    continue;
                }
                let (p, q) = (open[i], open[j]);
                // The ends where the seam would join two classes into one.
                let merging: Vec<u32> = [(p.0, p.2, q.2), (p.1, p.3, q.3)]
                    .iter()
                    .filter(|&&(v, x, y)| flagged(v) && class.find(x) != class.find(y))
                    .map(|&(v, _, _)| v)
                    .collect();
                if merging.iter().any(|v| classes[v] <= at[*v as usize])
                    || joining_crowds(&self.edges, &self.touching, &flagged, &mut class, p, q)
                {
                    continue;
                }
                merging.iter().for_each(|v| *classes.get_mut(v).expect("counted") -= 1);
                class.union(p.2, q.2);
                class.union(p.3, q.3);
                (paired[i], paired[j]) = (true, true);
                joins_left -= 1;
            }
        }
        let excess = classes
            .iter()
            .map(|(&v, &c)| u64::from(c.saturating_sub(at[v as usize])))
            .sum();
        Pairing {
            class,
            choices: Choices {
                options,
                chosen,
                excess,
            },
        }
    }
}

/// One corner edge at a flagged vertex, as [`unweld`] lists them: (low, high, file vertex at
/// low, at high, whether the face runs low to high, the face's third vertex).
type CornerEdge = (u32, u32, u32, u32, bool, u32);

/// Whether joining the seam `p`, `q` (two open file edges of one welded edge) would crowd an
/// edge at either of its ends: give it more than two faces, or two running the same way, with
/// the file vertices kept apart as `class` has them so far (as joining a cut of `delmesh
/// --repair` would put the cut edge's faces back together).
fn joining_crowds(
    edges: &[CornerEdge],
    touching: &FastMap<u32, Vec<usize>>,
    flagged: &impl Fn(u32) -> bool,
    class: &mut UnionFind,
    p: CornerEdge,
    q: CornerEdge,
) -> bool {
    let joined = [(class.find(q.2), class.find(p.2)), (class.find(q.3), class.find(p.3))];
    let mut near: Vec<usize> = [p.0, p.1]
        .iter()
        .filter_map(|v| touching.get(v))
        .flatten()
        .copied()
        .collect();
    near.sort_unstable();
    near.dedup();
    // A corner's ends as the classes they would be in (an unflagged vertex stays one vertex).
    let mut side = |welded: u32, file: u32| {
        if !flagged(welded) {
            return u32::MAX;
        }
        let c = class.find(file);
        joined.iter().find(|&&(from, _)| from == c).map_or(c, |&(_, to)| to)
    };
    let mut keys: Vec<CornerEdge> = near
        .iter()
        .map(|&i| {
            let e = edges[i];
            (e.0, e.1, side(e.0, e.2), side(e.1, e.3), e.4, 0)
        })
        .collect();
    keys.sort_unstable();
    keys.chunk_by(|x, y| (x.0, x.1, x.2, x.3) == (y.0, y.1, y.2, y.3))
        .any(|run| run.len() > 2 || (run.len() == 2 && run[0].4 == run[1].4))
}

/// Undoes welding where it would put more than two faces on an edge, or two faces running along
/// it the same way, if the file itself keeps those faces apart.
///
/// `delmesh --repair` cuts a non-manifold edge by giving every pair of its faces beyond the
/// first its own copies of the edge's two vertices, at the same positions, and cuts a
/// non-orientable surface (a Möbius band) open the same way: welded by position, the edge has
/// all its faces again. So, for every such edge after welding, every file vertex at one of its
/// ends that is not the first file vertex at that position (`file_corners`: the file's vertex
/// of each corner of `mesh.triangles`, first in corner order) keeps its own vertex, in all its
/// faces. Such a file then reads back as the surface it
/// was written from; a mesh whose welded edges have at most two faces, oppositely oriented
/// (every mesh the construction accepts without `--repair`), is unchanged, and an edge the
/// file itself gives more than two faces, or two the same way, stays an error.
fn split_welded_sheets(mesh: Mesh3, file: &FileVertices) -> Mesh3 {
    let file_corners = &file.corners;
    // Where welding joined no two file vertices there is nothing to undo (every mesh whose
    // file gives each position once): one pass over the corners instead of grouping edges.
    let n = mesh.positions.len();
    let mut file_vertex = vec![u32::MAX; n];
    let mut joined = false;
    for (t, f) in mesh.triangles.iter().zip(file_corners) {
        for (&v, &file) in t.iter().zip(f) {
            let slot = &mut file_vertex[v as usize];
            joined |= *slot != u32::MAX && *slot != file;
            *slot = file;
        }
    }
    if !joined {
        return mesh;
    }
    drop(file_vertex);
    // The corners' edges grouped by their lower end (counting sort: the lists are short), each
    // as (higher end, direction); an edge is crowded with more than two faces, or two running
    // along it the same way.
    let edges = || {
        mesh.triangles.iter().flat_map(|t| {
            [0, 1, 2].map(|i| {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                (a.min(b) as usize, (a.max(b), a < b))
            })
        })
    };
    let (start, higher) = grouped(n, edges);
    // The crowded edges' ends, found on all threads (each sorting a copy of its lists).
    let ends: Vec<u32> = crate::parallel::map_ranges(n, |range| {
        let (mut list, mut ends) = (Vec::new(), Vec::new());
        for low in range {
            list.clear();
            list.extend_from_slice(&higher[start[low]..start[low + 1]]);
            list.sort_unstable();
            for run in list.chunk_by(|x, y| x.0 == y.0) {
                if run.len() > 2 || (run.len() == 2 && run[0].1 == run[1].1) {
                    ends.extend([low as u32, run[0].0]);
                }
            }
        }
        ends
    })
    .into_iter()
    .flatten()
    .collect();
    if ends.is_empty() {
        return mesh;
    }
    let mut crowded = vec![0; n];
    ends.iter().for_each(|&v| crowded[v as usize] = 1);
    unweld(mesh, file, &crowded, None).0
}

/// The values of `items()` (pairs of a key below `n` and a value) grouped by key, in order:
/// the values of key `k` are `values[start[k]..start[k + 1]]`. A counting sort: `items` is
/// called twice.
fn grouped<T: Copy + Default, I: Iterator<Item = (usize, T)>>(n: usize, items: impl Fn() -> I) -> (Vec<usize>, Vec<T>) {
    let mut start = vec![0usize; n + 1];
    for (k, _) in items() {
        start[k + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut values = vec![T::default(); start[n]];
    for (k, value) in items() {
        values[fill[k]] = value;
        fill[k] += 1;
    }
    (start, values)
}

/// Gives every fan of a pinched vertex but the first its own vertex at the same position.
///
/// After welding, a vertex whose faces form several edge-connected fans is a pinch point. A
/// file written by `delmesh --repair` (or its output) has such vertices cut apart on purpose,
/// as separate vertices at one position; welding joins them again. Reading every pinch as
/// separate fans makes such a file read back as the surface it was written from, and leaves
/// manifold meshes unchanged. Fans are ordered by their lowest face index, so the rule is
/// deterministic; edges with more than two faces are not cut (they stay errors).
fn split_pinched_vertices(mut mesh: Mesh3) -> Settled {
    let n = mesh.positions.len();
    let around = VertexFaces::new(&mesh);
    // Which fan every face of a pinched vertex is in, found on all threads: a vertex's fans
    // do not depend on how the pinches before it were cut (faces sharing a neighbour that was
    // cut are in one of its fans, so they still share its copy), so each vertex's are found
    // in the mesh as read. Then the copies are made in order, as one pass would make them.
    let triangles = &mesh.triangles;
    let pinched: Vec<(u32, u32, u32)> = crate::parallel::map_ranges(n, |range| {
        let mut fans = Fans::default();
        let mut found = Vec::new();
        for v in range {
            let faces = around.of(v);
            if faces.len() >= 2 {
                fans.find(v, faces, triangles, &mut found);
            }
        }
        found
    })
    .into_iter()
    .flatten()
    .collect();
    // (vertex, fan) → its new vertex, for the current vertex only.
    let mut new_vertex: Vec<(u32, u32)> = Vec::new();
    for (i, &(v, f, fan)) in pinched.iter().enumerate() {
        if i == 0 || pinched[i - 1].0 != v {
            new_vertex.clear();
        }
        let id = match new_vertex.iter().find(|(r, _)| *r == fan) {
            Some(&(_, id)) => id,
            None => {
                let id = mesh.positions.len() as u32;
                mesh.positions.push(mesh.positions[v as usize]);
                new_vertex.push((fan, id));
                id
            }
        };
        for corner in mesh.triangles[f as usize].iter_mut() {
            if *corner == v {
                *corner = id;
            }
        }
    }
    // (Made again where pinches were cut, which moves faces to new vertices: rare.)
    let around = if pinched.is_empty() {
        around
    } else {
        VertexFaces::new(&mesh)
    };
    Settled { mesh, around }
}

/// The fans of one vertex, with buffers reused from vertex to vertex.
#[derive(Default)]
struct Fans {
    parent: Vec<usize>,
    by_neighbour: Vec<(u32, usize)>,
}

impl Fans {
    /// Appends `(v, face, fan)` for every face of `faces` (the faces around `v`, in
    /// increasing order) that is not in the fan of the lowest face, `fan` naming its fan
    /// (the root of its faces joined across shared edges `(v, w)`).
    /// Every fan is named by its lowest index into `faces`, whatever the order of the joins.
    fn find(&mut self, v: usize, faces: &[u32], triangles: &[[u32; 3]], found: &mut Vec<(u32, u32, u32)>) {
        let parent = &mut self.parent;
        parent.clear();
        parent.extend(0..faces.len());
        fn root(parent: &mut [usize], mut x: usize) -> usize {
            while parent[x] != x {
                parent[x] = parent[parent[x]];
                x = parent[x];
            }
            x
        }
        let join = |parent: &mut [usize], i: usize, j: usize| {
            let (a, b) = (root(parent, i), root(parent, j));
            parent[a.max(b)] = a.min(b);
        };
        if faces.len() <= SMALL_FAN {
            // Every pair of faces compared: fewer steps than sorting their neighbours.
            let mut corners = [[0u32; 3]; SMALL_FAN];
            for (c, &f) in corners.iter_mut().zip(faces) {
                *c = triangles[f as usize];
            }
            for i in 1..faces.len() {
                for j in 0..i {
                    if corners[i].iter().any(|&w| w as usize != v && corners[j].contains(&w)) {
                        join(parent, i, j);
                    }
                }
            }
        } else {
            self.by_neighbour.clear();
            for (i, &f) in faces.iter().enumerate() {
                for &w in &triangles[f as usize] {
                    if w as usize != v {
                        self.by_neighbour.push((w, i));
                    }
                }
            }
            self.by_neighbour.sort_unstable();
            for pair in self.by_neighbour.windows(2) {
                if pair[0].0 == pair[1].0 {
                    join(parent, pair[0].1, pair[1].1);
                }
            }
        }
        // Faces are listed in increasing order, so root 0 is the fan of the lowest face.
        for (i, &f) in faces.iter().enumerate() {
            let r = root(parent, i);
            if r != 0 {
                found.push((v as u32, f, r as u32));
            }
        }
    }
}

/// Fans of at most this many faces (nearly every vertex's) are found by comparing every pair
/// of faces ([`Fans::find`], [`is_single_small_fan`]) rather than by sorting.
const SMALL_FAN: usize = 16;

/// Welds positions by their bit patterns while models are appended: an open-addressing table
/// (linear probing, at most half full) of indices into `positions`, whose bits are the keys.
/// Four bytes a slot stay in cache far better than a map holding the 24-byte keys, where
/// inserting a million positions was mostly waiting for memory.
struct Welder {
    positions: Vec<DVec3>,
    /// Indices into `positions`, or [`Welder::EMPTY`]; a power of two long.
    slots: Vec<u32>,
}

impl Welder {
    /// An unused slot.
    const EMPTY: u32 = u32::MAX;

    /// A welder with room for `n` positions.
    fn with_capacity(n: usize) -> Welder {
        Welder {
            positions: Vec::with_capacity(n),
            slots: vec![Self::EMPTY; (2 * n).next_power_of_two().max(16)],
        }
    }

    /// Returns the welded index of `p`, adding it if new.
    fn insert(&mut self, p: DVec3) -> Result<u32, String> {
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

// ---------------------------------------------------------------------------------------------
// The check
// ---------------------------------------------------------------------------------------------

/// The two meshes of a check, and how their files name their vertices and faces.
#[derive(Clone, Copy)]
struct Meshes<'a> {
    input: &'a Mesh3,
    output: &'a Mesh3,
    input_naming: &'a Naming,
    output_naming: &'a Naming,
    /// The faces around the output's vertices, if already known (from reading it).
    output_around: Option<&'a VertexFaces>,
}

/// Runs every check, naming the meshes' vertices and faces as their files do; `Err` carries
/// why the input is invalid. `input_prepared` is [`prepare_input`] if already done.
fn check_core(meshes: Meshes, input_prepared: Option<Result<Prepared, String>>) -> Result<CheckReport, String> {
    let Meshes { input, output, .. } = meshes;
    let output_names = Names::new("output", output, meshes.output_naming);
    // Independent pieces run on two threads for large meshes (see `crate::parallel::join`):
    // the input's regions and the output's edges beside the search structures for the output's
    // vertices, then the output's Delaunay test beside the geometry rules. Failures are
    // recorded in the same order either way (only one side of each pair records any).
    let worth_it = input.triangles.len() + output.triangles.len() >= PARALLEL_FACES;
    let mut fail = Failures::default();
    let prepared = input_prepared.unwrap_or_else(|| prepare_input(input, None, meshes.input_naming))?;
    let out_referenced = validate(&output_names, &mut fail);
    let ((regions, out), search) = crate::parallel::join(
        worth_it,
        || {
            let regions = input_regions(input, &prepared);
            let around = meshes.output_around;
            let out = (out_referenced.as_ref()).map(|r| Prepared::build(&output_names, r.clone(), around, &mut fail));
            (regions, out)
        },
        || (out_referenced.as_ref()).map(|r| VertexSearch::new(input, &prepared, output, r)),
    );
    let (regions, vertex_regions) = regions;
    let model = InputModel {
        mesh: input,
        names: Names::new("input", input, meshes.input_naming),
        prepared,
        regions,
        vertex_regions,
    };
    let mut report = CheckReport::empty(input, output);
    report.input_vertices = model.prepared.stats.vertices;
    report.input_regions = model.regions.area.len();

    if let (Some(out), Some(mut search)) = (out, search) {
        report.output_vertices = out.stats.vertices;
        let (delaunay, ()) = crate::parallel::join(
            worth_it,
            || delaunay_edges(output, &out.edges),
            || {
                let candidates =
                    classify_output_vertices(&model, &mut search, &output_names, &out.referenced, &mut fail);
                drop(search);
                report.added_vertices = candidates.added;
                report.unused_vertices = candidates.unused;
                let mut assignment = assign_faces(&model, &output_names, &candidates, &mut fail);
                let rounding = rounding_allowance(&model, &candidates.edge_has_added);
                check_areas(&model, &mut assignment, &rounding, &mut fail);
                compare_topology(&model.prepared.stats, &out.stats, &mut fail);
            },
        );
        delaunay.report(&output_names, &mut fail);
        report.interior_edges = delaunay.interior;
        report.non_delaunay_edges = delaunay.bad.len();
        report.max_excess = delaunay.max_excess;
    }
    report.failures = fail.finish();
    Ok(report)
}

/// Validates the input (indices, finite coordinates, oriented manifold): its edges and
/// topology, or why it is invalid. `around`: the faces around its vertices, if known.
fn prepare_input(mesh: &Mesh3, around: Option<&VertexFaces>, naming: &Naming) -> Result<Prepared, String> {
    if mesh.triangles.is_empty() {
        return Err("the mesh has no faces".into());
    }
    let names = Names::new("input", mesh, naming);
    let mut problems = Failures::default();
    match Prepared::new(&names, around, &mut problems) {
        Some(p) if problems.is_empty() => Ok(p),
        _ => Err(problems.summary(5)),
    }
}

/// The planar regions of a validated input, and the regions of the faces around each of its
/// vertices (sorted, unique).
fn input_regions(mesh: &Mesh3, prepared: &Prepared) -> (Regions, Csr) {
    let regions = Regions::new(mesh, &prepared.edges);
    let corners: Vec<(u32, u32)> = mesh
        .triangles
        .iter()
        .enumerate()
        .flat_map(|(f, t)| t.map(|v| (v, regions.of_face[f])))
        .collect();
    let vertex_regions = Csr::from_pairs(mesh.positions.len(), &corners).sorted_unique();
    (regions, vertex_regions)
}

/// The validated input with its planar regions.
struct InputModel<'a> {
    mesh: &'a Mesh3,
    /// How failure lines name the input's vertices and faces.
    names: Names<'a>,
    prepared: Prepared,
    regions: Regions,
    /// Regions of the faces around each input vertex (sorted, unique).
    vertex_regions: Csr,
}

impl<'a> InputModel<'a> {
    /// Validates the input (indices, finite coordinates, oriented manifold) and computes its
    /// planar regions.
    #[cfg(test)]
    fn new(mesh: &'a Mesh3, naming: &'a Naming) -> Result<InputModel<'a>, String> {
        let prepared = prepare_input(mesh, None, naming)?;
        let (regions, vertex_regions) = input_regions(mesh, &prepared);
        Ok(InputModel {
            mesh,
            names: Names::new("input", mesh, naming),
            prepared,
            regions,
            vertex_regions,
        })
    }
}

impl InputModel<'_> {
    /// The regions of the faces of the given input edges (sorted, unique), into `set`. A point
    /// on several input edges (possible only near a vertex) gets the union of their regions.
    fn regions_of_edges(&self, edges: &[u32], set: &mut Vec<u32>) {
        set.clear();
        for &e in edges {
            let edge = &self.prepared.edges[e as usize];
            for &f in &edge.faces[..edge.count.min(2) as usize] {
                set.push(self.regions.of_face[f as usize]);
            }
        }
        set.sort_unstable();
        set.dedup();
    }
}

/// A mesh whose indices and coordinates were validated, with its edges and topology.
struct Prepared {
    referenced: Vec<bool>,
    edges: Vec<Edge>,
    stats: TopologyStats,
}

impl Prepared {
    /// Validates indices and coordinates (failures and `None` when wrong), then builds the edges
    /// and topology, reporting non-manifold features as failures. `around`: the faces around
    /// the vertices, if known.
    fn new(names: &Names, around: Option<&VertexFaces>, fail: &mut Failures) -> Option<Prepared> {
        validate(names, fail).map(|referenced| Prepared::build(names, referenced, around, fail))
    }

    /// The edges and topology of a mesh whose indices and coordinates are valid (`referenced`:
    /// [`validate`]), reporting non-manifold features as failures. `around`: the faces around
    /// the vertices, made here if not given.
    fn build(names: &Names, referenced: Vec<bool>, around: Option<&VertexFaces>, fail: &mut Failures) -> Prepared {
        let made;
        let around = match around {
            Some(around) => around,
            None => {
                made = VertexFaces::new(names.mesh);
                &made
            }
        };
        let EdgesAndFans { edges, not_single_fans } = build_edges(names, around, fail);
        let stats = topology_stats(names, &referenced, &edges, &not_single_fans, fail);
        Prepared {
            referenced,
            edges,
            stats,
        }
    }
}

/// Validates a mesh's indices and coordinates: which vertices its faces use, or `None` with
/// failures when an index or a used coordinate is wrong.
fn validate(names: &Names, fail: &mut Failures) -> Option<Vec<bool>> {
    let (mesh, who) = (names.mesh, names.who);
    let n = mesh.positions.len();
    let failures_before = fail.total();
    let mut referenced = vec![false; n];
    for (f, t) in mesh.triangles.iter().enumerate() {
        for &v in t {
            match referenced.get_mut(v as usize) {
                Some(r) => *r = true,
                None => fail.push(KIND_INDEX, || {
                    format!(
                        "{}{who} {} refers to vertex {} of {n}",
                        names.face_at(f),
                        names.face_noun(f),
                        names.vertex_number(v)
                    )
                }),
            }
        }
    }
    if fail.total() > failures_before {
        return None;
    }
    for (v, p) in mesh.positions.iter().enumerate() {
        if referenced[v] && !p.is_finite() {
            fail.push(KIND_INDEX, || {
                let v = v as u32;
                format!("{}{who} {} is not finite", names.vertex_at(v), names.vertex(v))
            });
        } else if referenced[v] && !crate::io::in_supported_range(*p) {
            // Products of such coordinates overflow: areas and angles
            // would read NaN. The construction refuses them too.
            fail.push(KIND_INDEX, || {
                let v = v as u32;
                format!(
                    "{}{who} {} has a coordinate beyond ±{:e}, the supported range",
                    names.vertex_at(v),
                    names.vertex(v),
                    crate::io::MAX_COORDINATE
                )
            });
        }
    }
    if fail.total() > failures_before {
        return None;
    }
    Some(referenced)
}

// ---------------------------------------------------------------------------------------------
// Edges and topology
// ---------------------------------------------------------------------------------------------

/// An undirected edge `lo < hi` with (up to) its first two faces.
struct Edge {
    lo: u32,
    hi: u32,
    /// The first two faces using the edge (`u32::MAX` when absent).
    faces: [u32; 2],
    /// Whether each of those faces uses the edge as `lo -> hi`.
    forward: [bool; 2],
    /// Number of faces using the edge.
    count: u32,
}

impl Edge {
    /// Two faces using the edge in opposite directions.
    fn is_interior(&self) -> bool {
        self.count == 2 && self.forward[0] != self.forward[1]
    }

    /// For an interior edge: `(a, b, f, g)` with face `f = (a, b, c)` and face `g = (b, a, d)`.
    fn oriented(&self) -> (u32, u32, u32, u32) {
        let (a, b) = if self.forward[0] {
            (self.lo, self.hi)
        } else {
            (self.hi, self.lo)
        };
        (a, b, self.faces[0], self.faces[1])
    }
}

/// A face repeating a vertex (it has no proper edges).
fn is_degenerate(t: &[u32; 3]) -> bool {
    t[0] == t[1] || t[1] == t[2] || t[2] == t[0]
}

/// The vertex of `t` that is neither `a` nor `b`.
fn third(t: &[u32; 3], a: u32, b: u32) -> u32 {
    t.iter().copied().find(|&v| v != a && v != b).unwrap_or(a)
}

/// The edges of a mesh, and the vertices whose faces do not form a single fan (a disk or
/// half-disk), found in one pass over the faces around each vertex.
struct EdgesAndFans {
    edges: Vec<Edge>,
    /// In increasing order; reported by [`topology_stats`], after the edges' failures.
    not_single_fans: Vec<u32>,
}

/// Builds the undirected edges of the non-degenerate faces (sorted by vertex pair), reporting
/// degenerate faces, edges with more than two faces and edges used twice in one direction,
/// and finds the vertices whose faces do not form a single fan. `around`: the faces around
/// each vertex.
fn build_edges(names: &Names, around: &VertexFaces, fail: &mut Failures) -> EdgesAndFans {
    let (mesh, who) = (names.mesh, names.who);
    for (f, t) in mesh.triangles.iter().enumerate() {
        if is_degenerate(t) {
            fail.push(KIND_DEGENERATE, || {
                format!("{}{who} {} repeats a vertex", names.face_at(f), names.face(f))
            });
        }
    }
    // The half-edges whose lower vertex is `lo`, as `(higher, face, forward)`, are those of the
    // faces around `lo` to a higher vertex: gathered and sorted one (small) row at a time. The
    // vertex's link edges, one per face `(lo, x, y)`: `(x, y)`. (Most edges have two faces.)
    let mut edges = Vec::with_capacity(3 * mesh.triangles.len() / 2 + 1);
    let mut not_single_fans = Vec::new();
    let (mut row, mut link, mut heads) = (Vec::new(), Vec::new(), Vec::new());
    for lo in 0..mesh.positions.len() {
        row.clear();
        link.clear();
        for &f in around.of(lo) {
            let t = &mesh.triangles[f as usize];
            if is_degenerate(t) {
                continue;
            }
            let k = t.iter().position(|&v| v as usize == lo).unwrap_or(0);
            // The half-edges (lo, next) and (previous, lo) of the face.
            let (next, previous) = (t[(k + 1) % 3], t[(k + 2) % 3]);
            if next as usize > lo {
                row.push((next, f, true));
            }
            if previous as usize > lo {
                row.push((previous, f, false));
            }
            link.push((next, previous));
        }
        row.sort_unstable();
        for group in row.chunk_by(|x, y| x.0 == y.0) {
            push_edge(lo as u32, group, &mut edges, names, fail);
        }
        if !link.is_empty() && is_single_fan(&mut link, &mut heads) == Some(false) {
            not_single_fans.push(lo as u32);
        }
    }
    EdgesAndFans { edges, not_single_fans }
}

/// Appends the edge `(lo, hi)` made of `group` (all `(hi, face, forward)` entries of one vertex
/// pair), reporting it when it has more than two faces or is misoriented.
/// A failure line names the line of the edge's third face, or its second, as the construction's
/// reader names the face where it finds the problem.
fn push_edge(lo: u32, group: &[(u32, u32, bool)], edges: &mut Vec<Edge>, names: &Names, fail: &mut Failures) {
    let who = names.who;
    let (hi, f0, d0) = group[0];
    let second = group.get(1).copied();
    let edge = Edge {
        lo,
        hi,
        faces: [f0, second.map_or(u32::MAX, |s| s.1)],
        forward: [d0, second.is_some_and(|s| s.2)],
        count: group.len() as u32,
    };
    if edge.count > 2 {
        fail.push(KIND_MANIFOLD, || {
            let third = group[2].1 as usize;
            let faces: Vec<String> = group.iter().take(4).map(|g| names.face_noun(g.1 as usize)).collect();
            let more = if group.len() > 4 { ", ..." } else { "" };
            format!(
                "{}{who} edge ({}, {}) is shared by {} faces ({}{more})",
                names.face_at(third),
                names.label(lo),
                names.label(hi),
                edge.count,
                faces.join(", ")
            )
        });
    } else if edge.count == 2 && !edge.is_interior() {
        fail.push(KIND_MANIFOLD, || {
            let (f, g) = (edge.faces[0] as usize, edge.faces[1] as usize);
            format!(
                "{}{who} {} and {} use edge ({}, {}) in the same direction \
                 (inconsistent orientation)",
                names.face_at(g),
                names.face_noun(f),
                names.face_noun(g),
                names.label(lo),
                names.label(hi)
            )
        });
    }
    edges.push(edge);
}
/// Topological invariants of a mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct TopologyStats {
    /// Referenced vertices.
    vertices: usize,
    /// Undirected edges.
    edges: usize,
    /// Faces.
    faces: usize,
    /// `V - E + F`.
    euler: i64,
    /// Connected components (through faces).
    components: usize,
    /// Boundary loops; `None` when the mesh is not manifold (then undefined).
    boundary_loops: Option<usize>,
}

/// Computes the invariants, reporting vertices whose faces do not form a single fan.
fn topology_stats(
    names: &Names,
    referenced: &[bool],
    edges: &[Edge],
    not_single_fans: &[u32],
    fail: &mut Failures,
) -> TopologyStats {
    let mesh = names.mesh;
    let errors_before = fail.total();
    report_vertex_fans(names, not_single_fans, fail);
    let manifold = fail.total() == errors_before && edges.iter().all(|e| e.count == 1 || e.is_interior());
    let vertices = referenced.iter().filter(|&&r| r).count();
    TopologyStats {
        vertices,
        edges: edges.len(),
        faces: mesh.triangles.len(),
        euler: vertices as i64 - edges.len() as i64 + mesh.triangles.len() as i64,
        components: count_components(mesh, referenced),
        boundary_loops: manifold.then(|| count_boundary_loops(mesh.positions.len(), edges)),
    }
}

/// Reports every vertex whose faces do not form a single fan (found by [`build_edges`]).
fn report_vertex_fans(names: &Names, not_single_fans: &[u32], fail: &mut Failures) {
    let who = names.who;
    for &v in not_single_fans {
        fail.push(KIND_MANIFOLD, || {
            format!(
                "{}{who} {}: its faces do not form a single fan (non-manifold vertex)",
                names.vertex_at(v),
                names.vertex(v)
            )
        });
    }
}

/// Given the link edges `x -> y` of a vertex (one per face `(v, x, y)`), tells whether they form
/// one path or one cycle. `None` when a link vertex has two successors or two predecessors
/// (a non-manifold or misoriented edge, reported elsewhere). `heads` is a buffer, reused from
/// vertex to vertex.
fn is_single_fan(link: &mut [(u32, u32)], heads: &mut Vec<u32>) -> Option<bool> {
    if link.len() <= SMALL_FAN {
        return is_single_small_fan(link);
    }
    is_single_sorted_fan(link, heads)
}

/// [`is_single_fan`] by sorting the link edges and their heads.
fn is_single_sorted_fan(link: &mut [(u32, u32)], heads: &mut Vec<u32>) -> Option<bool> {
    link.sort_unstable();
    if link.windows(2).any(|w| w[0].0 == w[1].0) {
        return None;
    }
    heads.clear();
    heads.extend(link.iter().map(|e| e.1));
    heads.sort_unstable();
    if heads.windows(2).any(|w| w[0] == w[1]) {
        return None;
    }
    let successor = |x: u32| link.binary_search_by_key(&x, |e| e.0).ok().map(|i| link[i].1);
    let start = link
        .iter()
        .map(|e| e.0)
        .find(|x| heads.binary_search(x).is_err())
        .unwrap_or(link[0].0);
    let mut steps = 0;
    let mut current = start;
    while let Some(next) = successor(current) {
        steps += 1;
        current = next;
        if current == start || steps > link.len() {
            break;
        }
    }
    Some(steps == link.len())
}

/// [`is_single_fan`] of a short link, by comparing every pair of link edges instead of
/// sorting them. The answer is the same: without two successors or two predecessors, the link
/// is disjoint paths and cycles, and the walk covers every edge iff it is one of them, starting
/// from a path's start (an `x` that is no edge's `y`) if there is one, else anywhere.
fn is_single_small_fan(link: &[(u32, u32)]) -> Option<bool> {
    let n = link.len();
    for i in 1..n {
        if link[..i].iter().any(|e| e.0 == link[i].0 || e.1 == link[i].1) {
            return None;
        }
    }
    let start = (link.iter().map(|e| e.0))
        .find(|&x| link.iter().all(|e| e.1 != x))
        .unwrap_or(link[0].0);
    let successor = |x: u32| link.iter().find(|e| e.0 == x).map(|e| e.1);
    let mut steps = 0;
    let mut current = start;
    while let Some(next) = successor(current) {
        steps += 1;
        current = next;
        if current == start || steps > n {
            break;
        }
    }
    Some(steps == n)
}

/// Number of connected components of the referenced vertices, joined through faces.
fn count_components(mesh: &Mesh3, referenced: &[bool]) -> usize {
    let mut sets = UnionFind::new(mesh.positions.len());
    for t in &mesh.triangles {
        sets.union(t[0], t[1]);
        sets.union(t[1], t[2]);
    }
    (0..mesh.positions.len() as u32)
        .filter(|&v| referenced[v as usize] && sets.find(v) == v)
        .count()
}

/// Number of boundary loops of a manifold mesh: cycles of the directed boundary edges.
fn count_boundary_loops(vertex_count: usize, edges: &[Edge]) -> usize {
    const NONE: u32 = u32::MAX;
    let mut next = vec![NONE; vertex_count];
    for e in edges.iter().filter(|e| e.count == 1) {
        let (a, b) = if e.forward[0] { (e.lo, e.hi) } else { (e.hi, e.lo) };
        next[a as usize] = b;
    }
    let mut visited = vec![false; vertex_count];
    let mut loops = 0;
    for start in 0..vertex_count {
        if next[start] == NONE || visited[start] {
            continue;
        }
        loops += 1;
        let mut current = start as u32;
        while current != NONE && !visited[current as usize] {
            visited[current as usize] = true;
            current = next[current as usize];
        }
    }
    loops
}

/// Reports every invariant of the output that differs from the input's.
fn compare_topology(input: &TopologyStats, output: &TopologyStats, fail: &mut Failures) {
    if input.euler != output.euler {
        fail.push(KIND_TOPOLOGY, || {
            format!(
                "Euler characteristic {} became {} (V-E+F: {}-{}+{} became {}-{}+{})",
                input.euler,
                output.euler,
                input.vertices,
                input.edges,
                input.faces,
                output.vertices,
                output.edges,
                output.faces
            )
        });
    }
    if let (Some(a), Some(b)) = (input.boundary_loops, output.boundary_loops) {
        if a != b {
            fail.push(KIND_TOPOLOGY, || format!("number of boundary loops {a} became {b}"));
        }
    }
    if input.components != output.components {
        fail.push(KIND_TOPOLOGY, || {
            format!(
                "number of connected components {} became {}",
                input.components, output.components
            )
        });
    }
}

// ---------------------------------------------------------------------------------------------
// Planar regions of the input
// ---------------------------------------------------------------------------------------------

/// The planar regions of the input.
struct Regions {
    /// Region of every input face.
    of_face: Vec<u32>,
    /// Area of every region.
    area: Vec<f64>,
    /// Unit normal of every region (of its largest face; zero if all its faces have zero area).
    normal: Vec<DVec3>,
    /// A point of every region's plane (a corner of its largest face).
    anchor: Vec<DVec3>,
    /// The region's plane seen along one coordinate axis: every output face of the region must
    /// have, exactly, the orientation `plane.sign` in the projection along `plane.axis`.
    plane: Vec<Projection>,
    /// Lowest-numbered input face of every region (to name it).
    first_face: Vec<u32>,
}

/// A coordinate axis to project along, and the exact orientation (the sign of `orient2d`, see
/// [`projected_orientation`]) that the region's faces have in that projection; `sign` is 0 only
/// when the region's largest face is exactly degenerate.
#[derive(Clone, Copy)]
struct Projection {
    axis: usize,
    sign: i8,
}

impl Regions {
    /// Joins input faces across every interior edge that is exactly coplanar and flat.
    fn new(mesh: &Mesh3, edges: &[Edge]) -> Regions {
        let p = |v: u32| mesh.positions[v as usize];
        let mut sets = UnionFind::new(mesh.triangles.len());
        for e in edges.iter().filter(|e| e.is_interior()) {
            let (a, b, f, g) = e.oriented();
            let c = third(&mesh.triangles[f as usize], a, b);
            let d = third(&mesh.triangles[g as usize], a, b);
            if coplanar_and_flat(p(a), p(b), p(c), p(d)) {
                sets.union(f, g);
            }
        }
        let mut id = vec![u32::MAX; mesh.triangles.len()];
        let mut of_face = vec![0; mesh.triangles.len()];
        let mut area: Vec<CompensatedSum> = Vec::new();
        let mut first_face = Vec::new();
        // The largest face of every region: (its area, its index, its normal).
        let mut largest: Vec<(f64, u32, DVec3)> = Vec::new();
        for (f, (region, t)) in of_face.iter_mut().zip(&mesh.triangles).enumerate() {
            let root = sets.find(f as u32) as usize;
            if id[root] == u32::MAX {
                id[root] = area.len() as u32;
                area.push(CompensatedSum::default());
                first_face.push(f as u32);
                largest.push((-1.0, f as u32, DVec3::ZERO));
            }
            let r = id[root] as usize;
            *region = r as u32;
            let n = triangle_normal(corners(mesh, t));
            let face_area = 0.5 * n.length();
            area[r].add(face_area);
            if face_area > largest[r].0 {
                largest[r] = (face_area, f as u32, n);
            }
        }
        let normal = largest.iter().map(|&(_, _, n)| n.normalize_or_zero()).collect();
        let anchor = largest
            .iter()
            .map(|&(_, f, _)| mesh.positions[mesh.triangles[f as usize][0] as usize])
            .collect();
        let plane = largest
            .iter()
            .map(|&(_, f, _)| Projection::of_face(corners(mesh, &mesh.triangles[f as usize])))
            .collect();
        Regions {
            of_face,
            area: area.iter().map(CompensatedSum::value).collect(),
            normal,
            anchor,
            plane,
            first_face,
        }
    }

    /// A name for region `r` in failure lines, its face named by `input` (the input's names).
    fn name(&self, r: usize, input: &Names) -> String {
        format!(
            "region {} (containing input {})",
            r + 1,
            input.face_noun(self.first_face[r] as usize)
        )
    }

    /// Whether point `p` is in the plane of region `r`: within [`ON_EDGE_TOLERANCE`] of it,
    /// relative to the largest coordinate (of `p` and of the plane's point), as a point on an
    /// input edge is on it.
    fn holds(&self, r: usize, p: DVec3) -> bool {
        let anchor = self.anchor[r];
        let scale = p.abs().max_element().max(anchor.abs().max_element()).max(1e-300);
        self.normal[r].dot(p - anchor).abs() <= ON_EDGE_TOLERANCE * scale
    }

    /// The exact orientation of a triangle relative to region `r`: 1 when its projection along
    /// the region's axis has the region's orientation, -1 when reversed, 0 when that projection
    /// is degenerate (or the region has no orientation).
    fn side(&self, r: usize, triangle: [DVec3; 3]) -> i8 {
        let plane = self.plane[r];
        plane.sign * projected_orientation(triangle, plane.axis)
    }
}

impl Projection {
    /// The projection for a region with face `triangle`: along the axis of the largest
    /// component, exactly, of the normal `(b - a) x (c - a)` (ties: the lower axis). All faces of
    /// a region are exactly coplanar and alike oriented, so any face gives the same projection;
    /// it is the rule the construction states for its own checks, so that a face whose rounded
    /// corners leave the plane is judged in the projection it was built in.
    fn of_face(triangle: [DVec3; 3]) -> Projection {
        let mut axis = 0;
        for other in [1, 2] {
            if larger_normal_component(triangle, other, axis) {
                axis = other;
            }
        }
        Projection {
            axis,
            sign: projected_orientation(triangle, axis),
        }
    }
}

/// Exactly: `|n[i]| > |n[j]|` for the normal `n = (b - a) x (c - a)` of `triangle`. In floating
/// point with a bound on its rounding (two differences, a product and a subtraction: 8 units of
/// roundoff of the terms, plus underflow) when that decides; otherwise from the exact signs of
/// `n . (e_i - e_j)` and `n . (e_i + e_j)`, whose product is that of `|n_i|^2 - |n_j|^2`.
fn larger_normal_component([a, b, c]: [DVec3; 3], i: usize, j: usize) -> bool {
    let (u, v) = (b - a, c - a);
    let estimate = |k: usize| {
        let (p, q) = ((k + 1) % 3, (k + 2) % 3);
        let terms = [u[p] * v[q], u[q] * v[p]];
        let bound = 4.0 * f64::EPSILON * (terms[0].abs() + terms[1].abs()) + 8.0 * f64::from_bits(1);
        ((terms[0] - terms[1]).abs(), bound)
    };
    let ((x, ex), (y, ey)) = (estimate(i), estimate(j));
    if [x, ex, y, ey].iter().all(|t| t.is_finite()) {
        if x - ex > y + ey {
            return true;
        }
        if y - ey >= x + ex {
            return false;
        }
    }
    // n . w = -det[[a, 1], [b, 1], [c, 1], [w, 0]]; the two signs' product drops the minus.
    let dot_sign = |w: [f64; 3]| {
        let row = |p: DVec3| [p.x, p.y, p.z, 1.0];
        exact_determinant_sign([row(a), row(b), row(c), [w[0], w[1], w[2], 0.0]])
    };
    let (mut minus, mut plus) = ([0.0; 3], [0.0; 3]);
    minus[i] = 1.0;
    minus[j] = -1.0;
    plus[i] = 1.0;
    plus[j] = 1.0;
    dot_sign(minus) * dot_sign(plus) > 0
}

/// The sign (-1, 0 or 1), exactly, of the orientation of a triangle projected along coordinate
/// axis `axis`, i.e. of component `axis` of its exact normal `(b - a) x (c - a)`: the projection
/// keeps the other two coordinates in cyclic order (y, z), (z, x) or (x, y).
fn projected_orientation([a, b, c]: [DVec3; 3], axis: usize) -> i8 {
    let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
    orient2d_sign([a[i], a[j]], [b[i], b[j]], [c[i], c[j]])
}

/// Whether a triangle is exactly degenerate (its corners are collinear): all three projections
/// along the coordinate axes are.
fn exactly_degenerate(triangle: [DVec3; 3]) -> bool {
    (0..3).all(|axis| projected_orientation(triangle, axis) == 0)
}

/// Exactly: `d` is in the plane of `a, b, c` and on the other side of line `ab` than `c`.
fn coplanar_and_flat(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    // Four points with one coordinate equal lie in that axis plane: decided without the exact
    // predicate, which would run its slowest stage to prove the zero (most flat pairs of CAD
    // meshes are such).
    let in_axis_plane = (0..3).any(|k| a[k] == b[k] && a[k] == c[k] && a[k] == d[k]);
    if !in_axis_plane && orient3d_sign(a, b, c, d) != 0 {
        return false;
    }
    for axis in 0..3 {
        let side_c = projected_orientation([a, b, c], axis);
        if side_c != 0 {
            return side_c == -projected_orientation([a, b, d], axis);
        }
    }
    false
}

/// The sign (-1, 0 or 1) of `(ax - cx)(by - cy) - (ay - cy)(bx - cx)`, exactly for every finite
/// input: `robust::orient2d` where it is exact (see [`robust_is_exact`]), on the coordinates of
/// each axis rescaled by a power of two where that makes it exact ([`rescaled`]), and an exact
/// expansion of the determinant otherwise ([`exact_determinant_sign`]).
fn orient2d_sign(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
    let robust_sign = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        let coord = |p: [f64; 2]| robust::Coord { x: p[0], y: p[1] };
        sign_of(robust::orient2d(coord(a), coord(b), coord(c)))
    };
    if robust_is_exact(&[a[0], a[1], b[0], b[1], c[0], c[1]]) {
        return robust_sign(a, b, c);
    }
    match (rescaled([a[0], b[0], c[0]]), rescaled([a[1], b[1], c[1]])) {
        (Some([ax, bx, cx]), Some([ay, by, cy])) => robust_sign([ax, ay], [bx, by], [cx, cy]),
        // The determinant of the rows (x, y, 1) of a, b, c.
        _ => exact_determinant_sign([[a[0], a[1], 1.0], [b[0], b[1], 1.0], [c[0], c[1], 1.0]]),
    }
}

/// The sign (-1, 0 or 1) of the determinant of the rows `a - d`, `b - d`, `c - d` (that of
/// `robust::orient3d`), exactly for every finite input, as [`orient2d_sign`].
fn orient3d_sign(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let robust_sign = |[a, b, c, d]: [DVec3; 4]| {
        let coord = |p: DVec3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
        sign_of(robust::orient3d(coord(a), coord(b), coord(c), coord(d)))
    };
    let coordinates = [a.to_array(), b.to_array(), c.to_array(), d.to_array()];
    if robust_is_exact(coordinates.as_flattened()) {
        return robust_sign([a, b, c, d]);
    }
    match [0, 1, 2].map(|i| rescaled([a[i], b[i], c[i], d[i]])) {
        [Some(x), Some(y), Some(z)] => robust_sign([0, 1, 2, 3].map(|k| DVec3::new(x[k], y[k], z[k]))),
        // The determinant of the rows (x, y, z, 1) of a, b, c, d.
        _ => exact_determinant_sign(coordinates.map(|[x, y, z]| [x, y, z, 1.0])),
    }
}

/// The coordinates of one axis (of all the points of a predicate) multiplied by the power of two
/// that brings the largest magnitude near 2^200, if then [`robust_is_exact`] on them; `None`
/// otherwise (a non-finite value, or magnitudes too far apart, such as 0.2 and 1e-160).
///
/// Both determinants are sums of terms with exactly one coordinate (difference) per axis, so
/// multiplying one axis by a positive factor keeps their sign. The multiplication is exact: up,
/// nothing is lost below 2^203; down, a value that loses bits ends below 2^-1022, and then
/// `robust_is_exact` refuses the result.
fn rescaled<const N: usize>(values: [f64; N]) -> Option<[f64; N]> {
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !values.iter().all(|v| v.is_finite()) {
        return None;
    }
    if largest == 0.0 {
        return Some(values);
    }
    let k = 200 - largest.log2().floor() as i32; // within -824 ..= 1274
    let (k1, k2) = (k / 2, k - k / 2);
    let scaled = values.map(|v| v * 2f64.powi(k1) * 2f64.powi(k2));
    robust_is_exact(&scaled).then_some(scaled)
}

/// -1, 0 or 1 (0 for NaN).
fn sign_of(x: f64) -> i8 {
    (x > 0.0) as i8 - (x < 0.0) as i8
}

/// Whether Shewchuk's predicates (the `robust` crate) are exact on these coordinates: they are
/// when no operation underflows or overflows. With every coordinate 0 or of magnitude in
/// [2^-250, 2^250], coordinates are multiples of 2^-302, and every value either predicate
/// computes (products of at most three coordinate differences, their sums and exact rounding
/// errors) is 0 or a multiple of 2^-906 below 2^760: all in the normal range. Outside it, a
/// coordinate such as 2e-323 makes products round to 0 and calls a valid triangle degenerate.
fn robust_is_exact(coordinates: &[f64]) -> bool {
    const LOW: f64 = 5.527147875260445e-76; // 2^-250
    const HIGH: f64 = 1.8092513943330656e75; // 2^250
    coordinates.iter().all(|&x| x == 0.0 || (LOW..=HIGH).contains(&x.abs()))
}

/// The exact sign of the determinant of a 3x3 or 4x4 matrix of finite numbers.
///
/// Leibniz expansion: every term, a product of N entries, is computed exactly as an integer
/// mantissa (at most 4 x 53 bits) times a power of two, and the terms are accumulated in two wide
/// fixed-point integers (positive and negative terms) whose lowest bit is the smallest power of
/// two among the terms; their comparison gives the sign. Slow (a few microseconds), only used
/// where `robust` is not exact. Non-finite entries give the sign of the float expansion.
fn exact_determinant_sign<const N: usize>(matrix: [[f64; N]; N]) -> i8 {
    if matrix.iter().flatten().any(|x| !x.is_finite()) {
        let mut sum = 0.0;
        for (permutation, odd) in permutations::<N>() {
            let product: f64 = (0..N).map(|i| matrix[i][permutation[i]]).product();
            sum += if odd { -product } else { product };
        }
        return sign_of(sum);
    }
    // (negative, mantissa limbs, exponent) of every non-zero term.
    let mut terms: Vec<(bool, Vec<u64>, i64)> = Vec::new();
    for (permutation, odd) in permutations::<N>() {
        let mut negative = odd;
        let mut mantissa = vec![1u64];
        let mut exponent = 0i64;
        let mut zero = false;
        for (i, row) in matrix.iter().enumerate() {
            let (m, e, is_negative) = integer_parts(row[permutation[i]]);
            zero |= m == 0;
            negative ^= is_negative;
            mantissa = multiply_by_word(&mantissa, m);
            exponent += e;
        }
        if !zero {
            terms.push((negative, mantissa, exponent));
        }
    }
    let Some(lowest) = terms.iter().map(|t| t.2).min() else {
        return 0;
    };
    let (mut positive, mut negative) = (Vec::new(), Vec::new());
    for (is_negative, mantissa, exponent) in &terms {
        let sum = if *is_negative { &mut negative } else { &mut positive };
        add_shifted(sum, mantissa, (exponent - lowest) as usize);
    }
    match compare_wide(&positive, &negative) {
        std::cmp::Ordering::Greater => 1,
        std::cmp::Ordering::Less => -1,
        std::cmp::Ordering::Equal => 0,
    }
}

/// `x = ±m 2^e` for a finite `x`: `(m, e, x < 0)`, `m` an integer below 2^53 (0 for zeros).
fn integer_parts(x: f64) -> (u64, i64, bool) {
    let bits = x.to_bits();
    let biased = ((bits >> 52) & 0x7FF) as i64;
    let fraction = bits & ((1u64 << 52) - 1);
    let (m, e) = match biased {
        0 => (fraction, -1074),
        _ => (fraction | (1u64 << 52), biased - 1075),
    };
    (m, e, x < 0.0)
}

/// The permutations of `0..N` with their parity (true for odd), in lexicographic order.
fn permutations<const N: usize>() -> Vec<([usize; N], bool)> {
    let mut out = Vec::new();
    let mut current = [0usize; N];
    fn extend<const N: usize>(k: usize, used: u32, current: &mut [usize; N], out: &mut Vec<([usize; N], bool)>) {
        if k == N {
            let inversions = (0..N)
                .flat_map(|i| (i + 1..N).map(move |j| (i, j)))
                .filter(|&(i, j)| current[i] > current[j])
                .count();
            out.push((*current, inversions % 2 == 1));
            return;
        }
        for v in (0..N).filter(|v| used & (1 << v) == 0) {
            current[k] = v;
            extend(k + 1, used | (1 << v), current, out);
        }
    }
    extend(0, 0, &mut current, &mut out);
    out
}

/// `limbs * m` (little-endian 64-bit limbs).
fn multiply_by_word(limbs: &[u64], m: u64) -> Vec<u64> {
    let mut out = Vec::with_capacity(limbs.len() + 1);
    let mut carry = 0u128;
    for &x in limbs {
        let t = x as u128 * m as u128 + carry;
        out.push(t as u64);
        carry = t >> 64;
    }
    out.push(carry as u64);
    out
}

/// `sum += value * 2^shift` (little-endian 64-bit limbs; `sum` grows as needed).
fn add_shifted(sum: &mut Vec<u64>, value: &[u64], shift: usize) {
    let (words, bits) = (shift / 64, shift % 64);
    let needed = words + value.len() + 2;
    if sum.len() < needed {
        sum.resize(needed, 0);
    }
    let mut carry = 0u128;
    for i in 0..=value.len() {
        let low = value.get(i).copied().unwrap_or(0);
        let high = if i > 0 && bits > 0 {
            value[i - 1] >> (64 - bits)
        } else {
            0
        };
        let word = (low << bits) | high;
        let t = sum[words + i] as u128 + word as u128 + carry;
        sum[words + i] = t as u64;
        carry = t >> 64;
    }
    let mut k = words + value.len() + 1;
    while carry != 0 {
        let t = sum[k] as u128 + carry;
        sum[k] = t as u64;
        carry = t >> 64;
        k += 1;
        if k == sum.len() && carry != 0 {
            sum.push(0);
        }
    }
}

/// Compares two little-endian wide integers (of any lengths, high zero limbs allowed).
fn compare_wide(a: &[u64], b: &[u64]) -> std::cmp::Ordering {
    let n = a.len().max(b.len());
    (0..n)
        .rev()
        .map(|i| a.get(i).copied().unwrap_or(0).cmp(&b.get(i).copied().unwrap_or(0)))
        .find(|o| o.is_ne())
        .unwrap_or(std::cmp::Ordering::Equal)
}

/// The corners of a face.
fn corners(mesh: &Mesh3, t: &[u32; 3]) -> [DVec3; 3] {
    t.map(|v| mesh.positions[v as usize])
}

/// The normal of a triangle (twice its area in length, oriented by the corner order), accurate
/// to a few units in the last place of each component whatever the coordinates' magnitude:
///
/// * the cross product is taken at the corner opposite the longest edge, so that the two edges
///   crossed are the two shortest ones: the plain `(b - a) x (c - a)` crosses two long, nearly
///   parallel edges when `a` is far from a short edge `bc`, and at coordinates near 4e9 with
///   faces a few units wide loses 3.5e-8 of a region's area to cancellation;
/// * the edge vectors are computed exactly, as unevaluated sums `hi + lo` (TwoSum), and each
///   component as a difference of products with fused multiply-adds (Kahan's algorithm) plus the
///   first-order terms of the `lo` parts, so that even a needle face (whose largest angle is
///   within 1e-16 of pi) gets a normal of the right direction and length, not 0.
///
/// The orientation checks do not rely on it (they are exact, see [`Regions::side`]); the area
/// and the choice between regions do.
fn triangle_normal(t: [DVec3; 3]) -> DVec3 {
    // Squared length of the edge opposite each corner.
    let l = [0, 1, 2].map(|i| (t[(i + 2) % 3] - t[(i + 1) % 3]).length_squared());
    let o = if l[0] >= l[1] && l[0] >= l[2] {
        0
    } else if l[1] >= l[2] {
        1
    } else {
        2
    };
    let (uh, ul) = exact_difference(t[(o + 1) % 3], t[o]);
    let (vh, vl) = exact_difference(t[(o + 2) % 3], t[o]);
    // u_i v_j - u_j v_i, with u = uh + ul and v = vh + vl (the ul vl terms are below rounding).
    let component = |i: usize, j: usize| {
        let main = difference_of_products(uh[i], vh[j], uh[j], vh[i]);
        let tails = (uh[i] * vl[j] + ul[i] * vh[j]) - (uh[j] * vl[i] + ul[j] * vh[i]);
        main + tails
    };
    DVec3::new(component(1, 2), component(2, 0), component(0, 1))
}

/// `p - q` as an unevaluated sum `hi + lo`, exactly per component (Knuth's TwoSum; exact for
/// every finite input whose difference does not overflow, subnormal ones included).
fn exact_difference(p: DVec3, q: DVec3) -> (DVec3, DVec3) {
    let two_diff = |a: f64, b: f64| {
        let s = a - b;
        let virtual_b = s - a;
        let lo = (a - (s - virtual_b)) - (b + virtual_b);
        (s, lo)
    };
    let (x, y, z) = (two_diff(p.x, q.x), two_diff(p.y, q.y), two_diff(p.z, q.z));
    (DVec3::new(x.0, y.0, z.0), DVec3::new(x.1, y.1, z.1))
}

/// `a b - c d` with one rounding error of each product compensated (Kahan's algorithm with
/// fused multiply-adds): within 1.5 units in the last place of the exact value.
fn difference_of_products(a: f64, b: f64, c: f64, d: f64) -> f64 {
    let cd = c * d;
    let cd_error = (-c).mul_add(d, cd); // cd - c d, exactly
    a.mul_add(b, -cd) + cd_error
}

/// Neumaier's compensated summation: the sum of many areas of very different sizes, accurate
/// to about one rounding of the result instead of one per term.
#[derive(Default, Clone, Copy)]
struct CompensatedSum {
    sum: f64,
    compensation: f64,
}

impl CompensatedSum {
    fn add(&mut self, x: f64) {
        let t = self.sum + x;
        self.compensation += if self.sum.abs() >= x.abs() {
            (self.sum - t) + x
        } else {
            (x - t) + self.sum
        };
        self.sum = t;
    }

    fn value(&self) -> f64 {
        self.sum + self.compensation
    }
}

// ---------------------------------------------------------------------------------------------
// Output vertices
// ---------------------------------------------------------------------------------------------

/// Candidate regions of every output vertex.
struct Candidates {
    /// Regions per output vertex (sorted, unique).
    regions: Csr,
    /// Whether the vertex was recognised (input vertex or on an input edge).
    known: Vec<bool>,
    /// Number of referenced output vertices that are not input vertices.
    added: usize,
    /// Number of output vertices no face uses.
    unused: usize,
    /// Whether an added vertex lies on each input edge (indexed like `Prepared::edges`).
    edge_has_added: Vec<bool>,
}

/// Where the output's vertices are looked up: the input's vertices by position, and for the
/// others the input's edges ([`EdgeGrid`]).
struct VertexSearch {
    /// The first input vertex (used by a face) at every such position...
    lookup: FastMap<[u64; 3], u32>,
    /// ...and the next one there (several share one position where a pinch was read as
    /// separate fans, see `split_pinched_vertices`), or [`VertexSearch::END`].
    same_next: Vec<u32>,
    /// Output vertices used by a face at each input vertex's position (counted on the first
    /// input vertex there).
    at_position: Vec<u32>,
    /// The positions of the output vertices the grid will look up (its trees are shaped by them).
    added_points: Vec<DVec3>,
    /// The positions of the input vertices no face uses: an unused output vertex may sit there.
    unused_input: HashSet<[u64; 3], crate::hash::FastBuild>,
    /// The grid, once built: at once when some output vertex is not at an input vertex's
    /// position, else when first needed (if ever).
    grid: Option<EdgeGrid>,
    /// The input edges containing each output vertex used by a face and not at an input
    /// vertex's position, looked up in the grid as soon as it is built (a row per output
    /// vertex, empty for the others): on the thread that builds the grid, beside the input's
    /// regions and the output's edges.
    added_edges: Csr,
}

impl VertexSearch {
    /// Marks the end of a `same_next` chain.
    const END: u32 = u32::MAX;

    /// Indexes the `input` (validated as `prepared`) for the vertices of `output`, whose faces
    /// use the vertices marked in `out_referenced`.
    fn new(input: &Mesh3, prepared: &Prepared, output: &Mesh3, out_referenced: &[bool]) -> VertexSearch {
        let mut lookup: FastMap<[u64; 3], u32> = FastMap::default();
        let mut same_next = vec![Self::END; input.positions.len()];
        for (v, p) in input.positions.iter().enumerate().rev() {
            if prepared.referenced[v] {
                if let Some(old) = lookup.insert(bits(*p), v as u32) {
                    same_next[v] = old;
                }
            }
        }
        let mut at_position = vec![0u32; input.positions.len()];
        let mut added_points = Vec::new();
        let unused_input: HashSet<[u64; 3], crate::hash::FastBuild> = (input.positions.iter().enumerate())
            .filter(|&(v, _)| !prepared.referenced[v])
            .map(|(_, p)| bits(*p))
            .collect();
        let is_input_position = |p: DVec3| lookup.contains_key(&bits(p)) || unused_input.contains(&bits(p));
        for (v, p) in output.positions.iter().enumerate() {
            match (out_referenced[v], lookup.get(&bits(*p))) {
                (true, Some(&first)) => at_position[first as usize] += 1,
                (true, None) => added_points.push(*p),
                (false, _) if p.is_finite() && !is_input_position(*p) => added_points.push(*p),
                (false, _) => {}
            }
        }
        // Every vertex of `added_points` is looked up in the grid.
        let grid = (!added_points.is_empty()).then(|| EdgeGrid::new(input, &prepared.edges, &added_points));
        let mut added_edges = CsrBuilder::default();
        if let Some(grid) = &grid {
            let mut on_edges = Vec::new();
            for (v, p) in output.positions.iter().enumerate() {
                if out_referenced[v] && !lookup.contains_key(&bits(*p)) {
                    grid.edges_containing(input, &prepared.edges, *p, &mut on_edges);
                    added_edges.extend(&on_edges);
                }
                added_edges.finish_row();
            }
        }
        VertexSearch {
            lookup,
            same_next,
            at_position,
            added_points,
            unused_input,
            grid,
            added_edges: added_edges.build(),
        }
    }
}

/// Checks rules 1 and 2 and returns the candidate regions of every output vertex, looked up
/// in `search` (made for this model and output).
fn classify_output_vertices(
    model: &InputModel,
    search: &mut VertexSearch,
    output_names: &Names,
    out_referenced: &[bool],
    fail: &mut Failures,
) -> Candidates {
    let input = model.mesh;
    let output = output_names.mesh;
    const END: u32 = VertexSearch::END;
    let VertexSearch {
        lookup,
        same_next,
        at_position,
        added_points,
        unused_input,
        grid,
        added_edges,
    } = search;
    let is_input_position = |p: DVec3| lookup.contains_key(&bits(p)) || unused_input.contains(&bits(p));
    let mut seen = vec![false; input.positions.len()];
    let mut regions = CsrBuilder::default();
    let mut known = vec![false; output.positions.len()];
    let mut added = 0;
    let mut unused = 0;
    let mut edge_has_added = vec![false; model.prepared.edges.len()];
    let mut on_edges = Vec::new();
    let mut set = Vec::new();
    let mut edge_regions = Vec::new();
    for (v, &p) in output.positions.iter().enumerate() {
        if !out_referenced[v] {
            // In no face, so in no region: it must only be where the output may have vertices.
            unused += 1;
            let on_input = p.is_finite()
                && (is_input_position(p) || {
                    let grid = grid.get_or_insert_with(|| EdgeGrid::new(input, &model.prepared.edges, added_points));
                    grid.edges_containing(input, &model.prepared.edges, p, &mut on_edges);
                    !on_edges.is_empty()
                });
            if !on_input {
                fail.push(KIND_VERTEX, || {
                    format!(
                        "an output vertex no face uses, {}, is neither an input vertex nor on an input edge",
                        point_text(p)
                    )
                });
            }
            regions.finish_row();
            continue;
        }
        if let Some(&first) = lookup.get(&bits(p)) {
            known[v] = true;
            set.clear();
            let mut iv = first;
            let mut input_count = 0;
            while iv != END {
                seen[iv as usize] = true;
                set.extend_from_slice(model.vertex_regions.row(iv as usize));
                iv = same_next[iv as usize];
                input_count += 1;
            }
            // Where the surface touches itself, an input vertex can lie inside an input edge of
            // another part (a T-junction in space): a vertex added on that edge there can have
            // the input vertex's position, bit for bit, and belongs to the edge's regions. When
            // the output has more vertices at the position than the input, which is which is
            // unknown: all of them get the regions of both. (Not otherwise: an input vertex
            // merely within the on-edge tolerance of an edge does not join its regions.)
            if at_position[first as usize] > input_count {
                let grid = grid.get_or_insert_with(|| EdgeGrid::new(input, &model.prepared.edges, added_points));
                grid.edges_containing(input, &model.prepared.edges, p, &mut on_edges);
                model.regions_of_edges(&on_edges, &mut edge_regions);
                set.extend_from_slice(&edge_regions);
                on_edges.iter().for_each(|&e| edge_has_added[e as usize] = true);
            }
            set.sort_unstable();
            set.dedup();
            regions.extend(&set);
        } else {
            added += 1;
            // (Looked up when the grid was built, which it was: `p` is among its points.)
            on_edges.clear();
            on_edges.extend_from_slice(added_edges.row(v));
            if on_edges.is_empty() {
                fail.push(KIND_VERTEX, || {
                    format!(
                        "output {} is neither an input vertex nor on an input edge",
                        output_names.vertex(v as u32)
                    )
                });
            } else {
                known[v] = true;
                model.regions_of_edges(&on_edges, &mut set);
                regions.extend(&set);
                on_edges.iter().for_each(|&e| edge_has_added[e as usize] = true);
            }
        }
        regions.finish_row();
    }
    for (v, &seen) in seen.iter().enumerate() {
        if model.prepared.referenced[v] && !seen {
            fail.push(KIND_MISSING, || {
                format!("input {} missing from output", model.names.vertex(v as u32))
            });
        }
    }
    Candidates {
        regions: regions.build(),
        known,
        added,
        unused,
        edge_has_added,
    }
}

/// The on-edge tolerance of input edge `(a, b)`; see [`ON_EDGE_TOLERANCE`].
fn edge_tolerance(a: DVec3, b: DVec3) -> f64 {
    ON_EDGE_TOLERANCE * a.abs().max_element().max(b.abs().max_element()).max(1e-300)
}

/// The distance from `p` to segment `(a, b)` if `p` lies on it strictly between its endpoints,
/// within tolerance; `None` otherwise.
fn distance_on_edge(p: DVec3, a: DVec3, b: DVec3) -> Option<f64> {
    let d = b - a;
    let len2 = d.length_squared();
    if len2 <= 0.0 {
        return None;
    }
    let t = (p - a).dot(d) / len2;
    let distance = (p - (a + t * d)).length();
    // Strictly between the endpoints: 0 < t < 1, decided from the nearer end (the computed t
    // rounds to 1 for a point a few units of roundoff of a from b on a long edge).
    let inside = (p - a).dot(d) > 0.0 && (p - b).dot(d) < 0.0;
    (inside && distance <= edge_tolerance(a, b)).then_some(distance)
}

/// How much farther than the nearest one another input edge containing a point may be and still
/// count as the point's edge, relative to the edge's largest coordinate: 16 units of roundoff,
/// the error of computing a point on an edge and its distance, and far below the on-edge
/// tolerance (about 70,000 units).
const NEAREST_EDGE_SLACK: f64 = 16.0 * f64::EPSILON;

/// A spatial hash over the input edges: every edge is cut into pieces no longer than the cell
/// size, and each piece (its bounding box grown by twice the edge's tolerance) is registered in
/// every cell it overlaps. Cells are hashed into a table of buckets stored as one flat array (CSR).
///
/// Crowded cells where output points fall (around a vertex of high valence, which every one of
/// its edges crosses) are refined by octrees, [`CellTrees`]: a point there is tested against the
/// edges of its leaf instead of the whole bucket.
///
/// Cell coordinates are computed in a frame scaled by an exact power of two (`scale`, 1 unless
/// coordinates exceed 2^1000), so that no difference of coordinates can overflow.
struct EdgeGrid {
    frame: GridFrame,
    mask: usize,
    starts: Vec<usize>,
    items: Vec<u32>,
    trees: CellTrees,
}

/// The geometry of an [`EdgeGrid`], in the scaled frame `q = p * scale`.
struct GridFrame {
    scale: f64,
    /// Lowest corner of the edges' bounding box, in the scaled frame.
    origin: DVec3,
    /// Cell size in the scaled frame.
    cell: f64,
    /// Deepest level of the [`CellTrees`]: at most [`TREE_DEPTH`], and cells of that level
    /// (`cell / 2^depth`) stay at least four times the largest edge tolerance.
    depth_limit: u32,
}

impl GridFrame {
    /// Chooses the frame for the edges that [`can_contain_points`]. The cell size is the median
    /// edge length, but at least a quarter of the mean length (so long edges make at most 5E
    /// pieces in total), at least four times the largest edge tolerance (so a grown piece spans
    /// at most 3 cells per axis) and at least `1e-9` of the extent (so cell coordinates stay far
    /// inside `i64`).
    fn new(mesh: &Mesh3, edges: &[Edge]) -> GridFrame {
        let usable = || {
            edges
                .iter()
                .map(|e| (mesh.positions[e.lo as usize], mesh.positions[e.hi as usize]))
                .filter(|&segment| can_contain_points(segment))
        };
        let largest = usable()
            .map(|(a, b)| a.abs().max(b.abs()).max_element())
            .fold(0.0, f64::max);
        let scale = if largest > 2f64.powi(1000) { 2f64.powi(-24) } else { 1.0 };
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        let mut lengths = Vec::new();
        for (a, b) in usable() {
            let (a, b) = (a * scale, b * scale);
            lo = lo.min(a).min(b);
            hi = hi.max(a).max(b);
            lengths.push((b - a).length());
        }
        if lengths.is_empty() {
            return GridFrame {
                scale,
                origin: DVec3::ZERO,
                cell: 1.0,
                depth_limit: 0,
            };
        }
        let mean = lengths.iter().sum::<f64>() / lengths.len() as f64;
        let mid = lengths.len() / 2;
        let median = *lengths.select_nth_unstable_by(mid, f64::total_cmp).1;
        let smallest = 4.0 * ON_EDGE_TOLERANCE * largest.max(1e-300) * scale;
        let mut cell = median.max(mean / 4.0).max(smallest).max((hi - lo).max_element() * 1e-9);
        if !(cell.is_finite() && cell > 0.0 && (1.0 / cell).is_finite()) {
            cell = 1.0;
        }
        let depth_limit = (0..TREE_DEPTH)
            .take_while(|&d| cell / (2u64 << d) as f64 >= smallest)
            .count() as u32;
        GridFrame {
            scale,
            origin: lo,
            cell,
            depth_limit,
        }
    }

    /// Integer cell coordinates of a point (monotone in each coordinate).
    fn cell_of(&self, p: DVec3) -> [i64; 3] {
        self.fine_cell(p, 0)
    }

    /// Integer coordinates of a point in the cells of level `depth` of the [`CellTrees`]
    /// (`cell / 2^depth`; level 0 is the grid's): monotone in each coordinate, and a point in
    /// cell `k` of level `d` is in cell `2k` or `2k + 1` of level `d + 1`, per axis (the scaled
    /// coordinate is multiplied by a power of two, exactly, before rounding down).
    fn fine_cell(&self, p: DVec3, depth: u32) -> [i64; 3] {
        let q = (p * self.scale - self.origin) / self.cell * (1u64 << depth) as f64;
        [floor_to_i64(q.x), floor_to_i64(q.y), floor_to_i64(q.z)]
    }

    /// Which child of its node of level `depth - 1` holds a point (see [`TreeNode`]): the
    /// parities of its cell coordinates at level `depth`.
    fn child_of(&self, p: DVec3, depth: u32) -> usize {
        let c = self.fine_cell(p, depth);
        (0..3).map(|axis| ((c[axis] & 1) as usize) << axis).sum()
    }

    /// How many pieces edge `(a, b)` is cut into at level 0 (each at most a cell long, unless
    /// the edge is longer than 10^7 cells).
    fn pieces(&self, (a, b): (DVec3, DVec3)) -> u64 {
        let length = (b - a).length() * self.scale;
        (length / self.cell).ceil().clamp(1.0, 1e7) as u64
    }
}

/// `x.floor() as i64` (saturating, and 0 for NaN), without calling `floor`: the conversion
/// truncates, and a negative non-integer is one above its floor.
fn floor_to_i64(x: f64) -> i64 {
    let t = x as i64;
    if t as f64 > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// The point at `k / n` along edge `(a, b)`: where piece `k` of `n` equal pieces starts. Piece
/// `k` of `n` is the union of pieces `2k` and `2k + 1` of `2n`, and shares its ends with them
/// bit for bit (the same fractions, correctly rounded).
fn piece_end((a, b): (DVec3, DVec3), k: u64, n: u64) -> DVec3 {
    a.lerp(b, k as f64 / n as f64)
}

/// The bounding box of piece `k` of `n` equal pieces of edge `(a, b)`, grown by `grow`.
fn piece_box(segment: (DVec3, DVec3), k: u64, n: u64, grow: DVec3) -> (DVec3, DVec3) {
    let (p0, p1) = (piece_end(segment, k, n), piece_end(segment, k + 1, n));
    (p0.min(p1) - grow, p0.max(p1) + grow)
}

/// The growth of the pieces' boxes of edge `(a, b)`: twice its tolerance, which covers every
/// accepted point plus any rounding of the pieces.
fn piece_growth((a, b): (DVec3, DVec3)) -> DVec3 {
    DVec3::splat(2.0 * edge_tolerance(a, b))
}

impl EdgeGrid {
    /// Builds the hash (two passes over the edges: count, then fill), then the trees of its
    /// crowded cells where the `points` to be looked up fall (the trees' shape depends on them,
    /// what [`EdgeGrid::edges_containing`] returns does not).
    fn new(mesh: &Mesh3, edges: &[Edge], points: &[DVec3]) -> EdgeGrid {
        let buckets = edges.len().max(64).next_power_of_two();
        let mut grid = EdgeGrid {
            frame: GridFrame::new(mesh, edges),
            mask: buckets - 1,
            starts: Vec::new(),
            items: Vec::new(),
            trees: CellTrees::default(),
        };
        let segment = |e: &Edge| (mesh.positions[e.lo as usize], mesh.positions[e.hi as usize]);
        let mut counts = vec![0usize; buckets + 1];
        for e in edges {
            grid.for_each_bucket(segment(e), |k| counts[k + 1] += 1);
        }
        for i in 1..counts.len() {
            counts[i] += counts[i - 1];
        }
        let mut next = counts.clone();
        let mut items = vec![0u32; counts[buckets]];
        for (i, e) in edges.iter().enumerate() {
            grid.for_each_bucket(segment(e), |k| {
                items[next[k]] = i as u32;
                next[k] += 1;
            });
        }
        grid.starts = counts;
        grid.items = items;
        grid.trees = CellTrees::new(&grid, mesh, edges, points);
        grid
    }

    /// The bucket of a cell: the cells of a block of 16 x 16 x 16 get consecutive buckets (its
    /// low 12 bits), and blocks a well-mixed hash of their coordinates (the others), so that
    /// nearby pieces and points (edges and vertices come in file order, mostly near the previous
    /// ones) count and look up nearby buckets, which stay in cache.
    fn bucket(&self, c: [i64; 3]) -> usize {
        let low = (c[0] & 15) | (c[1] & 15) << 4 | (c[2] & 15) << 8;
        let block = c.map(|x| (x >> 4) as u64);
        let h = block[0].wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ block[1].wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
            ^ block[2].wrapping_mul(0x1656_67B1_9E37_79F9);
        let h = (h ^ (h >> 31)).wrapping_mul(0xD6E8_FEB8_6659_FD93);
        ((h ^ (h >> 32)) << 12 ^ low as u64) as usize & self.mask
    }

    /// The edges registered in the bucket of a cell (an edge may come more than once).
    fn bucket_items(&self, c: [i64; 3]) -> &[u32] {
        let k = self.bucket(c);
        &self.items[self.starts[k]..self.starts[k + 1]]
    }

    /// Calls `f` with the bucket of every cell overlapped by the grown pieces of edge `(a, b)`
    /// (a bucket may come more than once). Edges that cannot contain points are skipped.
    fn for_each_bucket(&self, segment: (DVec3, DVec3), mut f: impl FnMut(usize)) {
        self.for_each_cell(segment, |_, c| f(self.bucket(c)));
    }

    /// Calls `f(k, c)` for every piece `k` of edge `(a, b)` (of [`GridFrame::pieces`]) and every
    /// cell `c` its grown box overlaps. Edges that cannot contain points are skipped.
    fn for_each_cell(&self, segment: (DVec3, DVec3), mut f: impl FnMut(u64, [i64; 3])) {
        if !can_contain_points(segment) {
            return;
        }
        let grow = piece_growth(segment);
        let pieces = self.frame.pieces(segment);
        for k in 0..pieces {
            let (lo, hi) = piece_box(segment, k, pieces, grow);
            let (lo, hi) = (self.frame.cell_of(lo), self.frame.cell_of(hi));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        f(k, [x, y, z]);
                    }
                }
            }
        }
    }

    /// The input edges that may contain `p` (with repeats): those of its leaf where its cell is
    /// refined, else those of its cell's bucket. Every edge that contains `p` within its
    /// tolerance is among them.
    fn candidates(&self, p: DVec3) -> &[u32] {
        let c = self.frame.cell_of(p);
        let bucket = self.bucket_items(c);
        if bucket.len() > CROWDED {
            if let Some(leaf) = self.trees.leaf(&self.frame, c, p) {
                return leaf;
            }
        }
        bucket
    }

    /// Fills `out` with the (sorted, unique) input edges that contain `p` and are nearest to it:
    /// of the edges within the on-edge tolerance, those within [`NEAREST_EDGE_SLACK`] of the
    /// smallest distance. A point computed on one edge is within roundoff of it; where another
    /// edge passes within the tolerance (near a shared vertex, or an edge nearly along it), that
    /// edge and its regions are not the point's: taking them as well let faces of one region be
    /// assigned to a nearly coplanar neighbour, and areas seem to move between them.
    fn edges_containing(&self, mesh: &Mesh3, edges: &[Edge], p: DVec3, out: &mut Vec<u32>) {
        nearest_edges_containing(mesh, edges, self.candidates(p), p, out);
    }
}

/// Of the `candidates` (input edges, repeats allowed), the ones that contain `p` and are nearest
/// to it, sorted and unique, into `out` (see [`EdgeGrid::edges_containing`]). The answer is the
/// same for every set of candidates that includes all the edges containing `p`.
fn nearest_edges_containing(mesh: &Mesh3, edges: &[Edge], candidates: &[u32], p: DVec3, out: &mut Vec<u32>) {
    out.clear();
    let distance = |e: u32| {
        let edge = &edges[e as usize];
        let (a, b) = (mesh.positions[edge.lo as usize], mesh.positions[edge.hi as usize]);
        let slack = NEAREST_EDGE_SLACK * a.abs().max_element().max(b.abs().max_element());
        distance_on_edge(p, a, b).map(|d| (d, slack))
    };
    // The edges containing `p` and the nearest distance, then of those edges the ones near
    // it: the second pass computes again only the few distances of the edges found, and
    // nothing is allocated per point.
    let mut nearest = f64::INFINITY;
    for &e in candidates {
        if let Some((d, _)) = distance(e) {
            nearest = nearest.min(d);
            out.push(e);
        }
    }
    out.retain(|&e| distance(e).is_some_and(|(d, slack)| d <= nearest + slack));
    out.sort_unstable();
    out.dedup();
}

/// A bucket of an [`EdgeGrid`] with more entries than this is crowded: its cells where output
/// points fall get a [`CellTrees`] octree.
const CROWDED: usize = 64;

/// A tree node with at most this many edges stays a leaf.
const LEAF_EDGES: usize = 32;

/// A tree node with at most this many points to look up stays a leaf: testing them against all
/// its edges costs less than dividing it.
const LEAF_POINTS: usize = 8;

/// The deepest level of a [`CellTrees`] octree (cells of `cell / 2^29`). Pieces of level `d`
/// number at most `10^7 * 2^d < 2^53` per edge, so their indices and fractions stay exact.
const TREE_DEPTH: u32 = 29;

/// Roots are cells less than this many cells from the grid's origin: the coordinates of their
/// points at the deepest level, below `(2^33 + 1) * 2^29`, stay exact in `f64` and within
/// `i64`, so that a point's cell at each level is one of the two halves, per axis, of its cell
/// at the level above.
const ROOT_RANGE: u64 = 1 << 33;

/// The spans of pieces that dividing tree nodes makes are at most this many per entry of the grid
/// and point looked up: the bound of the trees' memory.
const TREE_BUDGET: usize = 8;

/// Octrees refining crowded cells of an [`EdgeGrid`]. A cell whose bucket holds more than
/// [`CROWDED`] entries and where more than [`LEAF_POINTS`] of the points to be looked up fall
/// becomes a root, holding the level-0 pieces of the edges whose grown boxes overlap it. A node
/// is divided into its eight half-size children while it holds more than [`LEAF_EDGES`] edges
/// and more than [`LEAF_POINTS`] points, above the frame's `depth_limit`: every piece longer
/// than the children is cut in two halves (the pieces of the next level; pieces of level 0 are
/// at most a cell long, unless the edge is longer than 10^7 cells), and each piece goes to every
/// child that its box, grown by twice the edge's tolerance as in the grid, overlaps in the cells
/// of the next level. A node keeps the pieces of one edge as one [`Span`], from the first to the
/// last that overlap it (the ones between, if any do not, are kept too): a few pieces, since
/// they are not much shorter than the node unless the edge is. Only the children where points
/// fall are built: a point in another child, like a point in a cell that is not a root, is
/// tested against its cell's bucket. The trees' shape depends on the points; the edges found
/// never do.
///
/// Conservative like the grid: an edge containing a point within its tolerance has, at every
/// level, a piece whose grown box contains the point (the pieces of a level cover the edge, and
/// the box is grown by twice the tolerance); cell coordinates are monotone, so at every depth the
/// point's cell is within the range of cells of such a box. The root holds such a piece of level
/// 0, as the grid does; if a node holds such a piece, the piece itself, or the one of its halves
/// that contains the point, goes to the point's child. By induction, the point's leaf holds the
/// edge.
///
/// Memory, linear in the grid's entries `G` and the points `P`: the roots hold at most one span
/// per entry of the grid, and nodes are divided only while the spans made by dividing stay
/// within `TREE_BUDGET * (G + P)` (dividing a node of `m` spans makes at most `8 m`, one per
/// edge and child), so at most `(1 + TREE_BUDGET) * (G + P)` spans are ever made; the leaves
/// keep one edge per span; a division makes eight nodes and needs more than [`LEAF_EDGES`]
/// spans. While the trees are built, each point is in one node waiting to be built.
#[derive(Default)]
struct CellTrees {
    /// The root node of each refined cell.
    roots: FastMap<[i64; 3], usize>,
    nodes: Vec<TreeNode>,
    /// The edges of the leaves (unique per leaf).
    edges: Vec<u32>,
    /// How many pieces the divisions placed in children (a measure of the work, for the tests).
    #[cfg(test)]
    pieces_placed: usize,
}

/// A node of [`CellTrees`]: a leaf (`children == 0`) with edges `edges[start..end]`, or an inner
/// node whose children are `children + i`, where bits 0, 1, 2 of `i` say whether the child is
/// the upper half in x, y, z.
#[derive(Clone, Copy)]
struct TreeNode {
    children: usize,
    start: usize,
    end: usize,
}

impl TreeNode {
    /// A leaf where no point fell when the trees were built: it keeps no edges, and a point
    /// there is tested against its cell's bucket.
    const UNREFINED: TreeNode = TreeNode {
        children: 0,
        start: usize::MAX,
        end: usize::MAX,
    };
}

/// Pieces `first..=last` of an input edge, of its `pieces << level` equal pieces (see
/// [`GridFrame::pieces`]).
#[derive(Clone, Copy)]
struct Span {
    edge: u32,
    level: u32,
    first: u64,
    last: u64,
}

/// A tree node waiting to be built: its index, level, cell coordinates at that level, spans
/// (one per edge) and points.
struct Pending {
    node: usize,
    depth: u32,
    cell: [i64; 3],
    spans: Vec<Span>,
    points: Vec<DVec3>,
}

impl Pending {
    /// A node with nothing in it yet.
    fn new(node: usize, depth: u32, cell: [i64; 3]) -> Pending {
        Pending {
            node,
            depth,
            cell,
            spans: Vec::new(),
            points: Vec::new(),
        }
    }

    /// Adds piece `index` of level `level` of `edge`: to the last span if it is the edge's
    /// (pieces of an edge come together, of one level, in increasing order), else as a new span.
    fn add(&mut self, edge: u32, level: u32, index: u64) {
        match self.spans.last_mut() {
            Some(span) if span.edge == edge => span.last = span.last.max(index),
            _ => self.spans.push(Span {
                edge,
                level,
                first: index,
                last: index,
            }),
        }
    }
}

impl CellTrees {
    /// The trees of the crowded cells of `grid` where more than [`LEAF_POINTS`] of `points` fall.
    fn new(grid: &EdgeGrid, mesh: &Mesh3, edges: &[Edge], points: &[DVec3]) -> CellTrees {
        let mut trees = CellTrees::default();
        let mut work = Self::roots(grid, points);
        if work.is_empty() {
            return trees;
        }
        for (i, root) in work.iter_mut().enumerate() {
            root.node = i;
            trees.roots.insert(root.cell, i);
        }
        trees.nodes = vec![TreeNode::UNREFINED; work.len()];
        let segment = |e: u32| {
            let e = &edges[e as usize];
            (mesh.positions[e.lo as usize], mesh.positions[e.hi as usize])
        };
        // Only the edges of the roots' buckets can overlap a root (the grid registered every
        // edge in the bucket of every cell it overlaps): they are walked, in increasing order
        // as all edges were, instead of every edge of the mesh.
        let mut near: Vec<u32> = work
            .iter()
            .flat_map(|root| grid.bucket_items(root.cell))
            .copied()
            .collect();
        near.sort_unstable();
        near.dedup();
        for e in near {
            grid.for_each_cell(segment(e), |index, c| {
                if grid.bucket_items(c).len() > CROWDED {
                    if let Some(&root) = trees.roots.get(&c) {
                        work[root].add(e, 0, index);
                    }
                }
            });
        }
        let budget = TREE_BUDGET * (grid.items.len() + points.len());
        let mut made = 0;
        let mut queue: std::collections::VecDeque<Pending> = work.into();
        while let Some(node) = queue.pop_front() {
            let divide = node.spans.len() > LEAF_EDGES
                && node.points.len() > LEAF_POINTS
                && node.depth < grid.frame.depth_limit
                && made + 8 * node.spans.len() <= budget;
            if divide {
                let children = trees.divide(&grid.frame, node, segment);
                made += children.iter().map(|c| c.spans.len()).sum::<usize>();
                queue.extend(children);
            } else {
                trees.make_leaf(node);
            }
        }
        trees
    }

    /// The crowded cells of `grid` where more than [`LEAF_POINTS`] of `points` fall (within
    /// [`ROOT_RANGE`]), with their points, in the order of their first point.
    fn roots(grid: &EdgeGrid, points: &[DVec3]) -> Vec<Pending> {
        let mut index: FastMap<[i64; 3], usize> = FastMap::default();
        let mut roots: Vec<Pending> = Vec::new();
        for &p in points {
            let c = grid.frame.cell_of(p);
            if c.iter().any(|x| x.unsigned_abs() >= ROOT_RANGE) || grid.bucket_items(c).len() <= CROWDED {
                continue;
            }
            let i = *index.entry(c).or_insert_with(|| {
                roots.push(Pending::new(0, 0, c));
                roots.len() - 1
            });
            roots[i].points.push(p);
        }
        roots.retain(|r| r.points.len() > LEAF_POINTS);
        roots
    }

    /// Makes `node` a leaf holding the edges of its spans.
    fn make_leaf(&mut self, node: Pending) {
        let start = self.edges.len();
        self.edges.extend(node.spans.iter().map(|s| s.edge));
        self.nodes[node.node] = TreeNode {
            children: 0,
            start,
            end: self.edges.len(),
        };
    }

    /// Divides `node` into its eight children and returns those where points fall, to be built;
    /// the others are left unrefined.
    fn divide(&mut self, frame: &GridFrame, node: Pending, segment: impl Fn(u32) -> (DVec3, DVec3)) -> Vec<Pending> {
        let first = self.nodes.len();
        self.nodes.resize(first + 8, TreeNode::UNREFINED);
        self.nodes[node.node].children = first;
        let depth = node.depth + 1;
        let base = node.cell.map(|x| 2 * x);
        let mut children: Vec<Pending> = (0..8)
            .map(|i| {
                Pending::new(
                    first + i,
                    depth,
                    [0, 1, 2].map(|axis| base[axis] + ((i >> axis) & 1) as i64),
                )
            })
            .collect();
        for p in node.points {
            children[frame.child_of(p, depth)].points.push(p);
        }
        let size = frame.cell / (1u64 << depth) as f64;
        for span in node.spans {
            let segment = segment(span.edge);
            let pieces = frame.pieces(segment);
            // Pieces longer than the children are cut in halves, the pieces of the next level;
            // shorter ones are kept whole.
            let length = (segment.1 - segment.0).length() * frame.scale / (pieces << span.level) as f64;
            let (level, first, last) = if length > size {
                (span.level + 1, 2 * span.first, 2 * span.last + 1)
            } else {
                (span.level, span.first, span.last)
            };
            let (grow, n) = (piece_growth(segment), pieces << level);
            #[cfg(test)]
            {
                self.pieces_placed += (last - first + 1) as usize;
            }
            // The cells of a piece's grown box (`piece_box`) reach from the lower to the upper of
            // its ends' grown cells, per axis (cells are monotone, and so is rounding): each end
            // is computed once for the two pieces it bounds.
            let end = |k: u64| {
                let p = piece_end(segment, k, n);
                (frame.fine_cell(p - grow, depth), frame.fine_cell(p + grow, depth))
            };
            let mut start = end(first);
            for index in first..=last {
                let stop = end(index + 1);
                let lo = [0, 1, 2].map(|axis| start.0[axis].min(stop.0[axis]));
                let hi = [0, 1, 2].map(|axis| start.1[axis].max(stop.1[axis]));
                start = stop;
                let range = |axis: usize| {
                    lo[axis].saturating_sub(base[axis]).max(0)..=hi[axis].saturating_sub(base[axis]).min(1)
                };
                for x in range(0) {
                    for y in range(1) {
                        for z in range(2) {
                            let child = &mut children[(x | y << 1 | z << 2) as usize];
                            if !child.points.is_empty() {
                                child.add(span.edge, level, index);
                            }
                        }
                    }
                }
            }
        }
        children.retain(|c| !c.points.is_empty());
        children
    }

    /// The edges of the leaf holding `p`, in cell `c` of the grid, if that cell is refined.
    fn leaf(&self, frame: &GridFrame, c: [i64; 3], p: DVec3) -> Option<&[u32]> {
        let mut node = self.nodes[*self.roots.get(&c)?];
        let mut depth = 0;
        while node.children != 0 {
            depth += 1;
            node = self.nodes[node.children + frame.child_of(p, depth)];
        }
        self.edges.get(node.start..node.end)
    }
}

/// Whether [`on_edge`] can accept any point on segment `(a, b)`: its squared length must be
/// positive and finite (an overflowing length makes the test refuse everything). Other edges
/// are left out of the grid, which keeps its geometry finite.
fn can_contain_points((a, b): (DVec3, DVec3)) -> bool {
    let len2 = (b - a).length_squared();
    len2 > 0.0 && len2.is_finite()
}

// ---------------------------------------------------------------------------------------------
// Output faces and areas
// ---------------------------------------------------------------------------------------------

/// The output area assigned to every region, and the groups of regions an output face could be
/// assigned to equally.
struct Assignment {
    area: Vec<f64>,
    groups: UnionFind,
}

/// Checks rule 3 and returns the output area assigned to every region.
///
/// A face goes to one of the regions shared by its three vertices: preferably one in which it is
/// exactly well oriented, then the one its normal agrees with best. It must be well oriented in
/// that region, exactly ([`Regions::side`]): a reversed (folded) face, or one whose projection on
/// the region's plane is degenerate, is a failure. When the face is well oriented in several of
/// the shared regions (coplanar regions that overlap, possible in a self-intersecting input), it
/// cannot be told from geometry which one it belongs to: those regions form one group, whose
/// total area is checked ([`check_areas`]).
///
/// A face with a vertex that is neither an input vertex nor on an input edge (reported by
/// [`classify_output_vertices`]) goes to the regions of its other vertices whose planes hold that
/// vertex too, and proves no overlap (it joins no group). In the plane of none of them, it lies on
/// no input face: a failure, its area in no region. A face with no such other vertex is left to
/// its vertices' failures.
fn assign_faces(model: &InputModel, output_names: &Names, candidates: &Candidates, fail: &mut Failures) -> Assignment {
    let (regions, output) = (&model.regions, output_names.mesh);
    let mut assigned = vec![CompensatedSum::default(); regions.area.len()];
    let mut groups = UnionFind::new(regions.area.len());
    let mut common = Vec::new();
    let mut scored: Vec<(i8, f64, usize)> = Vec::new();
    for (f, t) in output.triangles.iter().enumerate() {
        if is_degenerate(t) {
            continue;
        }
        // (In a small array, not a vector: nothing is allocated per face.)
        let mut known = [0u32; 3];
        let mut count = 0;
        for &v in t.iter().filter(|&&v| candidates.known[v as usize]) {
            known[count] = v;
            count += 1;
        }
        let known = &mut known[..count];
        let all_known = count == 3;
        // The common regions are found by walking the shortest list (sorted: the same result
        // from any of them): a vertex of high valence can have thousands.
        known.sort_by_key(|&v| candidates.regions.row(v as usize).len());
        let Some((&first, rest)) = known.split_first() else {
            continue; // all three vertices already reported
        };
        common.clear();
        common.extend(candidates.regions.row(first as usize).iter().copied().filter(|r| {
            rest.iter()
                .all(|&v| candidates.regions.row(v as usize).binary_search(r).is_ok())
        }));
        let triangle = corners(output, t);
        let normal = triangle_normal(triangle);
        if !all_known {
            // Only the regions whose planes hold the face's vertices off the input's edges.
            let off = || t.iter().filter(|&&v| !candidates.known[v as usize]);
            common.retain(|&r| off().all(|&v| regions.holds(r as usize, output.positions[v as usize])));
            if common.is_empty() {
                fail.push(KIND_FACE, || {
                    known.sort_unstable();
                    let at: Vec<String> = known.iter().map(|&v| output_names.label(v)).collect();
                    let off: Vec<String> = off().map(|&v| output_names.label(v)).collect();
                    let verb = if off.len() == 1 { "is" } else { "are" };
                    format!(
                        "output {} lies on no input face: {}, off the input's edges, {verb} in the plane \
                         of none of the input faces at {}",
                        output_names.face(f),
                        off.join(" and "),
                        at.join(" and ")
                    )
                });
                continue;
            }
        }
        scored.clear();
        scored.extend(common.iter().map(|&r| {
            let r = r as usize;
            (regions.side(r, triangle), regions.normal[r].dot(normal), r)
        }));
        let best = scored
            .iter()
            .copied()
            .max_by(|x, y| x.0.cmp(&y.0).then(x.1.total_cmp(&y.1)));
        let Some((side, _, r)) = best else {
            fail.push(KIND_FACE, || {
                format!(
                    "output {} does not lie inside one planar region of the input \
                     (its vertices share no region)",
                    output_names.face(f)
                )
            });
            continue;
        };
        assigned[r].add(0.5 * normal.length());
        if side > 0 {
            for &(other_side, _, other) in &scored {
                // (A face with a vertex off the input's edges proves no overlap.)
                if other_side > 0 && other != r && all_known {
                    groups.union(r as u32, other as u32);
                }
            }
        } else {
            fail.push(KIND_FACE, || {
                let what = if exactly_degenerate(triangle) {
                    "has zero area (its corners are collinear) in"
                } else if side == 0 {
                    "has zero area in the projection on the plane of"
                } else {
                    "is reversed relative to"
                };
                let dot = regions.normal[r].dot(normal.normalize_or_zero());
                format!(
                    "output {} {what} {} (unit normal . region normal = {dot:.3e})",
                    output_names.face(f),
                    regions.name(r, &model.names)
                )
            });
        }
    }
    Assignment {
        area: assigned.iter().map(CompensatedSum::value).collect(),
        groups,
    }
}

/// How much the rounding of the added vertices may change the area of every region: the input
/// edges on the region's border (a boundary edge, or an edge to another region) that carry
/// added vertices, each allowing [`AREA_ROUNDING`] units of roundoff of its largest coordinate
/// across its length. (Vertices on an edge inside a region only move area between its faces.)
fn rounding_allowance(model: &InputModel, edge_has_added: &[bool]) -> Vec<f64> {
    let regions = &model.regions;
    let p = |v: u32| model.mesh.positions[v as usize];
    let mut rounding = vec![0.0; regions.area.len()];
    let edges = &model.prepared.edges;
    for e in (0..edges.len()).filter(|&e| edge_has_added[e]).map(|e| &edges[e]) {
        let faces = &e.faces[..e.count.min(2) as usize];
        let region = |f: u32| regions.of_face[f as usize] as usize;
        if e.is_interior() && region(faces[0]) == region(faces[1]) {
            continue;
        }
        let (a, b) = (p(e.lo), p(e.hi));
        let coordinate = a.abs().max_element().max(b.abs().max_element());
        let allowance = AREA_ROUNDING * f64::EPSILON * coordinate * (b - a).length();
        if allowance.is_finite() {
            for &f in faces {
                rounding[region(f)] += allowance;
            }
        }
    }
    rounding
}

/// Checks rule 4: every region keeps its area; regions grouped by [`assign_faces`] keep their
/// total area. `rounding_of` is [`rounding_allowance`].
fn check_areas(model: &InputModel, assignment: &mut Assignment, rounding_of: &[f64], fail: &mut Failures) {
    let regions = &model.regions;
    let n = regions.area.len();
    let mut before = vec![CompensatedSum::default(); n];
    let mut after = vec![CompensatedSum::default(); n];
    let mut rounding = vec![0.0; n];
    let roots: Vec<usize> = (0..n).map(|r| assignment.groups.find(r as u32) as usize).collect();
    for (r, &allowance) in rounding_of.iter().enumerate() {
        let root = roots[r];
        before[root].add(regions.area[r]);
        after[root].add(assignment.area[r]);
        rounding[root] += allowance;
    }
    // The regions of every group, in increasing order (a counting sort by root: no vector per
    // region, of which a curved input has about one per face).
    let (start, by_root) = grouped(n, || roots.iter().enumerate().map(|(r, &root)| (root, r)));
    let members = |root: usize| &by_root[start[root]..start[root + 1]];
    for root in (0..n).filter(|&r| !members(r).is_empty()) {
        let (before, after) = (before[root].value(), after[root].value());
        let tolerance = AREA_TOLERANCE * before + AREA_FLOOR + rounding[root];
        let kept = (after - before).abs() <= tolerance; // false for NaN too
        if !kept {
            fail.push(KIND_AREA, || match members(root) {
                [r] => format!("{} area {before} became {after}", regions.name(*r, &model.names)),
                group => {
                    let names: Vec<String> = group.iter().take(6).map(|&r| regions.name(r, &model.names)).collect();
                    let more = if group.len() > 6 { ", ..." } else { "" };
                    format!(
                        "the {} overlapping coplanar regions {}{more} (whose faces cannot be told \
                         apart) have total area {before}, which became {after}",
                        group.len(),
                        names.join(", ")
                    )
                }
            });
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Delaunay
// ---------------------------------------------------------------------------------------------

/// Result of the Delaunay check.
struct DelaunayStats {
    interior: usize,
    max_excess: f64,
    /// The non-Delaunay edges `(excess, lo, hi)`, worst first.
    bad: Vec<(f64, u32, u32)>,
}

impl DelaunayStats {
    /// Records the non-Delaunay edges as failures, worst first, named by `output`.
    fn report(&self, output: &Names, fail: &mut Failures) {
        for &(x, lo, hi) in &self.bad {
            fail.push(KIND_DELAUNAY, || {
                format!(
                    "non-Delaunay edge ({}, {}): alpha+beta-pi = {x:.3e} rad",
                    output.label(lo),
                    output.label(hi)
                )
            });
        }
    }
}

/// The angle between two vectors, in `[0, pi]`. Each vector is first scaled by a power of two
/// that brings its largest coordinate to about `[1, 2)` ([`power_of_two_scaled`]): the directions are
/// unchanged, exactly, and for vectors of ordinary length so is every rounding (the result is
/// what the unscaled formula gives), but the products no longer underflow at needles: a right
/// angle at a face 1e-323 wide, whose unscaled cross product has length 0 and dot product -0,
/// was taken for pi.
fn angle(u: DVec3, v: DVec3) -> f64 {
    let (u, v) = (power_of_two_scaled(u), power_of_two_scaled(v));
    u.cross(v).length().atan2(u.dot(v))
}

/// `v` times the power of two that brings its largest coordinate magnitude to about `[1, 2)`
/// (exact: only exponents change); `v` itself when it is zero or not finite.
fn power_of_two_scaled(v: DVec3) -> DVec3 {
    let largest = v.abs().max_element();
    if largest == 0.0 || !largest.is_finite() {
        return v;
    }
    // As in `rescaled`: 2^k in two factors, each a normal number.
    let k = -(largest.log2().floor() as i32); // within -1023 ..= 1074
    v * 2f64.powi(k / 2) * 2f64.powi(k - k / 2)
}

/// `alpha + beta - pi` of interior edge `(a, b)` with faces `(a, b, c)` and `(b, a, d)`.
fn excess(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    angle(a - c, b - c) + angle(a - d, b - d) - PI
}

/// Rule 6 on every interior output edge (see [`DelaunayStats::report`]).
///
/// [`excess`] (two `atan2`) is computed only for the edges that [`ExcessBound`] cannot place
/// below the largest excess found so far: the others change neither the maximum nor the list
/// of non-Delaunay edges, so the result is the same as computing every edge's.
fn delaunay_edges(output: &Mesh3, edges: &[Edge]) -> DelaunayStats {
    let p = |v: u32| output.positions[v as usize];
    let mut stats = DelaunayStats {
        interior: 0,
        max_excess: f64::NEG_INFINITY,
        bad: Vec::new(),
    };
    let mut bound = ExcessBound::below(stats.max_excess);
    for e in edges.iter().filter(|e| e.is_interior()) {
        let (a, b, f, g) = e.oriented();
        let c = third(&output.triangles[f as usize], a, b);
        let d = third(&output.triangles[g as usize], a, b);
        stats.interior += 1;
        let quad = [p(a), p(b), p(c), p(d)];
        if bound.holds(quad) {
            continue;
        }
        let [a, b, c, d] = quad;
        let x = excess(a, b, c, d);
        if x > stats.max_excess {
            bound = ExcessBound::below(x);
        }
        stats.max_excess = stats.max_excess.max(x);
        let delaunay = x <= DELAUNAY_TOLERANCE; // false for NaN too
        if !delaunay {
            stats.bad.push((x, e.lo, e.hi));
        }
    }
    stats.bad.sort_by(|x, y| y.0.total_cmp(&x.0));
    stats
}

/// A cheap test, without `atan2`, that an interior edge's [`excess`] is certainly below a
/// threshold `t` (the largest excess found so far) and not above [`DELAUNAY_TOLERANCE`]: that
/// `alpha + beta <= pi - m` with `m = max(-t, 0) + 1e-12`, where `excess` is within `1e-14` of
/// the exact `alpha + beta - pi` of its (rounded) edge vectors.
///
/// With `C = |u x v|` and `D = u . v` for the two vectors `u, v` of a face from its third
/// corner, `D + iC` is `|u| |v| e^(i alpha)`, so the product `R + iS` of the two faces' is
/// `|u1| |v1| |u2| |v2| e^(i (alpha + beta))`. For `alpha + beta` in `[0, 2 pi]`, `S > 0` puts it
/// in `(0, pi)`, and then `alpha + beta <= pi - m` iff `S + R tan(m) >= 0`. Both are required to
/// exceed their rounding error with a wide margin: `C` and `D` are within about 8 units of
/// roundoff of `|u| |v| <= |C| + |D|`, so `R` and `S` within 40 units of the product of those
/// sums, and the margin is 10^-12 of it (4,500 units). Vectors whose largest coordinate is 0 or
/// outside `[2^-200, 2^200]` (where products could underflow or overflow) are left to `excess`.
#[derive(Clone, Copy)]
struct ExcessBound {
    /// `tan(m)`, or `None` when no edge is to be skipped (no threshold yet, or one so low that
    /// `m` nears `pi / 2`).
    tan_margin: Option<f64>,
}

impl ExcessBound {
    /// The bound for threshold `t` (`f64::NEG_INFINITY`: none).
    fn below(t: f64) -> ExcessBound {
        let margin = t.min(0.0).abs() + 1e-12;
        ExcessBound {
            tan_margin: (margin < 1.4).then(|| margin.tan()),
        }
    }

    /// Whether the excess of the edge `(a, b)` with faces `(a, b, c)` and `(b, a, d)` is
    /// certainly below the threshold (`false` when unsure).
    fn holds(&self, [a, b, c, d]: [DVec3; 4]) -> bool {
        let Some(k) = self.tan_margin else {
            return false;
        };
        let (u1, v1, u2, v2) = (a - c, b - c, a - d, b - d);
        const LOW: f64 = 6.223015277861142e-61; // 2^-200
        const HIGH: f64 = 1.6069380442589903e60; // 2^200
        let plain = |w: DVec3| (LOW..=HIGH).contains(&w.abs().max_element());
        if !(plain(u1) && plain(v1) && plain(u2) && plain(v2)) {
            return false;
        }
        let (c1, d1) = (u1.cross(v1).length(), u1.dot(v1));
        let (c2, d2) = (u2.cross(v2).length(), u2.dot(v2));
        let (r, s) = (d1 * d2 - c1 * c2, c1 * d2 + d1 * c2);
        let error = 1e-12 * (c1 + d1.abs()) * (c2 + d2.abs());
        s > error && s + k * r > error * (1.0 + k)
    }
}

// ---------------------------------------------------------------------------------------------
// Small utilities
// ---------------------------------------------------------------------------------------------

const KIND_INDEX: &str = "invalid index or coordinate";
const KIND_DEGENERATE: &str = "degenerate face";
const KIND_MANIFOLD: &str = "non-manifold or misoriented feature";
const KIND_MISSING: &str = "missing input vertex";
const KIND_VERTEX: &str = "misplaced output vertex";
const KIND_FACE: &str = "face outside a planar region";
const KIND_AREA: &str = "region area change";
const KIND_TOPOLOGY: &str = "topology change";
const KIND_DELAUNAY: &str = "non-Delaunay edge";

/// Collects failure lines, keeping at most [`MAX_LINES_PER_KIND`] per kind.
#[derive(Default)]
struct Failures {
    lines: Vec<String>,
    /// Kinds in order of first appearance, with their total count.
    counts: Vec<(&'static str, usize)>,
}

impl Failures {
    /// Records one failure; the line is only formatted when it will be kept.
    fn push(&mut self, kind: &'static str, line: impl FnOnce() -> String) {
        let i = match self.counts.iter().position(|(k, _)| *k == kind) {
            Some(i) => i,
            None => {
                self.counts.push((kind, 0));
                self.counts.len() - 1
            }
        };
        self.counts[i].1 += 1;
        if self.counts[i].1 <= MAX_LINES_PER_KIND {
            self.lines.push(line());
        }
    }

    fn is_empty(&self) -> bool {
        self.counts.is_empty()
    }

    /// Number of failures recorded so far (kept or not).
    fn total(&self) -> usize {
        self.counts.iter().map(|(_, c)| c).sum()
    }

    /// The kept lines plus one `... and N more` line per overflowing kind.
    fn finish(mut self) -> Vec<String> {
        for (kind, count) in &self.counts {
            if *count > MAX_LINES_PER_KIND {
                let more = count - MAX_LINES_PER_KIND;
                self.lines.push(format!("... and {more} more {kind} failures"));
            }
        }
        self.lines
    }

    /// The first `n` lines joined, for an error message.
    fn summary(self, n: usize) -> String {
        let total = self.total();
        let lines = self.finish();
        let mut text = lines.iter().take(n).cloned().collect::<Vec<_>>().join("; ");
        if total > n {
            text.push_str(&format!(" (and {} more problems)", total - n));
        }
        text
    }
}

/// Counting sort of `(row, item)` pairs by row (stable): returns the start of every row (plus
/// the end) and the items. Every row must be `< rows`.
fn group_by_row<T: Copy + Default>(rows: usize, pairs: &[(u32, T)]) -> (Vec<usize>, Vec<T>) {
    let mut starts = vec![0usize; rows + 1];
    for &(r, _) in pairs {
        starts[r as usize + 1] += 1;
    }
    for i in 1..starts.len() {
        starts[i] += starts[i - 1];
    }
    let mut next = starts.clone();
    let mut items = vec![T::default(); pairs.len()];
    for &(r, x) in pairs {
        items[next[r as usize]] = x;
        next[r as usize] += 1;
    }
    (starts, items)
}

/// Rows of `u32` stored flat (compressed sparse rows).
struct Csr {
    starts: Vec<usize>,
    items: Vec<u32>,
}

impl Csr {
    /// Groups `(row, item)` pairs by row (counting sort; items keep their order).
    fn from_pairs(rows: usize, pairs: &[(u32, u32)]) -> Csr {
        let (starts, items) = group_by_row(rows, pairs);
        Csr { starts, items }
    }

    /// The same rows, each sorted and without duplicates.
    fn sorted_unique(mut self) -> Csr {
        let mut builder = CsrBuilder::default();
        for r in 0..self.starts.len() - 1 {
            let row = &mut self.items[self.starts[r]..self.starts[r + 1]];
            row.sort_unstable();
            let mut last = None;
            for &x in row.iter() {
                if last != Some(x) {
                    builder.items.push(x);
                    last = Some(x);
                }
            }
            builder.finish_row();
        }
        builder.build()
    }

    /// Row `r`.
    fn row(&self, r: usize) -> &[u32] {
        &self.items[self.starts[r]..self.starts[r + 1]]
    }
}

/// Builds a [`Csr`] row by row.
struct CsrBuilder {
    starts: Vec<usize>,
    items: Vec<u32>,
}

impl Default for CsrBuilder {
    fn default() -> Self {
        CsrBuilder {
            starts: vec![0],
            items: Vec::new(),
        }
    }
}

impl CsrBuilder {
    /// Appends items to the current row.
    fn extend(&mut self, items: &[u32]) {
        self.items.extend_from_slice(items);
    }

    /// Ends the current row.
    fn finish_row(&mut self) {
        self.starts.push(self.items.len());
    }

    fn build(self) -> Csr {
        Csr {
            starts: self.starts,
            items: self.items,
        }
    }
}

/// Disjoint sets over `0..n` with path halving and union by size.
struct UnionFind {
    parent: Vec<u32>,
    size: Vec<u32>,
}

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
            size: vec![1; n],
        }
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grandparent = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grandparent;
            x = grandparent;
        }
        x
    }

    fn union(&mut self, a: u32, b: u32) {
        let (mut a, mut b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        if self.size[a as usize] < self.size[b as usize] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b as usize] = a;
        self.size[a as usize] += self.size[b as usize];
    }
}

/// The welding key of a position: its bit patterns, -0 read as 0
/// ([`crate::hash::position_key`], as the readers weld).
fn bits(p: DVec3) -> [u64; 3] {
    crate::hash::position_key(p.to_array())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;

    /// `count_deviation` counts, at each place, how far a reading's vertices are from the count
    /// aimed at (one where `differ` says 0 or 1), copies that the reading added included.
    #[test]
    fn count_deviation_counts_vertices_against_the_aim_at_each_place() {
        let [a, b, c] = [DVec3::X, DVec3::Y, DVec3::Z];
        let welded = Mesh3 {
            positions: vec![a, b, c],
            triangles: vec![[0, 1, 2]],
        };
        // The input has two vertices at a, one at b; c is an added vertex's place.
        let differ = [2, 1, 0];
        let reading = |extra: &[DVec3]| Mesh3 {
            positions: [&welded.positions[..], extra].concat(),
            triangles: Vec::new(),
        };
        assert_eq!(count_deviation(&welded, &reading(&[a]), &differ), 0);
        assert_eq!(
            count_deviation(&welded, &reading(&[]), &differ),
            1,
            "one vertex short at a"
        );
        assert_eq!(
            count_deviation(&welded, &reading(&[a, b]), &differ),
            1,
            "one too many at b"
        );
        assert_eq!(count_deviation(&welded, &reading(&[a, a, b, c]), &differ), 3);
    }

    #[test]
    fn keeps_open_wants_the_input_s_cut_edges_open_where_the_reading_has_them() {
        // Two faces on either side of the edge a-b that `--repair` cut: the input has two
        // copies of b (1 and 3), and two boundary edges between a and b.
        let [a, b, c, d] = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::NEG_Y];
        let input = Mesh3 {
            positions: vec![a, b, c, b, d],
            triangles: vec![[0, 1, 2], [3, 0, 4]],
        };
        let places: FastMap<[u64; 3], i64> = [(bits(b), 2)].into_iter().collect();
        assert!(keeps_open(&input, &input, &places));
        // A reading that joined the copies of b closes the cut edge: one interior edge a-b.
        let joined = Mesh3 {
            positions: vec![a, b, c, d],
            triangles: vec![[0, 1, 2], [1, 0, 3]],
        };
        assert!(!keeps_open(&joined, &input, &places));
        // An output that split the edge a-b at its middle has no edge a-b to judge.
        let m = DVec3::new(0.5, 0.0, 0.0);
        let split = Mesh3 {
            positions: vec![a, b, c, b, d, m, m],
            triangles: vec![[0, 5, 2], [5, 1, 2], [3, 6, 4], [6, 0, 4]],
        };
        assert!(keeps_open(&split, &input, &places));
        // Where the input has no boundary edge at the places, any reading will do.
        assert!(keeps_open(&joined, &joined, &places));
    }

    #[test]
    fn normals_are_accurate_far_from_the_origin_and_for_needles() {
        // A right triangle of legs 3 and 4 (area 6), translated by exactly representable
        // offsets and written from each corner: the normal is always (0, 0, 12) exactly.
        for offset in [0.0, 4e9, 2f64.powi(50), -7.5e15] {
            let t = [
                DVec3::new(offset, offset, 1.0),
                DVec3::new(offset + 4.0, offset, 1.0),
                DVec3::new(offset, offset + 3.0, 1.0),
            ];
            for k in 0..3 {
                let rotated = [t[k], t[(k + 1) % 3], t[(k + 2) % 3]];
                assert_eq!(triangle_normal(rotated), DVec3::new(0.0, 0.0, 12.0), "{offset} {k}");
            }
        }
        // A needle of aspect ratio 1e20 whose plain cross product is exactly zero: the normal
        // points the right way with the right length (1e18 x 1/3 x 0.1 / 1e18 ~ 0.0333).
        let needle = [
            DVec3::new(5.534023222112866e18, 0.0, 0.0),
            DVec3::new(0.2, 1.0 / 3.0, 0.0),
            DVec3::new(0.1, 1.0 / 3.0, 0.0),
        ];
        let plain = (needle[1] - needle[0]).cross(needle[2] - needle[0]);
        assert_eq!(plain.z, 0.0, "the case must defeat the plain formula");
        for k in 0..3 {
            let rotated = [needle[k], needle[(k + 1) % 3], needle[(k + 2) % 3]];
            let n = triangle_normal(rotated);
            assert!((n.z - 0.1 / 3.0).abs() < 1e-17 && n.x == 0.0 && n.y == 0.0, "{n:?}");
            assert_eq!(projected_orientation(rotated, 2), 1);
            assert!(!exactly_degenerate(rotated));
        }
    }

    /// The axis-plane shortcut of `coplanar_and_flat` decides as the exact determinant does:
    /// random quads with one coordinate shared (0.0 and -0.0 mixed), some moved one ulp off.
    #[test]
    fn axis_plane_quads_are_judged_as_the_exact_determinant_says() {
        let mut rng = Rng(0xa715_91a9);
        let (mut flat, mut not_flat) = (0, 0);
        for case in 0..4000 {
            let axis = rng.below(3) as usize;
            let level = [0.0, 0.1, 3.0][rng.below(3) as usize];
            let mut p = [0; 4].map(|_| DVec3::new(rng.centered(), rng.centered(), rng.centered()));
            for q in &mut p {
                q[axis] = if level == 0.0 && rng.below(2) == 0 { -0.0 } else { level };
            }
            if case % 5 == 0 {
                p[3][axis] = p[3][axis].next_up();
            }
            let [a, b, c, d] = p;
            if exactly_degenerate([a, b, c]) || exactly_degenerate([b, a, d]) {
                continue;
            }
            let rows = [a, b, c, d].map(|v| [v.x, v.y, v.z, 1.0]);
            let coplanar = exact_determinant_sign(rows) == 0;
            let expected = coplanar && {
                let k = (0..3).find(|&k| projected_orientation([a, b, c], k) != 0).unwrap();
                projected_orientation([a, b, c], k) == -projected_orientation([a, b, d], k)
            };
            assert_eq!(coplanar_and_flat(a, b, c, d), expected, "case {case}: {p:?}");
            if expected {
                flat += 1;
            } else {
                not_flat += 1;
            }
        }
        assert!(flat > 1000 && not_flat > 1000, "{flat} flat, {not_flat} not");
    }

    /// `angle` scales its vectors exactly: at ordinary lengths it gives what the plain formula
    /// gives, bit for bit; at needles whose products underflow it still finds right angles.
    #[test]
    fn angles_do_not_underflow_at_needles() {
        let plain = |u: DVec3, v: DVec3| u.cross(v).length().atan2(u.dot(v));
        let mut rng = Rng(0x0a4c_1e55);
        for _ in 0..1000 {
            let u = DVec3::new(rng.centered(), rng.centered(), rng.centered()) * 1e3;
            let v = DVec3::new(rng.centered(), rng.centered(), rng.centered()) * 1e-3;
            assert_eq!(angle(u, v).to_bits(), plain(u, v).to_bits());
        }
        // The fuzz finding: the apex of a face 1.5e-323 wide sees its edge under a right angle.
        let (u, v) = (DVec3::new(-1.5e-323, 0.0, -0.0), DVec3::new(0.0, -1.0 / 3.0, 0.0));
        assert_eq!(plain(u, v), PI, "the case must defeat the plain formula");
        assert_eq!(angle(u, v), PI / 2.0);
        for k in [1e-300, 1e-200, 1e-160] {
            let (u, v) = (DVec3::new(k, k, 0.0), DVec3::new(-k, k, -0.0));
            assert!((angle(u, v) - PI / 2.0).abs() < 1e-15, "{k}");
        }
        assert_eq!(angle(DVec3::ZERO, DVec3::X), 0.0);
    }

    /// `ExcessBound` only skips edges whose excess is below its threshold and Delaunay:
    /// random quads near cocircular (excess near 0) and far from it, at scales from 1e-150
    /// to 1e150, some needles, against thresholds around each quad's own excess.
    #[test]
    fn excess_bound_skips_only_edges_below_the_threshold() {
        let mut rng = Rng(0x5eed_0d1e);
        let mut skipped = 0;
        for i in 0..20_000 {
            let scale = 10f64.powi(rng.int(150) as i32);
            let offset = DVec3::new(rng.centered(), rng.centered(), rng.centered()) * scale * rng.int(1e6 as u64);
            let on_circle = |t: f64, r: f64| DVec3::new(t.cos() * r, t.sin() * r, 0.0);
            let (ta, tb) = (rng.centered() * 6.0, rng.centered() * 6.0);
            let near = 10f64.powi(-(rng.below(17) as i32));
            let tilt = if i % 3 == 0 {
                rng.centered() * near
            } else {
                rng.centered()
            };
            let mut quad = [
                on_circle(ta, 1.0),
                on_circle(tb, 1.0),
                on_circle(rng.centered() * 6.0, 1.0 + rng.centered() * near),
                on_circle(rng.centered() * 6.0, 1.0 + rng.centered() * near) + DVec3::Z * tilt,
            ];
            if i % 7 == 0 {
                quad[2] = quad[0].lerp(quad[1], 0.5 + rng.centered()) + DVec3::Z * near * 1e-6;
            }
            let quad = quad.map(|p| p * scale + offset);
            let [a, b, c, d] = quad;
            let x = excess(a, b, c, d);
            for t in [
                f64::NEG_INFINITY,
                -1.5,
                -1.0,
                -1e-3,
                -1e-9,
                -1e-12,
                0.0,
                1e-12,
                1e-9,
                0.5,
                3.0,
            ]
            .into_iter()
            .chain([x, x - 1e-12, x + 1e-12, x - 1e-11, x - 1e-6, x + 1e-6])
            {
                if ExcessBound::below(t).holds(quad) {
                    skipped += 1;
                    assert!(x < t && x <= DELAUNAY_TOLERANCE, "{quad:?} {x} {t}");
                }
            }
        }
        assert!(skipped > 50_000, "{skipped}");
    }

    /// `delaunay_edges` finds what computing every edge's excess finds: on grids regular
    /// (cocircular quads, excess 0 up to rounding), jittered, and lifted into curved surfaces.
    #[test]
    fn delaunay_edges_agree_with_every_edge_computed() {
        let mut rng = Rng(0x00de_1a07);
        for (jitter, height) in [
            (0.0, 0.0),
            (1e-9, 0.0),
            (0.3, 0.0),
            (0.0, 0.2),
            (0.2, 1.0),
            (1e-3, 1e-3),
        ] {
            let n = 30;
            let mut mesh = Mesh3::default();
            for y in 0..=n {
                for x in 0..=n {
                    let j = DVec3::new(rng.centered(), rng.centered(), 0.0) * jitter;
                    let z = height * rng.centered();
                    mesh.positions.push(DVec3::new(x as f64, y as f64, z) + j);
                }
            }
            let v = |x: u32, y: u32| y * (n + 1) + x;
            for y in 0..n {
                for x in 0..n {
                    let (p, q, r, s) = (v(x, y), v(x + 1, y), v(x + 1, y + 1), v(x, y + 1));
                    if rng.below(2) == 0 {
                        mesh.triangles.extend([[p, q, r], [p, r, s]]);
                    } else {
                        mesh.triangles.extend([[p, q, s], [q, r, s]]);
                    }
                }
            }
            let naming = Naming::default();
            let names = Names::new("output", &mesh, &naming);
            let edges = build_edges(&names, &VertexFaces::new(&mesh), &mut Failures::default()).edges;
            let stats = delaunay_edges(&mesh, &edges);
            let p = |v: u32| mesh.positions[v as usize];
            let mut every: Vec<(f64, u32, u32)> = Vec::new();
            let mut max = f64::NEG_INFINITY;
            for e in edges.iter().filter(|e| e.is_interior()) {
                let (a, b, f, g) = e.oriented();
                let c = third(&mesh.triangles[f as usize], a, b);
                let d = third(&mesh.triangles[g as usize], a, b);
                let x = excess(p(a), p(b), p(c), p(d));
                max = max.max(x);
                every.push((x, e.lo, e.hi));
            }
            every.retain(|e| e.0 > DELAUNAY_TOLERANCE || e.0.is_nan());
            every.sort_by(|x, y| y.0.total_cmp(&x.0));
            assert_eq!(stats.interior, 3 * n as usize * n as usize - 2 * n as usize);
            assert_eq!(stats.max_excess.to_bits(), max.to_bits(), "{jitter} {height}");
            let bits = |list: &[(f64, u32, u32)]| list.iter().map(|e| (e.0.to_bits(), e.1, e.2)).collect::<Vec<_>>();
            assert_eq!(bits(&stats.bad), bits(&every), "{jitter} {height}");
        }
    }

    /// The pairwise rules for small fans answer as the sorting ones: random links and fans
    /// over a few vertices (repeats, paths, cycles, several pieces).
    #[test]
    fn small_fans_are_judged_as_by_sorting() {
        let mut rng = Rng(0x00fa_4a11);
        let mut heads = Vec::new();
        let (mut single, mut several, mut bad) = (0, 0, 0);
        for _ in 0..20_000 {
            let n = 1 + rng.below(SMALL_FAN as u64) as usize;
            let alphabet = 2 + rng.below(2 * n as u64);
            let mut link: Vec<(u32, u32)> = (0..n)
                .map(|_| (rng.below(alphabet) as u32, rng.below(alphabet) as u32))
                .filter(|e| e.0 != e.1)
                .collect();
            if rng.below(2) == 0 {
                // A path or cycle, cut or not, in random order.
                let cycle = rng.below(2) == 0;
                link = (0..n as u32)
                    .map(|i| (i, if cycle && i + 1 == n as u32 { 0 } else { i + 1 }))
                    .collect();
                link.retain(|_| rng.below(8) != 0);
                for i in (1..link.len()).rev() {
                    link.swap(i, rng.below(i as u64 + 1) as usize);
                }
            }
            if link.is_empty() {
                continue;
            }
            let small = is_single_small_fan(&link);
            assert_eq!(small, is_single_sorted_fan(&mut link.clone(), &mut heads), "{link:?}");
            match small {
                Some(true) => single += 1,
                Some(false) => several += 1,
                None => bad += 1,
            }
            // The fans of a vertex 0 whose faces are (0, x, y), some repeating a vertex.
            let faces: Vec<[u32; 3]> = link
                .iter()
                .map(|&(x, y)| {
                    if rng.below(10) == 0 {
                        [0, x + 1, x + 1]
                    } else {
                        [0, x + 1, y + 1]
                    }
                })
                .collect();
            let ids: Vec<u32> = (0..faces.len() as u32).collect();
            let mut fans = Fans::default();
            let (mut pairwise, mut sorted) = (Vec::new(), Vec::new());
            fans.find(0, &ids, &faces, &mut pairwise);
            let many: Vec<u32> = (0..2 * faces.len() as u32).collect();
            let doubled: Vec<[u32; 3]> = faces.iter().flat_map(|&t| [t; 2]).collect();
            // (Each face twice, joined to its copy: more than SMALL_FAN faces, found by sorting.)
            fans.find(0, &many, &doubled, &mut sorted);
            if faces.len() * 2 > SMALL_FAN {
                let halved: Vec<(u32, u32, u32)> = sorted
                    .iter()
                    .filter(|e| e.1 % 2 == 0)
                    .map(|&(v, f, r)| (v, f / 2, r / 2))
                    .collect();
                assert_eq!(pairwise, halved, "{faces:?}");
            }
        }
        assert!(
            single > 1000 && several > 1000 && bad > 1000,
            "{single} {several} {bad}"
        );
    }

    /// Face indices are read as `str::parse` reads them.
    #[test]
    fn indices_are_read_as_parse_reads_them() {
        let texts = [
            "1",
            "0",
            "-0",
            "+7",
            "-12",
            "007",
            "123456789012345678",
            "-999999999999999999",
            "1234567890123456789",
            "9223372036854775807",
            "9223372036854775808",
            "-9223372036854775808",
            "+",
            "-",
            "",
            "+-1",
            "1.0",
            "1e3",
            " 1",
            "1 ",
            "٣",
            "0x10",
            "--1",
            "++1",
        ];
        for text in texts {
            assert_eq!(parse_index(text.as_bytes()), text.parse::<i64>().ok(), "{text:?}");
        }
    }

    #[test]
    fn compensated_sum_keeps_small_terms() {
        let mut sum = CompensatedSum::default();
        for x in [1e16, 1.0, 1.0, -1e16, 1e-3] {
            sum.add(x);
        }
        assert_eq!(sum.value(), 2.001);
        assert_eq!([1e16, 1.0, 1.0, -1e16, 1e-3].iter().sum::<f64>(), 1e-3 + 0.0);
    }

    #[test]
    fn projections_follow_the_normal_components() {
        let t = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 2.0),
            DVec3::new(0.0, 1.0, 3.0),
        ];
        let n = (t[1] - t[0]).cross(t[2] - t[0]); // (-2, -3, 1)
        for axis in 0..3 {
            assert_eq!(projected_orientation(t, axis) as f64, n[axis].signum());
        }
        let p = Projection::of_face(t);
        assert_eq!((p.axis, p.sign), (1, -1));
        let collinear = [DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0), DVec3::new(2.0, 4.0, 6.0)];
        assert!(exactly_degenerate(collinear));
        assert_eq!(Projection::of_face(collinear).sign, 0);
    }

    #[test]
    fn projection_axis_is_the_exact_largest_normal_component() {
        let mut rng = Rng(0x0123_4567_89ab_cdef);
        for k in 0..20000 {
            let n = if k % 2 == 0 { 2 } else { 500 };
            let t = [0; 3].map(|_| DVec3::new(rng.int(n), rng.int(n), rng.int(n)));
            let normal = (t[1] - t[0]).cross(t[2] - t[0]); // exact: small integers
                                                           // Scaled exactly into the subnormals, where the float normal underflows to 0.
            let tiny = t.map(|p| p * 2f64.powi(-530) * 2f64.powi(-530));
            for (i, j) in [(0, 1), (1, 0), (0, 2), (2, 0), (1, 2), (2, 1)] {
                let expected = normal[i].abs() > normal[j].abs();
                assert_eq!(larger_normal_component(t, i, j), expected, "{t:?} {i} {j}");
                assert_eq!(larger_normal_component(tiny, i, j), expected, "{tiny:?} {i} {j}");
            }
            let p = Projection::of_face(tiny);
            assert!((0..3).all(|j| normal[p.axis].abs() >= normal[j].abs()));
            assert!(
                (0..p.axis).all(|j| normal[p.axis].abs() > normal[j].abs()),
                "ties: lower axis"
            );
        }
    }

    #[test]
    fn exact_range_bounds_are_powers_of_two() {
        assert!(robust_is_exact(&[0.0, -0.0, 2f64.powi(-250), -2f64.powi(250), 1.0]));
        assert!(!robust_is_exact(&[2f64.powi(-251)]) && !robust_is_exact(&[2f64.powi(251)]));
        assert!(!robust_is_exact(&[f64::NAN]) && !robust_is_exact(&[f64::INFINITY]));
    }

    #[test]
    fn determinant_expansion_agrees_with_robust() {
        let mut rng = Rng(0x2545_F491_4F6C_DD1D);
        let mut zeros = 0;
        for i in 0..20000 {
            let scale = if i % 2 == 0 {
                1.0
            } else {
                2f64.powi((rng.next() % 100) as i32 - 50)
            };
            let n = if i % 2 == 0 { 3 } else { 1 << 40 };
            let p = [0; 4].map(|_| DVec3::new(rng.int(n), rng.int(n), rng.int(n)) * scale);
            let coord = |p: DVec3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
            let expected = sign_of(robust::orient3d(coord(p[0]), coord(p[1]), coord(p[2]), coord(p[3])));
            let rows = p.map(|q| [q.x, q.y, q.z, 1.0]);
            assert_eq!(exact_determinant_sign(rows), expected, "{p:?}");
            let c2 = |p: DVec3| robust::Coord { x: p.x, y: p.y };
            let expected = sign_of(robust::orient2d(c2(p[0]), c2(p[1]), c2(p[2])));
            let rows = [p[0], p[1], p[2]].map(|q| [q.x, q.y, 1.0]);
            assert_eq!(exact_determinant_sign(rows), expected, "{p:?}");
            zeros += (expected == 0) as usize;
        }
        assert!(zeros > 500, "{zeros}: degenerate cases must be tested too");
    }

    #[test]
    fn orientation_is_exact_on_tiny_and_huge_coordinates() {
        // Small-integer points decided by robust at scale 1, then every axis scaled by its own
        // power of two (exactly, down to subnormals or up to 2^1000).
        let mut rng = Rng(99);
        let mut robust_wrong = 0;
        for _ in 0..20000 {
            let p = [0; 4].map(|_| DVec3::new(rng.int(7), rng.int(7), rng.int(7)));
            let power = |rng: &mut Rng| 2f64.powi((rng.next() % 2060) as i32 - 1070);
            let scale = DVec3::new(power(&mut rng), power(&mut rng), power(&mut rng));
            let q = p.map(|v| v * scale);
            if q.iter().zip(&p).any(|(s, v)| *s / scale != *v || !s.is_finite()) {
                continue;
            }
            let coord = |p: DVec3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
            let expected = sign_of(robust::orient3d(coord(p[0]), coord(p[1]), coord(p[2]), coord(p[3])));
            assert_eq!(orient3d_sign(q[0], q[1], q[2], q[3]), expected, "{q:?}");
            robust_wrong +=
                (sign_of(robust::orient3d(coord(q[0]), coord(q[1]), coord(q[2]), coord(q[3]))) != expected) as usize;
            assert_eq!(
                coplanar_and_flat(q[0], q[1], q[2], q[3]),
                coplanar_and_flat(p[0], p[1], p[2], p[3])
            );
            for axis in 0..3 {
                let t = [q[0], q[1], q[2]];
                let u = [p[0], p[1], p[2]];
                assert_eq!(projected_orientation(t, axis), projected_orientation(u, axis));
            }
        }
        assert!(
            robust_wrong > 1000,
            "the scaled cases must defeat robust itself ({robust_wrong})"
        );
    }

    #[test]
    fn subnormal_triangle_passes_against_itself() {
        // The fuzz finding of `regression_subnormal_zero_area`: y = 2e-323 is not 0.
        let mesh = Mesh3 {
            positions: vec![DVec3::ZERO, DVec3::new(0.2, 2e-323, 0.0), DVec3::new(0.1, 0.0, 0.0)],
            triangles: vec![[0, 1, 2]],
        };
        let report = check_meshes(&mesh, &mesh);
        assert!(report.passed(), "{report}");
        let mut reversed = mesh.clone();
        reversed.triangles[0] = [0, 2, 1];
        let report = check_meshes(&mesh, &reversed);
        assert!(report.failures.iter().any(|l| l.contains("is reversed")), "{report}");
    }

    #[test]
    fn wide_spans_within_one_axis_use_the_expansion() {
        // 0, b and b / 2^600 are collinear; their axes hold values 2^600 apart, which no
        // rescaling makes exact for robust. One unit in the last place off, they are not.
        let mut rng = Rng(5);
        for _ in 0..2000 {
            let mut any = || rng.int(1 << 50) * 2f64.powi((rng.next() % 40) as i32 - 20);
            let b = DVec3::new(any(), any(), any());
            let c = DVec3::new(any(), any(), any());
            if b.x == 0.0 || b.z == 0.0 {
                continue;
            }
            let sb = b * 2f64.powi(-600);
            assert_eq!(rescaled([0.0, b.x, sb.x]), None);
            assert!(exactly_degenerate([DVec3::ZERO, b, sb]), "{b:?}");
            // Moved one unit in the last place away from 0 along z (by delta, of the sign of z).
            let off = DVec3::new(sb.x, sb.y, f64::from_bits(sb.z.to_bits() + 1));
            assert!(!exactly_degenerate([DVec3::ZERO, b, off]), "{b:?}");
            assert_eq!(orient3d_sign(DVec3::ZERO, b, c, sb), 0, "{b:?} {c:?}");
            // orient3d(0, b, c, d) = -det(d, b, c), which the move changes by -delta (b x c).z,
            // whose sign is that of the turn 0, b, c seen along z.
            let turn = orient2d_sign([0.0, 0.0], [b.x, b.y], [c.x, c.y]);
            let expected = -turn * sign_of(b.z);
            assert_eq!(orient3d_sign(DVec3::ZERO, b, c, off), expected, "{b:?} {c:?}");
        }
    }

    #[test]
    fn floor_to_i64_is_floor_as_i64() {
        let mut rng = Rng(11);
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            -1.0,
            1.0,
            -1e-300,
            f64::MIN_POSITIVE,
            2f64.powi(52) + 0.5,
            -(2f64.powi(52) + 0.5),
            2f64.powi(53),
            2f64.powi(63),
            -2f64.powi(63),
            2f64.powi(70),
            -2f64.powi(70),
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        values.extend((0..10_000).map(|_| rng.centered() * 2f64.powi((rng.below(140) as i32) - 70)));
        for x in values {
            assert_eq!(floor_to_i64(x), x.floor() as i64, "{x:e}");
        }
    }

    /// A cone-like fan of `n` triangles (`n` a multiple of 4) around vertex 0 at the origin, its
    /// rim stepping through radii 1, 1/10, 1/100, 1/10 at heights -1, -1/10, 0, 1/20 (the fan of
    /// `tests/common`).
    fn cone_fan(n: usize) -> Mesh3 {
        const RIM: [(f64, f64); 4] = [(1.0, -1.0), (0.1, -0.1), (0.01, 0.0), (0.1, 0.05)];
        let mut positions = vec![DVec3::ZERO];
        positions.extend((0..n).map(|i| {
            let theta = std::f64::consts::TAU * i as f64 / n as f64;
            let (radius, height) = RIM[i % 4];
            DVec3::new(radius * theta.cos(), radius * theta.sin(), height)
        }));
        let triangles = (0..n as u32).map(|i| [0, 1 + i, 1 + (i + 1) % n as u32]).collect();
        Mesh3 { positions, triangles }
    }

    /// The spokes of a fan (its edges from vertex 0, `edges` indexed like `Prepared::edges`).
    fn spokes(mesh: &Mesh3, edges: &[Edge]) -> Vec<(DVec3, DVec3)> {
        edges
            .iter()
            .filter(|e| e.lo == 0)
            .map(|e| (mesh.positions[e.lo as usize], mesh.positions[e.hi as usize]))
            .collect()
    }

    /// Points on the `spokes` at the given fractions of their lengths, and beside each of them
    /// the points `offset` away, for every offset.
    fn spoke_points(spokes: &[(DVec3, DVec3)], fractions: &[f64], offsets: &[f64]) -> Vec<DVec3> {
        let mut points = Vec::new();
        for &(a, b) in spokes {
            let side = (b - a).cross(DVec3::Z).normalize();
            for &t in fractions {
                points.extend(offsets.iter().map(|&offset| a.lerp(b, t) + side * offset));
            }
        }
        points
    }

    /// Asserts that `grid` finds, for every point, the edges that testing every edge finds;
    /// returns how many points are on edges.
    fn assert_same_as_testing_every_edge(mesh: &Mesh3, edges: &[Edge], grid: &EdgeGrid, points: &[DVec3]) -> usize {
        let all: Vec<u32> = (0..edges.len() as u32).collect();
        let (mut found, mut expected) = (Vec::new(), Vec::new());
        let mut hits = 0;
        for &p in points {
            grid.edges_containing(mesh, edges, p, &mut found);
            nearest_edges_containing(mesh, edges, &all, p, &mut expected);
            assert_eq!(found, expected, "{p:?}");
            hits += usize::from(!found.is_empty());
        }
        hits
    }

    /// Points on the spokes of a fan near its apex, where every spoke crosses the grid's cell
    /// (its bucket holds all of them): the trees give each point few candidates, where the
    /// uniform grid alone gave it the whole bucket, and the edges found are those that testing
    /// every edge finds, for the points the trees were built for and for others (just off the
    /// spokes, within the tolerance and beyond it).
    #[test]
    fn points_near_a_vertex_of_high_valence_examine_few_candidates() {
        let n = 2000;
        let mesh = cone_fan(n);
        let naming = Naming::default();
        let model = InputModel::new(&mesh, &naming).expect("a valid fan");
        let edges = &model.prepared.edges;
        let spokes = spokes(&mesh, edges);
        assert_eq!(spokes.len(), n);
        let fractions = [1.0 / 128.0, 1.0 / 32.0, 1.0 / 8.0, 0.3];
        let on = spoke_points(&spokes, &fractions, &[0.0]);
        let grid = EdgeGrid::new(&mesh, edges, &on);
        // What the uniform grid alone examined, and what the trees examine.
        let bucketed: usize = on.iter().map(|&p| grid.bucket_items(grid.frame.cell_of(p)).len()).sum();
        let examined: usize = on.iter().map(|&p| grid.candidates(p).len()).sum();
        let most = on.iter().map(|&p| grid.candidates(p).len()).max().unwrap_or(0);
        let points = on.len();
        assert!(
            bucketed > n / 2 * points,
            "{bucketed} bucket entries for {points} points"
        );
        assert!(examined < 50 * points, "{examined} candidates for {points} points");
        assert!(most < n / 4, "{most} candidates for one point");
        let (entries, leaf_edges) = (grid.items.len() + points, grid.trees.edges.len());
        assert!(
            leaf_edges <= (1 + TREE_BUDGET) * entries,
            "{leaf_edges} edges in leaves"
        );
        // Every point on a spoke, and those just off the long spokes (within their tolerance).
        let off = spoke_points(&spokes, &fractions, &[8e-12, -1e-6]);
        let hits = assert_same_as_testing_every_edge(&mesh, edges, &grid, &[on, off].concat());
        assert_eq!(hits, points + n / 4 * fractions.len());
    }

    /// A fan far smaller than the grid's cell, which a vertex 10^13 away makes huge: its trees
    /// go deep, and the short spokes are not cut into ever more pieces on the way down (an
    /// earlier version halved every piece at every level, 2^25 pieces of a spoke, and hung).
    #[test]
    fn a_small_fan_beside_a_far_vertex_is_searched_in_few_pieces() {
        let n = 64;
        let mut mesh = cone_fan(n);
        mesh.positions.push(DVec3::new(1e6, 0.0, 0.0));
        mesh.triangles.push([2, 1, n as u32 + 1]);
        let naming = Naming::default();
        let model = InputModel::new(&mesh, &naming).expect("a valid fan");
        let edges = &model.prepared.edges;
        let spokes = spokes(&mesh, edges);
        let on = spoke_points(&spokes, &[1.0 / 1024.0, 1.0 / 32.0, 0.5], &[0.0]);
        let grid = EdgeGrid::new(&mesh, edges, &on);
        assert!(grid.frame.cell > 1e3 && grid.frame.depth_limit > 20);
        assert!(
            grid.trees.nodes.len() > 8 * 8,
            "the trees are {} nodes",
            grid.trees.nodes.len()
        );
        let examined: usize = on.iter().map(|&p| grid.candidates(p).len()).sum();
        assert!(
            examined < 32 * on.len(),
            "{examined} candidates for {} points",
            on.len()
        );
        // 4098 pieces; halving every piece at every level placed 60 million.
        let placed = grid.trees.pieces_placed;
        assert!(placed < 100_000, "{placed} pieces placed");
        let hits = assert_same_as_testing_every_edge(&mesh, edges, &grid, &on);
        assert_eq!(hits, on.len());
    }
}
