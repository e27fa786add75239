//! Tests of the independent checker (`check` module): valid results pass, every kind of
//! invalid result is reported, and the Delaunay count agrees with a brute-force count.

mod common;

use std::collections::HashMap;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use delmesh::check::{check_files, check_meshes, CheckError, CheckReport, Mesh3};
use glam::DVec3;
use tempfile::TempDir;

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/// OBJ text of a mesh with 0-based faces.
fn obj(vertices: &[[f64; 3]], faces: &[[u32; 3]]) -> String {
    let mut text = String::new();
    for v in vertices {
        text.push_str(&format!("v {:?} {:?} {:?}\n", v[0], v[1], v[2]));
    }
    for f in faces {
        text.push_str(&format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1));
    }
    text
}

/// Writes `text` to `dir/name` and returns the path.
fn write(dir: &TempDir, name: &str, text: &str) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, text).expect("write test file");
    path
}

/// Checks output text against input text through files.
fn check_texts(input: &str, output: &str) -> CheckReport {
    let dir = TempDir::new().expect("tempdir");
    let input = write(&dir, "input.obj", input);
    let output = write(&dir, "output.obj", output);
    check_files(&input, &output).expect("both files are valid meshes")
}

/// True iff some failure line contains `needle`.
fn has(report: &CheckReport, needle: &str) -> bool {
    report.failures.iter().any(|line| line.contains(needle))
}

/// Asserts that some failure line contains `needle`, showing the report otherwise.
fn assert_failure(report: &CheckReport, needle: &str) {
    assert!(
        has(report, needle),
        "expected a failure containing {needle:?}, got:\n{report}"
    );
}

fn assert_passes(report: &CheckReport) {
    assert!(report.passed(), "expected a pass, got:\n{report}");
}

/// A small deterministic random generator (SplitMix64) giving floats in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }

    fn vec(&mut self, scale: f64) -> DVec3 {
        DVec3::new(
            self.range(-scale, scale),
            self.range(-scale, scale),
            self.range(-scale, scale),
        )
    }
}

// ---------------------------------------------------------------------------------------------
// Test meshes
// ---------------------------------------------------------------------------------------------

const OCTA_V: [[f64; 3]; 6] = [
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
];
const OCTA_F: [[u32; 3]; 8] = [
    [0, 2, 4],
    [2, 1, 4],
    [1, 3, 4],
    [3, 0, 4],
    [2, 0, 5],
    [1, 2, 5],
    [3, 1, 5],
    [0, 3, 5],
];

fn octahedron() -> String {
    obj(&OCTA_V, &OCTA_F)
}

const TETRA_V: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
const TETRA_F: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];

/// a, b, c, d of the kite: edge ab is long, c above it, d below it (flat) or folded up.
fn kite(folded: bool) -> [[f64; 3]; 4] {
    let dz = if folded { 0.5 } else { 0.0 };
    [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [2.0, 0.3, 0.0], [2.0, -0.3, dz]]
}

/// The two kite faces sharing the long (non-Delaunay) edge ab.
const KITE_F: [[u32; 3]; 2] = [[0, 1, 2], [1, 0, 3]];

/// The folded kite with edge ab split at `m` (vertex 5): four faces.
fn split_kite(m: [f64; 3]) -> String {
    let mut v = kite(true).to_vec();
    v.push(m);
    obj(&v, &[[0, 4, 2], [4, 1, 2], [1, 4, 3], [4, 0, 3]])
}

// ---------------------------------------------------------------------------------------------
// Valid results pass
// ---------------------------------------------------------------------------------------------

/// The octahedron with vertex 0 given a copy at its position that two of
/// its four faces use: welded by position it is the octahedron, but a
/// reader that does not weld sees it cut open along two edges.
fn octahedron_with_a_copy() -> String {
    let mut v = OCTA_V.to_vec();
    v.push(OCTA_V[0]);
    let mut seen = 0;
    let f: Vec<[u32; 3]> = (OCTA_F.iter())
        .map(|t| {
            if t.contains(&0) {
                seen += 1;
                if seen <= 2 {
                    return t.map(|c| if c == 0 { 6 } else { c });
                }
            }
            *t
        })
        .collect();
    obj(&v, &f)
}

#[test]
fn an_output_cut_open_by_a_copy_of_a_vertex_fails() {
    let report = check_texts(&octahedron(), &octahedron_with_a_copy());
    assert_failure(
        &report,
        "but apart in the file (line 1 and line 7): a reader that does not weld positions sees a crack there",
    );
    assert_eq!(report.failures.len(), 1, "{report}");
    // An input cut so itself: its output is not judged for copies (the
    // construction welds them; --repair's cuts are such copies too).
    assert_passes(&check_texts(&octahedron_with_a_copy(), &octahedron_with_a_copy()));
    assert_passes(&check_texts(&octahedron_with_a_copy(), &octahedron()));
}

#[test]
fn delaunay_closed_meshes_pass_against_themselves() {
    for text in [octahedron(), obj(&TETRA_V, &TETRA_F)] {
        let report = check_texts(&text, &text);
        assert_passes(&report);
        assert_eq!(report.added_vertices, 0);
        assert_eq!(report.non_delaunay_edges, 0);
        assert_eq!(report.interior_edges, report.input_faces * 3 / 2);
        assert!(report.max_excess < 0.0);
    }
}

#[test]
fn cocircular_square_passes_within_tolerance() {
    let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let text = obj(&v, &[[0, 1, 2], [0, 2, 3]]);
    let report = check_texts(&text, &text);
    assert_passes(&report);
    assert_eq!(report.interior_edges, 1);
    assert!(report.max_excess.abs() < 1e-12);
}

#[test]
fn flat_kite_fixed_by_flipping_passes() {
    let input = obj(&kite(false), &KITE_F);
    let output = obj(&kite(false), &[[0, 3, 2], [3, 1, 2]]);
    let report = check_texts(&input, &output);
    assert_passes(&report);
    assert_eq!(report.input_regions, 1);
    assert_eq!(report.non_delaunay_edges, 0);
}

#[test]
fn folded_kite_fixed_by_splitting_passes() {
    let input = obj(&kite(true), &KITE_F);
    let report = check_texts(&input, &split_kite([2.0, 0.0, 0.0]));
    assert_passes(&report);
    assert_eq!(report.input_regions, 2);
    assert_eq!(report.added_vertices, 1);
    assert_eq!(report.interior_edges, 4);
}

#[test]
fn folded_back_coplanar_faces_are_separate_regions() {
    // Both faces in z = 0, but d is on the same side of ab as c: the surface folds back.
    let v = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [2.0, 1.0, 0.0], [2.0, 0.5, 0.0]];
    let text = obj(&v, &KITE_F);
    let report = check_texts(&text, &text);
    assert_eq!(report.input_regions, 2);
    let flat = obj(&kite(false), &KITE_F);
    assert_eq!(check_texts(&flat, &flat).input_regions, 1);
}

#[test]
fn points_computed_on_edges_are_accepted_and_points_off_edges_refused() {
    let mut rng = Rng(7);
    for i in 0..2000 {
        let scale = 10f64.powf(rng.range(-3.0, 6.0));
        let offset = if i % 2 == 0 { rng.vec(scale * 10.0) } else { DVec3::ZERO };
        let [a, b, c, d] = [0; 4].map(|_| rng.vec(scale) + offset);
        let input = Mesh3 {
            positions: vec![a, b, c, d],
            triangles: KITE_F.to_vec(),
        };
        let t = rng.range(0.001, 0.999);
        let on = a + t * (b - a);
        let split = |m: DVec3| Mesh3 {
            positions: vec![a, b, c, d, m],
            triangles: vec![[0, 4, 2], [4, 1, 2], [1, 4, 3], [4, 0, 3]],
        };
        let report = check_meshes(&input, &split(on));
        assert!(!has(&report, "neither"), "case {i}: point on edge refused:\n{report}");
        let largest = a.abs().max(b.abs()).max_element();
        let normal = (b - a).cross(c - a).normalize();
        let off = on + normal * (1e-9 * largest);
        let report = check_meshes(&input, &split(off));
        assert!(has(&report, "output vertex 5"), "case {i}: point off edge accepted");
    }
}

// ---------------------------------------------------------------------------------------------
// Invalid results are reported
// ---------------------------------------------------------------------------------------------

#[test]
fn non_delaunay_output_is_reported() {
    let input = obj(&kite(true), &KITE_F);
    let report = check_texts(&input, &input);
    assert_eq!(report.non_delaunay_edges, 1);
    assert_eq!(report.failures.len(), 1, "{report}");
    assert_failure(&report, "non-Delaunay edge (v1, v2): alpha+beta-pi = ");
    assert!(report.max_excess > 2.0);
}

