//! Large flat regions made Delaunay before Algorithm 2 starts: convex ones by
//! a linear number of flips ([`crate::convex_regions`]), any other by
//! building its constrained Delaunay triangulation outright.
//!
//! Inside a flat region, Algorithm 2's flips (Lawson's) end at the region's
//! constrained Delaunay triangulation: the one whose every inner edge is
//! Delaunay, its outline edges kept. But they may take quadratically many
//! flips to get there, in any order: a flat strip with n corners on each long
//! side takes n(n − 1)/2, a non-convex cap cut into ears by a CAD exporter
//! about n^1.5 (README, "Large flat regions far from Delaunay"). So a flat
//! region of at least [`MIN_VERTICES`] vertices (its outlines' corners and
//! the vertices inside it), with some edge not Delaunay, is
//!
//! 1. laid flat in an orthonormal frame of its plane (rounded: the frame is
//!    not exact, the test below is);
//! 2. triangulated there by `spade`'s constrained Delaunay triangulation,
//!    its outline edges (outer and around holes) as constraints, keeping the
//!    triangles inside the outlines (reached from them without crossing
//!    one): steps 1 and 2 are [`crate::constrained_delaunay`];
//! 3. checked: the same number of faces, every new face with the region's
//!    orientation and non-zero area, exactly ([`crate::geometry::RegionPlane::is_proper`]),
//!    and no new edge joining two vertices that an edge outside the region
//!    joins already;
//! 4. written into the mesh in place of the region's faces
//!    ([`crate::mesh::Topology::retriangulate`]): faces, inner edges and
//!    outline half-edges keep their ids; an inner edge that lies on an
//!    input edge (a diagonal of the input's own) gets its label back.
//!
//! ```text
//!     a-----------------b          a-----------------b
//!     |\___             |          |\   /\    /\    /|
//!     |    \____        |   ==>    | \ /  \  /  \  / |
//!     |         \____   |          |  /    \/    \/  |
//!     c---d---e---f--\--g          c---d---e---f-----g
//!      (fanned strip)              (constrained Delaunay)
//! ```
//!
//! A region is left to Algorithm 2 as it is when any step fails: a vertex
//! twice on its outline, a face beyond its outline folded flat onto it,
//! two of its vertices at one point of the frame, outlines that cross in
//! it, or a new face that the exact test refuses (the frame's rounding).
//! Where rounding or four vertices on a circle leave edges of the new
//! triangulation a hair from Delaunay, Algorithm 2's first pass flips them
//! as usual. No flip is made and none counted: the region's faces are
//! rebuilt, in time n log n.

use crate::constrained_delaunay::triangulate_inside;
use crate::convex_regions::{
    flip_convex_regions_in, folded_across, large_regions, min_faces_of_corners, ConvexRegions,
};
use crate::geometry::{is_non_delaunay, ACCEPT_TOLERANCE, ALGORITHM_TOLERANCE, SEED_TOLERANCE};
use crate::hash::FastMap;
#[cfg(debug_assertions)]
use crate::mesh::Topology;
use crate::mesh::{EdgeId, FaceId, HalfEdgeId, Surface, VertexId, NO_INPUT_EDGE};
use glam::DVec3;

/// Regions with fewer vertices are left to Algorithm 2's flips, which make
/// them Delaunay in a few thousand flips at most.
pub const MIN_VERTICES: usize = 256;

/// A region is rebuilt only if Lawson's flips, tried and undone, take more
/// than this many flips a vertex (more than the rebuilding costs).
pub const LAWSON_FLIPS_PER_VERTEX: usize = 8;

/// What [`make_flat_regions_delaunay`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FlatRegions {
    /// Convex regions flipped to Delaunay ([`crate::convex_regions`]).
    pub convex: ConvexRegions,
    /// Regions rebuilt as their constrained Delaunay triangulation.
    pub rebuilt: usize,
    /// Their vertices, in all.
    pub rebuilt_vertices: usize,
    /// Edges in and around the rebuilt regions non-Delaunay by more than
    /// [`ACCEPT_TOLERANCE`] before, and after.
    pub non_delaunay: [usize; 2],
}

impl FlatRegions {
    /// The flips made (by the convex regions' pass).
    pub fn flips(&self) -> usize {
        self.convex.flips
    }

    /// The input's non-Delaunay edges, given their count after both passes
    /// ([`crate::Stats::non_delaunay_before`]).
    pub fn non_delaunay_before(&self, after: usize) -> usize {
        let before_rebuilding = (after + self.non_delaunay[0]).saturating_sub(self.non_delaunay[1]);
        self.convex.non_delaunay_before(before_rebuilding)
    }
}

