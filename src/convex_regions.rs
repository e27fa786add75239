//! Large flat regions that are convex polygons, flipped to their Delaunay
//! triangulation in linearly many flips before Algorithm 2 starts.
//!
//! Algorithm 2 makes a flat region Delaunay by Lawson's flips, which can take
//! quadratically many: a convex polygon of n corners fanned from one corner,
//! as CAD exports triangulate the cap of an oval or a rounded part, takes
//! about n²/26 flips on a parabola in every order tried (README, "Large flat
//! regions far from Delaunay"). Yet any two triangulations of a convex
//! polygon are at most 2n flips apart (Sleator, Tarjan and Thurston), by way
//! of the fan of any corner v. So a flat region that is a strictly convex
//! polygon, with no vertex inside, of at least [`MIN_CORNERS`] corners and
//! not Delaunay already, is
//!
//! 1. triangulated Delaunay on the side, as corner triples (Chew's
//!    algorithm for convex polygons: take the corners away in a shuffled
//!    order, put them back in reverse, each as a triangle on the outline
//!    made Delaunay by flips: about one flip a corner on average);
//! 2. flipped, in the mesh, to the fan of its corner of highest degree
//!    (each flip joins v to one more corner: fewer than n flips);
//! 3. flipped from that fan to the triangulation of step 1, by the flips
//!    that take that triangulation to the same fan, found on the side and
//!    made in reverse (fewer than n flips).
//!
//! ```text
//!          v                      v                      v
//!        / | \                  /|||\                  / | \
//!      a   |  b      1.       a  |||  b      2.      a---|--b
//!      |\  |   \    ---->     | / | \  \    ---->    |  \|   \
//!      | \ |    c             |/  |  \  c            |   d----c
//!      e---d----'             e---d---`'             e--/ \---'
//!     (as read)             (fan of v)            (Delaunay)
//! ```
//!
//! A region folded flat onto a face beyond its outline (a disc whose two
//! sides are both in the mesh), or one whose fan or Delaunay diagonals an
//! edge outside it joins already, is not started. Every flip is one the
//! mesh allows ([`Surface::flip_is_possible`]: the new faces face the
//! region's way, exactly, and no edge is doubled); if one is not, the
//! region is left as it then is, a triangulation of the same polygon, for
//! Algorithm 2's flips to finish. A strip whose long sides
//! carry many corners on a straight line is not strictly convex: its fans
//! are degenerate, and no order of flips reaches its Delaunay triangulation
//! in fewer than quadratically many (README). With
//! [`crate::Options::keep_order`] Algorithm 2 flips every region itself, as
//! the report's tool did.

use crate::geometry::{
    coplanar, delaunay_test, flat_pair, DelaunayTest, ACCEPT_TOLERANCE, ALGORITHM_TOLERANCE, SEED_TOLERANCE,
};
use crate::hash::FastMap;
use crate::mesh::{EdgeId, FaceId, HalfEdgeId, Surface, VertexId, ADJACENCY_LIMIT, NO_INPUT_EDGE};
use glam::DVec3;

/// Regions with fewer corners are left to Algorithm 2's flips, which make
/// them Delaunay in a few thousand flips at most (n²/8 from a fan).
pub const MIN_CORNERS: usize = 256;

/// What [`flip_convex_regions`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ConvexRegions {
    /// Regions flipped to their Delaunay triangulation.
    pub regions: usize,
    /// Their corners, in all.
    pub corners: usize,
    /// Flips made (also in regions given up half way).
    pub flips: usize,
    /// Edges in and around those regions non-Delaunay by more than
    /// [`ACCEPT_TOLERANCE`] before, and after: Algorithm 2's count of the
    /// input's non-Delaunay edges, taken after, is off by the difference.
    pub non_delaunay: [usize; 2],
}

impl ConvexRegions {
    /// The input's non-Delaunay edges, given their count after the flips
    /// ([`crate::Stats::non_delaunay_before`]).
    pub fn non_delaunay_before(&self, after: usize) -> usize {
        (after + self.non_delaunay[0]).saturating_sub(self.non_delaunay[1])
    }
}

