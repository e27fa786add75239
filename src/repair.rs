//! Mesh repair: turns a triangle soup into a manifold, consistently oriented triangle mesh
//! without degenerate faces, without moving any point.
//!
//! Repair only ever
//! * **welds** vertices (merges vertices at the same position, or closer than a tolerance),
//! * **removes** faces that use a vertex twice, have exactly zero area, or repeat an earlier face,
//! * **reorients** faces (reverses their corner order),
//! * **duplicates** vertices (new vertex ids at the same position) to cut non-manifold edges and
//!   vertices apart.
//!
//! With the default exact welding no point moves and every surviving face keeps its geometry.
//!
//! # How it works
//! 1. *Weld* ([`RepairOptions::weld_tolerance`]): every vertex is mapped to a representative, the
//!    lowest input index of its cluster.
//! 2. *Filter faces*: drop faces with a repeated vertex, then faces whose corners are exactly
//!    collinear (exact `orient2d` on the three coordinate-plane projections, [`crate::geometry::collinear`]), then
//!    faces with the same vertex set as an earlier face (either orientation; the first is kept).
//! 3. *Pair faces across edges*: faces sharing an undirected edge are grouped. Two faces on an
//!    edge are glued together; on an edge with more than two faces (a non-manifold edge) the faces
//!    are sorted by angle around the edge and glued in pairs of angular neighbours, so glued
//!    sheets never cross each other; of the possible pairings the one with the most oppositely
//!    oriented pairs wins, then the one with the fewest pairs of faces lying on each other (ties:
//!    the odd face out is the one with the highest index, or the lowest-index face is paired with
//!    its lower-index neighbour). Faces lying on each other (one direction around the edge, as
//!    the two sheets of a flat two-sided plate at an inner edge) are ordered so that each sheet
//!    is glued on to its own continuation, not folded back onto the other sheet. Every pair
//!    beyond the first ends up on its own copies of the edge's vertices.
//! 4. *Orient*: each component (faces connected through glued edges) is walked breadth-first from
//!    its lowest-index face, flipping faces to agree with the faces they are glued to. A glued edge
//!    whose two faces still disagree when the walk reaches it from both sides proves the component
//!    non-orientable (a Möbius band); it is unglued (cut). Finally a closed component is turned to
//!    have positive signed volume (outward normals; the volume is summed in floating point), and
//!    an open one (or one of zero volume) keeps the orientation of the majority of its input faces
//!    (ties: that of its lowest-index face).
//! 5. *Split vertices*: the corners of a vertex are grouped into fans (corners of faces glued
//!    across an edge at that vertex share their vertex); every fan becomes its own output vertex.
//!    Where two distinct glued edges would still end up with the same two output vertices (only
//!    possible next to a cut), the faces of the later one are detached from their other glued
//!    neighbours at one endpoint, giving them their own copy of it.
//! 6. *Compact*: vertices used by no face are dropped; output vertices are sorted by the input
//!    vertex they come from, copies right after their original.
//!
//! Everything is linear or `O(n log n)` in the input size (the tolerance weld has a caveat, see
//! [`RepairOptions::weld_tolerance`]), without recursion. Most scans need steps 1, 2 and 6 only:
//! [`repair_with_topology`] learns that by building the result's connectivity straight after
//! step 2, and hands it on, so that refining does not build it again (the Stanford dragon's
//! 871,414 faces: reading and building 0.71 s before, 0.53 s with it).

use crate::mesh::{EdgeId, Topology};
use crate::union_find::UnionFind;
use std::collections::HashMap;
use std::hash::{Hash, Hasher};

/// "No partner" / "not assigned" marker for index arrays. Corner and face-edge indices are below
/// `3 * triangles.len() <= u32::MAX`, so it is never a valid index.
const NONE: u32 = u32::MAX;

/// The largest number of triangles [`repair`] accepts: corner indices must fit in `u32`.
const MAX_TRIANGLES: usize = (u32::MAX / 3) as usize;

/// Options of [`repair`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RepairOptions {
    /// Weld distance. `0.0` (the default) welds only vertices with exactly equal coordinates
    /// (compared as numbers, so `-0.0` equals `0.0`): no point moves.
    ///
    /// A positive tolerance also welds vertices closer than the tolerance: `dx² + dy² + dz² <
    /// tolerance²`, evaluated in `f64`. Welding is transitive: clusters are the connected
    /// components of the "closer than the tolerance" relation, so a chain of close vertices can
    /// merge vertices farther apart than the tolerance. Every vertex of a cluster takes the
    /// position of the cluster's lowest-index vertex, so faces touching a welded vertex may move
    /// by up to the cluster's extent. The search is linear while a tolerance-sized neighbourhood
    /// holds few vertices (the intended use: closing cracks left by rounding); a tolerance far
    /// above the vertex spacing makes it quadratic in the vertices per neighbourhood.
    /// [`repair`] itself treats a negative or NaN tolerance as `0.0` and welds all vertices
    /// with an infinite one; [`crate::io::read_mesh`] refuses all three, as the command line
    /// does ([`RepairOptions::validate`]).
    pub weld_tolerance: f64,
}

/// Whether `x` is a weld distance ([`RepairOptions::weld_tolerance`]) that the readers and the
/// command line's `--weld-tolerance` accept: finite, 0 or more.
pub fn is_weld_distance(x: f64) -> bool {
    x.is_finite() && x >= 0.0
}

impl RepairOptions {
    /// What a weld tolerance must be, as messages say it.
    pub const WELD_TOLERANCE_RANGE: &'static str = "a distance (a finite number, 0 or more)";

    /// Refuses a weld tolerance that is NaN, negative or infinite ([`is_weld_distance`]) with
    /// [`crate::Error::Setting`].
    pub fn validate(&self) -> crate::Result<()> {
        if is_weld_distance(self.weld_tolerance) {
            Ok(())
        } else {
            Err(crate::Error::Setting {
                name: "weld tolerance",
                value: self.weld_tolerance,
                expected: Self::WELD_TOLERANCE_RANGE,
            })
        }
    }
}