/// Makes every large flat region of `surface` that is not Delaunay
/// Delaunay: convex ones by flips ([`crate::convex_regions::flip_convex_regions`]), then any other
/// by [`rebuild_flat_regions_of`]. Meant for a freshly built surface, before
/// the first pass of Algorithm 2.
pub fn make_flat_regions_delaunay(surface: &mut Surface) -> FlatRegions {
    // Both passes look at the regions of 254 faces or more, listed once: the
    // first one's flips keep every face in its region.
    const MIN_FACES: usize = min_faces_of_vertices(MIN_VERTICES);
    const _: () = assert!(MIN_FACES == min_faces_of_corners(crate::convex_regions::MIN_CORNERS));
    let regions = large_regions(surface, MIN_FACES);
    let convex = flip_convex_regions_in(surface, &regions);
    FlatRegions {
        convex,
        ..rebuild_flat_regions_in(surface, &regions, MIN_VERTICES, LAWSON_FLIPS_PER_VERTEX)
    }
}

/// The fewest faces a region of `min_vertices` vertices has.
const fn min_faces_of_vertices(min_vertices: usize) -> usize {
    if min_vertices > 3 {
        min_vertices - 2
    } else {
        1
    }
}

/// Rebuilds every flat region of `s` with at least `min_vertices` vertices,
/// some edge not Delaunay, and on which Lawson's flips take more than
/// `lawson_flips_per_vertex` flips a vertex, as its constrained Delaunay
/// triangulation (see the module doc); `convex` of the result is left
/// empty. ([`make_flat_regions_delaunay`] passes [`MIN_VERTICES`] and
/// [`LAWSON_FLIPS_PER_VERTEX`]; tests pass less, down to 0: any region with
/// a flip to make.)
pub fn rebuild_flat_regions_of(s: &mut Surface, min_vertices: usize, lawson_flips_per_vertex: usize) -> FlatRegions {
    let regions = large_regions(s, min_faces_of_vertices(min_vertices));
    rebuild_flat_regions_in(s, &regions, min_vertices, lawson_flips_per_vertex)
}

/// [`rebuild_flat_regions_of`] on the regions whose faces are `regions`
/// ([`large_regions`] of [`min_faces_of_vertices`]`(min_vertices)` faces
/// or more).
fn rebuild_flat_regions_in(
    s: &mut Surface,
    regions: &[Vec<FaceId>],
    min_vertices: usize,
    lawson_flips_per_vertex: usize,
) -> FlatRegions {
    let mut done = FlatRegions::default();
    let mut local: Vec<u32> = Vec::new();
    let mut edge_local: Vec<u32> = Vec::new();
    for faces in regions {
        local.resize(s.topo.n_vertices(), u32::MAX);
        edge_local.resize(s.topo.n_edges(), u32::MAX);
        let Some(mut patch) = Patch::of_region(s, faces, &mut local, &mut edge_local) else {
            continue;
        };
        // The cheap tests first; what only the rebuilding needs after.
        let slow = patch.vertices.len() >= min_vertices
            && patch.lawson_is_slow(s, faces, &edge_local, lawson_flips_per_vertex);
        if slow {
            patch.number_outline(s, &local);
        }
        patch.unnumber(&mut local, &mut edge_local);
        if !slow {
            continue;
        }
        // The edges whose quads the new triangulation changes: those inside
        // and on the outline.
        let edges: Vec<EdgeId> = (patch.inner.iter().copied())
            .chain(
                patch
                    .outline
                    .iter()
                    .filter(|h| !s.topo.is_boundary_he(h.twin()))
                    .map(|h| h.edge()),
            )
            .collect();
        let bad = |s: &Surface| s.count_non_delaunay_among(edges.iter().copied(), ACCEPT_TOLERANCE).0;
        let before = bad(s);
        if patch.rebuild(s, faces) {
            done.rebuilt += 1;
            done.rebuilt_vertices += patch.vertices.len();
            done.non_delaunay[0] += before;
            done.non_delaunay[1] += bad(s);
        }
    }
    done
}

/// An edge of a [`Patch`], as a copy of the patch alone would have it.
#[derive(Clone, Copy)]
struct PatchEdge {
    edge: EdgeId,
    /// Whether the copy's first half-edge of it runs against the surface's.
    reversed: bool,
    /// Whether both its faces are in the region (else it is on the
    /// outline, the copy's boundary). Flips inside the region keep it so:
    /// a flip's two faces stay in the region, and so do the faces on
    /// either side of the quad's sides.
    interior: bool,
}

