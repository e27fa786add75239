//! The checker's soundness and stability, by damage with a known verdict.
//!
//! Outputs of the construction (the fixtures, a CAD part, a cone-like fan,
//! a marching-tetrahedra sphere with near-coincident vertices, a cube whose
//! exactly flat faces are jittered grids with random diagonals) are each
//! changed once, many times over, in ways whose verdict is known:
//!
//! - refused (`common::damage`): an added vertex moved off its input edge,
//!   or along it past the next vertex on it; an input vertex moved by one
//!   unit in the last place; a face removed, doubled or turned over; an edge
//!   flipped across a crease (between two input regions, its quad clearly
//!   not flat); an edge flipped inside a flat region where the other
//!   diagonal is non-Delaunay by more than 1e-6 rad; a face split into
//!   three at an inner point;
//! - accepted: the faces shuffled, each face's corners rotated, the added
//!   vertices renumbered;
//! - judged by the construction's own geometry: an added vertex slid along
//!   its input edge, between its neighbours on it, off the samples (the
//!   geometry stays the same, as a peer tool's split points would leave
//!   it): accepted if every interior edge is then within 0.5e-9 rad of
//!   Delaunay, refused if one is over by more than 2e-9.
//!
//! `CHECK_SOUNDNESS_ROUNDS` (default 2) sets how many of each per mesh and
//! setting, `CHECK_SOUNDNESS_SEED` the generator's seed.

mod common;

use std::collections::HashMap;

use common::damage::{damage, directed_edges, neighbours_on_edge, random_added_vertex, DAMAGES};
use common::Rng;
use delmesh::check::{check_meshes, CheckReport, Mesh3};
use delmesh::io;
use delmesh::mesh::Surface;
use delmesh::refine::{make_delaunay, Options, Worklist};
use delmesh::samples::Score;
use glam::DVec3;

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// An input, as the checker reads it.
struct Case {
    name: String,
    input: Mesh3,
}