/// What [`repair`] changed, by kind.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RepairReport {
    /// Input vertices merged into another (lower-index) vertex at the same or a close position.
    pub welded_vertices: usize,
    /// Welded vertices that moved as far as the tolerance or farther: welding chains (see
    /// [`RepairOptions::weld_tolerance`]), and these say the tolerance is not small beside the
    /// mesh's own detail.
    pub chained_vertices: usize,
    /// Faces dropped because they use a vertex twice (after welding).
    pub repeated_vertex_faces: usize,
    /// Faces dropped because their three corners are exactly collinear.
    pub zero_area_faces: usize,
    /// Faces dropped because an earlier face has the same vertex set (either orientation).
    pub duplicate_faces: usize,
    /// Faces whose orientation was reversed.
    pub reoriented_faces: usize,
    /// Edges shared by more than two faces, cut apart into manifold edges.
    pub non_manifold_edges: usize,
    /// Vertices whose faces formed several edge-connected fans, split into one vertex per fan.
    /// Vertices copied only because a non-manifold edge or an orientation cut runs through them
    /// are not counted here.
    pub non_manifold_vertices: usize,
    /// Edges cut because the component around them is not orientable (Möbius-like).
    pub orientation_cuts: usize,
    /// Input vertices (not welded into another) used by no remaining face; they are dropped.
    pub unreferenced_vertices: usize,
    /// Polygons of the file (more than three corners) that pass through a point twice, such as
    /// a hole's outline joined to the outer one by a bridge (a keyhole): triangulated as the
    /// outline they trace. Without `--repair` such a face is refused. Counted by the reader
    /// ([`crate::io`]), not by [`repair`], which sees triangles only.
    pub keyhole_polygons: usize,
    /// Corners of polygons (more than three corners) dropped because they lie at the position
    /// of the corner before them (`f 1 2 2 3`): the polygon is triangulated as the outline the
    /// others trace. Counted by the reader ([`crate::io`]), as `keyhole_polygons`.
    pub repeated_corners: usize,
}

impl RepairReport {
    /// One human-readable line per kind of change that happened, e.g. `"welded 263 vertices"`.
    pub fn lines(&self) -> Vec<String> {
        let kinds: [(usize, &str, &str); 12] = [
            (
                self.repeated_corners,
                "dropped {} polygon corner at the position of the corner before it",
                "dropped {} polygon corners at the position of the corner before them",
            ),
            (
                self.keyhole_polygons,
                "read {} polygon that passes through a point twice as the outline it traces",
                "read {} polygons that pass through a point twice as the outlines they trace",
            ),
            (self.welded_vertices, "welded {} vertex", "welded {} vertices"),
            (
                self.chained_vertices,
                "moved {} vertex as far as the weld tolerance or farther (close vertices chain: a smaller tolerance keeps the shape)",
                "moved {} vertices as far as the weld tolerance or farther (close vertices chain: a smaller tolerance keeps the shape)",
            ),
            (
                self.repeated_vertex_faces,
                "removed {} face with a repeated vertex",
                "removed {} faces with a repeated vertex",
            ),
            (
                self.zero_area_faces,
                "removed {} zero-area face",
                "removed {} zero-area faces",
            ),
            (
                self.duplicate_faces,
                "removed {} duplicate face",
                "removed {} duplicate faces",
            ),
            (self.reoriented_faces, "reoriented {} face", "reoriented {} faces"),
            (
                self.non_manifold_edges,
                "cut {} non-manifold edge",
                "cut {} non-manifold edges",
            ),
            (
                self.non_manifold_vertices,
                "split {} non-manifold vertex",
                "split {} non-manifold vertices",
            ),
            (
                self.orientation_cuts,
                "cut {} edge to orient a non-orientable surface",
                "cut {} edges to orient non-orientable surfaces",
            ),
            (
                self.unreferenced_vertices,
                "dropped {} unreferenced vertex",
                "dropped {} unreferenced vertices",
            ),
        ];
        kinds
            .iter()
            .filter(|(count, _, _)| *count > 0)
            .map(|&(count, one, many)| {
                let template = if count == 1 { one } else { many };
                template.replace("{}", &count.to_string())
            })
            .collect()
    }

    /// True when repair changed nothing at all.
    pub fn is_clean(&self) -> bool {
        *self == RepairReport::default()
    }
}

/// The repaired mesh, with where each part came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Repaired {
    /// Output vertex positions, each bit-identical to the position of its source vertex's
    /// representative (the lowest-index vertex it was welded with).
    pub positions: Vec<[f64; 3]>,
    /// Output triangles: manifold, consistently oriented, non-degenerate, without duplicates.
    pub triangles: Vec<[u32; 3]>,
    /// For each output vertex, the input vertex it comes from (a weld representative).
    /// Non-decreasing: output vertices keep the input order of their sources.
    pub source_vertex: Vec<u32>,
    /// For each output triangle, the input triangle it comes from. Increasing.
    pub source_triangle: Vec<u32>,
    /// For each output triangle, whether it was reoriented: its corners are then those of its
    /// source triangle in the order 0, 2, 1, else in the order 0, 1, 2.
    pub flipped: Vec<bool>,
    /// What was changed.
    pub report: RepairReport,
}

/// Repairs a triangle mesh; see the [module documentation](self) for the steps and rules.
///
/// Preconditions: every index in `triangles` is less than `positions.len()` and every coordinate
/// is finite. Under them, the result satisfies:
/// 1. every triangle has three distinct vertices and non-zero area (exactly);
/// 2. no two triangles have the same vertex set;
/// 3. every edge has at most two triangles, and two triangles traverse it in opposite directions;
/// 4. the triangles around every vertex form a single edge-connected fan;
/// 5. every position is bit-identical to an input position; every vertex is used;
/// 6. the triangles are exactly the input triangles minus the dropped ones (possibly flipped).
///
/// # Panics
/// If `positions.len()` exceeds `u32::MAX`, `triangles.len()` exceeds `u32::MAX / 3`, or an index
/// is out of range.
pub fn repair(positions: &[[f64; 3]], triangles: &[[u32; 3]], options: &RepairOptions) -> Repaired {
    let (report, rep, faces) = weld_and_filter(positions, triangles, options);
    repair_faces(positions, &rep, faces, report)
}

/// As [`repair`] (the same result, bit for bit), and also the connectivity of the result when
/// building it was part of the work: when the faces left by steps 1 and 2 already form a
/// manifold, consistently oriented mesh whose closed components face outwards, steps 3 to 5
/// change nothing, and building the connectivity ([`Topology::from_triangles`], whose checks
/// are exactly those conditions) is the cheapest way to learn it. A mesh that needs more is
/// repaired in full, and the connectivity built on the way is wasted.
///
/// # Panics
/// As [`repair`].
pub fn repair_with_topology(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    options: &RepairOptions,
) -> (Repaired, Option<Topology>) {
    let (report, rep, faces) = weld_and_filter(positions, triangles, options);
    match unchanged_topology(positions, &rep, &faces, &report) {
        Some((repaired, topology)) => (repaired, Some(topology)),
        None => (repair_faces(positions, &rep, faces, report), None),
    }
}

