//! Floating-point geometry on triangles: corner angles, the Delaunay test of
//! an edge, the intrinsic unfolding of neighbouring triangles into a plane,
//! and circumcircles. Exact predicates (for planar regions and zero-area
//! faces) live here too, on top of the `robust` crate.
//!
//! Nothing in this module knows about mesh connectivity.

use glam::{DVec2, DVec3};

/// The acceptance tolerance of SPEC §2: an interior edge is Delaunay when the
/// two angles opposite it sum to at most π + 1e-9 rad.
pub const ACCEPT_TOLERANCE: f64 = 1e-9;

/// The tolerance the algorithm acts on: edges whose opposite angles exceed π
/// by more than this are flipped or split. Tighter than [`ACCEPT_TOLERANCE`]
/// so that every output is accepted, loose enough that exactly cocircular
/// configurations (regular grids, whose angle sums are π up to rounding) are
/// left alone instead of being split forever.
pub const ALGORITHM_TOLERANCE: f64 = 1e-10;

/// The angle at `c` in triangle (a, b, c), i.e. between `a - c` and `b - c`,
/// in [0, π]. Accurate for needle triangles too (atan2 of cross and dot).
pub fn corner_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let u = a - c;
    let v = b - c;
    u.cross(v).length().atan2(u.dot(v))
}

