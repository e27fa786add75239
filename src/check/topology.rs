//! Rule 5 and the groundwork of the others: indices and coordinates, the edges with their
//! faces, fans, components and boundary loops.

use super::*;

/// Validates a mesh's indices and coordinates: which vertices its faces use, or `None` with
/// failures when an index or a used coordinate is wrong.
pub(super) fn validate(names: &Names, fail: &mut Failures) -> Option<Vec<bool>> {
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

/// An undirected edge `lo < hi` with (up to) its first two faces.
pub(super) struct Edge {
    pub(super) lo: u32,
    pub(super) hi: u32,
    /// The first two faces using the edge (`u32::MAX` when absent).
    pub(super) faces: [u32; 2],
    /// Whether each of those faces uses the edge as `lo -> hi`.
    pub(super) forward: [bool; 2],
    /// Number of faces using the edge.
    pub(super) count: u32,
}

impl Edge {
    /// One face using the edge.
    pub(super) fn is_boundary(&self) -> bool {
        self.count == 1
    }

    /// Two faces using the edge in opposite directions.
    pub(super) fn is_interior(&self) -> bool {
        self.count == 2 && self.forward[0] != self.forward[1]
    }

    /// For an interior edge: `(a, b, f, g)` with face `f = (a, b, c)` and face `g = (b, a, d)`.
    pub(super) fn oriented(&self) -> (u32, u32, u32, u32) {
        let (a, b) = if self.forward[0] {
            (self.lo, self.hi)
        } else {
            (self.hi, self.lo)
        };
        (a, b, self.faces[0], self.faces[1])
    }
}

/// A face repeating a vertex (it has no proper edges).
pub(super) fn is_degenerate(t: &[u32; 3]) -> bool {
    t[0] == t[1] || t[1] == t[2] || t[2] == t[0]
}

/// The vertex of `t` that is neither `a` nor `b`.
pub(super) fn third(t: &[u32; 3], a: u32, b: u32) -> u32 {
    t.iter().copied().find(|&v| v != a && v != b).unwrap_or(a)
}

/// The edges of a mesh, and the vertices whose faces do not form a single fan (a disk or
/// half-disk), found in one pass over the faces around each vertex.
pub(super) struct EdgesAndFans {
    pub(super) edges: Vec<Edge>,
    /// In increasing order; reported by [`topology_stats`], after the edges' failures.
    pub(super) not_single_fans: Vec<u32>,
}

/// Builds the undirected edges of the non-degenerate faces (sorted by vertex pair), reporting
/// degenerate faces, edges with more than two faces and edges used twice in one direction,
/// and finds the vertices whose faces do not form a single fan. `around`: the faces around
/// each vertex.
pub(super) fn build_edges(names: &Names, around: &VertexFaces, fail: &mut Failures) -> EdgesAndFans {
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
pub(super) struct TopologyStats {
    /// Referenced vertices.
    pub(super) vertices: usize,
    /// Undirected edges.
    pub(super) edges: usize,
    /// Faces.
    pub(super) faces: usize,
    /// `V - E + F`.
    pub(super) euler: i64,
    /// Connected components (through faces).
    pub(super) components: usize,
    /// Boundary loops; `None` when the mesh is not manifold (then undefined).
    pub(super) boundary_loops: Option<usize>,
}

/// Computes the invariants, reporting vertices whose faces do not form a single fan.
pub(super) fn topology_stats(
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
pub(super) fn is_single_sorted_fan(link: &mut [(u32, u32)], heads: &mut Vec<u32>) -> Option<bool> {
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
pub(super) fn is_single_small_fan(link: &[(u32, u32)]) -> Option<bool> {
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
pub(super) fn count_components(mesh: &Mesh3, referenced: &[bool]) -> usize {
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
pub(super) fn compare_topology(input: &TopologyStats, output: &TopologyStats, fail: &mut Failures) {
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

/// Rule 5's boundary: every output boundary edge lies along an input boundary edge (both its
/// ends on one, at its endpoints or within the on-edge tolerance), and every input boundary
/// edge has an output boundary edge along it.
///
/// The counts of rule 5 do not see a face along the boundary removed: its two other edges
/// become boundary and the loop goes round the gap,
///
/// ```text
///   input boundary  a ---- m ---- b         output   a      m ---- b
///                    \     |     /                    \      \    /
///                     \    |    /      face (a, m, c)  \      \  /
///                      \   |   /       removed:         \      \/
///                          c                                   c     (a, c) and (c, m) are
///                                                                     boundary edges now
/// ```
///
/// and only its region's area tells, which allows a billionth of the region: refinement makes
/// boundary faces far smaller than that (needles split at sample resolution), so such a face
/// could go unseen. Edges of output vertices not recognised (rules 1 and 2) are left to those
/// rules' failures.
pub(super) fn compare_boundaries(
    model: &InputModel,
    output_edges: &[Edge],
    candidates: &Candidates,
    output: &Names,
    fail: &mut Failures,
) {
    let input_edges = &model.prepared.edges;
    let mut along = vec![false; input_edges.len()];
    let mut all_judged = true;
    for edge in output_edges.iter().filter(|e| e.is_boundary()) {
        let (lo, hi) = (edge.lo, edge.hi);
        if !candidates.known[lo as usize] || !candidates.known[hi as usize] {
            all_judged = false;
            continue;
        }
        let mut on_one = false;
        for e in candidates.boundary_edges_of(lo) {
            if candidates.boundary_edges_of(hi).any(|f| f == e) {
                along[e as usize] = true;
                on_one = true;
            }
        }
        if !on_one {
            fail.push(KIND_BOUNDARY, || {
                format!(
                    "output boundary edge ({}, {}) lies along no input boundary edge (a face along the boundary removed, or one added)",
                    output.label(lo),
                    output.label(hi)
                )
            });
        }
    }
    if !all_judged {
        return;
    }
    for (e, edge) in input_edges.iter().enumerate() {
        if edge.is_boundary() && !along[e] {
            fail.push(KIND_BOUNDARY, || {
                format!(
                    "input boundary edge ({}, {}) has no output boundary edge along it",
                    model.names.label(edge.lo),
                    model.names.label(edge.hi)
                )
            });
        }
    }
}

/// Whether the component of face `start` can be oriented consistently (`faces` faces, `edges`
/// their edges): walks it from `start`, turning each face to agree with the face it is reached
/// from across an edge of two faces; a face reached both turned and not proves that no
/// orientation is consistent (a Möbius band). For the message on an input that has faces
/// running along an edge the same way.
pub(super) fn component_is_orientable(faces: usize, edges: &[Edge], start: u32) -> bool {
    // Across every edge of two faces: whether they run along it the same way (then exactly one
    // of them must be turned), from either side, by face.
    let mut across: Vec<(u32, u32, bool)> = (edges.iter().filter(|e| e.count == 2))
        .flat_map(|e| {
            let same = e.forward[0] == e.forward[1];
            [(e.faces[0], e.faces[1], same), (e.faces[1], e.faces[0], same)]
        })
        .collect();
    across.sort_unstable();
    let mut turned: Vec<Option<bool>> = vec![None; faces];
    turned[start as usize] = Some(false);
    let mut stack = vec![start];
    while let Some(f) = stack.pop() {
        let f_turned = turned[f as usize] == Some(true);
        let first = across.partition_point(|&(g, _, _)| g < f);
        for &(_, g, same) in across[first..].iter().take_while(|&&(g, _, _)| g == f) {
            let want = f_turned != same;
            match turned[g as usize] {
                None => {
                    turned[g as usize] = Some(want);
                    stack.push(g);
                }
                Some(was) if was != want => return false,
                Some(_) => {}
            }
        }
    }
    true
}