#[test]
fn moved_input_vertex_is_reported() {
    let mut v = OCTA_V;
    v[0][0] += 1e-6;
    let report = check_texts(&octahedron(), &obj(&v, &OCTA_F));
    assert_failure(&report, "input vertex 1 (1, 0, 0) missing from output");
    assert_failure(
        &report,
        "output vertex 1 (1.000001, 0, 0) is neither an input vertex nor on an input edge",
    );
}

#[test]
fn added_vertex_off_its_edge_is_reported() {
    let input = obj(&kite(true), &KITE_F);
    for y in [1e-7, 4e-9] {
        let report = check_texts(&input, &split_kite([2.0, y, 0.0]));
        assert_failure(&report, "output vertex 5 (2, ");
        assert_failure(&report, "is neither an input vertex nor on an input edge");
    }
}

/// A vertex no face uses is still an output vertex: SPEC's carrier rule holds for it too, so
/// one off the input's edges fails (before, the reader dropped it unseen), and one at an input
/// vertex or on an input edge passes, counted, since a Laplacian gets an empty row for it.
#[test]
fn unused_output_vertices_must_be_carriers_too() {
    let input = obj(&kite(true), &KITE_F);
    let output = split_kite([2.0, 0.0, 0.0]);
    let with = |extra: &str| format!("{output}{extra}");
    let stray = check_texts(&input, &with("v 7 7 7\n"));
    assert_failure(
        &stray,
        "an output vertex no face uses, (7, 7, 7), is neither an input vertex nor on an input edge",
    );
    assert_eq!((stray.failures.len(), stray.unused_vertices), (1, 1), "{stray}");
    assert_eq!((stray.output_vertices, stray.added_vertices), (5, 1));
    let not_finite = check_texts(&input, &with("v nan 0 0\n"));
    assert_failure(&not_finite, "an output vertex no face uses, (NaN, 0, 0), is neither");
    // Off the folded edge by 1e-7: not on it (the same rule as a used vertex's).
    assert_failure(
        &check_texts(&input, &with("v 1 1e-7 0\n")),
        "no face uses, (1, 0.0000001, 0)",
    );
    for fine in ["v 1 0 0\n", "v 2 0.3 0\nv 1 0 0\n", "v 0 0 0\n"] {
        let report = check_texts(&input, &with(fine));
        assert_passes(&report);
        // A repeated position is the same vertex, welded: not unused.
        let expected = if fine == "v 0 0 0\n" { 0 } else { 1 };
        assert_eq!(report.unused_vertices, expected, "{fine:?}");
    }
    // An input vertex no face uses may stay one in the output; elsewhere it is a stray.
    let input_with_stray = format!("{input}v 5 5 5\n");
    let kept = check_texts(&input_with_stray, &with("v 5 5 5\n"));
    assert_passes(&kept);
    assert_eq!(kept.unused_vertices, 1);
    assert_passes(&check_texts(&input_with_stray, &output));
    // The same through OFF, whose reader is another.
    let dir = TempDir::new().expect("tempdir");
    let input_path = write(&dir, "input.obj", &input);
    let mut v = kite(true).to_vec();
    v.extend([[2.0, 0.0, 0.0], [7.0, 7.0, 7.0]]);
    let mut off = format!("OFF\n{} 4 0\n", v.len());
    v.iter()
        .for_each(|p| off.push_str(&format!("{} {} {}\n", p[0], p[1], p[2])));
    ["0 4 2", "4 1 2", "1 4 3", "4 0 3"]
        .iter()
        .for_each(|f| off.push_str(&format!("3 {f}\n")));
    let report = check_files(&input_path, &write(&dir, "output.off", &off)).expect("valid files");
    assert_failure(&report, "an output vertex no face uses, (7, 7, 7)");
    // And through the library, with a position no triangle refers to.
    let mut mesh = Mesh3 {
        positions: v.iter().map(|p| DVec3::from_array(*p)).collect(),
        triangles: vec![[0, 4, 2], [4, 1, 2], [1, 4, 3], [4, 0, 3]],
    };
    let kite_mesh = Mesh3 {
        positions: kite(true).iter().map(|p| DVec3::from_array(*p)).collect(),
        triangles: KITE_F.to_vec(),
    };
    assert_failure(&check_meshes(&kite_mesh, &mesh), "no face uses, (7, 7, 7)");
    mesh.positions.pop();
    assert_passes(&check_meshes(&kite_mesh, &mesh));
}

/// The numbering is not geometry: an output that does not begin with the input's vertices in
/// their order passes, and the report says where it stops doing so.
#[test]
fn reordered_input_vertices_are_reported_not_failed() {
    let input = obj(&kite(true), &KITE_F);
    let report = check_texts(&input, &split_kite([2.0, 0.0, 0.0]));
    assert_eq!(report.first_reordered_vertex, None);
    // Vertices 2 and 3 swapped, the faces renumbered to match.
    let mut v = kite(true).to_vec();
    v.swap(1, 2);
    v.push([2.0, 0.0, 0.0]);
    let swapped = obj(&v, &[[0, 4, 1], [4, 2, 1], [2, 4, 3], [4, 0, 3]]);
    let report = check_texts(&input, &swapped);
    assert_passes(&report);
    assert_eq!(report.first_reordered_vertex, Some(1));
    assert!(report.to_string().contains("output vertex 2 differs"), "{report}");
    // Welded duplicates and unused vertices do not count: positions in order of first use.
    let dup = format!(
        "v 9 9 9\n{}",
        obj(&kite(true), &[[0, 1, 2], [1, 0, 3]]).replace("v 0.0 0.0 0.0\n", "v 0.0 0.0 0.0\nv 0.0 0.0 0.0\n")
    );
    let report = check_texts(
        &dup.replace("f 1 2 3\nf 2 1 4", "f 2 4 5\nf 4 2 6"),
        &split_kite([2.0, 0.0, 0.0]),
    );
    assert_passes(&report);
    assert_eq!(report.first_reordered_vertex, None, "{report}");
    // Fewer output vertices than input ones: the first missing one.
    let report = check_meshes(
        &Mesh3 {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            triangles: TETRA_F.to_vec(),
        },
        &Mesh3 {
            positions: vec![DVec3::ZERO, DVec3::X],
            triangles: vec![],
        },
    );
    assert_eq!(report.first_reordered_vertex, Some(2));
}