/// Lawson's flips on the flat patch whose edges are `edges` (in the
/// copy's numbering, which `local` gives), stopping after `budget + 1`;
/// the number made. Every flip is undone before returning.
///
/// In a flat patch an edge that is not Delaunay has a convex quad, so the
/// flips need no validity test (the copy this stands for was only counted,
/// never kept). Only interior edges are flipped: the outline's edges are
/// the copy's boundary.
fn lawson_flips(s: &mut Surface, edges: &[PatchEdge], local: &[u32], budget: usize) -> usize {
    let Surface { topo, positions, .. } = s;
    // Edge k's half-edge that runs as the copy's first one does.
    let oriented = |k: usize| {
        let PatchEdge { edge, reversed, .. } = edges[k];
        if reversed {
            edge.halfedge().twin()
        } else {
            edge.halfedge()
        }
    };
    let mut stack: Vec<usize> = (0..edges.len()).filter(|&k| edges[k].interior).collect();
    let mut queued = vec![false; edges.len()];
    for &k in &stack {
        queued[k] = true;
    }
    let mut journal = Vec::new();
    let mut flips = 0;
    while let Some(k) = stack.pop() {
        queued[k] = false;
        let h = oriented(k);
        let (c, d) = (topo.apex(h), topo.apex(h.twin()));
        // (Only interior edges are queued.)
        let bad = c != d && {
            let [a, b, c, d] = [topo.origin(h), topo.dest(h), c, d].map(|v| positions[v.idx()]);
            is_non_delaunay(a, b, c, d, ALGORITHM_TOLERANCE)
        };
        if !bad {
            continue;
        }
        let e = edges[k].edge;
        journal.push(topo.flip_record(e));
        topo.flip(e);
        flips += 1;
        if flips > budget {
            break;
        }
        // The quad's sides, in the order the copy's `outer_halfedges` gives.
        let h = oriented(k);
        let (h1, t1) = (topo.next(h), topo.next(h.twin()));
        for g in [topo.next(h1), h1, topo.next(t1), t1] {
            let j = local[g.edge().idx()] as usize;
            if edges[j].interior && !std::mem::replace(&mut queued[j], true) {
                stack.push(j);
            }
        }
    }
    topo.restore(&journal);
    flips
}

/// A flat region as the constrained triangulation takes it.
struct Patch {
    /// Its vertices, corners of its outlines and vertices inside.
    vertices: Vec<VertexId>,
    /// Its outline: the half-edges of its faces whose twins are not in it.
    outline: Vec<HalfEdgeId>,
    /// Its inner edges, both sides in it.
    inner: Vec<EdgeId>,
    /// All its edges, numbered as a copy of the patch alone would number
    /// them ([`crate::mesh::Topology::from_triangles`] of its faces: by their first
    /// corner, face by face), for [`Patch::lawson_is_slow`].
    edges: Vec<PatchEdge>,
    /// The outline's half-edges as pairs of numbers in `vertices` (empty
    /// until [`Patch::number_outline`]).
    outline_local: Vec<[usize; 2]>,
    /// Pairs of numbers in `vertices` (lower first), sorted, that an edge
    /// outside the patch joins: new edges may not join them again (empty
    /// until [`Patch::number_outline`]).
    joined_outside: Vec<[usize; 2]>,
    /// The region.
    region: u32,
}

impl Patch {
    /// The region whose faces are `faces` as a patch to rebuild, if it has
    /// an inner edge that is not Delaunay, no vertex twice on its outline
    /// and no face beyond its outline folded flat onto it. `local` (all
    /// `u32::MAX`, one per vertex) is left numbering the patch's vertices,
    /// and `edge_local` (all `u32::MAX`, one per edge) its edges, until
    /// [`Patch::unnumber`] (`None`: both left as they were).
    fn of_region(s: &Surface, faces: &[FaceId], local: &mut [u32], edge_local: &mut [u32]) -> Option<Patch> {
        let topo = &s.topo;
        let region = s.face_region[faces[0].idx()];
        let in_region = |h: HalfEdgeId| {
            let f = topo.face(h);
            !f.is_none() && s.face_region[f.idx()] == region
        };
        let half_edges = || topo.half_edges_of(faces);
        if s.region_plane[region as usize].sign == 0
            || !half_edges().any(|h| h < h.twin() && in_region(h.twin()) && s.is_non_delaunay(h.edge(), SEED_TOLERANCE))
        {
            return None;
        }
        // (A flat patch of n faces has about n/2 vertices and 3n/2 edges.)
        let n = faces.len();
        let mut vertices = Vec::with_capacity(n / 2 + 3);
        let (mut outline, mut inner, mut edges) = (
            Vec::new(),
            Vec::with_capacity(3 * n / 2),
            Vec::with_capacity(3 * n / 2 + 2),
        );
        for h in half_edges() {
            let v = topo.origin(h);
            if local[v.idx()] == u32::MAX {
                local[v.idx()] = vertices.len() as u32;
                vertices.push(v);
            }
            let interior = in_region(h.twin());
            if !interior {
                outline.push(h);
            } else if h < h.twin() {
                inner.push(h.edge());
            }
            let edge = h.edge();
            if edge_local[edge.idx()] == u32::MAX {
                edge_local[edge.idx()] = edges.len() as u32;
                edges.push(PatchEdge {
                    edge,
                    reversed: edge.halfedge() != h,
                    interior,
                });
            }
        }
        let patch = Patch {
            vertices,
            outline,
            inner,
            edges,
            outline_local: Vec::new(),
            joined_outside: Vec::new(),
            region,
        };
        let mut origins: Vec<VertexId> = patch.outline.iter().map(|&h| topo.origin(h)).collect();
        origins.sort_unstable();
        if origins.windows(2).any(|w| w[0] == w[1]) || patch.outline.iter().any(|&h| folded_across(s, h)) {
            patch.unnumber(local, edge_local);
            return None;
        }
        Some(patch)
    }

