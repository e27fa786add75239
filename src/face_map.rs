//! Where each output face lies on the input (`--face-map`): the face of the
//! input file it is in, for carrying per-face data (segment labels, a face
//! colour kept outside the file) from the input to the output.
//!
//! Refinement splits input edges and flips edges inside flat regions only.
//! An output face made by splits alone lies inside one input triangle. A
//! flip inside a flat region of several input triangles may make a face
//! that lies across two or more of them:
//!
//! ```text
//!   input: two coplanar faces       output: the diagonal flipped
//!        c                                c
//!       / \                              /|\
//!      / F \                            / | \
//!     a-----b        ->                a  |  b      each output face
//!      \ G /                            \ | /       lies across F and G
//!       \ /                              \|/
//!        d                                d
//! ```
//!
//! Such a face is named by the input face under its centroid, and said not
//! to be inside it. Decided exactly where it can be: a face is inside an
//! input triangle when its three corners lie on that triangle's corners or
//! sides (each output vertex is an input vertex or lies on an input edge:
//! [`crate::mesh::Carrier`]); inside a polygon of the file cut into several
//! triangles when its corners lie on the polygon's and the polygon is
//! convex; the centroid is located with exact orientation tests on the
//! input's positions in the region's projection ([`RegionPlane`]).

use std::io::Write;

use glam::{DVec2, DVec3};

use crate::geometry::{projected_orientation, RegionPlane};
use crate::io::push_decimal;
use crate::mesh::{group_by_key, FaceId, Surface};

/// Where one output face lies: see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaceOrigin {
    /// The input face (of the file, numbered from 0) that holds the face,
    /// or, if none holds it whole, the one under its centroid.
    pub face: u32,
    /// Whether that input face holds the output face whole.
    pub inside: bool,
}

/// What [`FaceOrigins::apply`] needs of the input, taken from the surface
/// before refinement (which never changes an input face's region): each
/// input triangle's corners, region and face of the file, and the triangles
/// by region and around each input vertex: the input's triangles and faces
/// borrowed, and 20 bytes per input triangle, 4 per input vertex and 4 per
/// region (at most one per triangle).
#[derive(Clone, Debug)]
pub struct FaceOrigins<'a> {
    /// The input triangles.
    triangles: &'a [[u32; 3]],
    /// The face of the file of each triangle (none: triangle `t` is face `t`).
    file_face: Option<&'a [u32]>,
    /// The planar region of each triangle.
    region: Vec<u32>,
    /// `by_region[region_start[r]..region_start[r + 1]]`: the triangles of
    /// region `r`, in order.
    region_start: Vec<u32>,
    /// See `region_start`.
    by_region: Vec<u32>,
    /// `by_vertex[vertex_start[v]..vertex_start[v + 1]]`: the triangles
    /// around input vertex `v`, in order; empty when no region has two
    /// triangles (every output face then lies in its region's one).
    vertex_start: Vec<u32>,
    /// See `vertex_start`.
    by_vertex: Vec<u32>,
}

