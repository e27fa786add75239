//! Half-edge connectivity of a manifold triangle mesh (with boundary), with
//! the two operations the algorithm needs — edge flip and edge split — and a
//! [`Topology::validate`] that tests call after them.
//!
//! Layout, as in geometry-central's `surface_mesh`: plain `Vec`s indexed by
//! small newtypes. The two half-edges of edge `e` are `2e` and `2e + 1`, so the
//! twin of `h` is `h ^ 1` and needs no storage. A half-edge on the boundary
//! has no face ([`FaceId::NONE`]) and no `next`. Memory: 12 bytes per
//! half-edge (origin, next, face), 4 bytes per face, 4 bytes per vertex.
//!
//! This module knows nothing of positions: geometry lives elsewhere.

use std::fmt;
use std::ops::Range;
use std::sync::atomic::{AtomicU32, Ordering};

macro_rules! id_type {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
        pub struct $name(pub u32);

        impl $name {
            /// "No such element" (a boundary half-edge's face, for instance).
            pub const NONE: $name = $name(u32::MAX);

            /// The index into the per-element vectors.
            #[inline]
            pub fn idx(self) -> usize {
                self.0 as usize
            }

            /// Whether this is [`Self::NONE`].
            #[inline]
            pub fn is_none(self) -> bool {
                self.0 == u32::MAX
            }
        }

        impl fmt::Debug for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                if self.is_none() {
                    write!(f, "{}(NONE)", stringify!($name))
                } else {
                    write!(f, "{}({})", stringify!($name), self.0)
                }
            }
        }
    };
}

id_type!(
    /// A vertex.
    VertexId
);
id_type!(
    /// A half-edge: one side of an edge, directed from its origin.
    HalfEdgeId
);
id_type!(
    /// An (undirected) edge: half-edges `2e` and `2e + 1`.
    EdgeId
);
id_type!(
    /// A triangle.
    FaceId
);

impl HalfEdgeId {
    /// The opposite half-edge of the same edge.
    #[inline]
    pub fn twin(self) -> HalfEdgeId {
        HalfEdgeId(self.0 ^ 1)
    }

    /// The edge this half-edge belongs to.
    #[inline]
    pub fn edge(self) -> EdgeId {
        EdgeId(self.0 >> 1)
    }
}

impl EdgeId {
    /// The first half-edge of the edge (the "canonical" direction).
    #[inline]
    pub fn halfedge(self) -> HalfEdgeId {
        HalfEdgeId(self.0 << 1)
    }
}

/// Why a list of triangles is not a manifold, consistently oriented mesh.
/// Indices are 0-based positions in the list given to
/// [`Topology::from_triangles`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TopologyError {
    /// The edge (a, b) is used by more than two faces; `face` is the third
    /// of them in list order (the first two alone would be fine).
    EdgeWithMoreThanTwoFaces {
        /// The third face.
        face: usize,
        /// One end of the edge.
        a: u32,
        /// The other end.
        b: u32,
    },
    /// Two faces (`face` is the second) use the edge a → b in the same
    /// direction: their orientations disagree.
    InconsistentOrientation {
        /// The second face using a → b.
        face: usize,
        /// The edge's origin in both faces.
        a: u32,
        /// Its destination in both faces.
        b: u32,
    },
    /// The faces around `vertex` form more than one fan (a pinch point).
    NonManifoldVertex {
        /// The pinch point.
        vertex: u32,
    },
    /// A vertex index is not below the vertex count.
    IndexOutOfRange {
        /// The face.
        face: usize,
        /// The index out of range.
        index: u32,
    },
    /// A face uses a vertex twice.
    RepeatedVertex {
        /// The face.
        face: usize,
        /// The vertex it uses twice.
        vertex: u32,
    },
    /// Faces `first` and `face` use the same three vertices (a closed
    /// two-face "pillow": every edge would have one vertex opposite it twice).
    SameThreeVertices {
        /// The earlier face.
        first: usize,
        /// The later one.
        face: usize,
    },
    /// More triangles than [`MAX_TRIANGLES`] (or more vertices than
    /// [`MAX_HALFEDGES`]): the ids, 32-bit, could not number them all.
    TooLarge {
        /// Triangles given.
        triangles: usize,
        /// Vertices given.
        vertices: usize,
    },
}

impl fmt::Display for TopologyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            TopologyError::EdgeWithMoreThanTwoFaces { face, a, b } => write!(
                f,
                "the edge between vertices {a} and {b} has more than two triangles (triangle {face} is the third): non-manifold edge"
            ),
            TopologyError::InconsistentOrientation { face, a, b } => write!(
                f,
                "triangle {face} runs along the edge {a} -> {b} in the same direction as another: inconsistent orientation"
            ),
            TopologyError::NonManifoldVertex { vertex } => {
                write!(f, "the triangles around vertex {vertex} form more than one fan: non-manifold vertex")
            }
            TopologyError::IndexOutOfRange { face, index } => {
                write!(f, "triangle {face} uses vertex {index}, beyond the vertex count")
            }
            TopologyError::RepeatedVertex { face, vertex } => write!(f, "triangle {face} uses vertex {vertex} twice"),
            TopologyError::SameThreeVertices { first, face } => {
                write!(f, "triangles {first} and {face} have the same three vertices")
            }
            TopologyError::TooLarge { triangles, vertices } => write!(
                f,
                "{triangles} triangles over {vertices} vertices: more than 32-bit ids can number (at most {MAX_TRIANGLES} triangles)"
            ),
        }
    }
}

impl std::error::Error for TopologyError {}

/// The longest fans the construction and pruning walk to learn whether two
/// vertices are joined ([`Topology::are_adjacent_within_either`]): a
/// change whose answer is still unknown then counts as making a duplicate
/// edge and is refused, which is always safe and keeps each test bounded.
pub const ADJACENCY_LIMIT: usize = 1024;

/// The most half-edges a [`Topology`] can have: ids are `u32`, and
/// `u32::MAX` is `NONE`. Half-edges run out first: a mesh has at least as
/// many as it has edges, faces or (used) vertices, and a split adds six.
pub const MAX_HALFEDGES: usize = u32::MAX as usize;

/// The most triangles [`Topology::from_triangles`] builds a mesh from
/// (715,827,882): even a soup of them, every edge on the boundary and six
/// half-edges a triangle, fits in [`MAX_HALFEDGES`].
pub const MAX_TRIANGLES: usize = MAX_HALFEDGES / 6;

/// How many splits the arrays of a mesh built from `n_triangles` triangles
/// have room for from the start: about one per edge, and at least 16,384,
/// what `refine` reserves. Capacity is address space until used, and
/// growing the arrays later would copy them (and fault their pages in
/// again).
pub fn room_for_splits(n_triangles: usize) -> usize {
    (3 * n_triangles / 2 + 16).max(MIN_ROOM_FOR_SPLITS)
}

/// Whether the faces joined to `face` (through edges of exactly two faces)
/// can be oriented alike, each keeping or reversing its corner order:
/// `false` for a Möbius band, where every choice leaves two faces running
/// along some edge in the same direction. The error path's question, so
/// that a refusal can say which fault it is: it builds an edge list of every
/// triangle (linear memory, a sort).
pub fn component_is_orientable(triangles: &[[u32; 3]], face: usize) -> bool {
    // Each face's three edges as (low end, high end, face, runs low -> high).
    let mut edges: Vec<(u32, u32, u32, bool)> = (triangles.iter().enumerate())
        .flat_map(|(f, t)| (0..3).map(move |k| (t[k], t[(k + 1) % 3], f as u32)))
        .map(|(a, b, f)| (a.min(b), a.max(b), f, a < b))
        .collect();
    edges.sort_unstable();
    // Faces glued across an edge of two faces, and whether they run along it
    // the same way (then exactly one of them must be reversed).
    let mut glued: Vec<(u32, u32, bool)> = Vec::new();
    for group in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if let [(_, _, f, df), (_, _, g, dg)] = *group {
            glued.extend([(f, g, df == dg), (g, f, df == dg)]);
        }
    }
    glued.sort_unstable();
    let start = |f: u32| glued.partition_point(|x| x.0 < f);
    // Walk the component, reversing faces to agree with the face they are
    // reached from; a face reached both ways proves it non-orientable.
    let mut reversed: Vec<Option<bool>> = vec![None; triangles.len()];
    let mut stack = vec![face as u32];
    reversed[face] = Some(false);
    while let Some(f) = stack.pop() {
        let flip = reversed[f as usize] == Some(true);
        for &(_, g, same) in glued[start(f)..].iter().take_while(|x| x.0 == f) {
            let want = flip != same;
            match reversed[g as usize] {
                None => {
                    reversed[g as usize] = Some(want);
                    stack.push(g);
                }
                Some(r) if r != want => return false,
                Some(_) => {}
            }
        }
    }
    true
}

/// The least room for splits any mesh gets: CAD parts with slivers add
/// several vertices per face (the rotor 3.9, mpi_triang 40), and for a
/// small mesh this much untouched capacity costs address space only.
const MIN_ROOM_FOR_SPLITS: usize = 16_384;

/// One saved entry of a [`Topology`], for undoing local changes.
#[derive(Clone, Copy, Debug)]
pub enum Saved {
    /// A half-edge's origin, next and face.
    HalfEdge(HalfEdgeId, VertexId, HalfEdgeId, FaceId),
    /// A face's half-edge.
    Face(FaceId, HalfEdgeId),
    /// A vertex's outgoing half-edge.
    Vertex(VertexId, HalfEdgeId),
    /// The numbers of half-edges, faces and vertices before a split: undoing
    /// truncates the arrays back to them.
    Lengths(u32, u32, u32),
    /// A flip of the edge, with what the flipped mesh does not tell: the
    /// half-edges its two faces had, and whether the outgoing half-edge of
    /// its first (bit 0) and second (bit 1) end moved
    /// ([`Topology::flip_record`]). A tenth of the entries of saving the
    /// quad, and undone by walking the flipped quad back.
    Flip(EdgeId, HalfEdgeId, HalfEdgeId, u8),
}

/// Half-edge connectivity. See the module documentation for the layout.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Topology {
    he_origin: Vec<VertexId>,
    he_next: Vec<HalfEdgeId>,
    he_face: Vec<FaceId>,
    face_he: Vec<HalfEdgeId>,
    /// An outgoing half-edge with a face; on a boundary vertex, the first one
    /// counter-clockwise (its twin has no face).
    vertex_he: Vec<HalfEdgeId>,
}

/// Lists of outgoing corners longer than this are sorted and searched by
/// halves in [`pair_corners_by_scanning`].
const LONG_LIST: usize = 16;

/// The corners of a mesh paired along their edges.
pub(crate) struct Pairing {
    /// For each corner, the corner running the other way along its edge
    /// ([`NO_TWIN`] on the boundary).
    twin: Vec<u32>,
    /// The number of edges: pairs and lone corners.
    n_edges: usize,
}

