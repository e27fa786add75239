//! The constrained Delaunay triangulation of a flat piece of surface inside
//! its outlines, by `spade`: how [`crate::flat_regions`] rebuilds a large
//! flat region and how [`crate::io::polygon`] cuts a large polygon of a
//! file, where Lawson's flips would take quadratically many steps.
//!
//! The piece is laid flat in an orthonormal frame of its plane (the Newell
//! normal of its outlines; rounded, so callers check the triangles they
//! get exactly or by their own rule), triangulated there with the outline
//! edges as constraints, and the triangles inside are those reached from
//! the left of an outline edge without crossing one (a sketch of a strip
//! before and after is in [`crate::flat_regions`]).

use glam::DVec3;
use spade::handles::FixedVertexHandle;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

/// The constrained Delaunay triangulation of the points `at`, which lie in
/// one plane (up to rounding), inside the outlines `outline`: directed
/// edges as pairs of indices into `at`, the inside on their left seen from
/// the side their Newell normal points to (outer outlines counter-clockwise,
/// those of holes clockwise). Returns the triangles inside, as triples of
/// indices into `at` turning the outlines' way, or `None` if there are not
/// exactly `n_faces` of them, the frame puts two points at one place, or
/// outlines cross (or an outline edge is missing, or lets the outside in).
pub fn triangulate_inside(at: &[DVec3], outline: &[[usize; 2]], n_faces: usize) -> Option<Vec<[usize; 3]>> {
    let origin = *at.first()?;
    // The normal, the way the faces turn: the sum of the outline's cross
    // products (Newell), from the first point.
    let normal: DVec3 = (outline.iter())
        .map(|&[a, b]| (at[a] - origin).cross(at[b] - origin))
        .sum();
    let n = normal.try_normalize()?;
    // A frame (u, w, n), right-handed: triangles turning the outlines' way
    // turn counter-clockwise in (u, w), as spade's do.
    let least = n.abs().min_element();
    let axis = if n.x.abs() == least {
        DVec3::X
    } else if n.y.abs() == least {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let u = axis.cross(n).try_normalize()?;
    let w = n.cross(u);
    let points: Vec<Point2<f64>> = (at.iter())
        .map(|&p| {
            let d = p - origin;
            Point2::new(d.dot(u), d.dot(w))
        })
        .collect();
    let mut conflict = false;
    let cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(points, outline.to_vec(), |_| {
        conflict = true
    })
    .ok()?;
    if conflict || cdt.num_vertices() != at.len() || cdt.num_constraints() != outline.len() {
        return None;
    }
    // The faces inside: from the left of every outline edge, across edges
    // that are not constraints. Reaching the outer face means an outline is
    // not where the caller said.
    let handle = FixedVertexHandle::from_index;
    let mut inside = vec![false; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for &[a, b] in outline {
        let edge = cdt.get_edge_from_neighbors(handle(a), handle(b))?;
        if !edge.is_constraint_edge() {
            return None;
        }
        stack.push(edge.face().as_inner()?.fix());
    }
    let mut triangles = Vec::with_capacity(n_faces);
    while let Some(f) = stack.pop() {
        if std::mem::replace(&mut inside[f.index()], true) {
            continue;
        }
        let face = cdt.face(f);
        triangles.push(face.vertices().map(|v| v.fix().index()));
        if triangles.len() > n_faces {
            return None;
        }
        for edge in face.adjacent_edges() {
            if !edge.is_constraint_edge() {
                let beyond = edge.rev().face().as_inner()?.fix();
                if !inside[beyond.index()] {
                    stack.push(beyond);
                }
            }
        }
    }
    (triangles.len() == n_faces).then_some(triangles)
}