/// Step 1 and step 2 but for duplicate faces: the report so far, the weld representatives and
/// the faces left.
fn weld_and_filter(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    options: &RepairOptions,
) -> (RepairReport, Vec<u32>, Faces) {
    assert!(
        u32::try_from(positions.len()).is_ok(),
        "repair: more than u32::MAX vertices"
    );
    assert!(
        triangles.len() <= MAX_TRIANGLES,
        "repair: more than {MAX_TRIANGLES} triangles"
    );
    let mut report = RepairReport::default();
    let rep = weld(positions, options.weld_tolerance);
    report.welded_vertices = rep.iter().enumerate().filter(|&(i, &r)| r as usize != i).count();
    report.chained_vertices = chained(positions, &rep, options.weld_tolerance);
    let faces = filter_faces(positions, triangles, &rep, &mut report);
    (report, rep, faces)
}

/// The rest of step 2 (duplicate faces) and steps 3 to 6.
fn repair_faces(positions: &[[f64; 3]], rep: &[u32], candidates: Faces, mut report: RepairReport) -> Repaired {
    // Two pieces of independent work at a time on large meshes. Duplicate faces are rare, so the
    // edges are grouped while they are searched for, and grouped again only if some are found.
    let n = positions.len();
    let worth_it = candidates.verts.len() >= crate::parallel::MIN_PARALLEL_ITEMS;
    let (duplicate, groups) = crate::parallel::join(
        worth_it,
        || find_duplicates(&candidates.verts, n),
        || EdgeGroups::build(&candidates.verts, n),
    );
    report.duplicate_faces = duplicate.iter().filter(|&&d| d).count();
    let (faces, groups) = if report.duplicate_faces == 0 {
        (candidates, groups)
    } else {
        drop(groups);
        let faces = candidates.without(&duplicate);
        let groups = EdgeGroups::build(&faces.verts, n);
        (faces, groups)
    };
    let mut partner = pair_faces(positions, &faces.verts, &groups, &mut report);
    let (flip, vertex_corners) = crate::parallel::join(
        worth_it,
        || orient(positions, &faces.verts, &mut partner, &mut report),
        || Csr::from_rows(n, 3 * faces.verts.len(), |c| corner_vertex(&faces.verts, c)),
    );
    let mut classes = separate_parallel_edges(&faces.verts, &groups, &mut partner);
    report.unreferenced_vertices = (0..n)
        .filter(|&v| rep[v] as usize == v && vertex_corners.row(v).is_empty())
        .count();

    assemble(positions, faces, &flip, &vertex_corners, &mut classes, report)
}

/// The output of steps 3 to 6 when they change nothing but the numbering, with the connectivity
/// that shows it (see [`repair_with_topology`]); `None` if they would change more.
///
/// Every referenced representative is then one output vertex, in input order, and every face is
/// kept as it is. The connectivity's own checks find any duplicate face (a second face on each
/// of its edges), edge with more than two faces, disagreeing orientation or vertex of several
/// fans; [`closed_components_face_outwards`] finds a closed component step 4 could turn.
fn unchanged_topology(
    positions: &[[f64; 3]],
    rep: &[u32],
    faces: &Faces,
    report: &RepairReport,
) -> Option<(Repaired, Topology)> {
    let mut new_index = vec![NONE; positions.len()];
    for t in &faces.verts {
        for &v in t {
            new_index[v as usize] = 0;
        }
    }
    let mut out_positions = Vec::new();
    let mut source_vertex = Vec::new();
    let mut unreferenced = 0;
    for (v, index) in new_index.iter_mut().enumerate() {
        if *index == NONE {
            unreferenced += usize::from(rep[v] as usize == v);
        } else {
            *index = ix(out_positions.len());
            out_positions.push(positions[v]);
            source_vertex.push(ix(v));
        }
    }
    let triangles: Vec<[u32; 3]> = faces.verts.iter().map(|t| t.map(|v| new_index[v as usize])).collect();
    drop(new_index);
    let topology = Topology::from_triangles(out_positions.len(), &triangles).ok()?;
    if !closed_components_face_outwards(&out_positions, &triangles, &topology) {
        return None;
    }
    let mut report = report.clone();
    report.unreferenced_vertices = unreferenced;
    let repaired = Repaired {
        positions: out_positions,
        triangles,
        source_vertex,
        flipped: vec![false; faces.source.len()],
        source_triangle: faces.source.clone(),
        report,
    };
    Some((repaired, topology))
}

/// Whether step 4 surely keeps every component of a consistently oriented mesh as it is: an
/// open one always (none of its faces disagree), a closed one unless the signed volume it sums
/// is negative.
///
/// Step 4 sums the volume's terms in the order of its walk; here they are summed in face order,
/// which can round differently, so a volume is only trusted when it is farther from zero than
/// any order's rounding error can carry it (`4 n u` times the sum of the terms' magnitudes, for
/// `n` terms and unit roundoff `u`). Each term is step 4's own, bit for bit (the same origin:
/// the first vertex of the component's lowest face). A volume that is negative, not finite or
/// too close to zero answers `false`, and the full repair decides.
fn closed_components_face_outwards(positions: &[[f64; 3]], triangles: &[[u32; 3]], topology: &Topology) -> bool {
    let n = triangles.len();
    let mut faces = UnionFind::new(n);
    let mut on_boundary = vec![false; n];
    for e in 0..topology.n_edges() {
        let h = EdgeId(ix(e)).halfedge();
        let (f, g) = (topology.face(h), topology.face(h.twin()));
        if f.is_none() {
            on_boundary[g.idx()] = true;
        } else if g.is_none() {
            on_boundary[f.idx()] = true;
        } else {
            faces.union(f.idx(), g.idx());
        }
    }
    // Components numbered by their lowest face (a union-find root), where step 4's walk starts.
    let mut lowest: Vec<usize> = Vec::new();
    let mut component = vec![0u32; n];
    for f in 0..n {
        let root = faces.find(f);
        component[f] = if root == f {
            lowest.push(f);
            ix(lowest.len() - 1)
        } else {
            component[root]
        };
    }
    drop(faces);
    let terms = crate::parallel::map(n, |f| {
        let origin = positions[triangles[lowest[component[f] as usize]][0] as usize];
        volume_term(positions, &triangles[f], &origin)
    });
    // (open, volume, sum of magnitudes, terms) by component
    let mut sums = vec![(false, 0.0f64, 0.0f64, 0usize); lowest.len()];
    for f in 0..n {
        let s = &mut sums[component[f] as usize];
        s.0 |= on_boundary[f];
        s.1 += terms[f];
        s.2 += terms[f].abs();
        s.3 += 1;
    }
    sums.iter().all(|&(open, volume, magnitude, count)| {
        let rounding = 4.0 * count as f64 * (f64::EPSILON / 2.0) * magnitude;
        open || (volume.is_finite() && magnitude.is_finite() && volume > rounding)
    })
}

