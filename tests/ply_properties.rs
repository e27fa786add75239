//! A PLY file's other vertex and face properties (MeshLab's `quality`, a
//! scan's `confidence`, face colours, segment labels) reach a PLY output
//! with their names and types: an added vertex interpolates its input
//! edge's ends (an integer property takes the nearer end's value), and each
//! output face takes the value of the input face it lies in. Formats that
//! cannot hold them leave them out with a note, as do lists and other
//! elements. Every output passes `delmesh check`.

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use delmesh::attributes::{Kind, ValueType};
use delmesh::io::{self, InputMesh, ReadOptions};
use glam::DVec3;

fn delmesh() -> Command {
    Command::cargo_bin("delmesh").unwrap()
}

/// Runs delmesh on `input` with `--check`, writing `output`; returns its
/// printout.
fn run(input: &Path, output: &Path, extra: &[&str]) -> String {
    let out = delmesh()
        .arg("-i")
        .arg(input)
        .arg("-o")
        .arg(output)
        .arg("--check")
        .args(extra)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "delmesh failed on {}: {text}{}",
        input.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    text
}

fn read(path: &Path) -> InputMesh {
    io::read_mesh(path, &ReadOptions::default()).unwrap()
}

/// The rotor (flat regions whose edges are flipped, thin faces that get
/// split) as a binary PLY with a float `quality` and a ushort `label` per
/// vertex, a feature list per vertex, face colours and an int `segment`
/// per face, and an `edge` element.
fn rotor_ply(dir: &Path) -> PathBuf {
    let rotor = read(&common::data_dir().join("cad").join("rotor.obj"));
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nproperty float quality\nproperty ushort label\nproperty list uchar float feature\n\
         element face {}\nproperty list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\n\
         property uchar blue\nproperty int segment\nelement edge 1\nproperty int vertex1\nproperty int vertex2\n\
         end_header\n",
        rotor.positions.len(),
        rotor.triangles.len()
    )
    .into_bytes();
    for (i, p) in rotor.positions.iter().enumerate() {
        for c in p.to_array() {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
        bytes.extend_from_slice(&(((3.0 * p.x).sin() + p.y * p.y) as f32).to_le_bytes());
        bytes.extend_from_slice(&((i * 7919 % 5) as u16).to_le_bytes());
        bytes.push(1);
        bytes.extend_from_slice(&0.5f32.to_le_bytes());
    }
    for (f, t) in rotor.triangles.iter().enumerate() {
        bytes.push(3);
        for v in t {
            bytes.extend_from_slice(&(*v as i32).to_le_bytes());
        }
        let segment = (f / 37 % 3) as i32;
        bytes.extend_from_slice(&[(60 * segment) as u8, 200, 7]);
        bytes.extend_from_slice(&(segment - 1).to_le_bytes());
    }
    bytes.extend_from_slice(&[0, 0, 0, 0, 1, 0, 0, 0]);
    let path = dir.join("rotor.ply");
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The values of vertex property `name` of `m`, per triangle corner.
fn vertex_values(m: &InputMesh, name: &str) -> Vec<f64> {
    let (i, p) = (m.attributes.properties.iter().enumerate())
        .find(|(_, p)| p.name == name)
        .unwrap_or_else(|| panic!("no vertex property {name}"));
    let channel = m.attributes.channels().find(|(k, _)| *k == Kind::Property(i as u16));
    let channel = channel
        .unwrap_or_else(|| panic!("vertex property {name} has no values"))
        .1;
    assert_eq!(p.channel.as_ref(), Some(channel));
    (0..channel.corners.len()).map(|c| channel.corner(c)[0]).collect()
}

/// The values of face property `name` of `m`, per triangle.
fn face_values<'a>(m: &'a InputMesh, name: &str) -> &'a [f64] {
    let p = m.attributes.face_properties.iter().find(|p| p.name == name);
    &p.unwrap_or_else(|| panic!("no face property {name}")).values
}

/// Where `p` lies on the input: at input vertex `v`, or on input edge (a, b)
/// at parameter t from a.
enum Place {
    Vertex(usize),
    Edge(usize, usize, f64),
}

