//! Damage with a known verdict, done to a refined mesh: what the checker
//! must refuse (`tests/check_soundness.rs`, and the pipeline fuzz target on
//! every mesh it refines).

use std::collections::HashMap;
use std::f64::consts::PI;

use super::Rng;
use delmesh::check::Mesh3;
use delmesh::mesh::{Carrier, Surface};
use glam::DVec3;

/// Where each directed edge (u, v) is: its face and the corner it starts at.
pub fn directed_edges(m: &Mesh3) -> HashMap<(u32, u32), (usize, usize)> {
    let mut map = HashMap::new();
    for (f, t) in m.triangles.iter().enumerate() {
        for k in 0..3 {
            map.insert((t[k], t[(k + 1) % 3]), (f, k));
        }
    }
    map
}

/// The angle at `at` between the directions to `p` and `q`, in [0, π].
pub fn angle(at: DVec3, p: DVec3, q: DVec3) -> f64 {
    let (u, v) = (p - at, q - at);
    u.cross(v).length().atan2(u.dot(v))
}

/// Shewchuk's exact orientation of `d` against the plane of `a`, `b`, `c`
/// (0: exactly coplanar).
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let c3 = |p: DVec3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
    robust::orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// Kinds of damage; each gives the damaged output, or `None` if this mesh
/// offers no place for it (tried again elsewhere by the caller).
#[derive(Clone, Copy, Debug)]
pub enum Damage {
    /// An added vertex moved square to its input edge, from 1e-9 of the
    /// edge's largest coordinate to a thousandth of its shortest edge.
    AddedVertexOffItsEdge,
    /// An added vertex moved along its input edge, halfway past the next
    /// vertex on it (or past the edge's end); not where the surface is
    /// folded flat onto itself at the vertex.
    AddedVertexPastItsNeighbour,
    /// An input vertex moved by one unit in the last place of a coordinate.
    InputVertexOneUlp,
    /// A face left out.
    FaceRemoved,
    /// A face written twice.
    FaceDoubled,
    /// A face's orientation reversed.
    FaceTurnedOver,
    /// An edge between two input regions, whose quad is clearly not flat,
    /// flipped.
    CreaseFlipped,
    /// An edge of an exactly flat quad flipped where the other diagonal is
    /// non-Delaunay by more than 1e-6 rad.
    FlatFlipNonDelaunay,
    /// A face split into three at an inner point.
    FaceSplitInside,
}

impl Damage {
    /// Whether the refusal holds on any mesh f64 can hold: not a vertex
    /// moved off its edge or added inside a face, which in a fuzzed mesh (a
    /// needle, near-coincident edges) can land within the on-edge tolerance
    /// of another input edge, and then keep the geometry.
    pub fn refused_on_any_mesh(self) -> bool {
        !matches!(self, Damage::AddedVertexOffItsEdge | Damage::FaceSplitInside)
    }
}

/// Every kind of damage.
pub const DAMAGES: [Damage; 9] = [
    Damage::AddedVertexOffItsEdge,
    Damage::AddedVertexPastItsNeighbour,
    Damage::InputVertexOneUlp,
    Damage::FaceRemoved,
    Damage::FaceDoubled,
    Damage::FaceTurnedOver,
    Damage::CreaseFlipped,
    Damage::FlatFlipNonDelaunay,
    Damage::FaceSplitInside,
];

/// The faces (a, b, c) and (b, a, d) of a random interior edge (a, b) such
/// that `wanted(face 1, face 2, [a, b, c, d])`, as (face 1, face 2, [a, b, c, d]); up to 200
/// tries.
pub fn random_interior_edge(
    m: &Mesh3,
    edges: &HashMap<(u32, u32), (usize, usize)>,
    rng: &mut Rng,
    wanted: impl Fn(usize, usize, [DVec3; 4]) -> bool,
) -> Option<(usize, usize, [u32; 4])> {
    for _ in 0..200 {
        let f = rng.below(m.triangles.len() as u64) as usize;
        let k = rng.below(3) as usize;
        let t = m.triangles[f];
        let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        let Some(&(g, j)) = edges.get(&(b, a)) else {
            continue;
        };
        let d = m.triangles[g][(j + 2) % 3];
        let quad = [a, b, c, d];
        if wanted(f, g, quad.map(|v| m.positions[v as usize])) {
            return Some((f, g, quad));
        }
    }
    None
}

/// Replaces faces `f` = (a, b, c) and `g` = (b, a, d) by (c, a, d) and (d, b, c).
///
/// ```text
///        c                c
///       / \              /|\
///      a---b    ->      a | b
///       \ /              \|/
///        d                d
/// ```
pub fn flip(m: &mut Mesh3, f: usize, g: usize, [a, b, c, d]: [u32; 4]) {
    m.triangles[f] = [c, a, d];
    m.triangles[g] = [d, b, c];
}

