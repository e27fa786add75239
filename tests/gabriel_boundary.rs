//! `--gabriel-boundary` (`Surface::gabriel_boundary`): on open meshes, refining (and pruning
//! after it) leaves no boundary edge facing an obtuse angle, so that every cotangent weight
//! of the output is non-negative; judged edge by edge here (angles computed afresh) and by
//! the independent `check`, on every combination of settings. Without it the same meshes keep
//! obtuse angles at their boundaries, which `check` counts without failing, unless asked to.

mod common;

use std::f64::consts::FRAC_PI_2;

use common::Rng;
use delmesh::check::{check_meshes, CheckReport, Mesh3, DELAUNAY_TOLERANCE};
use delmesh::mesh::Surface;
use delmesh::prune::prune;
use delmesh::refine::{make_delaunay, Options, Worklist};
use delmesh::samples::Score;
use glam::DVec3;

/// A height field of `n` × `n` vertices on a unit grid, moved by up to 0.4 in x and y (rim
/// vertices along the rim), heights in [0, 2), each cell cut along a random diagonal: an open
/// mesh whose rim triangles often face the boundary with obtuse angles.
fn terrain(n: usize, seed: u64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut rng = Rng::new(seed);
    let mut positions = Vec::new();
    for i in 0..n {
        for j in 0..n {
            // (Along the rim too: boundary vertices slide along it.)
            let inner = |k: usize| k > 0 && k + 1 < n;
            let dx = if inner(i) { rng.range(-0.4, 0.4) } else { 0.0 };
            let dy = if inner(j) { rng.range(-0.4, 0.4) } else { 0.0 };
            positions.push(DVec3::new(i as f64 + dx, j as f64 + dy, rng.range(0.0, 2.0)));
        }
    }
    let mut triangles = Vec::new();
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            let [a, b, c, d] = [i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1].map(|v| v as u32);
            if rng.below(2) == 0 {
                triangles.extend([[a, b, c], [a, c, d]]);
            } else {
                triangles.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    (positions, triangles)
}

/// A strip of needles along the x axis: each bottom edge faces an angle near π.
fn needle_strip() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut positions: Vec<DVec3> = (0..11).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
    positions.extend((0..10).map(|i| DVec3::new(i as f64 + 0.5, 0.001 * (1 + i % 3) as f64, 0.0)));
    let mut triangles: Vec<[u32; 3]> = (0..10).map(|i| [i, i + 1, 11 + i]).collect();
    triangles.extend((0..9).map(|i| [11 + i, i + 1, 12 + i]));
    (positions, triangles)
}

/// A cone over a rim of unevenly spaced points (a fan of long thin faces with a boundary),
/// lifted so that no two faces are coplanar.
fn uneven_fan(seed: u64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut rng = Rng::new(seed);
    let mut angles: Vec<f64> = (0..30).map(|_| rng.range(0.0, std::f64::consts::TAU)).collect();
    angles.sort_by(f64::total_cmp);
    let mut positions = vec![DVec3::new(0.0, 0.0, 0.3)];
    positions.extend(angles.iter().map(|t| DVec3::new(t.cos(), t.sin(), 0.0)));
    let n = angles.len() as u32;
    let triangles = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    (positions, triangles)
}

fn open_meshes() -> Vec<(String, Vec<DVec3>, Vec<[u32; 3]>)> {
    let mut meshes = Vec::new();
    for seed in 0..3 {
        let (p, t) = terrain(9, 0x6ab + seed);
        meshes.push((format!("terrain {seed}"), p, t));
    }
    let (p, t) = needle_strip();
    meshes.push(("needle strip".into(), p, t));
    let (p, t) = uneven_fan(11);
    meshes.push(("uneven fan".into(), p, t));
    meshes
}