/// Flips every flat region of `surface` that is a strictly convex polygon of
/// at least [`MIN_CORNERS`] corners, with no vertex inside and some edge
/// non-Delaunay, to its Delaunay triangulation (see the module doc). Meant
/// for a freshly built surface, before the first pass of Algorithm 2.
pub fn flip_convex_regions(surface: &mut Surface) -> ConvexRegions {
    flip_convex_regions_of(surface, MIN_CORNERS)
}

/// [`flip_convex_regions`] with another least number of corners (tests).
pub fn flip_convex_regions_of(s: &mut Surface, min_corners: usize) -> ConvexRegions {
    let faces = large_regions(s, min_faces_of_corners(min_corners));
    flip_convex_regions_in(s, &faces)
}

/// The fewest faces a region of `min_corners` corners has (a polygon of n
/// corners is cut into n - 2 triangles).
pub(crate) const fn min_faces_of_corners(min_corners: usize) -> usize {
    if min_corners > 4 {
        min_corners - 2
    } else {
        2
    }
}

/// [`flip_convex_regions_of`] on the regions whose faces are `faces`
/// ([`large_regions`]; flips keep every face in its region, so the list
/// stays right through them).
pub(crate) fn flip_convex_regions_in(s: &mut Surface, faces: &[Vec<FaceId>]) -> ConvexRegions {
    let mut done = ConvexRegions::default();
    // Each vertex's number among its region's corners (u32::MAX: none), for
    // the region at hand.
    let mut local: Vec<u32> = Vec::new();
    for list in faces {
        let r = s.face_region[list[0].idx()];
        let Some(polygon) = Polygon::of_region(s, r, list) else {
            continue;
        };
        // The edges whose quads the flips may change: those inside and on
        // the outline (edge ids stay through flips).
        let edges: Vec<EdgeId> = (s.topo.half_edges_of(list))
            .filter(|&h| !s.topo.is_boundary_he(h.twin()) && (h < h.twin() || !polygon.holds(s, h.twin())))
            .map(HalfEdgeId::edge)
            .collect();
        let bad = |s: &Surface| s.count_non_delaunay_among(edges.iter().copied(), ACCEPT_TOLERANCE).0;
        done.non_delaunay[0] += bad(s);
        local.resize(s.topo.n_vertices(), u32::MAX);
        for (i, v) in polygon.corners.iter().enumerate() {
            local[v.idx()] = i as u32;
        }
        let (flips, finished) = polygon.flip_to_delaunay(s, list, &local);
        for v in &polygon.corners {
            local[v.idx()] = u32::MAX;
        }
        done.non_delaunay[1] += bad(s);
        done.flips += flips;
        if finished {
            done.regions += 1;
            done.corners += polygon.corners.len();
        }
    }
    done
}

/// Whether the face beyond the edge of half-edge `h` (of a face of a flat
/// region) is folded flat onto `h`'s face: coplanar with it, on the same
/// side of the edge.
pub(crate) fn folded_across(s: &Surface, h: HalfEdgeId) -> bool {
    let topo = &s.topo;
    let (a, b, c, d) = (topo.origin(h), topo.dest(h), topo.apex(h), topo.apex(h.twin()));
    !d.is_none() && {
        let [a, b, c, d] = [a, b, c, d].map(|v| s.positions[v.idx()]);
        coplanar(a, b, c, d) && !flat_pair(a, b, c, d)
    }
}

/// The faces of every planar region of `s` with at least `min_faces` faces
/// (`min_faces` ≥ 2), a list per region, in face order.
pub(crate) fn large_regions(s: &Surface, min_faces: usize) -> Vec<Vec<FaceId>> {
    // A region of k faces makes k - 1 fewer regions than faces: most
    // meshes have no such region, told without a pass.
    let n_faces = s.topo.n_faces();
    if n_faces < s.n_regions + min_faces - 1 {
        return Vec::new();
    }
    let mut count = vec![0u32; s.n_regions];
    for &r in &s.face_region {
        count[r as usize] += 1;
    }
    let mut slot = vec![u32::MAX; s.n_regions];
    let mut faces: Vec<Vec<FaceId>> = Vec::new();
    for (r, &c) in count.iter().enumerate() {
        if c as usize >= min_faces {
            slot[r] = faces.len() as u32;
            faces.push(Vec::with_capacity(c as usize));
        }
    }
    if faces.is_empty() {
        return faces;
    }
    for (f, &r) in s.face_region.iter().enumerate() {
        if let Some(list) = faces.get_mut(slot[r as usize] as usize) {
            list.push(FaceId(f as u32));
        }
    }
    faces
}