// ---------------------------------------------------------------------------------------------
// Hashing, union-find and compressed rows

/// Positions as hashable bits, `-0.0` read as `0.0` ([`crate::hash::position_key`]).
#[derive(Clone, Copy, PartialEq, Eq)]
struct PositionKey([u64; 3]);

impl PositionKey {
    fn new(p: &[f64; 3]) -> Self {
        PositionKey(crate::hash::position_key(*p))
    }
}

impl Hash for PositionKey {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.0.iter().for_each(|&w| state.write_u64(w));
    }
}

type FastBuild = crate::hash::FastBuild;

/// Index conversion; `repair` checked that all vertex, corner and face-edge indices fit in `u32`.
fn ix(i: usize) -> u32 {
    i as u32
}

/// Compressed rows: row `r` is `items[start[r]..start[r + 1]]`.
struct Csr {
    start: Vec<usize>,
    items: Vec<u32>,
}

impl Csr {
    /// Buckets `0..n_items` by `row_of`, each row in increasing item order (counting sort).
    fn from_rows(n_rows: usize, n_items: usize, row_of: impl Fn(usize) -> usize) -> Self {
        Csr::from_keyed(n_rows, (0..n_items).map(|i| (row_of(i), ix(i))))
    }

    /// Buckets `(row, item)` pairs by row, keeping their order within a row (counting sort).
    fn from_keyed(n_rows: usize, pairs: impl Iterator<Item = (usize, u32)> + Clone) -> Self {
        let mut start = vec![0usize; n_rows + 1];
        for (row, _) in pairs.clone() {
            start[row + 1] += 1;
        }
        for r in 0..n_rows {
            start[r + 1] += start[r];
        }
        let mut next = start.clone();
        let mut items = vec![0u32; start[n_rows]];
        for (row, item) in pairs {
            items[next[row]] = item;
            next[row] += 1;
        }
        Csr { start, items }
    }

    fn rows(&self) -> usize {
        self.start.len() - 1
    }

    fn row(&self, r: usize) -> &[u32] {
        &self.items[self.start[r]..self.start[r + 1]]
    }

    fn row_mut(&mut self, r: usize) -> &mut [u32] {
        &mut self.items[self.start[r]..self.start[r + 1]]
    }
}

// ---------------------------------------------------------------------------------------------
// Corners and face-edges
//
// Corner `3 * f + k` is corner `k` of face `f`. Face-edge `3 * f + k` runs from corner `k` to
// corner `(k + 1) % 3` of face `f`, in the face's input orientation.

fn corner_vertex(verts: &[[u32; 3]], corner: usize) -> usize {
    verts[corner / 3][corner % 3] as usize
}

/// The (start, end) corners of a face-edge.
fn edge_corners(edge: usize) -> (usize, usize) {
    (edge, 3 * (edge / 3) + (edge % 3 + 1) % 3)
}

/// The (start, end) vertices of a face-edge.
fn edge_vertices(verts: &[[u32; 3]], edge: usize) -> (usize, usize) {
    let (s, t) = edge_corners(edge);
    (corner_vertex(verts, s), corner_vertex(verts, t))
}

/// The (smaller, larger) vertex ids of a face-edge.
fn edge_key(verts: &[[u32; 3]], edge: usize) -> (usize, usize) {
    let (a, b) = edge_vertices(verts, edge);
    (a.min(b), a.max(b))
}

/// The corner of a face-edge that lies at `vertex` (one of its endpoints).
fn edge_corner_at(verts: &[[u32; 3]], edge: usize, vertex: usize) -> usize {
    let (s, t) = edge_corners(edge);
    if corner_vertex(verts, s) == vertex {
        s
    } else {
        t
    }
}

/// The other face-edge of the same face that touches the corner of `edge` at `vertex`.
fn other_edge_at(verts: &[[u32; 3]], edge: usize, vertex: usize) -> usize {
    let face = edge / 3;
    let k = edge % 3;
    if corner_vertex(verts, edge) == vertex {
        3 * face + (k + 2) % 3
    } else {
        3 * face + (k + 1) % 3
    }
}

/// The face vertex that is not on the face-edge.
fn opposite_vertex(verts: &[[u32; 3]], edge: usize) -> usize {
    verts[edge / 3][(edge % 3 + 2) % 3] as usize
}

/// Whether two face-edges on the same undirected edge run in the same direction.
fn same_direction(verts: &[[u32; 3]], a: usize, b: usize) -> bool {
    edge_vertices(verts, a).0 == edge_vertices(verts, b).0
}

// ---------------------------------------------------------------------------------------------
// Step 1: welding

/// Maps every vertex to the lowest-index vertex of its weld cluster.
/// How many vertices welding moved by `tolerance` or more (through a chain of closer ones).
fn chained(positions: &[[f64; 3]], rep: &[u32], tolerance: f64) -> usize {
    if tolerance.is_nan() || tolerance <= 0.0 {
        return 0;
    }
    let moved = |i: usize| {
        let (p, q) = (positions[i], positions[rep[i] as usize]);
        let d2: f64 = (0..3).map(|k| (p[k] - q[k]) * (p[k] - q[k])).sum();
        d2 >= tolerance * tolerance
    };
    (0..positions.len())
        .filter(|&i| rep[i] as usize != i && moved(i))
        .count()
}

fn weld(positions: &[[f64; 3]], tolerance: f64) -> Vec<u32> {
    if tolerance == f64::INFINITY {
        return vec![0; positions.len()];
    }
    let exact = weld_exact(positions);
    if tolerance > 0.0 {
        weld_close(positions, &exact, tolerance)
    } else {
        exact
    }
}

fn weld_exact(positions: &[[f64; 3]]) -> Vec<u32> {
    let mut first: HashMap<PositionKey, u32, FastBuild> =
        HashMap::with_capacity_and_hasher(positions.len(), FastBuild::default());
    positions
        .iter()
        .enumerate()
        .map(|(i, p)| *first.entry(PositionKey::new(p)).or_insert(ix(i)))
        .collect()
}

/// The 13 grid offsets lexicographically greater than (0, 0, 0): each neighbouring cell pair is
/// visited once.
fn forward_offsets() -> impl Iterator<Item = [i64; 3]> {
    (-1..=1i64)
        .flat_map(|x| (-1..=1i64).flat_map(move |y| (-1..=1i64).map(move |z| [x, y, z])))
        .filter(|o| *o > [0, 0, 0])
}

