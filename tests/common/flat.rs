//! Helpers of the tests of flat regions made Delaunay before Algorithm 2
//! (tests/convex_regions.rs, tests/flat_regions.rs).

use std::path::Path;

use assert_cmd::Command;
use delmesh::check::{check_meshes, Mesh3};
use delmesh::Surface;
use glam::DVec3;

/// Exactly planar lifts of (x, y) (dyadic coordinates: every product and
/// sum below is exact): the plane z = 0, a tilted plane, and a vertical one.
pub const LIFTS: [fn(f64, f64) -> DVec3; 3] = [
    |x, y| DVec3::new(x, y, 0.0),
    |x, y| DVec3::new(x, y, x / 2.0 + y / 4.0),
    |x, y| DVec3::new(x, 0.75, y),
];

/// The triangles of `s`, each from its lowest corner, sorted.
pub fn triangle_set(s: &Surface) -> Vec<[u32; 3]> {
    let mut t: Vec<[u32; 3]> = s
        .triangles()
        .into_iter()
        .map(|t| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap();
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        })
        .collect();
    t.sort_unstable();
    t
}

/// The judge passes `s` as a Delaunay mesh of (`positions`, `triangles`).
pub fn judge(positions: &[DVec3], triangles: &[[u32; 3]], s: &Surface) {
    let input = Mesh3 {
        positions: positions.to_vec(),
        triangles: triangles.to_vec(),
    };
    let output = Mesh3 {
        positions: s.positions.clone(),
        triangles: s.triangles(),
    };
    let report = check_meshes(&input, &output);
    assert!(report.passed(), "{:?}", report.failures);
}

/// A prism's triangles: `bottom` and `top`, triangulations of the two
/// rings' `n` corners (`0..n` below, `n..2n` above, both numbered `0..n`
/// and counter-clockwise from above), the bottom turned over, and the
/// sides, two triangles a segment.
pub fn prism_triangles(n: usize, bottom: &[[u32; 3]], top: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let m = n as u32;
    let mut triangles: Vec<[u32; 3]> = bottom.iter().map(|&[a, b, c]| [a, c, b]).collect();
    triangles.extend(top.iter().map(|t| t.map(|v| m + v)));
    for i in 0..m {
        let j = (i + 1) % m;
        triangles.push([i, j, m + j]);
        triangles.push([i, m + j, m + i]);
    }
    triangles
}

/// Runs `delmesh -i input -o dir/out.obj` with `extra`, writing the vertex
/// and face maps too, and checks the output and both maps with `delmesh
/// check`; returns what the run printed.
pub fn refine_and_check(input: &Path, dir: &Path, extra: &[&str]) -> String {
    let (out, vm, fm) = (dir.join("out.obj"), dir.join("v.csv"), dir.join("f.csv"));
    let maps = |c: &mut Command| {
        c.arg("--vertex-map").arg(&vm).arg("--face-map").arg(&fm);
    };
    let mut run = Command::cargo_bin("delmesh").unwrap();
    run.arg("-i").arg(input).arg("-o").arg(&out);
    maps(&mut run);
    let output = run.args(extra).output().unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let mut check = Command::cargo_bin("delmesh").unwrap();
    check.arg("check").arg(input).arg(&out);
    maps(&mut check);
    let checked = check.output().unwrap();
    assert!(checked.status.success(), "{}", String::from_utf8_lossy(&checked.stdout));
    String::from_utf8(output.stdout).unwrap()
}

/// The command line on (`positions`, `triangles`), written as an OBJ file:
/// by default it prints `note` (with maps and check passing), and with
/// `--keep-order` nothing containing `absent`.
pub fn says_unless_keep_order(positions: &[DVec3], triangles: &[[u32; 3]], note: &str, absent: &str) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mesh.obj");
    delmesh::io::write_obj(&path, positions, triangles).unwrap();
    let said = refine_and_check(&path, dir.path(), &[]);
    assert!(said.contains(note), "{said}");
    let kept = refine_and_check(&path, dir.path(), &["--keep-order"]);
    assert!(!kept.contains(absent), "{kept}");
}