fn place(input: &InputMesh, p: DVec3) -> Place {
    if let Some(v) = input.positions.iter().position(|&q| q == p) {
        return Place::Vertex(v);
    }
    let mut best = (f64::INFINITY, 0, 0, 0.0);
    for t in &input.triangles {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let (pa, pb) = (input.positions[a], input.positions[b]);
            let d = pb - pa;
            let s = (p - pa).dot(d) / d.length_squared();
            let distance = (pa + s * d - p).length();
            if (0.0..=1.0).contains(&s) && distance < best.0 {
                best = (distance, a, b, s);
            }
        }
    }
    assert!(best.0 < 1e-9, "{p} is on no input edge ({})", best.0);
    Place::Edge(best.1, best.2, best.3)
}

/// The input triangle whose interior holds `p` (the one it is most inside of).
fn containing_triangle(input: &InputMesh, p: DVec3) -> usize {
    let mut best = (f64::NEG_INFINITY, usize::MAX);
    for (i, t) in input.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|v| input.positions[v as usize]);
        let n = (b - a).cross(c - a);
        let nn = n.length_squared();
        let lb = (p - a).cross(c - a).dot(n) / nn;
        let lc = (b - a).cross(p - a).dot(n) / nn;
        let off_plane = (p - a).dot(n).abs() / nn.sqrt();
        let inside = (1.0 - lb - lc).min(lb).min(lc);
        if off_plane < 1e-9 && inside > best.0 {
            best = (inside, i);
        }
    }
    assert!(best.0 > -1e-9, "{p} is in no input face");
    best.1
}

/// Checks every corner and face of `output` against `input`: input
/// vertices keep their values exactly; added ones interpolate `quality`
/// (within its float rounding) and take the nearer end's `label`; each
/// face has the face values of the input face holding its centroid.
fn assert_carried(input: &InputMesh, output: &InputMesh) {
    let per_vertex = |m: &InputMesh, name: &str| {
        let mut values = vec![f64::NAN; m.positions.len()];
        for (c, x) in vertex_values(m, name).into_iter().enumerate() {
            values[m.triangles[c / 3][c % 3] as usize] = x;
        }
        values
    };
    let (quality_in, label_in) = (per_vertex(input, "quality"), per_vertex(input, "label"));
    let (quality, label) = (vertex_values(output, "quality"), vertex_values(output, "label"));
    let mut added = 0;
    for (c, (&q, &l)) in quality.iter().zip(&label).enumerate() {
        let p = output.positions[output.triangles[c / 3][c % 3] as usize];
        match place(input, p) {
            Place::Vertex(v) => assert_eq!((q, l), (quality_in[v], label_in[v]), "at input vertex {v}"),
            Place::Edge(a, b, t) => {
                added += 1;
                let expected = quality_in[a] + t * (quality_in[b] - quality_in[a]);
                assert!(
                    (q - expected).abs() <= 1e-6 * expected.abs().max(1.0),
                    "quality {q} at {p}: {expected}"
                );
                let nearer = if t < 0.5 { label_in[a] } else { label_in[b] };
                let tie = (t - 0.5).abs() < 1e-9 && (l == label_in[a] || l == label_in[b]);
                assert!(
                    l == nearer || tie,
                    "label {l} at {p}, t = {t} from {a} ({}) to {b} ({})",
                    label_in[a],
                    label_in[b]
                );
            }
        }
    }
    assert!(added > 0, "nothing was added");
    for name in ["red", "green", "blue", "segment"] {
        let (before, after) = (face_values(input, name), face_values(output, name));
        assert_eq!(after.len(), output.triangles.len());
        for (f, t) in output.triangles.iter().enumerate() {
            let centroid = t.iter().map(|&v| output.positions[v as usize]).sum::<DVec3>() / 3.0;
            let holder = containing_triangle(input, centroid);
            assert_eq!(after[f], before[holder], "{name} of output face {f}");
        }
    }
}

