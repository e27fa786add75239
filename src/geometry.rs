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

/// The tolerance of the algorithm's first pass: it queues the input's edges
/// whose opposite angles exceed π by more than this. An input edge within
/// it, whose quad no flip or split changes, is written as it was read, and
/// is accepted ([`ACCEPT_TOLERANCE`], with room for another computation's
/// rounding); an edge whose quad changes is held to [`ALGORITHM_TOLERANCE`].
/// (With the first pass at [`ALGORITHM_TOLERANCE`], an input that already
/// passes `delmesh check` was refined all the same: one vertex on two
/// triangles 4e-10 rad over π, 595,183 on a terrain of 1e-4 rad angles.)
pub const SEED_TOLERANCE: f64 = 5e-10;
const _: () = assert!(ALGORITHM_TOLERANCE <= SEED_TOLERANCE && SEED_TOLERANCE < ACCEPT_TOLERANCE);

/// The e with 2^e ≤ `x` < 2^(e + 1), for a positive normal `x`: read from
/// its bits, exactly (no `log2`, whose last bit differs between C libraries).
pub fn binary_exponent(x: f64) -> i32 {
    ((x.to_bits() >> 52) & 0x7ff) as i32 - 1023
}

/// sin(atan2(`y`, `x`)) = y / √(x² + y²) for `y` ≥ 0, correctly rounded
/// (but in cases within about 2⁻¹⁰⁰ of halfway between two doubles), and so
/// the same on every platform: `sin` and `atan2` are not correctly rounded,
/// and their last bit differs between C libraries (glibc's `sin(atan2(y,
/// x))` is one unit in the last place off in about a quarter of cases, and
/// musl's differently). The sample constants derive from it, so every build
/// places the same samples.
///
/// Both are scaled by a power of two (exactly), then x² + y², its square
/// root and the quotient are carried in double-double arithmetic (a pair
/// `hi + lo` of doubles; products' rounding errors by [`two_product`], exact
/// on every platform without a fused multiply-add).
pub fn sine_of_direction(y: f64, x: f64) -> f64 {
    let m = y.max(x.abs());
    if m == 0.0 || !m.is_finite() {
        // No direction (0, 0), or infinite or NaN parts: as the libm would.
        return y.atan2(x).sin();
    }
    // The largest part scaled into [1, 2), by powers of two (exact; a part
    // far smaller may lose bits to underflow, below what affects the
    // result). Subnormal parts are first scaled up.
    let (mut y, mut x, mut m) = (y, x, m);
    if m < f64::MIN_POSITIVE {
        let up = f64::from_bits((1023 + 600) << 52); // 2^600
        (y, x, m) = (y * up, x * up, m * up);
    }
    let e = binary_exponent(m);
    let half = |k: i32| f64::from_bits(((1023 - k) as u64) << 52); // 2^-k, |k| ≤ 600
    let (a, b) = (e / 2, e - e / 2);
    let (y, x) = (y * half(a) * half(b), x * half(a) * half(b));
    // q = x² + y², as qh + ql.
    let two_sum = |a: f64, b: f64| {
        let s = a + b;
        let bb = s - a;
        (s, (a - (s - bb)) + (b - bb))
    };
    let ((xx, xe), (yy, ye)) = (two_product(x, x), two_product(y, y));
    let (sh, sl) = two_sum(xx, yy);
    let (qh, ql) = two_sum(sh, sl + xe + ye);
    // r = √q, as rh + rl: one Newton step from the double square root.
    let r = qh.sqrt();
    let (rr, rre) = two_product(r, r);
    let (rh, rl) = two_sum(r, ((qh - rr) - rre + ql) / (2.0 * r));
    // y / r: the quotient and its remainder. The remainder of a correctly
    // rounded quotient is a double, so y − p (Sterbenz: p ≈ y) and then
    // − pe are exact.
    let th = y / rh;
    let (p, pe) = two_product(th, rh);
    let rest = ((y - p) - pe) - th * rl;
    th + rest / rh
}

/// `(a·b, e)` with a·b = p + e exactly (Dekker's product, Veltkamp's
/// split), where no part overflows and the error is not below the
/// smallest normal double. The same as `(p, a.mul_add(b, -p))`, but
/// `mul_add` without the `fma` target feature calls a library function
/// that asks the processor its features once per process (`cpuid`,
/// which traps to the hypervisor on virtual machines: 0.1 ms a run).
#[inline]
pub fn two_product(a: f64, b: f64) -> (f64, f64) {
    let split = |v: f64| {
        let c = 134_217_729.0 * v; // 2^27 + 1
        let hi = c - (c - v);
        (hi, v - hi)
    };
    let p = a * b;
    let ((ah, al), (bh, bl)) = (split(a), split(b));
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

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
    let vectors = [a - c, b - c, a - d, b - d];
    // Scaled by 1/|ab|: products of four coordinates neither overflow nor
    // underflow, whatever the mesh's scale, but where an apex lies a
    // subnormal fraction of |ab| from an end (its sine and cosine
    // underflow), or 1e308 times |ab| away (they overflow).
    let k = 1.0 / (b - a).length();
    let (y, x) = excess_from_vectors(vectors.map(|v| v * k));
    if clear_of_underflow(y, x) {
        return (y, x);
    }
    rescaled_excess_sin_cos(vectors)
}

/// Whether a sine and cosine computed from vectors scaled by 1/|ab| are
/// clear of underflow (above [`TINY_PRODUCT`]) and finite.
#[inline(always)]
fn clear_of_underflow(y: f64, x: f64) -> bool {
    (y.abs().max(x.abs()) > TINY_PRODUCT) & (y + x).is_finite()
}

/// [`excess_sin_cos`] from the vectors `a − c`, `b − c`, `a − d`, `b − d`,
/// each first multiplied by the power of two that brings its largest
/// coordinate into [1, 2): exact, and each angle's sine and cosine are then
/// its true ones times |u||v| ≥ 1 up to about 1e-15, where nothing can
/// underflow but a sine below 1e-154 (an angle within 1e-154 of 0 or π).
/// Both angles' (sine, cosine) pairs get different positive factors, which
/// does not change the sign or the tangent of the excess.
#[cold]
#[inline(never)]
fn rescaled_excess_sin_cos(vectors: [DVec3; 4]) -> (f64, f64) {
    excess_from_vectors(vectors.map(power_of_two_scaled))
}

