//! Independent judge of the maps a run writes beside its output: `--vertex-map` (where each
//! output vertex comes from) and `--face-map` (which input face each output face lies in).
//!
//! Both number the input as its file lists it, so they are judged against the file the run
//! read (`ORIGINAL`: for a run with `--repair`, not the repaired file the mesh check compares
//! with), read as it lists its vertices and faces, nothing welded, and the output file, by
//! geometry alone; nothing is shared with the code that made the maps (with the construction's
//! reader, only what a file means: how a polygon is cut, [`triangulate`], and the outline
//! `--repair` reads one that passes a point twice as).
//!
//! # What is checked
//!
//! Vertex map (`output_index,input_index_a,input_index_b,t`): one row per vertex of the output
//! file, in its order; `a` and `b` vertices of ORIGINAL, each the first the file defines at its
//! position; `t` is 0 when `a = b` and strictly between 0 and 1 otherwise; and the output
//! vertex is `a + t·(b − a)`, computed in f64 from ORIGINAL's coordinates, bit for bit (-0 and
//! 0 alike).
//!
//! Face map (`output_index,input_index,inside`): one row per face of the output file, in its
//! order; the input face is a face of ORIGINAL (a polygon is one face, an STL facet one) and
//! holds the output face's centroid; and a face said `inside` (1) has all its corners on that
//! input face. (Not that the faces said inside one input face cover no more than its area:
//! where input faces overlap, a face may lie on several, and the map names one.) An
//! `inside` of 0 is not judged: the map may say 0 where it cannot be sure (a flip in a flat
//! region lays faces across coplanar input faces), and [`MapReport::not_inside`] counts them.
//! "On a face" allows for rounding: [`ROUNDING`] of the input's size plus a few units in the
//! last place of its coordinates, and for the centroid also [`CENTROID_SLACK`] of the face's
//! longest side (a centroid rounded just out of a sliver at a region's border is named by the
//! nearest face). An input face is where the construction reads it: a polygon cut into
//! triangles as the file's polygons are ([`triangulate`]), less the corners that repeat the
//! position of the one before (`--repair` reads such a polygon as the outline it traces); and
//! after a run's `--weld-tolerance`, each corner where the weld moved it (to the position of
//! the first vertex of its cluster: vertices joined by chains of distances below it).

use std::path::Path;

use glam::DVec3;

use super::{read_raw, CheckError, Failures, PARALLEL_FACES};
use crate::hash::FastMap;
use crate::io::formats::RawMesh;
use crate::io::polygon::triangulate;

/// How far off an input face a point may be and still be on it, relative to the input's size
/// (the diagonal of its bounding box).
pub const ROUNDING: f64 = 1e-9;

/// How far off its input face a face's centroid may be, besides [`ROUNDING`], relative to the
/// face's longest side.
pub const CENTROID_SLACK: f64 = 1e-6;

/// The vertex map's header line.
pub const VERTEX_MAP_HEADER: &str = "output_index,input_index_a,input_index_b,t";

/// The face map's header line.
pub const FACE_MAP_HEADER: &str = "output_index,input_index,inside";

/// The outcome of checking one map.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MapReport {
    /// Rows read (after the header).
    pub rows: usize,
    /// Face map: rows whose `inside` is 0 (always 0 for a vertex map).
    pub not_inside: usize,
    /// One human-readable line per failure, at most [`super::MAX_LINES_PER_KIND`] per kind
    /// plus one `... and N more` line per kind that overflowed. Empty iff the map is right.
    pub failures: Vec<String>,
}

impl MapReport {
    /// True iff the map is right (no failure).
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }
}

/// Checks the maps given (`vertex_map`, `face_map`: CSV files as delmesh writes them) of the
/// run that read `original` and wrote `output_path`, reading the files only; `weld_tolerance` is
/// the run's `--weld-tolerance` (0 without). Errors when a file cannot be read (or a mesh
/// file parsed), or the output is an STL ([`CheckError::Unjudgeable`]); everything wrong in a
/// map is a failure line of its report.
pub fn check_map_files(
    original: &Path,
    output_path: &Path,
    vertex_map: Option<&Path>,
    face_map: Option<&Path>,
    weld_tolerance: f64,
) -> Result<(Option<MapReport>, Option<MapReport>), CheckError> {
    let tables = read_map_tables(vertex_map, face_map)?;
    let (original, _) = read_raw(original)?;
    let (output, shares_vertices) = read_raw(output_path)?;
    check_maps_of(
        &original,
        &output,
        shares_vertices,
        output_path,
        &tables,
        weld_tolerance,
    )
}

