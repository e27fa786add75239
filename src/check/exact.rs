//! The judge's own exact predicates and careful arithmetic (orientations, coplanarity, exact
//! determinants, compensated sums), shared with nothing in the construction.

use super::*;

/// Exactly: `|n[i]| > |n[j]|` for the normal `n = (b - a) x (c - a)` of `triangle`. In floating
/// point with a bound on its rounding (two differences, a product and a subtraction: 8 units of
/// roundoff of the terms, plus underflow) when that decides; otherwise from the exact signs of
/// `n . (e_i - e_j)` and `n . (e_i + e_j)`, whose product is that of `|n_i|^2 - |n_j|^2`.
pub(super) fn larger_normal_component([a, b, c]: [DVec3; 3], i: usize, j: usize) -> bool {
    let (u, v) = (b - a, c - a);
    let estimate = |k: usize| {
        let (p, q) = ((k + 1) % 3, (k + 2) % 3);
        let terms = [u[p] * v[q], u[q] * v[p]];
        let bound = 4.0 * f64::EPSILON * (terms[0].abs() + terms[1].abs()) + 8.0 * f64::from_bits(1);
        ((terms[0] - terms[1]).abs(), bound)
    };
    let ((x, ex), (y, ey)) = (estimate(i), estimate(j));
    if [x, ex, y, ey].iter().all(|t| t.is_finite()) {
        if x - ex > y + ey {
            return true;
        }
        if y - ey >= x + ex {
            return false;
        }
    }
    // n . w = -det[[a, 1], [b, 1], [c, 1], [w, 0]]; the two signs' product drops the minus.
    let dot_sign = |w: [f64; 3]| {
        let row = |p: DVec3| [p.x, p.y, p.z, 1.0];
        exact_determinant_sign([row(a), row(b), row(c), [w[0], w[1], w[2], 0.0]])
    };
    let (mut minus, mut plus) = ([0.0; 3], [0.0; 3]);
    minus[i] = 1.0;
    minus[j] = -1.0;
    plus[i] = 1.0;
    plus[j] = 1.0;
    dot_sign(minus) * dot_sign(plus) > 0
}

/// The sign (-1, 0 or 1), exactly, of the orientation of a triangle projected along coordinate
/// axis `axis`, i.e. of component `axis` of its exact normal `(b - a) x (c - a)`: the projection
/// keeps the other two coordinates in cyclic order (y, z), (z, x) or (x, y).
pub(super) fn projected_orientation([a, b, c]: [DVec3; 3], axis: usize) -> i8 {
    let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
    orient2d_sign([a[i], a[j]], [b[i], b[j]], [c[i], c[j]])
}

/// Whether a triangle is exactly degenerate (its corners are collinear): all three projections
/// along the coordinate axes are.
pub(super) fn exactly_degenerate(triangle: [DVec3; 3]) -> bool {
    (0..3).all(|axis| projected_orientation(triangle, axis) == 0)
}

/// Exactly: `d` is in the plane of `a, b, c` and on the other side of line `ab` than `c`.
pub(super) fn coplanar_and_flat(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    coplanar_sides(a, b, c, d).is_some_and(|(side_c, side_d)| side_c == -side_d)
}

/// Exactly: `d` is in the plane of `a, b, c` and on the same side of line `ab` as `c`: faces
/// `(a, b, c)` and `(b, a, d)` lie folded onto each other.
pub(super) fn coplanar_and_folded(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    coplanar_sides(a, b, c, d).is_some_and(|(side_c, side_d)| side_c == side_d)
}

/// If `d` is exactly in the plane of `a, b, c` (and `c` off line `ab`): the sides of line `ab`
/// that `c` and `d` are on (-1, 0 or 1; `c`'s not 0), in a projection along an axis where the
/// plane's projection keeps its area.
fn coplanar_sides(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<(i8, i8)> {
    // Four points with one coordinate equal lie in that axis plane: decided without the exact
    // predicate, which would run its slowest stage to prove the zero (most flat pairs of CAD
    // meshes are such).
    let in_axis_plane = (0..3).any(|k| a[k] == b[k] && a[k] == c[k] && a[k] == d[k]);
    if !in_axis_plane && orient3d_sign(a, b, c, d) != 0 {
        return None;
    }
    (0..3).find_map(|axis| {
        let side_c = projected_orientation([a, b, c], axis);
        (side_c != 0).then(|| (side_c, projected_orientation([a, b, d], axis)))
    })
}

/// The sign (-1, 0 or 1) of `(ax - cx)(by - cy) - (ay - cy)(bx - cx)`, exactly for every finite
/// input: `robust::orient2d` where it is exact (see [`robust_is_exact`]), on the coordinates of
/// each axis rescaled by a power of two where that makes it exact ([`rescaled`]), and an exact
/// expansion of the determinant otherwise ([`exact_determinant_sign`]).
pub(super) fn orient2d_sign(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
    let robust_sign = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        let coord = |p: [f64; 2]| robust::Coord { x: p[0], y: p[1] };
        sign_of(robust::orient2d(coord(a), coord(b), coord(c)))
    };
    if robust_is_exact(&[a[0], a[1], b[0], b[1], c[0], c[1]]) {
        return robust_sign(a, b, c);
    }
    match (rescaled([a[0], b[0], c[0]]), rescaled([a[1], b[1], c[1]])) {
        (Some([ax, bx, cx]), Some([ay, by, cy])) => robust_sign([ax, ay], [bx, by], [cx, cy]),
        // The determinant of the rows (x, y, 1) of a, b, c.
        _ => exact_determinant_sign([[a[0], a[1], 1.0], [b[0], b[1], 1.0], [c[0], c[1], 1.0]]),
    }
}