/// [`excess_sin_cos`] from the vectors `a − c`, `b − c`, `a − d`, `b − d`,
/// each scaled by any positive factor (every factor is common to both
/// terms of sin and of cos).
#[inline(always)]
fn excess_from_vectors([u1, v1, u2, v2]: [DVec3; 4]) -> (f64, f64) {
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

/// A key that orders directions `(x, y)` as `atan2(y, x)` does, compared
/// with [`direction_cmp`]: the half-plane (y < 0, or −0, first), then −x/y,
/// which grows with the angle in each half. No `atan2`, whose last bit
/// differs between C libraries, so every platform decides alike; one
/// division, correctly rounded, so two directions tie only where their
/// angles agree to about 1e-16 of the angle itself near 0 and π (where
/// nearly folded faces meet) as elsewhere. Zero vectors key as atan2's
/// signed zeros make them (0, π, −0 or −π).
/// `--repair` sorts the faces around an edge by it, and polygons compare
/// Delaunay excesses by it ([`excess_order`]).
pub fn direction_key(y: f64, x: f64) -> (bool, f64) {
    if x == 0.0 && y == 0.0 {
        // As atan2's signed zeros: (±0, +0) at ±0, (±0, −0) at ±π.
        let end = if x.is_sign_negative() != y.is_sign_negative() {
            f64::INFINITY
        } else {
            f64::NEG_INFINITY
        };
        return (!y.is_sign_negative(), end);
    }
    // + 0.0: −0 and 0 (x = ±0, angle ±π/2) alike.
    (!y.is_sign_negative(), -x / y + 0.0)
}

/// The order of two [`direction_key`]s.
pub fn direction_cmp(a: (bool, f64), b: (bool, f64)) -> std::cmp::Ordering {
    a.0.cmp(&b.0).then(a.1.total_cmp(&b.1))
}

/// A key that orders edges by α + β − π as [`delaunay_excess`] does
/// ([`direction_key`], compared by [`direction_cmp`]), without `atan2`.
pub fn excess_order(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> (bool, f64) {
    let (y, x) = excess_sin_cos(a, b, c, d);
    direction_key(y, x)
}

/// Whether `(y, x)` from [`excess_sin_cos`] means α + β − π > `tolerance`
/// (0 ≤ `tolerance` < π/2), without computing the angle.
#[inline]
pub fn exceeds(y: f64, x: f64, tolerance: f64) -> bool {
    (y > 0.0) & ((x <= 0.0) | (y > x * tan_of_tolerance(tolerance)))
}

/// tan(t), without a libm call for the tiny tolerances used here: for
/// t < 1e-5 the series t + t³/3 is exact to well below an ulp of t.
#[inline(always)]
fn tan_of_tolerance(t: f64) -> f64 {
    if t.abs() < 1e-5 {
        t + t * t * t / 3.0
    } else {
        t.tan()
    }
}

/// Whether the edge (a, b) with opposite vertices `c`, `d` violates the
/// Delaunay condition by more than `tolerance` radians (an edge whose angles
/// underflow entirely counts as violating it: see [`delaunay_test`]).
#[inline(always)]
pub fn is_non_delaunay(a: DVec3, b: DVec3, c: DVec3, d: DVec3, tolerance: f64) -> bool {
    delaunay_test(a, b, c, d, tolerance) != DelaunayTest::Delaunay
}

/// What [`delaunay_test`] says of an edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DelaunayTest {
    /// α + β − π ≤ the tolerance.
    Delaunay,
    /// α + β − π > the tolerance.
    NonDelaunay,
    /// The excess's sine and cosine are both 0, even from rescaled vectors
    /// (an apex at an end of the edge, or products a subnormal distance
    /// from zero): f64 cannot tell.
    Underflow,
}

/// Products of coordinates above this are far from underflow: a dot
/// product's sign is then that of the exact one, up to the usual rounding
/// (about 1e-16 of |u||v|), and so are the excess's sine and cosine
/// ([`clear_of_underflow`]), products of four coordinates scaled by 1/|ab|.
const TINY_PRODUCT: f64 = 1e-280;

/// `v` times the power of two that brings its largest coordinate magnitude
/// into [1, 2) (exact: only exponents change); `v` itself when it is zero
/// or not finite.
fn power_of_two_scaled(v: DVec3) -> DVec3 {
    let largest = v.abs().max_element();
    if largest == 0.0 || !largest.is_finite() {
        return v;
    }
    // 2^-e in two factors, each a normal number (|e| <= 1074).
    let e = floor_log2(largest);
    let half = -e / 2;
    v * power_of_two(half) * power_of_two(-e - half)
}

/// The Delaunay test of the edge (a, b) with opposite vertices `c`, `d`.
///
/// Two non-obtuse opposite angles (both dot products ≥ 0) sum to at most π:
/// that common case is decided without a square root. Where a dot product,
/// or the excess's sine and cosine, are small enough to have underflowed,
/// the vectors are scaled exactly by powers of two instead (as
/// [`excess_sin_cos`] does there), which tells the angles apart however
/// close to the edge's line or ends (in f64) the apexes lie.
#[inline(always)]
pub fn delaunay_test(a: DVec3, b: DVec3, c: DVec3, d: DVec3, tolerance: f64) -> DelaunayTest {
    let (u1, v1) = (a - c, b - c);
    let (u2, v2) = (a - d, b - d);
    let (c1, c2) = (u1.dot(v1), u2.dot(v2));
    if (c1 >= 0.0) & (c2 >= 0.0) {
        if c1.min(c2) > TINY_PRODUCT {
            return DelaunayTest::Delaunay;
        }
        // Exact right angles, or dot products that may have underflowed
        // (a fuzz finding: at a needle 1e-323 wide every product is ±0).
        let (y, x) = rescaled_excess_sin_cos([u1, v1, u2, v2]);
        return decide(y, x, tolerance);
    }
    // One angle obtuse: the excess's sine and cosine as `excess_sin_cos`
    // makes them, from the vectors at hand, rescaled where they may have
    // underflowed, or where a dot product may have (then that face's sine
    // and cosine may have too, while the other face's larger ones keep the
    // excess's clear of underflow). One branch for both. A fuzz finding: an
    // angle of 72° at a vertex 1.6e-323 from the edge's end, its dot product
    // 0 and the other apex's negative, was read as 0.
    let k = 1.0 / (b - a).length();
    let (y, x) = excess_from_vectors([u1 * k, v1 * k, u2 * k, v2 * k]);
    if !((c1.abs().min(c2.abs()) > TINY_PRODUCT) & clear_of_underflow(y, x)) {
        let (y, x) = rescaled_excess_sin_cos([u1, v1, u2, v2]);
        return decide(y, x, tolerance);
    }
    decide(y, x, tolerance)
}

/// `(sin, cos)` of γ − π/2 for the angle γ = ∠acb opposite the boundary
/// edge (a, b) in its one face (a, b, c), both scaled by the same positive
/// factor: with u = a − c and v = b − c, −u·v and |u × v|. Positive sine:
/// γ is obtuse, and the edge's cotangent weight (cot γ)/2 is negative.
#[inline]
pub fn boundary_excess_sin_cos(a: DVec3, b: DVec3, c: DVec3) -> (f64, f64) {
    let (u, v) = (a - c, b - c);
    // Scaled by 1/|ab|, as in `excess_sin_cos`, and as there rescaled
    // exactly where that underflows (an apex a subnormal fraction of |ab|
    // from an end) or overflows.
    let k = 1.0 / (b - a).length();
    let (y, x) = (-(u * k).dot(v * k), (u * k).cross(v * k).length());
    if clear_of_underflow(y, x) {
        return (y, x);
    }
    rescaled_boundary_excess_sin_cos(u, v)
}

/// [`boundary_excess_sin_cos`] from `u = a − c` and `v = b − c`, each
/// scaled exactly by a power of two first (as [`rescaled_excess_sin_cos`]).
#[cold]
#[inline(never)]
fn rescaled_boundary_excess_sin_cos(u: DVec3, v: DVec3) -> (f64, f64) {
    let (u, v) = (power_of_two_scaled(u), power_of_two_scaled(v));
    (-u.dot(v), u.cross(v).length())
}

/// The test of a boundary edge (a, b) with one face (a, b, c) that
/// [`crate::mesh::Surface::gabriel_boundary`] asks for: `NonDelaunay` when
/// the angle at c exceeds π/2 by more than `tolerance` (its diametral circle
/// holds c: the edge is not Gabriel, and its cotangent weight is negative).
#[inline]
pub fn boundary_test(a: DVec3, b: DVec3, c: DVec3, tolerance: f64) -> DelaunayTest {
    let (u, v) = (a - c, b - c);
    let dot = u.dot(v);
    // A non-obtuse angle, its dot product clear of underflow: decided
    // without a square root (as `delaunay_test` decides its common case).
    if dot > TINY_PRODUCT {
        return DelaunayTest::Delaunay;
    }
    // A dot product near underflow: each vector scaled exactly by a power
    // of two first.
    let (y, x) = match dot.abs() > TINY_PRODUCT {
        true => boundary_excess_sin_cos(a, b, c),
        false => rescaled_boundary_excess_sin_cos(u, v),
    };
    decide(y, x, tolerance)
}

/// γ − π/2 (radians) of the boundary edge (a, b) with one face (a, b, c):
/// how far the angle opposite it is past a right angle.
pub fn boundary_excess(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (y, x) = boundary_excess_sin_cos(a, b, c);
    y.atan2(x)
}

/// What `(y, x)` from [`excess_sin_cos`] says of the edge.
#[inline(always)]
fn decide(y: f64, x: f64, tolerance: f64) -> DelaunayTest {
    // y = 0 with x < 0 is α + β = 0 or 2π, and 0 (two zero angles, both
    // dot products positive) is the non-obtuse case `delaunay_test` decides
    // before this: here both sines underflowed to
    // 0 (needles a subnormal distance from the edge's line) and both angles
    // are nearly π. y = x = 0 cannot come from two proper triangles (it
    // needs s₁ = c₁ = 0 or s₂ = c₂ = 0): sines and a cosine all underflowed,
    // and nothing can be told (a fuzz finding: a needle 1e-323 from its
    // edge's line, whose true excess was about π/2, was called Delaunay).
    //
    // (`&` and `|`, not `&&` and `||`: the outcome varies from edge to edge,
    // and one branch on it mispredicts less than one per comparison.)
    let underflow = (y == 0.0) & (x == 0.0);
    if underflow {
        DelaunayTest::Underflow
    } else if exceeds(y, x, tolerance) | ((y == 0.0) & (x < 0.0)) {
        DelaunayTest::NonDelaunay
    } else {
        DelaunayTest::Delaunay
    }
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
    #[inline]
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
    #[inline]
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
/// `inside` (a 2D point on this side). (The split conditions compute the
/// circle this unfolding defines from the apex's angle instead,
/// `refine::split_conditions`; the tests' oracle unfolds with this.)
#[inline]
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
#[inline]
pub fn second_axis_crossing(anchor: f64, p: DVec2, q: DVec2) -> f64 {
    // Translate the anchor to the origin: a circle through the origin is
    // x² + y² − 2 ox x − 2 oy y = 0, which meets y = 0 again at x = 2 ox.
    let p = DVec2::new(p.x - anchor, p.y);
    let q = DVec2::new(q.x - anchor, q.y);
    let d = 2.0 * (p.x * q.y - p.y * q.x);
    let ox = (q.y * p.length_squared() - p.y * q.length_squared()) / d;
    anchor + 2.0 * ox
}

/// The exact predicates below call `robust` (Shewchuk's adaptive predicates)
/// when every coordinate involved is 0 or has a magnitude in
/// [`FAST_MIN`, `FAST_MAX`]; otherwise on coordinates scaled into that range
/// by a power of two per axis (`scale_axis`) when the values of each axis
/// span at most 2^498, and in exact integer arithmetic ([`exact`]) when not.
///
/// Shewchuk's predicates are exact only when no operation underflows or
/// overflows: a coordinate of 2e-323 makes `orient2d`'s products round to 0
/// and calls a non-degenerate triangle collinear. Within the range, every
/// non-zero coordinate is a multiple of 2^-302 (its unit in the last place)
/// below 2^250, so every value the predicates compute (sums and products of
/// at most three coordinate differences, and their exact rounding errors) is
/// 0 or a multiple of 2^-906 below 2^760: inside the normal range of f64,
/// where they are exact. The range contains every coordinate of a mesh that
/// `io` accepts ([`crate::io::MAX_COORDINATE`] is 1e75 < 2^250) except
/// non-zero ones below 2^-250 (about 5.5e-76), which are rare (noise such as
/// 1e-300 in a file): those take the slower paths.
pub const FAST_MIN: f64 = f64::from_bits((1023 - 250) << 52);

/// See [`FAST_MIN`]: 2^250, about 1.8e75.
pub const FAST_MAX: f64 = f64::from_bits((1023 + 250) << 52);

/// Whether every coordinate of `points` is in the range where `robust`'s
/// predicates are exact (see [`FAST_MIN`]): then [`collinear_in_range`]
/// and [`pair_shape_in_range`] may be called on them, once for a whole mesh
/// instead of once per predicate.
pub fn all_in_fast_range(points: &[DVec3]) -> bool {
    points.iter().all(|p| fast_range(&[p.x, p.y, p.z]))
}

/// The zero-area test for triangles on `points`: [`collinear_in_range`]
/// if every coordinate is in the fast range ([`all_in_fast_range`], checked
/// here once for the whole mesh), else [`collinear`].
pub fn collinear_for(points: &[DVec3]) -> fn(DVec3, DVec3, DVec3) -> bool {
    if all_in_fast_range(points) {
        collinear_in_range
    } else {
        collinear
    }
}

/// The pair-shape test for quads on `points`, chosen as [`collinear_for`]
/// chooses: [`pair_shape_in_range`] or [`pair_shape`].
pub fn pair_shape_for(points: &[DVec3]) -> fn(DVec3, DVec3, DVec3, DVec3) -> PairShape {
    if all_in_fast_range(points) {
        pair_shape_in_range
    } else {
        pair_shape
    }
}

/// Whether `robust`'s predicates are exact on coordinates `coords` (see
/// [`FAST_MIN`]): each is ±0 or has a magnitude in [`FAST_MIN`,
/// [`FAST_MAX`]] (NaN and infinities are not).
///
/// On the hot path of building regions: the magnitudes are compared as bit
/// patterns (monotone for non-negative floats), without branches, two
/// integer comparisons per coordinate; `x - 1 < FAST_MIN - 1` holds exactly
/// for `0 < x < FAST_MIN`, as `0 - 1` wraps around.
#[inline]
fn fast_range(coords: &[f64]) -> bool {
    const LOW: u64 = FAST_MIN.to_bits();
    const HIGH: u64 = FAST_MAX.to_bits();
    let mut outside = false;
    for &c in coords {
        let magnitude = c.to_bits() & !(1 << 63);
        outside |= (magnitude.wrapping_sub(1) < LOW - 1) | (magnitude > HIGH);
    }
    !outside
}

/// The sign of `robust::orient2d(a, b, c)`: 1 when (a, b, c) turn
/// counter-clockwise, -1 clockwise, 0 when collinear; exact for every finite
/// input.
#[inline(always)]
pub(crate) fn orient2d_sign(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
    if fast_range(&[a[0], a[1], b[0], b[1], c[0], c[1]]) {
        robust_orient2d_sign(a, b, c)
    } else {
        orient2d_slow(a, b, c)
    }
}

/// [`orient2d_sign`] outside the fast range: each axis scaled into it by
/// [`scale_axis`] if possible, exact integer arithmetic otherwise.
#[cold]
#[inline(never)]
fn orient2d_slow(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
    match (scale_axis([a[0], b[0], c[0]]), scale_axis([a[1], b[1], c[1]])) {
        (Some([ax, bx, cx]), Some([ay, by, cy])) => robust_orient2d_sign([ax, ay], [bx, by], [cx, cy]),
        _ => exact::orient2d(a, b, c),
    }
}

/// The sign of `robust::orient3d(a, b, c, d)` (positive when `d` is below
/// the plane of the counter-clockwise triangle a, b, c), exact for every
/// finite input.
fn orient3d_sign(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    if fast_range(&[a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z]) {
        robust_orient3d_sign(a, b, c, d)
    } else {
        orient3d_slow(a, b, c, d)
    }
}

/// [`orient3d_sign`] outside the fast range, as [`orient2d_slow`].
#[cold]
#[inline(never)]
fn orient3d_slow(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let scaled = [0, 1, 2].map(|i| scale_axis([a[i], b[i], c[i], d[i]]));
    match scaled {
        [Some(x), Some(y), Some(z)] => {
            let point = |k: usize| DVec3::new(x[k], y[k], z[k]);
            robust_orient3d_sign(point(0), point(1), point(2), point(3))
        }
        _ => exact::orient3d(a.to_array(), b.to_array(), c.to_array(), d.to_array()),
    }
}

/// The coordinates of all points on one axis, multiplied by one power of
/// two that brings every non-zero one into the fast range, or `None` when
/// that is impossible (their magnitudes span more than 2^498, or one is not
/// finite).
///
/// The sign of both determinants is unchanged: each of their terms has
/// exactly one coordinate difference per axis, so scaling one axis by
/// `s > 0` scales the determinant by `s`. The scaling is exact: by at most
/// two powers of two, up from any value (no overflow: the result is below
/// 2^250) or down into the normal range.
fn scale_axis<const N: usize>(values: [f64; N]) -> Option<[f64; N]> {
    let (mut lowest, mut highest) = (i32::MAX, i32::MIN);
    for v in values {
        if !v.is_finite() {
            return None;
        }
        if v != 0.0 {
            let e = floor_log2(v);
            lowest = lowest.min(e);
            highest = highest.max(e);
        }
    }
    if lowest > highest {
        return Some(values); // all zero
    }
    if highest - lowest > 498 {
        return None;
    }
    // The smallest becomes at least 2^-250, the largest below 2^249.
    let k = -250 - lowest;
    let (first, second) = (power_of_two(k / 2), power_of_two(k - k / 2));
    Some(values.map(|v| v * first * second))
}

/// `floor(log2(|v|))` of a finite, non-zero `v` (subnormals included).
fn floor_log2(v: f64) -> i32 {
    let bits = v.to_bits();
    match ((bits >> 52) & 0x7ff) as i32 {
        0 => -1074 + 63 - (bits & ((1 << 52) - 1)).leading_zeros() as i32,
        biased => biased - 1023,
    }
}

/// `2^n` for `-1022 <= n <= 1023`.
fn power_of_two(n: i32) -> f64 {
    f64::from_bits(((n + 1023) as u64) << 52)
}

/// The sign of `robust::orient3d(a, b, c, d)`, exact only in the fast range.
#[inline(always)]
fn robust_orient3d_sign(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let coord = |p: DVec3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
    sign(robust::orient3d(coord(a), coord(b), coord(c), coord(d)))
}

/// The sign of `robust::orient2d(a, b, c)`, exact only in the fast range.
#[inline(always)]
fn robust_orient2d_sign(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
    let coord = |p: [f64; 2]| robust::Coord { x: p[0], y: p[1] };
    sign(robust::orient2d(coord(a), coord(b), coord(c)))
}

/// -1, 0 or 1 (0 for NaN too).
#[inline]
fn sign(x: f64) -> i8 {
    (x > 0.0) as i8 - (x < 0.0) as i8
}

/// The three projections on coordinate planes used by the predicates: (x,
/// y), (y, z) and (z, x).
const PLANES: [(usize, usize); 3] = [(0, 1), (1, 2), (2, 0)];

/// The exact sign (-1, 0 or 1) of the triangle (a, b, c) projected along
/// coordinate axis `axis` (component `axis` of its exact normal
/// `(b - a) x (c - a)`; the other two coordinates in cyclic order). Exact for
/// every finite input.
#[inline(always)]
pub fn projected_orientation([a, b, c]: [DVec3; 3], axis: usize) -> i8 {
    let (i, j) = [(1, 2), (2, 0), (0, 1)][axis];
    let (a, b, c) = (a.to_array(), b.to_array(), c.to_array());
    orient2d_sign([a[i], a[j]], [b[i], b[j]], [c[i], c[j]])
}

/// How the faces of a planar region look along one coordinate axis: every
/// face of the region, however its corners were rounded, must have exactly
/// the orientation `sign` in the projection along `axis` (see
/// [`projected_orientation`]). `sign` is 0 only for a region whose faces are
/// all exactly degenerate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegionPlane {
    /// The coordinate axis to project along (0, 1 or 2).
    pub axis: u8,
    /// The orientation of the region's faces in that projection.
    pub sign: i8,
}

impl RegionPlane {
    /// The plane of a region, given any of its faces: along the axis of the
    /// largest component, exactly, of the face's normal `(b - a) x (c - a)`
    /// (ties: the lower axis). All faces of a region are exactly coplanar and
    /// alike oriented, so every one gives the same answer, and `delmesh
    /// check` applies the same rule: the two agree even on faces whose
    /// rounded corners are not exactly in the plane.
    pub fn of_face(triangle: [DVec3; 3]) -> RegionPlane {
        // The three components estimated once; the exact fallbacks are those
        // of `normal_component_larger` and `projected_orientation`, whose
        // answers these are.
        let n = normal_estimates(triangle);
        let mut axis = 0;
        for other in [1, 2] {
            let larger = estimate_larger(n[other], n[axis])
                .unwrap_or_else(|| exact::normal_component_larger(triangle.map(|p| p.to_array()), other, axis));
            if larger {
                axis = other;
            }
        }
        // The projected orientation is the sign of that component, certain
        // when it exceeds its error bound.
        let (value, error) = n[axis];
        let sign = if value.is_finite() && error.is_finite() && value.abs() > error {
            sign(value)
        } else {
            projected_orientation(triangle, axis)
        };
        RegionPlane { axis: axis as u8, sign }
    }

    /// Exactly: does `triangle` have the region's orientation, with non-zero
    /// area, in the region's projection? (Always true for a region without
    /// orientation: there is nothing to compare with.)
    #[inline]
    pub fn is_proper(&self, triangle: [DVec3; 3]) -> bool {
        self.sign == 0 || projected_orientation(triangle, self.axis as usize) == self.sign
    }
}

/// Exactly: is component `i` of the normal `(b - a) x (c - a)` of
/// `triangle` larger in magnitude than component `j`? Decided in floating
/// point when the two differ by more than its rounding can (nearly always),
/// with integers otherwise.
pub fn normal_component_larger(triangle: [DVec3; 3], i: usize, j: usize) -> bool {
    let n = normal_estimates(triangle);
    estimate_larger(n[i], n[j]).unwrap_or_else(|| exact::normal_component_larger(triangle.map(|p| p.to_array()), i, j))
}

/// The components of the normal `(b - a) x (c - a)` of `triangle` in
/// floating point, each with a bound on its error: each difference and
/// product rounds once (relative 2^-53), the subtraction once; 8 ulps of the
/// terms' magnitudes, plus what underflow can lose.
#[inline]
fn normal_estimates([a, b, c]: [DVec3; 3]) -> [(f64, f64); 3] {
    let (d1, d2) = (b - a, c - a);
    [0, 1, 2].map(|k| {
        let (p, q) = ((k + 1) % 3, (k + 2) % 3);
        let (left, right) = (d1[p] * d2[q], d1[q] * d2[p]);
        let error = 8.0 * f64::EPSILON / 2.0 * (left.abs() + right.abs()) + 8.0 * f64::from_bits(1);
        (left - right, error)
    })
}

/// Whether `|n_i| > |n_j|` for two estimates of [`normal_estimates`], when
/// their error bounds decide it (`None` otherwise).
#[inline]
fn estimate_larger((ni, ei): (f64, f64), (nj, ej): (f64, f64)) -> Option<bool> {
    let (ni, nj) = (ni.abs(), nj.abs());
    if !(ni.is_finite() && nj.is_finite() && ei.is_finite() && ej.is_finite()) {
        return None;
    }
    if ni - ei > nj + ej {
        Some(true)
    } else if nj - ej >= ni + ei {
        Some(false)
    } else {
        None
    }
}

/// Exact test: are the points collinear (the triangle has zero area)? Exact
/// for every finite input, subnormal coordinates included.
pub fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    if !fast_range(&[a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z]) {
        return collinear_slow(a, b, c);
    }
    collinear_in_range(a, b, c)
}