    /// Sets the numbers [`Patch::of_region`] gave the patch's vertices in
    /// `local` and its edges in `edge_local` back to `u32::MAX`.
    fn unnumber(&self, local: &mut [u32], edge_local: &mut [u32]) {
        for v in &self.vertices {
            local[v.idx()] = u32::MAX;
        }
        for e in &self.edges {
            edge_local[e.edge.idx()] = u32::MAX;
        }
    }

    /// Fills in what only the rebuilding needs: the outline and the pairs
    /// of vertices joined outside, in the numbering `local` still holds.
    fn number_outline(&mut self, s: &Surface, local: &[u32]) {
        let topo = &s.topo;
        self.outline_local = (self.outline.iter())
            .map(|&h| [local[topo.origin(h).idx()] as usize, local[topo.dest(h).idx()] as usize])
            .collect();
        // (Only the outline's corners have edges outside the patch.)
        let mut own: Vec<EdgeId> = (self.outline.iter().map(|h| h.edge()))
            .chain(self.inner.iter().copied())
            .collect();
        own.sort_unstable();
        let mut joined_outside = Vec::new();
        for &h in &self.outline {
            let v = topo.origin(h);
            topo.for_each_neighbour(v, |e, w| {
                if local[w.idx()] != u32::MAX && own.binary_search(&e).is_err() {
                    let (a, b) = (local[v.idx()] as usize, local[w.idx()] as usize);
                    joined_outside.push([a.min(b), a.max(b)]);
                }
            });
        }
        joined_outside.sort_unstable();
        joined_outside.dedup();
        self.joined_outside = joined_outside;
    }

    /// Whether Lawson's flips take more than `per_vertex` flips a vertex to
    /// make the patch Delaunay. Where they take fewer, Algorithm 2 flips the
    /// region itself, and its output is the one it always was.
    ///
    /// They are tried on the surface's own half-edges and undone after
    /// (`s` is left as it was), in the order they would take on a copy of
    /// the patch alone ([`crate::mesh::Topology::from_triangles`] of its faces, numbered
    /// in `vertices`, which numbers the edges by their first corner, face by
    /// face, and runs each edge's first half-edge as that corner). Copying
    /// cost more than the flips: on the fandisk's region of 3,020 faces, 180
    /// of the trial's 250 microseconds. `faces`: the patch's faces (for
    /// that copy, in debug builds); `edge_local`: the numbers
    /// [`Patch::of_region`] gave the patch's edges.
    fn lawson_is_slow(&self, s: &mut Surface, faces: &[FaceId], edge_local: &[u32], per_vertex: usize) -> bool {
        #[cfg(not(debug_assertions))]
        let _ = faces;
        let budget = per_vertex * self.vertices.len();
        #[cfg(debug_assertions)]
        let before = s.topo.clone();
        let flips = lawson_flips(s, &self.edges, edge_local, budget);
        // Debug builds (every test): the surface is as it was, and a copy
        // of the patch takes the same flips.
        #[cfg(debug_assertions)]
        {
            assert!(s.topo == before, "the trial's flips undone");
            assert_eq!(
                flips,
                self.lawson_flips_on_copy(s, faces, budget),
                "the trial as on a copy"
            );
        }
        flips > budget
    }

