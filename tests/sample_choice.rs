//! The interval-based choice of a split sample (`samples::choose`) against
//! the test oracle that scores every sample one by one with independent
//! pointwise predicates (angle sums for the halves, an exact in-circle test
//! for the outer edges), on randomized configurations.

mod common;

use common::Rng;
use delmesh::geometry::{corner_angle, unfold_across, EdgeFrame};
use delmesh::refine::split_conditions;
use delmesh::samples::{choose, choose_by_enumeration, point_on_edge, EdgeSamples, SampleConstants, Score, SplitQuery};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

fn random_point(rng: &mut Rng, scale: f64) -> DVec3 {
    DVec3::new(
        rng.range(-scale, scale),
        rng.range(-scale, scale),
        rng.range(-scale, scale),
    )
}

/// True if `p` is strictly inside the circle through a, b, c (exact).
fn strictly_inside(a: DVec2, b: DVec2, c: DVec2, p: DVec2) -> bool {
    let k = |v: DVec2| robust::Coord { x: v.x, y: v.y };
    let orient = robust::orient2d(k(a), k(b), k(c));
    let inc = robust::incircle(k(a), k(b), k(c), k(p));
    orient * inc > 0.0
}

fn angle2(p: DVec2, q: DVec2, at: DVec2) -> f64 {
    corner_angle(p.extend(0.0), q.extend(0.0), at.extend(0.0))
}

struct Config {
    ends: [DVec3; 2],
    samples: EdgeSamples,
    t: [f64; 2],
    pos: [DVec3; 2],
    quad: [DVec3; 4],
    beyond: [Option<DVec3>; 4],
}

fn random_config(rng: &mut Rng) -> Config {
    let ends = [random_point(rng, 2.0), random_point(rng, 2.0)];
    let len = (ends[1] - ends[0]).length();
    // Constants giving between a handful and a few thousand samples.
    let theta = rng.range(0.02, 0.6);
    let l_min = len * rng.range(0.002, 0.5);
    let c = SampleConstants::new(theta, l_min);
    let samples = EdgeSamples::new(len, &c);
    // Sub-edge ends: input vertices or existing samples (as after splits).
    let n = samples.count();
    let pick = |rng: &mut Rng| match rng.below(4) {
        0 => 0.0,
        1 => 1.0,
        _ => samples.t(rng.below(n)),
    };
    let mut t = [pick(rng), pick(rng)];
    if t[0] == t[1] {
        t = [0.0, 1.0];
    }
    if rng.below(2) == 0 {
        t.swap(0, 1);
    }
    let at = |t: f64| {
        if t == 0.0 {
            ends[0]
        } else if t == 1.0 {
            ends[1]
        } else {
            point_on_edge(ends[0], ends[1], t)
        }
    };
    let pos = [at(t[0]), at(t[1])];
    // Opposite vertices near the sub-edge, on two sides of it.
    let mid = (pos[0] + pos[1]) / 2.0;
    let sub = (pos[1] - pos[0]).length();
    let quad = [
        pos[0],
        pos[1],
        mid + random_point(rng, sub),
        mid + random_point(rng, sub),
    ];
    let beyond = [0, 1, 2, 3].map(|_| (rng.below(6) != 0).then(|| mid + random_point(rng, 1.5 * sub)));
    Config {
        ends,
        samples,
        t,
        pos,
        quad,
        beyond,
    }
}

/// Pointwise conditions at distance x from a: 0, 1 the halves, 2..6 the outer
/// edges (a,c), (c,b), (b,d), (d,a).
fn pointwise(cfg: &Config) -> impl Fn(usize, f64) -> bool + '_ {
    let [a, b, c, d] = cfg.quad;
    let f = EdgeFrame::new(a, b);
    let (a2, b2) = (DVec2::ZERO, DVec2::new(f.length, 0.0));
    let (c2, d2) = (f.unfold(c, true), f.unfold(d, false));
    let unfold = |i: usize, p3: DVec3, q3: DVec3, p2: DVec2, q2: DVec2, inside: DVec2| {
        cfg.beyond[i].map(|x| unfold_across(p3, q3, x, p2, q2, inside))
    };
    let far = [
        unfold(0, a, c, a2, c2, b2),
        unfold(1, b, c, b2, c2, a2),
        unfold(2, b, d, b2, d2, a2),
        unfold(3, a, d, a2, d2, b2),
    ];
    move |i, x| {
        let p = DVec2::new(x, 0.0);
        match i {
            0 => angle2(a2, p, c2) + angle2(a2, p, d2) <= PI,
            1 => angle2(p, b2, c2) + angle2(p, b2, d2) <= PI,
            _ => {
                let (anchor, other) = [(a2, c2), (b2, c2), (b2, d2), (a2, d2)][i - 2];
                far[i - 2].is_none_or(|x2| !strictly_inside(anchor, other, x2, p))
            }
        }
    }
}

