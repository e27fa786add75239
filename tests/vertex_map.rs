//! `--vertex-map`: every output vertex is rebuilt, bit for bit, from the
//! input file's own vertices with the row's `a + t·(b − a)`, whatever the
//! file's numbering (unused and duplicate vertices), with pruning and with
//! repair.

mod common;

use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn delmesh() -> Command {
    Command::cargo_bin("delmesh").unwrap()
}

/// Refines `input` with `flags` and the vertex map, checks every row, and
/// returns the map.
fn rebuild(input: &Path, flags: &[&str]) -> String {
    rebuild_as(input, "out.obj", flags).0
}

/// [`rebuild`] into a file named `output` (OBJ, or PLY as delmesh writes
/// it); also returns the output's vertices, in the file's order.
fn rebuild_as(input: &Path, output: &str, flags: &[&str]) -> (String, Vec<[f64; 3]>) {
    let dir = tempfile::tempdir().unwrap();
    let (out, map) = (dir.path().join(output), dir.path().join("map.csv"));
    let run = delmesh()
        .arg("-q")
        .arg("-i")
        .arg(input)
        .arg("-o")
        .arg(&out)
        .arg("--vertex-map")
        .arg(&map)
        .args(flags)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let inp = common::obj_vertices(input);
    let outp = if output.ends_with(".ply") {
        ply_vertices(&out)
    } else {
        common::obj_vertices(&out)
    };
    let table = std::fs::read_to_string(&map).unwrap();
    let mut lines = table.lines();
    assert_eq!(lines.next(), Some("output_index,input_index_a,input_index_b,t"));
    let mut rows = 0;
    for (k, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        let (i, a, b): (usize, usize, usize) = (
            cells[0].parse().unwrap(),
            cells[1].parse().unwrap(),
            cells[2].parse().unwrap(),
        );
        let t: f64 = cells[3].parse().unwrap();
        assert_eq!(i, k);
        if a == b {
            assert_eq!(t, 0.0, "{line}");
        } else {
            assert!(t > 0.0 && t < 1.0, "{line}");
        }
        let want: [f64; 3] = std::array::from_fn(|c| inp[a][c] + t * (inp[b][c] - inp[a][c]));
        assert_eq!(want, outp[i], "{} row {line}", input.display());
        rows += 1;
    }
    assert_eq!(rows, outp.len());
    (table, outp)
}

#[test]
fn every_output_vertex_is_rebuilt_from_the_input_file() {
    let mut inputs: Vec<PathBuf> = common::fixtures();
    inputs.push(common::data_dir().join("cad/rotor.obj"));
    for input in &inputs {
        let rows = rebuild(input, &[]).lines().count() - 1;
        assert!(rows >= common::obj_vertices(input).len() / 2);
        rebuild(input, &["--prune", "-s", "3"]);
    }
    rebuild(&common::data_dir().join("repair/dragon-cut.obj"), &["--repair"]);
}

#[test]
fn input_indices_count_the_files_vertices() {
    // An unused vertex first, and vertex 5 a duplicate of vertex 2 (welded):
    // the map still names the file's own vertices (0-based: the unused one
    // is 0, the duplicate's first definition 1). The shared edge of the two
    // folded triangles is not Delaunay and gets split.
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("fold.obj");
    std::fs::write(
        &input,
        "v 9 9 9\nv 0 0 0\nv 4 0 0\nv 2 0.3 0.2\nv 0 0 0\nv 2 -0.3 0.2\nf 5 3 4\nf 3 2 6\n",
    )
    .unwrap();
    let table = rebuild(&input, &[]);
    let rows: Vec<&str> = table.lines().skip(1).collect();
    assert_eq!(rows[..4], ["0,1,1,0.0", "1,2,2,0.0", "2,3,3,0.0", "3,5,5,0.0"]);
    assert!(rows[4].starts_with("4,1,2,"), "{table}");
}

/// The vertex records of a binary little-endian PLY as delmesh writes it:
/// x, y, z as doubles first, then doubles and uchars.
fn ply_vertices(path: &Path) -> Vec<[f64; 3]> {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    assert!(header.contains("format binary_little_endian 1.0"), "{header}");
    let mut count = 0;
    let mut size = 0;
    for line in header.lines().skip_while(|l| !l.starts_with("element vertex")) {
        if let Some(n) = line.strip_prefix("element vertex ") {
            count = n.parse().unwrap();
        } else if line.starts_with("element") {
            break;
        } else if let Some(p) = line.strip_prefix("property ") {
            size += if p.starts_with("uchar") { 1 } else { 8 };
        }
    }
    let coordinate = |at: usize| f64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
    (0..count)
        .map(|i| std::array::from_fn(|c| coordinate(end + i * size + 8 * c)))
        .collect()
}