/// A flat square of side `side` in z = 0, fanned from its centre (vertex 4): its corners
/// and centre, and its four faces.
fn fanned_square(side: f64) -> (Vec<[f64; 3]>, [[u32; 3]; 4]) {
    let v = vec![
        [0.0, 0.0, 0.0],
        [side, 0.0, 0.0],
        [side, side, 0.0],
        [0.0, side, 0.0],
        [side / 2.0, side / 2.0, 0.0],
    ];
    (v, [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
}

#[test]
fn missing_input_vertex_is_reported() {
    let (v, faces) = fanned_square(2.0);
    let input = obj(&v, &faces);
    let output = obj(&v, &[[0, 1, 2], [0, 2, 3]]); // vertex 5 no longer used
    let report = check_texts(&input, &output);
    assert_eq!(
        report.failures,
        vec!["input vertex 5 (1, 1, 0) missing from output".to_string()]
    );
}

#[test]
fn removed_face_is_reported() {
    let report = check_texts(&octahedron(), &obj(&OCTA_V, &OCTA_F[..7]));
    assert_failure(&report, "region 8 (containing input face 8) area ");
    assert_failure(&report, "became 0");
    assert_failure(&report, "Euler characteristic 2 became 1");
    assert_failure(&report, "number of boundary loops 0 became 1");
}

/// A face at the border of a curved strip, removed: the Euler characteristic
/// and the boundary loops stay as they were (the border goes round the gap),
/// so only its region's area tells. Beside a far larger triangle (a far
/// vertex, as a fuzzed file had at 2.2e12) that area is below 1e-12 of the
/// total, which the area tolerance's floor once was: the output passed.
#[test]
fn face_removed_at_the_border_is_reported_beside_a_huge_face() {
    // A 3 x 1 strip of bent squares (each triangle its own region), and a
    // separate triangle of area 5e13.
    let mut v: Vec<[f64; 3]> = (0..8)
        .map(|i| [(i % 4) as f64, (i / 4) as f64, ((i * i) % 3) as f64 * 0.3])
        .collect();
    v.extend([[0.0, 0.0, 10.0], [1e7, 0.0, 10.0], [0.0, 1e7, 10.0]]);
    let strip: Vec<[u32; 3]> = (0..3).flat_map(|i| [[i, i + 1, i + 5], [i, i + 5, i + 4]]).collect();
    let mut faces = strip.clone();
    faces.push([8, 9, 10]);
    let input = obj(&v, &faces);
    assert_passes(&check_texts(&input, &input));
    for gone in 0..strip.len() {
        let mut fewer = faces.clone();
        fewer.remove(gone);
        let report = check_texts(&input, &obj(&v, &fewer));
        assert!(!report.passed(), "face {gone} removed, passed:\n{report}");
        assert_failure(&report, "became 0");
    }
}

/// A flat unit square fanned from its centre `e`, and an output with two vertices added on its
/// bottom edge 2^-34 apart: the face between them and `e` has an area of 1.5e-11, below the
/// billionth of its region's area that the area rule allows. Removed, it leaves the counts of
/// the topology as they were (one edge and one face fewer, one boundary loop), so only the
/// boundary rule sees it: the output's boundary now goes up to `e` and back.
#[test]
fn tiny_face_removed_along_the_boundary_is_reported() {
    let (mut v, square) = fanned_square(1.0);
    let input = obj(&v, &square);
    v.extend([[0.5, 0.0, 0.0], [0.5 + 2f64.powi(-34), 0.0, 0.0]]);
    let mut faces = vec![[0, 5, 4], [5, 6, 4], [6, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
    assert_passes(&check_texts(&input, &obj(&v, &faces)));
    faces.remove(1);
    let report = check_texts(&input, &obj(&v, &faces));
    assert_eq!(
        report.failures,
        vec![
            "output boundary edge (v5, v6) lies along no input boundary edge (a face along the boundary removed, or one added)",
            "output boundary edge (v5, v7) lies along no input boundary edge (a face along the boundary removed, or one added)",
        ],
        "{report}"
    );
}

/// A square fanned from its centre with one face missing, and an output that has the face:
/// the output's boundary edge across the gap lies along no input boundary edge, and the
/// input's two boundary edges into the centre have no output boundary edge along them.
#[test]
fn face_added_across_the_boundary_is_reported() {
    let (v, faces) = fanned_square(1.0);
    let report = check_texts(&obj(&v, &faces[..3]), &obj(&v, &faces));
    assert_failure(
        &report,
        "output boundary edge (v1, v4) lies along no input boundary edge",
    );
    assert_failure(
        &report,
        "input boundary edge (v1, v5) has no output boundary edge along it",
    );
    assert_failure(
        &report,
        "input boundary edge (v4, v5) has no output boundary edge along it",
    );
}

/// A face whose corners are collinear, closing the boundary under a vertex added on a boundary
/// edge, is reported, and nothing else fails: the areas add up, its two edges to the vertex
/// are Delaunay (it sees them under 0), the boundary edge it keeps lies along the input's, and
/// the fans are disks. Only rule 3's exact orientation test (zero area in the region's plane)
/// catches it. (Mutation testing: accepting a zero-area face there passed every other test.)
///
/// ```text
///   v4 ----------- v3
///   | .           .|      faces (v1, v5, v4), (v5, v2, v3), (v5, v3, v4)
///   |    .     .   |      and the collinear (v5, v1, v2): v5 at the middle of v1-v2,
///   |       .      |      which stays a boundary edge
///   v1 ---- v5 --- v2
/// ```
#[test]
fn a_collinear_face_closing_the_boundary_is_reported() {
    let square = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0]];
    let mut with_middle = square.to_vec();
    with_middle.push([1.0, 0.0, 0.0]);
    let faces = [[0, 4, 3], [4, 1, 2], [4, 2, 3], [4, 0, 1]];
    let input = obj(&square, &[[0, 1, 2], [0, 2, 3]]);
    let report = check_texts(&input, &obj(&with_middle, &faces));
    assert_failure(
        &report,
        "output face 4 (v5, v1, v2) has zero area (its corners are collinear) in region 1",
    );
    assert_eq!(report.failures.len(), 1, "{report}");
    // Without it, the three faces are a Delaunay mesh of the square, with v5 on its boundary.
    assert_passes(&check_texts(&input, &obj(&with_middle, &faces[..3])));
}

/// `misplaced_vertices` counts the output vertices off the input's edges, and those of them
/// with only rounded coordinates (what a file written with `%f` or as PLY `float` holds).
#[test]
fn misplaced_vertices_with_rounded_coordinates_are_counted() {
    // A triangle whose corners have irrational coordinates, and a vertex added at a third of
    // its first edge.
    let third = 1.0 / 3.0;
    let root = |x: f64| x.sqrt();
    let v = [
        [0.0, 0.0, 0.0],
        [root(2.0) / 4.0, root(3.0) / 7.0, 0.0],
        [root(5.0) / 9.0, 0.5, root(7.0) / 11.0],
    ];
    let input = obj(&v, &[[0, 1, 2]]);
    let on_edge = [v[1][0] / 3.0, v[1][1] / 3.0, 0.0];
    let faces = [[0, 3, 2], [3, 1, 2]];
    let exact = check_texts(&input, &obj(&[v[0], v[1], v[2], on_edge], &faces));
    assert_passes(&exact);
    assert_eq!(exact.misplaced_vertices, (0, 0));
    // Off its edge by 1e-7 at full precision: misplaced, not rounded.
    let moved = [on_edge[0], on_edge[1], 1e-7 * third];
    let report = check_texts(&input, &obj(&[v[0], v[1], v[2], moved], &faces));
    assert_eq!(report.misplaced_vertices, (1, 0), "{report}");
    // Printed with six decimals: two corners move too (missing input vertices, and misplaced
    // output ones; the origin stays), all three rounded; as 32-bit floats likewise.
    let six = |p: [f64; 3]| p.map(|x| format!("{x:.6}").parse::<f64>().unwrap());
    let report = check_texts(&input, &obj(&[v[0], v[1], v[2], on_edge].map(six), &faces));
    assert_eq!(report.misplaced_vertices, (3, 3), "{report}");
    let float = |p: [f64; 3]| p.map(|x| f64::from(x as f32));
    let report = check_texts(&input, &obj(&[v[0], v[1], v[2], on_edge].map(float), &faces));
    assert_eq!(report.misplaced_vertices, (3, 3), "{report}");
}

#[test]
fn edge_flipped_across_a_crease_is_reported() {
    let input = obj(&kite(true), &KITE_F);
    let output = obj(&kite(true), &[[0, 3, 2], [3, 1, 2]]);
    let report = check_texts(&input, &output);
    assert_failure(&report, "does not lie inside one planar region of the input");
    assert_failure(&report, "area");
}

#[test]
fn reversed_face_is_reported() {
    let mut faces = OCTA_F;
    faces[0] = [0, 4, 2];
    let report = check_texts(&octahedron(), &obj(&OCTA_V, &faces));
    assert_failure(&report, "in the same direction (inconsistent orientation)");
    assert_failure(&report, "output face 1 (v1, v5, v3) is reversed");
}

#[test]
fn extra_disconnected_triangle_is_reported() {
    let mut v = OCTA_V.to_vec();
    v.extend([[10.0, 10.0, 10.0], [11.0, 10.0, 10.0], [10.0, 11.0, 10.0]]);
    let mut f = OCTA_F.to_vec();
    f.push([6, 7, 8]);
    let report = check_texts(&octahedron(), &obj(&v, &f));
    assert_failure(&report, "number of connected components 1 became 2");
}

// ---------------------------------------------------------------------------------------------
// Numerics: faces with a far vertex, needles
// ---------------------------------------------------------------------------------------------

/// A triangle with a far vertex: `A` at the origin, the short edge `BC` (length 5) near
/// (3e9, 4e9, 0); area 1.25e10. Points on `BC` at parameter `t` are exact for `t` a multiple of
/// 2^-19 (coordinates near 4e9 have a spacing of 2^-21).
fn far_vertex_triangle() -> [[f64; 3]; 3] {
    [[0.0, 0.0, 0.0], [3e9, 4e9, 0.0], [3e9 + 4.0, 4e9 - 3.0, 0.0]]
}

/// The point of `BC` at parameter `t` (exact for the `t` used here).
fn on_far_edge(t: f64) -> [f64; 3] {
    [3e9 + 4.0 * t, 4e9 - 3.0 * t, 0.0]
}

#[test]
fn faces_with_a_far_vertex_keep_their_area() {
    // Split BC at two points: three faces sharing the far vertex A, written from A. The plain
    // (b - a) x (c - a) crosses two edges of length 5e9 that are nearly parallel and is off by
    // about 2e-8 of the area here (the input face is written from B, where it is accurate);
    // the checker must see no change.
    let input = obj(&far_vertex_triangle(), &[[1, 2, 0]]);
    let mut v = far_vertex_triangle().to_vec();
    v.extend([on_far_edge(0.25), on_far_edge(0.75)]);
    let output = obj(&v, &[[0, 1, 3], [0, 3, 4], [0, 4, 2]]);
    assert_passes(&check_texts(&input, &output));
}

#[test]
fn a_tiny_fold_beside_a_far_vertex_is_caught() {
    // The same split with the two added points 9.5e-6 apart and in the wrong order: the middle
    // face (A, M2, M1) is reversed (folded over its neighbours), although every vertex is on its
    // edge and the topology is a disk, as before. Its area is 1.9e-6 of the triangle's.
    let input = obj(&far_vertex_triangle(), &[[0, 1, 2]]);
    let (m1, m2) = (on_far_edge(0.5), on_far_edge(0.5 + 2f64.powi(-19)));
    let mut v = far_vertex_triangle().to_vec();
    v.extend([m2, m1]); // vertex 4 is the farther from B, vertex 5 the nearer
    let output = obj(&v, &[[0, 1, 3], [0, 3, 4], [0, 4, 2]]);
    let report = check_texts(&input, &output);
    assert_failure(&report, "output face 2 (v1, v4, v5) is reversed relative to region 1");
    assert_failure(
        &report,
        "region 1 (containing input face 1) area 12500000000 became 1250",
    );
    // An added vertex one unit in the last place off its edge is fine (points computed on
    // edges are rounded); 1e-10 of the coordinates (0.4) off it is not.
    let faces = [[0, 1, 3], [0, 3, 4], [0, 4, 2]];
    for (dy, refused) in [(2f64.powi(-21), false), (0.4, true)] {
        let mut v = far_vertex_triangle().to_vec();
        v.extend([on_far_edge(0.25), on_far_edge(0.75)]);
        v[3][1] += dy;
        let report = check_texts(&input, &obj(&v, &faces));
        assert_eq!(
            has(&report, "output vertex 4 (3000000001, 3999999999"),
            refused,
            "{report}"
        );
        // (Moved at all, the vertex makes its edge to A non-Delaunay: B, the vertex and the
        // next one are no longer collinear, and the angles opposite that edge sum to pi.)
        assert!(!has(&report, "area") && !has(&report, "reversed"), "{report}");
    }
}

/// A valid needle: its largest angle is within 1e-19 of pi (aspect ratio about 1e20).
const NEEDLE: [[f64; 3]; 3] = [
    [5.534023222112866e18, 0.0, -0.0],
    [0.1, 0.3333333333333333, -0.0],
    [0.2, 0.3333333333333333, 0.0],
];

#[test]
fn needle_faces_are_judged_exactly() {
    let input = obj(&NEEDLE, &[[0, 2, 1]]);
    // The needle itself, and split at the midpoint of its short edge.
    assert_passes(&check_texts(&input, &input));
    let mut v = NEEDLE.to_vec();
    v.push([0.15000000000000002, 0.3333333333333333, 0.0]);
    let split = obj(&v, &[[0, 3, 1], [0, 2, 3]]);
    assert_passes(&check_texts(&input, &split));
    // Reversed: the checker must say so (a float normal would call it zero-area or pass it).
    let report = check_texts(&input, &obj(&NEEDLE, &[[0, 1, 2]]));
    assert_failure(&report, "output face 1 (v1, v2, v3) is reversed relative to region 1");
    // The split with both faces reversed (folded over the needle's other side).
    let folded = obj(&v, &[[0, 1, 3], [0, 3, 2]]);
    let report = check_texts(&input, &folded);
    assert_failure(&report, "is reversed relative to region 1");
}

#[test]
fn bad_output_meshes_give_failures_not_panics() {
    let input = Mesh3 {
        positions: OCTA_V.iter().map(|p| DVec3::from_array(*p)).collect(),
        triangles: OCTA_F.to_vec(),
    };
    let mut nan = input.clone();
    nan.positions[2].y = f64::NAN;
    assert!(has(&check_meshes(&input, &nan), "output vertex 3"));
    let mut out_of_range = input.clone();
    out_of_range.triangles[0][1] = 99;
    assert!(has(&check_meshes(&input, &out_of_range), "refers to vertex 100"));
    let mut degenerate = input.clone();
    degenerate.triangles[0] = [0, 0, 4];
    assert!(has(&check_meshes(&input, &degenerate), "repeats a vertex"));
    let empty = Mesh3::default();
    assert!(!check_meshes(&input, &empty).passed());
    let report = check_meshes(&empty, &input);
    assert_eq!(report.failures, vec!["input mesh is invalid: the mesh has no faces"]);
    let report = check_meshes(&input, &nan.clone());
    assert!(!report.passed());
    let report = check_meshes(&nan, &input);
    assert!(has(&report, "input mesh is invalid: input vertex 3"));
}

#[test]
fn random_garbage_meshes_never_panic() {
    let mut rng = Rng(99);
    let values = [
        0.0,
        -0.0,
        1.0,
        0.5,
        2.0,
        5e-324,
        1e300,
        -f64::MAX,
        f64::MAX,
        f64::NAN,
        f64::INFINITY,
    ];
    let random_mesh = |rng: &mut Rng| {
        let n = 1 + (rng.next() * 8.0) as usize;
        let pick = |rng: &mut Rng| values[(rng.next() * values.len() as f64) as usize % values.len()];
        let positions = (0..n)
            .map(|_| {
                if rng.next() < 0.8 {
                    DVec3::new(rng.next().round(), rng.next().round(), (rng.next() * 2.0).round())
                } else {
                    DVec3::new(pick(rng), pick(rng), pick(rng))
                }
            })
            .collect();
        let faces = (0..(rng.next() * 10.0) as usize)
            .map(|_| [0; 3].map(|_| (rng.next() * (n as f64 + 0.3)) as u32))
            .collect();
        Mesh3 {
            positions,
            triangles: faces,
        }
    };
    let octa = Mesh3 {
        positions: OCTA_V.iter().map(|p| DVec3::from_array(*p)).collect(),
        triangles: OCTA_F.to_vec(),
    };
    for _ in 0..3000 {
        let a = random_mesh(&mut rng);
        let b = random_mesh(&mut rng);
        let _ = check_meshes(&a, &b);
        let report = check_meshes(&octa, &b);
        assert!(!report.passed() || b.triangles.len() >= 8);
        let _ = check_meshes(&a, &a);
    }
}

// ---------------------------------------------------------------------------------------------
// Invalid inputs and files
// ---------------------------------------------------------------------------------------------

#[test]
fn non_manifold_input_is_an_error_naming_the_file() {
    let dir = TempDir::new().expect("tempdir");
    // Two triangles sharing only vertex 1: a bow tie reads as two fans, each with its own
    // copy of the pinch vertex (the rule that lets repaired meshes be checked).
    let bowtie = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n";
    let input = write(&dir, "bowtie.obj", bowtie);
    let mesh = Mesh3::read_obj(&input).expect("readable");
    assert_eq!(mesh.positions.len(), 6);
    assert_eq!(mesh.positions[5], mesh.positions[0]);
    let report = check_files(&input, &input).expect("a pinch is read as two fans");
    assert!(report.passed(), "{report}");
    // Three faces on one edge.
    let fin = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
    let input = write(&dir, "fin.obj", fin);
    let err = check_files(&input, &input).expect_err("fin is not a valid input");
    assert!(err.to_string().contains("is shared by 3 faces"), "{err}");
}

/// A Möbius band as input is refused as not orientable; a face turned over, which turning it
/// back would mend, only as inconsistently oriented.
#[test]
fn moebius_band_input_is_refused_as_not_orientable() {
    let dir = TempDir::new().expect("tempdir");
    // Five triangles (i, i+1, i+2) round a pentagon's vertices: each edge (i, i+1) is shared by
    // two of them, and going round once turns the strip over.
    let mut band = String::new();
    for i in 0..5 {
        let angle = f64::from(i) * 2.0 * PI / 5.0;
        band.push_str(&format!("v {} {} {}\n", angle.cos(), angle.sin(), f64::from(i % 2)));
    }
    for i in 0..5 {
        band.push_str(&format!("f {} {} {}\n", i + 1, (i + 1) % 5 + 1, (i + 2) % 5 + 1));
    }
    let input = write(&dir, "band.obj", &band);
    let err = check_files(&input, &input).expect_err("a Möbius band is not a valid input");
    assert!(err.to_string().contains("in the same direction"), "{err}");
    assert!(err.to_string().contains("not orientable (a Möbius band)"), "{err}");
    // A tetrahedron with one face turned over.
    let turned = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 4 2\nf 2 3 4\nf 1 4 3\n";
    let input = write(&dir, "turned.obj", turned);
    let err = check_files(&input, &input).expect_err("a face turned over is not a valid input");
    assert!(err.to_string().contains("(inconsistent orientation)"), "{err}");
    assert!(!err.to_string().contains("orientable"), "{err}");
}

#[test]
fn unreadable_files_are_errors() {
    let dir = TempDir::new().expect("tempdir");
    let good = write(&dir, "good.obj", &octahedron());
    let cases = [
        ("empty.obj", ""),
        ("points.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n"),
        ("garbage.obj", "v 1 2 x\nf 1 1 1\n"),
        ("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
        ("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
        ("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
        ("inf.obj", "v inf 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
        ("binary.obj", "\u{0}\u{1}\u{2}\u{ff}v\n"),
    ];
    for (name, text) in cases {
        let bad = write(&dir, name, text);
        for (input, output) in [(&bad, &good), (&good, &bad)] {
            let err = check_files(input, output).expect_err(name);
            assert!(err.to_string().contains(name), "{name}: {err}");
        }
    }
    // The message names the format read, and says why as the main
    // command's readers do.
    let cases = [
        (
            "short.ply",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
             property float z\nend_header\n0 0 0\n",
            "short.ply: not a valid PLY mesh",
        ),
        (
            "mac.obj",
            "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r",
            "mac.obj: not a valid OBJ mesh: line 1: lines end in a carriage return alone",
        ),
    ];
    for (name, text, expected) in cases {
        let bad = write(&dir, name, text);
        let err = check_files(&good, &bad).expect_err(name);
        assert!(err.to_string().contains(expected), "{name}: {err}");
    }
    // Bytes that are not text (UTF-16, here with its byte order mark; a
    // binary file) are refused as the construction's reader refuses them,
    // not read as a mesh without faces; UTF-16 with a word on converting it.
    let utf16: Vec<u8> = [0xff, 0xfe]
        .into_iter()
        .chain(octahedron().bytes().flat_map(|b| [b, 0]))
        .collect();
    let utf16_path = dir.path().join("utf16.obj");
    std::fs::write(&utf16_path, utf16).unwrap();
    let err = check_files(&good, &utf16_path).expect_err("UTF-16");
    assert!(
        err.to_string()
            .contains("utf16.obj: not a valid OBJ mesh: the file is UTF-16 text"),
        "{err}"
    );
    // Not UTF-8 where it is no statement's business (a Latin-1 group
    // name, a comment) is text enough.
    let mut latin = octahedron().into_bytes();
    latin.extend_from_slice(b"g caf\xe9\n# \xff\n");
    let latin_path = dir.path().join("latin.obj");
    std::fs::write(&latin_path, latin).unwrap();
    assert!(check_files(&good, &latin_path).expect("readable").passed());
    let missing = dir.path().join("missing.obj");
    let err = check_files(&missing, &good).expect_err("missing file");
    assert!(matches!(err, CheckError::Io { .. }), "{err}");
    assert!(matches!(
        Mesh3::read_obj(write(&dir, "e.obj", "")),
        Err(CheckError::NoFaces { .. })
    ));
}

#[test]
fn reading_merges_objects_welds_and_numbers_by_v_lines() {
    let dir = TempDir::new().expect("tempdir");
    let text = "v 9 9 9\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\no quad\nf 4 5 2 3\n\
                o tri\nv 1 1 0\nv 2 1 0\nf 3 7 6\n";
    let mesh = Mesh3::read_obj(write(&dir, "m.obj", text)).expect("valid");
    let expected: Vec<DVec3> = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.], [2., 1., 0.]]
        .iter()
        .map(|p| DVec3::from_array(*p))
        .collect();
    assert_eq!(mesh.positions, expected);
    assert_eq!(mesh.triangles, vec![[2, 3, 0], [2, 0, 1], [1, 4, 2]]);
}

/// Two sheets that meet along one line, P-U, with distinct vertices at P (as a refined
/// self-overlapping input can have): sheet 1's faces (P,U,a) and (U,P,b), with a texture seam
/// along P-U, so that an OFF or PLY file gives each its own copies of P and U (with different
/// values); sheet 2's faces (Q,U,c) and (U,Q,d), Q at P's position. Welded by position P-U has
/// four faces, so the file's vertices at its ends are kept apart, but the seam's copies stay
/// one vertex: sheet 1 has one P and one U, Q stays apart, and U, where the sheets then only
/// touch, is one vertex per sheet (the pinch rule). Once, every file vertex at P and U was kept
/// apart, the seam's copies too. Copies with the same values are not a seam's (`--repair`
/// makes such copies where it cuts): they stay apart.
#[test]
fn seam_copies_stay_one_vertex_where_sheets_are_kept_apart() {
    let dir = TempDir::new().expect("tempdir");
    let (p, u) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
    let (a, b, c, d) = ([0.5, 1.0, 0.0], [0.5, -1.0, 0.0], [0.5, 0.0, 1.0], [0.5, 0.0, -1.0]);
    // Records: P1 U1 a P2 U2 b Q c d, the seam's sides at values 0 and 1.
    let vertices = [p, u, a, p, u, b, p, c, d];
    let values = [0, 0, 0, 1, 1, 1, 2, 2, 2];
    let faces = [[0, 1, 2], [4, 3, 5], [6, 1, 7], [1, 6, 8]];
    let files = |values: &[u8]| {
        [
            ("m.off", coloured_off(&vertices, values, &faces)),
            ("m.ply", textured_ply(&vertices, values, &faces)),
        ]
    };
    for (name, text) in files(&values) {
        let mesh = Mesh3::read(write(&dir, name, &text)).expect("valid");
        assert_eq!(mesh.positions.len(), 8, "{name}: {:?}", mesh.triangles);
        let at = |f: usize, q: [f64; 3]| {
            let t = mesh.triangles[f];
            t.into_iter()
                .find(|&v| mesh.positions[v as usize] == DVec3::from_array(q))
                .expect("a vertex there")
        };
        assert_eq!(at(0, p), at(1, p), "{name}: the seam's copies of P are one vertex");
        assert_eq!(at(0, u), at(1, u), "{name}: the seam's copies of U are one vertex");
        assert_eq!(at(2, p), at(3, p), "{name}: Q is one vertex");
        assert_ne!(at(0, p), at(2, p), "{name}: P and Q stay apart");
    }
    // The same copies with the same values, or with none: not a seam's, all kept apart.
    let mut texts = files(&[0; 9]).to_vec();
    texts.push(("plain.off", off(&vertices, &faces)));
    for (name, text) in texts {
        let mesh = Mesh3::read(write(&dir, name, &text)).expect("valid");
        assert_eq!(mesh.positions.len(), 10, "{name}: {:?}", mesh.triangles);
    }
    // Seams on both sheets: which open edges pair is not known, all stay apart.
    let vertices = [p, u, a, p, u, b, p, u, c, p, u, d];
    let values = [0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3];
    let faces = [[0, 1, 2], [4, 3, 5], [6, 7, 8], [10, 9, 11]];
    let text = coloured_off(&vertices, &values, &faces);
    let mesh = Mesh3::read(write(&dir, "both.off", &text)).expect("valid");
    assert_eq!(mesh.positions.len(), 12, "{:?}", mesh.triangles);
}

/// COFF text of a mesh whose vertex `i` has the grey level `values[i]`.
fn coloured_off(vertices: &[[f64; 3]], values: &[u8], faces: &[[u32; 3]]) -> String {
    let mut text = format!("COFF\n{} {} 0\n", vertices.len(), faces.len());
    for (v, g) in vertices.iter().zip(values) {
        text.push_str(&format!("{:?} {:?} {:?} {g} {g} {g} 255\n", v[0], v[1], v[2]));
    }
    text + &face_lines(faces)
}

/// ASCII PLY text of a mesh whose vertex `i` has the texture coordinates (`values[i]`, 0).
fn textured_ply(vertices: &[[f64; 3]], values: &[u8], faces: &[[u32; 3]]) -> String {
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nproperty float s\nproperty float t\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    );
    for (v, s) in vertices.iter().zip(values) {
        text.push_str(&format!("{:?} {:?} {:?} {s} 0\n", v[0], v[1], v[2]));
    }
    text + &face_lines(faces)
}

// ---------------------------------------------------------------------------------------------
// Larger sanity test
// ---------------------------------------------------------------------------------------------

/// A closed icosphere subdivided `levels` times, with vertices randomly perturbed.
fn perturbed_icosphere(levels: usize, rng: &mut Rng) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (mut v, f) = icosphere(levels);
    let edge = (v[f[0][0] as usize] - v[f[0][1] as usize]).length();
    for p in &mut v {
        *p = *p * rng.range(0.97, 1.03) + rng.vec(0.2 * edge);
    }
    (v, f)
}

/// The icosahedron on the unit sphere, subdivided `levels` times (each face
/// into four, the new vertices pushed out onto the sphere, numbered after
/// the old in order of the faces' edges).
fn icosphere(levels: usize) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<DVec3> = [
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ]
    .iter()
    .map(|p| DVec3::from_array(*p).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::new();
        for [a, b, c] in f {
            let mut m = |x: u32, y: u32| {
                *mid.entry((x.min(y), x.max(y))).or_insert_with(|| {
                    v.push(((v[x as usize] + v[y as usize]) / 2.0).normalize());
                    v.len() as u32 - 1
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        f = next;
    }
    (v, f)
}

/// Brute-force count of interior edges with alpha + beta > pi + 1e-9, with acos angles.
fn brute_force_non_delaunay(v: &[DVec3], f: &[[u32; 3]]) -> usize {
    let mut opposite: HashMap<(u32, u32), u32> = HashMap::new();
    for t in f {
        for k in 0..3 {
            opposite.insert((t[k], t[(k + 1) % 3]), t[(k + 2) % 3]);
        }
    }
    let angle = |apex: u32, x: u32, y: u32| {
        let (u, w) = (v[x as usize] - v[apex as usize], v[y as usize] - v[apex as usize]);
        (u.dot(w) / (u.length() * w.length())).clamp(-1.0, 1.0).acos()
    };
    opposite
        .iter()
        .filter(|((a, b), _)| a < b)
        .filter(|((a, b), c)| {
            let d = opposite[&(*b, *a)];
            angle(**c, *a, *b) + angle(d, *a, *b) > PI + 1e-9
        })
        .count()
}

#[test]
fn perturbed_icosphere_count_matches_brute_force() {
    let mut rng = Rng(2024);
    let (v, f) = perturbed_icosphere(4, &mut rng);
    let points: Vec<[f64; 3]> = v.iter().map(|p| p.to_array()).collect();
    let text = obj(&points, &f);
    let report = check_texts(&text, &text);
    let expected = brute_force_non_delaunay(&v, &f);
    assert!(expected > 20, "the perturbation should make non-Delaunay edges");
    assert_eq!(report.non_delaunay_edges, expected);
    assert_eq!(report.interior_edges, f.len() * 3 / 2);
    assert_eq!(report.input_regions, f.len());
    assert_eq!(report.output_vertices, v.len());
    // Only Delaunay failures, capped at 20 lines plus a summary line.
    assert_eq!(report.failures.len(), 21, "{report}");
    assert!(report.failures[..20].iter().all(|l| l.starts_with("non-Delaunay edge")));
    assert_eq!(
        report.failures[20],
        format!("... and {} more non-Delaunay edge failures", expected - 20)
    );
}

// ---------------------------------------------------------------------------------------------
// Real meshes (skipped when the shared meshes are absent)
// ---------------------------------------------------------------------------------------------

fn shared_mesh(name: &str) -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/meshes")
        .join(name);
    if path.exists() {
        Some(path)
    } else {
        eprintln!("skipping: {} not found", path.display());
        None
    }
}

#[test]
fn real_meshes_against_themselves_fail_only_on_delaunay() {
    for name in [
        "knot.obj",
        "fandisk.obj",
        "anchor.obj",
        "mpi_triang.obj",
        "nefertiti.obj",
    ] {
        let Some(path) = shared_mesh(name) else {
            continue;
        };
        let report = check_files(&path, &path).expect("valid mesh");
        assert_eq!(report.added_vertices, 0);
        let other = report
            .failures
            .iter()
            .filter(|l| !l.starts_with("non-Delaunay edge") && !l.starts_with("... and"));
        assert_eq!(other.count(), 0, "{name}: {report}");
        assert_eq!(report.passed(), report.non_delaunay_edges == 0);
        if name == "knot.obj" {
            assert_passes(&report);
        }
    }
}

#[test]
fn real_pinched_mesh_reads_as_separate_fans() {
    // Welded, the teapot has one vertex where two fans meet: read as two vertices, the mesh
    // is a valid input, and checked against itself only Delaunay failures can remain.
    if let Some(path) = shared_mesh("nonmanifold/teapot.obj") {
        let report = check_files(&path, &path).expect("the teapot reads as a manifold");
        let other = report
            .failures
            .iter()
            .filter(|l| !l.starts_with("non-Delaunay edge") && !l.starts_with("... and"));
        assert_eq!(other.count(), 0, "{report}");
    }
}

/// The judge's report does not depend on how many threads it may use: a bumpy grid large
/// enough for the two-thread paths (40k faces, about 2 MB of files), against a copy with a
/// moved vertex, a removed face and flipped diagonals, read and judged with one thread and with
/// two. The report has failures of several kinds, in the same order.
#[test]
fn report_does_not_depend_on_threads() {
    let n = 100usize;
    let mut rng = Rng(0xc4ec_0002);
    let id = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let vertices: Vec<[f64; 3]> = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| (i, j)))
        .map(|(i, j)| [i as f64, j as f64, rng.range(0.0, 0.4)])
        .collect();
    let mut faces = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            faces.push([a, b, c]);
            faces.push([a, c, d]);
        }
    }
    let mut moved = vertices.clone();
    moved[5 * (n + 1) + 7][2] += 0.25;
    let mut changed = faces.clone();
    for q in [40 * n + 40, 60 * n + 13] {
        // Flip the diagonal of one quad: (a, b, c), (a, c, d) -> (a, b, d), (b, c, d).
        let ([a, b, c], [_, _, d]) = (changed[2 * q], changed[2 * q + 1]);
        changed[2 * q] = [a, b, d];
        changed[2 * q + 1] = [b, c, d];
    }
    changed.remove(3 * n + 11);
    let dir = TempDir::new().expect("tempdir");
    let input = write(&dir, "input.obj", &obj(&vertices, &faces));
    let output = write(&dir, "output.obj", &obj(&moved, &changed));
    let size = |p: &Path| std::fs::metadata(p).unwrap().len();
    assert!(
        size(&input) + size(&output) > 1 << 20,
        "large enough for the parallel reading"
    );
    let reports: Vec<CheckReport> = [1, 2]
        .into_iter()
        .map(|threads| {
            delmesh::parallel::set_threads(threads);
            let report = check_files(&input, &output).expect("both files are valid meshes");
            delmesh::parallel::set_threads(0);
            report
        })
        .collect();
    assert_eq!(reports[0], reports[1]);
    for needle in [
        "non-Delaunay edge",
        "missing from output",
        "Euler characteristic",
        "does not lie inside",
    ] {
        assert_failure(&reports[0], needle);
    }
}