/// The sign (-1, 0 or 1) of the determinant of the rows `a - d`, `b - d`, `c - d` (that of
/// `robust::orient3d`), exactly for every finite input, as [`orient2d_sign`].
pub(super) fn orient3d_sign(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let robust_sign = |[a, b, c, d]: [DVec3; 4]| {
        let coord = |p: DVec3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
        sign_of(robust::orient3d(coord(a), coord(b), coord(c), coord(d)))
    };
    let coordinates = [a.to_array(), b.to_array(), c.to_array(), d.to_array()];
    if robust_is_exact(coordinates.as_flattened()) {
        return robust_sign([a, b, c, d]);
    }
    match [0, 1, 2].map(|i| rescaled([a[i], b[i], c[i], d[i]])) {
        [Some(x), Some(y), Some(z)] => robust_sign([0, 1, 2, 3].map(|k| DVec3::new(x[k], y[k], z[k]))),
        // The determinant of the rows (x, y, z, 1) of a, b, c, d.
        _ => exact_determinant_sign(coordinates.map(|[x, y, z]| [x, y, z, 1.0])),
    }
}

/// The coordinates of one axis (of all the points of a predicate) multiplied by the power of two
/// that brings the largest magnitude near 2^200, if then [`robust_is_exact`] on them; `None`
/// otherwise (a non-finite value, or magnitudes too far apart, such as 0.2 and 1e-160).
///
/// Both determinants are sums of terms with exactly one coordinate (difference) per axis, so
/// multiplying one axis by a positive factor keeps their sign. The multiplication is exact: up,
/// nothing is lost below 2^203; down, a value that loses bits ends below 2^-1022, and then
/// `robust_is_exact` refuses the result.
pub(super) fn rescaled<const N: usize>(values: [f64; N]) -> Option<[f64; N]> {
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !values.iter().all(|v| v.is_finite()) {
        return None;
    }
    if largest == 0.0 {
        return Some(values);
    }
    let k = 200 - largest.log2().floor() as i32; // within -824 ..= 1274
    let (k1, k2) = (k / 2, k - k / 2);
    let scaled = values.map(|v| v * 2f64.powi(k1) * 2f64.powi(k2));
    robust_is_exact(&scaled).then_some(scaled)
}

/// -1, 0 or 1 (0 for NaN).
pub(super) fn sign_of(x: f64) -> i8 {
    (x > 0.0) as i8 - (x < 0.0) as i8
}

/// Whether Shewchuk's predicates (the `robust` crate) are exact on these coordinates: they are
/// when no operation underflows or overflows. With every coordinate 0 or of magnitude in
/// [2^-250, 2^250], coordinates are multiples of 2^-302, and every value either predicate
/// computes (products of at most three coordinate differences, their sums and exact rounding
/// errors) is 0 or a multiple of 2^-906 below 2^760: all in the normal range. Outside it, a
/// coordinate such as 2e-323 makes products round to 0 and calls a valid triangle degenerate.
pub(super) fn robust_is_exact(coordinates: &[f64]) -> bool {
    const LOW: f64 = 5.527147875260445e-76; // 2^-250
    const HIGH: f64 = 1.8092513943330656e75; // 2^250
    coordinates.iter().all(|&x| x == 0.0 || (LOW..=HIGH).contains(&x.abs()))
}