/// `(sin, cos)` of α + β − π, both scaled by the same positive factor, for
/// the angles α = ∠acb and β = ∠adb opposite the edge (a, b).
///
/// With sᵢ = |uᵢ × vᵢ| and cᵢ = uᵢ · vᵢ (|uᵢ||vᵢ| times the sine and cosine of
/// each angle), sin(α + β − π) ∝ −(s₁c₂ + c₁s₂) and cos(α + β − π) ∝
/// s₁s₂ − c₁c₂. The common factor |u₁||v₁||u₂||v₂| cancels in every use, so
/// no normalisation is needed, and the pair is accurate near α + β = π, where
/// the decision is made.
#[inline]
pub fn excess_sin_cos(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> (f64, f64) {
    // Scaled by 1/|ab|: products of four coordinates neither overflow nor
    // underflow, whatever the mesh's scale.
    let k = 1.0 / (b - a).length();
    let (u1, v1) = ((a - c) * k, (b - c) * k);
    let (u2, v2) = ((a - d) * k, (b - d) * k);
    let (s1, c1) = (u1.cross(v1).length(), u1.dot(v1));
    let (s2, c2) = (u2.cross(v2).length(), u2.dot(v2));
    (-(s1 * c2 + c1 * s2), s1 * s2 - c1 * c2)
}

/// How far the edge (a, b) with opposite vertices `c` and `d` is from being
/// Delaunay: α + β − π in radians, in (−π, π) (negative when Delaunay).
pub fn delaunay_excess(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let (y, x) = excess_sin_cos(a, b, c, d);
    y.atan2(x)
}

/// Whether `(y, x)` from [`excess_sin_cos`] means α + β − π > `tolerance`
/// (0 ≤ `tolerance` < π/2), without computing the angle.
#[inline]
pub fn exceeds(y: f64, x: f64, tolerance: f64) -> bool {
    y > 0.0 && (x <= 0.0 || y > x * tolerance.tan())
}

/// Whether the edge (a, b) with opposite vertices `c`, `d` violates the
/// Delaunay condition by more than `tolerance` radians.
///
/// Two non-obtuse opposite angles (both dot products ≥ 0) sum to at most π:
/// that common case is decided without a square root.
#[inline]
pub fn is_non_delaunay(a: DVec3, b: DVec3, c: DVec3, d: DVec3, tolerance: f64) -> bool {
    let (u1, v1) = (a - c, b - c);
    let (u2, v2) = (a - d, b - d);
    let (c1, c2) = (u1.dot(v1), u2.dot(v2));
    if c1 >= 0.0 && c2 >= 0.0 {
        return false;
    }
    let (y, x) = excess_sin_cos(a, b, c, d);
    exceeds(y, x, tolerance)
}

/// Positions of a triangle pair unfolded into the plane of the edge (a, b):
/// `a` at the origin, `b` on the positive x axis at distance |b − a|.
///
/// Maps a point `q` of the triangle on the upper side (y > 0) or lower side.
#[derive(Clone, Copy, Debug)]
pub struct EdgeFrame {
    origin: DVec3,
    axis: DVec3,
    /// |b − a|.
    pub length: f64,
}

impl EdgeFrame {
    /// The frame of the edge from `a` to `b`.
    pub fn new(a: DVec3, b: DVec3) -> Self {
        let d = b - a;
        let length = d.length();
        EdgeFrame {
            origin: a,
            axis: d / length,
            length,
        }
    }

    /// Unfolds `q` (a vertex of a triangle on the edge) to the upper (`up =
    /// true`) or lower half plane, keeping its distances to a and b.
    pub fn unfold(&self, q: DVec3, up: bool) -> DVec2 {
        let r = q - self.origin;
        let x = r.dot(self.axis);
        let y = r.cross(self.axis).length();
        DVec2::new(x, if up { y } else { -y })
    }
}

/// Unfolds the apex `x3` of the triangle beyond the 2D edge (p2, q2), where
/// `p3`, `q3` are the 3D positions of that edge: the result keeps the 3D
/// distances to p and q and lies on the opposite side of the line p2q2 from
/// `inside` (a 2D point on this side).
pub fn unfold_across(p3: DVec3, q3: DVec3, x3: DVec3, p2: DVec2, q2: DVec2, inside: DVec2) -> DVec2 {
    let frame = EdgeFrame::new(p3, q3);
    let local = frame.unfold(x3, true);
    let dir = (q2 - p2) / (q2 - p2).length();
    let mut perp = DVec2::new(-dir.y, dir.x);
    if perp.dot(inside - p2) > 0.0 {
        perp = -perp;
    }
    p2 + dir * local.x + perp * local.y
}

/// The circle through the point `(anchor, 0)` of the x axis and the 2D
/// points `p` and `q` meets the x axis a second time: returns that x.
///
/// Infinite or NaN when the three points are collinear (no finite circle);
/// callers treat such a value as "no breakpoint".
pub fn second_axis_crossing(anchor: f64, p: DVec2, q: DVec2) -> f64 {
    // Translate the anchor to the origin: a circle through the origin is
    // x² + y² − 2 ox x − 2 oy y = 0, which meets y = 0 again at x = 2 ox.
    let p = DVec2::new(p.x - anchor, p.y);
    let q = DVec2::new(q.x - anchor, q.y);
    let d = 2.0 * (p.x * q.y - p.y * q.x);
    let ox = (q.y * p.length_squared() - p.y * q.length_squared()) / d;
    anchor + 2.0 * ox
}

/// Exact test: are the points collinear (the triangle has zero area)?
pub fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let o = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        robust::orient2d(
            robust::Coord { x: a[0], y: a[1] },
            robust::Coord { x: b[0], y: b[1] },
            robust::Coord { x: c[0], y: c[1] },
        )
    };
    o([a.x, a.y], [b.x, b.y], [c.x, c.y]) == 0.0
        && o([a.y, a.z], [b.y, b.z], [c.y, c.z]) == 0.0
        && o([a.z, a.x], [b.z, b.x], [c.z, c.x]) == 0.0
}