/// [`TopologyError::TooLarge`] if `n_triangles` is past [`MAX_TRIANGLES`]
/// or `n_vertices` past [`MAX_HALFEDGES`].
pub(crate) fn refuse_beyond_ids(n_vertices: usize, n_triangles: usize) -> Result<(), TopologyError> {
    if n_triangles > MAX_TRIANGLES || n_vertices > MAX_HALFEDGES {
        return Err(TopologyError::TooLarge {
            triangles: n_triangles,
            vertices: n_vertices,
        });
    }
    Ok(())
}

/// A corner (or half-edge) not numbered yet, while pairing.
const UNSET: u32 = u32::MAX;
/// The twin of a corner on the boundary: no corner runs the other way.
const NO_TWIN: u32 = u32::MAX - 1;

/// The corners of `triangles` (c = 3f + i: the directed edge `tri[i]` ->
/// `tri[i + 1]`) paired along their edges: `twin[c]` runs the other way along
/// c's edge, [`NO_TWIN`] on the boundary. `None` if some edge is not a
/// plain pair (three or more corners, or two in the same direction), or
/// the mesh has 2^31 corners or more.
///
/// The corners are sorted by the smaller vertex of their edge (a counting
/// sort, keeping corner order), so that both corners of an edge land in
/// the same short list, which is then paired in place. Looking each
/// corner's twin up among the corners leaving its destination
/// ([`pair_corners_by_scanning`]) reads two lists at random places per
/// edge: on a large mesh, twice the time.
///
/// On a large mesh each thread sorts and pairs the edges whose smaller
/// vertex is in its own range of vertices ([`pair_edges_from`]): the
/// corners each one pairs are its own, so the pairs do not depend on the
/// number of threads.
pub(crate) fn pair_corners_by_sorting(n_vertices: usize, triangles: &[[u32; 3]]) -> Option<Pairing> {
    let n_corners = 3 * triangles.len();
    if n_corners >= 1 << 31 {
        return None;
    }
    // (Relaxed atomics: plain loads and stores, written by one thread each.)
    let twin: Vec<AtomicU32> = (0..n_corners).map(|_| AtomicU32::new(UNSET)).collect();
    let edges = crate::parallel::map_ranges(n_vertices, |vertices| pair_edges_from(vertices, triangles, &twin));
    let n_edges = edges.into_iter().sum::<Option<usize>>()?;
    // (In place: the same allocation.)
    let twin = twin.into_iter().map(AtomicU32::into_inner).collect();
    Some(Pairing { twin, n_edges })
}