/// Merges the exact-weld representatives closer than `tolerance` (union-find over a grid).
fn weld_close(positions: &[[f64; 3]], exact: &[u32], tolerance: f64) -> Vec<u32> {
    let points = grid_points(positions, exact, tolerance);
    let mut cells: HashMap<[i64; 3], &[GridPoint], FastBuild> = HashMap::default();
    for run in points.chunk_by(|p, q| p.0 == q.0) {
        cells.insert(run[0].0, run);
    }
    let tolerance2 = tolerance * tolerance;
    let mut sets = UnionFind::new(positions.len());
    for (&key, &here) in &cells {
        merge_close(positions, here, here, tolerance2, &mut sets);
        for offset in forward_offsets() {
            let neighbour = [0, 1, 2].map(|k| key[k].wrapping_add(offset[k]));
            if let Some(&there) = cells.get(&neighbour) {
                merge_close(positions, here, there, tolerance2, &mut sets);
            }
        }
    }
    exact.iter().map(|&r| ix(sets.find(r as usize))).collect()
}

/// A grid cell and a vertex in it.
type GridPoint = ([i64; 3], usize);

/// The exact-weld representatives with their grid cells, sorted by cell.
///
/// Cells are `2 * tolerance` wide (wider if needed so that `coordinate / cell` stays below
/// 2^50): two points closer than the tolerance then lie, even after rounding, in the same or
/// adjacent cells.
fn grid_points(positions: &[[f64; 3]], exact: &[u32], tolerance: f64) -> Vec<GridPoint> {
    let uniques = (0..positions.len()).filter(|&i| exact[i] as usize == i);
    let max_abs = uniques
        .clone()
        .flat_map(|i| positions[i])
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let mut cell = (2.0 * tolerance).max(max_abs * 2f64.powi(-50));
    if !cell.is_finite() {
        cell = f64::MAX;
    }
    let mut points: Vec<GridPoint> = uniques
        .map(|i| (positions[i].map(|x| (x / cell).floor() as i64), i))
        .collect();
    points.sort_unstable();
    points
}

/// Unites every pair of points from `a` and `b` (`a == b`: every pair within it) with squared
/// distance below `tolerance2`, skipping pairs already in one set.
fn merge_close(positions: &[[f64; 3]], a: &[GridPoint], b: &[GridPoint], tolerance2: f64, sets: &mut UnionFind) {
    let same = std::ptr::eq(a, b);
    for (i, &(_, p)) in a.iter().enumerate() {
        let others = if same { &b[i + 1..] } else { b };
        for &(_, q) in others {
            if sets.find(p) != sets.find(q) && distance2(&positions[p], &positions[q]) < tolerance2 {
                sets.union(p, q);
            }
        }
    }
}

fn distance2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(&d, &d)
}

// ---------------------------------------------------------------------------------------------
// Step 2: face filtering

/// Faces on weld representatives, with their input indices.
struct Faces {
    verts: Vec<[u32; 3]>,
    source: Vec<u32>,
}

/// The faces without a repeated vertex and of non-zero area (duplicates are dropped later).
fn filter_faces(positions: &[[f64; 3]], triangles: &[[u32; 3]], rep: &[u32], report: &mut RepairReport) -> Faces {
    let mut candidates = Faces {
        verts: Vec::with_capacity(triangles.len()),
        source: Vec::with_capacity(triangles.len()),
    };
    // Each face judged on every core (the exact zero-area test is the
    // costly part); then, in face order, the bookkeeping.
    #[derive(Clone, Copy, PartialEq)]
    enum Verdict {
        Keep,
        RepeatedVertex,
        ZeroArea,
    }
    // The exact zero-area test: a triangle has zero area iff its
    // projections on the xy, yz and zx planes all do (exact for subnormal
    // coordinates too, on which `robust` alone underflows). Coordinates
    // checked once for the whole mesh, not per triangle.
    let points: &[glam::DVec3] = bytemuck::cast_slice(positions);
    let collinear = crate::geometry::collinear_for(points);
    let verdicts = crate::parallel::map(triangles.len(), |t| {
        let v = triangles[t].map(|i| rep[i as usize]);
        if v[0] == v[1] || v[1] == v[2] || v[2] == v[0] {
            Verdict::RepeatedVertex
        } else if collinear(points[v[0] as usize], points[v[1] as usize], points[v[2] as usize]) {
            Verdict::ZeroArea
        } else {
            Verdict::Keep
        }
    });
    for (t, (tri, verdict)) in triangles.iter().zip(verdicts).enumerate() {
        match verdict {
            Verdict::RepeatedVertex => report.repeated_vertex_faces += 1,
            Verdict::ZeroArea => report.zero_area_faces += 1,
            Verdict::Keep => {
                candidates.verts.push(tri.map(|i| rep[i as usize]));
                candidates.source.push(ix(t));
            }
        }
    }
    candidates
}

impl Faces {
    /// The faces not marked in `dropped`.
    fn without(self, dropped: &[bool]) -> Faces {
        let kept = |i: &usize| !dropped[*i];
        Faces {
            verts: (0..dropped.len()).filter(kept).map(|i| self.verts[i]).collect(),
            source: (0..dropped.len()).filter(kept).map(|i| self.source[i]).collect(),
        }
    }
}

/// Marks every face whose vertex set equals that of an earlier face. Faces are bucketed by their
/// smallest vertex, then each (small) bucket is sorted by the other two.
fn find_duplicates(verts: &[[u32; 3]], n_vertices: usize) -> Vec<bool> {
    let keys: Vec<(usize, u64)> = verts
        .iter()
        .map(|v| {
            let mut key = *v;
            key.sort_unstable();
            (key[0] as usize, u64::from(key[1]) << 32 | u64::from(key[2]))
        })
        .collect();
    let mut by_lowest = Csr::from_keyed(n_vertices, keys.iter().enumerate().map(|(f, &(low, _))| (low, ix(f))));
    let mut duplicate = vec![false; verts.len()];
    for r in 0..by_lowest.rows() {
        let row = by_lowest.row_mut(r);
        if row.len() < 2 {
            continue;
        }
        row.sort_unstable_by_key(|&f| (keys[f as usize].1, f));
        for w in 1..row.len() {
            if keys[row[w] as usize] == keys[row[w - 1] as usize] {
                duplicate[row[w] as usize] = true;
            }
        }
    }
    duplicate
}

// ---------------------------------------------------------------------------------------------
// Step 3: pairing faces across edges

/// Face-edges grouped by undirected edge: group `g` is `members[start[g]..start[g + 1]]`, in
/// increasing face-edge order.
struct EdgeGroups {
    start: Vec<usize>,
    members: Vec<u32>,
}

