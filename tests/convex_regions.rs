//! Large flat regions that are convex polygons, flipped to their Delaunay
//! triangulation directly before Algorithm 2 (src/convex_regions.rs): in
//! linearly many flips, to the triangulation Algorithm 2's own flips reach,
//! and only where the region is such a polygon; the meshes stay valid and
//! every result passes the judge.

mod common;

use common::flat::{judge, prism_triangles, says_unless_keep_order, triangle_set, LIFTS};
use common::Rng;
use delmesh::convex_regions::{flip_convex_regions, flip_convex_regions_of, MIN_CORNERS};
use delmesh::geometry::ALGORITHM_TOLERANCE;
use delmesh::{io, make_delaunay, Options, Surface};
use glam::DVec3;

/// `n` corners of an ellipse (3 by 1) at jittered angles, counter-clockwise,
/// rounded to multiples of 2^-20.
fn oval(n: usize, rng: &mut Rng) -> Vec<(f64, f64)> {
    let round = |v: f64| (v * 1048576.0).round() / 1048576.0;
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * (i as f64 + rng.range(-0.3, 0.3)) / n as f64;
            (round(3.0 * a.cos()), round(a.sin()))
        })
        .collect()
}

/// The fan of corner `apex` of a polygon of `n` corners.
fn fan(n: usize, apex: usize) -> Vec<[u32; 3]> {
    (1..n - 1)
        .map(|i| [apex, (apex + i) % n, (apex + i + 1) % n].map(|v| v as u32))
        .collect()
}

/// A random triangulation of a convex polygon of `n` corners.
fn random_triangulation(n: usize, rng: &mut Rng) -> Vec<[u32; 3]> {
    let mut out = Vec::new();
    let mut todo = vec![(0, n - 1)];
    while let Some((i, j)) = todo.pop() {
        if j - i < 2 {
            continue;
        }
        let k = i + 1 + rng.below((j - i - 1) as u64) as usize;
        out.push([i as u32, k as u32, j as u32]);
        todo.push((i, k));
        todo.push((k, j));
    }
    out
}

#[test]
fn a_fanned_convex_polygon_becomes_the_delaunay_triangulation_in_linear_flips() {
    let mut rng = Rng::new(60);
    let n = 600;
    for lift in LIFTS {
        let corners = oval(n, &mut rng);
        let positions: Vec<DVec3> = corners.iter().map(|&(x, y)| lift(x, y)).collect();
        for apex in [0, n / 8, n / 4] {
            let triangles = fan(n, apex);
            let mut s = Surface::new(positions.clone(), &triangles).unwrap();
            assert!(
                s.count_non_delaunay(ALGORITHM_TOLERANCE).0 > 0,
                "the fan must not be Delaunay already"
            );
            let done = flip_convex_regions(&mut s);
            assert_eq!((done.regions, done.corners), (1, n), "{done:?}");
            assert!(done.flips <= 2 * n, "{} flips", done.flips);
            s.validate().unwrap();
            assert_eq!(s.count_non_delaunay(ALGORITHM_TOLERANCE).0, 0);
            // The triangulation Algorithm 2's own flips reach (the corners are
            // in general position, so it is the only Delaunay one).
            let mut lawson = Surface::new(positions.clone(), &triangles).unwrap();
            let options = Options {
                keep_order: true,
                ..Options::default()
            };
            let stats = make_delaunay(&mut lawson, &options).unwrap();
            assert!(stats.flips > 10 * n, "{} flips: not quadratic, no test", stats.flips);
            assert_eq!(triangle_set(&s), triangle_set(&lawson));
            // make_delaunay does the same first, and counts the flips.
            let mut direct = Surface::new(positions.clone(), &triangles).unwrap();
            let stats = make_delaunay(&mut direct, &Options::default()).unwrap();
            assert_eq!((stats.splits, stats.flips), (0, done.flips));
            assert_eq!(triangle_set(&direct), triangle_set(&s));
            judge(&positions, &triangles, &direct);
        }
    }
}