#[test]
fn interval_choice_matches_enumeration() {
    let mut rng = Rng::new(2015);
    let mut compared = 0;
    let mut none = 0;
    for _ in 0..3000 {
        let cfg = random_config(&mut rng);
        let (halves, outer) = split_conditions(cfg.quad, cfg.beyond);
        let flippable = [0, 1, 2, 3].map(|_| rng.below(2) == 0);
        for score in Score::ALL {
            for (median, shells) in [(true, false), (false, false), (true, true)] {
                let q = SplitQuery {
                    samples: &cfg.samples,
                    edge_ends: cfg.ends,
                    t_a: cfg.t[0],
                    t_b: cfg.t[1],
                    pos_a: cfg.pos[0],
                    pos_b: cfg.pos[1],
                    halves,
                    outer,
                    outer_flippable: flippable,
                    score,
                    median,
                    shells,
                };
                let fast = choose(&q);
                let slow = choose_by_enumeration(&q, pointwise(&cfg));
                assert_eq!(
                    fast,
                    slow,
                    "score {score:?} median {median} shells {shells}: t = {:?}, {} samples",
                    cfg.t,
                    cfg.samples.count()
                );
                compared += 1;
                none += fast.is_none() as usize;
            }
        }
    }
    // The configurations must exercise both outcomes.
    assert!(none > 0 && none < compared / 2, "{none} of {compared} without sample");
}

#[test]
fn chosen_sample_lies_strictly_inside_even_with_1e16_samples() {
    // mpi_triang-like constants: about 10^16 samples on the edge, far more
    // than f64 distinguishes; near an end many of them round onto one point.
    let mut rng = Rng::new(7);
    let c = SampleConstants::new(3.5e-7, 1.2e-3);
    for _ in 0..500 {
        let start = random_point(&mut rng, 10.0);
        let dir = random_point(&mut rng, 1.0).normalize_or(DVec3::X);
        let ends = [start, start + dir * rng.range(8.0, 20.0)];
        let samples = EdgeSamples::new((ends[1] - ends[0]).length(), &c);
        assert!(samples.count() > 1 << 53);
        let n = samples.count();
        // A tiny sub-edge between two samples a few ulps apart, or a long one.
        let k0 = rng.below(n - 1000);
        let gap = [1, 2, 3, 1000, n / 3][rng.below(5) as usize].min(n - 1 - k0);
        let t = [samples.t(k0), samples.t(k0 + gap)];
        let pos = t.map(|t| point_on_edge(ends[0], ends[1], t));
        if pos[0] == pos[1] {
            continue;
        }
        let mid = (pos[0] + pos[1]) / 2.0;
        let quad = [
            pos[0],
            pos[1],
            mid + DVec3::new(0.0, 1.0, 0.0),
            mid - DVec3::new(0.0, 1.0, 0.3),
        ];
        let (halves, outer) = split_conditions(quad, [None; 4]);
        let q = SplitQuery {
            samples: &samples,
            edge_ends: ends,
            t_a: t[0],
            t_b: t[1],
            pos_a: pos[0],
            pos_b: pos[1],
            halves,
            outer,
            outer_flippable: [false; 4],
            score: Score::AlwaysCenter,
            median: true,
            shells: rng.below(2) == 0,
        };
        if let Some(ch) = choose(&q) {
            assert!(ch.k > k0 && ch.k < k0 + gap);
            let p = point_on_edge(ends[0], ends[1], ch.t);
            assert!(p != pos[0] && p != pos[1], "sample rounds onto an end point");
            assert!(ch.t > t[0] && ch.t < t[1]);
        } else {
            // Only possible when every sample between rounds onto an end.
            assert!(gap < 1000);
        }
    }
}