/// A fan of 4000 triangles around one vertex (a CAD disk or cone), refined: many vertices are
/// added on the spokes close to the apex, each in the grid's cells that every spoke crosses,
/// and the result passes.
#[test]
fn refined_fan_around_a_vertex_of_high_valence_passes() {
    let (vertices, faces) = common::cone_fan(4000);
    let positions: Vec<DVec3> = vertices.iter().map(|&v| DVec3::from_array(v)).collect();
    let mut surface = delmesh::Surface::new(positions.clone(), &faces).expect("a valid fan");
    let stats = delmesh::make_delaunay(&mut surface, &delmesh::Options::default()).expect("refined");
    assert!(stats.splits > 4000, "{} vertices added", stats.splits);
    let input = Mesh3 {
        positions,
        triangles: faces,
    };
    let output = Mesh3 {
        positions: surface.positions.clone(),
        triangles: surface.triangles(),
    };
    let report = check_meshes(&input, &output);
    assert_passes(&report);
    assert_eq!(report.added_vertices, stats.splits);
}

/// Coordinates beyond ±1e75 (where products overflow and areas read NaN)
/// make an input the judge refuses, as the construction does, by name, not
/// a failure of "area NaN became NaN" when a mesh is compared with itself.
#[test]
fn coordinates_beyond_the_supported_range_are_named() {
    let dir = TempDir::new().expect("tempdir");
    let big = [[0.0, 0.0, 0.0], [1e300, 0.0, 0.0], [0.0, 1e300, 0.0], [0.0, 0.0, 1e300]];
    let path = write(
        &dir,
        "big.obj",
        &obj(&big, &[[1, 0, 2], [0, 1, 3], [1, 2, 3], [0, 3, 2]]),
    );
    let err = check_files(&path, &path).expect_err("out of range");
    assert!(matches!(err, CheckError::InvalidInput { .. }), "{err}");
    assert!(
        err.to_string()
            .contains("input vertex 2 (1e300, 0, 0) has a coordinate beyond ±1e75, the supported range"),
        "{err}"
    );
}

