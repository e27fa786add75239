//! Sample points on input edges (SPEC §3) and the choice of the sample at
//! which a non-Delaunay sub-edge is split (SPEC §4).
//!
//! Samples are never stored: sample `k` of an input edge is computed from the
//! edge's length and the two global constants. An edge may carry more samples
//! than an `f64` can count (about 10^16 on `mpi_triang.obj`), so indices are
//! `u64`, and the choice works on *ranges* of indices: each of the six score
//! conditions holds on one side of a breakpoint along the edge, so the score
//! is piecewise constant over at most seven index ranges, found by a galloping
//! search from an analytic guess. [`choose_by_enumeration`] visits samples one
//! by one; it is the test oracle and is never used by the algorithm.

use glam::DVec3;

/// The two sample spacings of Liu et al. 2015, from the input's smallest
/// corner angle and shortest edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleConstants {
    /// θ_min, the smallest corner angle of the input, in radians.
    pub theta_min: f64,
    /// l_min, the shortest input edge.
    pub l_min: f64,
    /// ρ_v = min(l_min·sin θ_min / (0.5 + sin θ_min), l_min / 2): distance of
    /// the first and last samples from the edge's ends.
    pub rho_v: f64,
    /// ρ_e = 2·ρ_v·sin θ_min: the largest spacing of the inner samples.
    pub rho_e: f64,
}

impl SampleConstants {
    /// The constants for a mesh with smallest angle `theta_min` and shortest
    /// edge `l_min`.
    pub fn new(theta_min: f64, l_min: f64) -> Self {
        Self::with_sine(theta_min, theta_min.sin(), l_min)
    }

    /// [`SampleConstants::new`], given sin θ_min as well (as
    /// [`crate::mesh::InputFigures::min_angle_sin`] computes it, the same on
    /// every platform, where `sin`'s last bit depends on the C library).
    pub fn with_sine(theta_min: f64, s: f64, l_min: f64) -> Self {
        let rho_v = (l_min * s / (0.5 + s)).min(l_min / 2.0);
        let rho_e = 2.0 * rho_v * s;
        SampleConstants {
            theta_min,
            l_min,
            rho_v,
            rho_e,
        }
    }
}

/// The most samples an edge is given: spacing below length/2^62 is far
/// below f64 resolution anyway.
const MAX_INTERVALS: f64 = 4_611_686_018_427_387_904.0; // 2^62

/// The samples of one input edge of length `len`, computed on demand.
///
/// If `len < 2ρ_v` the only sample is the midpoint; otherwise they are at
/// distance ρ_v + k·step from the first end, k = 0..=n, n = ⌈(len − 2ρ_v)/ρ_e⌉
/// and step = (len − 2ρ_v)/n.
#[derive(Clone, Copy, Debug)]
pub struct EdgeSamples {
    len: f64,
    rho_v: f64,
    step: f64,
    /// 1/step (0 with one sample): the searches' starting guesses multiply
    /// by it, where a division would wait for the one before (they run in
    /// a chain, a dozen a split).
    inv_step: f64,
    count: u64,
}

impl EdgeSamples {
    /// The samples of an input edge of length `len`.
    pub fn new(len: f64, c: &SampleConstants) -> Self {
        let inner = len - 2.0 * c.rho_v;
        let n = if inner > 0.0 { (inner / c.rho_e).ceil() } else { 0.0 };
        if n.is_nan() || n < 1.0 {
            return EdgeSamples {
                len,
                rho_v: len / 2.0,
                step: 0.0,
                inv_step: 0.0,
                count: 1,
            };
        }
        let n = n.min(MAX_INTERVALS);
        EdgeSamples {
            len,
            rho_v: c.rho_v,
            step: inner / n,
            inv_step: n / inner,
            count: n as u64 + 1,
        }
    }

    /// How many samples the edge has.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The index of the sample nearest to parameter `t` (clamped to the
    /// samples that exist).
    pub fn nearest(&self, t: f64) -> u64 {
        if self.count <= 1 || self.step <= 0.0 {
            return 0;
        }
        let k = ((t * self.len - self.rho_v) / self.step).round();
        if k.is_nan() || k < 0.0 {
            0
        } else {
            (k as u64).min(self.count - 1)
        }
    }

    /// The parameter t ∈ (0, 1) of sample `k` along the input edge, measured
    /// from its first end. Non-decreasing in `k` (strictly while the spacing
    /// is above f64 resolution).
    #[inline]
    pub fn t(&self, k: u64) -> f64 {
        // k < count <= 2^62 + 1: through i64, one instruction, the same value.
        debug_assert!(k < 1 << 63);
        (self.rho_v + k as i64 as f64 * self.step) / self.len
    }

    /// The index of the sample at about distance `d` from the first end (a
    /// starting guess for searches, whose results do not depend on it).
    #[inline]
    fn guess_at(&self, d: f64) -> f64 {
        (d - self.rho_v) * self.inv_step
    }
}

/// The position of the point at parameter `t` on the input edge (p0, p1): the
/// one formula used for every added vertex, so that the same `t` always gives
/// the same coordinates.
#[inline]
pub fn point_on_edge(p0: DVec3, p1: DVec3, t: f64) -> DVec3 {
    p0 + t * (p1 - p0)
}

/// Which of the report's scores ranks the samples (`-s`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Score {
    /// `-s 0`, "all equal": +1 per Delaunay edge among the six.
    AllEqual,
    /// `-s 1`, "weighted center": +1.5 per Delaunay half, +1 per outer edge.
    WeightedCenter,
    /// `-s 2`, "always center": +5 if both halves are Delaunay (else +1 per
    /// Delaunay half), +1 per Delaunay outer edge.
    AlwaysCenter,
    /// `-s 3`, "split-aware" (delmesh's own): as always center, but an outer
    /// edge that can be flipped counts as Delaunay either way — if it turns
    /// non-Delaunay it costs a flip, never a vertex.
    SplitAware,
    /// `-s 4`, "uniform" (delmesh's own): every sample scores the same, so
    /// the rule that picks among the best alone decides: with the median the
    /// middle sample, with [`SplitQuery::shells`] the shell point.
    Uniform,
}