impl EdgeGroups {
    fn build(verts: &[[u32; 3]], n_vertices: usize) -> Self {
        // bucket by lower vertex, carrying (higher vertex, face-edge) packed in a u64
        let pairs = (0..3 * verts.len()).map(|e| edge_key(verts, e));
        let mut start = vec![0usize; n_vertices + 1];
        for (low, _) in pairs.clone() {
            start[low + 1] += 1;
        }
        for r in 0..n_vertices {
            start[r + 1] += start[r];
        }
        let mut next = start.clone();
        let mut packed = vec![0u64; 3 * verts.len()];
        for (e, (low, high)) in pairs.enumerate() {
            packed[next[low]] = (high as u64) << 32 | e as u64;
            next[low] += 1;
        }
        let mut group_start = Vec::with_capacity(packed.len() / 2 + 1);
        for r in 0..n_vertices {
            let row = &mut packed[start[r]..start[r + 1]];
            row.sort_unstable();
            for i in 0..row.len() {
                if i == 0 || row[i] >> 32 != row[i - 1] >> 32 {
                    group_start.push(start[r] + i);
                }
            }
        }
        group_start.push(packed.len());
        let members = packed.iter().map(|&x| x as u32).collect();
        EdgeGroups {
            start: group_start,
            members,
        }
    }

    fn len(&self) -> usize {
        self.start.len() - 1
    }

    fn group(&self, g: usize) -> &[u32] {
        &self.members[self.start[g]..self.start[g + 1]]
    }
}

fn link(partner: &mut [u32], a: usize, b: usize) {
    partner[a] = ix(b);
    partner[b] = ix(a);
}

fn unlink(partner: &mut [u32], a: usize) {
    let b = partner[a];
    if b != NONE {
        partner[a] = NONE;
        partner[b as usize] = NONE;
    }
}

/// Glues faces across edges: `partner[e]` is the face-edge glued to face-edge `e`, or `NONE`.
fn pair_faces(positions: &[[f64; 3]], verts: &[[u32; 3]], groups: &EdgeGroups, report: &mut RepairReport) -> Vec<u32> {
    let mut partner = vec![NONE; 3 * verts.len()];
    for g in 0..groups.len() {
        match *groups.group(g) {
            [_] => {}
            [a, b] => link(&mut partner, a as usize, b as usize),
            ref many => {
                report.non_manifold_edges += 1;
                let members: Vec<usize> = many.iter().map(|&e| e as usize).collect();
                pair_around_edge(positions, verts, &members, &mut partner);
            }
        }
    }
    partner
}

/// Pairs the faces of a non-manifold edge: angular neighbours, as many oppositely oriented
/// pairs as possible; of those pairings, the one with the fewest pairs of faces lying on each
/// other (see [`coincident_last`]).
fn pair_around_edge(positions: &[[f64; 3]], verts: &[[u32; 3]], members: &[usize], partner: &mut [u32]) {
    let order = angular_order(positions, verts, members);
    let (order, on_next) = coincident_last(positions, verts, order);
    let k = order.len();
    // Per position: whether the face there and the next one make a good pair (glued oppositely,
    // and not lying on each other), the first counting before the second.
    let pair_score: Vec<(bool, bool)> = (0..k)
        .map(|i| (!same_direction(verts, order[i], order[(i + 1) % k]), !on_next[i]))
        .collect();
    let first = if k % 2 == 0 {
        best_even_start(&order, &pair_score)
    } else {
        best_odd_start(&order, &pair_score)
    };
    for j in 0..k / 2 {
        link(partner, order[(first + 2 * j) % k], order[(first + 2 * j + 1) % k]);
    }
}

/// Face-edges sorted by the angle of their face's third vertex around the edge axis
/// (ties by face-edge index).
fn angular_order(positions: &[[f64; 3]], verts: &[[u32; 3]], members: &[usize]) -> Vec<usize> {
    let (low, high) = edge_key(verts, members[0]);
    let origin = &positions[low];
    let axis = sub(&positions[high], origin);
    let axis_len2 = dot(&axis, &axis);
    let r0 = sub(&positions[opposite_vertex(verts, members[0])], origin);
    let x_dir = sub(&r0, &scale(&axis, dot(&r0, &axis) / axis_len2));
    let y_dir = cross(&axis, &x_dir); // |y_dir| = |axis| |x_dir|
    let axis_len = axis_len2.sqrt();
    let mut keyed: Vec<((bool, f64), usize)> = members
        .iter()
        .map(|&e| {
            let r = sub(&positions[opposite_vertex(verts, e)], origin);
            (
                crate::geometry::direction_key(dot(&r, &y_dir), axis_len * dot(&r, &x_dir)),
                e,
            )
        })
        .collect();
    keyed.sort_by(|a, b| crate::geometry::direction_cmp(a.0, b.0).then(a.1.cmp(&b.1)));
    keyed.into_iter().map(|(_, e)| e).collect()
}

/// Faces lying on each other around the edge (their third vertices exactly in one plane with
/// it, on one side: one direction, as the two sheets of a flat two-sided plate, or a double-
/// sided card welded into one, meet at each inner edge) are neighbours in the angular order in
/// any order. They are put in the one that glues each sheet on to its continuation rather than
/// back onto the other sheet: the faces running along the edge from its lower vertex, whose
/// normals point towards the angles after theirs, last (next to the faces after them), the
/// others first. Returns the order (turned so that no such run straddles its end) and, per
/// position, whether the face there lies on the next one; without such faces, the order as
/// given.
///
/// ```text
///   T1 ---- T2       a plate's top (T) and bottom (B) faces at an inner edge, side view:
///   B1 ---- B2       glued in angular order B1 T1 | T2 B2 as T1-T2 and B2-B1 (two sheets),
///        ^ edge      not T1-B1 and T2-B2 (each cell folded shut on its own)
/// ```
fn coincident_last(positions: &[[f64; 3]], verts: &[[u32; 3]], mut order: Vec<usize>) -> (Vec<usize>, Vec<bool>) {
    let k = order.len();
    let p = |v: usize| glam::DVec3::from_array(positions[v]);
    let (low, high) = edge_key(verts, order[0]);
    let on_each_other = |e: usize, f: usize| {
        let (c, d) = (p(opposite_vertex(verts, e)), p(opposite_vertex(verts, f)));
        crate::geometry::pair_shape(p(low), p(high), c, d) == crate::geometry::PairShape::Folded
    };
    let on_next =
        |order: &[usize]| -> Vec<bool> { (0..k).map(|i| on_each_other(order[i], order[(i + 1) % k])).collect() };
    let joined = on_next(&order);
    if !joined.contains(&true) {
        return (order, joined);
    }
    // Start at a run's first face (all of them one run: anywhere).
    let start = (0..k).find(|&i| !joined[(i + k - 1) % k]).unwrap_or(0);
    order.rotate_left(start);
    let joined: Vec<bool> = (0..k).map(|i| joined[(i + start) % k]).collect();
    let forward = |e: usize| edge_vertices(verts, e).0 == low;
    let mut i = 0;
    while i < k {
        let mut end = i;
        while end + 1 < k && joined[end] {
            end += 1;
        }
        order[i..=end].sort_by_key(|&e| (forward(e), e));
        i = end + 1;
    }
    let joined = on_next(&order);
    (order, joined)
}