/// A flat region that is a strictly convex polygon with no vertex inside.
struct Polygon {
    /// Its region.
    region: u32,
    /// Its corners, in the turning order of its faces.
    corners: Vec<VertexId>,
    /// Their positions.
    at: Vec<DVec3>,
}

impl Polygon {
    /// The region `r`, whose faces are `faces`, as a polygon, if it is one:
    /// a single outline through every vertex of its faces, turning the
    /// region's way at every corner (exactly) and once around in all; and if
    /// some edge inside it is not Delaunay.
    fn of_region(s: &Surface, r: u32, faces: &[FaceId]) -> Option<Polygon> {
        let topo = &s.topo;
        let in_region = |h: HalfEdgeId| {
            let f = topo.face(h);
            !f.is_none() && s.face_region[f.idx()] == r
        };
        // The outline: half-edges of the region's faces whose twins are not
        // in the region, by their origins.
        let half_edges = || topo.half_edges_of(faces);
        let n = half_edges().filter(|&h| !in_region(h.twin())).count();
        // A disc whose every vertex is on its outline has n - 2 faces (with
        // k vertices inside, n - 2 + 2k; an annulus n): told before any
        // Delaunay test or allocation, as most large flat regions (of scans,
        // terrains, voxel models) have vertices inside.
        if faces.len() + 2 != n
            || !half_edges().any(|h| h < h.twin() && in_region(h.twin()) && s.is_non_delaunay(h.edge(), SEED_TOLERANCE))
        {
            return None;
        }
        let mut outline: Vec<(VertexId, HalfEdgeId)> = half_edges()
            .filter(|&h| !in_region(h.twin()))
            .map(|h| (topo.origin(h), h))
            .collect();
        outline.sort_unstable();
        if outline.windows(2).any(|w| w[0].0 == w[1].0) {
            return None; // a corner twice on the outline
        }
        // A face beyond the outline folded flat onto the region (a disc whose
        // two sides are both in the mesh): the region's Delaunay diagonals
        // may be the other side's too, and it is left to Algorithm 2.
        if outline.iter().any(|&(_, h)| folded_across(s, h)) {
            return None;
        }
        let leaving = |v: VertexId| outline.binary_search_by_key(&v, |&(u, _)| u).ok().map(|i| outline[i].1);
        let start = outline[0].1;
        let mut corners = Vec::with_capacity(n);
        let mut h = start;
        for i in 0..n {
            if i > 0 && h == start {
                return None; // more than one loop
            }
            corners.push(topo.origin(h));
            h = leaving(topo.dest(h))?;
        }
        if h != start {
            return None;
        }
        let at: Vec<DVec3> = corners.iter().map(|v| s.positions[v.idx()]).collect();
        let plane = s.region_plane[r as usize];
        if plane.sign == 0 {
            return None;
        }
        let corner = |i: usize| [at[(i + n - 1) % n], at[i], at[(i + 1) % n]];
        if !(0..n).all(|i| plane.is_proper(corner(i))) {
            return None;
        }
        // Every turn is the region's way: the outline goes round once (a
        // convex polygon) or more (one that overlaps itself, refused).
        let (x, y) = [(1, 2), (2, 0), (0, 1)][plane.axis as usize];
        let turning: f64 = (0..n)
            .map(|i| {
                let [a, b, c] = corner(i);
                let (u, w) = (b - a, c - b);
                let cross = u[x] * w[y] - u[y] * w[x];
                (f64::from(plane.sign) * cross).atan2(u[x] * w[x] + u[y] * w[y])
            })
            .sum();
        if (turning - std::f64::consts::TAU).abs() > std::f64::consts::PI {
            return None;
        }
        Some(Polygon { region: r, corners, at })
    }