/// [`collinear`] of points whose coordinates are known to be in the fast
/// range ([`all_in_fast_range`]); outside it the answer may be wrong.
#[inline]
pub fn collinear_in_range(a: DVec3, b: DVec3, c: DVec3) -> bool {
    PLANES
        .iter()
        .all(|&(i, j)| robust_orient2d_sign([a[i], a[j]], [b[i], b[j]], [c[i], c[j]]) == 0)
}

/// [`collinear`] outside the fast range.
#[cold]
#[inline(never)]
fn collinear_slow(a: DVec3, b: DVec3, c: DVec3) -> bool {
    PLANES
        .iter()
        .all(|&(i, j)| orient2d_sign([a[i], a[j]], [b[i], b[j]], [c[i], c[j]]) == 0)
}

/// How two triangles (a, b, c) and (b, a, d) that share the edge (a, b)
/// lie against each other ([`pair_shape`]).
///
/// ```text
///   Flat:    c          Folded:    c
///           / \                   / \       d on c's side of ab, in
///          a---b                 /  d \      c's plane: the faces
///           \ /                 / .' '. \     (a, b, c) and (b, a, d)
///            d                 a---------b    overlap
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PairShape {
    /// Not in one plane (or `d` on the line ab).
    Bent,
    /// In one plane, on opposite sides of the edge: a flat pair, whose edge
    /// may be flipped.
    Flat,
    /// In one plane, on the same side of the edge: the surface folds flat
    /// onto itself there (a face turned over in a flat part, or the rim of
    /// a flat two-sided sheet).
    Folded,
}