/// Even count: pairs start at position 0 or 1. The best `pair_score`s (most opposite pairs,
/// then fewest faces on each other); tie: the lowest-index face is paired with its lower-index
/// angular neighbour.
fn best_even_start(order: &[usize], pair_score: &[(bool, bool)]) -> usize {
    let k = order.len();
    let score = |s: usize| {
        (0..k / 2).fold((0, 0), |(o, n), j| {
            let (opposite, apart) = pair_score[(s + 2 * j) % k];
            (o + usize::from(opposite), n + usize::from(apart))
        })
    };
    let (s0, s1) = (score(0), score(1));
    if s0 != s1 {
        return if s0 > s1 { 0 } else { 1 };
    }
    let lowest = (0..k).min_by_key(|&i| order[i]).unwrap_or(0);
    let with_next = order[(lowest + 1) % k] < order[(lowest + k - 1) % k];
    if with_next {
        lowest % 2
    } else {
        (lowest + 1) % 2
    }
}

/// Odd count: pairs start at position `s`, leaving position `s - 1` alone. The best
/// `pair_score`s (most opposite pairs, then fewest faces on each other); tie: the face left
/// alone has the highest index. Scores are updated in O(1) per start.
fn best_odd_start(order: &[usize], pair_score: &[(bool, bool)]) -> usize {
    let k = order.len();
    let value = |i: usize| {
        let (opposite, apart) = pair_score[i % k];
        (usize::from(opposite), usize::from(apart))
    };
    let mut score = (0..k / 2).fold((0, 0), |(o, n), j| (o + value(2 * j).0, n + value(2 * j).1));
    let mut s = 0;
    let mut best = (score, order[k - 1], 0);
    for _ in 1..k {
        // pairs of start s: s, s+2, ..., s+k-3; of start s+2: drop s, add s+k-1.
        let (dropped, added) = (value(s), value(s + k - 1));
        score = (score.0 - dropped.0 + added.0, score.1 - dropped.1 + added.1);
        s = (s + 2) % k;
        let candidate = (score, order[(s + k - 1) % k], s);
        if (candidate.0, candidate.1) > (best.0, best.1) {
            best = candidate;
        }
    }
    best.2
}

// ---------------------------------------------------------------------------------------------
// Step 4: orientation

/// Chooses a flip per face so that glued faces agree; cuts glued edges where they cannot.
fn orient(positions: &[[f64; 3]], verts: &[[u32; 3]], partner: &mut [u32], report: &mut RepairReport) -> Vec<bool> {
    let n = verts.len();
    let mut flip = vec![false; n];
    let mut seen = vec![false; n];
    let mut component: Vec<u32> = Vec::new();
    // direction of every face-edge, read sequentially here instead of at random below
    let forward: Vec<bool> = (0..3 * n)
        .map(|e| edge_vertices(verts, e).0 == edge_key(verts, e).0)
        .collect();
    for seed in 0..n {
        if seen[seed] {
            continue;
        }
        component.clear();
        component.push(ix(seed));
        seen[seed] = true;
        let mut head = 0;
        while head < component.len() {
            let f = component[head] as usize;
            head += 1;
            for e in 3 * f..3 * f + 3 {
                let p = partner[e];
                if p == NONE {
                    continue;
                }
                let g = p as usize / 3;
                let wanted = flip[f] ^ (forward[e] == forward[p as usize]);
                if !seen[g] {
                    seen[g] = true;
                    flip[g] = wanted;
                    component.push(ix(g));
                } else if flip[g] != wanted {
                    unlink(partner, e);
                    report.orientation_cuts += 1;
                }
            }
        }
        if should_invert(positions, verts, partner, &component, &flip) {
            for &f in &component {
                flip[f as usize] ^= true;
            }
        }
    }
    report.reoriented_faces = flip.iter().filter(|&&f| f).count();
    flip
}

/// Closed component: invert if its signed volume is negative. Open component (or zero volume):
/// invert if more than half of its faces are flipped.
fn should_invert(
    positions: &[[f64; 3]],
    verts: &[[u32; 3]],
    partner: &[u32],
    component: &[u32],
    flip: &[bool],
) -> bool {
    let closed = component
        .iter()
        .all(|&f| (3 * f as usize..3 * f as usize + 3).all(|e| partner[e] != NONE));
    if closed {
        let volume = signed_volume(positions, verts, component, flip);
        if volume != 0.0 {
            return volume < 0.0;
        }
    }
    2 * component.iter().filter(|&&f| flip[f as usize]).count() > component.len()
}

/// Six times the signed volume enclosed by the faces, as oriented by `flip`.
fn signed_volume(positions: &[[f64; 3]], verts: &[[u32; 3]], component: &[u32], flip: &[bool]) -> f64 {
    let origin = positions[verts[component[0] as usize][0] as usize];
    component
        .iter()
        .map(|&f| {
            let det = volume_term(positions, &verts[f as usize], &origin);
            if flip[f as usize] {
                -det
            } else {
                det
            }
        })
        .sum()
}

/// Six times the signed volume of the tetrahedron of `origin` and a face (as it is listed): one
/// term of [`signed_volume`], and of the outward test of [`closed_components_face_outwards`].
fn volume_term(positions: &[[f64; 3]], face: &[u32; 3], origin: &[f64; 3]) -> f64 {
    let [a, b, c] = face.map(|v| sub(&positions[v as usize], origin));
    dot(&a, &cross(&b, &c))
}

// ---------------------------------------------------------------------------------------------
// Step 5: vertex classes

/// Union-find over corners: corners of faces glued across an edge share their vertex.
fn vertex_classes(verts: &[[u32; 3]], partner: &[u32]) -> UnionFind {
    let mut classes = UnionFind::new(3 * verts.len());
    for (e, &p) in partner.iter().enumerate() {
        let p = p as usize;
        if p == NONE as usize || p < e {
            continue;
        }
        let (es, et) = edge_corners(e);
        let (ps, pt) = edge_corners(p);
        if corner_vertex(verts, es) == corner_vertex(verts, ps) {
            classes.union(es, ps);
            classes.union(et, pt);
        } else {
            classes.union(es, pt);
            classes.union(et, ps);
        }
    }
    classes
}

