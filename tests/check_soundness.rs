//! The checker's soundness and stability, by damage with a known verdict.
//!
//! Outputs of the construction (the fixtures, a CAD part, a cone-like fan,
//! a marching-tetrahedra sphere with near-coincident vertices, a cube whose
//! exactly flat faces are jittered grids with random diagonals) are each
//! changed once, many times over, in ways whose verdict is known:
//!
//! - refused: an added vertex moved off its input edge, or along it past the
//!   next vertex on it; an input vertex moved
//!   by one unit in the last place; a face removed, doubled or turned over; an
//!   edge flipped across a crease (its quad not exactly flat); an edge
//!   flipped inside a flat region where the other diagonal is non-Delaunay by
//!   more than 1e-6 rad; a face split into three at an inner point;
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
use std::f64::consts::PI;

use common::Rng;
use delmesh::check::{check_meshes, CheckReport, Mesh3};
use delmesh::io;
use delmesh::mesh::{Carrier, Surface};
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

/// Where each directed edge (u, v) is: its face and the corner it starts at.
fn directed_edges(m: &Mesh3) -> HashMap<(u32, u32), (usize, usize)> {
    let mut map = HashMap::new();
    for (f, t) in m.triangles.iter().enumerate() {
        for k in 0..3 {
            map.insert((t[k], t[(k + 1) % 3]), (f, k));
        }
    }
    map
}

fn angle(at: DVec3, p: DVec3, q: DVec3) -> f64 {
    let (u, v) = (p - at, q - at);
    u.cross(v).length().atan2(u.dot(v))
}

fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let c3 = |p: DVec3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
    robust::orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// Kinds of damage; each gives the damaged output, or `None` if this mesh
/// offers no place for it (tried again elsewhere by the caller).
#[derive(Clone, Copy, Debug)]
enum Damage {
    AddedVertexOffItsEdge,
    AddedVertexPastItsNeighbour,
    InputVertexOneUlp,
    FaceRemoved,
    FaceDoubled,
    FaceTurnedOver,
    CreaseFlipped,
    FlatFlipNonDelaunay,
    FaceSplitInside,
}

const DAMAGES: [Damage; 9] = [
    Damage::AddedVertexOffItsEdge,
    Damage::AddedVertexPastItsNeighbour,
    Damage::InputVertexOneUlp,
    Damage::FaceRemoved,
    Damage::FaceDoubled,
    Damage::FaceTurnedOver,
    Damage::CreaseFlipped,
    Damage::FlatFlipNonDelaunay,
    Damage::FaceSplitInside,
];

/// The faces (a, b, c) and (b, a, d) of a random interior edge (a, b) such
/// that `wanted(a, b, c, d)`, as (face 1, face 2, [a, b, c, d]); up to 200
/// tries.
fn random_interior_edge(
    m: &Mesh3,
    edges: &HashMap<(u32, u32), (usize, usize)>,
    rng: &mut Rng,
    wanted: impl Fn([DVec3; 4]) -> bool,
) -> Option<(usize, usize, [u32; 4])> {
    for _ in 0..200 {
        let f = rng.below(m.triangles.len() as u64) as usize;
        let k = rng.below(3) as usize;
        let t = m.triangles[f];
        let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        let Some(&(g, j)) = edges.get(&(b, a)) else {
            continue;
        };
        let d = m.triangles[g][(j + 2) % 3];
        let quad = [a, b, c, d];
        if wanted(quad.map(|v| m.positions[v as usize])) {
            return Some((f, g, quad));
        }
    }
    None
}

/// Replaces faces `f` = (a, b, c) and `g` = (b, a, d) by (c, a, d) and (d, b, c).
///
/// ```text
///        c                c
///       / \              /|\
///      a---b    ->      a | b
///       \ /              \|/
///        d                d
/// ```
fn flip(m: &mut Mesh3, f: usize, g: usize, [a, b, c, d]: [u32; 4]) {
    m.triangles[f] = [c, a, d];
    m.triangles[g] = [d, b, c];
}

/// A random added vertex of `s` (`None` if it has none), with its input
/// edge and parameter on it.
fn random_added_vertex(s: &Surface, n_input: usize, rng: &mut Rng) -> Option<(usize, u32, f64)> {
    let added = s.positions.len() - n_input;
    if added == 0 {
        return None;
    }
    let v = n_input + rng.below(added as u64) as usize;
    let Carrier::Edge { edge, t } = s.carriers[v] else {
        unreachable!("an added vertex lies on an input edge")
    };
    Some((v, edge, t))
}

/// The parameters of the vertices next to parameter `t` on input edge
/// `edge` of `s`, before and after it (0 and 1 at its ends).
fn neighbours_on_edge(s: &Surface, n_input: usize, edge: u32, t: f64) -> (f64, f64) {
    let (mut before, mut after) = (0.0f64, 1.0f64);
    for c in &s.carriers[n_input..] {
        if let Carrier::Edge { edge: e, t: u } = *c {
            if e == edge && u < t {
                before = before.max(u);
            } else if e == edge && u > t {
                after = after.min(u);
            }
        }
    }
    (before, after)
}