/// Exact test: do the triangles (a, b, c) and (b, a, d), which share the edge
/// (a, b), lie in one plane and on opposite sides of the edge (a flat, not
/// folded, pair)? Both triangles must be non-degenerate. Exact for every
/// finite input, subnormal coordinates included.
pub fn flat_pair(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    pair_shape(a, b, c, d) == PairShape::Flat
}

/// Exact: how the triangles (a, b, c) and (b, a, d), which share the edge
/// (a, b), lie against each other. The triangle (a, b, c) must be
/// non-degenerate. Exact for every finite input, subnormal coordinates
/// included.
pub fn pair_shape(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> PairShape {
    if !fast_range(&[a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z]) {
        return pair_shape_slow(a, b, c, d);
    }
    pair_shape_in_range(a, b, c, d)
}

/// [`pair_shape`] of points whose coordinates are known to be in the fast
/// range ([`all_in_fast_range`]); outside it the answer may be wrong.
#[inline]
pub fn pair_shape_in_range(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> PairShape {
    if !in_axis_plane(a, b, c, d) && robust_orient3d_sign(a, b, c, d) != 0 {
        return PairShape::Bent;
    }
    // Coplanar: project on a coordinate plane where (a, b, c) does not
    // degenerate; sides of the line ab are preserved by that projection.
    for (i, j) in PLANES {
        let sc = robust_orient2d_sign([a[i], a[j]], [b[i], b[j]], [c[i], c[j]]);
        if sc != 0 {
            let sd = robust_orient2d_sign([a[i], a[j]], [b[i], b[j]], [d[i], d[j]]);
            return shape_of_sides(sc * sd);
        }
    }
    PairShape::Bent
}

/// The shape of a coplanar pair from the product of its apexes' sides of
/// the shared edge.
#[inline(always)]
fn shape_of_sides(product: i8) -> PairShape {
    match product {
        ..0 => PairShape::Flat,
        0 => PairShape::Bent,
        1.. => PairShape::Folded,
    }
}

/// Exact test: are the triangle (a, b, c) and the point d in one plane?
/// Exact for every finite input.
pub fn coplanar(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    in_axis_plane(a, b, c, d) || orient3d_sign(a, b, c, d) == 0
}

/// Whether the four points have one coordinate equal, bit for bit: they
/// then lie in a plane `x = const` (or y, z), and orient3d is exactly zero
/// (one column of its determinant of differences is zero). Most flat pairs
/// of CAD meshes are such, and this costs three comparisons where the
/// exact predicate, whose floating-point filter cannot decide zero, would
/// run its exact stage (a quarter of fandisk's build).
#[inline(always)]
fn in_axis_plane(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    (0..3).any(|i| a[i] == b[i] && a[i] == c[i] && a[i] == d[i])
}

/// [`pair_shape`] outside the fast range (same steps, exact signs).
#[cold]
#[inline(never)]
fn pair_shape_slow(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> PairShape {
    if !in_axis_plane(a, b, c, d) && orient3d_sign(a, b, c, d) != 0 {
        return PairShape::Bent;
    }
    for (i, j) in PLANES {
        let sc = orient2d_sign([a[i], a[j]], [b[i], b[j]], [c[i], c[j]]);
        if sc != 0 {
            let sd = orient2d_sign([a[i], a[j]], [b[i], b[j]], [d[i], d[j]]);
            return shape_of_sides(sc * sd);
        }
    }
    PairShape::Bent
}

/// Exact orientation predicates in integer arithmetic, for coordinates
/// outside the range where `robust` is exact (see [`FAST_MIN`]).
///
/// Every finite f64 is `m · 2^e` with an integer `m` and `e >= -1074`. Both
/// determinants are sums of products taking one coordinate difference per
/// axis (one x, one y, one z), so each axis can be scaled on its own: its
/// coordinates are written as integers times `2^q`, `q` the smallest
/// exponent on that axis, and the sign of the determinant of those integers
/// (at most about 2,100 bits each, 6,300 for a product) is the answer. Slow
/// (microseconds) but only taken when the coordinates of one axis span more
/// than 2^498 (say 0.2 and 1e-160 in one predicate).
pub mod exact {
    use std::cmp::Ordering;

    /// A signed integer of any size: sign and magnitude (little-endian
    /// 64-bit limbs without high zero limbs; zero is empty and not negative).
    #[derive(Clone, Debug, PartialEq, Eq)]
    struct Int {
        negative: bool,
        limbs: Vec<u64>,
    }

    impl Int {
        /// `±m · 2^shift`.
        fn scaled(negative: bool, m: u64, shift: u32) -> Int {
            let mut limbs = vec![0; (shift / 64) as usize];
            let wide = (m as u128) << (shift % 64);
            limbs.push(wide as u64);
            limbs.push((wide >> 64) as u64);
            Int { negative, limbs }.normalized()
        }

        fn normalized(mut self) -> Int {
            while self.limbs.last() == Some(&0) {
                self.limbs.pop();
            }
            if self.limbs.is_empty() {
                self.negative = false;
            }
            self
        }

        fn negated(&self) -> Int {
            Int {
                negative: !self.negative,
                limbs: self.limbs.clone(),
            }
            .normalized()
        }

        fn add(&self, other: &Int) -> Int {
            if self.negative == other.negative {
                return Int {
                    negative: self.negative,
                    limbs: add_magnitudes(&self.limbs, &other.limbs),
                }
                .normalized();
            }
            match compare_magnitudes(&self.limbs, &other.limbs) {
                Ordering::Less => Int {
                    negative: other.negative,
                    limbs: subtract_magnitudes(&other.limbs, &self.limbs),
                },
                _ => Int {
                    negative: self.negative,
                    limbs: subtract_magnitudes(&self.limbs, &other.limbs),
                },
            }
            .normalized()
        }

        fn sub(&self, other: &Int) -> Int {
            self.add(&other.negated())
        }

        fn mul(&self, other: &Int) -> Int {
            let mut limbs = vec![0u64; self.limbs.len() + other.limbs.len()];
            for (i, &x) in self.limbs.iter().enumerate() {
                let mut carry = 0u128;
                for (j, &y) in other.limbs.iter().enumerate() {
                    let t = limbs[i + j] as u128 + x as u128 * y as u128 + carry;
                    limbs[i + j] = t as u64;
                    carry = t >> 64;
                }
                limbs[i + other.limbs.len()] = carry as u64;
            }
            Int {
                negative: self.negative != other.negative,
                limbs,
            }
            .normalized()
        }

        fn signum(&self) -> i8 {
            match (self.limbs.is_empty(), self.negative) {
                (true, _) => 0,
                (false, true) => -1,
                (false, false) => 1,
            }
        }
    }

    fn compare_magnitudes(a: &[u64], b: &[u64]) -> Ordering {
        a.len().cmp(&b.len()).then_with(|| a.iter().rev().cmp(b.iter().rev()))
    }

    fn add_magnitudes(a: &[u64], b: &[u64]) -> Vec<u64> {
        let (long, short) = if a.len() >= b.len() { (a, b) } else { (b, a) };
        let mut out = Vec::with_capacity(long.len() + 1);
        let mut carry = 0u128;
        for (i, &x) in long.iter().enumerate() {
            let t = x as u128 + short.get(i).copied().unwrap_or(0) as u128 + carry;
            out.push(t as u64);
            carry = t >> 64;
        }
        out.push(carry as u64);
        out
    }

    /// `a - b` for `a >= b`.
    fn subtract_magnitudes(a: &[u64], b: &[u64]) -> Vec<u64> {
        let mut out = Vec::with_capacity(a.len());
        let mut borrow = false;
        for (i, &x) in a.iter().enumerate() {
            let (t, b1) = x.overflowing_sub(b.get(i).copied().unwrap_or(0));
            let (t, b2) = t.overflowing_sub(borrow as u64);
            out.push(t);
            borrow = b1 || b2;
        }
        out
    }

    /// `x = ±m · 2^e` with `m` odd (or `m = 0`), for a finite `x`.
    fn decompose(x: f64) -> (bool, u64, i32) {
        let bits = x.to_bits();
        let negative = bits >> 63 == 1;
        let biased = ((bits >> 52) & 0x7ff) as i32;
        let fraction = bits & ((1 << 52) - 1);
        let (m, e) = if biased == 0 {
            (fraction, -1074)
        } else {
            (fraction | 1 << 52, biased - 1075)
        };
        if m == 0 {
            return (false, 0, 0);
        }
        let zeros = m.trailing_zeros();
        (negative, m >> zeros, e + zeros as i32)
    }

    /// The values of one axis (or of any set that must share one scale) as
    /// integers `v / 2^q`, with `q` the smallest exponent among them (all
    /// exact).
    fn axis<const N: usize>(values: [f64; N]) -> [Int; N] {
        let parts = values.map(decompose);
        let q = parts.iter().filter(|p| p.1 != 0).map(|p| p.2).min().unwrap_or(0);
        parts.map(|(negative, m, e)| match m {
            0 => Int::scaled(false, 0, 0),
            _ => Int::scaled(negative, m, (e - q) as u32),
        })
    }

    /// Whether all coordinates are finite (the integer path needs them; on
    /// other input the predicates answer as `robust` does).
    fn finite(points: &[&[f64]]) -> bool {
        points.iter().all(|p| p.iter().all(|c| c.is_finite()))
    }

    /// The exact sign of `(ax - cx)(by - cy) - (ay - cy)(bx - cx)` (the sign
    /// of `robust::orient2d`) for any finite coordinates.
    pub fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
        if !finite(&[&a, &b, &c]) {
            let coord = |p: [f64; 2]| robust::Coord { x: p[0], y: p[1] };
            return super::sign(robust::orient2d(coord(a), coord(b), coord(c)));
        }
        let [ax, bx, cx] = axis([a[0], b[0], c[0]]);
        let [ay, by, cy] = axis([a[1], b[1], c[1]]);
        let left = ax.sub(&cx).mul(&by.sub(&cy));
        let right = ay.sub(&cy).mul(&bx.sub(&cx));
        left.sub(&right).signum()
    }

    /// Exactly: is `|n[i]| > |n[j]|` for the normal `n = (b - a) x (c - a)` of a
    /// triangle with finite corners?
    pub fn normal_component_larger(triangle: [[f64; 3]; 3], i: usize, j: usize) -> bool {
        // One scale for all nine coordinates: the components' ratio must not change.
        let flat: [f64; 9] = triangle.as_flattened().try_into().expect("nine coordinates");
        let [ax, ay, az, bx, by, bz, cx, cy, cz] = axis(flat);
        let d1 = [bx.sub(&ax), by.sub(&ay), bz.sub(&az)];
        let d2 = [cx.sub(&ax), cy.sub(&ay), cz.sub(&az)];
        let component = |k: usize| {
            let (p, r) = ((k + 1) % 3, (k + 2) % 3);
            d1[p].mul(&d2[r]).sub(&d1[r].mul(&d2[p]))
        };
        compare_magnitudes(&component(i).limbs, &component(j).limbs) == Ordering::Greater
    }

    /// The exact sign of the determinant of the rows `a - d`, `b - d`,
    /// `c - d` (the sign of `robust::orient3d`) for any finite coordinates.
    pub fn orient3d(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> i8 {
        if !finite(&[&a, &b, &c, &d]) {
            let coord = |p: [f64; 3]| robust::Coord3D {
                x: p[0],
                y: p[1],
                z: p[2],
            };
            return super::sign(robust::orient3d(coord(a), coord(b), coord(c), coord(d)));
        }
        let [ax, bx, cx, dx] = axis([a[0], b[0], c[0], d[0]]);
        let [ay, by, cy, dy] = axis([a[1], b[1], c[1], d[1]]);
        let [az, bz, cz, dz] = axis([a[2], b[2], c[2], d[2]]);
        let (adx, bdx, cdx) = (ax.sub(&dx), bx.sub(&dx), cx.sub(&dx));
        let (ady, bdy, cdy) = (ay.sub(&dy), by.sub(&dy), cy.sub(&dy));
        let (adz, bdz, cdz) = (az.sub(&dz), bz.sub(&dz), cz.sub(&dz));
        let minor = |p: &Int, q: &Int, r: &Int, s: &Int| p.mul(q).sub(&r.mul(s));
        let det = adx
            .mul(&minor(&bdy, &cdz, &bdz, &cdy))
            .add(&bdx.mul(&minor(&cdy, &adz, &cdz, &ady)))
            .add(&cdx.mul(&minor(&ady, &bdz, &adz, &bdy)));
        det.signum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;

    /// The boundary test calls an angle past π/2 by more than the tolerance non-Delaunay, a
    /// right or acute one Delaunay, at any scale (down to a face 1e-300 wide, where the
    /// products underflow unless the vectors are scaled first), and says so for the same
    /// edges as the angle itself.
    #[test]
    fn boundary_test_tells_obtuse_from_right_and_acute_at_any_scale() {
        let (a, b) = (DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0));
        for scale in [1e-300, 1e-150, 1e-20, 1.0, 1e20, 1e70] {
            for (height, want) in [
                (1.0, DelaunayTest::Delaunay),      // right angle
                (2.0, DelaunayTest::Delaunay),      // acute
                (0.5, DelaunayTest::NonDelaunay),   // obtuse
                (1e-12, DelaunayTest::NonDelaunay), // a needle
            ] {
                let c = DVec3::new(0.0, height, 0.0) * scale;
                let got = boundary_test(a * scale, b * scale, c, ALGORITHM_TOLERANCE);
                assert_eq!(got, want, "scale {scale}, height {height}");
            }
        }
        // An apex 1e-253 from an end of an edge 1e70 long, its angle 0.01
        // rad past a right one: the dot product is clear of underflow, but
        // scaled by 1/|ab|² the cosine underflows to 0 and the sine to 1e-323.
        let (a, b, c) = (DVec3::ZERO, DVec3::new(1e70, 0.0, 0.0), DVec3::new(1e-255, 1e-253, 0.0));
        let k = 1.0 / (b - a).length();
        assert_eq!(((a - c) * k).dot((b - c) * k), 0.0, "the case must underflow");
        assert!((boundary_excess(a, b, c) - 0.01).abs() < 1e-3);
        assert_eq!(boundary_test(a, b, c, ALGORITHM_TOLERANCE), DelaunayTest::NonDelaunay);
        let mut rng = Rng(0xb0_0da7);
        for _ in 0..10_000 {
            let p = |rng: &mut Rng| DVec3::new(rng.centered(), rng.centered(), rng.centered());
            let (a, b, c) = (p(&mut rng), p(&mut rng), p(&mut rng));
            let excess = boundary_excess(a, b, c);
            if excess.abs() < 1e-9 {
                continue;
            }
            let bad = boundary_test(a, b, c, ALGORITHM_TOLERANCE) == DelaunayTest::NonDelaunay;
            assert_eq!(bad, excess > ALGORITHM_TOLERANCE, "{a} {b} {c}: {excess}");
        }
    }

    /// (y, x, correctly rounded y/√(x² + y²)): the smallest corners of the
    /// shared meshes and `data/`, then extreme scales.
    const SINES: [(f64, f64, f64); 19] = [
        (8.883849183338587e-05, 0.30704595268293, 0.0002893328745701901), // anchor.obj
        (0.35835467338507315, 4.562287190999999, 0.07830596477079604),    // armadillo.obj
        (0.04550338966089142, 0.1941366177380001, 0.22820377754662696),   // bunny.obj (glibc sin∘atan2 one off)
        (0.0006507902559625789, 0.0011267989048100002, 0.5001340621546846), // elephant.obj
        (5.6372690196583414e-05, 0.00018725999999999983, 0.28826109994582044), // fandisk.obj
        (0.0003461668878494586, 0.001296427114679, 0.25797781166163486),  // knot.obj (glibc sin∘atan2 one off)
        (4.088097239321824e-05, 112.8364585101, 3.623028667596502e-07),   // mpi_triang.obj
        (0.07676785796680943, 0.41060488962400005, 0.1837784356502932),   // nefertiti.obj (glibc sin∘atan2 one off)
        (0.0006755493518115572, 0.0496147245347, 0.013614642544939024),   // rotor.obj (glibc sin∘atan2 one off)
        (0.3, 2.0, 0.14834045293024462),                                  // cube.obj (glibc sin∘atan2 one off)
        (0.059593229481208695, 4.0, 0.01489665423460109), // oval_cylinder_smooth_normals.obj (glibc sin∘atan2 one off)
        (0.005157102890488694, 1.4264575344441892, 0.0036152980815795446), // a generated terrain (glibc sin∘atan2 one off)
        (5e-324, 1.0, 5e-324),                                             // extreme
        (1.0, 5e-324, 1.0),                                                // extreme
        (1e+308, 1.7e+308, 0.5070201265633939),                            // extreme (glibc sin∘atan2 one off)
        (3e-310, 1e-309, 0.2873478855663441),                              // extreme
        (1e-200, 1e+150, 0.0),                                             // extreme
        (0.7, -0.2, 0.9615239476408232),                                   // extreme
        (3.0, 4.0, 0.6),                                                   // extreme
    ];

    /// The direction key sorts directions as atan2 does: at the axes and
    /// diagonals, signed zeros included, and over random directions at
    /// every scale and close to the axes wherever the two angles differ by
    /// more than rounding.
    #[test]
    fn direction_keys_order_as_atan2() {
        let dirs = [
            (-1.0, -0.0),
            (-1.0, -1.0),
            (-0.0, -1.0),
            (1.0, -1.0),
            (1.0, -0.0),
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (-1.0, 1.0),
            (-1.0, 0.0),
        ];
        for w in dirs.windows(2) {
            let ((x0, y0), (x1, y1)) = (w[0], w[1]);
            let expected = f64::atan2(y0, x0).total_cmp(&f64::atan2(y1, x1));
            assert_eq!(
                direction_cmp(direction_key(y0, x0), direction_key(y1, x1)),
                expected,
                "{w:?}"
            );
        }
        for (y, x) in [(0.0, 0.0), (0.0, -0.0), (-0.0, 0.0), (-0.0, -0.0)] {
            for (y1, x1) in [
                (1.0, -1.0),
                (-1.0, -1.0),
                (1e-300, 1.0),
                (-1e-300, 1.0),
                (0.0, -1.0),
                (-0.0, -1.0),
            ] {
                let expected = f64::atan2(y, x).total_cmp(&f64::atan2(y1, x1));
                let got = direction_cmp(direction_key(y, x), direction_key(y1, x1));
                assert_eq!(got, expected, "({y}, {x}) against ({y1}, {x1})");
            }
        }
        let mut rng = Rng(0x00a1_71e5);
        let mut dirs: Vec<(f64, f64)> = (0..6000)
            .map(|i| {
                let s = 2f64.powi(rng.below(600) as i32 - 300);
                let (x, y) = (rng.centered() * s, rng.centered() * s);
                // A third of them within 1e-12 of an axis.
                match i % 3 {
                    0 => (x, y),
                    1 => (x, y * 1e-12 * rng.centered()),
                    _ => (x * 1e-12 * rng.centered(), y),
                }
            })
            .collect();
        dirs.sort_by(|a, b| a.1.atan2(a.0).total_cmp(&b.1.atan2(b.0)));
        for w in dirs.windows(2) {
            let (a, b) = (w[0].1.atan2(w[0].0), w[1].1.atan2(w[1].0));
            if b - a > 4.0 * f64::EPSILON * a.abs().max(b.abs()) {
                let (ka, kb) = (direction_key(w[0].1, w[0].0), direction_key(w[1].1, w[1].0));
                assert!(direction_cmp(ka, kb).is_lt(), "{w:?}");
            }
        }
    }

    /// `sine_of_direction` is correctly rounded (the values below are the
    /// exact y/√(x² + y²) rounded to the nearest double, by 60-digit
    /// decimal arithmetic), including the pairs where glibc's
    /// `sin(atan2(y, x))` is one unit off, at extreme scales, and within
    /// 2 ulp of `sin(atan2)` on random acute directions (obtuse ones lose
    /// accuracy in atan2 near π).
    #[test]
    fn sine_of_direction_is_correctly_rounded() {
        for (y, x, sine) in SINES {
            assert_eq!(sine_of_direction(y, x).to_bits(), sine.to_bits(), "({y:e}, {x:e})");
        }
        assert_eq!(sine_of_direction(1.0, 0.0), 1.0);
        assert_eq!(sine_of_direction(0.0, 1.0), 0.0);
        let mut rng = Rng(0x51_7e5);
        for _ in 0..10_000 {
            let s = 2f64.powi(rng.below(1200) as i32 - 600);
            let (y, x) = (rng.centered().abs() * s, rng.centered().abs() * s);
            let (ours, libm) = (sine_of_direction(y, x), y.atan2(x).sin());
            assert!(
                (ours - libm).abs() <= 2.0 * f64::EPSILON * libm.abs().max(f64::MIN_POSITIVE),
                "({y:e}, {x:e})"
            );
        }
    }

    /// `two_product`'s error is the fused multiply-add's, bit for bit, at
    /// the scales `sine_of_direction` uses (parts in [2^-60, 4)).
    #[test]
    fn two_product_is_exact() {
        let mut rng = Rng(0x2_0d0c7);
        for _ in 0..200_000 {
            let a = rng.centered() * 2f64.powi(rng.below(62) as i32 - 60);
            let b = rng.centered() * 2f64.powi(rng.below(62) as i32 - 60);
            let (p, e) = two_product(a, b);
            assert_eq!(p.to_bits(), (a * b).to_bits());
            assert_eq!(e, a.mul_add(b, -p), "{a:e} {b:e}");
        }
    }

    use std::f64::consts::{FRAC_PI_2, FRAC_PI_3, PI};

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
        let mut rng = Rng(12345);
        let mut rnd = move || rng.centered();
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
        // The same folded, at a subnormal distance from the edge's line: both
        // sines underflow to 0 (regression_refine_subnormal_fold_judged_delaunay).
        let (a, b) = (DVec3::ZERO, DVec3::new(3.0, 0.0, -1e-323));
        let (c, d) = (DVec3::new(1.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 0.0));
        assert_eq!(excess_sin_cos(a, b, c, d).0, 0.0);
        assert!(is_non_delaunay(a, b, c, d, ALGORITHM_TOLERANCE));
        // Two zero angles (the opposite vertices beyond b, on its line): Delaunay.
        let (c, d) = (DVec3::new(4.0, 0.0, 0.0), DVec3::new(5.0, 0.0, 0.0));
        assert!(!is_non_delaunay(a, b, c, d, ALGORITHM_TOLERANCE));
    }

    /// `exceeds` is strict: an excess equal to the tolerance is not over it, at tolerance 0
    /// (an exactly cocircular quad, y = 0) as at any other; an obtuse excess (x ≤ 0, y > 0) is.
    /// (Mutation testing: no test told `>` from `>=` at the tolerance.)
    #[test]
    fn exceeds_is_strict() {
        assert!(!exceeds(0.0, 1.0, 0.0));
        assert!(exceeds(1e-300, 1.0, 0.0));
        assert!(!exceeds(-1e-300, 1.0, 0.0));
        let t: f64 = 1e-3;
        let y = t.tan();
        assert!(!exceeds(y, 1.0, t));
        assert!(exceeds(y.next_up(), 1.0, t));
        assert!(exceeds(1.0, 0.0, t) && exceeds(1.0, -1.0, t));
    }

    /// `decide` on the excess's sine and cosine: ±π/2 (cosine 0) is decided by the sine's
    /// sign, not taken for underflow, which needs both 0. (Mutation testing.)
    #[test]
    fn decide_reads_a_zero_cosine_by_the_sine() {
        let t = ALGORITHM_TOLERANCE;
        assert_eq!(decide(-1.0, 0.0, t), DelaunayTest::Delaunay);
        assert_eq!(decide(1.0, 0.0, t), DelaunayTest::NonDelaunay);
        assert_eq!(decide(0.0, 0.0, t), DelaunayTest::Underflow);
        assert_eq!(decide(0.0, -1.0, t), DelaunayTest::NonDelaunay);
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

    /// The shortcut for four points in one axis plane (`in_axis_plane`)
    /// decides as the exact predicates do: random quads with one coordinate
    /// shared (0.0 and -0.0 mixed), some folded, some one ulp off the plane.
    #[test]
    fn flat_pair_in_axis_planes_agrees_with_the_exact_predicates() {
        let by_predicates = |a: DVec3, b: DVec3, c: DVec3, d: DVec3| {
            let side = |(i, j): (usize, usize), p: DVec3| exact::orient2d([a[i], a[j]], [b[i], b[j]], [p[i], p[j]]);
            exact::orient3d(a.into(), b.into(), c.into(), d.into()) == 0
                && PLANES
                    .into_iter()
                    .find(|&plane| side(plane, c) != 0)
                    .is_some_and(|plane| side(plane, c) * side(plane, d) < 0)
        };
        let mut rng = Rng(0x5eed_a715);
        let (mut flat, mut not_flat) = (0, 0);
        for case in 0..4000 {
            let axis = rng.below(3) as usize;
            let level = [0.0, -0.0, 0.1, 3.0][rng.below(4) as usize];
            let mut p = [0; 4].map(|_| DVec3::new(rng.centered(), rng.centered(), rng.centered()));
            for q in &mut p {
                // 0.0 and -0.0 are one plane (they compare equal).
                q[axis] = if level == 0.0 && rng.below(2) == 0 {
                    -level
                } else {
                    level
                };
            }
            if case % 5 == 0 {
                // One ulp off the plane: no longer flat.
                p[3][axis] = p[3][axis].next_up();
            }
            let [a, b, c, d] = p;
            if collinear(a, b, c) || collinear(b, a, d) {
                continue;
            }
            let expected = by_predicates(a, b, c, d);
            assert_eq!(flat_pair(a, b, c, d), expected, "case {case}: {p:?}");
            if expected {
                flat += 1;
            } else {
                not_flat += 1;
            }
        }
        // Both outcomes were exercised (flat about half the time: d on the
        // far side of ab).
        assert!(flat > 1000 && not_flat > 1000, "{flat} flat, {not_flat} not");
    }

    fn robust2(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
        let coord = |p: [f64; 2]| robust::Coord { x: p[0], y: p[1] };
        sign(robust::orient2d(coord(a), coord(b), coord(c)))
    }

    fn robust3(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
        let coord = |p: DVec3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
        sign(robust::orient3d(coord(a), coord(b), coord(c), coord(d)))
    }

    #[test]
    fn integer_predicates_agree_with_robust_in_its_exact_range() {
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        let mut zeros = [0, 0];
        for i in 0..20000 {
            // Small integers (many exact zeros), or random doubles of mixed sizes, or points
            // rounded onto a line or a plane (nearly degenerate, decided in robust's later stages).
            let mut p = [DVec3::ZERO; 4];
            for q in p.iter_mut() {
                *q = match i % 3 {
                    0 => DVec3::new(rng.int(3), rng.int(3), rng.int(3)),
                    _ => {
                        DVec3::new(rng.int(1 << 40), rng.int(1 << 40), rng.int(1 << 40))
                            * 2f64.powi(rng.below(80) as i32 - 40)
                    }
                };
            }
            if i % 3 == 2 {
                let t = rng.below(1000) as f64 / 997.0;
                p[2] = p[0] + t * (p[1] - p[0]);
                p[3] = p[0] + t * (p[1] - p[0]) + 0.3 * (p[2] - p[1]);
            }
            let [a, b, c, d] = p;
            let expected = robust3(a, b, c, d);
            assert_eq!(
                exact::orient3d(a.into(), b.into(), c.into(), d.into()),
                expected,
                "{p:?}"
            );
            zeros[0] += (expected == 0) as usize;
            for (i, j) in PLANES {
                let expected = robust2([a[i], a[j]], [b[i], b[j]], [c[i], c[j]]);
                let got = exact::orient2d([a[i], a[j]], [b[i], b[j]], [c[i], c[j]]);
                assert_eq!(got, expected, "{p:?}");
                zeros[1] += (expected == 0) as usize;
            }
        }
        assert!(
            zeros[0] > 200 && zeros[1] > 1500,
            "{zeros:?}: degenerate cases must be tested too"
        );
    }

    #[test]
    fn predicates_are_exact_on_tiny_and_huge_coordinates() {
        // Small-integer points decided by robust at scale 1, then every axis scaled by its own
        // power of two (exactly, down to subnormals or up to 2^1000): the answers must not
        // change, although robust's own products underflow or overflow there.
        let mut rng = Rng(42);
        let mut robust_wrong = 0;
        for i in 0..20000 {
            let p: [DVec3; 4] = [0; 4].map(|_| DVec3::new(rng.int(7), rng.int(7), rng.int(7)));
            let scale = DVec3::new(
                2f64.powi(rng.below(2060) as i32 - 1070),
                2f64.powi(rng.below(2060) as i32 - 1070),
                2f64.powi(rng.below(2060) as i32 - 1070),
            );
            let q = p.map(|v| v * scale);
            if q.iter().zip(&p).any(|(s, v)| *s / scale != *v || !s.is_finite()) {
                continue; // not exactly representable
            }
            let [a, b, c, d] = p;
            let [sa, sb, sc, sd] = q;
            assert_eq!(collinear(sa, sb, sc), collinear(a, b, c), "case {i}: {q:?}");
            assert_eq!(flat_pair(sa, sb, sc, sd), flat_pair(a, b, c, d), "case {i}: {q:?}");
            let expected = robust3(a, b, c, d);
            assert_eq!(exact::orient3d(sa.into(), sb.into(), sc.into(), sd.into()), expected);
            robust_wrong += (robust3(sa, sb, sc, sd) != expected) as usize;
        }
        assert!(
            robust_wrong > 1000,
            "the scaled cases must defeat robust itself ({robust_wrong})"
        );
    }

    #[test]
    fn underflowing_angles_are_not_called_delaunay() {
        // The excess of the rescaled vectors, in radians.
        let rescaled_excess = |a: DVec3, b: DVec3, c: DVec3, d: DVec3| {
            let (y, x) = rescaled_excess_sin_cos([a - c, b - c, a - d, b - d]);
            y.atan2(x)
        };
        // (sin, cos) of the excess from the vectors scaled by 1/|ab| only.
        let scaled = |a: DVec3, b: DVec3, c: DVec3, d: DVec3| {
            let k = 1.0 / (b - a).length();
            excess_from_vectors([a - c, b - c, a - d, b - d].map(|v| v * k))
        };
        // The pipeline fuzz finding (tests/regressions/fuzz-pipeline-dbeb…):
        // the apexes lie 1e-323 and 0 from the edge's line; every sine and
        // one cosine underflow, (sin, cos) of the excess is (0, 0). The true
        // excess is about π/2, and the rescaled vectors tell it.
        let (a, b) = (DVec3::new(0.25, 0.0, 0.0), DVec3::new(0.2, 2e-323, 0.0));
        let (c, d) = (DVec3::new(0.225, 0.0, 0.0), DVec3::new(0.25, 1e-323, 0.0));
        for (a, b, c, d) in [(a, b, c, d), (b, a, d, c)] {
            assert_eq!(scaled(a, b, c, d), (0.0, 0.0));
            assert!((delaunay_excess(a, b, c, d) - FRAC_PI_2).abs() < 1e-3);
            assert!((rescaled_excess(a, b, c, d) - FRAC_PI_2).abs() < 1e-3);
            assert_eq!(
                delaunay_test(a, b, c, d, ALGORITHM_TOLERANCE),
                DelaunayTest::NonDelaunay
            );
        }
        // The attributes fuzz finding (tests/regressions/fuzz-attributes-
        // f3e3…): an apex 1.6e-323 from the edge's end b sees the edge at
        // 71.6° (atan 3), but its dot product underflows to 0, and the other
        // apex's is negative (129.6°): the excess, 21.2°, read as about 0.
        let (a, b) = (DVec3::new(-0.2, 0.0, 0.0), DVec3::ZERO);
        let (c, d) = (DVec3::new(5e-324, 0.0, -1.5e-323), DVec3::new(-0.1, 0.0, 0.0471));
        assert_eq!((a - c).dot(b - c), 0.0, "the case must underflow");
        for (a, b, c, d) in [(a, b, c, d), (b, a, d, c)] {
            assert!((rescaled_excess(a, b, c, d) - 0.37).abs() < 1e-2);
            assert!((delaunay_excess(a, b, c, d) - 0.37).abs() < 1e-2);
            assert_eq!(
                delaunay_test(a, b, c, d, ALGORITHM_TOLERANCE),
                DelaunayTest::NonDelaunay
            );
        }
        // Both apexes 1e-200 from `a` (angles 120°): the dot products are
        // clear of underflow, but the excess's products of four
        // coordinates are not; its true value is 60°.
        let (a, b) = (DVec3::ZERO, DVec3::X);
        let (c, d) = (DVec3::new(5e-201, 8.66e-201, 0.0), DVec3::new(5e-201, -8.66e-201, 0.0));
        assert_eq!(scaled(a, b, c, d), (0.0, 0.0), "the case must underflow");
        assert!((delaunay_excess(a, b, c, d) - FRAC_PI_3).abs() < 1e-3);
        assert!((rescaled_excess(a, b, c, d) - FRAC_PI_3).abs() < 1e-3);
        assert_eq!(
            delaunay_test(a, b, c, d, ALGORITHM_TOLERANCE),
            DelaunayTest::NonDelaunay
        );
        // An apex 1e309 times the edge's length away: the vectors scaled by
        // 1/|ab| overflow, and the rescaled ones tell the angles (the far
        // one below 1e-308, the near one 0.04 short of π): Delaunay.
        let (a, b) = (DVec3::ZERO, DVec3::new(1e-10, 0.0, 0.0));
        let (c, d) = (DVec3::new(5e-11, 1e-12, 0.0), DVec3::new(0.0, -1e299, 0.0));
        let (y, x) = scaled(a, b, c, d);
        assert!(!(y + x).is_finite(), "the case must overflow");
        assert!((delaunay_excess(a, b, c, d) + 0.04).abs() < 1e-3);
        assert!((rescaled_excess(a, b, c, d) + 0.04).abs() < 1e-3);
        assert_eq!(delaunay_test(a, b, c, d, ALGORITHM_TOLERANCE), DelaunayTest::Delaunay);
        // Both dot products underflow to ±0, so the shortcut for two
        // non-obtuse angles cannot trust them: an apex 1e-200 from `a` (angle
        // nearly π) and a right angle, excess about π/2.
        let (a, b) = (DVec3::ZERO, DVec3::new(1e-170, 0.0, 0.0));
        let (c, d) = (DVec3::new(1e-200, 1e-210, 0.0), DVec3::new(5e-171, -5e-171, 0.0));
        assert_eq!(
            ((a - c).dot(b - c), (a - d).dot(b - d)),
            (0.0, 0.0),
            "the case must underflow"
        );
        assert_eq!(
            delaunay_test(a, b, c, d, ALGORITHM_TOLERANCE),
            DelaunayTest::NonDelaunay
        );
        // The checker's fuzz finding (tests/regressions/bug-checker-subnormal-
        // right-angle.obj): a right angle at a needle 1.5e-323 wide, whose dot
        // product is -0, beside an angle of 1.485 rad: Delaunay, rescaled too.
        let (a, b) = (DVec3::new(2e-323, 0.0, -0.0), DVec3::new(0.0, 0.33333333333333326, 0.0));
        let c = DVec3::new(0.06982956419572245, 0.3216952016366297, 0.03274038839260605);
        let d = DVec3::new(1.5e-323, 0.33333333333333326, 0.0);
        assert_eq!((a - d).dot(b - d), 0.0);
        assert_eq!(delaunay_test(a, b, c, d, ALGORITHM_TOLERANCE), DelaunayTest::Delaunay);
        // Exact right angles at ordinary scale (a grid's diagonal): Delaunay.
        let (a, b) = (DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0));
        let (c, d) = (DVec3::new(0.0, 1.0, 0.0), DVec3::new(1.0, 0.0, 0.0));
        assert_eq!(delaunay_test(a, b, c, d, 0.0), DelaunayTest::Delaunay);
        // A proper pair is never (0, 0): a square's diagonal is exactly
        // cocircular (excess 0, cosine positive) and stays Delaunay.
        let square = [
            DVec3::ZERO,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
        ];
        let (y, x) = excess_sin_cos(square[0], square[1], square[2], square[3]);
        assert!(y.abs() < 1e-15 && x > 0.0);
        assert!(!is_non_delaunay(
            square[0],
            square[1],
            square[2],
            square[3],
            ALGORITHM_TOLERANCE
        ));
    }

    #[test]
    fn region_plane_axis_is_the_exact_largest_normal_component() {
        let mut rng = Rng(0x9e3779b97f4a7c15);
        for k in 0..20_000 {
            // Small integers: the float normal is exact, so it is the oracle.
            let n = if k % 2 == 0 { 3 } else { 1000 };
            let t = [0; 3].map(|_| DVec3::new(rng.int(n), rng.int(n), rng.int(n)));
            let normal = (t[1] - t[0]).cross(t[2] - t[0]);
            // The same triangle scaled down into the subnormals (exactly: the
            // integers need at most 11 bits) and up near the overflow.
            let tiny = t.map(|p| p * power_of_two(-1000) * power_of_two(-60));
            let huge = t.map(|p| p * power_of_two(1000));
            for (i, j) in [(0, 1), (1, 0), (0, 2), (2, 0), (1, 2), (2, 1)] {
                let expected = normal[i].abs() > normal[j].abs();
                assert_eq!(normal_component_larger(t, i, j), expected, "{t:?} {i} {j}");
                assert_eq!(normal_component_larger(tiny, i, j), expected, "{tiny:?} {i} {j}");
                assert_eq!(normal_component_larger(huge, i, j), expected, "{huge:?} {i} {j}");
                let exact = exact::normal_component_larger(t.map(|p| p.to_array()), i, j);
                assert_eq!(exact, expected, "{t:?} {i} {j}");
            }
            for triangle in [t, tiny, huge] {
                let plane = RegionPlane::of_face(triangle);
                let axis = plane.axis as usize;
                assert!((0..3).all(|j| normal[axis].abs() >= normal[j].abs()));
                assert!(
                    (0..axis).all(|j| normal[axis].abs() > normal[j].abs()),
                    "ties go to the lower axis"
                );
                assert_eq!(
                    plane.sign as f64,
                    if normal == DVec3::ZERO {
                        0.0
                    } else {
                        normal[axis].signum()
                    }
                );
                assert_eq!(plane.sign, projected_orientation(triangle, axis));
            }
        }
        // The fuzz finding: a needle whose float normal underflows; its exact
        // normal is about (1e-589, 1.5e-323, 6.8e-305): the plane is along z.
        let needle = [
            DVec3::ZERO,
            DVec3::new(-9.893200629020876e-39, 0.0, 1.5e-323),
            DVec3::new(1.0, -6.855535480901878e-267, 0.0),
        ];
        assert_eq!(RegionPlane::of_face(needle).axis, 2);
    }

    #[test]
    fn subnormal_coordinates() {
        // The fuzz finding: y = 2e-323 is not 0, so these are not collinear.
        let (a, b, c) = (DVec3::ZERO, DVec3::new(0.2, 2e-323, 0.0), DVec3::new(0.1, 0.0, 0.0));
        assert!(!collinear(a, b, c) && !collinear(b, c, a) && !collinear(c, a, b));
        assert!(collinear(a, DVec3::new(0.2, 0.0, 0.0), c));
        // Points on a line through the origin with slope 2, in units of the smallest subnormal.
        let t = f64::from_bits(1);
        let (p, q) = (DVec3::new(2.0 * t, 4.0 * t, 0.0), DVec3::new(3.0 * t, 6.0 * t, 0.0));
        assert!(collinear(DVec3::ZERO, p, q));
        assert!(!collinear(DVec3::ZERO, p, DVec3::new(3.0 * t, 7.0 * t, 0.0)));
        // Largest and smallest magnitudes together.
        let big = f64::MAX;
        assert!(!collinear(
            DVec3::ZERO,
            DVec3::new(big, 0.0, 0.0),
            DVec3::new(big, t, 0.0)
        ));
        assert!(collinear(
            DVec3::ZERO,
            DVec3::new(big, 0.0, t),
            DVec3::new(-big, 0.0, -t)
        ));
        // A flat pair lifted off z = 0 by one subnormal at d: no longer coplanar.
        let (a, b, c) = (DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0), DVec3::new(1.0, 0.0, 0.0));
        assert!(flat_pair(a, b, c, DVec3::new(0.0, 1.0, 0.0)));
        assert!(!flat_pair(a, b, c, DVec3::new(0.0, 1.0, t)));
        // Non-finite input: an answer, no panic.
        let _ = collinear(
            DVec3::ZERO,
            DVec3::new(f64::NAN, 1.0, t),
            DVec3::new(f64::INFINITY, 0.0, 1.0),
        );
        let _ = flat_pair(a, b, DVec3::splat(f64::NEG_INFINITY), DVec3::new(0.0, t, f64::NAN));
    }

    #[test]
    fn wide_spans_within_one_axis() {
        // Points 0, b and s b on a line through the origin, s = 2^-500 .. 2^-1000 (exactly), so
        // that each axis holds values 2^500 and more apart: the integer path decides. Moved by
        // one unit in the last place, they are not collinear; and with c, the plane of 0, b, c
        // contains s b, but not s b moved off it along z (orient3d's sign is then that of the
        // triangle 0, b, c seen along z, reversed).
        let mut rng = Rng(7);
        let mut wide = 0;
        for _ in 0..5000 {
            // |x| in [2^-100, 2^100), any mantissa, any sign.
            let mut any = || {
                let x = f64::from_bits((rng.next() >> 12) | ((1023 - 100 + rng.below(200)) << 52));
                if rng.below(2) == 0 {
                    x
                } else {
                    -x
                }
            };
            let (b, c) = (DVec3::new(any(), any(), any()), DVec3::new(any(), any(), any()));
            let s = 2f64.powi(-500 - rng.below(400) as i32);
            let sb = b * s;
            if !(b.is_finite() && c.is_finite()) || sb / s != b || sb.abs().min_element() == 0.0 {
                continue;
            }
            wide += (scale_axis([0.0, b.x, sb.x]).is_none()) as usize;
            assert!(collinear(DVec3::ZERO, b, sb), "{b:?} {s}");
            assert!(collinear(sb, DVec3::ZERO, b), "{b:?} {s}");
            let off = DVec3::new(sb.x, sb.y, next_up(sb.z));
            assert!(!collinear(DVec3::ZERO, b, off), "{b:?} {s}");
            let o = [0.0; 3];
            assert_eq!(exact::orient3d(o, b.into(), c.into(), sb.into()), 0, "{b:?} {c:?} {s}");
            let turn = orient2d_sign([0.0, 0.0], [b.x, b.y], [c.x, c.y]);
            assert_eq!(
                exact::orient3d(o, b.into(), c.into(), off.into()),
                -turn,
                "{b:?} {c:?} {s}"
            );
            assert!(!flat_pair(DVec3::ZERO, b, c, off));
        }
        assert!(wide > 1000, "spans wider than 2^498 must be tested ({wide})");
    }

    /// The next f64 towards +infinity of a finite, non-zero `x`.
    fn next_up(x: f64) -> f64 {
        let bits = x.to_bits();
        f64::from_bits(if x > 0.0 { bits + 1 } else { bits - 1 })
    }

    #[test]
    fn the_mesh_wide_range_check_sees_every_coordinate() {
        // A bad coordinate is found first, in the middle and last.
        let mut points: Vec<DVec3> = (0..200).map(|i| DVec3::new(i as f64, -0.5 * i as f64, 1e70)).collect();
        points[7] = DVec3::ZERO;
        assert!(all_in_fast_range(&points));
        assert!(all_in_fast_range(&[]));
        for bad in [1e-300, -1e-80, 1e76, f64::NAN, f64::INFINITY, 5e-324] {
            for at in [0, 130, 199] {
                for axis in 0..3 {
                    let mut p = points.clone();
                    p[at][axis] = bad;
                    assert!(!all_in_fast_range(&p), "{bad} at point {at}, axis {axis}");
                }
            }
        }
        // In range, the unchecked predicates answer as the checked ones.
        let (a, b, c, d) = (
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(0.0, 1.0, 1.0),
            DVec3::new(0.5, -1.0, 1.0),
        );
        assert_eq!(pair_shape_in_range(a, b, c, d), pair_shape(a, b, c, d));
        assert_eq!(pair_shape_in_range(a, b, c, d), PairShape::Flat);
        assert!(collinear_in_range(a, b, (a + b) * 0.5));
        assert!(!collinear_in_range(a, b, c));
        // The mesh-wide choice: on a triangle 1e-310 across the unchecked
        // test underflows; the choice made for its points is the exact one.
        let tiny = [DVec3::ZERO, DVec3::new(1e-310, 0.0, 0.0), DVec3::new(0.0, 1e-310, 0.0)];
        assert!(collinear_in_range(tiny[0], tiny[1], tiny[2]), "underflows, as said");
        assert!(!collinear_for(&tiny)(tiny[0], tiny[1], tiny[2]));
        assert!(!collinear_for(&[a, b, c])(a, b, c));
        assert_eq!(pair_shape_for(&[a, b, c, d])(a, b, c, d), PairShape::Flat);
        let far = DVec3::new(0.0, 0.0, 1e-310);
        assert_eq!(
            pair_shape_for(&[tiny[0], tiny[1], tiny[2], far])(tiny[0], tiny[1], tiny[2], far),
            PairShape::Bent
        );
    }

    #[test]
    fn pair_shapes_tell_flat_from_folded_and_bent_in_and_out_of_the_fast_range() {
        // The edge a-b, c above it; d below (flat), above (folded), lifted
        // off the plane (bent), on the line ab (degenerate: bent).
        // (Dyadic coordinates: every sum and scaling below is exact.)
        let (a, b, c) = (
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::new(1.0, 0.0, 2.0),
            DVec3::new(0.25, 1.0, 2.0),
        );
        let cases = [
            (DVec3::new(0.625, -1.0, 2.0), PairShape::Flat),
            (DVec3::new(0.75, 0.5, 2.0), PairShape::Folded),
            (DVec3::new(0.75, 0.5, 2.0 + 2f64.powi(-40)), PairShape::Bent),
            (DVec3::new(0.5, -1.0, 2.5), PairShape::Bent),
            (DVec3::new(2.0, 0.0, 2.0), PairShape::Bent),
        ];
        // In a tilted plane too (z = x + y), and scaled out of the fast
        // range both ways (by powers of two).
        let tilt = |p: DVec3| DVec3::new(p.x, p.y, p.x + p.y);
        for scale in [1.0, 2f64.powi(-1000), 2f64.powi(900)] {
            for (d, shape) in cases {
                let [a, b, c, d] = [a, b, c, d].map(|p| p * scale);
                assert_eq!(pair_shape(a, b, c, d), shape, "{d} at scale {scale:e}");
                assert_eq!(flat_pair(a, b, c, d), shape == PairShape::Flat);
                if shape != PairShape::Bent || d.z == c.z {
                    let [a, b, c, d] = [a, b, c, d].map(tilt);
                    assert_eq!(pair_shape(a, b, c, d), shape, "tilted {d} at scale {scale:e}");
                }
            }
        }
    }

    #[test]
    fn axis_scaling_is_exact_and_lands_in_the_fast_range() {
        let t = f64::from_bits(1);
        let scaled = scale_axis([0.0, 2e-323, -3.0 * t, 1e-310]).unwrap();
        assert!(fast_range(&scaled));
        assert_eq!(scaled[1] / scaled[2], -4.0 / 3.0);
        let scaled = scale_axis([1e300, -7e299, 0.0]).unwrap();
        assert!(fast_range(&scaled) && scaled[0] / scaled[1] == 1e300 / -7e299);
        assert_eq!(scale_axis([0.2, 1e-160, 0.0]), None);
        assert_eq!(scale_axis([f64::NAN, 1.0]), None);
        assert_eq!(scale_axis([0.0, -0.0]), Some([0.0, -0.0]));
        assert_eq!(floor_log2(t), -1074);
        assert_eq!(floor_log2(-3.0 * t), -1073);
        assert_eq!(floor_log2(f64::MIN_POSITIVE), -1022);
        assert_eq!(floor_log2(f64::MAX), 1023);
        assert_eq!(floor_log2(0.75), -1);
    }
}