/// A random added vertex of `s` (`None` if it has none), with its input
/// edge and parameter on it.
pub fn random_added_vertex(s: &Surface, rng: &mut Rng) -> Option<(usize, u32, f64)> {
    let n_input = s.n_input_vertices;
    let added = s.positions.len() - n_input;
    if added == 0 {
        return None;
    }
    let v = n_input + rng.below(added as u64) as usize;
    let Carrier::Edge { edge, t } = s.carriers[v] else {
        unreachable!("an added vertex lies on an input edge")
    };
    Some((v, edge, t))
}

/// The parameters of the vertices next to parameter `t` on input edge
/// `edge` of `s`, before and after it (0 and 1 at its ends).
pub fn neighbours_on_edge(s: &Surface, edge: u32, t: f64) -> (f64, f64) {
    let (mut before, mut after) = (0.0f64, 1.0f64);
    for c in &s.carriers[s.n_input_vertices..] {
        if let Carrier::Edge { edge: e, t: u } = *c {
            if e == edge && u < t {
                before = before.max(u);
            } else if e == edge && u > t {
                after = after.min(u);
            }
        }
    }
    (before, after)
}

/// Whether two faces at vertex `v` of `m` lie flat on each other: unit
/// normals opposite within 1e-9 (a fold of the input shut to within
/// rounding, as where a face's corner is one unit in the last place from
/// its neighbour's across the edge). There a face turned over on one side
/// is, within rounding, a face of the other side the right way up, and the
/// other side's edges are within rounding of this side's: the checker
/// rightly cannot tell them apart.
fn on_a_flat_fold(m: &Mesh3, v: usize) -> bool {
    let normals: Vec<DVec3> = (m.triangles.iter())
        .filter(|t| t.contains(&(v as u32)))
        .map(|t| {
            let [a, b, c] = t.map(|x| m.positions[x as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();
    normals.iter().any(|n| normals.iter().any(|o| n.dot(*o) < -1.0 + 1e-9))
}

/// The area of face `f` of `m`.
fn face_area(m: &Mesh3, f: usize) -> f64 {
    let [a, b, c] = m.triangles[f].map(|v| m.positions[v as usize]);
    0.5 * (b - a).cross(c - a).length()
}

/// Whether face `f` of `m` has an edge no other face has, with the opposite corner closer to
/// that edge's line than 1e-10 times the mesh's largest coordinate (six times `check`'s on-edge
/// tolerance, which is relative to the input edge's coordinates, at most the mesh's): removed,
/// such a face leaves a boundary `check` may rightly take to lie along the input's.
fn hugs_the_boundary(m: &Mesh3, f: usize) -> bool {
    let t = m.triangles[f];
    let scale = m.positions.iter().map(|p| p.abs().max_element()).fold(0.0, f64::max);
    (0..3).any(|k| {
        let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        let boundary = !(m.triangles.iter().enumerate()).any(|(g, u)| g != f && u.contains(&a) && u.contains(&b));
        let [a, b, c] = [a, b, c].map(|v| m.positions[v as usize]);
        let height = (b - a).cross(c - a).length() / (b - a).length();
        // (A NaN height, of an edge of length 0, hugs it too.)
        boundary && (height.is_nan() || height <= 1e-10 * scale)
    })
}

/// `out`, the refined `s` as a [`Mesh3`], with damage of `kind` at a random
/// place; `None` if it has no place for it.
pub fn damage(kind: Damage, s: &Surface, out: &Mesh3, rng: &mut Rng) -> Option<Mesh3> {
    let mut m = out.clone();
    let n_faces = m.triangles.len() as u64;
    match kind {
        Damage::AddedVertexOffItsEdge => {
            let (v, edge, _) = random_added_vertex(s, rng)?;
            let [a, b] = s.input_edge_ends(edge);
            let dir = (b - a).normalize();
            // A random direction square to the edge ...
            let w = DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            let perp = (w - dir * w.dot(dir)).try_normalize()?;
            // ... and a distance from 100 times the on-edge tolerance (1e-9
            // of the edge's largest coordinate) to a thousandth of the
            // shortest edge at the vertex, log-uniform.
            let p = m.positions[v];
            let shortest = (m.triangles.iter())
                .filter(|t| t.contains(&(v as u32)))
                .flat_map(|t| t.map(|x| (m.positions[x as usize] - p).length()))
                .filter(|&l| l > 0.0)
                .fold(f64::INFINITY, f64::min);
            let scale = a.abs().max_element().max(b.abs().max_element());
            let (near, far) = (1e-9 * scale, (1e-3 * shortest).max(2e-9 * scale));
            let distance = near * (far / near).powf(rng.f64());
            m.positions[v] = p + perp * distance;
        }
        Damage::AddedVertexPastItsNeighbour => {
            // Along its input edge, halfway past the next vertex on it (an
            // added one, or the edge's end: then off the edge): the faces
            // between the two turn over.
            let (v, edge, t) = random_added_vertex(s, rng)?;
            if on_a_flat_fold(&m, v) {
                return None;
            }
            // Faces turned over that are all below 1e-8 of the whole area change the regions'
            // areas by less than `check` allows (1e-9 of a region): not done there, as
            // `--gabriel-boundary` makes such faces (splits at sample resolution by a needle).
            let total: f64 = (0..m.triangles.len()).map(|g| face_area(&m, g)).sum();
            let tiny = |g: usize| !m.triangles[g].contains(&(v as u32)) || face_area(&m, g) < 1e-8 * total;
            if (0..m.triangles.len()).all(tiny) {
                return None;
            }
            let (_, next) = neighbours_on_edge(s, edge, t);
            let [a, b] = s.input_edge_ends(edge);
            m.positions[v] = delmesh::samples::point_on_edge(a, b, next + 0.5 * (next - t));
        }
        Damage::InputVertexOneUlp => {
            let v = rng.below(s.n_input_vertices as u64) as usize;
            let k = rng.below(3) as usize;
            let mut c = m.positions[v].to_array();
            c[k] = f64::from_bits(c[k].to_bits() ^ 1);
            m.positions[v] = DVec3::from_array(c);
        }
        Damage::FaceRemoved => {
            let f = rng.below(n_faces) as usize;
            // A face along the boundary, removed, leaves the topology's counts as they were
            // (one edge and one face fewer, the same boundary loops), and its region's area
            // changes by less than `check` allows where the face is tiny (as
            // `--gabriel-boundary` makes them, by needles); `check` sees the boundary move,
            // unless the face is so thin that its corner is on the boundary edge.
            if hugs_the_boundary(&m, f) {
                return None;
            }
            m.triangles.swap_remove(f);
        }
        Damage::FaceDoubled => {
            let t = m.triangles[rng.below(n_faces) as usize];
            m.triangles.push(t);
        }
        Damage::FaceTurnedOver => {
            let f = rng.below(n_faces) as usize;
            m.triangles[f].swap(0, 1);
        }
        Damage::CreaseFlipped => {
            let edges = directed_edges(&m);
            // Faces of two input regions whose planes are clearly apart
            // (d a millionth of the quad's size off the plane of a, b, c):
            // across a nearly flat edge, the faces moved by less than the
            // on-edge tolerance could pass, rightly.
            let (f, g, quad) = random_interior_edge(&m, &edges, rng, |f, g, [a, b, c, d]| {
                let size = [a - b, a - c, a - d, b - c, b - d]
                    .map(DVec3::length)
                    .into_iter()
                    .fold(0.0, f64::max);
                let off = ((d - a).dot((b - a).cross(c - a).normalize_or_zero())).abs();
                s.face_region[f] != s.face_region[g] && off > 1e-6 * size
            })?;
            flip(&mut m, f, g, quad);
        }
        Damage::FlatFlipNonDelaunay => {
            // In an exactly flat convex quad (a, d, b, c), the other
            // diagonal's angles sum to 2π − (α + β): over π by as much as
            // α + β is under it. Not where the surface is folded flat onto
            // itself (c and d on one side of ab: the quad's faces overlap),
            // where the flipped pair can be Delaunay too and, inside the
            // fold, keeps the faces within their region and its area within
            // tolerance (the pipeline target's seed 2026120462): so the
            // angles at a and b are measured, not inferred.
            let edges = directed_edges(&m);
            let (f, g, quad) = random_interior_edge(&m, &edges, rng, |_, _, [a, b, c, d]| {
                orient3d(a, b, c, d) == 0.0
                    && angle(c, a, b) + angle(d, a, b) < PI - 1e-6
                    && angle(a, c, d) + angle(b, d, c) > PI + 1e-6
            })?;
            flip(&mut m, f, g, quad);
        }
        Damage::FaceSplitInside => {
            let f = rng.below(n_faces) as usize;
            let [a, b, c] = m.triangles[f];
            let p = [a, b, c].map(|v| m.positions[v as usize]);
            let (wa, wb) = (rng.range(0.2, 0.4), rng.range(0.2, 0.4));
            let inner = p[0] * wa + p[1] * wb + p[2] * (1.0 - wa - wb);
            let v = m.positions.len() as u32;
            m.positions.push(inner);
            m.triangles[f] = [a, b, v];
            m.triangles.extend([[b, c, v], [c, a, v]]);
        }
    }
    Some(m)
}
