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
//!    never called degenerate and a folded one never passes). Two output faces folded onto each
//!    other (coplanar, exactly or within their corners' rounding where their normals are
//!    clear, on one side of their common edge) meet only along an input edge:
//!    where the input overlaps itself, a face turned over fits the other sheet, the right way
//!    up, and a tiny one moves less area than rule 4 sees.
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
//!    number of boundary loops and number of connected components equal the input's. The
//!    boundary is where it was: every output boundary edge lies along an input boundary edge
//!    (its two ends at that edge's endpoints or on it, within [`ON_EDGE_TOLERANCE`]), and every
//!    input boundary edge has an output boundary edge along it (a face along the boundary,
//!    removed, keeps the counts, and can be far smaller than rule 4 sees).
//! 6. Every interior output edge is Delaunay: `alpha + beta <= pi + DELAUNAY_TOLERANCE`.
//! 7. ([`check_files`] only.) The OUTPUT's file does not give one vertex two records that reading
//!    joins (not copies a seam made, nor distinct vertices rounded to one point, which reading
//!    keeps apart) unless the INPUT's file has such copies too: a reader that does not weld
//!    by position would see the surface cut there.
//!
//! The maps a run writes beside its output are judged by [`maps`].
//!
//! Where each part lives: reading the two files (and rule 7) in `read.rs`, keeping apart what
//! `--repair` cut in `cuts.rs`; indices, edges, fans and rule 5 in `topology.rs`; the input's
//! planar regions in `regions.rs`; rules 1 and 2 in `vertices.rs`, with the spatial hash over
//! the input edges in `grid.rs`; rules 3 and 4 in `faces.rs`; rule 6 in `delaunay.rs`; the
//! exact predicates in `exact.rs`; the failure lines in `failures.rs`; small index tables in
//! `tables.rs`. This file holds the meshes, the report, the names of vertices and faces, and
//! the check's order ([`check_files_with`]).
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

mod cuts;
mod delaunay;
mod exact;
mod faces;
mod failures;
mod grid;
mod read;
mod regions;
mod tables;
mod topology;
mod vertices;

use cuts::*;
use delaunay::*;
use exact::*;
use faces::*;
pub use failures::FAILURE_KINDS;
use failures::*;
use grid::*;
pub use read::read_raw;
use read::*;
use regions::*;
use tables::*;
use topology::*;
use vertices::*;

use std::collections::HashSet;
use std::f64::consts::{FRAC_PI_2, PI};
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

/// A decimal with at most this many significant digits counts as a rounded coordinate in
/// [`CheckReport::misplaced_vertices`]: a double computed on an edge has 15 to 17 (three such
/// coordinates of at most 9 by chance: about one vertex in 10^20).
pub const SHORT_DIGITS: usize = 9;

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
    /// Output vertices used by a face that are neither input vertices nor on an input edge
    /// (failures of rule 2), and how many of them have only coordinates that a file with
    /// rounded numbers holds: each a 32-bit float, or a decimal of at most
    /// [`SHORT_DIGITS`] significant digits. When nearly all are so, OUTPUT was most likely
    /// written with rounded coordinates (by a tool printing `%f`, or as PLY `float`), which moves
    /// every vertex, and the check says so in a note.
    pub misplaced_vertices: (usize, usize),
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
    /// Boundary edges of the output (one face).
    pub boundary_edges: usize,
    /// Boundary edges whose one opposite angle gamma exceeds `pi/2 + DELAUNAY_TOLERANCE`: not
    /// Gabriel, their cotangent weight negative. Not a failure (the spec counts boundary
    /// edges as Delaunay) unless [`CheckReport::require_gabriel_boundary`] makes them one.
    pub non_gabriel_boundary_edges: usize,
    /// `max(gamma - pi/2)` over the boundary edges, in radians (`f64::NEG_INFINITY` when there
    /// is none).
    pub max_boundary_excess: f64,
    /// One line per boundary edge counted in [`CheckReport::non_gabriel_boundary_edges`], worst
    /// first (at most [`MAX_LINES_PER_KIND`], then one `... and N more` line).
    pub boundary_lines: Vec<String>,
    /// One human-readable line per failure, at most [`MAX_LINES_PER_KIND`] per kind plus one
    /// `... and N more` line per kind that overflowed. Empty iff the output is valid.
    pub failures: Vec<String>,
    /// How many failures of each kind there were (all of them, also those past the lines
    /// kept), kinds in the order of their first failure: `("non-Delaunay edge", 37)`. Empty
    /// iff the output is valid.
    pub failure_counts: Vec<(&'static str, usize)>,
}

