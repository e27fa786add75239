//! The planar regions of the input: faces joined across exactly coplanar, unfolded edges, and
//! each region's projection.

use super::*;

/// The planar regions of the input.
pub(super) struct Regions {
    /// Region of every input face.
    pub(super) of_face: Vec<u32>,
    /// Area of every region.
    pub(super) area: Vec<f64>,
    /// Unit normal of every region (of its largest face; zero if all its faces have zero area).
    pub(super) normal: Vec<DVec3>,
    /// A point of every region's plane (a corner of its largest face).
    anchor: Vec<DVec3>,
    /// The region's plane seen along one coordinate axis: every output face of the region must
    /// have, exactly, the orientation `plane.sign` in the projection along `plane.axis`.
    pub(super) plane: Vec<Projection>,
    /// Lowest-numbered input face of every region (to name it).
    first_face: Vec<u32>,
}

/// A coordinate axis to project along, and the exact orientation (the sign of `orient2d`, see
/// [`projected_orientation`]) that the region's faces have in that projection; `sign` is 0 only
/// when the region's largest face is exactly degenerate.
#[derive(Clone, Copy)]
pub(super) struct Projection {
    pub(super) axis: usize,
    pub(super) sign: i8,
}

impl Regions {
    /// Joins input faces across every interior edge that is exactly coplanar and flat.
    pub(super) fn new(mesh: &Mesh3, edges: &[Edge]) -> Regions {
        let p = |v: u32| mesh.positions[v as usize];
        let mut sets = UnionFind::new(mesh.triangles.len());
        for e in edges.iter().filter(|e| e.is_interior()) {
            let (a, b, f, g) = e.oriented();
            let c = third(&mesh.triangles[f as usize], a, b);
            let d = third(&mesh.triangles[g as usize], a, b);
            if coplanar_and_flat(p(a), p(b), p(c), p(d)) {
                sets.union(f, g);
            }
        }
        let mut id = vec![u32::MAX; mesh.triangles.len()];
        let mut of_face = vec![0; mesh.triangles.len()];
        let mut area: Vec<CompensatedSum> = Vec::new();
        let mut first_face = Vec::new();
        // The largest face of every region: (its area, its index, its normal).
        let mut largest: Vec<(f64, u32, DVec3)> = Vec::new();
        for (f, (region, t)) in of_face.iter_mut().zip(&mesh.triangles).enumerate() {
            let root = sets.find(f as u32) as usize;
            if id[root] == u32::MAX {
                id[root] = area.len() as u32;
                area.push(CompensatedSum::default());
                first_face.push(f as u32);
                largest.push((-1.0, f as u32, DVec3::ZERO));
            }
            let r = id[root] as usize;
            *region = r as u32;
            let n = triangle_normal(corners(mesh, t));
            let face_area = 0.5 * n.length();
            area[r].add(face_area);
            if face_area > largest[r].0 {
                largest[r] = (face_area, f as u32, n);
            }
        }
        let normal = largest.iter().map(|&(_, _, n)| n.normalize_or_zero()).collect();
        let anchor = largest
            .iter()
            .map(|&(_, f, _)| mesh.positions[mesh.triangles[f as usize][0] as usize])
            .collect();
        let plane = largest
            .iter()
            .map(|&(_, f, _)| Projection::of_face(corners(mesh, &mesh.triangles[f as usize])))
            .collect();
        Regions {
            of_face,
            area: area.iter().map(CompensatedSum::value).collect(),
            normal,
            anchor,
            plane,
            first_face,
        }
    }

    /// A name for region `r` in failure lines, its face named by `input` (the input's names).
    pub(super) fn name(&self, r: usize, input: &Names) -> String {
        format!(
            "region {} (containing input {})",
            r + 1,
            input.face_noun(self.first_face[r] as usize)
        )
    }

    /// Whether point `p` is in the plane of region `r`: within [`ON_EDGE_TOLERANCE`] of it,
    /// relative to the largest coordinate (of `p` and of the plane's point), as a point on an
    /// input edge is on it.
    pub(super) fn holds(&self, r: usize, p: DVec3) -> bool {
        let anchor = self.anchor[r];
        let scale = p.abs().max_element().max(anchor.abs().max_element()).max(1e-300);
        self.normal[r].dot(p - anchor).abs() <= ON_EDGE_TOLERANCE * scale
    }

    /// The exact orientation of a triangle relative to region `r`: 1 when its projection along
    /// the region's axis has the region's orientation, -1 when reversed, 0 when that projection
    /// is degenerate (or the region has no orientation).
    pub(super) fn side(&self, r: usize, triangle: [DVec3; 3]) -> i8 {
        let plane = self.plane[r];
        plane.sign * projected_orientation(triangle, plane.axis)
    }
}

impl Projection {
    /// The projection for a region with face `triangle`: along the axis of the largest
    /// component, exactly, of the normal `(b - a) x (c - a)` (ties: the lower axis). All faces of
    /// a region are exactly coplanar and alike oriented, so any face gives the same projection;
    /// it is the rule the construction states for its own checks, so that a face whose rounded
    /// corners leave the plane is judged in the projection it was built in.
    pub(super) fn of_face(triangle: [DVec3; 3]) -> Projection {
        let mut axis = 0;
        for other in [1, 2] {
            if larger_normal_component(triangle, other, axis) {
                axis = other;
            }
        }
        Projection {
            axis,
            sign: projected_orientation(triangle, axis),
        }
    }
}
