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

/// The `v` lines of an OBJ file, in order.
fn obj_vertices(path: &Path) -> Vec<[f64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let x: Vec<f64> = l.split_whitespace().take(3).map(|x| x.parse().unwrap()).collect();
            [x[0], x[1], x[2]]
        })
        .collect()
}

/// Refines `input` with `flags` and the vertex map, checks every row, and
/// returns the map.
fn rebuild(input: &Path, flags: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let (out, map) = (dir.path().join("out.obj"), dir.path().join("map.csv"));
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
    let (inp, outp) = (obj_vertices(input), obj_vertices(&out));
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
    table
}

#[test]
fn every_output_vertex_is_rebuilt_from_the_input_file() {
    let mut inputs: Vec<PathBuf> = common::fixtures();
    inputs.push(common::data_dir().join("cad/rotor.obj"));
    for input in &inputs {
        let rows = rebuild(input, &[]).lines().count() - 1;
        assert!(rows >= obj_vertices(input).len() / 2);
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

#[test]
fn a_ply_with_attributes_is_refused_before_refining() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("tex.obj");
    std::fs::write(
        &input,
        "v 0 0 0\nv 4 0 0\nv 4 1 0\nv 0 1 0\nv 2 0.1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.1\n\
         f 1/1 2/2 5/5\nf 2/2 3/3 5/5\nf 3/3 4/4 5/5\nf 4/4 1/1 5/5\n",
    )
    .unwrap();
    let run = delmesh()
        .arg("-i")
        .arg(&input)
        .arg("-o")
        .arg(dir.path().join("out.ply"))
        .arg("--vertex-map")
        .arg(dir.path().join("map.csv"))
        .output()
        .unwrap();
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("--drop-attributes"), "{stderr}");
    assert!(!dir.path().join("out.ply").exists() && !dir.path().join("map.csv").exists());
    // As OBJ it is fine, and the texture coordinates do not change the rows.
    rebuild(&input, &[]);
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