#[test]
fn random_triangulations_of_convex_polygons_too() {
    let mut rng = Rng::new(61);
    for round in 0..30 {
        let n = 4 + rng.below(300) as usize;
        let lift = LIFTS[round % 3];
        let positions: Vec<DVec3> = oval(n, &mut rng).iter().map(|&(x, y)| lift(x, y)).collect();
        let triangles = random_triangulation(n, &mut rng);
        let mut s = Surface::new(positions.clone(), &triangles).unwrap();
        let bad_before = s.count_non_delaunay(ALGORITHM_TOLERANCE).0;
        let done = flip_convex_regions_of(&mut s, 4);
        s.validate().unwrap();
        assert!(done.flips <= 2 * n, "{n} corners: {} flips", done.flips);
        if bad_before > 0 {
            assert_eq!(done.regions, 1, "{n} corners");
            assert_eq!(s.count_non_delaunay(ALGORITHM_TOLERANCE).0, 0, "{n} corners");
        } else {
            assert_eq!(done.flips, 0);
        }
        judge(&positions, &triangles, &s);
    }
}

#[test]
fn what_is_not_a_convex_polygon_is_left_to_algorithm_2() {
    let mut rng = Rng::new(62);
    let n = 300;
    let corners = oval(n, &mut rng);
    type Case = (&'static str, Vec<DVec3>, Vec<[u32; 3]>);
    let mut cases: Vec<Case> = Vec::new();
    // A corner pushed inwards: not convex there (the fan from its
    // opposite corner still draws the polygon).
    let mut dented: Vec<DVec3> = corners.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    dented[n / 2] *= 0.9;
    cases.push(("a reflex corner", dented, fan(n, 0)));
    // A vertex inside, joined to every corner.
    let mut hub: Vec<DVec3> = corners.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    hub.push(DVec3::new(0.5, 0.125, 0.0));
    let spokes: Vec<[u32; 3]> = (0..n).map(|i| [i as u32, ((i + 1) % n) as u32, n as u32]).collect();
    cases.push(("a vertex inside", hub, spokes));
    // A strip with corners on its long sides: collinear, not strictly convex.
    // Fanned from its bottom left corner over the top side, and from its top
    // right corner over the bottom side.
    let k = 300;
    let mut strip: Vec<DVec3> = (0..=k).map(|i| DVec3::new(i as f64 / 256.0, 0.0, 0.0)).collect();
    strip.extend((0..=k).rev().map(|i| DVec3::new(i as f64 / 256.0, 1.0 / 1024.0, 0.0)));
    let top = |i: usize| (2 * k + 1 - i) as u32;
    let mut fans: Vec<[u32; 3]> = (0..k).map(|i| [0, top(i + 1), top(i)]).collect();
    fans.extend((0..k).map(|i| [top(k), i as u32, i as u32 + 1]));
    cases.push(("a strip", strip, fans));
    // An annulus: two outlines.
    let mut ring: Vec<DVec3> = corners.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    ring.extend(corners.iter().map(|&(x, y)| DVec3::new(x / 2.0, y / 2.0, 0.0)));
    let band: Vec<[u32; 3]> = (0..n as u32)
        .flat_map(|i| {
            let j = (i + 1) % n as u32;
            let m = n as u32;
            [[i, j, m + j], [i, m + j, m + i]]
        })
        .collect();
    cases.push(("an annulus", ring, band));
    for (what, positions, triangles) in cases {
        let mut s = Surface::new(positions.clone(), &triangles).unwrap();
        let before = s.clone();
        let done = flip_convex_regions_of(&mut s, 4);
        assert_eq!((done.regions, done.flips), (0, 0), "{what}");
        assert!(s == before, "{what}: changed");
        let mut s = Surface::new(positions.clone(), &triangles).unwrap();
        make_delaunay(&mut s, &Options::default()).unwrap_or_else(|e| panic!("{what}: {e}"));
        judge(&positions, &triangles, &s);
    }
}

/// An oval prism of `n` corners a cap, the top ring turned by 1.2 segments
/// (its sides are not flat), both caps fanned from corner `apex`.
fn twisted_prism(n: usize, apex: usize) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut rng = Rng::new(63);
    let bottom = oval(n, &mut rng);
    let mut positions: Vec<DVec3> = bottom.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    positions.extend((0..n).map(|i| {
        let a = std::f64::consts::TAU * (i as f64 + 1.2) / n as f64;
        DVec3::new(3.0 * a.cos(), a.sin(), 0.3)
    }));
    let triangles = prism_triangles(n, &fan(n, apex), &fan(n, apex));
    (positions, triangles)
}