/// The exact sign of the determinant of a 3x3 or 4x4 matrix of finite numbers.
///
/// Leibniz expansion: every term, a product of N entries, is computed exactly as an integer
/// mantissa (at most 4 x 53 bits) times a power of two, and the terms are accumulated in two wide
/// fixed-point integers (positive and negative terms) whose lowest bit is the smallest power of
/// two among the terms; their comparison gives the sign. Slow (a few microseconds), only used
/// where `robust` is not exact. Non-finite entries give the sign of the float expansion.
pub(super) fn exact_determinant_sign<const N: usize>(matrix: [[f64; N]; N]) -> i8 {
    if matrix.iter().flatten().any(|x| !x.is_finite()) {
        let mut sum = 0.0;
        for (permutation, odd) in permutations::<N>() {
            let product: f64 = (0..N).map(|i| matrix[i][permutation[i]]).product();
            sum += if odd { -product } else { product };
        }
        return sign_of(sum);
    }
    // (negative, mantissa limbs, exponent) of every non-zero term.
    let mut terms: Vec<(bool, Vec<u64>, i64)> = Vec::new();
    for (permutation, odd) in permutations::<N>() {
        let mut negative = odd;
        let mut mantissa = vec![1u64];
        let mut exponent = 0i64;
        let mut zero = false;
        for (i, row) in matrix.iter().enumerate() {
            let (m, e, is_negative) = integer_parts(row[permutation[i]]);
            zero |= m == 0;
            negative ^= is_negative;
            mantissa = multiply_by_word(&mantissa, m);
            exponent += e;
        }
        if !zero {
            terms.push((negative, mantissa, exponent));
        }
    }
    let Some(lowest) = terms.iter().map(|t| t.2).min() else {
        return 0;
    };
    let (mut positive, mut negative) = (Vec::new(), Vec::new());
    for (is_negative, mantissa, exponent) in &terms {
        let sum = if *is_negative { &mut negative } else { &mut positive };
        add_shifted(sum, mantissa, (exponent - lowest) as usize);
    }
    match compare_wide(&positive, &negative) {
        std::cmp::Ordering::Greater => 1,
        std::cmp::Ordering::Less => -1,
        std::cmp::Ordering::Equal => 0,
    }
}

/// `x = ±m 2^e` for a finite `x`: `(m, e, x < 0)`, `m` an integer below 2^53 (0 for zeros).
fn integer_parts(x: f64) -> (u64, i64, bool) {
    let bits = x.to_bits();
    let biased = ((bits >> 52) & 0x7FF) as i64;
    let fraction = bits & ((1u64 << 52) - 1);
    let (m, e) = match biased {
        0 => (fraction, -1074),
        _ => (fraction | (1u64 << 52), biased - 1075),
    };
    (m, e, x < 0.0)
}

/// The permutations of `0..N` with their parity (true for odd), in lexicographic order.
fn permutations<const N: usize>() -> Vec<([usize; N], bool)> {
    let mut out = Vec::new();
    let mut current = [0usize; N];
    fn extend<const N: usize>(k: usize, used: u32, current: &mut [usize; N], out: &mut Vec<([usize; N], bool)>) {
        if k == N {
            let inversions = (0..N)
                .flat_map(|i| (i + 1..N).map(move |j| (i, j)))
                .filter(|&(i, j)| current[i] > current[j])
                .count();
            out.push((*current, inversions % 2 == 1));
            return;
        }
        for v in (0..N).filter(|v| used & (1 << v) == 0) {
            current[k] = v;
            extend(k + 1, used | (1 << v), current, out);
        }
    }
    extend(0, 0, &mut current, &mut out);
    out
}

/// `limbs * m` (little-endian 64-bit limbs).
fn multiply_by_word(limbs: &[u64], m: u64) -> Vec<u64> {
    let mut out = Vec::with_capacity(limbs.len() + 1);
    let mut carry = 0u128;
    for &x in limbs {
        let t = x as u128 * m as u128 + carry;
        out.push(t as u64);
        carry = t >> 64;
    }
    out.push(carry as u64);
    out
}

/// `sum += value * 2^shift` (little-endian 64-bit limbs; `sum` grows as needed).
fn add_shifted(sum: &mut Vec<u64>, value: &[u64], shift: usize) {
    let (words, bits) = (shift / 64, shift % 64);
    let needed = words + value.len() + 2;
    if sum.len() < needed {
        sum.resize(needed, 0);
    }
    let mut carry = 0u128;
    for i in 0..=value.len() {
        let low = value.get(i).copied().unwrap_or(0);
        let high = if i > 0 && bits > 0 {
            value[i - 1] >> (64 - bits)
        } else {
            0
        };
        let word = (low << bits) | high;
        let t = sum[words + i] as u128 + word as u128 + carry;
        sum[words + i] = t as u64;
        carry = t >> 64;
    }
    let mut k = words + value.len() + 1;
    while carry != 0 {
        let t = sum[k] as u128 + carry;
        sum[k] = t as u64;
        carry = t >> 64;
        k += 1;
        if k == sum.len() && carry != 0 {
            sum.push(0);
        }
    }
}