/// The text of a vertex map and of a face map, as [`read_map_tables`] reads them.
#[derive(Debug, Default)]
pub struct MapTables {
    /// The vertex map's text, if one is judged.
    pub vertex: Option<Vec<u8>>,
    /// The face map's text, if one is judged.
    pub face: Option<Vec<u8>>,
}

/// Reads the map files named (inflated when compressed, as delmesh writes a map named `.gz`).
pub fn read_map_tables(vertex_map: Option<&Path>, face_map: Option<&Path>) -> Result<MapTables, CheckError> {
    let table = |path: &Path| {
        let bytes = crate::io::read_bytes(path).map_err(|source| CheckError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        match crate::io::formats::maybe_gunzip(&bytes, 16 << 30) {
            Ok(std::borrow::Cow::Borrowed(_)) => Ok(bytes),
            Ok(std::borrow::Cow::Owned(inflated)) => Ok(inflated),
            Err(e) => Err(CheckError::Parse {
                path: path.to_path_buf(),
                format: "gzip",
                reason: e.to_string(),
            }),
        }
    };
    Ok(MapTables {
        vertex: vertex_map.map(table).transpose()?,
        face: face_map.map(table).transpose()?,
    })
}

/// [`check_map_files`] on files already read: `original` and `output` as they list their
/// vertices and faces (as [`crate::check::check_files_with`] hands them over), whether the
/// output's faces share vertices by index (not an STL, which is refused: see
/// [`check_map_files`]), the output's path (for that error) and the maps' `tables`.
pub fn check_maps_of(
    original: &RawMesh,
    output: &RawMesh,
    shares_vertices: bool,
    output_path: &Path,
    tables: &MapTables,
    weld_tolerance: f64,
) -> Result<(Option<MapReport>, Option<MapReport>), CheckError> {
    if !shares_vertices {
        return Err(CheckError::Unjudgeable {
            path: output_path.to_path_buf(),
            reason: "an STL output has no vertex list and rounds coordinates to f32: its maps cannot be judged (write OBJ, OFF or PLY)".into(),
        });
    }
    // The two maps are judged at once when both are large enough to repay a thread.
    let worth_it = tables.vertex.is_some() && tables.face.is_some() && output.indices.len() >= 3 * PARALLEL_FACES;
    Ok(crate::parallel::join(
        worth_it,
        || (tables.vertex.as_ref()).map(|t| check_vertex_map(original, output, t)),
        || (tables.face.as_ref()).map(|t| check_face_map(original, output, t, weld_tolerance)),
    ))
}

/// The rows of a map's text after its header (lines, numbered from 2); `None` and a failure
/// when the text is not UTF-8 or its header is not `header`.
fn rows<'t>(
    what: &str,
    text: &'t [u8],
    header: &str,
    failures: &mut Failures,
) -> Option<impl Iterator<Item = (usize, &'t str)>> {
    let Ok(text) = std::str::from_utf8(text) else {
        failures.push("map", || format!("{what}: not UTF-8 text"));
        return None;
    };
    let mut lines = text.lines();
    let first = lines.next().unwrap_or("");
    if first.trim_end() != header {
        failures.push("map", || {
            format!(
                "{what}: its first line is '{}', not the header '{header}'",
                first.chars().take(80).collect::<String>()
            )
        });
        return None;
    }
    Some(lines.enumerate().map(|(i, line)| (i + 2, line.trim_end())))
}

/// The `N` cells after the output index of `text`, row `k` of map `what` (on line `line`), its
/// output `noun` (vertex or face) numbered `k`; `None` and a failure when it has another count
/// of cells or another number.
fn row<'t, const N: usize>(
    what: &str,
    noun: &str,
    k: usize,
    line: usize,
    text: &'t str,
    failures: &mut Failures,
) -> Option<[&'t str; N]> {
    let mut split = text.split(',');
    let index = split.next().unwrap_or("");
    let mut cells = [""; N];
    let mut n = 0;
    for cell in split {
        if n < N {
            cells[n] = cell;
        }
        n += 1;
    }
    if n != N {
        failures.push("row", || format!("{what} line {line}: {} cells, not {}", n + 1, N + 1));
        return None;
    }
    if index.parse::<usize>().ok() != Some(k) {
        failures.push("row number", || {
            format!("{what} line {line}: output_index {index}, not {k} (one row per output {noun}, in order)")
        });
        return None;
    }
    Some(cells)
}

