//! Every mesh in `data/` through every one of the 18 combinations, and every
//! score (0-4) with each DS and concentric shells (`--shells`): the mesh
//! stays valid, ends with zero non-Delaunay edges, keeps the input vertices
//! bit for bit, and the written file passes the independent `check`.

mod common;

use delmesh::io;
use delmesh::refine::{make_delaunay, Options, Worklist};
use delmesh::samples::Score;

fn combinations() -> Vec<Options> {
    let mut v = Vec::new();
    for worklist in [Worklist::Stack, Worklist::Queue, Worklist::PriorityQueue] {
        for score in [Score::AllEqual, Score::WeightedCenter, Score::AlwaysCenter] {
            for median in [true, false] {
                v.push(Options::new(worklist, score, median));
            }
        }
        for score in Score::ALL {
            let mut o = Options::new(worklist, score, true);
            o.shells = true;
            v.push(o);
        }
    }
    v
}

#[test]
fn every_fixture_every_combination_passes_check() {
    let dir = tempfile::tempdir().unwrap();
    let fixtures = common::fixtures();
    assert!(fixtures.len() >= 3, "data/ must hold the fixtures");
    for path in fixtures {
        let mut input = io::read_obj(&path).unwrap();
        for options in combinations() {
            let mut surface = io::build_surface(&mut input, &path).unwrap();
            let stats = make_delaunay(&mut surface, &options)
                .unwrap_or_else(|e| panic!("{}: {options:?}: {e}", path.display()));
            surface
                .validate()
                .unwrap_or_else(|e| panic!("{}: {options:?}: {e}", path.display()));
            assert_eq!(stats.non_delaunay_after, 0);
            // Median runs flip far less than the switch to longest first needs.
            assert!(!options.median || stats.longest_first_after.is_none(), "{stats:?}");
            assert_eq!(surface.count_non_delaunay(delmesh::geometry::ACCEPT_TOLERANCE).0, 0);
            assert_eq!(stats.splits, surface.positions.len() - input.positions.len());
            assert_eq!(&surface.positions[..input.positions.len()], &input.positions[..]);
            let out = dir.path().join("out.obj");
            io::write_obj(&out, &surface.positions, &surface.triangles()).unwrap();
            let report = delmesh::check::check_files(&path, &out).unwrap();
            assert!(
                report.passed(),
                "{}: {options:?}: {:?}",
                path.display(),
                report.failures
            );
            assert_eq!(report.non_delaunay_edges, 0);
            assert_eq!(report.added_vertices, stats.splits);
            // Judged from the files too: the input's vertices first, in order; none unused.
            assert_eq!((report.first_reordered_vertex, report.unused_vertices), (None, 0));
        }
    }
}

#[test]
fn cube_fixture_needs_both_splits_and_flips() {
    let path = common::data_dir().join("cube.obj");
    let mut input = io::read_obj(&path).unwrap();
    let mut surface = io::build_surface(&mut input, &path).unwrap();
    // The crease 5-6 (0-based 4-5) cannot be flipped; bottom edge 9-3 can.
    let find = |s: &delmesh::mesh::Surface, a: u32, b: u32| {
        (0..s.topo.n_edges() as u32).map(delmesh::mesh::EdgeId).find(|&e| {
            let h = e.halfedge();
            let (o, d) = (s.topo.origin(h).0, s.topo.dest(h).0);
            (o, d) == (a, b) || (o, d) == (b, a)
        })
    };
    let crease = find(&surface, 4, 5).unwrap();
    let flat = find(&surface, 8, 2).unwrap();
    assert!(surface.is_non_delaunay(crease, 1e-9) && !surface.is_flippable(crease));
    assert!(surface.is_non_delaunay(flat, 1e-9) && surface.is_flippable(flat));
    assert_eq!(surface.n_regions, 6);
    let stats = make_delaunay(&mut surface, &Options::default()).unwrap();
    assert!(stats.splits > 0 && stats.flips > 0, "{stats:?}");
    surface.validate().unwrap();
}

#[test]
fn splits_and_flips_keep_the_mesh_valid_step_by_step() {
    // Drive the operations by hand on the bunny: split or flip each
    // non-Delaunay edge once, validating after every operation.
    let path = common::data_dir().join("bunny.obj");
    let mut input = io::read_obj(&path).unwrap();
    let mut s = io::build_surface(&mut input, &path).unwrap();
    let n = s.topo.n_edges();
    let mut ops = 0;
    for e in 0..n as u32 {
        let e = delmesh::mesh::EdgeId(e);
        if !s.is_non_delaunay(e, 1e-9) {
            continue;
        }
        if s.is_flippable(e) {
            s.flip(e);
        } else {
            let input_edge = s.edge_input[e.idx()];
            let h = e.halfedge();
            let (ta, tb) = (
                s.param_on(s.topo.origin(h), input_edge),
                s.param_on(s.topo.dest(h), input_edge),
            );
            s.split(e, (ta + tb) / 2.0);
        }
        ops += 1;
        if ops % 25 == 0 {
            s.validate().unwrap();
        }
    }
    s.validate().unwrap();
    assert!(ops > 50);
}
