//! Rule 6: every interior output edge Delaunay, `alpha + beta <= pi + DELAUNAY_TOLERANCE`.

use super::*;

/// Result of the Delaunay check.
pub(super) struct DelaunayStats {
    pub(super) interior: usize,
    pub(super) max_excess: f64,
    /// The non-Delaunay edges `(excess, lo, hi)`, worst first.
    pub(super) bad: Vec<(f64, u32, u32)>,
    /// Boundary edges (one face).
    pub(super) boundary: usize,
    /// `max(gamma - pi/2)` over them, gamma the angle opposite in the one face.
    pub(super) max_boundary_excess: f64,
    /// Those facing an obtuse angle, `gamma > pi/2 + DELAUNAY_TOLERANCE`: `(gamma - pi/2, lo,
    /// hi)`, worst first. Not failures unless asked for
    /// ([`CheckReport::require_gabriel_boundary`]).
    pub(super) bad_boundary: Vec<(f64, u32, u32)>,
    /// The interior edges (indices into the edges given) whose two faces lie exactly folded
    /// onto each other ([`folded`]), for [`check_folds`].
    pub(super) folds: Vec<u32>,
}

impl DelaunayStats {
    /// Records the non-Delaunay edges as failures, worst first, named by `output`.
    pub(super) fn report(&self, output: &Names, fail: &mut Failures) {
        for &(x, lo, hi) in &self.bad {
            fail.push(KIND_DELAUNAY, || {
                format!(
                    "non-Delaunay edge ({}, {}): alpha+beta-pi = {x:.3e} rad",
                    output.label(lo),
                    output.label(hi)
                )
            });
        }
    }
}

impl DelaunayStats {
    /// The lines naming the boundary edges that face an obtuse angle, worst first (at most
    /// [`MAX_LINES_PER_KIND`], then a count of the rest).
    pub(super) fn boundary_lines(&self, output: &Names) -> Vec<String> {
        let shown = self.bad_boundary.iter().take(MAX_LINES_PER_KIND).map(|&(x, lo, hi)| {
            format!(
                "boundary edge ({}, {}) faces an obtuse angle: gamma-pi/2 = {x:.3e} rad (its cotangent weight is negative)",
                output.label(lo),
                output.label(hi)
            )
        });
        let more = self.bad_boundary.len().saturating_sub(MAX_LINES_PER_KIND);
        shown
            .chain((more > 0).then(|| format!("... and {more} more boundary edges facing an obtuse angle")))
            .collect()
    }
}

/// The angle between two vectors, in `[0, pi]`. Each vector is first scaled by a power of two
/// that brings its largest coordinate to about `[1, 2)` ([`power_of_two_scaled`]): the directions are
/// unchanged, exactly, and for vectors of ordinary length so is every rounding (the result is
/// what the unscaled formula gives), but the products no longer underflow at needles: a right
/// angle at a face 1e-323 wide, whose unscaled cross product has length 0 and dot product -0,
/// was taken for pi.
pub(super) fn angle(u: DVec3, v: DVec3) -> f64 {
    let (u, v) = (power_of_two_scaled(u), power_of_two_scaled(v));
    u.cross(v).length().atan2(u.dot(v))
}

/// `v` times the power of two that brings its largest coordinate magnitude to about `[1, 2)`
/// (exact: only exponents change); `v` itself when it is zero or not finite.
fn power_of_two_scaled(v: DVec3) -> DVec3 {
    let largest = v.abs().max_element();
    if largest == 0.0 || !largest.is_finite() {
        return v;
    }
    // As in `rescaled`: 2^k in two factors, each a normal number.
    let k = -(largest.log2().floor() as i32); // within -1023 ..= 1074
    v * 2f64.powi(k / 2) * 2f64.powi(k - k / 2)
}

/// `alpha + beta - pi` of interior edge `(a, b)` with faces `(a, b, c)` and `(b, a, d)`.
pub(super) fn excess(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    angle(a - c, b - c) + angle(a - d, b - d) - PI
}