/// An index cell: a vertex or face number below `count`.
fn index(cell: &str, count: usize) -> Option<usize> {
    cell.parse::<usize>().ok().filter(|&i| i < count)
}

fn point(p: [f64; 3]) -> String {
    crate::io::number::point_text(DVec3::from_array(p))
}

/// Checks the vertex map `text` of the run that read `original` and wrote `output`.
pub fn check_vertex_map(original: &RawMesh, output: &RawMesh, text: &[u8]) -> MapReport {
    const WHAT: &str = "vertex map";
    let mut failures = Failures::default();
    let Some(rows) = rows(WHAT, text, VERTEX_MAP_HEADER, &mut failures) else {
        return MapReport {
            failures: failures.finish(),
            ..MapReport::default()
        };
    };
    // The first vertex the file defines at each position (-0 and 0 alike).
    let mut first = FastMap::default();
    for (i, p) in original.positions.iter().enumerate() {
        first.entry(crate::hash::position_key(*p)).or_insert(i);
    }
    let n = original.positions.len();
    let out = &output.positions;
    let mut count = 0;
    for (k, (line, text)) in rows.enumerate() {
        count += 1;
        let Some([a, b, t]) = row(WHAT, "vertex", k, line, text, &mut failures) else {
            continue;
        };
        let (Some(a), Some(b)) = (index(a, n), index(b, n)) else {
            failures.push("vertex number", || {
                format!("{WHAT} line {line}: input vertex {a} or {b} is not one of the input's {n} (from 0)")
            });
            continue;
        };
        let t = match t.parse::<f64>() {
            Ok(t) if (a == b && t == 0.0) || (a != b && t > 0.0 && t < 1.0) => t,
            _ => {
                failures.push("parameter", || {
                    format!("{WHAT} line {line}: t = {t} (0 for an input vertex, a = b; strictly between 0 and 1 for one added between a and b)")
                });
                continue;
            }
        };
        for v in [a, b] {
            let p = original.positions[v];
            let earlier = first.get(&crate::hash::position_key(p)).copied();
            if earlier.is_some_and(|e| e != v) {
                failures.push("first definition", || {
                    format!(
                        "{WHAT} line {line}: input vertex {v} at {} is defined before as vertex {} (the map names the first)",
                        point(p),
                        earlier.unwrap_or(v)
                    )
                });
            }
        }
        let Some(&q) = out.get(k) else {
            continue; // (Counted below.)
        };
        let (pa, pb) = (original.positions[a], original.positions[b]);
        let want: [f64; 3] = std::array::from_fn(|c| pa[c] + t * (pb[c] - pa[c]));
        if want != q {
            failures.push("vertex position", || {
                format!(
                    "{WHAT} line {line}: output vertex {k} is at {}, but a + t·(b − a) is {}",
                    point(q),
                    point(want)
                )
            });
        }
    }
    if count != out.len() {
        failures.push("row count", || {
            format!("{WHAT}: {count} rows for the output's {} vertices", out.len())
        });
    }
    MapReport {
        rows: count,
        not_inside: 0,
        failures: failures.finish(),
    }
}