impl Score {
    /// Every score, in the order of their `-s` numbers (0 to 4).
    pub const ALL: [Score; 5] = [
        Score::AllEqual,
        Score::WeightedCenter,
        Score::AlwaysCenter,
        Score::SplitAware,
        Score::Uniform,
    ];

    /// The score, doubled so that it is an integer.
    pub fn doubled(self, halves: [bool; 2], outer_delaunay: u32) -> u32 {
        let h = halves.iter().filter(|&&x| x).count() as u32;
        self.doubled_from_counts(h, outer_delaunay)
    }

    /// [`Score::doubled`] from the number `h` of Delaunay halves, written
    /// without a branch on the counts.
    #[inline]
    fn doubled_from_counts(self, h: u32, outer_delaunay: u32) -> u32 {
        let outer = 2 * outer_delaunay;
        match self {
            Score::AllEqual => 2 * h + outer,
            Score::WeightedCenter => 3 * h + outer,
            // 10 (not 4) when both halves are Delaunay.
            Score::AlwaysCenter | Score::SplitAware => 2 * h + 6 * (h == 2) as u32 + outer,
            Score::Uniform => 0,
        }
    }
}

/// Which side of its breakpoint a condition holds on, along the sub-edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Holds where x ≤ breakpoint.
    AtMost,
    /// Holds where x ≥ breakpoint.
    AtLeast,
}

/// One of the six conditions of a split, as a half-line of the sub-edge: x
/// is the distance of the split point from the sub-edge's start `a`. A NaN
/// breakpoint (degenerate circle) means the condition always holds.
#[derive(Clone, Copy, Debug)]
pub struct Condition {
    /// The side of the breakpoint where the condition holds.
    pub side: Side,
    /// Where along the sub-edge the condition changes.
    pub breakpoint: f64,
}

impl Condition {
    /// Whether the condition holds at `x`.
    #[inline]
    pub fn holds(&self, x: f64) -> bool {
        match self.side {
            _ if self.breakpoint.is_nan() => true,
            Side::AtMost => x <= self.breakpoint,
            Side::AtLeast => x >= self.breakpoint,
        }
    }
}

/// Everything the choice of a split sample depends on.
#[derive(Clone, Copy, Debug)]
pub struct SplitQuery<'a> {
    /// The samples of the input edge carrying the sub-edge.
    pub samples: &'a EdgeSamples,
    /// The input edge's end points (t = 0 and t = 1).
    pub edge_ends: [DVec3; 2],
    /// Parameter of the sub-edge's start `a` (the origin of the half-edge
    /// taken from DS) and of its end `b`.
    pub t_a: f64,
    /// See `t_a`.
    pub t_b: f64,
    /// Positions of `a` and `b`: a sample that rounds onto one is skipped.
    pub pos_a: DVec3,
    /// See `pos_a`.
    pub pos_b: DVec3,
    /// The conditions for the halves (a, p) and (p, b).
    pub halves: [Condition; 2],
    /// The conditions for the four outer edges.
    pub outer: [Condition; 4],
    /// Which outer edges can be flipped (used by [`Score::SplitAware`]).
    pub outer_flippable: [bool; 4],
    /// The score.
    pub score: Score,
    /// Median of the best samples (`true`) or the first one from `a`.
    pub median: bool,
    /// The best sample nearest [`shell_target`] instead (the median rule is
    /// then ignored).
    pub shells: bool,
}

impl SplitQuery<'_> {
    /// The outer edges that count as Delaunay whatever the split point, as
    /// bits 2..6 (numbered as in [`SplitQuery::conditions`]).
    #[inline]
    fn free_outer_mask(&self) -> u8 {
        let split_aware = self.score == Score::SplitAware;
        (0..4).fold(0, |m, i| {
            m | (((split_aware & self.outer_flippable[i]) as u8) << (i + 2))
        })
    }

    /// The six conditions: the halves (0, 1), then the outer edges (2..6).
    fn conditions(&self) -> [Condition; 6] {
        let ([h0, h1], [o0, o1, o2, o3]) = (self.halves, self.outer);
        [h0, h1, o0, o1, o2, o3]
    }

    /// The doubled score of a split point at which condition `i` holds
    /// when `holds(i)` (numbered as in [`SplitQuery::conditions`]).
    fn score_where(&self, holds: impl Fn(usize) -> bool) -> u32 {
        self.score_of_mask((0..6).fold(0, |m, i| m | ((holds(i) as u8) << i)))
    }

    /// The doubled score of a split point at which condition `i` holds when
    /// bit `i` of `mask` is set.
    #[inline]
    fn score_of_mask(&self, mask: u8) -> u32 {
        self.score_of_mask_with(mask, self.free_outer_mask())
    }

    /// [`SplitQuery::score_of_mask`], given [`SplitQuery::free_outer_mask`].
    #[inline]
    fn score_of_mask_with(&self, mask: u8, free: u8) -> u32 {
        // Bit counts by table: the baseline x86-64 has no popcnt.
        const ONES: [u8; 16] = [0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4];
        let h = ONES[(mask & 0b11) as usize] as u32;
        let outer = ONES[((mask | free) >> 2 & 0b1111) as usize] as u32;
        self.score.doubled_from_counts(h, outer)
    }
}

/// The chosen sample: its index on the input edge and its parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Choice {
    /// Index of the sample on its input edge.
    pub k: u64,
    /// Its parameter t along the input edge.
    pub t: f64,
}

/// The samples strictly inside a sub-edge, listed from `a` to `b`:
/// local index j ↦ sample index k.
#[derive(Clone, Copy)]
struct Window<'a> {
    samples: &'a EdgeSamples,
    /// Parameter of the sub-edge's start `a`.
    t_a: f64,
    first: u64,
    count: u64,
    forward: bool,
}

impl<'a> Window<'a> {
    fn new(q: &SplitQuery<'a>) -> Option<Self> {
        let s = q.samples;
        let forward = q.t_a < q.t_b;
        let (t_lo, t_hi, p_lo, p_hi) = if forward {
            (q.t_a, q.t_b, q.pos_a, q.pos_b)
        } else {
            (q.t_b, q.t_a, q.pos_b, q.pos_a)
        };
        let pos = |k: u64| point_on_edge(q.edge_ends[0], q.edge_ends[1], s.t(k));
        // First sample past the low end (in t and in rounded position) ...
        let first = first_true(s.count, s.guess_at(t_lo * s.len), |k| s.t(k) > t_lo && pos(k) != p_lo);
        // ... and first sample at or past the high end.
        let end = first_true(s.count, s.guess_at(t_hi * s.len), |k| {
            !(s.t(k) < t_hi && pos(k) != p_hi)
        });
        (first < end).then_some(Window {
            samples: q.samples,
            t_a: q.t_a,
            first,
            count: end - first,
            forward,
        })
    }

