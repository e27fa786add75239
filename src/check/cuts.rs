//! Keeping apart what `--repair` cut on purpose: welded sheets, pinched vertices, seams, and
//! the output read like the input.

use super::*;

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
pub(super) fn settle_like(
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
pub(super) fn keeps_open(reading: &Mesh3, input_mesh: &Mesh3, places: &FastMap<[u64; 3], i64>) -> bool {
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
pub(super) fn count_deviation(welded: &Mesh3, settled: &Mesh3, differ: &[u32]) -> u64 {
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
    pub(super) settled: Settled,
    choices: Choices,
    miss: (u64, u64, u64),
}

/// What a mesh's refinement keeps, cheap to find: its connected components, Euler
/// characteristic and boundary loops (counted as cycles of the edges with one face, which is
/// the number of boundary loops on a manifold).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Shape {
    pub(super) components: i64,
    pub(super) euler: i64,
    pub(super) boundary_loops: i64,
}

impl Shape {
    /// The shape of `mesh`, counting only the vertices some face uses.
    pub(super) fn of(mesh: &Mesh3) -> Shape {
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
    pub(super) fn distance(&self, other: &Shape) -> u64 {
        (self.components.abs_diff(other.components))
            + self.euler.abs_diff(other.euler)
            + self.boundary_loops.abs_diff(other.boundary_loops)
    }
}

/// The last steps of reading a welded mesh: [`split_welded_sheets`], then
/// [`split_pinched_vertices`]; with the faces around every vertex of the result.
pub(super) fn settle(mesh: Mesh3, file_corners: &FileVertices) -> Settled {
    split_pinched_vertices(split_welded_sheets(mesh, file_corners))
}

/// A mesh as read, with the faces around each of its vertices.
pub(super) struct Settled {
    pub(super) mesh: Mesh3,
    pub(super) around: VertexFaces,
}

/// The faces around every vertex of a mesh (whose indices are valid), in increasing order: a
/// counting sort of the corners by vertex, made once and used by the pinch rule, the edges and
/// the fans (a face repeating a vertex is listed once per corner there). Vertices past those it
/// was made for (the ones no face uses, appended later) have no faces.
pub(super) struct VertexFaces {
    pub(super) start: Vec<usize>,
    pub(super) faces: Vec<u32>,
}

impl VertexFaces {
    pub(super) fn new(mesh: &Mesh3) -> VertexFaces {
        let corners = || (mesh.triangles.iter().enumerate()).flat_map(|(f, t)| t.map(|v| (v as usize, f as u32)));
        let (start, faces) = grouped(mesh.positions.len(), corners);
        VertexFaces { start, faces }
    }

    /// The faces around vertex `v`.
    pub(super) fn of(&self, v: usize) -> &[u32] {
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
    pub(super) excess: u64,
}

/// The corner edges at flagged vertices that [`join_seams`] pairs, with their file vertices
/// numbered among themselves (`files`), so that each attempt at a pairing is small.
struct Seams<'a> {
    /// The welded mesh's positions.
    pub(super) positions: &'a [DVec3],
    /// The corner edges, as [`CornerEdge`] with file vertices as indices into `files`, sorted.
    pub(super) edges: Vec<CornerEdge>,
    /// Which of `edges` touch each flagged vertex: a union there is checked against them.
    touching: FastMap<u32, Vec<usize>>,
    /// How many file vertices each flagged vertex has.
    classes: FastMap<u32, u32>,
    /// The file vertices `edges` name, in increasing order.
    pub(super) files: Vec<u32>,
    /// Whether each welded vertex is flagged.
    flagged: Vec<bool>,
}

/// One pairing of [`Seams`]: its classes (of `Seams::files`) and its choices.
struct Pairing {
    class: UnionFind,
    choices: Choices,
}

impl Seams<'_> {
    pub(super) fn new<'a>(mesh: &'a Mesh3, file: &FileVertices, flagged: &impl Fn(u32) -> bool) -> Option<Seams<'a>> {
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
pub(super) fn split_welded_sheets(mesh: Mesh3, file: &FileVertices) -> Mesh3 {
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
pub(super) fn grouped<T: Copy + Default, I: Iterator<Item = (usize, T)>>(
    n: usize,
    items: impl Fn() -> I,
) -> (Vec<usize>, Vec<T>) {
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
pub(super) fn split_pinched_vertices(mut mesh: Mesh3) -> Settled {
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
pub(super) struct Fans {
    pub(super) parent: Vec<usize>,
    by_neighbour: Vec<(u32, usize)>,
}

impl Fans {
    /// Appends `(v, face, fan)` for every face of `faces` (the faces around `v`, in
    /// increasing order) that is not in the fan of the lowest face, `fan` naming its fan
    /// (the root of its faces joined across shared edges `(v, w)`).
    /// Every fan is named by its lowest index into `faces`, whatever the order of the joins.
    pub(super) fn find(&mut self, v: usize, faces: &[u32], triangles: &[[u32; 3]], found: &mut Vec<(u32, u32, u32)>) {
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
pub(super) const SMALL_FAN: usize = 16;