#[test]
fn a_prism_with_fanned_caps_needs_far_fewer_flips_and_counts_its_input_alike() {
    let (positions, triangles) = twisted_prism(MIN_CORNERS + 44, 37);
    let run = |keep_order: bool| {
        let mut s = Surface::new(positions.clone(), &triangles).unwrap();
        let options = Options {
            keep_order,
            ..Options::default()
        };
        let stats = make_delaunay(&mut s, &options).unwrap();
        s.validate().unwrap();
        judge(&positions, &triangles, &s);
        stats
    };
    let (direct, lawson) = (run(false), run(true));
    assert!(direct.splits > 0, "the sides must need splits: {direct:?}");
    assert!(
        3 * direct.flips < lawson.flips,
        "{} against {} flips",
        direct.flips,
        lawson.flips
    );
    // The input's non-Delaunay edges, counted as read either way.
    assert_eq!(direct.non_delaunay_before, lawson.non_delaunay_before);
}

#[test]
fn every_fixture_with_its_small_convex_regions_flipped_first() {
    let mut paths = common::fixtures();
    paths.push(common::data_dir().join("cad/rotor.obj"));
    paths.push(common::data_dir().join("attributes/oval_cylinder_smooth_normals.obj"));
    for path in paths {
        let mut input = io::read_mesh(&path, &Default::default()).unwrap();
        let mut s = io::build_surface(&mut input, &path).unwrap();
        flip_convex_regions_of(&mut s, 4);
        s.validate().unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let stats = make_delaunay(&mut s, &Options::default()).unwrap();
        assert_eq!(stats.non_delaunay_after, 0);
        s.validate().unwrap();
        let positions: Vec<DVec3> = input.positions.clone();
        judge(&positions, &input.triangles, &s);
    }
}

#[test]
fn the_command_line_says_so_and_keep_order_leaves_it() {
    let (positions, triangles) = twisted_prism(400, 50);
    let note = "note    2 convex flat regions flipped to Delaunay directly (800 corners";
    says_unless_keep_order(&positions, &triangles, note, "convex flat region");
}

#[test]
fn the_prism_through_every_median_combination_and_shells() {
    use delmesh::{Score, Worklist};
    let (positions, triangles) = twisted_prism(MIN_CORNERS + 10, 3);
    for worklist in [Worklist::Stack, Worklist::Queue, Worklist::PriorityQueue] {
        for score in Score::ALL {
            for shells in [false, true] {
                let mut options = Options::new(worklist, score, true);
                options.shells = shells;
                let mut s = Surface::new(positions.clone(), &triangles).unwrap();
                let stats = make_delaunay(&mut s, &options).unwrap_or_else(|e| panic!("{options:?}: {e}"));
                assert_eq!(stats.non_delaunay_after, 0);
                s.validate().unwrap();
                judge(&positions, &triangles, &s);
            }
        }
    }
}

/// A flat disc whose two sides are both in the mesh, on the same corners
/// (fanned from neighbouring corners, so that no edge is shared): each side
/// folds flat onto the other across its outline, and their Delaunay
/// diagonals are the same, which no flip may double: neither region is
/// started, and Algorithm 2 gets the mesh as it was read.
#[test]
fn a_disc_with_both_sides_on_the_same_corners_is_left_alone() {
    let mut rng = Rng::new(64);
    let n = 300;
    let positions: Vec<DVec3> = oval(n, &mut rng).iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    let mut triangles = fan(n, 0);
    triangles.extend(fan(n, 1).into_iter().map(|[a, b, c]| [a, c, b]));
    let mut s = Surface::new(positions, &triangles).unwrap();
    let before = s.clone();
    let done = flip_convex_regions_of(&mut s, 4);
    assert_eq!((done.regions, done.flips), (0, 0));
    assert!(s == before);
}