/// Checks the face map `text` of the run that read `original` (with `--repair
/// --weld-tolerance weld_tolerance`, or 0) and wrote `output`.
pub fn check_face_map(original: &RawMesh, output: &RawMesh, text: &[u8], weld_tolerance: f64) -> MapReport {
    const WHAT: &str = "face map";
    let mut failures = Failures::default();
    let Some(rows) = rows(WHAT, text, FACE_MAP_HEADER, &mut failures) else {
        return MapReport {
            failures: failures.finish(),
            ..MapReport::default()
        };
    };
    let faces = original.face_start.len().saturating_sub(1);
    let output_faces = output.face_start.len().saturating_sub(1);
    // The corners of face `f` of `mesh`, into `out`.
    let polygon = |mesh: &RawMesh, f: usize, out: &mut Vec<DVec3>| {
        let corners = &mesh.indices[mesh.face_start[f] as usize..mesh.face_start[f + 1] as usize];
        out.clear();
        out.extend(corners.iter().map(|&v| DVec3::from_array(mesh.positions[v as usize])));
    };
    // Where a weld moved the input's vertices, each cut triangle's corners go with them.
    let moved = (weld_tolerance > 0.0).then(|| welded(&original.positions, weld_tolerance));
    // Rounding: of the input's size, and of its coordinates' magnitude (a small part far from
    // the origin).
    let (lo, hi) = (original.positions.iter())
        .map(|&p| DVec3::from_array(p))
        .filter(|p| p.is_finite())
        .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
    let (size, magnitude) = if lo.x <= hi.x {
        ((hi - lo).length(), lo.abs().max(hi.abs()).max_element())
    } else {
        (0.0, 0.0)
    };
    let rounding = ROUNDING * size + 64.0 * f64::EPSILON * magnitude;
    // The triangles of an input face, as its file's polygon is cut (as the construction and
    // the mesh check cut it): a polygon's found once.
    let mut pieces = Vec::new();
    let mut polygons = FastMap::<usize, Pieces>::default();
    let mut corners = Vec::new();
    let mut not_inside = 0;
    let mut count = 0;
    for (k, (line, text)) in rows.enumerate() {
        count += 1;
        let Some([f, inside]) = row(WHAT, "face", k, line, text, &mut failures) else {
            continue;
        };
        let Some(f) = index(f, faces) else {
            failures.push("face number", || {
                format!("{WHAT} line {line}: input face {f} is not one of the input's {faces} (from 0)")
            });
            continue;
        };
        let inside = match inside {
            "1" => true,
            "0" => false,
            _ => {
                failures.push("row", || {
                    format!("{WHAT} line {line}: inside is '{inside}', not 0 or 1")
                });
                continue;
            }
        };
        if !inside {
            not_inside += 1;
        }
        if k >= output_faces {
            continue; // (Counted below.)
        }
        let corner_ids = &original.indices[original.face_start[f] as usize..original.face_start[f + 1] as usize];
        let triangle;
        let (triangles, grid): (&[[DVec3; 3]], _) = if let &[a, b, c] = corner_ids {
            // (A triangle as it is, or where the weld moved its corners: nothing to keep.)
            let at =
                |v: u32| DVec3::from_array(moved.as_ref().map_or(original.positions[v as usize], |m| m[v as usize]));
            triangle = [at(a), at(b), at(c)];
            (std::slice::from_ref(&triangle), None)
        } else {
            let pieces = polygons.entry(f).or_insert_with(|| {
                let triangles = cut(original, f, moved.as_deref(), &mut pieces);
                let grid = PieceGrid::new(&triangles, rounding);
                Pieces { triangles, grid }
            });
            (&pieces.triangles[..], pieces.grid.as_ref())
        };
        let on = |p: DVec3, slack: f64, t: [DVec3; 3]| {
            let [a, b, c] = t;
            let side = (b - a).length().max((c - b).length()).max((a - c).length());
            on_triangle(p, t, rounding + slack * side)
        };
        let on_face = |p: DVec3, slack: f64| match grid {
            Some(grid) => grid.near(p).any(|i| on(p, slack, triangles[i as usize])),
            None => triangles.iter().any(|&t| on(p, slack, t)),
        };
        polygon(output, k, &mut corners);
        let centroid = corners.iter().sum::<DVec3>() / corners.len() as f64;
        if !on_face(centroid, CENTROID_SLACK) {
            failures.push("face centroid", || {
                format!(
                    "{WHAT} line {line}: output face {k}'s centroid {} is not on input face {f}",
                    crate::io::number::point_text(centroid)
                )
            });
            continue;
        }
        if inside {
            if let Some(&off) = corners.iter().find(|&&p| !on_face(p, 0.0)) {
                failures.push("inside", || {
                    format!(
                        "{WHAT} line {line}: output face {k} is said inside input face {f}, but its corner {} is off it",
                        crate::io::number::point_text(off)
                    )
                });
                continue;
            }
        }
    }
    if count != output_faces {
        failures.push("row count", || {
            format!("{WHAT}: {count} rows for the output's {output_faces} faces")
        });
    }
    MapReport {
        rows: count,
        not_inside,
        failures: failures.finish(),
    }
}

/// A polygon's triangles, as [`cut`] gives them, and for a large one a grid to find those
/// near a point.
struct Pieces {
    triangles: Vec<[DVec3; 3]>,
    grid: Option<PieceGrid>,
}