/// Vertex classes such that no two distinct glued edges join the same two classes.
///
/// Such parallel edges can only appear on an input edge whose faces were not all glued together
/// (a non-manifold edge or an orientation cut). The faces of every later parallel edge are
/// unglued from their other neighbours at the edge's lower vertex, which gives them a class of
/// their own there; repeat until none is left (each round removes at least one glued edge).
fn separate_parallel_edges(verts: &[[u32; 3]], groups: &EdgeGroups, partner: &mut [u32]) -> UnionFind {
    loop {
        let mut classes = vertex_classes(verts, partner);
        let mut to_unlink = Vec::new();
        for g in 0..groups.len() {
            let members = groups.group(g);
            let whole = members.len() == 1 || (members.len() == 2 && partner[members[0] as usize] == members[1]);
            if !whole {
                parallel_edge_cuts(verts, members, partner, &mut classes, &mut to_unlink);
            }
        }
        let before = to_unlink.iter().filter(|&&e| partner[e] != NONE).count();
        for &e in &to_unlink {
            unlink(partner, e);
        }
        if before == 0 {
            return classes;
        }
    }
}

/// Collects, for one input edge, the face-edges to unglue so that its glued edges (pairs or
/// single face-edges) end on distinct class pairs.
fn parallel_edge_cuts(
    verts: &[[u32; 3]],
    members: &[u32],
    partner: &[u32],
    classes: &mut UnionFind,
    to_unlink: &mut Vec<usize>,
) {
    let (low, high) = edge_key(verts, members[0] as usize);
    let mut keyed: Vec<((usize, usize), usize)> = members
        .iter()
        .filter(|&&e| partner[e as usize] == NONE || partner[e as usize] > e)
        .map(|&e| {
            let e = e as usize;
            let a = classes.find(edge_corner_at(verts, e, low));
            let b = classes.find(edge_corner_at(verts, e, high));
            ((a, b), e)
        })
        .collect();
    keyed.sort_unstable();
    for i in 1..keyed.len() {
        if keyed[i].0 != keyed[i - 1].0 {
            continue;
        }
        let e = keyed[i].1;
        for side in [e, partner[e] as usize] {
            if side != NONE as usize {
                let other = other_edge_at(verts, side, low);
                if partner[other] != NONE {
                    to_unlink.push(other);
                }
            }
        }
    }
}

/// Whether the corners at `vertex` form more than one fan when faces sharing any edge at the
/// vertex count as connected (the classical non-manifold vertex).
fn is_non_manifold_vertex(verts: &[[u32; 3]], corners: &[u32]) -> bool {
    // (neighbour vertex, slot of the corner) for both neighbours of every corner
    let mut by_neighbour: Vec<(u32, u32)> = corners
        .iter()
        .enumerate()
        .flat_map(|(slot, &c)| {
            let (f, k) = (c as usize / 3, c as usize % 3);
            [(verts[f][(k + 1) % 3], ix(slot)), (verts[f][(k + 2) % 3], ix(slot))]
        })
        .collect();
    by_neighbour.sort_unstable();
    let mut fans = UnionFind::new(corners.len());
    for w in by_neighbour.windows(2) {
        if w[0].0 == w[1].0 {
            fans.union(w[0].1 as usize, w[1].1 as usize);
        }
    }
    (0..corners.len()).any(|slot| fans.find(slot) != 0)
}

// ---------------------------------------------------------------------------------------------
// Step 6: output

/// Numbers the vertex classes in the order of their source vertex (then of their first corner)
/// and builds the output. Counts the classical non-manifold vertices among the split ones (a
/// vertex that is not split cannot be one: its classes are finer than its classical fans).
fn assemble(
    positions: &[[f64; 3]],
    faces: Faces,
    flip: &[bool],
    vertex_corners: &Csr,
    classes: &mut UnionFind,
    mut report: RepairReport,
) -> Repaired {
    let mut class_id = vec![NONE; 3 * faces.verts.len()];
    let mut corner_id = vec![0u32; 3 * faces.verts.len()];
    let mut out_positions = Vec::new();
    let mut source_vertex = Vec::new();
    for (v, position) in positions.iter().enumerate() {
        let corners = vertex_corners.row(v);
        let first_new = out_positions.len();
        for &c in corners {
            let root = classes.find(c as usize);
            if class_id[root] == NONE {
                class_id[root] = ix(out_positions.len());
                out_positions.push(*position);
                source_vertex.push(ix(v));
            }
            corner_id[c as usize] = class_id[root];
        }
        if out_positions.len() > first_new + 1 && is_non_manifold_vertex(&faces.verts, corners) {
            report.non_manifold_vertices += 1;
        }
    }
    let triangles = (0..faces.verts.len())
        .map(|f| {
            let [a, b, c] = [0, 1, 2].map(|k| corner_id[3 * f + k]);
            if flip[f] {
                [a, c, b]
            } else {
                [a, b, c]
            }
        })
        .collect();
    Repaired {
        positions: out_positions,
        triangles,
        source_vertex,
        source_triangle: faces.source,
        flipped: flip.to_vec(),
        report,
    }
}

// ---------------------------------------------------------------------------------------------
// Small vector helpers

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn scale(a: &[f64; 3], s: f64) -> [f64; 3] {
    a.map(|x| x * s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The zero-area test is exact at every scale: the mesh-wide range check
    /// sends meshes with subnormal coordinates to the slow exact test, on
    /// which a proper triangle 1e-310 across is kept (the fast test alone
    /// underflows and would call it collinear), and a collinear one dropped.
    #[test]
    fn zero_area_faces_are_found_at_every_scale() {
        for scale in [1.0, 1e-310] {
            let positions = [
                [0.0, 0.0, 0.0],
                [scale, 0.0, 0.0],
                [0.0, scale, 0.0],
                [2.0 * scale, 0.0, 0.0],
            ];
            let triangles = [[0, 1, 2], [0, 1, 3], [1, 1, 2]];
            let rep = [0, 1, 2, 3];
            let mut report = RepairReport::default();
            let faces = filter_faces(&positions, &triangles, &rep, &mut report);
            assert_eq!(faces.source, [0], "scale {scale}");
            assert_eq!(
                (report.zero_area_faces, report.repeated_vertex_faces),
                (1, 1),
                "scale {scale}"
            );
        }
    }
}