#[test]
fn vertex_and_face_properties_reach_a_ply_output() {
    let dir = tempfile::tempdir().unwrap();
    let input_path = rotor_ply(dir.path());
    let input = read(&input_path);
    for flags in [&[][..], &["--prune"], &["--shells", "-s", "4"]] {
        let out = dir.path().join("out.ply");
        let printout = run(&input_path, &out, flags);
        assert!(
            printout.contains(
                "        attributes: vertex properties (quality, label), face properties (red, green, blue, segment)\n"
            ),
            "{printout}"
        );
        assert!(
            printout.contains("note    vertex property feature left out: delmesh carries single numbers, not lists\n"),
            "{printout}"
        );
        assert!(
            printout.contains("note    element edge (1 record) left out: delmesh reads vertices and faces\n"),
            "{printout}"
        );
        let bytes = std::fs::read(&out).unwrap();
        let header = String::from_utf8_lossy(&bytes[..600]).into_owned();
        let header = &header[..header.find("end_header").unwrap()];
        assert!(
            header.contains("property float quality\nproperty ushort label\nelement face"),
            "{header}"
        );
        assert!(
            header.contains(
                "vertex_indices\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty int segment\n"
            ),
            "{header}"
        );
        let output = read(&out);
        assert_eq!(output.attributes.properties[1].ty, ValueType::U16);
        assert_carried(&input, &output);
    }
}

/// An OBJ output cannot hold the properties: they are left out before the
/// construction (no splits for them), with a note; `--drop-attributes`
/// refines the same mesh.
#[test]
fn properties_an_obj_cannot_hold_are_left_out() {
    let dir = tempfile::tempdir().unwrap();
    let input = rotor_ply(dir.path());
    let obj = run(&input, &dir.path().join("out.obj"), &[]);
    assert!(
        obj.contains(
            "note    vertex properties (quality, label) and face properties (red, green, blue, segment) left out: \
             OBJ cannot hold them (the mesh is refined as without them)\n"
        ),
        "{obj}"
    );
    let plain = run(&input, &dir.path().join("plain.obj"), &["--drop-attributes"]);
    let output_line = |s: &str| {
        s.lines()
            .find(|l| l.starts_with("output"))
            .unwrap()
            .split(':')
            .nth(1)
            .unwrap()
            .to_owned()
    };
    assert_eq!(output_line(&obj), output_line(&plain));
    assert_eq!(
        std::fs::read(dir.path().join("out.obj")).unwrap(),
        std::fs::read(dir.path().join("plain.obj")).unwrap()
    );
}

/// A flat grid whose faces carry two labels: faces of different labels
/// never share a planar region, so the diagonals between them are split,
/// not flipped, and every output face keeps one label.
#[test]
fn faces_of_different_values_stay_apart() {
    let dir = tempfile::tempdir().unwrap();
    // A strip of thin triangles: flipping their shared diagonals is what
    // makes it Delaunay.
    let n = 12;
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nproperty uchar part\nend_header\n",
        2 * (n + 1),
        2 * n
    );
    for i in 0..=n {
        writeln!(text, "{i} 0 0\n{} 0.25 0", i as f64 + 0.75).unwrap();
    }
    for i in 0..n {
        let (a, b, c, d) = (2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1);
        let part = u8::from(i >= n / 2);
        writeln!(text, "3 {a} {b} {c} {part}\n3 {a} {c} {d} {part}").unwrap();
    }
    let input_path = dir.path().join("strip.ply");
    std::fs::write(&input_path, text).unwrap();
    let plain = run(&input_path, &dir.path().join("plain.ply"), &["--drop-attributes"]);
    let labelled = run(&input_path, &dir.path().join("labelled.ply"), &[]);
    let added = |s: &str| -> usize {
        let line = s.lines().find(|l| l.starts_with("output")).unwrap();
        line.split(", ")
            .last()
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    assert!(added(&labelled) >= added(&plain), "{plain}\n{labelled}");
    let input = read(&input_path);
    let output = read(&dir.path().join("labelled.ply"));
    let before = face_values(&input, "part");
    let after = face_values(&output, "part");
    assert_eq!(
        after.iter().filter(|&&x| x == 0.0).count() + after.iter().filter(|&&x| x == 1.0).count(),
        after.len()
    );
    for (f, t) in output.triangles.iter().enumerate() {
        let centroid = t.iter().map(|&v| output.positions[v as usize]).sum::<DVec3>() / 3.0;
        assert_eq!(after[f], before[containing_triangle(&input, centroid)], "face {f}");
    }
}