/// The triangles of a large polygon by grid cell: each listed in every cell its bounding box
/// meets, grown by more than the farthest a point on it can be ([`on_triangle`]'s tolerance,
/// `rounding` plus [`CENTROID_SLACK`] of its longest side). So the triangles a point is on
/// are among those of its cell, and judging a polygon's faces costs about their number, not
/// its square (a 2,000-gon's face map took 1.7 s). A triangle without a normal (no area),
/// which [`on_triangle`] takes every point to be on, is in every cell's list.
struct PieceGrid {
    /// Where the cells are.
    cells: Cells,
    /// Where each cell's triangles start in `items` (one more entry than cells).
    start: Vec<u32>,
    /// The triangles (numbers in the polygon's list), cell by cell.
    items: Vec<u32>,
    /// The triangles without a normal.
    everywhere: Vec<u32>,
}

/// The cells of a [`PieceGrid`]: boxes of equal size from a corner, numbered x fastest.
struct Cells {
    /// The grown boxes' corner of least coordinates.
    low: DVec3,
    /// Cells per unit of length, along each axis.
    scale: DVec3,
    /// Cells along each axis.
    dims: [usize; 3],
}

impl PieceGrid {
    /// A grid over `triangles` if there are more than a few, about one cell per triangle
    /// across the polygon's two widest extents.
    fn new(triangles: &[[DVec3; 3]], rounding: f64) -> Option<PieceGrid> {
        if triangles.len() < 32 {
            return None;
        }
        let grown: Vec<(DVec3, DVec3)> = (triangles.iter())
            .map(|&[a, b, c]| {
                let side = (b - a).length().max((c - b).length()).max((a - c).length());
                let magnitude = a.abs().max(b.abs()).max(c.abs()).max_element();
                let margin = 2.0 * (rounding + CENTROID_SLACK * side) + 8.0 * f64::EPSILON * magnitude;
                (
                    a.min(b).min(c) - DVec3::splat(margin),
                    a.max(b).max(c) + DVec3::splat(margin),
                )
            })
            .collect();
        if !grown.iter().all(|(lo, hi)| lo.is_finite() && hi.is_finite()) {
            return None;
        }
        let low = grown.iter().fold(DVec3::splat(f64::INFINITY), |m, b| m.min(b.0));
        let high = grown.iter().fold(DVec3::splat(f64::NEG_INFINITY), |m, b| m.max(b.1));
        let extent = high - low;
        let mut widths = extent.to_array();
        widths.sort_by(f64::total_cmp);
        let cell = (widths[1] * widths[2] / triangles.len() as f64)
            .sqrt()
            .max(widths[2] / 1024.0);
        if !(cell > 0.0 && cell.is_finite()) {
            return None;
        }
        let dims = extent.to_array().map(|e| ((e / cell).ceil() as usize).clamp(1, 1024));
        let scale = DVec3::from_array([0, 1, 2].map(|k| dims[k] as f64 / extent[k].max(f64::MIN_POSITIVE)));
        let cells = Cells { low, scale, dims };
        let has_normal = |&[a, b, c]: &[DVec3; 3]| (b - a).cross(c - a).normalize_or_zero() != DVec3::ZERO;
        let mut count = vec![0u32; dims[0] * dims[1] * dims[2] + 1];
        let mut everywhere = Vec::new();
        for (i, (t, b)) in triangles.iter().zip(&grown).enumerate() {
            if !has_normal(t) {
                everywhere.push(i as u32);
                continue;
            }
            cells.for_each_cell(b.0, b.1, |c| count[c + 1] += 1);
        }
        for c in 1..count.len() {
            count[c] += count[c - 1];
        }
        let mut items = vec![0u32; count[count.len() - 1] as usize];
        let mut next = count.clone();
        for (i, (t, b)) in triangles.iter().zip(&grown).enumerate() {
            if has_normal(t) {
                cells.for_each_cell(b.0, b.1, |c| {
                    items[next[c] as usize] = i as u32;
                    next[c] += 1;
                });
            }
        }
        Some(PieceGrid {
            cells,
            start: count,
            items,
            everywhere,
        })
    }

    /// The triangles that `p` may be on: those of its cell (none outside the grid) and
    /// those without a normal.
    fn near(&self, p: DVec3) -> impl Iterator<Item = u32> + '_ {
        let here = self.cells.containing(p).map_or(&[][..], |c| {
            &self.items[self.start[c] as usize..self.start[c + 1] as usize]
        });
        here.iter().chain(&self.everywhere).copied()
    }
}