/// A face of one or two vertices (`f 5`, `f 1 2`) is refused with its line, as the
/// construction's reader refuses it (when the judge read OBJ with tobj, tobj read it as a point
/// or a line, dropped unseen, so an output with such a line, or one as the input, passed).
#[test]
fn faces_of_fewer_than_three_vertices_are_refused_with_their_line() {
    let dir = TempDir::new().expect("tempdir");
    let good = write(&dir, "good.obj", &octahedron());
    for (name, face, vertices) in [
        ("two.obj", "f 1 2", "2 vertices"),
        ("one.obj", "f 5", "1 vertex"),
        ("none.obj", "f", "0 vertices"),
    ] {
        let text = format!("{}{face}\n", octahedron());
        let bad = write(&dir, name, &text);
        let line = text.lines().count();
        let expected = format!("{name}: not a valid OBJ mesh: line {line}: face has {vertices}, needs at least 3");
        for (input, output) in [(&good, &bad), (&bad, &good)] {
            let err = check_files(input, output).expect_err(name);
            assert!(err.to_string().contains(&expected), "{name}: {err}");
        }
    }
}

/// What the judge cannot read is named with its line, in the words of the construction's
/// reader.
#[test]
fn obj_syntax_errors_name_their_line() {
    let dir = TempDir::new().expect("tempdir");
    let good = write(&dir, "good.obj", &octahedron());
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let cases = [
        (
            "v 0 0 0\nv 1,5 0 0\nv 0 1 0\nf 1 2 3\n",
            "line 2: vertex coordinate '1,5' is not a number",
        ),
        (&format!("{tri}f 1 2 a\n"), "line 4: face index 'a' is not an integer"),
        (
            &format!("{tri}f 1 2 99999999999999999999\n"),
            "line 4: face index '99999999999999999999' is out of range",
        ),
        (
            &format!("{tri}f 1 2 -99999999999999999999/1\n"),
            "line 4: face index '-99999999999999999999' is out of range",
        ),
        (
            &format!("{tri}f 1 2 4\n"),
            "line 4: face index 4 is out of range (the file has 3 vertices)",
        ),
        (
            &format!("{tri}f 0 1 2\n"),
            "line 4: face index 0 (OBJ indices start at 1)",
        ),
        (&format!("{tri}f -4 -3 -2\n"), "line 4: face index -4 is out of range"),
        (
            &format!("{tri}f 1/1 2/2 /3\n"),
            "line 4: face index '/3' is not an integer",
        ),
        (
            "v 0 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "line 1: vertex 1 has weight 0",
        ),
        (
            "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "line 1: vertex has 2 coordinates, needs 3",
        ),
        (
            "v 0 0 0\nv 1 0 0 1 1\nv 0 1 0\nf 1 2 3\n",
            "line 2: vertex line has 5 values",
        ),
        (
            "v 0 0 0\nv 1 0 0 x\nv 0 1 0\nf 1 2 3\n",
            "line 2: vertex weight 'x' is not a number",
        ),
        (
            // A carriage return alone among line feeds is refused, as the
            // construction's reader refuses it.
            "v 0 0 0\r\nv 1 0 0\nv 0 1 0\rf 1 2 3\n",
            "line 3: lines end in a carriage return alone (classic Mac OS text): convert them to line feeds",
        ),
        // Later lines keep their numbers after a continued line.
        (
            &format!("v 0 \\\n0 0\n{}f 1 2 3 4\n", &tri[8..]),
            "line 5: face index 4 is out of range",
        ),
        (
            &format!("{tri}f 1 2 3\nf 1 2 9\nf 3 2 4\nv 1 1 1\n"),
            "line 5: face index 9 is out of range (the file has 4 vertices)",
        ),
    ];
    for (k, (text, expected)) in cases.iter().enumerate() {
        let name = format!("bad{k}.obj");
        let bad = write(&dir, &name, text);
        for (input, output) in [(&bad, &good), (&good, &bad)] {
            let err = check_files(input, output).expect_err(&name);
            let expected = format!("{name}: not a valid OBJ mesh: {expected}");
            assert!(err.to_string().contains(&expected), "{text:?}: {err}");
        }
    }
    // A face may name a vertex of a later line.
    let forward = write(&dir, "forward.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n");
    assert_passes(&check_files(&forward, &forward).expect("a forward reference is fine"));
}