    #[inline]
    fn k(&self, j: u64) -> u64 {
        if self.forward {
            self.first + j
        } else {
            self.first + self.count - 1 - j
        }
    }

    /// Distance of sample j from `a`, measured along the input edge;
    /// non-decreasing in j.
    #[inline]
    fn x(&self, j: u64) -> f64 {
        let t = self.samples.t(self.k(j));
        let d = if self.forward { t - self.t_a } else { self.t_a - t };
        d * self.samples.len
    }

    /// The sample in the middle of the window (by index).
    fn middle(&self) -> Choice {
        let k = self.k(self.count / 2);
        Choice {
            k,
            t: self.samples.t(k),
        }
    }

    /// Local index about at distance `x` from `a` (a starting guess for a
    /// search).
    #[inline]
    fn guess(&self, x: f64) -> f64 {
        let s = self.samples;
        let from_a = if self.forward { x } else { -x };
        self.local(s.guess_at(self.t_a * s.len + from_a))
    }

    /// The local index of (real) sample index `k`.
    #[inline]
    fn local(&self, k: f64) -> f64 {
        if self.forward {
            k - self.first as f64
        } else {
            (self.first + self.count - 1) as f64 - k
        }
    }

    /// The local index of the sample nearest parameter `t` (clamped to the
    /// window). Its guess is the neighbourhood that [`Pieces::choose`]
    /// searches (`--shells`), so it is computed as it always was, with
    /// divisions: the same guess, the same choices.
    fn nearest_local(&self, t: f64) -> u64 {
        let s = self.samples;
        let x = if self.forward { t - self.t_a } else { self.t_a - t };
        let x = x * s.len;
        let t = if self.forward {
            self.t_a + x / s.len
        } else {
            self.t_a - x / s.len
        };
        let k = if s.step > 0.0 {
            (t * s.len - s.rho_v) / s.step
        } else {
            0.0
        };
        let g = self.local(k).round();
        if g.is_nan() || g <= 0.0 {
            0
        } else {
            (g as u64).min(self.count - 1)
        }
    }

    /// The first local index at which `c` changes value (the first j with
    /// x > breakpoint for `AtMost`, with x ≥ breakpoint for `AtLeast`).
    #[inline]
    fn cut(&self, c: &Condition) -> u64 {
        if c.breakpoint.is_nan() {
            return 0;
        }
        let g = self.guess(c.breakpoint);
        // One predicate for both sides (`|` and `&`, not `||` and `&&`: the
        // side alternates from condition to condition, so a branch on it is
        // mispredicted about half the time).
        let at_least = c.side == Side::AtLeast;
        first_true(self.count, g, |j| {
            let x = self.x(j);
            (x > c.breakpoint) | (at_least & (x == c.breakpoint))
        })
    }
}

/// `v` in increasing order, by a sorting network (12 compare-exchanges,
/// each a `min` and a `max`: no branch on the values).
#[inline]
fn sorted6(mut v: [u64; 6]) -> [u64; 6] {
    const PAIRS: [(usize, usize); 12] = [
        (0, 5),
        (1, 3),
        (2, 4),
        (1, 2),
        (3, 4),
        (0, 3),
        (2, 5),
        (0, 1),
        (2, 3),
        (4, 5),
        (1, 2),
        (3, 4),
    ];
    for (i, j) in PAIRS {
        let (a, b) = (v[i], v[j]);
        v[i] = a.min(b);
        v[j] = a.max(b);
    }
    v
}