/// Rule 6 on every interior output edge (see [`DelaunayStats::report`]).
///
/// [`excess`] (two `atan2`) is computed only for the edges that [`ExcessBound`] cannot place
/// below the largest excess found so far: the others change neither the maximum nor the list
/// of non-Delaunay edges, so the result is the same as computing every edge's.
pub(super) fn delaunay_edges(output: &Mesh3, edges: &[Edge]) -> DelaunayStats {
    let p = |v: u32| output.positions[v as usize];
    let mut stats = DelaunayStats {
        interior: 0,
        max_excess: f64::NEG_INFINITY,
        bad: Vec::new(),
        boundary: 0,
        max_boundary_excess: f64::NEG_INFINITY,
        bad_boundary: Vec::new(),
        folds: Vec::new(),
    };
    // Boundary edges: the one angle opposite each, against a right angle (few edges: no bound
    // needed).
    for e in edges.iter().filter(|e| e.count == 1) {
        let c = third(&output.triangles[e.faces[0] as usize], e.lo, e.hi);
        let (a, b, c) = (p(e.lo), p(e.hi), p(c));
        let x = angle(a - c, b - c) - FRAC_PI_2;
        stats.boundary += 1;
        stats.max_boundary_excess = stats.max_boundary_excess.max(x);
        let gabriel = x <= DELAUNAY_TOLERANCE; // false for NaN too
        if !gabriel {
            stats.bad_boundary.push((x, e.lo, e.hi));
        }
    }
    stats.bad_boundary.sort_by(|x, y| y.0.total_cmp(&x.0));
    let mut bound = ExcessBound::below(stats.max_excess);
    for (i, e) in edges.iter().enumerate().filter(|(_, e)| e.is_interior()) {
        let (a, b, f, g) = e.oriented();
        let c = third(&output.triangles[f as usize], a, b);
        let d = third(&output.triangles[g as usize], a, b);
        stats.interior += 1;
        let quad = [p(a), p(b), p(c), p(d)];
        // (Rule 3's folds, found here where the quad is at hand.)
        if folded(quad) {
            stats.folds.push(i as u32);
        }
        if bound.holds(quad) {
            continue;
        }
        let [a, b, c, d] = quad;
        let x = excess(a, b, c, d);
        if x > stats.max_excess {
            bound = ExcessBound::below(x);
        }
        stats.max_excess = stats.max_excess.max(x);
        let delaunay = x <= DELAUNAY_TOLERANCE; // false for NaN too
        if !delaunay {
            stats.bad.push((x, e.lo, e.hi));
        }
    }
    stats.bad.sort_by(|x, y| y.0.total_cmp(&x.0));
    stats
}

/// A cheap test, without `atan2`, that an interior edge's [`excess`] is certainly below a
/// threshold `t` (the largest excess found so far) and not above [`DELAUNAY_TOLERANCE`]: that
/// `alpha + beta <= pi - m` with `m = max(-t, 0) + 1e-12`, where `excess` is within `1e-14` of
/// the exact `alpha + beta - pi` of its (rounded) edge vectors.
///
/// With `C = |u x v|` and `D = u . v` for the two vectors `u, v` of a face from its third
/// corner, `D + iC` is `|u| |v| e^(i alpha)`, so the product `R + iS` of the two faces' is
/// `|u1| |v1| |u2| |v2| e^(i (alpha + beta))`. For `alpha + beta` in `[0, 2 pi]`, `S > 0` puts it
/// in `(0, pi)`, and then `alpha + beta <= pi - m` iff `S + R tan(m) >= 0`. Both are required to
/// exceed their rounding error with a wide margin: `C` and `D` are within about 8 units of
/// roundoff of `|u| |v| <= |C| + |D|`, so `R` and `S` within 40 units of the product of those
/// sums, and the margin is 10^-12 of it (4,500 units). Vectors whose largest coordinate is 0 or
/// outside `[2^-200, 2^200]` (where products could underflow or overflow) are left to `excess`.
#[derive(Clone, Copy)]
pub(super) struct ExcessBound {
    /// `tan(m)`, or `None` when no edge is to be skipped (no threshold yet, or one so low that
    /// `m` nears `pi / 2`).
    tan_margin: Option<f64>,
}

impl ExcessBound {
    /// The bound for threshold `t` (`f64::NEG_INFINITY`: none).
    pub(super) fn below(t: f64) -> ExcessBound {
        let margin = t.min(0.0).abs() + 1e-12;
        ExcessBound {
            tan_margin: (margin < 1.4).then(|| margin.tan()),
        }
    }

    /// Whether the excess of the edge `(a, b)` with faces `(a, b, c)` and `(b, a, d)` is
    /// certainly below the threshold (`false` when unsure).
    pub(super) fn holds(&self, [a, b, c, d]: [DVec3; 4]) -> bool {
        let Some(k) = self.tan_margin else {
            return false;
        };
        let (u1, v1, u2, v2) = (a - c, b - c, a - d, b - d);
        const LOW: f64 = 6.223015277861142e-61; // 2^-200
        const HIGH: f64 = 1.6069380442589903e60; // 2^200
        let plain = |w: DVec3| (LOW..=HIGH).contains(&w.abs().max_element());
        if !(plain(u1) && plain(v1) && plain(u2) && plain(v2)) {
            return false;
        }
        let (c1, d1) = (u1.cross(v1).length(), u1.dot(v1));
        let (c2, d2) = (u2.cross(v2).length(), u2.dot(v2));
        let (r, s) = (d1 * d2 - c1 * c2, c1 * d2 + d1 * c2);
        let error = 1e-12 * (c1 + d1.abs()) * (c2 + d2.abs());
        s > error && s + k * r > error * (1.0 + k)
    }
}