    /// Flips the region to its Delaunay triangulation (steps 1-3 of the
    /// module doc), `local` numbering its corners (`u32::MAX` for every other
    /// vertex). Returns the flips made and whether it got there.
    fn flip_to_delaunay(&self, s: &mut Surface, faces: &[FaceId], local: &[u32]) -> (usize, bool) {
        let n = self.corners.len();
        let Some(mut target) = Corners::delaunay(&self.at) else {
            return (0, false);
        };
        let local_of = |v: VertexId| Some(local[v.idx()]).filter(|&i| i != u32::MAX);
        // The corner with the most faces: the fan the mesh passes through.
        let mut degree = vec![0u32; n];
        for &f in faces {
            for v in s.topo.face_vertices(f) {
                if let Some(i) = local_of(v) {
                    degree[i as usize] += 1;
                }
            }
        }
        let apex = (0..n).max_by_key(|&i| (degree[i], std::cmp::Reverse(i))).unwrap_or(0);
        // The diagonals the flips make, those of the fan of the apex and of
        // the target, may not join corners that an edge outside the region
        // joins already (a disc whose two sides are two regions on the same
        // corners): such a region is left to Algorithm 2.
        // (And the input edges the diagonals lie on, to label them again
        // where step 3 makes the same diagonal: a flip forgets its edge's
        // label.)
        let mut own: Vec<(u32, u32)> = Vec::with_capacity(n);
        let mut labels: FastMap<(u32, u32), u32> = FastMap::default();
        for h in s.topo.half_edges_of(faces) {
            if let (Some(a), Some(b)) = (local_of(s.topo.origin(h)), local_of(s.topo.dest(h))) {
                own.push((a.min(b), a.max(b)));
                let label = s.edge_input[h.edge().idx()];
                if label != NO_INPUT_EDGE {
                    labels.insert((a.min(b), a.max(b)), label);
                }
            }
        }
        own.sort_unstable();
        own.dedup();
        let joined_outside = |a: u32, b: u32| {
            let (a, b) = (a.min(b), a.max(b));
            own.binary_search(&(a, b)).is_err()
                && s.topo.are_adjacent_within_either(
                    self.corners[a as usize],
                    self.corners[b as usize],
                    ADJACENCY_LIMIT,
                ) != Some(false)
        };
        let mut fan_diagonals =
            (0..n as u32).filter(|&z| (z as usize + n - apex) % n > 1 && (apex + n - z as usize) % n > 1);
        // (Each edge once: from the triangle that holds it from its lower end.)
        let mut target_diagonals = (target.triangles.iter())
            .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
            .filter(|&(a, b)| a < b);
        if fan_diagonals.any(|z| joined_outside(apex as u32, z)) || target_diagonals.any(|(a, b)| joined_outside(a, b))
        {
            return (0, false);
        }
        let Some(steps) = target.flip_to_fan(apex as u32) else {
            return (0, false);
        };
        let mut flips = 0;
        let v = self.corners[apex];
        // Step 2: the mesh to the fan of v. The edges facing v in its faces
        // of the region; one inside the region is flipped into an edge from
        // v, and the two beyond it then face v.
        let mut facing: Vec<EdgeId> = Vec::new();
        for &f in faces {
            let [a, b, c] = s.topo.face_vertices(f);
            if [a, b, c].contains(&v) {
                facing.push(self.edge_facing(s, f, v));
            }
        }
        while let Some(e) = facing.pop() {
            let mut h = e.halfedge();
            if s.topo.apex(h) != v {
                h = h.twin();
            }
            let t = h.twin();
            if s.topo.apex(h) != v || !self.holds(s, t) {
                continue; // on the outline
            }
            let beyond = [s.topo.next(t).edge(), s.topo.next(s.topo.next(t)).edge()];
            if !s.flip_is_possible(e) {
                return (flips, false);
            }
            s.flip(e);
            flips += 1;
            facing.extend(beyond);
        }
        // Step 3: the fan to the target, by the flips that took the target
        // to the same fan, in reverse: each turns the edge v-z back into the
        // diagonal x-y.
        let mut from_v = vec![EdgeId::NONE; n];
        for h in s.topo.half_edges_of(faces).filter(|&h| s.topo.origin(h) == v) {
            if let Some(z) = local_of(s.topo.dest(h)) {
                from_v[z as usize] = h.edge();
            }
        }
        for &(x, y, z) in steps.iter().rev() {
            let e = from_v[z as usize];
            if e.is_none() {
                return (flips, false);
            }
            let h = e.halfedge();
            let apexes = [s.topo.apex(h), s.topo.apex(h.twin())].map(local_of);
            if apexes != [Some(x), Some(y)] && apexes != [Some(y), Some(x)] {
                return (flips, false);
            }
            if !s.flip_is_possible(e) {
                return (flips, false);
            }
            s.flip(e);
            flips += 1;
            from_v[z as usize] = EdgeId::NONE;
            if let Some(&label) = labels.get(&(x.min(y), x.max(y))) {
                s.edge_input[e.idx()] = label;
            }
        }
        (flips, true)
    }