fn damage(kind: Damage, s: &Surface, out: &Mesh3, n_input: usize, rng: &mut Rng) -> Option<Mesh3> {
    let mut m = out.clone();
    let n_faces = m.triangles.len() as u64;
    match kind {
        Damage::AddedVertexOffItsEdge => {
            let (v, edge, _) = random_added_vertex(s, n_input, rng)?;
            let [a, b] = s.input_edge_ends(edge);
            let dir = (b - a).normalize();
            // A random direction square to the edge ...
            let w = DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            let perp = (w - dir * w.dot(dir)).try_normalize()?;
            // ... and a distance from 100 times the on-edge tolerance (1e-9
            // of the edge's largest coordinate) to a thousandth of the
            // shortest edge at the vertex, log-uniform.
            let p = m.positions[v];
            let shortest = (m.triangles.iter())
                .filter(|t| t.contains(&(v as u32)))
                .flat_map(|t| t.map(|x| (m.positions[x as usize] - p).length()))
                .filter(|&l| l > 0.0)
                .fold(f64::INFINITY, f64::min);
            let scale = a.abs().max_element().max(b.abs().max_element());
            let (near, far) = (1e-9 * scale, (1e-3 * shortest).max(2e-9 * scale));
            let distance = near * (far / near).powf(rng.f64());
            m.positions[v] = p + perp * distance;
        }
        Damage::AddedVertexPastItsNeighbour => {
            // Along its input edge, halfway past the next vertex on it (an
            // added one, or the edge's end: then off the edge): the faces
            // between the two turn over.
            let (v, edge, t) = random_added_vertex(s, n_input, rng)?;
            let (_, next) = neighbours_on_edge(s, n_input, edge, t);
            let [a, b] = s.input_edge_ends(edge);
            m.positions[v] = delmesh::samples::point_on_edge(a, b, next + 0.5 * (next - t));
        }
        Damage::InputVertexOneUlp => {
            let v = rng.below(n_input as u64) as usize;
            let k = rng.below(3) as usize;
            let mut c = m.positions[v].to_array();
            c[k] = f64::from_bits(c[k].to_bits() ^ 1);
            m.positions[v] = DVec3::from_array(c);
        }
        Damage::FaceRemoved => {
            m.triangles.swap_remove(rng.below(n_faces) as usize);
        }
        Damage::FaceDoubled => {
            let t = m.triangles[rng.below(n_faces) as usize];
            m.triangles.push(t);
        }
        Damage::FaceTurnedOver => {
            let f = rng.below(n_faces) as usize;
            m.triangles[f].swap(0, 1);
        }
        Damage::CreaseFlipped => {
            let edges = directed_edges(&m);
            let (f, g, quad) = random_interior_edge(&m, &edges, rng, |[a, b, c, d]| orient3d(a, b, c, d) != 0.0)?;
            flip(&mut m, f, g, quad);
        }
        Damage::FlatFlipNonDelaunay => {
            // In an exactly flat quad (a, d, b, c), the other diagonal's
            // angles sum to 2π − (α + β), the angles at c and d: over π by
            // as much as α + β is under it. (If the quad is not convex the
            // flip folds a face instead: refused as well.)
            let edges = directed_edges(&m);
            let (f, g, quad) = random_interior_edge(&m, &edges, rng, |[a, b, c, d]| {
                orient3d(a, b, c, d) == 0.0 && angle(c, a, b) + angle(d, a, b) < PI - 1e-6
            })?;
            flip(&mut m, f, g, quad);
        }
        Damage::FaceSplitInside => {
            let f = rng.below(n_faces) as usize;
            let [a, b, c] = m.triangles[f];
            let p = [a, b, c].map(|v| m.positions[v as usize]);
            let (wa, wb) = (rng.range(0.2, 0.4), rng.range(0.2, 0.4));
            let inner = p[0] * wa + p[1] * wb + p[2] * (1.0 - wa - wb);
            let v = m.positions.len() as u32;
            m.positions.push(inner);
            m.triangles[f] = [a, b, v];
            m.triangles.extend([[b, c, v], [c, a, v]]);
        }
    }
    Some(m)
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
fn slid(s: &Surface, out: &Mesh3, n_input: usize, rng: &mut Rng) -> Option<(Mesh3, f64)> {
    let (v, edge, t) = random_added_vertex(s, n_input, rng)?;
    let (before, after) = neighbours_on_edge(s, n_input, edge, t);
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
                if let Some((m, worst)) = slid(&s, &out, n_input, &mut rng) {
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
                    let Some(damaged) = damage(kind, &s, &out, n_input, &mut rng) else {
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