/// Exact test: do the triangles (a, b, c) and (b, a, d), which share the edge
/// (a, b), lie in one plane and on opposite sides of the edge (a flat, not
/// folded, pair)? Both triangles must be non-degenerate.
pub fn flat_pair(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    let c3 = |p: DVec3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
    if robust::orient3d(c3(a), c3(b), c3(c), c3(d)) != 0.0 {
        return false;
    }
    // Coplanar: project on a coordinate plane where (a, b, c) does not
    // degenerate; sides of the line ab are preserved by that projection.
    let projections: [fn(DVec3) -> robust::Coord<f64>; 3] = [
        |p| robust::Coord { x: p.x, y: p.y },
        |p| robust::Coord { x: p.y, y: p.z },
        |p| robust::Coord { x: p.z, y: p.x },
    ];
    for proj in projections {
        let sc = robust::orient2d(proj(a), proj(b), proj(c));
        if sc != 0.0 {
            let sd = robust::orient2d(proj(a), proj(b), proj(d));
            return sc * sd < 0.0;
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn corner_angle_of_right_triangle() {
        let a = DVec3::new(1.0, 0.0, 0.0);
        let b = DVec3::new(0.0, 1.0, 0.0);
        assert!((corner_angle(a, b, DVec3::ZERO) - PI / 2.0).abs() < 1e-15);
        assert!((corner_angle(DVec3::ZERO, b, a) - PI / 4.0).abs() < 1e-15);
    }

    #[test]
    fn delaunay_test_on_square_and_rhombus() {
        // A square: α + β = π exactly (cocircular), Delaunay.
        let a = DVec3::new(0.0, 0.0, 0.0);
        let b = DVec3::new(1.0, 1.0, 0.0);
        let c = DVec3::new(0.0, 1.0, 0.0);
        let d = DVec3::new(1.0, 0.0, 0.0);
        assert!(delaunay_excess(a, b, c, d).abs() < 1e-15);
        assert!(!is_non_delaunay(a, b, c, d, ALGORITHM_TOLERANCE));
        // A flat rhombus along its long diagonal: non-Delaunay.
        let (a, b) = (DVec3::new(-2.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 0.0));
        let (c, d) = (DVec3::new(0.0, 0.5, 0.0), DVec3::new(0.0, -0.5, 0.0));
        assert!(delaunay_excess(a, b, c, d) > 1.0);
        assert!(is_non_delaunay(a, b, c, d, ALGORITHM_TOLERANCE));
        // ... and along its short one: Delaunay.
        assert!(!is_non_delaunay(c, d, b, a, ALGORITHM_TOLERANCE));
        // Folding the rhombus out of plane does not change the intrinsic test.
        let d3 = DVec3::new(0.0, -0.3, 0.4);
        assert_eq!(
            is_non_delaunay(a, b, c, d3, ALGORITHM_TOLERANCE),
            delaunay_excess(a, b, c, d3) > 0.0
        );
    }

    #[test]
    fn excess_agrees_with_angle_sums_everywhere() {
        // Random quads, including nearly flat triangles whose opposite angles
        // approach π (so that α + β approaches 2π).
        let mut seed = 12345u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for i in 0..20000 {
            let a = DVec3::new(-1.0, 0.0, 0.0);
            let b = DVec3::new(1.0, 0.0, 0.0);
            let h = if i % 3 == 0 { 1e-6 } else { 1.0 };
            let c = DVec3::new(rnd() * 3.0, h * (rnd() + 0.5).abs() + 1e-9, rnd() * h);
            let d = DVec3::new(rnd() * 3.0, -h * (rnd() + 0.5).abs() - 1e-9, rnd() * h);
            let sum = corner_angle(a, b, c) + corner_angle(a, b, d) - PI;
            let excess = delaunay_excess(a, b, c, d);
            assert!((sum - excess).abs() < 1e-9, "{sum} vs {excess}");
            if (sum - 1e-3).abs() > 1e-9 {
                assert_eq!(is_non_delaunay(a, b, c, d, 1e-3), sum > 1e-3);
            }
        }
        // Two needles whose angles opposite the edge are both nearly π.
        let (a, b) = (DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0));
        let (c, d) = (DVec3::new(0.0, 1e-12, 0.0), DVec3::new(0.1, -1e-12, 0.0));
        assert!(is_non_delaunay(a, b, c, d, ALGORITHM_TOLERANCE));
        assert!(delaunay_excess(a, b, c, d) > 3.0);
    }

    #[test]
    fn tolerance_is_respected_near_pi() {
        // Four points near a circle, perturbed by tiny amounts.
        for i in 0..200 {
            let e = (i as f64 - 100.0) * 1e-11;
            let a = DVec3::new(-1.0, 0.0, 0.0);
            let b = DVec3::new(1.0, 0.0, 0.0);
            let c = DVec3::new(0.0, 1.0 + e, 0.0);
            let d = DVec3::new(0.6, -0.8, 0.0);
            let excess = corner_angle(a, b, c) + corner_angle(a, b, d) - PI;
            if (excess - ALGORITHM_TOLERANCE).abs() > 1e-14 {
                assert_eq!(
                    is_non_delaunay(a, b, c, d, ALGORITHM_TOLERANCE),
                    excess > ALGORITHM_TOLERANCE,
                    "e = {e}"
                );
            }
        }
    }

    #[test]
    fn unfolding_keeps_lengths() {
        let a = DVec3::new(0.1, 0.2, 0.3);
        let b = DVec3::new(1.5, -0.2, 0.7);
        let c = DVec3::new(0.4, 1.2, -0.3);
        let d = DVec3::new(0.9, -1.0, 0.2);
        let f = EdgeFrame::new(a, b);
        let (c2, d2) = (f.unfold(c, true), f.unfold(d, false));
        let b2 = DVec2::new(f.length, 0.0);
        assert!((c2.length() - (c - a).length()).abs() < 1e-14);
        assert!(((c2 - b2).length() - (c - b).length()).abs() < 1e-14);
        assert!((d2.length() - (d - a).length()).abs() < 1e-14);
        assert!(((d2 - b2).length() - (d - b).length()).abs() < 1e-14);
        assert!(c2.y > 0.0 && d2.y < 0.0);
        // The apex beyond (a, c), unfolded away from b.
        let x = DVec3::new(-0.8, 0.9, 0.5);
        let x2 = unfold_across(a, c, x, DVec2::ZERO, c2, b2);
        assert!((x2.length() - (x - a).length()).abs() < 1e-13);
        assert!(((x2 - c2).length() - (x - c).length()).abs() < 1e-13);
        let side = |p: DVec2| c2.perp_dot(p);
        assert!(side(x2) * side(b2) < 0.0);
    }

    #[test]
    fn circle_crossings() {
        // Unit circle through (-1, 0), (0, 1), (0, -1): meets the axis at 1.
        let x = second_axis_crossing(-1.0, DVec2::new(0.0, 1.0), DVec2::new(0.0, -1.0));
        assert!((x - 1.0).abs() < 1e-15);
        // Circle centred (2, 3) through the origin: second crossing at 4.
        let r = 13f64.sqrt();
        let p = DVec2::new(2.0 + r, 3.0);
        let q = DVec2::new(2.0, 3.0 - r);
        assert!((second_axis_crossing(0.0, p, q) - 4.0).abs() < 1e-12);
        assert!(!second_axis_crossing(0.0, DVec2::new(1.0, 1.0), DVec2::new(2.0, 2.0)).is_finite());
    }

    #[test]
    fn exact_predicates() {
        let a = DVec3::new(0.0, 0.0, 0.0);
        let b = DVec3::new(1.0, 1.0, 1.0);
        assert!(collinear(a, b, DVec3::new(0.5, 0.5, 0.5)));
        assert!(!collinear(a, b, DVec3::new(0.5, 0.5, 0.5000000000000001)));
        let c = DVec3::new(1.0, 0.0, 0.0);
        let d_flat = DVec3::new(0.0, 1.0, 0.0);
        let (a, b) = (DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0));
        assert!(flat_pair(a, b, c, d_flat));
        // Folded back onto itself: coplanar but same side.
        assert!(!flat_pair(a, b, c, DVec3::new(2.0, 0.0, 0.0)));
        // Out of plane.
        assert!(!flat_pair(a, b, c, DVec3::new(0.0, 1.0, 1e-300)));
    }
}