fn case(name: &str, positions: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Case {
    Case {
        name: name.to_string(),
        input: Mesh3 {
            positions: positions.into_iter().map(DVec3::from).collect(),
            triangles,
        },
    }
}

fn read_case(path: &std::path::Path) -> Case {
    let input = io::read_obj(path).unwrap();
    Case {
        name: path.file_name().unwrap().to_string_lossy().into_owned(),
        input: Mesh3 {
            positions: input.positions,
            triangles: input.triangles,
        },
    }
}

/// The unit cube, each face an `n`×`n` grid (n a power of two, so that the
/// faces' shared border points agree bit for bit) whose inner points are
/// jittered in the face's plane by multiples of 1/1024 (exactly flat
/// faces), each cell cut along a random diagonal: large planar regions far
/// from Delaunay, which the construction flips.
fn jittered_cube(n: usize, rng: &mut Rng) -> Case {
    let mut index: HashMap<[u64; 3], u32> = HashMap::new();
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut triangles = Vec::new();
    // (origin, u, v) with u × v pointing out of the cube.
    let faces: [([f64; 3], [f64; 3], [f64; 3]); 6] = [
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
    ];
    for (o, u, v) in faces {
        let mut grid = vec![0u32; (n + 1) * (n + 1)];
        for j in 0..=n {
            for i in 0..=n {
                let inner = i > 0 && i < n && j > 0 && j < n;
                let jitter = |rng: &mut Rng| {
                    if inner {
                        (rng.below(161) as f64 - 80.0) / 1024.0
                    } else {
                        0.0
                    }
                };
                let (a, b) = (i as f64 / n as f64 + jitter(rng), j as f64 / n as f64 + jitter(rng));
                let p = [0, 1, 2].map(|k| o[k] + a * u[k] + b * v[k]);
                let key = p.map(f64::to_bits);
                let id = *index.entry(key).or_insert_with(|| {
                    positions.push(p);
                    positions.len() as u32 - 1
                });
                grid[j * (n + 1) + i] = id;
            }
        }
        for j in 0..n {
            for i in 0..n {
                let at = |i: usize, j: usize| grid[j * (n + 1) + i];
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                if rng.below(2) == 0 {
                    triangles.extend([[a, b, c], [a, c, d]]);
                } else {
                    triangles.extend([[a, b, d], [b, c, d]]);
                }
            }
        }
    }
    case("jittered cube", positions, triangles)
}

fn cases(rng: &mut Rng) -> Vec<Case> {
    let mut cases: Vec<Case> = common::fixtures().iter().map(|p| read_case(p)).collect();
    cases.push(read_case(&common::data_dir().join("cad/rotor.obj")));
    let (p, t) = common::cone_fan(32);
    cases.push(case("cone fan", p, t));
    let (p, t) = common::marching_sphere(6, 0.01);
    cases.push(case("marching sphere", p, t));
    cases.push(jittered_cube(8, rng));
    // Far from the origin and at extreme scales (powers of two: the cube's
    // faces stay exactly flat).
    let moved = |c: &Case, name: &str, f: &dyn Fn(DVec3) -> DVec3| Case {
        name: format!("{} {name}", c.name),
        input: Mesh3 {
            positions: c.input.positions.iter().map(|&p| f(p)).collect(),
            triangles: c.input.triangles.clone(),
        },
    };
    let (cone, cube) = (&cases[cases.len() - 3], &cases[cases.len() - 1]);
    let more = [
        moved(cone, "at 1e6", &|p| p + DVec3::splat(1e6)),
        moved(cube, "at 2^20", &|p| p + DVec3::splat(1048576.0)),
        moved(cube, "times 2^-200", &|p| p * 2f64.powi(-200)),
        moved(cone, "times 2^200", &|p| p * 2f64.powi(200)),
    ];
    cases.extend(more);
    cases
}

/// The construction's output for `input`, with the surface (which knows
/// each added vertex's input edge).
fn refine(input: &Mesh3, options: &Options) -> (Surface, Mesh3) {
    let mut s = Surface::new(input.positions.clone(), &input.triangles).unwrap();
    make_delaunay(&mut s, options).unwrap();
    let output = Mesh3 {
        positions: s.positions.clone(),
        triangles: s.triangles(),
    };
    (s, output)
}

/// The output renumbered without changing it: faces shuffled, corners
/// rotated, added vertices permuted.
fn renumbered(out: &Mesh3, n_input: usize, rng: &mut Rng) -> Mesh3 {
    let n = out.positions.len();
    // Fisher-Yates over the added vertices: new index of each old one.
    let mut order: Vec<usize> = (0..n).collect();
    for i in (n_input + 1..n).rev() {
        let j = n_input + rng.below((i - n_input + 1) as u64) as usize;
        order.swap(i, j);
    }
    let mut positions = vec![DVec3::ZERO; n];
    for (old, &new) in order.iter().enumerate() {
        positions[new] = out.positions[old];
    }
    let mut triangles: Vec<[u32; 3]> = (out.triangles.iter())
        .map(|t| {
            let r = rng.below(3) as usize;
            let t = t.map(|v| order[v as usize] as u32);
            [t[r], t[(r + 1) % 3], t[(r + 2) % 3]]
        })
        .collect();
    for i in (1..triangles.len()).rev() {
        let j = rng.below(i as u64 + 1) as usize;
        triangles.swap(i, j);
    }
    Mesh3 { positions, triangles }
}

/// An added vertex of `out` slid along its input edge to a random point
/// strictly between its neighbours on it (no face turns over), with the
/// largest α + β − π of the interior edges then.
fn slid(s: &Surface, out: &Mesh3, rng: &mut Rng) -> Option<(Mesh3, f64)> {
    let (v, edge, t) = random_added_vertex(s, rng)?;
    let (before, after) = neighbours_on_edge(s, edge, t);
    let gap = after - before;
    let t = rng.range(before + 0.05 * gap, after - 0.05 * gap);
    let [a, b] = s.input_edge_ends(edge);
    let mut m = out.clone();
    m.positions[v] = delmesh::samples::point_on_edge(a, b, t);
    let edges = directed_edges(&m);
    let p = |v: u32| m.positions[v as usize];
    let worst = (edges.iter())
        .filter(|&(&(a, b), _)| a < b)
        .filter_map(|(&(a, b), &(f, k))| {
            let &(g, j) = edges.get(&(b, a))?;
            let (c, d) = (m.triangles[f][(k + 2) % 3], m.triangles[g][(j + 2) % 3]);
            Some(delmesh::geometry::delaunay_excess(p(a), p(b), p(c), p(d)))
        })
        .fold(f64::NEG_INFINITY, f64::max);
    Some((m, worst))
}

fn describe(report: &CheckReport) -> String {
    report.failures.join("; ")
}

#[test]
fn damaged_outputs_are_refused_and_renumbered_ones_accepted() {
    let rounds = env_u64("CHECK_SOUNDNESS_ROUNDS", 2);
    let mut rng = Rng::new(env_u64("CHECK_SOUNDNESS_SEED", 20261204));
    let settings = [Options::default(), Options::new(Worklist::Queue, Score::AllEqual, true)];
    let mut refused = HashMap::<String, usize>::new();
    let mut slides = HashMap::<&str, usize>::new();
    let mut problems = Vec::new();
    for case in cases(&mut rng) {
        let n_input = case.input.positions.len();
        for options in &settings {
            let (s, out) = refine(&case.input, options);
            let tag = format!("{} ({:?}, {:?})", case.name, options.worklist, options.score);
            let report = check_meshes(&case.input, &out);
            assert!(report.passed(), "{tag}: the output itself fails: {}", describe(&report));
            for _ in 0..rounds {
                let same = renumbered(&out, n_input, &mut rng);
                let report = check_meshes(&case.input, &same);
                if !report.passed() {
                    problems.push(format!("{tag}: renumbered output refused: {}", describe(&report)));
                }
                if let Some((m, worst)) = slid(&s, &out, &mut rng) {
                    let passed = check_meshes(&case.input, &m).passed();
                    if worst < 0.5e-9 && !passed {
                        problems.push(format!("{tag}: slid vertex refused (worst excess {worst:e})"));
                    } else if worst > 2e-9 && passed {
                        problems.push(format!("{tag}: slid vertex accepted (worst excess {worst:e})"));
                    }
                    let verdict = if worst < 0.5e-9 { "Delaunay" } else { "over 0.5e-9" };
                    *slides.entry(verdict).or_default() += 1;
                }
                for kind in DAMAGES {
                    let Some(damaged) = damage(kind, &s, &out, &mut rng) else {
                        continue;
                    };
                    let report = check_meshes(&case.input, &damaged);
                    if report.passed() {
                        problems.push(format!("{tag}: {kind:?} accepted"));
                    } else {
                        *refused.entry(format!("{kind:?}")).or_default() += 1;
                    }
                }
            }
        }
    }
    let mut counts: Vec<_> = refused.into_iter().collect();
    counts.sort();
    eprintln!("refused: {counts:?}; slides: {slides:?}");
    assert!(
        problems.is_empty(),
        "{} problems:\n{}",
        problems.len(),
        problems.join("\n")
    );
    // Every kind of damage found a place on some mesh.
    assert_eq!(
        counts.len(),
        DAMAGES.len(),
        "a kind of damage never applied: {counts:?}"
    );
}
