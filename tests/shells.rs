//! Concentric shells (`--shells`): on a cone whose base is wavy, so that
//! every edge at the tip is a crease between two thin faces, splitting each
//! edge at the same distances from the tip keeps the fan Delaunay; the
//! median puts the points of neighbouring edges at slightly different
//! distances and the splits run down to the tip. Both outputs are checked.

use delmesh::io::{self, InputMesh};
use delmesh::refine::{make_delaunay, Options, Worklist};
use delmesh::samples::Score;

/// A cone of `n` segments: its tip at height 1 over a wavy rim of radius 1
/// (height 0.05 sin 7φ), closed by a fan from the base's centre.
fn wavy_cone(n: usize) -> String {
    let mut obj = String::new();
    for i in 0..n {
        let phi = std::f64::consts::TAU * i as f64 / n as f64;
        obj += &format!("v {} {} {}\n", phi.cos(), phi.sin(), 0.05 * (7.0 * phi).sin());
    }
    obj += "v 0 0 1\nv 0 0 0\n";
    let (tip, centre) = (n + 1, n + 2);
    for i in 0..n {
        let (a, b) = (i + 1, (i + 1) % n + 1);
        obj += &format!("f {a} {b} {tip}\nf {centre} {b} {a}\n");
    }
    obj
}

/// Refines the mesh at `path` with `options`, writes it and checks it;
/// returns the added vertices.
fn refine_and_check(input: &InputMesh, path: &std::path::Path, options: &Options, dir: &std::path::Path) -> usize {
    let mut surface = io::build_surface(&mut input.clone(), path).unwrap();
    let stats = make_delaunay(&mut surface, options).unwrap();
    surface.validate().unwrap();
    assert_eq!(stats.non_delaunay_after, 0);
    let out = dir.join("out.obj");
    io::write_obj(&out, &surface.positions, &surface.triangles()).unwrap();
    let report = delmesh::check::check_files(path, &out).unwrap();
    assert!(report.passed(), "{options:?}: {:?}", report.failures);
    assert_eq!(report.added_vertices, stats.splits);
    stats.splits
}

#[test]
fn shells_keep_a_cone_tip_delaunay_with_far_fewer_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cone.obj");
    std::fs::write(&path, wavy_cone(48)).unwrap();
    let input = io::read_mesh(&path, &io::ReadOptions::default()).unwrap();
    let median = refine_and_check(&input, &path, &Options::default(), dir.path());
    let mut shells = Options::new(Worklist::Stack, Score::Uniform, true);
    shells.shells = true;
    let on_shells = refine_and_check(&input, &path, &shells, dir.path());
    // 1,229 against 240 when written.
    assert!(
        on_shells * 3 < median,
        "shells {on_shells} added vertices, the median {median}"
    );
    // Score 2 with shells: still valid, and not worse than the median here.
    shells.score = Score::AlwaysCenter;
    let scored = refine_and_check(&input, &path, &shells, dir.path());
    assert!(scored <= median, "score 2 with shells {scored}, the median {median}");
}