/// A value its type cannot hold (in ASCII data) drops that property alone,
/// with a note naming the line; the others are kept.
#[test]
fn a_defective_property_is_dropped_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
                property uchar label\nproperty double height\nelement face 2\n\
                property list uchar int vertex_indices\nend_header\n\
                0 0 0 1 0.5\n1 0 0 300 1.5\n1 1 0 2 2.5\n0 1 0 3 3.5\n3 0 1 2\n3 0 2 3\n";
    let input = dir.path().join("bad.ply");
    std::fs::write(&input, text).unwrap();
    let printout = run(&input, &dir.path().join("out.ply"), &[]);
    assert!(
        printout.contains(
            "note    vertex property label dropped: line 13: vertex 1 property label: `300` does not fit its declared \
             type uchar (an integer from 0 to 255)\n"
        ),
        "{printout}"
    );
    assert!(
        printout.contains("        attributes: vertex property height\n"),
        "{printout}"
    );
    let output = read(&dir.path().join("out.ply"));
    assert_eq!(output.attributes.properties.len(), 1);
    assert_eq!(output.attributes.properties[0].ty, ValueType::F64);
    // One property left out of an OBJ: `it`.
    let printout = run(&input, &dir.path().join("out.obj"), &[]);
    assert!(
        printout.contains(
            "note    vertex property height left out: OBJ cannot hold it (the mesh is refined as without it)\n"
        ),
        "{printout}"
    );
}

/// `--attribute-tolerance properties=REL` sets the vertex properties' own.
#[test]
fn the_properties_tolerance_is_a_relative_number() {
    let dir = tempfile::tempdir().unwrap();
    let input = rotor_ply(dir.path());
    run(
        &input,
        &dir.path().join("out.ply"),
        &["--attribute-tolerance", "properties=0"],
    );
    let out = delmesh()
        .args(["-i"])
        .arg(&input)
        .args(["-o"])
        .arg(dir.path().join("x.ply"))
        .args(["--attribute-tolerance", "properties=2"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("is not a relative tolerance"), "{stderr}");
}

/// A vertex element of more properties than delmesh numbers (65,536) keeps
/// the first ones, each with its own values, and names the rest in a note:
/// the 65,537th was carried in the first's place, overwriting its values.
#[test]
fn vertex_properties_beyond_the_most_carried_are_left_out_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let n = delmesh::attributes::MAX_VERTEX_PROPERTIES + 2;
    let mut bytes = String::from(
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\n\
         property double z\n",
    );
    for j in 0..n {
        writeln!(bytes, "property uchar p{j}").unwrap();
    }
    bytes.push_str("element face 1\nproperty list uchar int vertex_indices\nend_header\n");
    let mut bytes = bytes.into_bytes();
    let value = |v: usize, j: usize| ((7 * v + j) % 251) as u8;
    for (v, p) in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        .iter()
        .enumerate()
    {
        for c in p {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
        bytes.extend((0..n).map(|j| value(v, j)));
    }
    bytes.push(3);
    for v in 0..3i32 {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let input = dir.path().join("wide.ply");
    std::fs::write(&input, bytes).unwrap();
    let out = dir.path().join("out.ply");
    let printout = run(&input, &out, &[]);
    assert!(
        printout
            .contains("note    2 more vertex properties left out (from p65536 on): delmesh carries at most 65536\n"),
        "{}",
        &printout[printout.len().saturating_sub(2000)..]
    );
    let output = read(&out);
    assert_eq!(output.attributes.properties.len(), n - 2);
    for j in [0, 1, n - 3] {
        let values = vertex_values(&output, &format!("p{j}"));
        for (c, x) in values.into_iter().enumerate() {
            let v = output.triangles[c / 3][c % 3] as usize;
            assert_eq!(x, value(v, j) as f64, "p{j} of vertex {v}");
        }
    }
}

/// `--repair` carries the vertex and face properties (once it dropped them,
/// with a note naming them): the output has what the run without it has.
#[test]
fn repair_keeps_the_properties() {
    let dir = tempfile::tempdir().unwrap();
    let input = rotor_ply(dir.path());
    let printout = run(&input, &dir.path().join("out.ply"), &["--repair"]);
    assert!(!printout.contains("dropped"), "{printout}");
    run(&input, &dir.path().join("plain.ply"), &[]);
    assert_eq!(
        std::fs::read(dir.path().join("out.ply")).unwrap(),
        std::fs::read(dir.path().join("plain.ply")).unwrap(),
        "a mesh repair leaves as it is refines to the same file with --repair"
    );
    let output = read(&dir.path().join("out.ply"));
    let (vertex, face) = output.attributes.property_names();
    assert_eq!(vertex.len(), 2);
    assert_eq!(face.len(), 4);
}
