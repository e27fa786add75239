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
pub const MAX_APEXES: usize = 16;

/// Below this, a triangle's turn (the sine of its angle at the apex times the
/// cosine of its tilt from the polygon's normal) counts as no turn: its
/// corners are collinear up to rounding.
pub const MIN_TURN: f64 = 1e-12;

/// The fan of a polygon: where it starts, and whether it draws the polygon.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fan {
    /// The corner the fan starts at: its triangles are `(k, k+i, k+i+1)`,
    /// indices modulo the corner count, for `i` in `1..n-1`.
    pub apex: usize,
    /// Whether every triangle turns the polygon's way ([`fan`]); `false`
    /// for a polygon that no corner sees whole, whose fan (from its first
    /// corner) then overlaps itself.
    pub proper: bool,
}

/// The fan of the polygon with `n` corners: from the first corner `k` from
/// which every triangle turns the way of the polygon's normal (Newell's) by
/// more than [`MIN_TURN`]; from corner 0 for a triangle, for every convex
/// polygon, and (not proper) when no corner of the first [`MAX_APEXES`]
/// does. Allocates nothing: `corner` is called again as needed.
pub fn fan(n: usize, corner: impl Fn(usize) -> [f64; 3]) -> Fan {
    if n <= 3 {
        return Fan { apex: 0, proper: true };
    }
    let normal = newell_normal(n, &corner);
    let normal = scale(normal, 1.0 / length(normal));
    let turns_from = |k: usize| {
        let a = corner(k);
        (1..n - 1).all(|i| {
            let (u, v) = (sub(corner((k + i) % n), a), sub(corner((k + i + 1) % n), a));
            dot(cross(u, v), normal) > MIN_TURN * (dot(u, u) * dot(v, v)).sqrt()
        })
    };
    match (0..n.min(MAX_APEXES)).find(|&k| turns_from(k)) {
        Some(apex) => Fan { apex, proper: true },
        None => Fan { apex: 0, proper: false },
    }
}

/// [`fan`]'s apex alone.
pub fn fan_apex(n: usize, corner: impl Fn(usize) -> [f64; 3]) -> usize {
    fan(n, corner).apex
}

/// Newell's normal of a polygon: twice its vector area, whatever its shape
/// (exact for a planar polygon, a mean plane's normal for a warped one).
/// Corners are taken relative to the first, which keeps the sums small.
fn newell_normal(n: usize, corner: &impl Fn(usize) -> [f64; 3]) -> [f64; 3] {
    let o = corner(0);
    let mut sum = [0.0; 3];
    let mut a = [0.0; 3];
    for i in 1..=n {
        let b = if i == n { [0.0; 3] } else { sub(corner(i), o) };
        let c = cross(a, b);
        sum = [sum[0] + c[0], sum[1] + c[1], sum[2] + c[2]];
        a = b;
    }
    sum
}

fn scale(a: [f64; 3], k: f64) -> [f64; 3] {
    [a[0] * k, a[1] * k, a[2] * k]
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
        assert!(fan(4, |i| warped[i]).proper);
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
        assert!(fan(6, |i| l[i]).proper);
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
        assert!(!fan(p.len(), |i| p[i]).proper);
        // Non-finite corners: the first corner (the reader refuses them).
        let bad = [[0.0, 0.0, 0.0], [f64::NAN, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(apex(&bad), 0);
    }
}