/// OFF text of a mesh with 0-based faces.
fn off(vertices: &[[f64; 3]], faces: &[[u32; 3]]) -> String {
    let mut text = format!("OFF\n{} {} 0\n", vertices.len(), faces.len());
    vertices
        .iter()
        .for_each(|v| text.push_str(&format!("{:?} {:?} {:?}\n", v[0], v[1], v[2])));
    text + &face_lines(faces)
}

/// ASCII PLY text of a mesh with 0-based faces: a header of 9 lines, then a line per vertex
/// and a line per face.
fn ply(vertices: &[[f64; 3]], faces: &[[u32; 3]]) -> String {
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    );
    vertices
        .iter()
        .for_each(|v| text.push_str(&format!("{:?} {:?} {:?}\n", v[0], v[1], v[2])));
    text + &face_lines(faces)
}

/// The face lines of OFF and ASCII PLY text: `3 a b c`, 0-based.
fn face_lines(faces: &[[u32; 3]]) -> String {
    faces
        .iter()
        .map(|f| format!("3 {} {} {}\n", f[0], f[1], f[2]))
        .collect()
}

/// Binary STL bytes of triangles.
fn binary_stl(triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut bytes = vec![0u8; 80];
    bytes.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        bytes.extend([0u8; 12]);
        t.iter().flatten().for_each(|c| bytes.extend(c.to_le_bytes()));
        bytes.extend([0u8; 2]);
    }
    bytes
}