impl Cells {
    /// The cell along each axis of `p`, clamped to the grid.
    fn cell_of(&self, p: DVec3) -> [usize; 3] {
        let q = (p - self.low) * self.scale;
        [0, 1, 2].map(|k| (q[k].max(0.0) as usize).min(self.dims[k] - 1))
    }

    /// The number of the cell with these indices along each axis.
    fn number(&self, [x, y, z]: [usize; 3]) -> usize {
        (z * self.dims[1] + y) * self.dims[0] + x
    }

    /// The number of the cell holding `p`; `None` outside the grid.
    fn containing(&self, p: DVec3) -> Option<usize> {
        let high = self.low + DVec3::from_array([0, 1, 2].map(|k| self.dims[k] as f64)) / self.scale;
        let inside = p.cmpge(self.low).all() && p.cmple(high).all();
        inside.then(|| self.number(self.cell_of(p)))
    }

    /// Calls `f` with the number of every cell the box from `lo` to `hi` meets.
    fn for_each_cell(&self, lo: DVec3, hi: DVec3, mut f: impl FnMut(usize)) {
        let ([x0, y0, z0], [x1, y1, z1]) = (self.cell_of(lo), self.cell_of(hi));
        for z in z0..=z1 {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    f(self.number([x, y, z]));
                }
            }
        }
    }
}

/// The triangles of face `f` of `original`, as the construction reads it: a polygon cut as
/// [`triangulate`] cuts it, after leaving out each corner at the position of the corner kept
/// before it (around the outline: what `--repair` reads a polygon that passes a point twice
/// so as), and each corner then at its position in `moved` (the positions a weld gave the
/// vertices) if given.
fn cut(original: &RawMesh, f: usize, moved: Option<&[[f64; 3]]>, pieces: &mut Vec<[usize; 3]>) -> Vec<[DVec3; 3]> {
    let corners = &original.indices[original.face_start[f] as usize..original.face_start[f + 1] as usize];
    let at = |v: u32| original.positions[v as usize];
    // (As the construction's reader: the outline only where it keeps three corners.)
    let mut outline = Vec::with_capacity(corners.len());
    crate::io::polygon::without_repeated_corners(corners, &original.positions, &mut outline);
    if outline.len() < 3 {
        outline.clear();
        outline.extend_from_slice(corners);
    }
    triangulate(outline.len(), |c| at(outline[c]), pieces);
    let position = |v: u32| DVec3::from_array(moved.map_or(at(v), |m| m[v as usize]));
    pieces.iter().map(|t| t.map(|c| position(outline[c]))).collect()
}

/// `positions` as `--repair --weld-tolerance tolerance` moves them: vertices joined by chains of
/// distances below `tolerance` (a cluster) all take the position of the cluster's first vertex.
fn welded(positions: &[[f64; 3]], tolerance: f64) -> Vec<[f64; 3]> {
    if tolerance == f64::INFINITY {
        return vec![positions.first().copied().unwrap_or_default(); positions.len()];
    }
    // Cells twice the tolerance wide (wider where coordinates are so large that their quotients
    // would lose integers): points closer than it are then, even rounded, in one cell or two
    // adjacent ones.
    let largest = positions.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut width = (2.0 * tolerance).max(largest * 2f64.powi(-50));
    if !width.is_finite() {
        width = f64::MAX;
    }
    let mut cells: FastMap<[i64; 3], Vec<u32>> = FastMap::default();
    for (i, p) in positions.iter().enumerate() {
        cells
            .entry(p.map(|x| (x / width).floor() as i64))
            .or_default()
            .push(i as u32);
    }
    let mut sets = super::UnionFind::new(positions.len());
    let near = |a: u32, b: u32| {
        let (p, q) = (positions[a as usize], positions[b as usize]);
        (0..3).map(|k| (p[k] - q[k]) * (p[k] - q[k])).sum::<f64>() < tolerance * tolerance
    };
    for (key, here) in &cells {
        for offset in (0..27).map(|o| [o / 9 - 1, o / 3 % 3 - 1, o % 3 - 1]) {
            let neighbour = [0, 1, 2].map(|k| key[k].wrapping_add(offset[k]));
            let Some(there) = cells.get(&neighbour) else {
                continue;
            };
            for &a in here {
                for &b in there.iter().filter(|&&b| b > a) {
                    if near(a, b) {
                        sets.union(a, b);
                    }
                }
            }
        }
    }
    // (Sets are rooted anywhere: the first vertex of each is found in order.)
    let mut first = vec![u32::MAX; positions.len()];
    (0..positions.len() as u32)
        .map(|v| {
            let root = sets.find(v) as usize;
            if first[root] == u32::MAX {
                first[root] = v;
            }
            positions[first[root] as usize]
        })
        .collect()
}

