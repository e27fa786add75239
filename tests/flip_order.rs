//! The switch to longest edge first (`refine::FLIPS_PER_EDGE_BEFORE_LONGEST_FIRST`):
//! an oval cylinder whose flat caps are fanned from one rim vertex, as CAD
//! exports write them, takes the stack and the queue quadratically many
//! flips; after the switch the flips grow linearly. Every output is checked.

mod common;

use delmesh::io;
use delmesh::refine::{
    make_delaunay_from, non_delaunay_edges, Options, Stats, Worklist, FLIPS_PER_EDGE_BEFORE_LONGEST_FIRST,
};
use delmesh::samples::Score;

/// An elliptic cylinder (semi-axes 2 and 1, height 1) of `n` segments, each
/// cap fanned from its first rim vertex: 2n vertices, 4n − 4 faces. The rim
/// vertex at the top of the ellipse is pulled in by 0.1%, so that the caps
/// are not convex: Algorithm 2's flips make them Delaunay (a convex cap of
/// 256 corners or more is flipped directly first: tests/convex_regions.rs).
fn oval_cylinder(n: usize) -> String {
    let mut obj = String::new();
    for z in [0, 1] {
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let r = if i == n / 4 { 0.999 } else { 1.0 };
            obj += &format!("v {} {} {z}\n", 2.0 * r * a.cos(), r * a.sin());
        }
    }
    for i in 1..=n {
        let j = i % n + 1;
        obj += &format!("f {i} {j} {}\nf {i} {} {}\n", n + j, n + j, n + i);
    }
    for i in 2..n {
        obj += &format!("f 1 {} {i}\nf {} {} {}\n", i + 1, n + 1, n + i, n + i + 1);
    }
    obj
}

/// Refines the cylinder with `options`, checks the output against the
/// input, and returns the run's figures. By `make_delaunay_from`, without
/// the flat regions made Delaunay first (`make_delaunay` would rebuild
/// these caps outright: tests/flat_regions.rs): the switch is for the
/// regions that pass leaves to Algorithm 2.
fn refine_checked(path: &std::path::Path, options: &Options) -> Stats {
    let mut input = io::read_obj(path).unwrap();
    let mut surface = io::build_surface(&mut input, path).unwrap();
    let first_pass = non_delaunay_edges(&surface);
    let stats = make_delaunay_from(&mut surface, options, &first_pass).unwrap();
    surface.validate().unwrap();
    assert_eq!(stats.splits, 0, "flat caps need flips only");
    let report = common::check_refined(&input, &surface);
    assert!(report.passed(), "{options:?}: {:?}", report.failures);
    stats
}

#[test]
fn fanned_flat_caps_switch_the_stack_and_queue_to_longest_first() {
    let dir = tempfile::tempdir().unwrap();
    let n = 2000;
    let path = dir.path().join("oval.obj");
    std::fs::write(&path, oval_cylinder(n)).unwrap();
    let edges = 6 * n - 6;
    let longest = refine_checked(&path, &Options::new(Worklist::PriorityQueue, Score::AlwaysCenter, true));
    assert_eq!(longest.longest_first_after, None);
    for worklist in [Worklist::Stack, Worklist::Queue] {
        let mut options = Options::new(worklist, Score::AlwaysCenter, true);
        options.keep_order = true;
        let kept = refine_checked(&path, &options);
        assert_eq!(kept.longest_first_after, None);
        options.keep_order = false;
        let switched = refine_checked(&path, &options);
        // The switch comes at the first flip past the bound.
        assert_eq!(
            switched.longest_first_after,
            Some(FLIPS_PER_EDGE_BEFORE_LONGEST_FIRST * edges + 1),
            "{worklist:?}"
        );
        // Quadratic without the switch (about n²/6 for both caps with the
        // stack, n²/18 with the queue: 667,000 and 222,000 flips here),
        // linear with it, and more than longest first from the start.
        assert!(kept.flips > n * n / 20, "{worklist:?}: {kept:?}");
        assert!(
            switched.flips < 2 * FLIPS_PER_EDGE_BEFORE_LONGEST_FIRST * edges,
            "{switched:?}"
        );
        assert!(
            switched.flips * 3 < kept.flips * 2,
            "{worklist:?}: {switched:?} against {kept:?}"
        );
        assert!(longest.flips < switched.flips, "{longest:?} against {switched:?}");
    }
}