/// [`pair_corners_by_sorting`] for the edges whose smaller vertex is in
/// `vertices`: writes their corners' twins, and returns how many edges
/// they make (`None` if one is not a plain pair).
fn pair_edges_from(vertices: Range<usize>, triangles: &[[u32; 3]], twin: &[AtomicU32]) -> Option<usize> {
    let corners = || {
        triangles
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .enumerate()
    };
    // The local number of the vertex at which a corner (u, v) is listed,
    // if it is in the range (one comparison).
    let (first, n) = (vertices.start, vertices.len());
    let local = |u: u32, v: u32| {
        let k = (u.min(v) as usize).wrapping_sub(first);
        (k < n).then_some(k)
    };
    let mut start = vec![0u32; n + 1];
    for (_, (u, v)) in corners() {
        if let Some(k) = local(u, v) {
            start[k + 1] += 1;
        }
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    // Each list entry: the edge's larger vertex, and the corner's number
    // times two plus one if it runs from the larger vertex.
    let mut list = vec![(0u32, 0u32); start[n] as usize];
    {
        let mut fill = start.clone();
        for (c, (u, v)) in corners() {
            if let Some(k) = local(u, v) {
                let at = &mut fill[k];
                list[*at as usize] = (u.max(v), (c as u32) << 1 | (u > v) as u32);
                *at += 1;
            }
        }
    }
    let set = |c: u32, d: u32| twin[c as usize].store(d, Ordering::Relaxed);
    let mut n_edges = 0;
    for k in 0..n {
        let edges = &mut list[start[k] as usize..start[k + 1] as usize];
        if edges.len() > LONG_LIST {
            // A vertex with many faces: pairs found by sorting, not by
            // scanning the list once per entry. Stable, so that each
            // edge's corners stay in corner order.
            edges.sort_by_key(|e| e.0);
        }
        // An entry paired with an earlier one is marked by PAIRED in
        // place of its far vertex (no vertex has that number).
        const PAIRED: u32 = u32::MAX;
        for i in 0..edges.len() {
            let (far, c) = edges[i];
            if far == PAIRED {
                continue;
            }
            n_edges += 1;
            // Entries of the same edge after this one: one running the
            // other way, or none (the boundary).
            let mut other = None;
            let rest = &mut edges[i + 1..];
            let n_rest = rest.len();
            let same_edge = if n_rest > LONG_LIST {
                let n = rest.partition_point(|e| e.0 == far);
                &mut rest[..n]
            } else {
                rest
            };
            for e in same_edge.iter_mut() {
                if e.0 == far {
                    if other.is_some() || (e.1 ^ c) & 1 == 0 {
                        return None;
                    }
                    other = Some(e.1 >> 1);
                    e.0 = PAIRED;
                }
            }
            match other {
                Some(d) => {
                    set(c >> 1, d);
                    set(d, c >> 1);
                }
                None => set(c >> 1, NO_TWIN),
            }
        }
    }
    Some(n_edges)
}

/// [`pair_corners_by_sorting`]'s pairing done one corner at a time, in face
/// order, by scanning the corners leaving each edge's two vertices
/// (a compressed adjacency list; n log n past [`LONG_LIST`] faces at a
/// vertex): the first edge that is not a plain pair is named.
pub(crate) fn pair_corners_by_scanning(n_vertices: usize, triangles: &[[u32; 3]]) -> Result<Pairing, TopologyError> {
    let n_corners = triangles.len() * 3;
    // Outgoing corners per vertex, compressed (counting sort), each with
    // its destination so that scanning a vertex's list reads one block.
    let mut start = vec![0u32; n_vertices + 1];
    for t in triangles {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for v in 0..n_vertices {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut out = vec![(0u32, 0u32); n_corners]; // (destination, corner)
    for (f, t) in triangles.iter().enumerate() {
        for i in 0..3 {
            let v = t[i] as usize;
            out[fill[v] as usize] = (t[(i + 1) % 3], (3 * f + i) as u32);
            fill[v] += 1;
        }
    }
    drop(fill);
    // A vertex with many faces (the apex of a fan of thousands) has its
    // list sorted by destination, then corner, and searched by halves:
    // scanning it once per corner would be quadratic in its degree.
    // Short lists (nearly all) stay in corner order and are scanned.
    // Either way the matches of a destination come in corner order.
    for v in 0..n_vertices {
        let list = &mut out[start[v] as usize..start[v + 1] as usize];
        if list.len() > LONG_LIST {
            list.sort_unstable();
        }
    }
    let outgoing = |v: u32| &out[start[v as usize] as usize..start[v as usize + 1] as usize];
    // The entries of `v`'s list that go to `to`, in corner order.
    let towards = |v: u32, to: u32| {
        let list = outgoing(v);
        if list.len() > LONG_LIST {
            let lo = list.partition_point(|o| o.0 < to);
            let hi = lo + list[lo..].partition_point(|o| o.0 == to);
            &list[lo..hi]
        } else {
            list
        }
    };
    let mut twin = vec![UNSET; n_corners];
    let mut n_edges = 0;
    for (c, (u, v)) in triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .enumerate()
    {
        if twin[c] != UNSET {
            continue;
        }
        n_edges += 1;
        let same = towards(u, v).iter().filter(|o| o.0 == v).count();
        let mut other = None;
        let mut opposite = 0;
        for &(d, o) in towards(v, u) {
            if d == u {
                opposite += 1;
                other = Some(o);
            }
        }
        if same + opposite > 2 {
            // The third face on the edge in list order (corner `c`, the
            // first, is the edge's lowest corner).
            let mut corners: Vec<u32> = (towards(u, v).iter().filter(|o| o.0 == v))
                .chain(towards(v, u).iter().filter(|o| o.0 == u))
                .map(|o| o.1)
                .collect();
            corners.sort_unstable();
            return Err(TopologyError::EdgeWithMoreThanTwoFaces {
                face: corners[2] as usize / 3,
                a: u,
                b: v,
            });
        }
        if same > 1 {
            let second = towards(u, v)
                .iter()
                .filter(|o| o.0 == v)
                .map(|o| o.1 as usize)
                .max()
                .unwrap_or(c);
            return Err(TopologyError::InconsistentOrientation {
                face: second / 3,
                a: u,
                b: v,
            });
        }
        match other {
            Some(t) => {
                twin[c] = t;
                twin[t as usize] = c as u32;
            }
            None => twin[c] = NO_TWIN,
        }
    }
    Ok(Pairing { twin, n_edges })
}

impl Topology {
    /// Builds the connectivity of `triangles` over `n_vertices` vertices.
    ///
    /// Every vertex must be used by some triangle. Runs in linear time for
    /// bounded degrees (n log n past 16 faces at a vertex): the directed
    /// edges are paired with their twins in lists by their edge's smaller
    /// vertex (`pair_corners_by_sorting`), not in a hash map. Where
    /// that finds an edge that is not a plain pair, the pairing is done
    /// again by scanning adjacency lists (`pair_corners_by_scanning`),
    /// which names the first fault in face order.
    pub fn from_triangles(n_vertices: usize, triangles: &[[u32; 3]]) -> Result<Topology, TopologyError> {
        refuse_beyond_ids(n_vertices, triangles.len())?;
        // The number of faces at each vertex (its corners), counted while
        // the indices are checked.
        let mut degree = vec![0u32; n_vertices];
        for (f, t) in triangles.iter().enumerate() {
            for &v in t {
                if v as usize >= n_vertices {
                    return Err(TopologyError::IndexOutOfRange { face: f, index: v });
                }
                degree[v as usize] += 1;
            }
            if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
                let vertex = if t[0] == t[1] || t[0] == t[2] { t[0] } else { t[1] };
                return Err(TopologyError::RepeatedVertex { face: f, vertex });
            }
        }
        // Corners c = 3f + i are the directed edges tri[i] -> tri[i+1];
        // twin[c] is the corner running the other way along the same edge.
        let pairing = match pair_corners_by_sorting(n_vertices, triangles) {
            Some(pairing) => pairing,
            None => pair_corners_by_scanning(n_vertices, triangles)?,
        };
        // Half-edges in the order of each edge's first corner: 2e runs as
        // that corner does, 2e + 1 the other way (with a face if the edge
        // has a twin corner, on the boundary if not). A face's three
        // corners have their half-edges once the face is reached, so its
        // `next` links and face are set there.
        let n_corners = triangles.len() * 3;
        let n_he = 2 * pairing.n_edges;
        let twin = pairing.twin;
        let spare = room_for_splits(triangles.len());
        fn with_room<T: Clone>(len: usize, room: usize, value: T) -> Vec<T> {
            let mut v = Vec::with_capacity(len + room);
            v.resize(len, value);
            v
        }
        let mut corner_he = vec![UNSET; n_corners];
        let mut he_origin = Vec::with_capacity(n_corners + n_corners / 8 + 6 * spare);
        let mut he_next = with_room(n_he, 6 * spare, HalfEdgeId::NONE);
        let mut he_face = with_room(n_he, 6 * spare, FaceId::NONE);
        let mut face_he = Vec::with_capacity(triangles.len() + 2 * spare);
        // One outgoing half-edge with a face per vertex: the first, except
        // that on the boundary it is the one whose twin has no face (the
        // first of the fan counter-clockwise); and its corner.
        let mut vertex_he = with_room(n_vertices, spare, HalfEdgeId::NONE);
        let mut vertex_corner = vec![UNSET; n_vertices];
        for (f, t) in triangles.iter().enumerate() {
            for i in 0..3 {
                let c = 3 * f + i;
                if corner_he[c] != UNSET {
                    continue;
                }
                let (u, v) = (t[i], t[(i + 1) % 3]);
                let h = he_origin.len() as u32;
                corner_he[c] = h;
                he_origin.push(VertexId(u));
                he_origin.push(VertexId(v));
                let tw = twin[c];
                if tw == NO_TWIN {
                    vertex_he[u as usize] = HalfEdgeId(h);
                    vertex_corner[u as usize] = c as u32;
                } else {
                    corner_he[tw as usize] = h + 1;
                    for (x, hx, cx) in [(u, h, c as u32), (v, h + 1, tw)] {
                        if vertex_he[x as usize].is_none() {
                            vertex_he[x as usize] = HalfEdgeId(hx);
                            vertex_corner[x as usize] = cx;
                        }
                    }
                }
            }
            let hs = [corner_he[3 * f], corner_he[3 * f + 1], corner_he[3 * f + 2]];
            for i in 0..3 {
                he_next[hs[i] as usize] = HalfEdgeId(hs[(i + 1) % 3]);
                he_face[hs[i] as usize] = FaceId(f as u32);
            }
            face_he.push(HalfEdgeId(hs[0]));
        }
        debug_assert_eq!(he_origin.len(), n_he);
        drop(corner_he);
        // Every vertex must be a single fan: walking it must meet all its
        // faces. The walk goes from corner to corner: the corner before c
        // in its face ends at c's vertex, and its twin leaves it, the next
        // face counter-clockwise. (Read-only, on every core; the first
        // failure in vertex order is reported, whatever the number of
        // threads.)
        let fan_len = |first: u32| {
            let mut c = first;
            let mut n = 0;
            loop {
                n += 1;
                let before = if c % 3 == 0 { c + 2 } else { c - 1 };
                c = twin[before as usize];
                if c == NO_TWIN || c == first || n > n_corners {
                    return n;
                }
            }
        };
        let pinched = crate::parallel::filter_indices(n_vertices, |v| {
            let degree = degree[v] as usize;
            degree != 0 && fan_len(vertex_corner[v]) != degree
        });
        if let Some(&v) = pinched.first() {
            return Err(TopologyError::NonManifoldVertex { vertex: v });
        }
        drop(twin);
        let topo = Topology {
            he_origin,
            he_next,
            he_face,
            face_he,
            vertex_he,
        };
        // An edge with the same vertex opposite on both sides: its two faces
        // share all three vertices (nothing could split or flip it soundly).
        let pillows = crate::parallel::filter_indices(topo.n_edges(), |e| {
            let h = EdgeId(e as u32).halfedge();
            topo.is_interior(EdgeId(e as u32)) && topo.apex(h) == topo.apex(h.twin())
        });
        if let Some(&e) = pillows.first() {
            let h = EdgeId(e).halfedge();
            let (f1, f2) = (topo.face(h).idx(), topo.face(h.twin()).idx());
            return Err(TopologyError::SameThreeVertices {
                first: f1.min(f2),
                face: f1.max(f2),
            });
        }
        Ok(topo)
    }

    /// One half-edge leaving `v`.
    pub fn vertex_he(&self, v: VertexId) -> HalfEdgeId {
        self.vertex_he[v.idx()]
    }

    /// Number of vertices.
    pub fn n_vertices(&self) -> usize {
        self.vertex_he.len()
    }
    /// Number of half-edges (twice the number of edges).
    pub fn n_halfedges(&self) -> usize {
        self.he_origin.len()
    }
    /// How many more splits the ids can number (six half-edges each, see
    /// [`MAX_HALFEDGES`]).
    pub fn split_room(&self) -> usize {
        (MAX_HALFEDGES - self.n_halfedges()) / 6
    }
    /// Number of edges.
    pub fn n_edges(&self) -> usize {
        self.he_origin.len() / 2
    }
    /// Number of faces.
    pub fn n_faces(&self) -> usize {
        self.face_he.len()
    }

    /// The vertex a half-edge leaves.
    #[inline]
    pub fn origin(&self, h: HalfEdgeId) -> VertexId {
        self.he_origin[h.idx()]
    }
    /// The vertex a half-edge points to.
    #[inline]
    pub fn dest(&self, h: HalfEdgeId) -> VertexId {
        self.he_origin[h.twin().idx()]
    }
    /// The next half-edge around the face (`NONE` on the boundary).
    #[inline]
    pub fn next(&self, h: HalfEdgeId) -> HalfEdgeId {
        self.he_next[h.idx()]
    }
    /// The four outer half-edges of the two faces of interior edge `e`, whose
    /// first half-edge `h` runs a → b: `[c→a, b→c, d→b, a→d]`.
    ///
    /// ```text
    ///            c
    ///      c→a /   \ b→c
    ///         a --h-> b
    ///      a→d \   / d→b
    ///            d
    /// ```
    #[inline]
    pub fn outer_halfedges(&self, e: EdgeId) -> [HalfEdgeId; 4] {
        let h = e.halfedge();
        let (h1, t1) = (self.next(h), self.next(h.twin()));
        [self.next(h1), h1, self.next(t1), t1]
    }
    /// [`Topology::outer_halfedges`] of any edge: `NONE` for the two of a
    /// side with no face (a boundary edge has one side).
    pub fn outer_halfedges_of_faces(&self, e: EdgeId) -> [HalfEdgeId; 4] {
        let h = e.halfedge();
        let side = |x: HalfEdgeId| match self.is_boundary_he(x) {
            true => [HalfEdgeId::NONE; 2],
            false => {
                let x1 = self.next(x);
                [self.next(x1), x1]
            }
        };
        let ([a, b], [c, d]) = (side(h), side(h.twin()));
        [a, b, c, d]
    }
    /// The face of a half-edge (`NONE` on the boundary).
    #[inline]
    pub fn face(&self, h: HalfEdgeId) -> FaceId {
        self.he_face[h.idx()]
    }
    /// One half-edge of a face.
    #[inline]
    pub fn face_halfedge(&self, f: FaceId) -> HalfEdgeId {
        self.face_he[f.idx()]
    }
    /// Whether a half-edge lies on the boundary (has no face). Read from
    /// `next` (also `NONE` there, see [`Topology::validate`]): the callers
    /// nearly always read it next, so the face array stays out of the cache.
    #[inline]
    pub fn is_boundary_he(&self, h: HalfEdgeId) -> bool {
        self.he_next[h.idx()].is_none()
    }
    /// Whether an edge has faces on both sides.
    #[inline]
    pub fn is_interior(&self, e: EdgeId) -> bool {
        let h = e.halfedge();
        !self.is_boundary_he(h) && !self.is_boundary_he(h.twin())
    }
    /// The vertex opposite half-edge `h` in its face (`NONE` on the boundary).
    #[inline]
    pub fn apex(&self, h: HalfEdgeId) -> VertexId {
        let n = self.he_next[h.idx()];
        if n.is_none() {
            return VertexId::NONE;
        }
        self.dest(n)
    }
    /// The three vertices of a face, in order.
    pub fn face_vertices(&self, f: FaceId) -> [VertexId; 3] {
        let h = self.face_he[f.idx()];
        let n = self.next(h);
        [self.origin(h), self.origin(n), self.dest(n)]
    }

    /// Counter-clockwise successor of the outgoing half-edge `h` around its
    /// origin, or `NONE` at the boundary.
    pub(crate) fn rotate_ccw(&self, h: HalfEdgeId) -> HalfEdgeId {
        let prev = self.next(self.next(h));
        let t = prev.twin();
        if self.is_boundary_he(t) {
            HalfEdgeId::NONE
        } else {
            t
        }
    }

    /// The three half-edges of each of `faces`, face by face.
    pub fn half_edges_of<'a>(&'a self, faces: &'a [FaceId]) -> impl Iterator<Item = HalfEdgeId> + Clone + 'a {
        faces.iter().flat_map(|&f| {
            let h = self.face_halfedge(f);
            [h, self.next(h), self.next(self.next(h))]
        })
    }

    /// Calls `f(edge, w)` for every edge at `v` and the vertex `w` at its
    /// other end, counter-clockwise from `v`'s half-edge.
    pub fn for_each_neighbour(&self, v: VertexId, mut f: impl FnMut(EdgeId, VertexId)) {
        let first = self.vertex_he[v.idx()];
        if first.is_none() {
            return;
        }
        let mut h = first;
        for _ in 0..self.he_face.len() {
            f(h.edge(), self.dest(h));
            let n = self.rotate_ccw(h);
            if n.is_none() {
                // A boundary vertex: the fan's last edge comes into v.
                let last = self.next(self.next(h));
                f(last.edge(), self.origin(last));
                return;
            }
            if n == first {
                return;
            }
            h = n;
        }
    }

    /// Whether an edge joins `u` and `v`, walking the two fans side by side:
    /// 64 edges of each, then 256, and so on up to `limit`; `None` if both
    /// fans are longer than that. The cost is of the order of the shorter
    /// fan, so a vertex with thousands of neighbours (a CAD disk's centre)
    /// costs little when its other end has few.
    pub fn are_adjacent_within_either(&self, u: VertexId, v: VertexId, limit: usize) -> Option<bool> {
        let mut cap = 64;
        loop {
            let found = self
                .are_adjacent_within(u, v, cap)
                .or_else(|| self.are_adjacent_within(v, u, cap));
            if found.is_some() || cap >= limit {
                return found;
            }
            cap = (cap * 4).min(limit);
        }
    }

    /// Whether an edge joins `u` and `v`, walking at most `cap` edges of the
    /// fan of `u`; `None` if the fan is longer than that. Private: one fan
    /// alone once made pruning give up beside long fans, and its callers
    /// took "unknown" in different ways; they all ask
    /// [`Topology::are_adjacent_within_either`].
    fn are_adjacent_within(&self, u: VertexId, v: VertexId, cap: usize) -> Option<bool> {
        let first = self.vertex_he[u.idx()];
        let mut h = first;
        for _ in 0..cap {
            if self.dest(h) == v {
                return Some(true);
            }
            let n = self.rotate_ccw(h);
            if n.is_none() {
                // Boundary vertex: the last edge of the fan is the one before the gap.
                return Some(self.dest(self.next(h)) == v);
            }
            if n == first {
                return Some(false);
            }
            h = n;
        }
        None
    }

    /// Number of faces met walking the fan of `v` from its stored half-edge.
    fn fan_len(&self, v: VertexId) -> usize {
        let first = self.vertex_he[v.idx()];
        let mut h = first;
        let mut n = 0;
        loop {
            n += 1;
            h = self.rotate_ccw(h);
            if h.is_none() || h == first || n > self.he_face.len() {
                return n;
            }
        }
    }

    /// Flips the interior edge `e` inside the quad formed by its two faces.
    /// The edge keeps its id and its two faces keep theirs.
    ///
    /// ```text
    ///         c                    c
    ///        / \                  /|\
    ///       / F1\                / | \
    ///      a --e-- b    ==>     a F1e F2 b
    ///       \ F2/                \ | /
    ///        \ /                  \|/
    ///         d                    d
    /// ```
    /// Before: F1 = (a, b, c) holds `h = 2e` (a→b), F2 = (b, a, d) its twin.
    /// After: F1 = (d, c, a) with `h` d→c, F2 = (c, d, b) with the twin c→d.
    pub fn flip(&mut self, e: EdgeId) {
        let h = e.halfedge();
        let t = h.twin();
        debug_assert!(self.is_interior(e));
        let (h1, t1) = (self.next(h), self.next(t));
        let (h2, t2) = (self.next(h1), self.next(t1));
        let (a, b) = (self.origin(h), self.origin(t));
        let (c, d) = (self.origin(h2), self.origin(t2));
        let (f1, f2) = (self.face(h), self.face(t));
        // F1: h (d→c), h2 (c→a), t1 (a→d).
        self.he_origin[h.idx()] = d;
        self.he_next[h.idx()] = h2;
        self.he_next[h2.idx()] = t1;
        self.he_next[t1.idx()] = h;
        self.he_face[t1.idx()] = f1;
        self.face_he[f1.idx()] = h;
        // F2: t (c→d), t2 (d→b), h1 (b→c).
        self.he_origin[t.idx()] = c;
        self.he_next[t.idx()] = t2;
        self.he_next[t2.idx()] = h1;
        self.he_next[h1.idx()] = t;
        self.he_face[h1.idx()] = f2;
        self.face_he[f2.idx()] = t;
        // a and b no longer own h and t.
        if self.vertex_he[a.idx()] == h {
            self.vertex_he[a.idx()] = t1;
        }
        if self.vertex_he[b.idx()] == t {
            self.vertex_he[b.idx()] = h1;
        }
    }

    /// Splits the interior edge `e` = (a, b) at a new vertex `p`, and each of
    /// its two faces in two. Returns `p`; the new edges and faces get the next
    /// free ids.
    ///
    /// ```text
    ///         c                       c
    ///        / \                    / | \
    ///       / F1\                  /F1|F3\
    ///      a --e-- b     ==>      a-e-p-e1-b
    ///       \ F2/                  \F2|F4/
    ///        \ /                    \ | /
    ///         d                       d
    /// ```
    /// With n = the old edge count and m = the old face count: `e` becomes
    /// (a, p), new edge `n` is (p, b), `n + 1` is (p, c), `n + 2` is (p, d);
    /// F1 = (a, p, c), F2 = (p, a, d), new faces `m` = (p, b, c) and
    /// `m + 1` = (b, p, d). Half-edge `2e` still leaves `a`.
    pub fn split(&mut self, e: EdgeId) -> VertexId {
        let h = e.halfedge();
        let t = h.twin();
        debug_assert!(self.is_interior(e));
        let (h1, t1) = (self.next(h), self.next(t));
        let (h2, t2) = (self.next(h1), self.next(t1));
        let b = self.origin(t);
        let (c, d) = (self.origin(h2), self.origin(t2));
        let (f1, f2) = (self.face(h), self.face(t));
        let p = VertexId(self.vertex_he.len() as u32);
        let base = self.he_origin.len() as u32;
        let (g, g_t) = (HalfEdgeId(base), HalfEdgeId(base + 1)); // p→b, b→p
        let (k, k_t) = (HalfEdgeId(base + 2), HalfEdgeId(base + 3)); // p→c, c→p
        let (m, m_t) = (HalfEdgeId(base + 4), HalfEdgeId(base + 5)); // p→d, d→p
        let f3 = FaceId(self.face_he.len() as u32);
        let f4 = FaceId(f3.0 + 1);
        self.he_origin.extend_from_slice(&[p, b, p, c, p, d]);
        self.he_next.extend_from_slice(&[HalfEdgeId::NONE; 6]);
        self.he_face.extend_from_slice(&[FaceId::NONE; 6]);
        self.face_he.extend_from_slice(&[g, g_t]);
        self.vertex_he.push(g);
        self.he_origin[t.idx()] = p;
        // F1 = (a, p, c): h, k, h2.
        self.link(f1, [h, k, h2]);
        // F3 = (p, b, c): g, h1, k_t.
        self.link(f3, [g, h1, k_t]);
        // F2 = (p, a, d): t, t1, m_t.
        self.link(f2, [t, t1, m_t]);
        // F4 = (b, p, d): g_t, m, t2.
        self.link(f4, [g_t, m, t2]);
        if self.vertex_he[b.idx()] == t {
            self.vertex_he[b.idx()] = g_t;
        }
        p
    }

    /// Splits the boundary edge `e` at a new vertex p (returned): its one
    /// face (a, b, c), where `h` = a→b is the half-edge with the face,
    /// becomes (a, p, c) and a new face (p, b, c). Ids as in
    /// [`Topology::split`], one edge fewer: edge `e` becomes a–p (on the
    /// boundary), edge n (the edge count before) p–b (on the boundary),
    /// edge n + 1 p–c; the new face is face m (the face count before).
    ///
    /// ```text
    ///          c                      c
    ///         / \                    /|\
    ///        /   \                  / | \
    ///       /  F1 \      ->        / F1|F3\
    ///      /   h   \              /  h | g \
    ///     a ------- b            a -- p -- b
    ///     (boundary: t)        (t, p->a) (g_t, b->p)
    /// ```
    pub fn split_boundary(&mut self, e: EdgeId) -> VertexId {
        let mut h = e.halfedge();
        if self.is_boundary_he(h) {
            h = h.twin();
        }
        let t = h.twin();
        debug_assert!(!self.is_boundary_he(h) && self.is_boundary_he(t));
        let h1 = self.next(h);
        let h2 = self.next(h1);
        let b = self.origin(t);
        let c = self.origin(h2);
        let f1 = self.face(h);
        let p = VertexId(self.vertex_he.len() as u32);
        let base = self.he_origin.len() as u32;
        // p→b, then b→p (base + 1: on the boundary, no face, no next).
        let g = HalfEdgeId(base);
        let (k, k_t) = (HalfEdgeId(base + 2), HalfEdgeId(base + 3)); // p→c, c→p
        let f3 = FaceId(self.face_he.len() as u32);
        self.he_origin.extend_from_slice(&[p, b, p, c]);
        self.he_next.extend_from_slice(&[HalfEdgeId::NONE; 4]);
        self.he_face.extend_from_slice(&[FaceId::NONE; 4]);
        self.face_he.push(g);
        // p's first outgoing half-edge counter-clockwise, its twin on the
        // boundary: p→b.
        self.vertex_he.push(g);
        // The boundary half-edge b→a is now p→a (no face, no next).
        self.he_origin[t.idx()] = p;
        // F1 = (a, p, c): h, k, h2.
        self.link(f1, [h, k, h2]);
        // F3 = (p, b, c): g, h1, k_t.
        self.link(f3, [g, h1, k_t]);
        // (b's outgoing half-edges with a face are those it had: b→a had
        // none, so b's own is unchanged; so are a's and c's.)
        p
    }

    /// Undoes [`Topology::split`] on a vertex of degree four: `hu` runs from
    /// `u` to the vertex `p` to remove, which must have exactly the four
    /// neighbours u, x, w, y (x and y opposite the two halves). Edge `hu`
    /// becomes (u, w); the edges p–w, p–x, p–y, the two faces beside p–w and
    /// p itself are left dead (no origin, face or next) until
    /// [`Topology::compact`]. Returns the dead edges and faces, or `None`
    /// (nothing changed) if `p` does not have that shape.
    ///
    /// ```text
    ///         x                       x
    ///       / | \                   /       ///      /F1|F3\                 / F1      ///     u --p-- w     ==>       u ----- w
    ///      \F2|F4/                 \ F2  /
    ///       \ | /                   \   /
    ///         y                       y
    /// ```
    pub fn unsplit(&mut self, hu: HalfEdgeId) -> Option<([EdgeId; 3], [FaceId; 2])> {
        let tu = hu.twin(); // p→u
        let (k, t1) = (self.next(hu), self.next(tu)); // p→x, u→y
        if k.is_none() || t1.is_none() {
            return None;
        }
        let (h2, m_t) = (self.next(k), self.next(t1)); // x→u, y→p
        let m = m_t.twin(); // p→y
        let t2 = self.next(m); // y→w
        if t2.is_none() {
            return None;
        }
        let g_t = self.next(t2); // w→p
        let g = g_t.twin(); // p→w
        let gw = self.next(g); // w→x
        if gw.is_none() || self.next(gw) != k.twin() {
            return None;
        }
        // The faces F1, F2, F4, F3 close up around p: it has degree four.
        let (u, w) = (self.origin(hu), self.origin(g_t));
        let (x, y) = (self.origin(h2), self.origin(t2));
        if u == w || x == y {
            return None;
        }
        let p = self.origin(tu);
        let (f1, f2, f3, f4) = (self.face(hu), self.face(tu), self.face(g), self.face(g_t));
        self.he_origin[tu.idx()] = w;
        self.link(f1, [hu, gw, h2]);
        self.link(f2, [tu, t1, t2]);
        for v in [u, w, x, y] {
            let vh = self.vertex_he[v.idx()];
            if vh == g_t {
                self.vertex_he[v.idx()] = tu;
            } else if vh == k.twin() {
                self.vertex_he[v.idx()] = h2;
            } else if vh == m_t {
                self.vertex_he[v.idx()] = t2;
            }
        }
        for h in [g, g_t, k, k.twin(), m, m_t] {
            self.he_origin[h.idx()] = VertexId::NONE;
            self.he_next[h.idx()] = HalfEdgeId::NONE;
            self.he_face[h.idx()] = FaceId::NONE;
        }
        for f in [f3, f4] {
            self.face_he[f.idx()] = HalfEdgeId::NONE;
        }
        self.vertex_he[p.idx()] = HalfEdgeId::NONE;
        Some(([g.edge(), k.edge(), m.edge()], [f3, f4]))
    }

    /// Saves the entries of the given elements that [`Topology::flip`] or
    /// [`Topology::unsplit`] may write, for [`Topology::restore`].
    pub fn save(&self, hes: &[HalfEdgeId], faces: &[FaceId], verts: &[VertexId], out: &mut Vec<Saved>) {
        for &h in hes {
            let i = h.idx();
            out.push(Saved::HalfEdge(h, self.he_origin[i], self.he_next[i], self.he_face[i]));
        }
        out.extend(faces.iter().map(|&f| Saved::Face(f, self.face_he[f.idx()])));
        out.extend(verts.iter().map(|&v| Saved::Vertex(v, self.vertex_he[v.idx()])));
    }

    /// Writes back entries saved by [`Topology::save`], newest first.
    pub fn restore(&mut self, saved: &[Saved]) {
        for s in saved.iter().rev() {
            match *s {
                Saved::HalfEdge(h, o, n, f) => {
                    self.he_origin[h.idx()] = o;
                    self.he_next[h.idx()] = n;
                    self.he_face[h.idx()] = f;
                }
                Saved::Face(f, h) => self.face_he[f.idx()] = h,
                Saved::Vertex(v, h) => self.vertex_he[v.idx()] = h,
                Saved::Lengths(hes, faces, verts) => {
                    let (hes, faces, verts) = (hes as usize, faces as usize, verts as usize);
                    self.he_origin.truncate(hes);
                    self.he_next.truncate(hes);
                    self.he_face.truncate(hes);
                    self.face_he.truncate(faces);
                    self.vertex_he.truncate(verts);
                }
                Saved::Flip(e, g1, g2, moved) => self.unflip(e, [g1, g2], moved),
            }
        }
    }

    /// The entry that undoes the growth of the arrays by later splits.
    pub fn lengths(&self) -> Saved {
        let len = |n: usize| u32::try_from(n).expect("ids are 32-bit");
        Saved::Lengths(
            len(self.he_origin.len()),
            len(self.face_he.len()),
            len(self.vertex_he.len()),
        )
    }

    /// The entry that undoes [`Topology::flip`] of the interior edge `e`,
    /// taken just before it (see [`Saved::Flip`]).
    #[inline]
    pub fn flip_record(&self, e: EdgeId) -> Saved {
        let (h, t) = (e.halfedge(), e.halfedge().twin());
        let (f1, f2) = (self.face(h), self.face(t));
        let moved = u8::from(self.vertex_he[self.origin(h).idx()] == h)
            | (u8::from(self.vertex_he[self.origin(t).idx()] == t) << 1);
        Saved::Flip(e, self.face_he[f1.idx()], self.face_he[f2.idx()], moved)
    }

    /// Undoes [`Topology::flip`] of `e`, the mesh being as the flip left it:
    /// every entry the flip wrote is found again from the flipped quad (the
    /// flip's `h2`, `t1` follow `h`, and its `t2`, `h1` follow `t`), but the
    /// faces' half-edges `faces` and which ends' outgoing half-edges
    /// `moved` (see [`Saved::Flip`]).
    fn unflip(&mut self, e: EdgeId, faces: [HalfEdgeId; 2], moved: u8) {
        let (h, t) = (e.halfedge(), e.halfedge().twin());
        let (h2, t2) = (self.next(h), self.next(t));
        let (t1, h1) = (self.next(h2), self.next(t2));
        let (a, b) = (self.origin(t1), self.origin(h1));
        let (f1, f2) = (self.face(h), self.face(t));
        // F1: h (a→b), h1 (b→c), h2 (c→a); F2: t (b→a), t1 (a→d), t2 (d→b).
        self.he_origin[h.idx()] = a;
        self.he_next[h.idx()] = h1;
        self.he_next[h1.idx()] = h2;
        self.he_next[h2.idx()] = h;
        self.he_face[h1.idx()] = f1;
        self.face_he[f1.idx()] = faces[0];
        self.he_origin[t.idx()] = b;
        self.he_next[t.idx()] = t1;
        self.he_next[t1.idx()] = t2;
        self.he_next[t2.idx()] = t;
        self.he_face[t1.idx()] = f2;
        self.face_he[f2.idx()] = faces[1];
        if moved & 1 != 0 {
            self.vertex_he[a.idx()] = h;
        }
        if moved & 2 != 0 {
            self.vertex_he[b.idx()] = t;
        }
    }

    /// Whether `e` was removed by [`Topology::unsplit`].
    pub fn is_dead_edge(&self, e: EdgeId) -> bool {
        self.he_origin[e.halfedge().idx()].is_none()
    }

    /// Whether `v` was removed by [`Topology::unsplit`].
    pub fn is_dead_vertex(&self, v: VertexId) -> bool {
        self.vertex_he[v.idx()].is_none()
    }

    /// Drops the elements left dead by [`Topology::unsplit`], keeping the
    /// others in order. Returns the new id of every old vertex, edge and
    /// face (`NONE` for dead ones).
    pub fn compact(&mut self) -> (Vec<VertexId>, Vec<EdgeId>, Vec<FaceId>) {
        fn renumber<T: Copy>(alive: impl Iterator<Item = bool>, make: fn(u32) -> T, none: T) -> Vec<T> {
            let mut next = 0;
            alive
                .map(|a| {
                    if a {
                        next += 1;
                        make(next - 1)
                    } else {
                        none
                    }
                })
                .collect()
        }
        let vmap = renumber(self.vertex_he.iter().map(|h| !h.is_none()), VertexId, VertexId::NONE);
        let emap = renumber(
            (0..self.n_edges()).map(|e| !self.he_origin[2 * e].is_none()),
            EdgeId,
            EdgeId::NONE,
        );
        let fmap = renumber(self.face_he.iter().map(|h| !h.is_none()), FaceId, FaceId::NONE);
        let hmap = |h: HalfEdgeId| {
            if h.is_none() {
                h
            } else {
                HalfEdgeId(emap[h.edge().idx()].0 * 2 + (h.0 & 1))
            }
        };
        let mut w = 0;
        for i in 0..self.he_origin.len() {
            if emap[i / 2].is_none() {
                continue;
            }
            let o = self.he_origin[i];
            self.he_origin[w] = vmap[o.idx()];
            self.he_next[w] = hmap(self.he_next[i]);
            let f = self.he_face[i];
            self.he_face[w] = if f.is_none() { f } else { fmap[f.idx()] };
            w += 1;
        }
        self.he_origin.truncate(w);
        self.he_next.truncate(w);
        self.he_face.truncate(w);
        self.face_he = self.face_he.iter().filter(|h| !h.is_none()).map(|&h| hmap(h)).collect();
        self.vertex_he = self
            .vertex_he
            .iter()
            .filter(|h| !h.is_none())
            .map(|&h| hmap(h))
            .collect();
        (vmap, emap, fmap)
    }

    fn link(&mut self, f: FaceId, hs: [HalfEdgeId; 3]) {
        for i in 0..3 {
            self.he_next[hs[i].idx()] = hs[(i + 1) % 3];
            self.he_face[hs[i].idx()] = f;
        }
        self.face_he[f.idx()] = hs[0];
    }

    /// Reserves room for `splits` more edge splits, so that the main loop does
    /// not reallocate.
    pub fn reserve_splits(&mut self, splits: usize) {
        self.he_origin.reserve(6 * splits);
        self.he_next.reserve(6 * splits);
        self.he_face.reserve(6 * splits);
        self.face_he.reserve(2 * splits);
        self.vertex_he.reserve(splits);
    }

    /// Replaces the triangles of a patch, the faces `faces` whose edges
    /// inside the patch (both sides in it) are `inner`, by `triangles`,
    /// another triangulation of the same patch: the same vertices, the same
    /// outline. The faces and the inner edges keep their ids (face `faces[i]`
    /// becomes `triangles[i]`, the inner edges are dealt out in turn to the
    /// new inner edges), the outline's half-edges keep theirs and their
    /// origins. Returns false, changing nothing, if `triangles` does not fit:
    /// another count, an outline half-edge not used exactly once, an inner
    /// edge used on one side only or twice the same way.
    ///
    /// ```text
    ///    a-------b         a-------b      the outline (a, b, c, d, e) and
    ///    |\      |         |    _/ |      its half-edges stay; the inner
    ///    | \  f0 |   ==>   | f0/ f1|      edges (here 2) and faces (3) are
    ///    |f1\____c         |  / ___c      dealt out again
    ///    |  / f2 /          | /_/ f2/
    ///    e-'----d           e-------d
    /// ```
    pub fn retriangulate(&mut self, faces: &[FaceId], inner: &[EdgeId], triangles: &[[VertexId; 3]]) -> bool {
        use crate::hash::FastMap;
        if triangles.len() != faces.len() {
            return false;
        }
        let is_inner: FastMap<EdgeId, ()> = inner.iter().map(|&e| (e, ())).collect();
        let mut outline: FastMap<(VertexId, VertexId), HalfEdgeId> = FastMap::default();
        for &f in faces {
            let mut h = self.face_halfedge(f);
            for _ in 0..3 {
                if !is_inner.contains_key(&h.edge()) {
                    outline.insert((self.origin(h), self.dest(h)), h);
                }
                h = self.next(h);
            }
        }
        // Each triangle's three half-edges: an outline one, or a side of an
        // inner edge, whose other side is then waiting (Some) until the
        // neighbouring triangle takes it (None: both sides taken).
        let mut sides: FastMap<(VertexId, VertexId), Option<HalfEdgeId>> = FastMap::default();
        let mut dealt = 0;
        let mut plan: Vec<[HalfEdgeId; 3]> = Vec::with_capacity(triangles.len());
        for t in triangles {
            let mut hs = [HalfEdgeId::NONE; 3];
            for k in 0..3 {
                let (u, v) = (t[k], t[(k + 1) % 3]);
                hs[k] = if let Some(h) = outline.remove(&(u, v)) {
                    h
                } else if let Some(side) = sides.get_mut(&(u, v)) {
                    match side.take() {
                        Some(h) => h,
                        None => return false, // u -> v twice
                    }
                } else {
                    let Some(&e) = inner.get(dealt) else {
                        return false; // more inner edges than the patch has
                    };
                    dealt += 1;
                    sides.insert((u, v), None);
                    sides.insert((v, u), Some(e.halfedge().twin()));
                    e.halfedge()
                };
            }
            plan.push(hs);
        }
        if !outline.is_empty() || dealt != inner.len() || sides.values().any(Option::is_some) {
            return false;
        }
        for ((&f, t), hs) in faces.iter().zip(triangles).zip(&plan) {
            for k in 0..3 {
                let h = hs[k].idx();
                self.he_origin[h] = t[k];
                self.he_next[h] = hs[(k + 1) % 3];
                self.he_face[h] = f;
            }
            self.face_he[f.idx()] = hs[0];
        }
        // A vertex whose outgoing half-edge was an inner one dealt out to
        // another vertex takes one of its new ones. (A vertex on the mesh's
        // boundary keeps its own: a boundary half-edge is on the outline.)
        for (t, hs) in triangles.iter().zip(&plan) {
            for k in 0..3 {
                let v = t[k];
                let h = self.vertex_he[v.idx()];
                if is_inner.contains_key(&h.edge()) && self.origin(h) != v {
                    self.vertex_he[v.idx()] = hs[k];
                }
            }
        }
        true
    }

    /// The faces as vertex triples, in face order.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        crate::parallel::map(self.n_faces(), |f| self.face_vertices(FaceId(f as u32)).map(|v| v.0))
    }

    /// Checks every invariant of the structure; `Err` describes the first one
    /// broken. Linear time; meant for tests and debug runs.
    pub fn validate(&self) -> Result<(), String> {
        let n_he = self.he_origin.len();
        if n_he % 2 != 0 || self.he_next.len() != n_he || self.he_face.len() != n_he {
            return Err("half-edge arrays disagree in length".into());
        }
        for i in 0..n_he {
            let h = HalfEdgeId(i as u32);
            let v = self.origin(h);
            if v.idx() >= self.n_vertices() {
                return Err(format!("{h:?} has origin {v:?} out of range"));
            }
            if self.origin(h) == self.dest(h) {
                return Err(format!("{h:?} is a loop at {v:?}"));
            }
            let f = self.face(h);
            if f.is_none() != self.next(h).is_none() {
                return Err(format!("{h:?}: face {f:?} but next {:?}", self.next(h)));
            }
            if f.is_none() {
                if self.is_boundary_he(h.twin()) {
                    return Err(format!("edge {:?} has no face on either side", h.edge()));
                }
                continue;
            }
            let n = self.next(h);
            if n.is_none() || self.face(n) != f {
                return Err(format!("{h:?}: next {n:?} is not in face {f:?}"));
            }
            if self.origin(n) != self.dest(h) {
                return Err(format!("{h:?}: next does not start where it ends"));
            }
            if self.next(self.next(n)) != h {
                return Err(format!("{h:?}: face {f:?} is not a triangle"));
            }
        }
        for f in 0..self.n_faces() {
            let h = self.face_he[f];
            if self.face(h) != FaceId(f as u32) {
                return Err(format!("face {f}: its half-edge {h:?} is in another face"));
            }
            let [a, b, c] = self.face_vertices(FaceId(f as u32));
            if a == b || b == c || c == a {
                return Err(format!("face {f} repeats a vertex"));
            }
        }
        // Each vertex: a valid outgoing half-edge and a single fan covering
        // all its faces; no two edges join the same pair of vertices.
        let mut corners = vec![0usize; self.n_vertices()];
        for f in 0..self.n_faces() {
            for v in self.face_vertices(FaceId(f as u32)) {
                corners[v.idx()] += 1;
            }
        }
        let mut seen = vec![u32::MAX; self.n_vertices()];
        for (v, &used_by) in corners.iter().enumerate() {
            let vid = VertexId(v as u32);
            let h = self.vertex_he[v];
            if h.is_none() || h.idx() >= n_he || self.origin(h) != vid || self.is_boundary_he(h) {
                return Err(format!("{vid:?}: bad outgoing half-edge {h:?}"));
            }
            // Walking counter-clockwise from the stored half-edge must meet every
            // face (on a boundary vertex it must therefore start the fan).
            if self.fan_len(vid) != used_by {
                return Err(format!(
                    "{vid:?}: fan of {} faces, but {used_by} faces use it",
                    self.fan_len(vid)
                ));
            }
            // Neighbours must be distinct.
            let mut g = h;
            loop {
                let w = self.dest(g);
                if seen[w.idx()] == v as u32 {
                    return Err(format!("two edges join {vid:?} and {w:?}"));
                }
                seen[w.idx()] = v as u32;
                let next = self.rotate_ccw(g);
                if next.is_none() {
                    // Boundary: also the last edge of the fan.
                    let last = self.next(g);
                    let w = self.dest(last);
                    if seen[w.idx()] == v as u32 {
                        return Err(format!("two edges join {vid:?} and {w:?}"));
                    }
                    seen[w.idx()] = v as u32;
                    break;
                }
                if next == h {
                    break;
                }
                g = next;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Möbius band (five triangles on five vertices, each running along
    /// the edge it shares with the next in the same direction: an odd cycle
    /// of disagreements) is not orientable; a tetrahedron with one face
    /// turned over is (turn that face back); and the question is of the
    /// component of the face asked about.
    #[test]
    fn component_is_orientable_tells_a_moebius_band_from_a_turned_face() {
        let band: Vec<[u32; 3]> = (0..5).map(|i| [i, (i + 1) % 5, (i + 2) % 5]).collect();
        assert!((0..5).all(|f| !component_is_orientable(&band, f)));
        let tetrahedron = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        assert!(component_is_orientable(&tetrahedron, 0));
        let turned = [[0, 2, 1], [0, 3, 1], [1, 2, 3], [0, 3, 2]];
        assert!(Topology::from_triangles(4, &turned).is_err());
        assert!((0..4).all(|f| component_is_orientable(&turned, f)));
        // The band and, apart, a triangle (vertices 5 to 7).
        let both: Vec<[u32; 3]> = band.iter().copied().chain([[5, 6, 7]]).collect();
        assert!(component_is_orientable(&both, 5));
        assert!(!component_is_orientable(&both, 0));
    }

    /// The faces of `t` as vertex triples, each from its lowest corner, sorted.
    fn face_set(t: &Topology) -> Vec<[u32; 3]> {
        let mut faces: Vec<[u32; 3]> = (t.triangles().into_iter())
            .map(|f| {
                let k = (0..3).min_by_key(|&k| f[k]).unwrap();
                [f[k], f[(k + 1) % 3], f[(k + 2) % 3]]
            })
            .collect();
        faces.sort_unstable();
        faces
    }

    #[test]
    fn retriangulate_deals_out_faces_and_inner_edges_again_or_changes_nothing() {
        // A pentagon fanned from 0 (inner edges 0-2 and 0-3) inside an
        // octahedron-like closed mesh: the fan's apex 5 caps it below.
        let pentagon: Vec<[u32; 3]> = vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]];
        let mut triangles = pentagon.clone();
        triangles.extend((0..5).map(|i| [(i + 1) % 5, i, 5]));
        let mut t = Topology::from_triangles(6, &triangles).unwrap();
        let faces = [FaceId(0), FaceId(1), FaceId(2)];
        let inner: Vec<EdgeId> = (0..t.n_edges() as u32)
            .map(EdgeId)
            .filter(|&e| {
                let h = e.halfedge();
                faces.contains(&t.face(h)) && faces.contains(&t.face(h.twin()))
            })
            .collect();
        assert_eq!(inner.len(), 2);
        let before = t.clone();
        let v = |t: [u32; 3]| t.map(VertexId);
        // Wrong: a face too few; an edge used twice the same way; a
        // triangle off the outline.
        for wrong in [
            vec![v([1, 2, 4]), v([2, 3, 4])],
            vec![v([1, 2, 4]), v([1, 2, 4]), v([4, 0, 1])],
            vec![v([0, 1, 2]), v([0, 2, 3]), v([0, 3, 5])],
        ] {
            assert!(!t.retriangulate(&faces, &inner, &wrong), "{wrong:?}");
            assert!(t == before);
        }
        // Right: the fan of 2, then back to the fan of 0.
        let fan2 = vec![v([2, 3, 4]), v([2, 4, 0]), v([2, 0, 1])];
        assert!(t.retriangulate(&faces, &inner, &fan2));
        t.validate().unwrap();
        let mut expected: Vec<[u32; 3]> = vec![[0, 1, 2], [0, 2, 4], [2, 3, 4]];
        expected.extend((0..5).map(|i| {
            let f = [(i + 1) % 5, i, 5];
            let k = (0..3).min_by_key(|&k| f[k]).unwrap();
            [f[k], f[(k + 1) % 3], f[(k + 2) % 3]]
        }));
        expected.sort_unstable();
        assert_eq!(face_set(&t), expected);
        let fan0: Vec<[VertexId; 3]> = pentagon.iter().map(|&f| v(f)).collect();
        assert!(t.retriangulate(&faces, &inner, &fan0));
        t.validate().unwrap();
        assert_eq!(face_set(&t), face_set(&before));
    }

    /// Octahedron: closed, every vertex of degree 4.
    fn octahedron() -> Vec<[u32; 3]> {
        vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ]
    }

    #[test]
    fn builds_closed_and_open_meshes() {
        let t = Topology::from_triangles(6, &octahedron()).unwrap();
        t.validate().unwrap();
        assert_eq!((t.n_vertices(), t.n_edges(), t.n_faces()), (6, 12, 8));
        // A square of two triangles: 5 edges, 4 on the boundary.
        let s = Topology::from_triangles(4, &[[0, 1, 2], [0, 2, 3]]).unwrap();
        s.validate().unwrap();
        assert_eq!(s.n_edges(), 5);
        assert_eq!((0..5).filter(|&e| s.is_interior(EdgeId(e))).count(), 1);
        assert_eq!(s.triangles(), vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn refuses_bad_topology() {
        let three = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        assert!(matches!(
            Topology::from_triangles(5, &three),
            Err(TopologyError::EdgeWithMoreThanTwoFaces { .. })
        ));
        let flipped = [[0, 1, 2], [0, 1, 3]];
        assert!(matches!(
            Topology::from_triangles(4, &flipped),
            Err(TopologyError::InconsistentOrientation { face: 1, a: 0, b: 1 })
        ));
        // Two triangles sharing only vertex 0: a bow tie.
        let bowtie = [[0, 1, 2], [0, 3, 4]];
        assert_eq!(
            Topology::from_triangles(5, &bowtie).unwrap_err(),
            TopologyError::NonManifoldVertex { vertex: 0 }
        );
        assert!(matches!(
            Topology::from_triangles(3, &[[0, 1, 3]]),
            Err(TopologyError::IndexOutOfRange { index: 3, .. })
        ));
        assert!(matches!(
            Topology::from_triangles(3, &[[0, 1, 1]]),
            Err(TopologyError::RepeatedVertex { vertex: 1, .. })
        ));
        assert_eq!(
            Topology::from_triangles(3, &[[0, 1, 2], [0, 2, 1]]).map(|_| ()),
            Err(TopologyError::SameThreeVertices { first: 0, face: 1 })
        );
    }

    /// The two ways of pairing corners agree: on random soups of
    /// triangles over a few vertices (most edges faulty), on meshes with
    /// some faces turned over or repeated, and past [`LONG_LIST`] faces at
    /// a vertex, the sorting pairs exactly when the scanning does, with
    /// the same twins and edge count.
    #[test]
    fn pairing_by_sorting_agrees_with_scanning() {
        let mut rng = crate::test_rng::Rng(0x5eed_7091);
        let mut cases: Vec<(usize, Vec<[u32; 3]>)> = vec![(6, octahedron()), (42, double_cone(40))];
        for _ in 0..400 {
            let n = 3 + rng.below(8) as u32;
            let faces = (0..1 + rng.below(12))
                .filter_map(|_| {
                    let t = [0, 1, 2].map(|_| rng.below(n as u64) as u32);
                    (t[0] != t[1] && t[1] != t[2] && t[2] != t[0]).then_some(t)
                })
                .collect();
            cases.push((n as usize, faces));
        }
        for base in [octahedron(), double_cone(40)] {
            let n = base.iter().flatten().max().map_or(0, |&m| m as usize + 1);
            for _ in 0..100 {
                let mut faces = base.clone();
                let f = rng.below(faces.len() as u64) as usize;
                match rng.below(3) {
                    0 => faces[f].swap(0, 1),
                    1 => faces.push(faces[f]),
                    _ => {
                        faces.remove(f);
                    }
                }
                cases.push((n, faces));
            }
        }
        let (mut paired, mut refused) = (0, 0);
        for (n, faces) in &cases {
            match (pair_corners_by_sorting(*n, faces), pair_corners_by_scanning(*n, faces)) {
                (Some(a), Ok(b)) => {
                    assert_eq!((&a.twin, a.n_edges), (&b.twin, b.n_edges), "{faces:?}");
                    paired += 1;
                }
                (None, Err(_)) => refused += 1,
                (a, b) => panic!("{faces:?}: sorting {:?}, scanning {:?}", a.is_some(), b.is_ok()),
            }
        }
        assert!(paired > 100 && refused > 100, "{paired} paired, {refused} refused");
    }

    /// On a mesh large enough for threads, the pairing is the same on two
    /// threads, on one, and by scanning: a grid of 40,000 vertices as it
    /// is, with a face turned over or repeated in either thread's range of
    /// vertices, and with holes.
    #[test]
    fn pairing_does_not_depend_on_threads() {
        let side = 200u32;
        let mut grid = Vec::new();
        for y in 0..side - 1 {
            for x in 0..side - 1 {
                let v = y * side + x;
                grid.push([v, v + 1, v + side + 1]);
                grid.push([v, v + side + 1, v + side]);
            }
        }
        let n = (side * side) as usize;
        assert!(n > crate::parallel::MIN_PARALLEL_ITEMS);
        let mut cases = vec![grid.clone()];
        for f in [10, grid.len() / 2 + 7, grid.len() - 3] {
            let mut turned = grid.clone();
            turned[f].swap(0, 1);
            let mut repeated = grid.clone();
            repeated.push(grid[f]);
            let mut holed = grid.clone();
            holed.remove(f);
            cases.extend([turned, repeated, holed]);
        }
        let show = |p: Option<Pairing>| p.map(|p| (p.twin, p.n_edges));
        for faces in &cases {
            let (threaded, alone) = crate::parallel::threaded_and_alone(2, || show(pair_corners_by_sorting(n, faces)));
            assert!(threaded == alone);
            match (threaded, pair_corners_by_scanning(n, faces)) {
                (Some(a), Ok(b)) => assert!(a == (b.twin, b.n_edges)),
                (None, Err(_)) => {}
                (a, b) => panic!("sorting {:?}, scanning {:?}", a.is_some(), b.is_ok()),
            }
        }
    }

    /// A vertex whose faces form two fans is refused, whether the fans are
    /// closed (two octahedra sharing a vertex) or one is closed and one
    /// open (an octahedron with a triangle hanging from a vertex).
    #[test]
    fn refuses_two_fans_at_a_vertex() {
        let shifted = |d: u32| {
            octahedron()
                .into_iter()
                .map(move |t| t.map(|v| if v == 0 { 0 } else { v + d }))
        };
        let two_closed: Vec<_> = octahedron().into_iter().chain(shifted(5)).collect();
        assert_eq!(
            Topology::from_triangles(11, &two_closed).unwrap_err(),
            TopologyError::NonManifoldVertex { vertex: 0 }
        );
        for hanging in [[0, 6, 7], [6, 0, 7], [6, 7, 0]] {
            let mut faces = octahedron();
            faces.insert(3, hanging);
            assert_eq!(
                Topology::from_triangles(8, &faces).unwrap_err(),
                TopologyError::NonManifoldVertex { vertex: 0 }
            );
        }
    }

    /// A closed cone: apex 0 and base centre 1, joined to n rim vertices
    /// 2..n+2 (both of degree n, past [`LONG_LIST`]).
    fn double_cone(n: u32) -> Vec<[u32; 3]> {
        let rim = |i: u32| 2 + i % n;
        (0..n)
            .flat_map(|i| [[0, rim(i), rim(i + 1)], [1, rim(i + 1), rim(i)]])
            .collect()
    }

    /// Adjacency of two vertices of high degree: found by walking their
    /// fans side by side, or unknown (`None`) only while both fans are
    /// longer than the limit.
    #[test]
    fn adjacency_between_long_fans() {
        let n = 300u32;
        // Apex 0 and base centre 1: degree n each, not joined.
        let t = Topology::from_triangles(n as usize + 2, &double_cone(n)).unwrap();
        let (apex, centre, rim) = (VertexId(0), VertexId(1), |i: u32| VertexId(2 + i % n));
        assert_eq!(t.are_adjacent_within_either(apex, centre, 64), None);
        assert_eq!(t.are_adjacent_within_either(apex, centre, 1024), Some(false));
        for i in [0, 1, n / 2, n - 1] {
            assert_eq!(t.are_adjacent_within_either(apex, rim(i), 64), Some(true));
            assert_eq!(t.are_adjacent_within_either(rim(i), rim(i + 1), 64), Some(true));
            assert_eq!(t.are_adjacent_within_either(rim(i), rim(i + 2), 64), Some(false));
        }
        // An open disc where 0 and 1 are joined, each with about n
        // neighbours: 0's fan over the chain q_0..q_n, 1's over q_n..q_2n.
        let q = |i: u32| 2 + i;
        let mut disc: Vec<[u32; 3]> = (0..n).map(|i| [0, q(i), q(i + 1)]).collect();
        disc.push([0, q(n), 1]);
        disc.extend((n..2 * n).map(|i| [1, q(i), q(i + 1)]));
        disc.push([1, q(2 * n), 0]);
        let t = Topology::from_triangles(2 * n as usize + 3, &disc).unwrap();
        t.validate().unwrap();
        assert_eq!(t.are_adjacent_within_either(VertexId(0), VertexId(1), 1024), Some(true));
        assert_eq!(t.are_adjacent_within_either(VertexId(1), VertexId(0), 1024), Some(true));
        assert_eq!(
            t.are_adjacent_within_either(VertexId(1), VertexId(q(0)), 1024),
            Some(false)
        );
    }

    /// Meshes past the 32-bit ids are refused before anything is built, and
    /// a mesh's room for splits never reaches `NONE`: the last split's last
    /// half-edge is `u32::MAX - 1` at most.
    #[test]
    fn ids_never_run_past_their_room() {
        // A soup at the limit: six half-edges a triangle, all numbered.
        assert_eq!(6 * MAX_TRIANGLES, MAX_HALFEDGES - 3);
        assert!(refuse_beyond_ids(3 * MAX_TRIANGLES, MAX_TRIANGLES).is_ok());
        let past = refuse_beyond_ids(1000, MAX_TRIANGLES + 1).unwrap_err();
        assert!(matches!(past, TopologyError::TooLarge { triangles, .. } if triangles == MAX_TRIANGLES + 1));
        assert_eq!(
            past.to_string(),
            "715827883 triangles over 1000 vertices: more than 32-bit ids can number (at most 715827882 triangles)"
        );
        assert!(refuse_beyond_ids(MAX_HALFEDGES + 1, 10).is_err());
        // from_triangles refuses before allocating anything per vertex.
        assert!(matches!(
            Topology::from_triangles(MAX_HALFEDGES + 1, &[]),
            Err(TopologyError::TooLarge { .. })
        ));
        // The room left on a small mesh, and after splits that use it.
        let mut t = Topology::from_triangles(6, &octahedron()).unwrap();
        assert_eq!(t.n_halfedges(), 24);
        assert_eq!(t.split_room(), (u32::MAX as usize - 24) / 6);
        for _ in 0..10 {
            let room = t.split_room();
            t.split(EdgeId(0));
            assert_eq!(t.split_room(), room - 1);
        }
        // At the largest closed mesh: hundreds of millions of splits, and
        // the last id they would use is below NONE.
        let closed = 3 * MAX_TRIANGLES;
        let room = (MAX_HALFEDGES - closed) / 6;
        assert!(room > 357_000_000);
        assert!(closed + 6 * room - 1 < HalfEdgeId::NONE.idx());
    }

    /// High-degree vertices (their corner lists sorted and searched by
    /// halves) give the same structure and the same errors, naming the same
    /// face, as low-degree ones.
    #[test]
    fn builds_and_refuses_around_high_degree_vertices() {
        for n in [5, 16, 17, 300] {
            let cone = double_cone(n);
            let t = Topology::from_triangles(n as usize + 2, &cone).unwrap();
            t.validate().unwrap();
            assert_eq!((t.n_edges(), t.n_faces()), (3 * n as usize, 2 * n as usize));
            assert_eq!(t.fan_len(VertexId(0)), n as usize);
            // Face 2n = (0, rim m+1, rim m) again, reversed: edge 0-(rim m)
            // gets a third face, the one reported.
            let m = n / 2;
            let mut bad = cone.clone();
            bad.push([0, 2 + (m + 1) % n, 2 + m]);
            assert!(
                matches!(
                    Topology::from_triangles(n as usize + 2, &bad),
                    Err(TopologyError::EdgeWithMoreThanTwoFaces { face, a: 2.., b: 0 }) if face == 2 * n as usize
                ),
                "{n}: {:?}",
                Topology::from_triangles(n as usize + 2, &bad).map(|_| ())
            );
            // One face of the apex's fan reversed: reported at that face.
            let mut flipped = cone.clone();
            let k = 2 * (n as usize / 2);
            flipped[k].swap(1, 2);
            assert!(
                matches!(
                    Topology::from_triangles(n as usize + 2, &flipped),
                    Err(TopologyError::InconsistentOrientation { face, .. }) if face == k
                ),
                "{n}: {:?}",
                Topology::from_triangles(n as usize + 2, &flipped).map(|_| ())
            );
        }
    }

    #[test]
    fn flip_keeps_structure() {
        let mut t = Topology::from_triangles(4, &[[0, 1, 2], [1, 0, 3]]).unwrap();
        let e = (0..t.n_edges() as u32).map(EdgeId).find(|&e| t.is_interior(e)).unwrap();
        t.flip(e);
        t.validate().unwrap();
        let (o, d) = (t.origin(e.halfedge()), t.dest(e.halfedge()));
        assert_eq!([o.0.min(d.0), o.0.max(d.0)], [2, 3]);
        // Flipping back restores the edge (0, 1).
        t.flip(e);
        t.validate().unwrap();
        let (o, d) = (t.origin(e.halfedge()), t.dest(e.halfedge()));
        assert_eq!([o.0.min(d.0), o.0.max(d.0)], [0, 1]);
        // Every edge of an octahedron, flipped and flipped back.
        let mut t = Topology::from_triangles(6, &octahedron()).unwrap();
        let before = t.triangles();
        for e in 0..t.n_edges() as u32 {
            t.flip(EdgeId(e));
            t.validate().unwrap();
            t.flip(EdgeId(e));
            t.validate().unwrap();
        }
        let sorted = |mut v: Vec<[u32; 3]>| {
            for t in v.iter_mut() {
                let m = (0..3).min_by_key(|&i| t[i]).unwrap();
                t.rotate_left(m);
            }
            v.sort();
            v
        };
        assert_eq!(sorted(t.triangles()), sorted(before));
    }

    #[test]
    fn unsplit_undoes_split_and_compact_renumbers() {
        // Split every edge of the octahedron once, then merge the new vertices
        // back in reverse order: the faces are the octahedron's again.
        let mut t = Topology::from_triangles(6, &octahedron()).unwrap();
        let mut added = Vec::new();
        for e in 0..t.n_edges() as u32 {
            let a = t.origin(EdgeId(e).halfedge());
            added.push((t.split(EdgeId(e)), a));
        }
        t.validate().unwrap();
        for i in (0..added.len()).rev() {
            let (p, a) = added[i];
            // The half-edge a→p: p's neighbours are a, b and the two apexes.
            let mut h = t.vertex_he(p);
            while t.dest(h) != a {
                h = t.rotate_ccw(h);
            }
            let (dead_edges, dead_faces) = t.unsplit(h.twin()).expect("degree four");
            assert!(t.is_dead_vertex(p));
            assert!(dead_edges.iter().all(|&e| t.is_dead_edge(e)));
            assert_eq!(dead_faces.len(), 2);
            if i % 4 == 0 {
                // Compacting midway keeps the structure valid.
                let (vmap, _, _) = t.compact();
                t.validate().unwrap();
                assert!(vmap[..6].iter().enumerate().all(|(i, v)| v.idx() == i));
                for (q, b) in added[..i].iter_mut() {
                    (*q, *b) = (vmap[q.idx()], vmap[b.idx()]);
                }
            }
        }
        t.compact();
        t.validate().unwrap();
        assert_eq!((t.n_vertices(), t.n_edges(), t.n_faces()), (6, 12, 8));
        let canon = |f: [u32; 3]| {
            let m = (0..3).min_by_key(|&i| f[i]).unwrap();
            [f[m], f[(m + 1) % 3], f[(m + 2) % 3]]
        };
        let mut got: Vec<_> = t.triangles().into_iter().map(canon).collect();
        let mut want: Vec<_> = octahedron().into_iter().map(canon).collect();
        got.sort();
        want.sort();
        assert_eq!(got, want);
        // A vertex of degree five is refused and left untouched.
        let mut t = Topology::from_triangles(6, &octahedron()).unwrap();
        let e = EdgeId(0);
        let a = t.origin(e.halfedge());
        let bc = t.next(e.halfedge()).edge(); // b→c of the face (a, b, c)
        let p = t.split(e);
        t.flip(bc); // (p, b, c) + (c, b, z) → p gains z
        t.validate().unwrap();
        let before = t.triangles();
        let mut h = t.vertex_he(p);
        while t.dest(h) != a {
            h = t.rotate_ccw(h);
        }
        assert!(t.unsplit(h.twin()).is_none());
        assert_eq!(t.triangles(), before);
        t.validate().unwrap();
    }

    #[test]
    fn save_and_restore_undo_flips_and_splits() {
        let mut t = Topology::from_triangles(6, &octahedron()).unwrap();
        let before = t.triangles();
        let mut log = Vec::new();
        for e in [0u32, 3, 5] {
            let e = EdgeId(e);
            let h = e.halfedge();
            let tw = h.twin();
            let (h1, t1) = (t.next(h), t.next(tw));
            let (h2, t2) = (t.next(h1), t.next(t1));
            let faces = [t.face(h), t.face(tw)];
            let verts = [t.origin(h), t.origin(tw)];
            if e.0 != 0 {
                log.push(t.lengths());
                t.save(&[h, tw, h1, h2, t1, t2], &faces, &verts[1..], &mut log);
                t.split(e);
            } else {
                t.save(&[h, tw, h1, h2, t1, t2], &faces, &verts, &mut log);
                t.flip(e);
            }
            t.validate().unwrap();
        }
        assert_ne!(t.triangles(), before);
        t.restore(&log);
        t.validate().unwrap();
        assert_eq!(t.triangles(), before);
        assert_eq!((t.n_vertices(), t.n_edges()), (6, 12));
    }

    #[test]
    fn flip_records_undo_flips_entry_for_entry() {
        let before = Topology::from_triangles(6, &octahedron()).unwrap();
        let mut t = before.clone();
        let mut log = Vec::new();
        // Split first, so that the flips meet both kinds of entries, then
        // flip edges in turn (some twice), and undo everything.
        log.push(t.lengths());
        let e = EdgeId(4);
        let h = e.halfedge();
        let (h1, t1) = (t.next(h), t.next(h.twin()));
        let quad = [h, h.twin(), h1, t.next(h1), t1, t.next(t1)];
        t.save(&quad, &[t.face(h), t.face(h.twin())], &[t.dest(h)], &mut log);
        t.split(e);
        let (split, split_entries) = (t.clone(), log.len());
        for round in 0..3u32 {
            for e in (0..t.n_edges() as u32).map(EdgeId) {
                let h = e.halfedge();
                let (c, d) = (t.apex(h), t.apex(h.twin()));
                if (e.0 + round) % 2 == 0 && c != d && t.are_adjacent_within_either(c, d, 64) == Some(false) {
                    log.push(t.flip_record(e));
                    t.flip(e);
                    t.validate().unwrap();
                }
            }
        }
        assert!(log.len() > split_entries + 5);
        // Every array back as it was, not only the same triangles.
        t.restore(&log[split_entries..]);
        assert_eq!(t, split);
        t.restore(&log[..split_entries]);
        assert_eq!(t, before);
    }

    /// Splitting boundary edges, again and again (of a single triangle, of a square of two, of
    /// a fan around a vertex), keeps a valid mesh: one vertex, two edges and a face more each
    /// time, the boundary one edge longer, the split edge now running to the new vertex.
    #[test]
    fn split_boundary_keeps_structure() {
        let meshes: [&[[u32; 3]]; 3] = [
            &[[0, 1, 2]],
            &[[0, 1, 2], [0, 2, 3]],
            &[[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
        ];
        for triangles in meshes {
            let n = 1 + triangles.iter().flatten().copied().max().unwrap() as usize;
            let mut t = Topology::from_triangles(n, triangles).unwrap();
            let boundary = |t: &Topology| (0..t.n_edges() as u32).filter(|&e| !t.is_interior(EdgeId(e))).count();
            for round in 0..3 {
                for e in 0..t.n_edges() as u32 {
                    let e = EdgeId(e);
                    if t.is_interior(e) {
                        continue;
                    }
                    let before = (t.n_vertices(), t.n_edges(), t.n_faces(), boundary(&t));
                    let h = e.halfedge();
                    let (a, b) = (t.origin(h), t.dest(h));
                    let p = t.split_boundary(e);
                    t.validate()
                        .unwrap_or_else(|m| panic!("{triangles:?}, round {round}, {e:?}: {m}"));
                    assert_eq!(
                        (t.n_vertices(), t.n_edges(), t.n_faces(), boundary(&t)),
                        (before.0 + 1, before.1 + 2, before.2 + 1, before.3 + 1)
                    );
                    // Edge e keeps the end its face side starts from; edge n runs p-b or p-a.
                    let ends = [t.origin(h), t.dest(h)];
                    assert!(
                        ends.contains(&p) && (ends.contains(&a) || ends.contains(&b)),
                        "{ends:?}"
                    );
                    assert!(!t.is_interior(e) && !t.is_interior(EdgeId(before.1 as u32)));
                    assert!(t.is_interior(EdgeId(before.1 as u32 + 1)));
                }
            }
        }
    }

    #[test]
    fn split_keeps_structure() {
        let mut t = Topology::from_triangles(6, &octahedron()).unwrap();
        for round in 0..3 {
            for e in 0..t.n_edges() as u32 {
                let before = (t.n_vertices(), t.n_edges(), t.n_faces());
                let e = EdgeId(e);
                let a = t.origin(e.halfedge());
                let p = t.split(e);
                t.validate()
                    .unwrap_or_else(|m| panic!("round {round}, edge {e:?}: {m}"));
                assert_eq!(
                    (t.n_vertices(), t.n_edges(), t.n_faces()),
                    (before.0 + 1, before.1 + 3, before.2 + 2)
                );
                assert_eq!((t.origin(e.halfedge()), t.dest(e.halfedge())), (a, p));
            }
        }
        // Euler characteristic stays 2.
        assert_eq!(t.n_vertices() as i64 - t.n_edges() as i64 + t.n_faces() as i64, 2);
        // Split an open mesh's interior edge next to the boundary.
        let mut s = Topology::from_triangles(4, &[[0, 1, 2], [0, 2, 3]]).unwrap();
        let e = (0..s.n_edges() as u32).map(EdgeId).find(|&e| s.is_interior(e)).unwrap();
        s.split(e);
        s.validate().unwrap();
        for e in 0..s.n_edges() as u32 {
            if s.is_interior(EdgeId(e)) {
                s.flip(EdgeId(e));
                s.validate().unwrap();
                s.flip(EdgeId(e));
            }
        }
        // Flipping two spokes of the split square would join 1 and 3 twice:
        // validate() must catch that.
        let spokes: Vec<EdgeId> = (0..s.n_edges() as u32)
            .map(EdgeId)
            .filter(|&e| s.is_interior(e))
            .collect();
        let mut caught = false;
        for &e in &spokes {
            s.flip(e);
            caught |= s.validate().is_err();
        }
        assert!(caught, "duplicate edges not detected");
    }
}