/// The 18 combinations of the report, score 3, and scores 2 and 4 with concentric shells.
fn settings() -> Vec<Options> {
    let mut all = Vec::new();
    for worklist in [Worklist::Stack, Worklist::Queue, Worklist::PriorityQueue] {
        for score in [
            Score::AllEqual,
            Score::WeightedCenter,
            Score::AlwaysCenter,
            Score::SplitAware,
        ] {
            for median in [true, false] {
                all.push(Options::new(worklist, score, median));
            }
        }
        for score in [Score::AlwaysCenter, Score::Uniform] {
            let mut o = Options::new(worklist, score, true);
            o.shells = true;
            all.push(o);
        }
    }
    for o in &mut all {
        o.max_added = 200_000;
    }
    all
}

/// The largest γ − π/2 over the boundary edges of `s` (γ the angle opposite in the one face),
/// computed from the faces afresh: atan2 of the cross and dot products.
fn worst_boundary_angle(s: &Surface) -> f64 {
    let triangles = s.triangles();
    let mut faces_of = std::collections::HashMap::new();
    for t in &triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            faces_of
                .entry((a.min(b), a.max(b)))
                .or_insert_with(Vec::new)
                .push(t[(k + 2) % 3]);
        }
    }
    let p = |v: u32| s.positions[v as usize];
    (faces_of.iter())
        .filter(|(_, apexes)| apexes.len() == 1)
        .map(|(&(a, b), apexes)| {
            let (u, v) = (p(a) - p(apexes[0]), p(b) - p(apexes[0]));
            u.cross(v).length().atan2(u.dot(v)) - FRAC_PI_2
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

fn judge(input: &Mesh3, s: &Surface) -> CheckReport {
    let output = Mesh3 {
        positions: s.positions.clone(),
        triangles: s.triangles(),
    };
    check_meshes(input, &output)
}

#[test]
fn refining_and_pruning_leave_no_boundary_edge_facing_an_obtuse_angle() {
    let mut obtuse_before = 0;
    for (name, positions, triangles) in open_meshes() {
        let input = Mesh3 {
            positions: positions.clone(),
            triangles: triangles.clone(),
        };
        let mut base = Surface::new(positions, &triangles).unwrap();
        let mut plain = base.clone();
        make_delaunay(&mut plain, &Options::default()).unwrap();
        obtuse_before += usize::from(worst_boundary_angle(&plain) > DELAUNAY_TOLERANCE);
        base.gabriel_boundary = true;
        let (n, bound) = (base.positions.len(), base.added_vertex_lower_bound());
        for options in settings() {
            let what = format!("{name}: {options:?}");
            let mut s = base.clone();
            let stats = match make_delaunay(&mut s, &options) {
                Ok(stats) => stats,
                // Without the median, needles may need too much, as without the flag (the
                // properties tests allow it too); with it, never.
                Err(delmesh::Error::WorkLimit { .. }) if !options.median => continue,
                Err(e) => panic!("{what}: {e}"),
            };
            for step in ["refined", "pruned"] {
                if step == "pruned" {
                    prune(&mut s, &options);
                }
                s.validate().unwrap_or_else(|e| panic!("{what}, {step}: {e}"));
                assert!(
                    s.positions.len() - n >= bound,
                    "{what}, {step}: fewer added than the bound {bound}"
                );
                let worst = worst_boundary_angle(&s);
                assert!(worst <= DELAUNAY_TOLERANCE, "{what}, {step}: gamma - pi/2 = {worst}");
                let mut report = judge(&input, &s);
                assert_eq!(report.non_gabriel_boundary_edges, 0, "{what}, {step}");
                report.require_gabriel_boundary();
                assert!(report.passed(), "{what}, {step}: {:?}", report.failures);
            }
            assert_eq!(stats.non_delaunay_after, 0, "{what}");
        }
    }
    // The meshes are worth the test: refined without the flag, most face obtuse angles at
    // their boundary.
    assert!(obtuse_before >= 4, "{obtuse_before}");
}

#[test]
fn without_it_boundary_edges_may_face_obtuse_angles_and_check_counts_them() {
    let (positions, triangles) = needle_strip();
    let input = Mesh3 {
        positions: positions.clone(),
        triangles: triangles.clone(),
    };
    let mut s = Surface::new(positions, &triangles).unwrap();
    make_delaunay(&mut s, &Options::default()).unwrap();
    assert!(worst_boundary_angle(&s) > 1.0);
    let mut report = judge(&input, &s);
    assert!(report.passed(), "{:?}", report.failures);
    // The ten bottom edges, the nine top ones, the two ends.
    assert_eq!(report.boundary_edges, 21);
    assert!(
        report.non_gabriel_boundary_edges >= 10,
        "{}",
        report.non_gabriel_boundary_edges
    );
    assert!(report.max_boundary_excess > 1.0);
    report.require_gabriel_boundary();
    assert!(!report.passed());
    assert!(
        report.failures[0].contains("faces an obtuse angle")
            && report.failures[0].contains("cotangent weight is negative"),
        "{:?}",
        report.failures
    );
}

#[test]
fn a_closed_mesh_refines_as_without_it() {
    // No boundary edge: the flag changes nothing (same vertices, bit for bit).
    let path = common::data_dir().join("bunny.obj");
    let mut input = delmesh::io::read_mesh(&path, &delmesh::io::ReadOptions::default()).unwrap();
    let base = delmesh::io::build_surface(&mut input, &path).unwrap();
    let mut plain = base.clone();
    let mut gabriel = base;
    gabriel.gabriel_boundary = true;
    make_delaunay(&mut plain, &Options::default()).unwrap();
    make_delaunay(&mut gabriel, &Options::default()).unwrap();
    assert_eq!(plain.positions, gabriel.positions);
    assert_eq!(plain.triangles(), gabriel.triangles());
}

#[test]
fn many_obtuse_boundary_edges_are_listed_worst_first_then_counted() {
    // A flat zigzag strip of 59 needles, 1 long and 0.1 to 0.13 high: every
    // bottom and top edge faces an angle of 150 to 157 degrees (59 edges),
    // the two ends and the inner edges acute ones. Judged against itself, it passes;
    // its boundary lines are the worst 20 and one line counting the rest.
    let n = 30;
    let mut positions = Vec::new();
    for i in 0..=n {
        positions.push(DVec3::new(i as f64, 0.0, 0.0)); // b_i = 2i
        positions.push(DVec3::new(i as f64 + 0.5, 0.1 + 0.001 * i as f64, 0.0));
        // t_i = 2i + 1
    }
    let (b, t) = (|i: u32| 2 * i, |i: u32| 2 * i + 1);
    let mut triangles = Vec::new();
    for i in 0..n {
        triangles.push([b(i), b(i + 1), t(i)]);
        if i + 1 < n {
            triangles.push([t(i), b(i + 1), t(i + 1)]);
        }
    }
    let mesh = Mesh3 { positions, triangles };
    let mut report = check_meshes(&mesh, &mesh);
    assert!(report.passed(), "{:?}", report.failures);
    assert_eq!(report.non_gabriel_boundary_edges, 59);
    let lines = &report.boundary_lines;
    assert_eq!(lines.len(), delmesh::check::MAX_LINES_PER_KIND + 1, "{lines:?}");
    assert_eq!(lines[20], "... and 39 more boundary edges facing an obtuse angle");
    let excess = |line: &str| -> f64 {
        let x = line.split("gamma-pi/2 = ").nth(1).unwrap();
        x.split(' ').next().unwrap().parse().unwrap()
    };
    assert!(
        lines[..20].windows(2).all(|w| excess(&w[0]) >= excess(&w[1])),
        "{lines:?}"
    );
    assert!(excess(&lines[0]) > 1.0 && excess(&lines[19]) > 1.0);
    report.require_gabriel_boundary();
    assert!(!report.passed());
    assert_eq!(report.failures.len(), 21);
    assert!(
        report.failure_counts.iter().any(|&(_, count)| count == 59),
        "{:?}",
        report.failure_counts
    );
}
