//! `--prune` on every fixture and every combination (the 18 of DelMesh,
//! score 3, and scores 2 and 4 with concentric shells): the pruned mesh stays valid and Delaunay, keeps the input
//! vertices bit for bit, never has more added vertices than before pruning,
//! and its written file passes the independent `check`. On the CAD fixture,
//! pruning must actually remove vertices.

mod common;

use delmesh::io;
use delmesh::prune::prune;
use delmesh::refine::{make_delaunay, Options, Worklist};
use delmesh::samples::Score;

const SCORES: [Score; 4] = [
    Score::AllEqual,
    Score::WeightedCenter,
    Score::AlwaysCenter,
    Score::SplitAware,
];

/// Refines and prunes `path` with `options`, checks everything, and returns
/// the added vertices before and after pruning.
fn refine_prune_check(path: &std::path::Path, options: &Options, dir: &std::path::Path) -> (usize, usize) {
    let mut input = io::read_mesh(path, &io::ReadOptions::default()).unwrap();
    let mut surface = io::build_surface(&mut input, path).unwrap();
    let bound = surface.added_vertex_lower_bound();
    let stats = make_delaunay(&mut surface, options).unwrap_or_else(|e| panic!("{}: {options:?}: {e}", path.display()));
    let pruned = prune(&mut surface, options);
    let what = format!("{}: {options:?}: {pruned:?}", path.display());
    surface.validate().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(
        surface.count_non_delaunay(delmesh::geometry::ACCEPT_TOLERANCE).0,
        0,
        "{what}"
    );
    let n_input = input.positions.len();
    assert_eq!(&surface.positions[..n_input], &input.positions[..], "{what}");
    let added = surface.positions.len() - n_input;
    assert_eq!(added + pruned.removed, stats.splits, "{what}");
    assert!(added >= bound, "{what}: {added} added, below the lower bound {bound}");
    let out = dir.join("pruned.obj");
    io::write_obj(&out, &surface.positions, &surface.triangles()).unwrap();
    let report = delmesh::check::check_files(path, &out).unwrap();
    assert!(report.passed(), "{what}: {:?}", report.failures);
    assert_eq!(report.added_vertices, added, "{what}");
    (stats.splits, added)
}

#[test]
fn every_fixture_every_combination_pruned_passes_check() {
    let dir = tempfile::tempdir().unwrap();
    for path in common::fixtures() {
        for worklist in [Worklist::Stack, Worklist::Queue, Worklist::PriorityQueue] {
            for score in SCORES {
                for median in [true, false] {
                    refine_prune_check(&path, &Options::new(worklist, score, median), dir.path());
                }
            }
            for score in [Score::AlwaysCenter, Score::Uniform] {
                let mut options = Options::new(worklist, score, true);
                options.shells = true;
                refine_prune_check(&path, &options, dir.path());
            }
        }
    }
}

#[test]
fn lower_bound_counts_creases_between_single_faces_only() {
    use delmesh::Surface;
    use glam::DVec3;
    // A thin rhombus folded along its long diagonal (two single-face regions):
    // the diagonal must be split.
    let folded = vec![
        DVec3::new(-2.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 0.5, 0.0),
        DVec3::new(0.0, -0.4, 0.3),
    ];
    let triangles = [[0, 1, 2], [1, 0, 3]];
    assert_eq!(Surface::new(folded, &triangles).unwrap().added_vertex_lower_bound(), 1);
    // The same rhombus flat: one region, the diagonal is flipped instead.
    let flat = vec![
        DVec3::new(-2.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 0.5, 0.0),
        DVec3::new(0.0, -0.4, 0.0),
    ];
    let mut surface = Surface::new(flat, &triangles).unwrap();
    assert_eq!(surface.added_vertex_lower_bound(), 0);
    let stats = make_delaunay(&mut surface, &Options::default()).unwrap();
    assert_eq!((stats.splits, stats.flips), (0, 1));
    // Folded the other way round (Delaunay already): nothing needed.
    let open = vec![
        DVec3::new(-1.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 2.0, 0.0),
        DVec3::new(0.0, -1.5, 1.0),
    ];
    assert_eq!(Surface::new(open, &triangles).unwrap().added_vertex_lower_bound(), 0);
}

#[test]
fn pruning_removes_many_vertices_on_a_cad_part() {
    // rotor.obj: slivers along flat regions, where Algorithm 2 over-splits.
    let dir = tempfile::tempdir().unwrap();
    let path = common::data_dir().join("cad").join("rotor.obj");
    for options in [
        Options::default(),
        Options::new(Worklist::Queue, Score::SplitAware, true),
        Options::new(Worklist::PriorityQueue, Score::AllEqual, true),
    ] {
        let (before, after) = refine_prune_check(&path, &options, dir.path());
        assert!(
            after * 4 < before * 3,
            "{options:?}: {before} -> {after} added vertices"
        );
    }
}