/// A PLY output of a mesh with attributes writes a vertex once per value
/// (at texture seams) and the map has a row per written vertex, a copy's
/// row the row of the vertex it repeats; with per-vertex colours (no seam)
/// the rows are the vertices. Every row rebuilds its vertex bit for bit.
#[test]
fn a_ply_with_attributes_has_a_row_per_written_vertex() {
    let dir = tempfile::tempdir().unwrap();
    // A square fanned around vertex 5, with a texture seam along the edge
    // 1-5: vertex 1 has coordinates (0, 0) in face 1 and (1, 1) in face 4,
    // and vertex 5 (0.5, 0.1) and (0.5, 0.9).
    let seam = dir.path().join("seam.obj");
    std::fs::write(
        &seam,
        "v 0 0 0\nv 4 0 0\nv 4 1 0.5\nv 0 1 0.5\nv 2 0.1 0\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.1\nvt 1 1\nvt 0.5 0.9\n\
         f 1/1 2/2 5/5\nf 2/2 3/3 5/5\nf 3/3 4/4 5/7\nf 4/4 1/6 5/7\n",
    )
    .unwrap();
    // The bunny with a colour on every vertex (`v x y z r g b`).
    let bunny = common::data_dir().join("bunny.obj");
    let coloured = dir.path().join("coloured.obj");
    let text: String = std::fs::read_to_string(&bunny)
        .unwrap()
        .lines()
        .enumerate()
        .map(|(i, l)| match l.strip_prefix("v ") {
            Some(xyz) => format!("v {xyz} {} 0.5 {}\n", (i % 7) as f64 / 7.0, (i % 3) as f64 / 3.0),
            None => format!("{l}\n"),
        })
        .collect();
    std::fs::write(&coloured, text).unwrap();
    for (input, has_copies) in [(&seam, true), (&coloured, false)] {
        let (_, outp) = rebuild_as(input, "out.ply", &[]);
        // Copies are written at the same position as an earlier vertex.
        let distinct: std::collections::HashSet<[u64; 3]> = outp.iter().map(|p| p.map(f64::to_bits)).collect();
        assert_eq!(distinct.len() < outp.len(), has_copies, "{}", input.display());
    }
}

#[test]
fn batch_writes_the_same_maps() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let inputs = common::fixtures();
    let run = delmesh()
        .arg("batch")
        .arg("-q")
        .arg("--vertex-maps")
        .arg("-d")
        .arg(&out_dir)
        .args(&inputs)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    for input in &inputs {
        let map = dir.path().join("single.csv");
        delmesh()
            .arg("-q")
            .arg("-i")
            .arg(input)
            .arg("-o")
            .arg(dir.path().join("single.obj"))
            .arg("--vertex-map")
            .arg(&map)
            .assert()
            .success();
        let stem = input.file_stem().unwrap().to_string_lossy();
        let batch_map = out_dir.join(format!("{stem}.vertex-map.csv"));
        assert_eq!(
            std::fs::read(&batch_map).unwrap(),
            std::fs::read(&map).unwrap(),
            "{stem}"
        );
    }
}

/// A file with unused or repeated vertices is numbered without them in
/// the output: the printout says so where it counts them, and points to
/// --vertex-map.
#[test]
fn the_printout_says_when_the_input_is_renumbered() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "v 0 0 0\nv 5 5 5\nv 4 0 0\nv 4 1 0\nv 0 1 .1\nf 1 3 4\nf 1 4 5\n",
            "dropped 1 unused vertex: the output numbers the input's vertices without it",
        ),
        (
            "v 0 0 0\nv 4 0 0\nv 4 0 0\nv 4 1 0\nv 0 1 .1\nv 9 9 9\nf 1 2 4\nf 1 4 5\n",
            "welded 1 duplicate vertex, dropped 1 unused vertex: the output numbers the input's vertices without them",
        ),
    ];
    for (i, (text, line)) in cases.iter().enumerate() {
        let input = dir.path().join(format!("in{i}.obj"));
        std::fs::write(&input, text).unwrap();
        let out = delmesh()
            .arg("-i")
            .arg(&input)
            .arg("-o")
            .arg(dir.path().join(format!("out{i}.obj")))
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{stdout}");
        assert!(
            stdout.contains(line) && stdout.contains("(--vertex-map gives each vertex its number in the input file)"),
            "{stdout}"
        );
    }
}
