//! How a polygon of a file becomes triangles: a fan from one of its corners.
//!
//! A fan from the first corner draws a convex polygon exactly, but not a
//! non-convex one (some of its triangles then turn the other way, outside the
//! outline, overlapping the others), nor a polygon with three corners on a
//! straight stretch of its outline (a T-junction, common in CAD exports: the
//! fan's triangle along that stretch has zero area). So the fan starts at the
//! first corner from which every triangle clearly turns the polygon's way
//! ([`fan_apex`]): the first corner for every convex polygon, and a corner
//! that sees the whole outline for a star-shaped one.
//!
//! This is part of what a file *means*: the construction's readers and the
//! judge (`delmesh check`) both triangulate with [`fan_apex`], so that they
//! read the same surface from the same file.
//!
//! ```text
//!   5-------4            5-------4
//!   |       |            | `.  .'|     the L from corner 0: its triangle
//!   |   2---3            |   2---3     0-2-3 turns the wrong way (outside
//!   |   |                |  /|         the L); from corner 2 every
//!   0---1                0---1         triangle lies inside it
//! ```

/// How many corners are tried as the fan's apex, at most: a large polygon
/// that no early corner sees whole is not star-shaped from any of them in
/// practice, and each try costs a pass over the polygon.
const MAX_APEXES: usize = 16;

/// Below this, a triangle's turn (the sine of its angle at the apex times the
/// cosine of its tilt from the polygon's normal) counts as no turn: its
/// corners are collinear up to rounding.
const MIN_TURN: f64 = 1e-12;

/// The corner of the polygon with `n` corners at which its fan starts (the
/// triangles `(k, k+i, k+i+1)`, indices modulo `n`, for `i` in `1..n-1`):
/// the first `k` from which every triangle turns the way of the polygon's
/// normal (Newell's) by more than [`MIN_TURN`]. 0 for a triangle, for every
/// convex polygon, and when no corner (of the first [`MAX_APEXES`]) does.
pub fn fan_apex(n: usize, corner: impl Fn(usize) -> [f64; 3]) -> usize {
    if n <= 3 {
        return 0;
    }
    let p: Vec<[f64; 3]> = (0..n).map(&corner).collect();
    let normal = newell_normal(&p);
    let normal_length = length(normal);
    (0..n.min(MAX_APEXES))
        .find(|&k| {
            (1..n - 1).all(|i| {
                let (a, b, c) = (p[k], p[(k + i) % n], p[(k + i + 1) % n]);
                let (u, v) = (sub(b, a), sub(c, a));
                dot(cross(u, v), normal) > MIN_TURN * length(u) * length(v) * normal_length
            })
        })
        .unwrap_or(0)
}

/// Whether the fan from [`fan_apex`] draws the polygon: every triangle
/// turns its way. `false` for a polygon no corner sees whole (its fan from
/// the first corner then overlaps itself).
pub fn fan_is_proper(n: usize, corner: impl Fn(usize) -> [f64; 3]) -> bool {
    if n <= 3 {
        return true;
    }
    let p: Vec<[f64; 3]> = (0..n).map(&corner).collect();
    let k = fan_apex(n, |i| p[i]);
    let normal = newell_normal(&p);
    let normal_length = length(normal);
    (1..n - 1).all(|i| {
        let (a, b, c) = (p[k], p[(k + i) % n], p[(k + i + 1) % n]);
        let (u, v) = (sub(b, a), sub(c, a));
        dot(cross(u, v), normal) > MIN_TURN * length(u) * length(v) * normal_length
    })
}

/// Newell's normal of a polygon: twice its vector area, whatever its shape
/// (exact for a planar polygon, a mean plane's normal for a warped one).
/// Corners are taken relative to the first, which keeps the sums small.
fn newell_normal(p: &[[f64; 3]]) -> [f64; 3] {
    let o = p[0];
    let mut n = [0.0; 3];
    for i in 0..p.len() {
        let (a, b) = (sub(p[i], o), sub(p[(i + 1) % p.len()], o));
        let c = cross(a, b);
        n = [n[0] + c[0], n[1] + c[1], n[2] + c[2]];
    }
    n
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn length(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn apex(p: &[[f64; 3]]) -> usize {
        fan_apex(p.len(), |i| p[i])
    }

    #[test]
    fn convex_polygons_start_at_their_first_corner() {
        let square = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(apex(&square), 0);
        let hexagon: Vec<[f64; 3]> = (0..6)
            .map(|i| {
                let a = i as f64 * std::f64::consts::PI / 3.0;
                [a.cos(), a.sin(), 0.5]
            })
            .collect();
        assert_eq!(apex(&hexagon), 0);
        // A warped quad (not planar) whose fan from 0 turns its way.
        let warped = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.1], [1.0, 1.0, 0.0], [0.0, 1.0, 0.1]];
        assert_eq!(apex(&warped), 0);
        assert!(fan_is_proper(4, |i| warped[i]));
    }

    #[test]
    fn an_l_starts_at_its_reflex_corner() {
        // The L of the module's sketch: corner 2 is the reflex one, and
        // neither 0 nor 1 sees the whole outline.
        let l = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 1.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
        ];
        assert_eq!(apex(&l), 2);
        assert!(fan_is_proper(6, |i| l[i]));
    }

    #[test]
    fn corners_on_a_straight_stretch_are_not_the_apex() {
        // A rectangle with a corner in the middle of its bottom side: the
        // fan from 0 would make the triangle 0-1-2 of zero area.
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        assert_eq!(apex(&p), 1);
        // Also with coordinates whose collinearity is only up to rounding.
        let q = [[0.1, 0.1, 0.0], [0.2, 0.2, 0.0], [0.3, 0.3, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(apex(&q), 1);
    }

    #[test]
    fn a_polygon_no_corner_sees_whole_keeps_its_first_corner() {
        // A comb: two notches, no corner sees all of it.
        let p = [
            [0.0, 0.0, 0.0],
            [5.0, 0.0, 0.0],
            [5.0, 3.0, 0.0],
            [4.0, 3.0, 0.0],
            [4.0, 1.0, 0.0],
            [3.0, 1.0, 0.0],
            [3.0, 3.0, 0.0],
            [2.0, 3.0, 0.0],
            [2.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 3.0, 0.0],
            [0.0, 3.0, 0.0],
        ];
        assert_eq!(apex(&p), 0);
        assert!(!fan_is_proper(p.len(), |i| p[i]));
        // Non-finite corners: the first corner (the reader refuses them).
        let bad = [[0.0, 0.0, 0.0], [f64::NAN, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(apex(&bad), 0);
    }
}