/// Pruning in at most k passes: what the full run had after k passes. The
/// added vertices never grow with k, k = MAX_PASSES is the full run, and
/// every result is a valid Delaunay mesh whose file passes `check`.
#[test]
fn fewer_passes_stop_pruning_early_and_stay_delaunay() {
    use delmesh::prune::{prune_passes, MAX_PASSES};
    let dir = tempfile::tempdir().unwrap();
    let path = common::data_dir().join("cad").join("rotor.obj");
    let mut input = io::read_mesh(&path, &io::ReadOptions::default()).unwrap();
    let mut refined = io::build_surface(&mut input, &path).unwrap();
    let options = Options::default();
    make_delaunay(&mut refined, &options).unwrap();
    let mut full = refined.clone();
    let full_stats = prune(&mut full, &options);
    assert!(full_stats.passes >= 2, "{full_stats:?}: the test would see little");
    let mut last_removed = 0;
    for k in [1, 2, MAX_PASSES] {
        let mut s = refined.clone();
        let stats = prune_passes(&mut s, &options, k, None);
        let what = format!("{k} passes: {stats:?}");
        assert_eq!(stats.passes, k.min(full_stats.passes), "{what}");
        assert!(
            stats.removed >= last_removed && stats.removed <= full_stats.removed,
            "{what}"
        );
        last_removed = stats.removed;
        s.validate().unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(s.count_non_delaunay(delmesh::geometry::ACCEPT_TOLERANCE).0, 0, "{what}");
        if k >= full_stats.passes {
            assert_eq!((stats, &s.positions), (full_stats, &full.positions), "{what}");
        }
        let out = dir.path().join("pruned.obj");
        io::write_obj(&out, &s.positions, &s.triangles()).unwrap();
        let report = delmesh::check::check_files(&path, &out).unwrap();
        assert!(report.passed(), "{what}: {:?}", report.failures);
    }
}

/// A sphere-like "orange with one wedge taken out": two poles `u` (vertex
/// n) and `w` (vertex n + 1) joined by a ring of n vertices on an arc of
/// 300°, and by an edge of their own between the wedge's two flat faces.
/// Both poles have n + 1 neighbours; their edge is Delaunay (the ring is
/// wider than the poles are apart, so its apexes see it under less than a
/// right angle each).
fn orange_without_a_wedge(n: usize) -> (Vec<glam::DVec3>, Vec<[u32; 3]>) {
    let mut positions: Vec<glam::DVec3> = (0..n)
        .map(|i| {
            let a = (30.0 + 300.0 * i as f64 / (n - 1) as f64).to_radians();
            glam::DVec3::new(1.5 * a.cos(), 1.5 * a.sin(), 0.0)
        })
        .collect();
    positions.push(glam::DVec3::new(0.0, 0.0, 1.0));
    positions.push(glam::DVec3::new(0.0, 0.0, -1.0));
    let (u, w) = (n as u32, n as u32 + 1);
    let mut triangles = Vec::new();
    for i in 0..n as u32 - 1 {
        triangles.push([u, i, i + 1]);
        triangles.push([w, i + 1, i]);
    }
    triangles.push([u, n as u32 - 1, w]);
    triangles.push([w, 0, u]);
    (positions, triangles)
}

#[test]
fn pruning_removes_a_vertex_between_two_vertices_of_high_degree() {
    // Pruning once refused to merge the two halves of an edge back when
    // both its ends had more than 64 neighbours (it could not tell whether
    // they were joined elsewhere already); it now walks both fans.
    let n = 100;
    let (positions, triangles) = orange_without_a_wedge(n);
    let mut surface = delmesh::Surface::new(positions, &triangles).unwrap();
    let options = Options::default();
    make_delaunay(&mut surface, &options).unwrap();
    let before = surface.positions.len();
    let (u, w) = (delmesh::mesh::VertexId(n as u32), delmesh::mesh::VertexId(n as u32 + 1));
    let topo = &surface.topo;
    let edge = (0..topo.n_edges() as u32)
        .map(delmesh::mesh::EdgeId)
        .find(|e| {
            let h = e.halfedge();
            [topo.origin(h), topo.dest(h)] == [u, w] || [topo.origin(h), topo.dest(h)] == [w, u]
        })
        .expect("the poles' edge is Delaunay, never split");
    surface.split(edge, 0.5);
    surface.validate().unwrap();
    assert_eq!(surface.topo.are_adjacent_within_either(u, w, 1024), Some(false));
    let pruned = prune(&mut surface, &options);
    surface.validate().unwrap();
    assert_eq!(pruned.removed, 1, "{pruned:?}");
    assert_eq!(surface.positions.len(), before);
    assert_eq!(surface.topo.are_adjacent_within_either(u, w, 1024), Some(true));
    assert_eq!(surface.count_non_delaunay(delmesh::geometry::ACCEPT_TOLERANCE).0, 0);
}