    /// Whether half-edge `h` has a face of this region.
    fn holds(&self, s: &Surface, h: HalfEdgeId) -> bool {
        let f = s.topo.face(h);
        !f.is_none() && s.face_region[f.idx()] == self.region
    }

    /// The edge of face `f` opposite its corner `v`.
    fn edge_facing(&self, s: &Surface, f: FaceId, v: VertexId) -> EdgeId {
        let mut h = s.topo.face_halfedge(f);
        while s.topo.origin(h) == v || s.topo.dest(h) == v {
            h = s.topo.next(h);
        }
        h.edge()
    }
}

/// A triangulation of a convex polygon's corners `0..n`, on the side: its
/// triangles (counter-clockwise) and, for each directed edge, the triangle
/// that holds it.
struct Corners {
    triangles: Vec<[u32; 3]>,
    holding: FastMap<(u32, u32), u32>,
}

impl Corners {
    /// The Delaunay triangulation of the strictly convex polygon with
    /// corners `at` (Chew's algorithm; `None` if its flips run past a
    /// budget, which rounding alone could cause).
    fn delaunay(at: &[DVec3]) -> Option<Corners> {
        let n = at.len();
        let mut t = Corners {
            triangles: Vec::with_capacity(n - 2),
            holding: FastMap::with_capacity_and_hasher(3 * n, Default::default()),
        };
        // A shuffle fixed by n (xorshift), so that the result depends on
        // the polygon alone.
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut state = 0x9E37_79B9_7F4A_7C15u64 ^ n as u64;
        for i in (1..n).rev() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            order.swap(i, (state % (i as u64 + 1)) as usize);
        }
        // Take the corners away, last of the order first, each between its
        // neighbours of the moment.
        let mut prev: Vec<u32> = (0..n).map(|i| ((i + n - 1) % n) as u32).collect();
        let mut next: Vec<u32> = (0..n).map(|i| ((i + 1) % n) as u32).collect();
        let mut taken: Vec<[u32; 3]> = Vec::with_capacity(n);
        for &q in order[3..].iter().rev() {
            let (a, b) = (prev[q as usize], next[q as usize]);
            taken.push([a, q, b]);
            next[a as usize] = b;
            prev[b as usize] = a;
        }
        let a = order[0];
        let b = next[a as usize];
        t.add([a, b, next[b as usize]]);
        // Put them back: q beyond the outline's edge a-b, then Lawson's flips
        // of the edges facing q.
        let mut budget = 16 * n + 64;
        let mut stack: Vec<(u32, u32)> = Vec::new();
        for &[a, q, b] in taken.iter().rev() {
            t.add([a, q, b]);
            stack.push((a, b));
            while let Some((u, w)) = stack.pop() {
                // (w, u, q) holds w->u; beyond u-w lies y.
                let Some(y) = t.across(w, u) else { continue };
                let (pu, pw, pq, py) = (at[u as usize], at[w as usize], at[q as usize], at[y as usize]);
                if delaunay_test(pu, pw, pq, py, ALGORITHM_TOLERANCE) != DelaunayTest::NonDelaunay
                    || delaunay_test(pq, py, pw, pu, ALGORITHM_TOLERANCE) == DelaunayTest::NonDelaunay
                {
                    continue;
                }
                if budget == 0 {
                    return None;
                }
                budget -= 1;
                t.flip(u, w)?;
                stack.push((u, y));
                stack.push((y, w));
            }
        }
        Some(t)
    }

    fn add(&mut self, tri: [u32; 3]) {
        let i = self.triangles.len() as u32;
        self.triangles.push(tri);
        self.hold(i);
    }

    fn hold(&mut self, i: u32) {
        let tri = self.triangles[i as usize];
        for k in 0..3 {
            self.holding.insert((tri[k], tri[(k + 1) % 3]), i);
        }
    }

    /// The corner beyond the directed edge a->b: the apex of the triangle
    /// holding b->a (`None` on the outline).
    fn across(&self, a: u32, b: u32) -> Option<u32> {
        let tri = self.triangles[*self.holding.get(&(b, a))? as usize];
        tri.into_iter().find(|&c| c != a && c != b)
    }

    /// Flips the diagonal a-b: (a, b, c) and (b, a, d) become (a, d, c) and
    /// (d, b, c). `None` (nothing done) if a-b is not a diagonal, which the
    /// callers' bookkeeping rules out.
    fn flip(&mut self, a: u32, b: u32) -> Option<()> {
        let (&i, &j) = (self.holding.get(&(a, b))?, self.holding.get(&(b, a))?);
        let third = |tri: [u32; 3]| tri.into_iter().find(|&x| x != a && x != b).unwrap_or(a);
        let (c, d) = (third(self.triangles[i as usize]), third(self.triangles[j as usize]));
        self.holding.remove(&(a, b));
        self.holding.remove(&(b, a));
        self.triangles[i as usize] = [a, d, c];
        self.triangles[j as usize] = [d, b, c];
        self.hold(i);
        self.hold(j);
        Some(())
    }

    /// Flips this triangulation to the fan of corner `v`, and returns the
    /// flips made: `(x, y, z)` turned the diagonal x-y into v-z (`None` if
    /// the bookkeeping failed, which it does not).
    fn flip_to_fan(&mut self, v: u32) -> Option<Vec<(u32, u32, u32)>> {
        let mut facing: Vec<(u32, u32)> = Vec::new();
        for tri in &self.triangles {
            if let Some(k) = tri.iter().position(|&c| c == v) {
                facing.push((tri[(k + 1) % 3], tri[(k + 2) % 3]));
            }
        }
        let mut steps = Vec::new();
        while let Some((x, y)) = facing.pop() {
            // (v, x, y) holds x->y; beyond it lies z.
            let Some(z) = self.across(x, y) else { continue };
            self.flip(x, y)?;
            steps.push((x, y, z));
            facing.push((x, z));
            facing.push((z, y));
        }
        Some(steps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::is_non_delaunay;

    /// Every interior edge of `t` Delaunay, every triangle counter-clockwise
    /// in the (x, y) plane, n - 2 of them.
    fn assert_delaunay(at: &[DVec3], t: &Corners) {
        assert_eq!(t.triangles.len(), at.len() - 2);
        for &[a, b, c] in &t.triangles {
            let [pa, pb, pc] = [a, b, c].map(|i| at[i as usize]);
            assert!((pb - pa).cross(pc - pa).z > 0.0, "{a} {b} {c} turns the other way");
            for (u, w) in [(a, b), (b, c), (c, a)] {
                if let Some(y) = t.across(u, w) {
                    let apex = [a, b, c].into_iter().find(|&x| x != u && x != w).unwrap();
                    let p = |i: u32| at[i as usize];
                    assert!(
                        !is_non_delaunay(p(u), p(w), p(apex), p(y), ALGORITHM_TOLERANCE),
                        "{u}-{w}"
                    );
                }
            }
        }
    }

    fn parabola(n: usize) -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let x = -1.0 + 2.0 * i as f64 / (n - 1) as f64;
                DVec3::new(x, x * x - 1.0, 0.0)
            })
            .collect()
    }

    #[test]
    fn chew_gives_the_delaunay_triangulation_of_convex_polygons() {
        for n in [3, 4, 5, 17, 300, 2000] {
            let oval: Vec<DVec3> = (0..n)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / n as f64;
                    DVec3::new(3.0 * a.cos(), a.sin(), 0.0)
                })
                .collect();
            assert_delaunay(&oval, &Corners::delaunay(&oval).unwrap());
            let p = parabola(n);
            assert_delaunay(&p, &Corners::delaunay(&p).unwrap());
        }
    }

    #[test]
    fn a_triangulation_goes_to_a_fan_of_n_minus_3_diagonals() {
        let p = parabola(500);
        let mut t = Corners::delaunay(&p).unwrap();
        let steps = t.flip_to_fan(7).unwrap();
        assert!(steps.len() <= 497);
        for tri in &t.triangles {
            assert!(tri.contains(&7), "{tri:?} not in the fan of 7");
        }
    }
}