/// The first index in `0..n` at which the monotone predicate `pred` (false
/// then true) is true, or `n`. Gallops from `guess` (clamped; NaN is 0), so it
/// costs O(log |answer − guess|) evaluations.
pub fn first_true(n: u64, guess: f64, pred: impl Fn(u64) -> bool) -> u64 {
    if n == 0 {
        return 0;
    }
    // Through i64 (one instruction; n - 1 < 9e18 < 2^63, so the clamp to
    // 9e18 first changes nothing).
    let g = if guess >= 0.0 {
        (guess.min(9e18) as i64 as u64).min(n - 1)
    } else {
        0
    };
    // Bracket: pred is false below `lo`, and true at `hi` (or hi == n).
    let (mut lo, mut hi);
    if pred(g) {
        hi = g;
        lo = 0;
        let mut step = 1u64;
        while step <= g {
            let c = g - step;
            if pred(c) {
                hi = c;
                step = step.saturating_mul(2);
            } else {
                lo = c + 1;
                break;
            }
        }
    } else {
        lo = g + 1;
        hi = n;
        let mut step = 1u64;
        loop {
            let c = g.saturating_add(step);
            if c >= n {
                break;
            }
            if pred(c) {
                hi = c;
                break;
            }
            lo = c + 1;
            step = step.saturating_mul(2);
        }
    }
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if pred(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

/// Chooses the sample at which to split, without visiting samples one by
/// one; `None` if no sample lies strictly inside the sub-edge.
///
/// The best score over the sub-edge's samples is found piece by piece, the
/// pieces being delimited by the six conditions' breakpoints. Among the best
/// samples, ordered from `a` to `b`, it takes the median (the lower one of an
/// even count) or the first.
pub fn choose(q: &SplitQuery) -> Option<Choice> {
    Some(Pieces::new(q)?.choose(q))
}

/// The sample in the middle of the sub-edge of `q` (by index), whatever
/// the score: the fallback when the chosen sample lands too close to a
/// vertex for the coordinates to resolve (`None`: no sample inside).
pub fn middle(q: &SplitQuery) -> Option<Choice> {
    Some(Window::new(q)?.middle())
}

/// The samples inside a sub-edge cut into seven pieces (runs of
/// consecutive samples, some of them empty) on each of which every one of
/// the six conditions either holds or not: what [`choose`] computes before
/// scoring. The pieces do not depend on the score or the median rule, so
/// one `Pieces` serves every variant of a query ([`Pieces::choose`]).
///
/// Which pieces are empty and which conditions hold vary from split to
/// split, so both are computed here, not branched on (a sorting network,
/// bit masks): branches on them were mispredicted about 20 times a split.
#[derive(Clone, Copy)]
pub struct Pieces<'a> {
    w: Window<'a>,
    /// Piece k holds the local indices `bounds[k]..bounds[k + 1]`: 0, the
    /// six conditions' cuts in increasing order, the window's count.
    bounds: [u64; 8],
    /// Which conditions hold on piece k: bit i for condition i, the halves
    /// 0 and 1 then the outer edges 2..6.
    masks: [u8; 7],
}

impl<'a> Pieces<'a> {
    /// The pieces of the sub-edge of `q`; `None` if no sample lies strictly
    /// inside it.
    pub fn new(q: &SplitQuery<'a>) -> Option<Self> {
        let w = Window::new(q)?;
        let conds = q.conditions();
        let cuts = conds.map(|c| w.cut(&c));
        let mut bounds = [0u64; 8];
        bounds[1..7].copy_from_slice(&sorted6(cuts));
        bounds[7] = w.count;
        // Condition i holds at local index j iff its breakpoint is NaN, or
        // j < cut (AtMost), or j ≥ cut (AtLeast): with `passed` the
        // conditions whose cut is at most j, the mask is
        // always | (passed ^ at_most).
        let (mut always, mut at_most) = (0u8, 0u8);
        for (i, c) in conds.iter().enumerate() {
            always |= (c.breakpoint.is_nan() as u8) << i;
            at_most |= ((c.side == Side::AtMost) as u8) << i;
        }
        let masks = std::array::from_fn(|k| {
            let passed = (0..6).fold(0u8, |m, i| m | (((cuts[i] <= bounds[k]) as u8) << i));
            always | (passed ^ at_most)
        });
        Some(Pieces { w, bounds, masks })
    }

    /// The sample that the score and median rule of `q` choose (`q` being
    /// the query these pieces were made from, or one differing from it only
    /// in those two).
    pub fn choose(&self, q: &SplitQuery) -> Choice {
        let free = q.free_outer_mask();
        let (lo, hi) = (|k: usize| self.bounds[k], |k: usize| self.bounds[k + 1]);
        // Each piece's score plus one, 0 for an empty piece: the best is that
        // of a non-empty piece (a window has one).
        let ranks: [u32; 7] =
            std::array::from_fn(|k| (q.score_of_mask_with(self.masks[k], free) + 1) * (lo(k) < hi(k)) as u32);
        let best = *ranks.iter().max().expect("seven pieces");
        let j = if q.shells {
            // The best sample nearest the shell point (ties: the first from
            // `a`): in each best piece, the index guessed for the target,
            // clamped to the piece, or a neighbour (the guess can be one off).
            let target = shell_target(q);
            let g = self.w.nearest_local(target);
            let mut nearest: Option<(f64, u64)> = None;
            for k in (0..7).filter(|&k| ranks[k] == best) {
                for j in [g.saturating_sub(1), g, g + 1].map(|j| j.clamp(lo(k), hi(k) - 1)) {
                    let d = (self.w.samples.t(self.w.k(j)) - target).abs();
                    if nearest.is_none_or(|(best_d, best_j)| (d, j) < (best_d, best_j)) {
                        nearest = Some((d, j));
                    }
                }
            }
            nearest.expect("best is a score").1
        } else if q.median {
            // The best samples counted, then the middle one found, piece by
            // piece without branching on which pieces are best.
            let sizes: [u64; 7] = std::array::from_fn(|k| if ranks[k] == best { hi(k) - lo(k) } else { 0 });
            let total: u64 = sizes.iter().sum();
            let mut rank = (total - 1) / 2;
            let mut found = u64::MAX;
            for (k, &size) in sizes.iter().enumerate() {
                let here = (found == u64::MAX) & (rank < size);
                found = if here { lo(k) + rank } else { found };
                rank = if found == u64::MAX { rank - size } else { rank };
            }
            found
        } else {
            lo(ranks.iter().position(|&r| r == best).expect("best is a rank"))
        };
        let k = self.w.k(j);
        Choice {
            k,
            t: self.w.samples.t(k),
        }
    }

    /// The sample in the middle of the sub-edge (by index).
    pub fn middle(&self) -> Choice {
        self.w.middle()
    }
}

/// The concentric-shell split point of the sub-edge of `q`, as a parameter
/// on its input edge (the rule of Ruppert's and Shewchuk's "concentric
/// shells", used for Delaunay meshes by Dyer et al. 2007). If exactly one
/// end of the sub-edge is an end of the input edge (an input vertex `v`),
/// the point at distance ρ_v·2^k from `v`, with k ≥ 0 the integer that puts
/// it nearest the sub-edge's middle (so between 0.35 and 0.71 of the way,
/// or ρ_v itself on a sub-edge shorter than 1.41 ρ_v); otherwise the
/// sub-edge's middle.
///
/// ```text
///            ρ_v  2ρ_v     4ρ_v            8ρ_v
///   v *-------+----+---------+----------------+------ input edge
///      \       .    .          .                .
///       *------+----+----------+----------------+-- another edge at v
/// ```
///
/// Every edge at `v` is then split at the same distances from it, so the
/// new vertices around `v` lie on the same spheres: the thin triangles of a
/// fan (a cone's tip, a CAD disk's centre) keep their two long sides equal,
/// and stay Delaunay, where points chosen edge by edge (the median) differ
/// slightly from edge to edge and make the next edge non-Delaunay, all the
/// way down to the vertex. Splits still go to samples only: the nearest
/// one is taken ([`Pieces::choose`]).
pub fn shell_target(q: &SplitQuery) -> f64 {
    let (lo, hi) = (q.t_a.min(q.t_b), q.t_a.max(q.t_b));
    let len = (hi - lo) * q.samples.len;
    let rho_v = q.samples.rho_v;
    if (lo == 0.0) == (hi == 1.0) || !(rho_v > 0.0 && len > 0.0) {
        return (lo + hi) / 2.0;
    }
    // 2^k nearest r = len / (2 ρ_v) on a log scale, k ≥ 0, exactly (no
    // `log2`, whose last bit differs between C libraries): with
    // 2^e ≤ r < 2^(e + 1), k = e + 1 where r ≥ 2^e·√2, else e. (No double
    // lies between 2^e·√2 and 2^e·`SQRT_2`, its rounding upwards.)
    let r = len / (2.0 * rho_v);
    if !r.is_finite() {
        return (lo + hi) / 2.0; // ρ_v far below the sub-edge: no sample inside
    }
    let k = if r < 1.0 {
        0
    } else {
        let e = crate::geometry::binary_exponent(r);
        e + (r >= std::f64::consts::SQRT_2 * 2f64.powi(e)) as i32
    };
    let d = rho_v * 2f64.powi(k);
    if d >= len {
        return (lo + hi) / 2.0; // no sample inside anyway
    }
    let d = d / q.samples.len;
    if lo == 0.0 {
        lo + d
    } else {
        hi - d
    }
}

/// The middle of the longest stretch of the sub-edge of `q` where its score
/// is best, as a parameter on the input edge: unlike [`choose`], any point
/// of the sub-edge, not only a sample (the split point of SplitToDelaunay,
/// the public C++ re-implementation of Liu et al.). `None` if that middle
/// is not strictly inside the sub-edge (it has no length).
///
/// Algorithm 2 never splits there (only samples bound its work); pruning
/// tries it as one more place for the vertex that replaces others: a point
/// between two samples can keep more edges Delaunay than either.
pub fn best_interval_middle(q: &SplitQuery) -> Option<f64> {
    let len = q.samples.len * (q.t_b - q.t_a).abs();
    let conds = q.conditions();
    // Stretch ends: 0, the breakpoints inside the sub-edge, its length.
    let mut ends = [0.0f64; 8];
    let mut n = 1;
    for c in &conds {
        if c.breakpoint > 0.0 && c.breakpoint < len {
            ends[n] = c.breakpoint;
            n += 1;
        }
    }
    ends[n] = len;
    let ends = &mut ends[..n + 1];
    ends.sort_by(f64::total_cmp);
    // (score, start, end) of the best stretch so far; the first longest wins.
    let mut best: Option<(u32, f64, f64)> = None;
    for w in ends.windows(2).filter(|w| w[1] > w[0]) {
        let x = 0.5 * (w[0] + w[1]);
        let score = q.score_where(|i| conds[i].holds(x));
        if best.is_none_or(|(s, lo, hi)| score > s || (score == s && w[1] - w[0] > hi - lo)) {
            best = Some((score, w[0], w[1]));
        }
    }
    let (_, lo, hi) = best?;
    let x = 0.5 * (lo + hi);
    let t = if q.t_a < q.t_b {
        q.t_a + x / q.samples.len
    } else {
        q.t_a - x / q.samples.len
    };
    (t > q.t_a.min(q.t_b) && t < q.t_a.max(q.t_b)).then_some(t)
}

/// The test oracle for [`choose`]: scores every sample inside the sub-edge
/// one by one with `holds(condition index, x)` evaluated pointwise, where
/// conditions 0 and 1 are the halves and 2..6 the outer edges. Only usable
/// on edges with few samples.
pub fn choose_by_enumeration(q: &SplitQuery, holds: impl Fn(usize, f64) -> bool) -> Option<Choice> {
    let s = q.samples;
    let (t_lo, t_hi) = (q.t_a.min(q.t_b), q.t_a.max(q.t_b));
    let mut inside: Vec<u64> = (0..s.count())
        .filter(|&k| {
            let t = s.t(k);
            let p = point_on_edge(q.edge_ends[0], q.edge_ends[1], t);
            t > t_lo && t < t_hi && p != q.pos_a && p != q.pos_b
        })
        .collect();
    if q.t_a > q.t_b {
        inside.reverse();
    }
    let scored: Vec<(u64, u32)> = inside
        .iter()
        .map(|&k| {
            let x = (s.t(k) - q.t_a).abs() * s.len;
            (k, q.score_where(|i| holds(i, x)))
        })
        .collect();
    let best = scored.iter().map(|p| p.1).max()?;
    let winners: Vec<u64> = scored.iter().filter(|p| p.1 == best).map(|p| p.0).collect();
    let k = if q.shells {
        // Nearest the shell point; ties: the first from `a`.
        let target = shell_target(q);
        let d = |k: u64| (s.t(k) - target).abs();
        let mut nearest = winners[0];
        for &k in &winners[1..] {
            if d(k) < d(nearest) {
                nearest = k;
            }
        }
        nearest
    } else if q.median {
        winners[(winners.len() - 1) / 2]
    } else {
        winners[0]
    };
    Some(Choice { k, t: s.t(k) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constants_follow_the_formulas() {
        let c = SampleConstants::new(std::f64::consts::FRAC_PI_6, 2.0);
        // sin 30° = 0.5: ρ_v = min(2·0.5/1, 1) = 1, ρ_e = 2·1·0.5 = 1.
        assert!((c.rho_v - 1.0).abs() < 1e-15 && (c.rho_e - 1.0).abs() < 1e-15);
        let c = SampleConstants::new(0.1, 1.0);
        let s = 0.1f64.sin();
        assert_eq!(c.rho_v, (s / (0.5 + s)).min(0.5));
        assert_eq!(c.rho_e, 2.0 * c.rho_v * s);
        // θ_min above 30° (nearly equilateral triangles): l_min·sin θ/(0.5 +
        // sin θ) passes l_min/2, which caps ρ_v.
        let c = SampleConstants::new(std::f64::consts::FRAC_PI_3, 3.0);
        assert_eq!(c.rho_v, 1.5);
        assert_eq!(c.rho_e, 3.0 * std::f64::consts::FRAC_PI_3.sin());
    }

    #[test]
    fn sample_positions() {
        // ρ_v = ρ_e = 1. Length 10: samples at 1, 2, ..., 9 (n = 8 intervals).
        let c = SampleConstants::new(std::f64::consts::FRAC_PI_6, 2.0);
        let s = EdgeSamples::new(10.0, &c);
        assert_eq!(s.count(), 9);
        for k in 0..9 {
            assert!((s.t(k) * 10.0 - (1.0 + k as f64)).abs() < 1e-12);
        }
        // The nearest sample, clamped to those that exist.
        let nearest = [0.0, 0.14, 0.26, 0.5, 0.74, 0.96, 1.0, -1.0, f64::NAN].map(|t| s.nearest(t));
        assert_eq!(nearest, [0, 0, 2, 4, 6, 8, 8, 0, 0]);
        // Length 3.5: samples at 1 and 2.5 and one between: n = ⌈1.5⌉ = 2.
        let s = EdgeSamples::new(3.5, &c);
        assert_eq!(s.count(), 3);
        assert!((s.t(1) * 3.5 - 1.75).abs() < 1e-12);
        // The nearest sample on a spacing other than 1 (0.75 here): t = 0.7
        // lies at 2.45, nearest the sample at 2.5.
        assert_eq!(s.nearest(0.7), 2);
        // Shorter than 2ρ_v: the midpoint only.
        let s = EdgeSamples::new(1.5, &c);
        assert_eq!((s.count(), s.t(0)), (1, 0.5));
        // Exactly 2ρ_v: one sample, the midpoint.
        let s = EdgeSamples::new(2.0, &c);
        assert_eq!((s.count(), s.t(0)), (1, 0.5));
    }

    #[test]
    fn huge_sample_counts_are_integers() {
        // The needle constants of mpi_triang: ~10^16 samples on an edge.
        let c = SampleConstants::new(3.5e-7, 1.0);
        let s = EdgeSamples::new(1.7e4, &c);
        assert!(s.count() > 1u64 << 53);
        assert!(s.t(s.count() - 1) < 1.0 && s.t(0) > 0.0);
        // Monotone even where neighbouring samples round together.
        let mut last = 0.0;
        for k in (s.count() - 1000)..s.count() {
            assert!(s.t(k) >= last);
            last = s.t(k);
        }
    }

    #[test]
    fn first_true_finds_the_boundary_from_any_guess() {
        for n in [0u64, 1, 2, 3, 10, 1000] {
            for answer in 0..=n.min(12) {
                for guess in [-5.0, 0.0, 1.0, 3.7, 9.0, 500.0, 1e30, f64::NAN] {
                    assert_eq!(
                        first_true(n, guess, |j| j >= answer),
                        answer,
                        "n {n} answer {answer} guess {guess}"
                    );
                }
            }
        }
        let n = u64::MAX / 4;
        assert_eq!(first_true(n, 12.0, |j| j >= n / 3), n / 3);
        assert_eq!(first_true(n, 1e300, |j| j >= 7), 7);
    }

    #[test]
    fn the_sorting_network_sorts() {
        // Every 0/1 input (which suffices for a comparator network), then
        // inputs with ties and large values.
        for bits in 0u32..64 {
            let v: [u64; 6] = std::array::from_fn(|i| ((bits >> i) & 1) as u64);
            let mut want = v;
            want.sort_unstable();
            assert_eq!(sorted6(v), want, "{v:?}");
        }
        let mut rng = crate::test_rng::Rng(6);
        for _ in 0..1000 {
            let v: [u64; 6] = std::array::from_fn(|_| rng.below(4) * (u64::MAX / 3));
            let mut want = v;
            want.sort_unstable();
            assert_eq!(sorted6(v), want, "{v:?}");
        }
    }

    /// [`shell_target`] on the sub-edge from `t_a` to `t_b` of `samples`'
    /// edge, from (0, 0, 0) to (100, 0, 0) (no condition ever holds).
    fn shell_target_on(samples: &EdgeSamples, t_a: f64, t_b: f64) -> f64 {
        let at = |t: f64| DVec3::new(100.0 * t, 0.0, 0.0);
        let never = Condition {
            side: Side::AtMost,
            breakpoint: -1.0,
        };
        shell_target(&SplitQuery {
            samples,
            edge_ends: [DVec3::ZERO, DVec3::new(100.0, 0.0, 0.0)],
            t_a,
            t_b,
            pos_a: at(t_a),
            pos_b: at(t_b),
            halves: [never; 2],
            outer: [never; 4],
            outer_flippable: [false; 4],
            score: Score::AlwaysCenter,
            median: true,
            shells: true,
        })
    }

    #[test]
    fn shell_targets_are_powers_of_two_of_rho_v_from_the_input_vertex() {
        let c = SampleConstants::new(std::f64::consts::FRAC_PI_6, 2.0); // ρ_v = ρ_e = 1
        let samples = EdgeSamples::new(100.0, &c);
        let target = |t_a: f64, t_b: f64| shell_target_on(&samples, t_a, t_b);
        // 30 long from the input vertex at t = 0: 2^4 = 16 is the power of
        // two nearest 15 on a log scale; from either direction.
        assert_eq!(target(0.0, 0.3), 0.16);
        assert_eq!(target(0.3, 0.0), 0.16);
        // From the vertex at t = 1.
        assert_eq!(target(0.7, 1.0), 1.0 - 0.16);
        // 2.2 from it: 2^0 = ρ_v (1.1 is nearer 1 than 2).
        assert_eq!(target(0.0, 0.022), 0.01);
        // 20 long: 10 is nearer 8 than 16 on a log scale (log2 10 = 3.3).
        assert_eq!(target(0.0, 0.2), 0.08);
        // The whole input edge, or no input vertex at either end: the middle.
        assert_eq!(target(0.0, 1.0), 0.5);
        assert_eq!(target(0.2, 0.6), 0.4);
        // Shorter than ρ_v from the vertex: no shell inside, the middle.
        assert_eq!(target(0.0, 0.005), 0.0025);
        // Shorter than 2ρ_v but longer than ρ_v: r = 0.3 < 1, so 2^0 = ρ_v,
        // not 2^-2 (nearer 0.3 on a log scale): shells stop at ρ_v, the
        // first sample, and ρ_v does not fit inside 0.6 with room to spare.
        assert_eq!(target(0.0, 0.006), 0.003);
    }

    #[test]
    fn shell_targets_scale_with_rho_v() {
        // sin θ = 1/2, l_min = 4: ρ_v = min(4·0.5/1, 2) = 2.
        let c = SampleConstants::with_sine(std::f64::consts::FRAC_PI_6, 0.5, 4.0);
        assert_eq!(c.rho_v, 2.0);
        let samples = EdgeSamples::new(100.0, &c);
        // 30 from the vertex: r = 30/(2·2) = 7.5, nearest 2^3 on a log
        // scale, so 2·8 = 16 from it.
        assert_eq!(shell_target_on(&samples, 0.0, 0.3), 0.16);
        assert_eq!(shell_target_on(&samples, 1.0, 0.7), 1.0 - 0.16);
        // A subnormal ρ_v (l_min 1e-310): r = len/(2ρ_v) overflows, and
        // no power of two of ρ_v is looked for: the middle.
        let c = SampleConstants::with_sine(std::f64::consts::FRAC_PI_6, 0.5, 1e-310);
        assert!(c.rho_v > 0.0 && c.rho_v < f64::MIN_POSITIVE);
        let samples = EdgeSamples::new(100.0, &c);
        assert_eq!(shell_target_on(&samples, 0.0, 0.5), 0.25);
        assert_eq!(shell_target_on(&samples, 1.0, 0.5), 0.75);
    }

    /// The samples of an edge of length 10 with ρ_v = ρ_e = 1 exactly (sin θ
    /// given, not computed): at x = 1, ..., 9 (k = 0, ..., 8).
    fn ten_samples() -> EdgeSamples {
        EdgeSamples::new(10.0, &SampleConstants::with_sine(std::f64::consts::FRAC_PI_6, 0.5, 2.0))
    }

    /// A query on the sub-edge from x = `a` to x = `b` of [`ten_samples`]'
    /// edge, from (0, 0, 0) to (10, 0, 0): no condition ever holds, score
    /// all-equal, median.
    fn query_on_ten(samples: &EdgeSamples, a: f64, b: f64) -> SplitQuery<'_> {
        let at = |x: f64| DVec3::new(x, 0.0, 0.0);
        let never = Condition {
            side: Side::AtMost,
            breakpoint: -1.0,
        };
        SplitQuery {
            samples,
            edge_ends: [at(0.0), at(10.0)],
            t_a: a / 10.0,
            t_b: b / 10.0,
            pos_a: at(a),
            pos_b: at(b),
            halves: [never; 2],
            outer: [never; 4],
            outer_flippable: [false; 4],
            score: Score::AllEqual,
            median: true,
            shells: false,
        }
    }

    #[test]
    fn the_best_interval_middle_has_the_best_score() {
        let samples = ten_samples();
        let cond = |side, breakpoint| Condition { side, breakpoint };
        let mut q = SplitQuery {
            // Both halves Delaunay on x in [2.5, 4.0] (from a), outer edges
            // on [0, 3.2], [3.0, 7], never, always.
            halves: [cond(Side::AtMost, 4.0), cond(Side::AtLeast, 2.5)],
            outer: [
                cond(Side::AtMost, 3.2),
                cond(Side::AtLeast, 3.0),
                cond(Side::AtMost, -1.0),
                cond(Side::AtLeast, f64::NAN),
            ],
            score: Score::AlwaysCenter,
            ..query_on_ten(&samples, 2.0, 9.0)
        };
        let score_at = |q: &SplitQuery, x: f64| {
            let conds = [q.halves[0], q.halves[1], q.outer[0], q.outer[1], q.outer[2], q.outer[3]];
            let outer = (2..6).filter(|&i| conds[i].holds(x)).count() as u32;
            q.score.doubled([conds[0].holds(x), conds[1].holds(x)], outer)
        };
        for forward in [true, false] {
            if !forward {
                // The same sub-edge walked from its other end.
                q.t_a = 0.9;
                q.t_b = 0.2;
                q.halves = [cond(Side::AtMost, 4.5), cond(Side::AtLeast, 3.0)];
                q.outer = [
                    cond(Side::AtMost, 4.0),
                    cond(Side::AtLeast, 3.8),
                    cond(Side::AtMost, -1.0),
                    cond(Side::AtLeast, f64::NAN),
                ];
            }
            let t = best_interval_middle(&q).unwrap();
            assert!(t > 0.2 && t < 0.9);
            let x = (t - q.t_a).abs() * 10.0;
            let best = (1..700).map(|i| score_at(&q, i as f64 * 0.01)).max().unwrap();
            assert_eq!(score_at(&q, x), best, "forward {forward}: x {x}");
        }
        // Forward: best (both halves, outer 0, 1, 3) on [3.0, 3.2]: its middle.
        q.t_a = 0.2;
        q.t_b = 0.9;
        q.halves = [cond(Side::AtMost, 4.0), cond(Side::AtLeast, 2.5)];
        q.outer[0] = cond(Side::AtMost, 3.2);
        q.outer[1] = cond(Side::AtLeast, 3.0);
        assert!((best_interval_middle(&q).unwrap() - 0.51).abs() < 1e-12);
    }

    #[test]
    fn the_best_interval_middle_takes_the_first_longest_stretch_inside() {
        let samples = ten_samples();
        let cond = |side, breakpoint| Condition { side, breakpoint };
        let always = cond(Side::AtLeast, f64::NAN);
        // The sub-edge from x = 2 to x = 9 (7 long); all-equal scores: two
        // per condition that holds.
        let on = |halves, outer| {
            let q = SplitQuery {
                halves,
                outer,
                ..query_on_ten(&samples, 2.0, 9.0)
            };
            best_interval_middle(&q).map(|t| (t - 0.2) * 10.0)
        };
        let near = |x: Option<f64>, want: f64| x.is_some_and(|x| (x - want).abs() < 1e-12);
        // Best on the last stretch, [4, 7], which ends at the sub-edge's
        // length; before the sub-edge starts (x < 0, from breakpoints
        // outside it) two more conditions would hold, but no split is there.
        let x = on(
            [cond(Side::AtLeast, 4.0), cond(Side::AtMost, -0.5)],
            [cond(Side::AtMost, -0.5), cond(Side::AtLeast, -2.0), always, always],
        );
        assert!(near(x, 5.5), "{x:?}");
        // The same score on [0, 3] and on [3, 7]: the longer, second one.
        // Both conditions hold at x = 3 alone: a point, not a stretch.
        let x = on([cond(Side::AtMost, 3.0), cond(Side::AtLeast, 3.0)], [always; 4]);
        assert!(near(x, 5.0), "{x:?}");
        // The same score on [0, 5] and on [5, 7]: the longer, first one.
        let x = on([cond(Side::AtMost, 5.0), cond(Side::AtLeast, 5.0)], [always; 4]);
        assert!(near(x, 2.5), "{x:?}");
        // The same score on [1, 4] and on [4, 7], as long: the first.
        let x = on(
            [cond(Side::AtLeast, 1.0), cond(Side::AtMost, 4.0)],
            [cond(Side::AtLeast, 4.0), always, always, always],
        );
        assert!(near(x, 2.5), "{x:?}");
        // The same score on [1, 3] and on [3, 7], and on [0.5, 2] and on
        // [2, 5]: the longer, second one, which neither starts at 0.
        let x = on(
            [cond(Side::AtLeast, 1.0), cond(Side::AtMost, 3.0)],
            [cond(Side::AtLeast, 3.0), always, always, always],
        );
        assert!(near(x, 5.0), "{x:?}");
        let x = on(
            [cond(Side::AtLeast, 0.5), cond(Side::AtMost, 2.0)],
            [cond(Side::AtLeast, 2.0), cond(Side::AtMost, 5.0), always, always],
        );
        assert!(near(x, 3.5), "{x:?}");
        // A sub-edge one unit in the last place long: its middle rounds
        // (to even) onto an end, which is no split point.
        let one_ulp = |t_a: f64| SplitQuery {
            t_a,
            t_b: t_a + f64::EPSILON / 2.0,
            ..query_on_ten(&samples, 2.0, 9.0)
        };
        assert_eq!(best_interval_middle(&one_ulp(0.5)), None); // onto t_a
        assert_eq!(best_interval_middle(&one_ulp(0.5 + f64::EPSILON / 2.0)), None);
        // onto t_b
    }

    #[test]
    fn scores_weigh_as_the_report_says() {
        use Score::*;
        assert_eq!(AllEqual.doubled([true, true], 4), 12);
        assert_eq!(AllEqual.doubled([true, false], 1), 4);
        assert_eq!(WeightedCenter.doubled([true, true], 0), 6);
        assert_eq!(WeightedCenter.doubled([false, true], 2), 7);
        assert_eq!(AlwaysCenter.doubled([true, true], 0), 10);
        assert_eq!(AlwaysCenter.doubled([true, false], 4), 10);
        // Always-center: both halves tie with one half and four outer edges.
        assert_eq!(
            AlwaysCenter.doubled([true, true], 0),
            AlwaysCenter.doubled([true, false], 4)
        );
    }

    #[test]
    fn split_aware_counts_a_flippable_outer_edge_as_delaunay_everywhere() {
        // The sub-edge from 2 to 9: its samples are 1, ..., 6 from `a` (k =
        // 2, ..., 7).
        let samples = ten_samples();
        let cond = |side, breakpoint| Condition { side, breakpoint };
        let mut q = SplitQuery {
            // Both halves always Delaunay; outer edge 0 Delaunay at the first
            // sample only, outer edge 1 at the last only, the others never.
            halves: [cond(Side::AtMost, f64::NAN); 2],
            outer: [
                cond(Side::AtMost, 1.5),
                cond(Side::AtLeast, 5.5),
                cond(Side::AtMost, -1.0),
                cond(Side::AtMost, -1.0),
            ],
            // Outer edge 0 can be flipped.
            outer_flippable: [true, false, false, false],
            score: Score::AlwaysCenter,
            ..query_on_ten(&samples, 2.0, 9.0)
        };
        // Always center: the first and the last sample tie (10 + 2); the
        // median of the two is the first.
        assert_eq!(choose(&q).map(|c| c.k), Some(2));
        // Split-aware: outer edge 0 counts everywhere, so the last sample,
        // where outer edge 1 holds as well, is the only best (10 + 2 + 2).
        q.score = Score::SplitAware;
        assert_eq!(q.score_where(|i| i < 3), 12);
        assert_eq!(q.score_where(|i| i < 2 || i == 3), 14);
        assert_eq!(choose(&q).map(|c| c.k), Some(7));
    }

    #[test]
    fn the_middle_sample_is_counted_from_a() {
        let samples = ten_samples();
        let query = |a, b| query_on_ten(&samples, a, b);
        // From 2 to 9: samples k = 2, ..., 7 inside, the middle (by index,
        // the upper one of an even count) k = 5; from 9 to 2, k = 4.
        for (a, b, k) in [(2.0, 9.0, 5), (9.0, 2.0, 4), (0.0, 10.0, 4), (2.5, 4.5, 3)] {
            let q = query(a, b);
            let m = middle(&q).expect("samples inside");
            assert_eq!((m.k, m.t), (k, samples.t(k)), "from {a} to {b}");
            assert_eq!(Pieces::new(&q).map(|p| p.middle()), Some(m));
        }
        // Between two neighbouring samples: none inside.
        assert_eq!(middle(&query(3.0, 4.0)), None);
    }

    #[test]
    fn a_breakpoint_on_a_sample_counts_it_on_the_side_that_holds() {
        // Each condition's breakpoint exactly at a sample's distance from
        // `a` (the distance the window measures): an `AtMost` one holds
        // there and from there back to `a`, an `AtLeast` one from there on.
        let samples = ten_samples();
        let cond = |side, breakpoint| Condition { side, breakpoint };
        for (a, b) in [(0.0, 10.0), (10.0, 0.0), (2.0, 9.0), (9.0, 2.0)] {
            let base = query_on_ten(&samples, a, b);
            let x_of = |k: u64| (samples.t(k) - base.t_a).abs() * samples.len;
            for (k1, k2, median) in (0..9).flat_map(|k1| (0..9).flat_map(move |k2| [(k1, k2, true), (k1, k2, false)])) {
                let q = SplitQuery {
                    halves: [cond(Side::AtLeast, x_of(k1)), cond(Side::AtMost, x_of(k2))],
                    median,
                    ..base
                };
                let conds = q.conditions();
                let want = choose_by_enumeration(&q, |i, x| conds[i].holds(x));
                assert_eq!(choose(&q), want, "from {a} to {b}: samples {k1}, {k2}, median {median}");
            }
        }
    }
}