/// Compares two little-endian wide integers (of any lengths, high zero limbs allowed).
fn compare_wide(a: &[u64], b: &[u64]) -> std::cmp::Ordering {
    let n = a.len().max(b.len());
    (0..n)
        .rev()
        .map(|i| a.get(i).copied().unwrap_or(0).cmp(&b.get(i).copied().unwrap_or(0)))
        .find(|o| o.is_ne())
        .unwrap_or(std::cmp::Ordering::Equal)
}

/// The corners of a face.
pub(super) fn corners(mesh: &Mesh3, t: &[u32; 3]) -> [DVec3; 3] {
    t.map(|v| mesh.positions[v as usize])
}

/// The normal of a triangle (twice its area in length, oriented by the corner order), accurate
/// to a few units in the last place of each component whatever the coordinates' magnitude:
///
/// * the cross product is taken at the corner opposite the longest edge, so that the two edges
///   crossed are the two shortest ones: the plain `(b - a) x (c - a)` crosses two long, nearly
///   parallel edges when `a` is far from a short edge `bc`, and at coordinates near 4e9 with
///   faces a few units wide loses 3.5e-8 of a region's area to cancellation;
/// * the edge vectors are computed exactly, as unevaluated sums `hi + lo` (TwoSum), and each
///   component as a difference of products with fused multiply-adds (Kahan's algorithm) plus the
///   first-order terms of the `lo` parts, so that even a needle face (whose largest angle is
///   within 1e-16 of pi) gets a normal of the right direction and length, not 0.
///
/// The orientation checks do not rely on it (they are exact, see [`Regions::side`]); the area
/// and the choice between regions do.
pub(super) fn triangle_normal(t: [DVec3; 3]) -> DVec3 {
    // Squared length of the edge opposite each corner.
    let l = [0, 1, 2].map(|i| (t[(i + 2) % 3] - t[(i + 1) % 3]).length_squared());
    let o = if l[0] >= l[1] && l[0] >= l[2] {
        0
    } else if l[1] >= l[2] {
        1
    } else {
        2
    };
    let (uh, ul) = exact_difference(t[(o + 1) % 3], t[o]);
    let (vh, vl) = exact_difference(t[(o + 2) % 3], t[o]);
    // u_i v_j - u_j v_i, with u = uh + ul and v = vh + vl (the ul vl terms are below rounding).
    let component = |i: usize, j: usize| {
        let main = difference_of_products(uh[i], vh[j], uh[j], vh[i]);
        let tails = (uh[i] * vl[j] + ul[i] * vh[j]) - (uh[j] * vl[i] + ul[j] * vh[i]);
        main + tails
    };
    DVec3::new(component(1, 2), component(2, 0), component(0, 1))
}

/// `p - q` as an unevaluated sum `hi + lo`, exactly per component (Knuth's TwoSum; exact for
/// every finite input whose difference does not overflow, subnormal ones included).
fn exact_difference(p: DVec3, q: DVec3) -> (DVec3, DVec3) {
    let two_diff = |a: f64, b: f64| {
        let s = a - b;
        let virtual_b = s - a;
        let lo = (a - (s - virtual_b)) - (b + virtual_b);
        (s, lo)
    };
    let (x, y, z) = (two_diff(p.x, q.x), two_diff(p.y, q.y), two_diff(p.z, q.z));
    (DVec3::new(x.0, y.0, z.0), DVec3::new(x.1, y.1, z.1))
}

/// `a b - c d` with one rounding error of each product compensated (Kahan's algorithm with
/// fused multiply-adds): within 1.5 units in the last place of the exact value.
fn difference_of_products(a: f64, b: f64, c: f64, d: f64) -> f64 {
    let cd = c * d;
    let cd_error = (-c).mul_add(d, cd); // cd - c d, exactly
    a.mul_add(b, -cd) + cd_error
}

/// Neumaier's compensated summation: the sum of many areas of very different sizes, accurate
/// to about one rounding of the result instead of one per term.
#[derive(Default, Clone, Copy)]
pub(super) struct CompensatedSum {
    pub(super) sum: f64,
    pub(super) compensation: f64,
}

impl CompensatedSum {
    pub(super) fn add(&mut self, x: f64) {
        let t = self.sum + x;
        self.compensation += if self.sum.abs() >= x.abs() {
            (self.sum - t) + x
        } else {
            (x - t) + self.sum
        };
        self.sum = t;
    }

    pub(super) fn value(&self) -> f64 {
        self.sum + self.compensation
    }
}