/// Whether `p` lies on triangle `t` within `tol`: near one of its sides (segment distances,
/// which needles do not upset), or over its inside (the signs of the sub-triangles' normals
/// along its own) and near its plane.
fn on_triangle(p: DVec3, t: [DVec3; 3], tol: f64) -> bool {
    // (Over the inside first: most points asked about are.)
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let over = (0..3).all(|k| (t[(k + 1) % 3] - t[k]).cross(p - t[k]).dot(n) >= 0.0);
    if over && (p - t[0]).dot(n.normalize_or_zero()).abs() <= tol {
        return true;
    }
    (0..3).any(|k| {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let e = b - a;
        let s = ((p - a).dot(e) / e.length_squared()).clamp(0.0, 1.0);
        let s = if s.is_finite() { s } else { 0.0 };
        (a + s * e).distance(p) <= tol
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grid finds every triangle a point is on: for points on, near and off the triangles
    /// of polygons cut into fans and into their Delaunay triangulations (tilted ovals, flat
    /// and off any axis, with a needle and a triangle of no area among them), the triangles
    /// of the point's cell say what all of them say, with either slack.
    #[test]
    fn the_grid_finds_what_testing_every_triangle_finds() {
        let mut rng = crate::test_rng::Rng(62);
        let (mut on, mut off) = (0, 0);
        for n in [40, 300, 1000] {
            let (s, c) = 0.4f64.sin_cos();
            let corners: Vec<[f64; 3]> = (0..n)
                .map(|i| {
                    let a = i as f64 * std::f64::consts::TAU / n as f64;
                    let [x, y] = [5.0 * a.cos(), a.sin()];
                    [x * c, y, x * s + 100.0]
                })
                .collect();
            let fan: Vec<[usize; 3]> = (1..n - 1).map(|i| [0, i, i + 1]).collect();
            let mut cut = Vec::new();
            triangulate(n, |i| corners[i], &mut cut);
            let mut with_no_area = cut.clone();
            with_no_area.push([3, 3, 7]); // (on_triangle takes every point to be on it)
            for pieces in [fan, cut, with_no_area] {
                let triangles: Vec<[DVec3; 3]> = (pieces.iter())
                    .map(|t| t.map(|i| DVec3::from_array(corners[i])))
                    .collect();
                let rounding = ROUNDING * 10.0;
                let grid = PieceGrid::new(&triangles, rounding).unwrap();
                let on_with = |p: DVec3, slack: f64, t: [DVec3; 3]| {
                    let side = (t[1] - t[0])
                        .length()
                        .max((t[2] - t[1]).length())
                        .max((t[0] - t[2]).length());
                    on_triangle(p, t, rounding + slack * side)
                };
                for _ in 0..1500 {
                    let t = triangles[rng.below(triangles.len() as u64) as usize];
                    let (u, v) = match rng.below(3) {
                        // At a corner (on the outline's extremes, past the grid's box
                        // unless it is grown), or anywhere.
                        0 => [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)][rng.below(3) as usize],
                        _ => (rng.centered() + 0.5, rng.centered() + 0.5),
                    };
                    let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
                    let scale = [0.0, 1e-9, 1e-6, 1e-2][rng.below(4) as usize];
                    let jitter = DVec3::new(rng.centered(), rng.centered(), rng.centered()) * scale;
                    let p = t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]) + jitter;
                    for slack in [0.0, CENTROID_SLACK] {
                        let all = triangles.iter().any(|&t| on_with(p, slack, t));
                        let near = grid.near(p).any(|i| on_with(p, slack, triangles[i as usize]));
                        assert_eq!(near, all, "{n}: {p}");
                        (on, off) = if all { (on + 1, off) } else { (on, off + 1) };
                    }
                }
                assert!(grid.near(DVec3::splat(1e6)).all(|i| grid.everywhere.contains(&i)));
            }
        }
        assert!(on > 1000 && off > 1000, "{on} {off}");
    }
}