    /// Lawson's flips on a copy of the patch alone, counted as
    /// [`lawson_flips`] counts them (debug builds check that both agree).
    #[cfg(debug_assertions)]
    fn lawson_flips_on_copy(&self, s: &Surface, faces: &[FaceId], budget: usize) -> usize {
        let at: Vec<DVec3> = self.vertices.iter().map(|v| s.positions[v.idx()]).collect();
        let number: FastMap<VertexId, u32> = (self.vertices.iter().enumerate())
            .map(|(i, &v)| (v, i as u32))
            .collect();
        let triangles: Vec<[u32; 3]> = (faces.iter())
            .map(|&f| s.topo.face_vertices(f).map(|v| number[&v]))
            .collect();
        let Ok(mut copy) = Topology::from_triangles(at.len(), &triangles) else {
            return 0;
        };
        let non_delaunay = |t: &Topology, e: EdgeId| {
            let h = e.halfedge();
            t.is_interior(e) && t.apex(h) != t.apex(h.twin()) && {
                let [a, b, c, d] = [t.origin(h), t.dest(h), t.apex(h), t.apex(h.twin())].map(|v| at[v.idx()]);
                is_non_delaunay(a, b, c, d, ALGORITHM_TOLERANCE)
            }
        };
        let n_edges = copy.n_edges();
        let mut stack: Vec<EdgeId> = (0..n_edges as u32)
            .map(EdgeId)
            .filter(|&e| copy.is_interior(e))
            .collect();
        let mut queued = vec![false; n_edges];
        for e in &stack {
            queued[e.idx()] = true;
        }
        let mut flips = 0;
        while let Some(e) = stack.pop() {
            queued[e.idx()] = false;
            if non_delaunay(&copy, e) {
                copy.flip(e);
                flips += 1;
                if flips > budget {
                    return flips;
                }
                for h in copy.outer_halfedges(e) {
                    let g = h.edge();
                    if copy.is_interior(g) && !std::mem::replace(&mut queued[g.idx()], true) {
                        stack.push(g);
                    }
                }
            }
        }
        flips
    }

    /// Rebuilds the patch, whose faces are `faces`, as its constrained
    /// Delaunay triangulation (steps 1-4 of the module doc); false, changing
    /// nothing, if a step fails.
    fn rebuild(&self, s: &mut Surface, faces: &[FaceId]) -> bool {
        let Some(triangles) = self.triangulate(s, faces.len()) else {
            return false;
        };
        let plane = s.region_plane[self.region as usize];
        let at = |v: usize| s.positions[self.vertices[v].idx()];
        if !triangles.iter().all(|t| plane.is_proper(t.map(at))) {
            return false;
        }
        // No new edge may join two vertices that an edge outside joins.
        if (triangles.iter())
            .flat_map(|&[a, b, c]| [[a, b], [b, c], [c, a]])
            .any(|[a, b]| self.joined_outside.binary_search(&[a.min(b), a.max(b)]).is_ok())
        {
            return false;
        }
        let pair = |a: VertexId, b: VertexId| (a.min(b), a.max(b));
        // The input edges the old inner edges lie on, to label the new ones
        // that lie on the same.
        let labels: FastMap<(VertexId, VertexId), u32> = (self.inner.iter())
            .filter(|&&e| s.edge_input[e.idx()] != NO_INPUT_EDGE)
            .map(|&e| {
                let h = e.halfedge();
                (pair(s.topo.origin(h), s.topo.dest(h)), s.edge_input[e.idx()])
            })
            .collect();
        let triangles: Vec<[VertexId; 3]> = triangles.iter().map(|t| t.map(|v| self.vertices[v])).collect();
        if !s.topo.retriangulate(faces, &self.inner, &triangles) {
            return false;
        }
        for &e in &self.inner {
            let h = e.halfedge();
            let key = pair(s.topo.origin(h), s.topo.dest(h));
            s.edge_input[e.idx()] = labels.get(&key).copied().unwrap_or(NO_INPUT_EDGE);
        }
        true
    }

    /// The constrained Delaunay triangulation of the patch in a frame of its
    /// plane, as triples of numbers in `vertices` turning the region's way:
    /// the triangles inside the outline
    /// ([`crate::constrained_delaunay::triangulate_inside`]). `None` if it
    /// does not have `n_faces` of them, or the frame put two vertices at one
    /// point, or outlines cross there.
    fn triangulate(&self, s: &Surface, n_faces: usize) -> Option<Vec<[usize; 3]>> {
        let at: Vec<DVec3> = self.vertices.iter().map(|v| s.positions[v.idx()]).collect();
        triangulate_inside(&at, &self.outline_local, n_faces)
    }
}