impl<'a> FaceOrigins<'a> {
    /// Prepares the map of refinements of `surface`, built from `triangles`
    /// (face `i` is triangle `i`) and not yet refined; `file_face` gives
    /// each triangle's face of the file ([`crate::io::InputMesh::triangle_polygon`];
    /// empty: each triangle a face of its own).
    pub fn new(triangles: &'a [[u32; 3]], file_face: &'a [u32], surface: &Surface) -> FaceOrigins<'a> {
        let n = triangles.len();
        // (Defensive, as `Transfer::new`: a surface not built from these
        // triangles gives a meaningless map, not a panic.)
        let regions = surface.n_regions.max(1);
        let region: Vec<u32> = (0..n)
            .map(|t| {
                surface
                    .face_region
                    .get(t)
                    .copied()
                    .filter(|&r| (r as usize) < regions)
                    .unwrap_or(0)
            })
            .collect();
        let file_face = (file_face.len() == n).then_some(file_face);
        let (region_start, by_region) = group_by_key(regions, region.iter().copied());
        let shared = region_start.windows(2).any(|w| w[1] - w[0] > 1);
        let (vertex_start, by_vertex) = if shared {
            // Each vertex's corners (3·triangle + k), as triangles.
            let vertices = triangles.iter().flatten().map(|&v| v as usize + 1).max().unwrap_or(0);
            let (start, corners) = group_by_key(vertices, triangles.iter().flatten().copied());
            (start, corners.into_iter().map(|c| c / 3).collect())
        } else {
            (Vec::new(), Vec::new())
        };
        FaceOrigins {
            triangles,
            file_face,
            region,
            region_start,
            by_region,
            vertex_start,
            by_vertex,
        }
    }

    /// The face of the file of triangle `t`.
    fn file_face(&self, t: u32) -> u32 {
        self.file_face.map_or(t, |faces| faces[t as usize])
    }

    /// The triangles of region `r` (none for a region not of the input).
    fn of_region(&self, r: u32) -> &[u32] {
        let r = r as usize;
        match (self.region_start.get(r), self.region_start.get(r + 1)) {
            (Some(&s), Some(&e)) => &self.by_region[s as usize..e as usize],
            _ => &[],
        }
    }

    /// The triangles around input vertex `v`.
    fn around(&self, v: u32) -> &[u32] {
        let v = v as usize;
        match (self.vertex_start.get(v), self.vertex_start.get(v + 1)) {
            (Some(&s), Some(&e)) => &self.by_vertex[s as usize..e as usize],
            _ => &[],
        }
    }

    /// Where each face of the refined `surface` lies, face by face.
    pub fn apply(&self, surface: &Surface) -> Vec<FaceOrigin> {
        let mut polygons = PolygonCache::default();
        (0..surface.topo.n_faces() as u32)
            .map(|f| self.origin(surface, FaceId(f), &mut polygons))
            .collect()
    }

    /// Where face `f` of `surface` lies.
    fn origin(&self, surface: &Surface, f: FaceId, polygons: &mut PolygonCache) -> FaceOrigin {
        let r = surface.face_region[f.idx()];
        let region = self.of_region(r);
        let corners = surface.topo.face_vertices(f);
        // Each corner's input vertices: (i, i) on vertex i, (a, b) on edge ab.
        let ends = corners.map(|v| {
            let (a, b, _) = surface.vertex_source(v);
            [a, b]
        });
        let inside_triangle = |t: u32| {
            let tri = self.triangles[t as usize];
            ends.iter().flatten().all(|v| tri.contains(v))
        };
        let named = |t: u32, inside: bool| FaceOrigin {
            face: self.file_face(t),
            inside,
        };
        match region {
            [] => return FaceOrigin { face: 0, inside: false },
            &[t] => return named(t, true),
            _ => {}
        }
        // A triangle around the first corner that has all three.
        let [a, b] = ends[0];
        let start = self.around(a).iter().copied().filter(|&t| self.region[t as usize] == r);
        let mut first = None;
        for t in start {
            if self.triangles[t as usize].contains(&b) {
                if inside_triangle(t) {
                    return named(t, true);
                }
                first.get_or_insert(t);
            }
        }
        // Across several: the triangle under the centroid, and whether its
        // polygon of the file (if cut into several) holds the face whole.
        let q = corners.iter().map(|v| surface.positions[v.idx()]).sum::<DVec3>() / 3.0;
        let plane = surface.region_plane.get(r as usize).copied();
        let t = self.locate(surface, plane, r, first.unwrap_or(region[0]), q);
        let face = self.file_face(t);
        let inside = polygons.holds(self, surface, plane, r, face, t, &ends);
        FaceOrigin { face, inside }
    }

    /// The triangle of region `r` under point `q`: a walk from triangle
    /// `start` towards `q`; where the region's border blocks it (the
    /// centroid of a sliver along the border, rounded out of the region)
    /// or it wanders, the nearby triangle that holds `q` or that `q` is
    /// barely out of, else the region's ([`FaceOrigins::nearest`]).
    fn locate(&self, surface: &Surface, plane: Option<RegionPlane>, r: u32, start: u32, q: DVec3) -> u32 {
        let p = |v: u32| surface.positions[v as usize];
        let Some(plane) = plane.filter(|plane| plane.sign != 0) else {
            return self.nearest(surface, plane, r, q);
        };
        let (axis, sign) = (plane.axis as usize, plane.sign);
        let mut t = start;
        // Beyond this many steps a walk wanders (inexact centroids can
        // make it circle).
        let limit = 3 * self.of_region(r).len() + 8;
        'walk: for step in 0..limit {
            let tri = self.triangles[t as usize];
            let mut blocked = false;
            for k in 0..3 {
                // Edges in turn from a changing one, so that no edge order circles.
                let i = (k + step) % 3;
                let (u, v) = (tri[i], tri[(i + 1) % 3]);
                if projected_orientation([p(u), p(v), q], axis) == -sign {
                    match self.neighbour(t, u, v, r) {
                        Some(next) => {
                            t = next;
                            continue 'walk;
                        }
                        None => blocked = true,
                    }
                }
            }
            if !blocked {
                return t;
            }
            break;
        }
        // The triangles near where the walk stopped, breadth first.
        let mut seen = vec![t];
        let mut best = (f64::NEG_INFINITY, t);
        let mut next = 0;
        while next < seen.len() && seen.len() < NEARBY {
            let u = seen[next];
            next += 1;
            if self.holds(surface, plane, u, q) {
                return u;
            }
            let depth = self.depth(surface, plane, u, q);
            if depth > best.0 {
                best = (depth, u);
            }
            let tri = self.triangles[u as usize];
            for k in 0..3 {
                if let Some(n) = self.neighbour(u, tri[k], tri[(k + 1) % 3], r) {
                    if !seen.contains(&n) {
                        seen.push(n);
                    }
                }
            }
        }
        if best.0 >= -BARELY_OUT * self.size(surface, plane, best.1) {
            return best.1;
        }
        self.nearest(surface, Some(plane), r, q)
    }

    /// The triangle of region `r` across edge `uv` from triangle `t`.
    fn neighbour(&self, t: u32, u: u32, v: u32, r: u32) -> Option<u32> {
        (self.around(u).iter().copied())
            .find(|&n| n != t && self.region[n as usize] == r && self.triangles[n as usize].contains(&v))
    }

    /// Exactly: does triangle `t` hold `q` (on its sides too) in the
    /// projection of `plane`?
    fn holds(&self, surface: &Surface, plane: RegionPlane, t: u32, q: DVec3) -> bool {
        let p = |v: u32| surface.positions[v as usize];
        let tri = self.triangles[t as usize];
        (0..3).all(|k| projected_orientation([p(tri[k]), p(tri[(k + 1) % 3]), q], plane.axis as usize) != -plane.sign)
    }

    /// Triangle `t`'s corners, and `q`, in the projection of `plane` (the
    /// other two coordinates in cyclic order, as [`projected_orientation`]).
    fn projected(&self, surface: &Surface, plane: RegionPlane, t: u32, q: DVec3) -> ([DVec2; 3], DVec2) {
        let (i, j) = [(1, 2), (2, 0), (0, 1)][plane.axis as usize];
        let flat = |p: DVec3| DVec2::new(p[i], p[j]);
        let corners = self.triangles[t as usize].map(|v| flat(surface.positions[v as usize]));
        (corners, flat(q))
    }

    /// How far `q` is inside triangle `t` in the projection of `plane`:
    /// its smallest distance to a side's line, negative outside (in
    /// floating point).
    fn depth(&self, surface: &Surface, plane: RegionPlane, t: u32, q: DVec3) -> f64 {
        let (c, q) = self.projected(surface, plane, t, q);
        (0..3)
            .map(|k| {
                let side = c[(k + 1) % 3] - c[k];
                f64::from(plane.sign) * side.perp_dot(q - c[k]) / side.length()
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The longest side of triangle `t` in the projection of `plane`.
    fn size(&self, surface: &Surface, plane: RegionPlane, t: u32) -> f64 {
        let (c, _) = self.projected(surface, plane, t, DVec3::ZERO);
        (0..3).map(|k| c[k].distance(c[(k + 1) % 3])).fold(0.0, f64::max)
    }

    /// The first triangle of region `r` that holds `q` in the region's
    /// projection, else the one it is nearest inside of (the largest
    /// [`FaceOrigins::depth`]).
    fn nearest(&self, surface: &Surface, plane: Option<RegionPlane>, r: u32, q: DVec3) -> u32 {
        let region = self.of_region(r);
        let first = region.first().copied().unwrap_or(0);
        let Some(plane) = plane.filter(|plane| plane.sign != 0) else {
            return first;
        };
        let mut best = (f64::NEG_INFINITY, first);
        for &t in region {
            if self.holds(surface, plane, t, q) {
                return t;
            }
            let depth = self.depth(surface, plane, t, q);
            if depth > best.0 {
                best = (depth, t);
            }
        }
        best.1
    }
}

/// How many triangles near a blocked walk's end [`FaceOrigins::locate`]
/// looks at before the whole region.
const NEARBY: usize = 64;

/// How far out of a triangle, relative to its longest side, a point may be
/// and still count as on it when the walk ends at the region's border: far
/// above the rounding of a centroid (1e-16 of the coordinates), far below
/// where another triangle would hold it.
const BARELY_OUT: f64 = 1e-6;

/// Whether polygons of the file (cut into several triangles) are convex in
/// a region, each found once.
#[derive(Default)]
struct PolygonCache {
    convex: crate::hash::FastMap<(u32, u32), (bool, Vec<u32>)>,
}

impl PolygonCache {
    /// Whether polygon `face` of the file, found at triangle `t` of region
    /// `r`, holds whole a face whose corners lie on input vertices and
    /// edges with `ends`: it is convex there and has all those vertices.
    /// (Its triangles are consecutive around `t`.)
    #[allow(clippy::too_many_arguments)]
    fn holds(
        &mut self,
        origins: &FaceOrigins,
        surface: &Surface,
        plane: Option<RegionPlane>,
        r: u32,
        face: u32,
        t: u32,
        ends: &[[u32; 2]; 3],
    ) -> bool {
        let (convex, vertices) = self.convex.entry((face, r)).or_insert_with(|| {
            let same = |u: usize| origins.file_face(u as u32) == face && origins.region[u] == r;
            let (mut first, mut end) = (t as usize, t as usize + 1);
            while first > 0 && same(first - 1) {
                first -= 1;
            }
            while end < origins.triangles.len() && same(end) {
                end += 1;
            }
            let corners = &origins.triangles[first..end];
            let mut vertices: Vec<u32> = corners.iter().flatten().copied().collect();
            vertices.sort_unstable();
            vertices.dedup();
            (
                corners.len() > 1 && is_convex(surface, plane, corners, &vertices),
                vertices,
            )
        });
        *convex && ends.iter().flatten().all(|v| vertices.binary_search(v).is_ok())
    }
}

/// Whether the union of `triangles` (exactly coplanar, oriented alike, with
/// the corners `vertices`) is convex in the projection of `plane`: every
/// vertex on the inner side of every side of the union (an edge of one
/// triangle only), exactly.
fn is_convex(surface: &Surface, plane: Option<RegionPlane>, triangles: &[[u32; 3]], vertices: &[u32]) -> bool {
    let Some(plane) = plane.filter(|plane| plane.sign != 0) else {
        return false;
    };
    let p = |v: u32| surface.positions[v as usize];
    let sides = triangles.iter().flat_map(|t| [0, 1, 2].map(|k| (t[k], t[(k + 1) % 3])));
    let inner = |(u, v): (u32, u32)| {
        triangles
            .iter()
            .any(|t| (0..3).any(|k| (t[k], t[(k + 1) % 3]) == (v, u)))
    };
    sides.filter(|&side| !inner(side)).all(|(u, v)| {
        vertices
            .iter()
            .all(|&w| projected_orientation([p(u), p(v), p(w)], plane.axis as usize) != -plane.sign)
    })
}

/// `origins`, of the faces of the refined surface, in the order of the
/// output file's faces ([`crate::io::Written::face_order`]: empty for the
/// surface's own).
pub fn in_file_order(origins: Vec<FaceOrigin>, face_order: &[u32]) -> Vec<FaceOrigin> {
    if face_order.is_empty() {
        origins
    } else {
        face_order.iter().map(|&f| origins[f as usize]).collect()
    }
}

/// Writes `origins` as the CSV of `--face-map`: `output_index,input_index,inside`,
/// then a row per face (0-based; inside 1 or 0).
pub fn write_csv(w: &mut dyn Write, origins: &[FaceOrigin]) -> std::io::Result<()> {
    w.write_all(b"output_index,input_index,inside\n")?;
    let mut chunk = Vec::with_capacity(1 << 16);
    for (i, o) in origins.iter().enumerate() {
        push_decimal(&mut chunk, i as u64);
        chunk.push(b',');
        push_decimal(&mut chunk, u64::from(o.face));
        chunk.extend_from_slice(if o.inside { b",1\n" } else { b",0\n" });
        if chunk.len() > (1 << 16) - 32 {
            w.write_all(&chunk)?;
            chunk.clear();
        }
    }
    w.write_all(&chunk)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{make_delaunay, Options};

    fn refined(positions: Vec<DVec3>, triangles: &[[u32; 3]], file_face: &[u32]) -> (Surface, Vec<FaceOrigin>) {
        let mut surface = Surface::new(positions, triangles).unwrap();
        let origins = FaceOrigins::new(triangles, file_face, &surface);
        make_delaunay(&mut surface, &Options::default()).unwrap();
        surface.validate().unwrap();
        let map = origins.apply(&surface);
        assert_eq!(map.len(), surface.topo.n_faces());
        (surface, map)
    }

    /// A thin rhombus with the long diagonal ab, its lower corner raised by
    /// `fold` (0: flat).
    fn rhombus(fold: f64) -> (Vec<DVec3>, [[u32; 3]; 2]) {
        let positions = vec![
            DVec3::new(-2.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 0.5, 0.0),
            DVec3::new(0.0, -0.4, fold),
        ];
        (positions, [[0, 1, 2], [1, 0, 3]])
    }

    /// The rhombus of the sketch, flat and thin: its diagonal ab is flipped,
    /// and each new face lies across both input faces.
    #[test]
    fn a_flipped_diagonal_lies_across_both_faces() {
        let (positions, triangles) = rhombus(0.0);
        let (surface, map) = refined(positions.clone(), &triangles, &[]);
        assert_eq!(surface.positions.len(), 4, "flipped, not split");
        assert!(map.iter().all(|o| !o.inside), "{map:?}");
        // Each new face's centroid is on the side of the larger piece:
        // x < 0 in face 0 (above ab: y > 0) or 1.
        for (f, o) in map.iter().enumerate() {
            let c: DVec3 = surface
                .topo
                .face_vertices(FaceId(f as u32))
                .map(|v| positions[v.idx()])
                .iter()
                .sum::<DVec3>()
                / 3.0;
            assert_eq!(o.face, if c.y > 0.0 { 0 } else { 1 }, "{c}");
        }
        // As one quad of the file (convex), both are inside it.
        let (_, map) = refined(positions, &triangles, &[7, 7]);
        assert!(map.iter().all(|o| o.inside && o.face == 7), "{map:?}");
    }

    /// A folded mesh (no flat region of two faces): splits only, every
    /// face inside the input face it was cut from.
    #[test]
    fn split_faces_lie_inside_their_face() {
        let (positions, triangles) = rhombus(0.3);
        let (surface, map) = refined(positions, &triangles, &[]);
        assert!(surface.positions.len() > 4);
        for (f, o) in map.iter().enumerate() {
            assert!(o.inside);
            let z = surface
                .topo
                .face_vertices(FaceId(f as u32))
                .map(|v| surface.positions[v.idx()].z);
            assert_eq!(o.face, if z.iter().any(|&z| z > 0.0) { 1 } else { 0 });
        }
    }

    /// An L of four triangles is not convex; its notch, a quadrilateral
    /// of two, is (the test behind "inside" for polygons of the file).
    #[test]
    fn polygons_are_convex_or_not_exactly() {
        //  5---4-------6
        //  |   |       |      the L: 0 1 2 3 4 5, reflex at 3;
        //  |   | notch |      the notch: 3 2 6 4
        //  |    3------2
        //  0-----------1
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(3.0, 0.0, 0.0),
            DVec3::new(3.0, 1.0, 0.0),
            DVec3::new(1.2, 1.0, 0.0),
            DVec3::new(1.0, 3.0, 0.0),
            DVec3::new(0.0, 3.0, 0.0),
            DVec3::new(3.0, 3.0, 0.0),
        ];
        let l = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]];
        let notch = [[3, 2, 6], [3, 6, 4]];
        let all: Vec<[u32; 3]> = l.iter().chain(&notch).copied().collect();
        let surface = Surface::new(positions, &all).unwrap();
        let plane = surface.region_plane.first().copied();
        assert_eq!(surface.n_regions, 1, "one flat region");
        let vertices = |tris: &[[u32; 3]]| {
            let mut v: Vec<u32> = tris.iter().flatten().copied().collect();
            v.sort_unstable();
            v.dedup();
            v
        };
        assert!(!is_convex(&surface, plane, &l, &vertices(&l)));
        assert!(is_convex(&surface, plane, &notch, &vertices(&notch)));
        assert!(is_convex(&surface, plane, &l[..2], &vertices(&l[..2])));
        // The whole region, L and notch: a rectangle with 3 inside.
        assert!(is_convex(&surface, plane, &all, &vertices(&all)));
    }
}