impl CheckReport {
    /// True iff the output is a valid result for the input (no failure).
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }

    /// Makes every boundary edge facing an obtuse angle a failure (`check
    /// --gabriel-boundary`, for outputs of `--gabriel-boundary`).
    pub fn require_gabriel_boundary(&mut self) {
        self.failures.append(&mut self.boundary_lines);
        if self.non_gabriel_boundary_edges > 0 {
            self.failure_counts
                .push((KIND_NOT_GABRIEL, self.non_gabriel_boundary_edges));
        }
    }

    /// [`CheckReport::max_boundary_excess`] for a printout: in radians, or
    /// `none` when the output has no boundary edge.
    pub fn max_boundary_excess_text(&self) -> String {
        if self.boundary_edges == 0 {
            "none (no boundary edge)".to_string()
        } else {
            format!("{:.3e} rad", self.max_boundary_excess)
        }
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
            misplaced_vertices: (0, 0),
            first_reordered_vertex: None,
            first_reordered_vertex_names: None,
            interior_edges: 0,
            non_delaunay_edges: 0,
            max_excess: f64::NEG_INFINITY,
            boundary_edges: 0,
            non_gabriel_boundary_edges: 0,
            max_boundary_excess: f64::NEG_INFINITY,
            boundary_lines: Vec::new(),
            failures: Vec::new(),
            failure_counts: Vec::new(),
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
        if let (misplaced @ 1.., rounded) = self.misplaced_vertices {
            writeln!(
                f,
                "output vertices off the input: {misplaced}, {rounded} of them with only rounded coordinates"
            )?;
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
    if cracks.0 > 0 {
        report.failure_counts.push((KIND_CRACK, cracks.0));
    }
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
        report.failure_counts.push((KIND_INVALID_INPUT, 1));
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

/// An edge as [`Mesh3::reads_back_as`] compares it: its ends' positions
/// (as bits, in order) and the positions of its faces' apexes (in order).
type EdgeWithFaces = ([[u64; 3]; 2], Vec<[u64; 3]>);

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

    /// Whether the file at `path`, read as `check` reads a run's output
    /// ([`Mesh3::read_like`], aimed at `input`, the run's input: not at
    /// `written`, which would tell the reading which sheet of a cut edge a
    /// split went to), is the mesh `written` that was written to it, as far
    /// as positions tell: as many used vertices,
    /// faces and connected components, and the same edges with the same
    /// faces on them (each edge by its ends' positions and the positions of
    /// the apexes of its faces). Where a file copies vertices (at attribute
    /// seams, or an OBJ's for colours) and distinct vertices share a position
    /// (the copies `--repair` makes where it cuts), the reading has to guess
    /// which copies are one vertex; a wrong guess joins other faces across an
    /// edge, or cuts the surface apart. The command line refuses to write a
    /// file read back otherwise.
    pub fn reads_back_as(path: impl AsRef<Path>, written: &Mesh3, input: &Mesh3) -> Result<bool, CheckError> {
        let back = Mesh3::read_like(path, input)?;
        Ok(back.shape() == written.shape())
    }

    /// Used vertices, faces and connected components, and every edge (its
    /// ends' positions, in order) with the positions of its faces' apexes
    /// (in order), sorted: what [`Mesh3::reads_back_as`] compares.
    fn shape(&self) -> ([usize; 3], Vec<EdgeWithFaces>) {
        // (-0 and 0 alike, as reading welds them.)
        let key = |v: u32| self.positions[v as usize].to_array().map(|x| (x + 0.0).to_bits());
        let mut apexes: FastMap<(u32, u32), Vec<[u64; 3]>> = FastMap::default();
        let mut sets = UnionFind::new(self.positions.len());
        for t in &self.triangles {
            for i in 0..3 {
                let (a, b, c) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
                apexes.entry((a.min(b), a.max(b))).or_default().push(key(c));
                sets.union(a, b);
            }
        }
        let used: HashSet<u32> = self.triangles.iter().flatten().copied().collect();
        let components: HashSet<u32> = used.iter().map(|&v| sets.find(v)).collect();
        let mut edges: Vec<EdgeWithFaces> = apexes
            .into_iter()
            .map(|((a, b), mut on)| {
                on.sort_unstable();
                let (p, q) = (key(a), key(b));
                ([p.min(q), p.max(q)], on)
            })
            .collect();
        edges.sort_unstable();
        ([used.len(), self.triangles.len(), components.len()], edges)
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
                report.misplaced_vertices = candidates.misplaced;
                let mut assignment = assign_faces(&model, &output_names, &candidates, &mut fail);
                let rounding = rounding_allowance(&model, &candidates.edge_has_added);
                check_areas(&model, &mut assignment, &rounding, &mut fail);
                compare_topology(&model.prepared.stats, &out.stats, &mut fail);
                compare_boundaries(&model, &out.edges, &candidates, &output_names, &mut fail);
            },
        );
        check_folds(&model, &output_names, &out.edges, &delaunay.folds, &mut fail);
        delaunay.report(&output_names, &mut fail);
        report.interior_edges = delaunay.interior;
        report.non_delaunay_edges = delaunay.bad.len();
        report.max_excess = delaunay.max_excess;
        report.boundary_edges = delaunay.boundary;
        report.non_gabriel_boundary_edges = delaunay.bad_boundary.len();
        report.max_boundary_excess = delaunay.max_boundary_excess;
        report.boundary_lines = delaunay.boundary_lines(&output_names);
    }
    report.failure_counts = fail.counts.clone();
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
        Some(p) => {
            // Faces along an edge the same way, on a surface no orientation makes consistent:
            // said as such, as the construction says it (turning faces would not help).
            let misoriented = p.edges.iter().find(|e| e.count == 2 && !e.is_interior());
            let moebius =
                misoriented.is_some_and(|e| !component_is_orientable(mesh.triangles.len(), &p.edges, e.faces[0]));
            let why = if moebius {
                "; the surface is not orientable (a Möbius band): no orientation of its faces is consistent (check the output of `delmesh --repair` against the file its `--repaired` writes, cut open)"
            } else {
                ""
            };
            Err(problems.summary(5) + why)
        }
        None => Err(problems.summary(5)),
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

    /// The axis-plane shortcut of `coplanar_and_flat` and `coplanar_and_folded` decides as the
    /// exact determinant does: random quads with one coordinate shared (0.0 and -0.0 mixed), some
    /// moved one ulp off.
    #[test]
    fn axis_plane_quads_are_judged_as_the_exact_determinant_says() {
        let mut rng = Rng(0xa715_91a9);
        let (mut flat, mut folded, mut neither) = (0, 0, 0);
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
            let k = (0..3).find(|&k| projected_orientation([a, b, c], k) != 0).unwrap();
            let sides = projected_orientation([a, b, c], k) * projected_orientation([a, b, d], k);
            let (expected_flat, expected_folded) = (coplanar && sides < 0, coplanar && sides > 0);
            assert_eq!(coplanar_and_flat(a, b, c, d), expected_flat, "case {case}: {p:?}");
            assert_eq!(coplanar_and_folded(a, b, c, d), expected_folded, "case {case}: {p:?}");
            flat += usize::from(expected_flat);
            folded += usize::from(expected_folded);
            neither += usize::from(!expected_flat && !expected_folded);
        }
        assert!(
            flat > 1000 && folded > 1000 && neither > 500,
            "{flat} flat, {folded} folded, {neither} neither"
        );
    }

    /// Two faces folded onto each other in a tilted plane far from the origin, whose corners are
    /// off that plane by their rounding only: the exact test says not coplanar, and `folded`
    /// finds them within the rounding of their positions (`position_rounding`: their normals are
    /// 6e-6 rad from opposite, where it allows 8e-4 and the arithmetic's rounding 1e-14). Unfolded,
    /// the same pair is not folded, nor is it with d lifted clear of the rounding. (Mutation
    /// testing: no fixture told `position_rounding`'s factors apart, nor `folded`'s threshold.)
    #[test]
    fn a_pair_folded_within_the_rounding_of_its_positions_is_folded() {
        //   c . d        (a, b, c) and (b, a, d) on one side of ab: folded
        //   |  `.
        //   a----b       in the plane z = 1e8 + 0.3 (x - 1e8) + 0.3 (y - 1e8)
        let (p0, h) = (DVec3::splat(1e8), 2e-3);
        let (e1, e2) = (DVec3::new(1.0, 0.0, 0.3), DVec3::new(0.0, 1.0, 0.3));
        let (a, b, c) = (p0, p0 + e1 * h, p0 + e2 * h);
        let d = p0 + (e1 * (0.3 * h) + e2 * (0.8 * h));
        assert!(!coplanar_and_folded(a, b, c, d), "the case must defeat the exact test");
        assert!(faces::folded([a, b, c, d]));
        let unfolded = p0 + (e1 * (0.3 * h) - e2 * (0.8 * h));
        assert!(!faces::folded([a, b, c, unfolded]));
        // d lifted off the plane by 1e-5: their normals 6.5e-3 rad from opposite, where the
        // rounding allows 8e-4: not folded.
        let lifted = d + DVec3::new(-0.3, -0.3, 1.0) * (0.005 * h);
        assert!(!faces::folded([a, b, c, lifted]));
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

    /// A straight strip two cells wide and 40,000 long fills a few of each 16 x 16 x 16 block's
    /// places; its blocks share runs of buckets, and without the block's hash in the low bits
    /// every bucket in use held the entries of dozens of blocks (the largest 624).
    #[test]
    fn a_long_thin_strip_spreads_over_the_buckets() {
        let n = 40_000u32;
        let positions = (0..=n).flat_map(|i| [DVec3::new(i as f64, 0.0, 0.0), DVec3::new(i as f64, 1.0, 0.0)]);
        let triangles = (0..n).flat_map(|i| [[2 * i, 2 * i + 2, 2 * i + 1], [2 * i + 1, 2 * i + 2, 2 * i + 3]]);
        let mesh = Mesh3 {
            positions: positions.collect(),
            triangles: triangles.collect(),
        };
        let naming = Naming::default();
        let model = InputModel::new(&mesh, &naming).expect("a valid strip");
        let edges = &model.prepared.edges;
        let grid = EdgeGrid::new(&mesh, edges, &[]);
        let fullest = grid.starts.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0);
        assert!(fullest <= CROWDED, "{fullest} entries in one bucket");
        let points = [DVec3::new(12_345.5, 0.0, 0.0), DVec3::new(39_999.0, 0.5, 0.0)];
        assert_eq!(assert_same_as_testing_every_edge(&mesh, edges, &grid, &points), 2);
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

    /// A point computed on one input edge belongs to that edge only, though another runs
    /// 2e-13 beside it, well within the on-edge tolerance (1.6e-11 here): of the edges that
    /// contain a point, only those within `NEAREST_EDGE_SLACK` of the nearest count (taking
    /// both let faces go to the wrong one of two nearly coplanar regions,
    /// `tests/regressions/bug-checker-nearly-coplanar-regions.obj`).
    #[test]
    fn a_point_on_an_edge_is_not_given_a_parallel_edge_beside_it() {
        let gap = 2e-13;
        let mesh = Mesh3 {
            positions: vec![
                DVec3::ZERO,
                DVec3::X,
                DVec3::new(0.5, -1.0, 0.0),
                DVec3::new(0.0, gap, 0.0),
                DVec3::new(1.0, gap, 0.0),
                DVec3::new(0.5, 1.0, 0.1),
            ],
            triangles: vec![[0, 1, 2], [4, 3, 5]],
        };
        let naming = Naming::default();
        let model = InputModel::new(&mesh, &naming).expect("two separate triangles");
        let edges = &model.prepared.edges;
        let edge = |lo: u32, hi: u32| edges.iter().position(|e| (e.lo, e.hi) == (lo, hi)).unwrap() as u32;
        let (below, above) = (edge(0, 1), edge(3, 4));
        let all: Vec<u32> = (0..edges.len() as u32).collect();
        let mut found = Vec::new();
        for t in [0.1, 0.37, 0.5, 0.9] {
            let on_below = DVec3::ZERO.lerp(DVec3::X, t);
            let on_above = mesh.positions[3].lerp(mesh.positions[4], t);
            // Both edges contain each point within the tolerance...
            for p in [on_below, on_above] {
                let (a, b) = (mesh.positions[0], mesh.positions[1]);
                assert!(distance_on_edge(p, a, b).is_some());
                let (a, b) = (mesh.positions[3], mesh.positions[4]);
                assert!(distance_on_edge(p, a, b).is_some());
            }
            // ...but each belongs to its own.
            nearest_edges_containing(&mesh, edges, &all, on_below, &mut found);
            assert_eq!(found, [below], "{t}");
            nearest_edges_containing(&mesh, edges, &all, on_above, &mut found);
            assert_eq!(found, [above], "{t}");
        }
    }
}