/// Failure lines and refusals name vertices and faces as the file's format numbers them, as
/// the construction's messages do: OBJ from 1 (by its `v` and `f` lines, also where a vertex is
/// unused or a face a polygon), OFF and PLY from 0, STL's vertices by position and its facets
/// from 0; a refused input names the line (or binary record) of the face or vertex at fault.
#[test]
fn failures_number_as_each_format_numbers() {
    let dir = TempDir::new().expect("tempdir");
    let flat = write(&dir, "flat.obj", &obj(&kite(false), &KITE_F));
    // The flat kite's long edge is not Delaunay: vertices 1 and 2 in OBJ, 0 and 1 in OFF, PLY.
    for (name, text, expected) in [
        ("kite.obj", obj(&kite(false), &KITE_F), "non-Delaunay edge (v1, v2)"),
        ("kite.off", off(&kite(false), &KITE_F), "non-Delaunay edge (v0, v1)"),
        ("kite.ply", ply(&kite(false), &KITE_F), "non-Delaunay edge (v0, v1)"),
        // An unused first vertex: the file's numbers, not the used vertices' ranks.
        (
            "unused.obj",
            format!("v 9 9 9\n{}", obj(&kite(false), &[[1, 2, 3], [2, 1, 4]])),
            "non-Delaunay edge (v2, v3)",
        ),
    ] {
        let report = check_files(&flat, &write(&dir, name, &text)).expect("readable");
        assert_failure(&report, expected);
    }
    // The vertex where the output stops following the input, as each file names it.
    let mut swapped = kite(false).to_vec();
    swapped.swap(0, 1);
    let swapped = write(&dir, "swapped.ply", &ply(&swapped, &[[1, 0, 2], [0, 1, 3]]));
    let report = check_files(&flat, &swapped).expect("readable");
    assert_eq!(
        report.first_reordered_vertex_names,
        Some(("vertex 0".to_string(), "vertex 1".to_string()))
    );
    assert!(report.to_string().contains("output vertex 0 differs"), "{report}");
    // A polygon is one face: the reversed triangle after a quad is face 2, not triangle 3.
    let house = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 0.5, 0.0],
    ];
    let points: String = house
        .iter()
        .map(|p| format!("v {} {} {}\n", p[0], p[1], p[2]))
        .collect();
    let input = write(&dir, "house.obj", &format!("{points}f 1 2 3 4\nf 2 5 3\n"));
    let output = write(&dir, "reversed.obj", &format!("{points}f 1 2 3 4\nf 2 3 5\n"));
    let report = check_files(&input, &output).expect("readable");
    assert_failure(
        &report,
        "line 7: output face 1 and face 2 use edge (v2, v3) in the same direction",
    );
    assert_failure(&report, "output face 2 (v2, v3, v5) is reversed relative to region 1");
    // Refused inputs: the line or record, and the format's numbers.
    let fin_v = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let fin_f = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
    let triangle = write(&dir, "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let stl_ascii = "solid t\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n\
                     endloop\nendfacet\nfacet normal 0 0 0\nouter loop\nvertex 0 1 0\nvertex 0 1 0\n\
                     vertex 1 0 0\nendloop\nendfacet\nendsolid t\n";
    let cases: [(&str, Vec<u8>, &str); 6] = [
        (
            "fin.obj",
            obj(&fin_v, &fin_f).into_bytes(),
            "line 8: input edge (v1, v2) is shared by 3 faces (face 1, face 2, face 3)",
        ),
        (
            "fin.ply",
            ply(&fin_v, &fin_f).into_bytes(),
            "line 17: input edge (v0, v1) is shared by 3 faces (face 0, face 1, face 2)",
        ),
        (
            "repeat.off",
            off(&kite(false), &[[0, 2, 0], [1, 0, 3]]).into_bytes(),
            "line 7: input face 0 (v0, v2, v0) repeats a vertex",
        ),
        (
            "repeat.stl",
            stl_ascii.as_bytes().to_vec(),
            "line 9: input facet 1 ((0, 1, 0), (0, 1, 0), (1, 0, 0)) repeats a vertex",
        ),
        (
            "binary.stl",
            binary_stl(&[
                [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                [[0.0, 1.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
            ]),
            "face record 1: input facet 1 ((0, 1, 0), (0, 1, 0), (1, 0, 0)) repeats a vertex",
        ),
        (
            "nan.obj",
            b"v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n".to_vec(),
            "line 3: vertex 3 (NaN, 1, 0) has a non-finite coordinate",
        ),
    ];
    for (name, bytes, expected) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let err = check_files(&path, &triangle).expect_err(name);
        assert!(err.to_string().contains(expected), "{name}: {err}");
    }
}

/// An icosahedron against its subdivision pushed out onto the sphere (the surfaces differ:
/// every added vertex is off the input's edges, every output face off the input's planes) is
/// failed for what is wrong: output faces on no input face, input faces left uncovered. Faces
/// with a vertex off the input's edges used to join the regions they touched into "the 20
/// overlapping coplanar regions (whose faces cannot be told apart)", which they are not.
#[test]
fn a_different_surface_is_not_called_overlapping_coplanar_regions() {
    let (v, f) = icosphere(0);
    let input = obj(&v.iter().map(|p| p.to_array()).collect::<Vec<_>>(), &f);
    let (v, fine) = icosphere(1);
    let output = obj(&v.iter().map(|p| p.to_array()).collect::<Vec<_>>(), &fine);
    let report = check_texts(&input, &output);
    assert!(!has(&report, "overlapping"), "{report}");
    let [a, ab, ca] = fine[0];
    assert_failure(
        &report,
        &format!(
            "output face 1 (v{}, v{}, v{}) lies on no input face: v{} and v{}, off the input's edges, \
             are in the plane of none of the input faces at v{}",
            a + 1,
            ab + 1,
            ca + 1,
            ab + 1,
            ca + 1,
            a + 1
        ),
    );
    assert_failure(&report, "region 1 (containing input face 1) area ");
    assert_failure(&report, "became 0");
    // A vertex moved off its edge within the flat kite's plane leaves its faces on the input
    // (its own failure is enough), and one moved off the plane does not.
    let split = |m: [f64; 3]| {
        let mut v = kite(false).to_vec();
        v.push(m);
        let faces = [[0, 4, 2], [4, 1, 2], [1, 4, 3], [4, 0, 3]];
        check_texts(&obj(&kite(false), &KITE_F), &obj(&v, &faces))
    };
    let within = split([2.0, 1e-7, 0.0]);
    assert_failure(&within, "output vertex 5 (2, 0.0000001, 0) is neither");
    assert!(!has(&within, "lies on no input face"), "{within}");
    let off = split([2.0, 0.0, 1e-7]);
    assert_failure(
        &off,
        "output face 1 (v1, v5, v3) lies on no input face: v5, off the input's edges, is in the plane of \
         none of the input faces at v1 and v3",
    );
}

/// Coincident copies of one square are regions whose faces cannot be told apart: their total
/// area is checked, and the failure names the group, its first six regions and then "...".
/// (Mutation testing: the "..." for groups over six was never exercised.)
#[test]
fn overlapping_coplanar_regions_are_checked_by_their_total_area() {
    let squares = |copies: u32, faces: usize| {
        let vertices: Vec<[f64; 3]> = (0..copies)
            .flat_map(|_| [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0]])
            .collect();
        let all: Vec<[u32; 3]> = (0..copies)
            .flat_map(|k| [[4 * k, 4 * k + 1, 4 * k + 2], [4 * k, 4 * k + 2, 4 * k + 3]])
            .collect();
        obj(&vertices, &all[..faces])
    };
    // The last copy loses a face: which region lost it, geometry cannot tell.
    let report = check_texts(&squares(2, 4), &squares(2, 3));
    assert_failure(
        &report,
        "the 2 overlapping coplanar regions region 1 (containing input face 1), region 2 (containing input \
         face 3) (whose faces cannot be told apart) have total area 8, which became 6",
    );
    let report = check_texts(&squares(7, 14), &squares(7, 13));
    let named: Vec<String> = (1..=6)
        .map(|r| format!("region {r} (containing input face {})", 2 * r - 1))
        .collect();
    assert_failure(
        &report,
        &format!(
            "the 7 overlapping coplanar regions {}, ... (whose faces cannot be told apart) have total area 28, \
             which became 26",
            named.join(", ")
        ),
    );
    assert!(!has(&report, "region 7 ("), "{report}");
    // Six are all named.
    let report = check_texts(&squares(6, 12), &squares(6, 11));
    assert_failure(
        &report,
        &format!("regions {} (whose faces cannot be told apart)", named.join(", ")),
    );
    // Whole, the copies pass.
    assert_passes(&check_texts(&squares(7, 14), &squares(7, 14)));
}

/// A file whose content is another format than its name says is refused as
/// misnamed, as the main command refuses it, not with the named reader's
/// reason (a PLY named `.obj` had "lines end in a carriage return alone").
#[test]
fn a_misnamed_file_is_refused_as_misnamed() {
    let dir = TempDir::new().unwrap();
    let text = octahedron();
    let obj = write(&dir, "o.obj", &text);
    let ply = write(&dir, "o.ply", &text);
    let stl = write(&dir, "o.stl", &text);
    for (path, named) in [(&ply, "PLY"), (&stl, "STL")] {
        match check_files(path, &obj) {
            Err(CheckError::Parse { format, reason, .. }) => {
                assert_eq!(format, named);
                assert_eq!(
                    reason,
                    "its content is OBJ (name it .obj: the name's extension decides the format)"
                );
            }
            other => panic!("{other:?}"),
        }
    }
    // A file that no reader takes keeps its own reader's reason.
    let bad = write(&dir, "bad.ply", "garbage\n");
    match check_files(&bad, &obj) {
        Err(CheckError::Parse { reason, .. }) => assert!(reason.contains("not a PLY file"), "{reason}"),
        other => panic!("{other:?}"),
    }
    assert!(check_files(&obj, &obj).unwrap().passed());
}

/// A face turned over where the input is folded flat onto itself (fuzz seed 2026120530): the
/// input's faces lie in the plane z = 0, and its vertex 7, at x = 12, pulls two faces back over
/// the others, so two planar regions facing opposite ways overlap, their edges running along
/// each other on the line y = 1/3. Moving an added vertex there 3.5e-8 along its input edge,
/// past its neighbour, turns two faces of 3e-9 over: each then fits the other sheet, the right
/// way up, and the regions' areas move by less than a billionth. Only the fold across an output
/// edge inside the input's faces tells it.
#[test]
fn face_turned_over_on_a_folded_region_is_reported() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/regressions");
    let input = dir.join("bug-checker-folded-turned-face.obj");
    let output = dir.join("bug-checker-folded-turned-face-output.obj");
    // The refined output (`--repair -ds queue -s 0`), folded edges along the input's fold
    // included, passes.
    assert_passes(&check_files(&input, &output).expect("valid files"));
    let text = std::fs::read_to_string(&output).expect("readable");
    let (moved, past) = (
        "v 1.5731372550311296 0.3333333333333333 0.0",
        "1.5731372317623578 0.3333333333333333",
    );
    assert!(
        text.contains(moved) && text.contains(past),
        "the vertex and its neighbour on y = 1/3"
    );
    let damaged = text.replace(moved, "v 1.5731372201279719 0.3333333333333333 0.0");
    let input_text = std::fs::read_to_string(&input).expect("readable");
    let report = check_texts(&input_text, &damaged);
    assert_failure(&report, "lie folded onto each other across the edge");
    assert_failure(&report, "which lies along no input edge: one of them is turned over");
    // Nothing else tells it: no area, orientation or vertex failure.
    assert!(
        report
            .failures
            .iter()
            .all(|line| line.contains("folded onto each other")),
        "{report}"
    );
}
