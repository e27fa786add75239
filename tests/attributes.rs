//! Attributes survive (issue 6, item 1): texture coordinates, normals,
//! colours, groups and materials of the input reach the output, and the
//! piecewise-linear fields they define are the same before and after, at
//! random surface points. Every output also passes `delmesh check`.

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use common::{barycentric, channel, Rng};
use delmesh::attributes::{Channel, Kind};
use delmesh::io::{self, InputMesh, ReadOptions};
use delmesh::repair::RepairOptions;
use glam::DVec3;

fn delmesh() -> Command {
    Command::cargo_bin("delmesh").unwrap()
}

/// Runs delmesh on `input`, writing `output`; returns its printout.
fn run(input: &Path, output: &Path, extra: &[&str]) -> String {
    let out = delmesh()
        .arg("-i")
        .arg(input)
        .arg("-o")
        .arg(output)
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

/// `delmesh check` passes.
fn check(input: &Path, output: &Path) {
    let out = delmesh().arg("check").arg(input).arg(output).output().unwrap();
    assert!(
        out.status.success(),
        "check failed: {}",
        String::from_utf8_lossy(&out.stdout)
    );
}

/// (added vertices, splits, flips) from a printout.
fn work(printout: &str) -> (usize, usize, usize) {
    // (The word singular after 1: "1 split".)
    let number_before = |line: &str, word: &str| -> usize {
        let words: Vec<&str> = line.split([' ', ',', ';']).filter(|w| !w.is_empty()).collect();
        let i = (words.iter())
            .position(|w| *w == word || Some(*w) == word.strip_suffix('s'))
            .unwrap();
        words[i - 1].parse().unwrap()
    };
    let output = printout.lines().find(|l| l.starts_with("output")).unwrap();
    let work = printout.lines().find(|l| l.starts_with("work")).unwrap();
    (
        number_before(output, "added"),
        number_before(work, "splits"),
        number_before(work, "flips"),
    )
}

fn read(path: &Path) -> InputMesh {
    io::read_mesh(path, &ReadOptions::default()).unwrap()
}

/// The value of `kind` at barycentric `l` of triangle `t` (`None` on a
/// triangle without values).
fn interpolate(ch: &Channel, t: usize, l: [f64; 3]) -> Option<Vec<f64>> {
    if (0..3).any(|i| ch.corner(3 * t + i).len() != ch.dim) {
        return None;
    }
    let values = (0..ch.dim)
        .map(|k| (0..3).map(|i| l[i] * ch.corner(3 * t + i)[k]).sum())
        .collect();
    Some(values)
}

/// The input triangle holding `p`: the one it is most inside of.
fn locate(m: &InputMesh, p: DVec3, scale: f64) -> Option<(usize, [f64; 3])> {
    let mut best: Option<(usize, [f64; 3], f64)> = None;
    for t in 0..m.triangles.len() {
        let (l, distance) = barycentric(m, t, p);
        let inside = l.iter().copied().fold(f64::INFINITY, f64::min);
        if distance <= 1e-9 * scale && inside >= -1e-9 && best.is_none_or(|b| inside > b.2) {
            best = Some((t, l, inside));
        }
    }
    best.map(|(t, l, _)| (t, l))
}

/// At `samples` random points of the output surface, the largest
/// difference of each attribute between output and input (0 for missing).
fn compare(input: &InputMesh, output: &InputMesh, samples: usize, seed: u64) -> [f64; 3] {
    let mut rng = Rng::new(seed);
    let scale = input.positions.iter().fold(1.0f64, |m, p| m.max(p.abs().max_element()));
    let mut worst = [0.0f64; 3];
    for _ in 0..samples {
        let t = rng.below(output.triangles.len() as u64) as usize;
        let (r1, r2) = (rng.f64().sqrt(), rng.f64());
        let l = [1.0 - r1, r1 * (1.0 - r2), r1 * r2];
        let [a, b, c] = output.triangles[t].map(|v| output.positions[v as usize]);
        let p = l[0] * a + l[1] * b + l[2] * c;
        let (s, ls) = locate(input, p, scale).unwrap_or_else(|| panic!("{p} is on no input face"));
        for (k, kind) in [Kind::TexCoord, Kind::Normal, Kind::Color].into_iter().enumerate() {
            match (channel(input, kind), channel(output, kind)) {
                (None, None) => {}
                (Some(ci), Some(co)) => match (interpolate(ci, s, ls), interpolate(co, t, l)) {
                    (None, None) => {}
                    (Some(before), Some(after)) => {
                        for (x, y) in before.iter().zip(&after) {
                            worst[k] = worst[k].max((x - y).abs());
                        }
                    }
                    _ => panic!("{} at {p} on one side only", kind.name()),
                },
                _ => panic!("{} present on one side only", kind.name()),
            }
        }
    }
    worst
}

fn num(x: f64) -> String {
    // Display of f64 is the shortest text that reads back to the same value.
    format!("{x}")
}

/// A jittered grid on the plane z = x/2 + y/4 with alternating diagonals
/// (so that edges must be flipped), coordinates dyadic (exactly coplanar).
struct Grid {
    n: usize,
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

impl Grid {
    fn new(n: usize, seed: u64) -> Grid {
        let mut rng = Rng::new(seed);
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (mut x, mut y) = (i as f64, j as f64);
                if i > 0 && i < n && j > 0 && j < n {
                    x += (rng.below(49) as f64 - 24.0) / 64.0;
                    y += (rng.below(49) as f64 - 24.0) / 64.0;
                }
                positions.push(DVec3::new(x, y, x / 2.0 + y / 4.0));
            }
        }
        let triangles = common::grid_triangles(n);
        Grid {
            n,
            positions,
            triangles,
        }
    }

    /// Whether triangle `t` is in the right half (x beyond n/2).
    fn right(&self, t: usize) -> bool {
        let c: f64 = self.triangles[t]
            .iter()
            .map(|&v| self.positions[v as usize].x)
            .sum::<f64>()
            / 3.0;
        c > self.n as f64 / 2.0
    }

    /// OBJ text: texture coordinates from `uv` (of the vertex and whether
    /// its face is in the right half), written once per corner; affine
    /// normals and colours if asked; `usemtl left`/`right` by half if asked.
    fn obj(&self, uv: impl Fn(DVec3, bool) -> [f64; 2], normals: bool, colors: bool, groups: bool) -> String {
        let mut s = String::from("# textured grid\nmtllib grid.mtl\no grid\n");
        for p in &self.positions {
            let c = if colors {
                format!(" {} {} 0.5", num(p.x / 16.0), num(p.y / 16.0))
            } else {
                String::new()
            };
            writeln!(s, "v {} {} {}{c}", num(p.x), num(p.y), num(p.z)).unwrap();
        }
        for p in &self.positions {
            writeln!(s, "vn {} {} 1", num(p.x / 32.0), num(-p.y / 64.0)).unwrap();
        }
        let mut material = "";
        for (t, tri) in self.triangles.iter().enumerate() {
            for &v in tri {
                let [u, w] = uv(self.positions[v as usize], self.right(t));
                writeln!(s, "vt {} {}", num(u), num(w)).unwrap();
            }
            if groups {
                let m = if self.right(t) { "right" } else { "left" };
                if m != material {
                    writeln!(s, "usemtl {m}").unwrap();
                    material = m;
                }
            }
            s.push('f');
            for (k, &v) in tri.iter().enumerate() {
                let vt = -3 + k as i64; // per corner, relative
                if normals {
                    write!(s, " {}/{vt}/{}", v + 1, v + 1).unwrap();
                } else {
                    write!(s, " {}/{vt}", v + 1).unwrap();
                }
            }
            s.push('\n');
        }
        s
    }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// An affine texture on a flat grid: edges are flipped as without
/// attributes (same geometry out), and the mapping is the same.
#[test]
fn affine_texture_on_a_flat_grid_allows_flips_and_is_kept() {
    let dir = tempfile::tempdir().unwrap();
    let grid = Grid::new(12, 1);
    let input = write(
        dir.path(),
        "grid.obj",
        &grid.obj(|p, _| [p.x / 8.0, p.y / 16.0], true, true, false),
    );
    let (out, plain) = (dir.path().join("out.obj"), dir.path().join("plain.obj"));
    let printout = run(&input, &out, &[]);
    let (added, _, flips) = work(&printout);
    assert!(flips > 10, "{printout}");
    let dropped = run(&input, &plain, &["--drop-attributes"]);
    assert_eq!(work(&dropped), work(&printout), "attributes changed the construction");
    check(&input, &out);
    let (a, b) = (read(&input), read(&out));
    assert_eq!(b.positions.len(), a.positions.len() + added);
    assert_eq!(b.positions[..a.positions.len()], a.positions[..]);
    let worst = compare(&a, &b, 1000, 7);
    assert!(worst.iter().all(|&d| d <= 1e-9), "{worst:?}");
    // The output without attributes has the same geometry, and no vt.
    let text = std::fs::read_to_string(&plain).unwrap();
    assert!(text.lines().all(|l| l.starts_with("v ") || l.starts_with("f ")));
    assert_eq!(read(&plain).triangles, b.triangles);
    let out_text = std::fs::read_to_string(&out).unwrap();
    assert!(out_text.starts_with("mtllib grid.mtl\n"), "{out_text}");
    assert!(out_text.contains("\no grid\n"));
}

/// A texture that is not affine over the grid: no flip may cross an edge,
/// so non-Delaunay edges are split instead, and the mapping is the same.
#[test]
fn non_affine_texture_is_kept_by_splitting() {
    let dir = tempfile::tempdir().unwrap();
    let grid = Grid::new(8, 2);
    let input = write(
        dir.path(),
        "grid.obj",
        &grid.obj(
            |p, _| [p.x * p.x / 64.0, p.y / 8.0 + p.x * p.y / 128.0],
            false,
            false,
            false,
        ),
    );
    let out = dir.path().join("out.obj");
    let printout = run(&input, &out, &[]);
    let (_, splits, flips) = work(&printout);
    let plain = run(&input, &dir.path().join("plain.obj"), &["--drop-attributes"]);
    assert!(work(&plain).2 > 0 && splits > 0, "{plain}\n{printout}");
    // Flips only inside the new faces of splits (their diagonals lie on no input edge).
    let (a, b) = (read(&input), read(&out));
    check(&input, &out);
    let worst = compare(&a, &b, 1000, 8);
    assert!(worst[0] <= 1e-9, "{worst:?} ({flips} flips)");
}

/// A seam down the middle (the right half's u shifted by 0.5): the seam
/// edges keep their two values and the mapping is the same on both sides.
#[test]
fn texture_seam_is_kept() {
    let dir = tempfile::tempdir().unwrap();
    let grid = Grid::new(12, 3);
    let uv = |p: DVec3, right: bool| [p.x / 8.0 + if right { 0.5 } else { 0.0 }, p.y / 16.0];
    let input = write(dir.path(), "grid.obj", &grid.obj(uv, false, false, false));
    let out = dir.path().join("out.obj");
    let printout = run(&input, &out, &[]);
    assert!(work(&printout).2 > 0, "{printout}");
    check(&input, &out);
    let (a, b) = (read(&input), read(&out));
    let worst = compare(&a, &b, 1000, 9);
    assert!(worst[0] <= 1e-9, "{worst:?}");
    // Every output face keeps to one side of the seam: its u range is that of one half.
    let tc = b.attributes.texcoords.as_ref().unwrap();
    for t in 0..b.triangles.len() {
        let xs = b.triangles[t].map(|v| b.positions[v as usize].x);
        let us: Vec<f64> = (0..3).map(|k| tc.corner(3 * t + k)[0]).collect();
        let shift = us[0] - xs[0] / 8.0;
        for k in 0..3 {
            assert!((us[k] - xs[k] / 8.0 - shift).abs() < 1e-12, "face {t} crosses the seam");
        }
    }
}

/// Materials: faces keep theirs, and no flip crosses from one to the other.
#[test]
fn groups_and_materials_stay_on_their_faces() {
    let dir = tempfile::tempdir().unwrap();
    let grid = Grid::new(10, 4);
    let input = write(
        dir.path(),
        "grid.obj",
        &grid.obj(|p, _| [p.x / 8.0, p.y / 16.0], true, false, true),
    );
    let out = dir.path().join("out.obj");
    let printout = run(&input, &out, &[]);
    assert!(work(&printout).2 > 0, "{printout}");
    check(&input, &out);
    let (a, b) = (read(&input), read(&out));
    let material = |m: &InputMesh, t: usize| {
        let g = m.attributes.face_group[t] as usize;
        m.attributes.groups[g].material.clone().unwrap()
    };
    let scale = 20.0;
    let mut seen = std::collections::BTreeSet::new();
    for t in 0..b.triangles.len() {
        let centroid = b.triangles[t].iter().map(|&v| b.positions[v as usize]).sum::<DVec3>() / 3.0;
        let (s, _) = locate(&a, centroid, scale).unwrap();
        assert_eq!(material(&b, t), material(&a, s), "output face {t}");
        seen.insert(material(&b, t));
        assert_eq!(
            b.attributes.groups[b.attributes.face_group[t] as usize]
                .object
                .as_deref(),
            Some("grid")
        );
    }
    assert_eq!(seen.len(), 2);
    let worst = compare(&a, &b, 1000, 10);
    assert!(worst.iter().all(|&d| d <= 1e-9), "{worst:?}");
}

/// Smoothing groups (`s`), which decide a renderer's shading where a file
/// has no normals, are kept like materials: each output face has the one
/// of the input face it lies in, no flip crosses from one to another (the
/// same construction as with two materials in their place), and the output
/// says them where they change. A PLY output cannot hold them: a note says
/// so, and they cost nothing.
#[test]
fn smoothing_groups_stay_on_their_faces() {
    let dir = tempfile::tempdir().unwrap();
    let grid = Grid::new(10, 4);
    let with_materials = grid.obj(|p, _| [p.x / 8.0, p.y / 16.0], true, false, true);
    let with_smoothing = with_materials
        .replace("usemtl left", "s 1")
        .replace("usemtl right", "s off");
    assert_ne!(with_smoothing, with_materials);
    let materials = write(dir.path(), "materials.obj", &with_materials);
    let input = write(dir.path(), "grid.obj", &with_smoothing);
    let out = dir.path().join("out.obj");
    let printout = run(&input, &out, &[]);
    assert!(
        printout.contains("attributes: texture coordinates, normals, 2 groups/materials/smoothing groups, mtllib"),
        "{printout}"
    );
    assert!(work(&printout).2 > 0, "{printout}");
    assert_eq!(work(&printout), work(&run(&materials, &dir.path().join("m.obj"), &[])));
    check(&input, &out);
    let written = std::fs::read_to_string(&out).unwrap();
    let statements: Vec<&str> = written.lines().filter(|l| l.starts_with("s ")).collect();
    assert_eq!(
        statements,
        ["s 1", "s off"],
        "each group's faces together, under one line"
    );
    let (a, b) = (read(&input), read(&out));
    let smoothing = |m: &InputMesh, t: usize| {
        let g = m.attributes.face_group[t] as usize;
        m.attributes.groups[g].smoothing.clone().unwrap()
    };
    let mut seen = std::collections::BTreeSet::new();
    for t in 0..b.triangles.len() {
        let centroid = b.triangles[t].iter().map(|&v| b.positions[v as usize]).sum::<DVec3>() / 3.0;
        let (s, _) = locate(&a, centroid, 20.0).unwrap();
        assert_eq!(smoothing(&b, t), smoothing(&a, s), "output face {t}");
        seen.insert(smoothing(&b, t));
    }
    assert_eq!(seen.len(), 2);
    // PLY: left out before the construction, with a note.
    let ply = dir.path().join("out.ply");
    let printout = run(&input, &ply, &[]);
    assert!(
        printout.contains("note    groups, materials and smoothing groups left out: PLY cannot hold them"),
        "{printout}"
    );
    let without = write(
        dir.path(),
        "without.obj",
        &with_smoothing.replace("s 1\n", "").replace("s off\n", ""),
    );
    assert_eq!(work(&printout), work(&run(&without, &dir.path().join("w.ply"), &[])));
    check(&input, &ply);
}

/// The bunny with a spherical texture map written per corner (a seam where
/// the longitude wraps): the same mesh comes out as without attributes
/// (its faces are not coplanar), with the same mapping.
#[test]
fn bunny_with_a_spherical_map() {
    let dir = tempfile::tempdir().unwrap();
    let plain_input = common::data_dir().join("bunny.obj");
    let m = read(&plain_input);
    let center = m.positions.iter().sum::<DVec3>() / m.positions.len() as f64;
    let sphere = |p: DVec3| {
        let d = p - center;
        let u = d.z.atan2(d.x) / std::f64::consts::TAU + 0.5;
        [u, (d.y / d.length()).acos() / std::f64::consts::PI]
    };
    let mut text = String::new();
    for p in &m.positions {
        writeln!(text, "v {} {} {}", num(p.x), num(p.y), num(p.z)).unwrap();
    }
    for t in &m.triangles {
        let mut uv = t.map(|v| sphere(m.positions[v as usize]));
        let us = uv.map(|x| x[0]);
        if us.iter().copied().fold(f64::MIN, f64::max) - us.iter().copied().fold(f64::MAX, f64::min) > 0.5 {
            for x in &mut uv {
                if x[0] < 0.5 {
                    x[0] += 1.0;
                }
            }
        }
        for [u, v] in uv {
            writeln!(text, "vt {} {}", num(u), num(v)).unwrap();
        }
        writeln!(text, "f {}/-3 {}/-2 {}/-1", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
    let input = write(dir.path(), "bunny-uv.obj", &text);
    let out = dir.path().join("out.obj");
    let printout = run(&input, &out, &[]);
    assert_eq!(work(&printout).0, 315, "{printout}");
    check(&input, &out);
    let (a, b) = (read(&input), read(&out));
    let worst = compare(&a, &b, 1000, 11);
    assert!(worst[0] <= 1e-9, "{worst:?}");
    // Without attributes: byte for byte what the plain bunny gives.
    let (dropped, plain) = (dir.path().join("dropped.obj"), dir.path().join("plain.obj"));
    run(&input, &dropped, &["--drop-attributes"]);
    run(&plain_input, &plain, &[]);
    assert_eq!(std::fs::read(&dropped).unwrap(), std::fs::read(&plain).unwrap());
}

/// Meshes without attributes come out as before: data/bunny.obj gets its
/// 315 vertices, and only `v` and `f` lines are written.
#[test]
fn no_attributes_no_change() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::data_dir().join("bunny.obj");
    let out = dir.path().join("out.obj");
    let printout = run(&input, &out, &[]);
    assert_eq!(work(&printout), (315, 315, 0), "{printout}");
    assert!(!printout.contains("attributes"), "{printout}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.lines().all(|l| l.starts_with("v ") || l.starts_with("f ")));
}

/// A PLY grid with per-vertex texture coordinates, normals and colours, and
/// a seam made by duplicate vertices: written as PLY and OFF (copies of
/// seam vertices) and as OBJ, read back with the same fields.
#[test]
fn ply_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let grid = Grid::new(10, 5);
    // Right-half faces use copies of the vertices on the seam column.
    let n = grid.positions.len();
    let seam: Vec<usize> = (0..n).filter(|&v| (grid.positions[v].x - 5.0).abs() < 1e-12).collect();
    let mut vertices: Vec<(DVec3, bool)> = grid.positions.iter().map(|&p| (p, p.x > 5.0)).collect();
    let mut copy = vec![u32::MAX; n];
    for &v in &seam {
        copy[v] = vertices.len() as u32;
        vertices.push((grid.positions[v], true));
    }
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         property double s\nproperty double t\nproperty float nx\nproperty float ny\nproperty float nz\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        grid.triangles.len()
    );
    for (p, right) in &vertices {
        let s = p.x / 8.0 + if *right { 0.5 } else { 0.0 };
        let (r, g) = ((p.x * 16.0).round(), (p.y * 16.0).round());
        writeln!(
            text,
            "{} {} {} {} {} 0 0 1 {r} {g} 7",
            num(p.x),
            num(p.y),
            num(p.z),
            num(s),
            num(p.y / 16.0)
        )
        .unwrap();
    }
    for (t, tri) in grid.triangles.iter().enumerate() {
        let right = grid.right(t);
        let ids = tri.map(|v| {
            if right && copy[v as usize] != u32::MAX {
                copy[v as usize]
            } else {
                v
            }
        });
        writeln!(text, "3 {} {} {}", ids[0], ids[1], ids[2]).unwrap();
    }
    let input = write(dir.path(), "grid.ply", &text);
    let a = read(&input);
    assert!(a.attributes.texcoords.is_some() && a.attributes.normals.is_some() && a.attributes.colors.is_some());
    for ext in ["ply", "obj", "off"] {
        let out = dir.path().join(format!("out.{ext}"));
        let printout = run(&input, &out, &[]);
        assert!(work(&printout).2 > 0, "{printout}");
        check(&input, &out);
        let b = read(&out);
        let worst = compare(&a, &b, 1000, 12);
        assert!(worst[0] <= 1e-9 && worst[1] <= 1e-9, "{ext}: {worst:?}");
        // Colours are written to PLY and OFF with 8 bits: rounded at added
        // vertices.
        let colour_tolerance = if ext == "obj" { 1e-9 } else { 0.5 / 255.0 + 1e-12 };
        assert!(worst[2] <= colour_tolerance, "{ext}: {worst:?}");
    }
    // The PLY output holds the seam as copies of vertices, after the others.
    let b = read(&dir.path().join("out.ply"));
    let out_ply = std::fs::read(dir.path().join("out.ply")).unwrap();
    let header = String::from_utf8_lossy(&out_ply[..400]);
    assert!(header.contains("property double s\nproperty double t\n"), "{header}");
    assert!(header.contains("property uchar red"), "{header}");
    assert!(b.welded >= seam.len(), "{} welded", b.welded);
}

/// `--repair` carries attributes (once it dropped them, with a note); OFF
/// output leaves out what it cannot hold (groups and materials; it keeps
/// the texture coordinates), and says so.
#[test]
fn attributes_kept_by_repair_and_dropped_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let grid = Grid::new(4, 6);
    let input = write(
        dir.path(),
        "grid.obj",
        &grid.obj(|p, _| [p.x / 8.0, p.y / 16.0], false, false, false),
    );
    let printout = run(&input, &dir.path().join("r.obj"), &["--repair"]);
    assert!(!printout.contains("dropped"), "{printout}");
    let repaired = read(&dir.path().join("r.obj"));
    assert!(repaired.attributes.texcoords.is_some() && !repaired.attributes.face_group.is_empty());
    let printout = run(&input, &dir.path().join("o.off"), &[]);
    assert!(
        printout.contains("note    groups and materials left out: OFF cannot hold them"),
        "{printout}"
    );
    assert!(read(&dir.path().join("o.off")).attributes.texcoords.is_some());
    // A bad texture index drops texture coordinates, not the mesh.
    let bad = write(
        dir.path(),
        "bad.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/9 3/1\n",
    );
    let printout = run(&bad, &dir.path().join("bad-out.obj"), &[]);
    assert!(printout.contains("note    texture coordinates dropped"), "{printout}");
}

/// `--prune` removes and re-adds vertices after the construction: the
/// mapping must survive it too (non-affine texture and a seam).
#[test]
fn texture_kept_through_prune() {
    let dir = tempfile::tempdir().unwrap();
    let grid = Grid::new(12, 5);
    let uv = |p: DVec3, right: bool| {
        [
            p.x * p.x / 64.0 + if right { 0.5 } else { 0.0 },
            p.y / 8.0 + p.x * p.y / 128.0,
        ]
    };
    let input = write(dir.path(), "grid.obj", &grid.obj(uv, true, true, false));
    for extra in [&["--prune"][..], &["--prune", "-s", "3", "-ds", "queue"][..]] {
        let out = dir.path().join("out.obj");
        let printout = run(&input, &out, extra);
        assert!(printout.contains("prune   removed"), "{printout}");
        check(&input, &out);
        let (a, b) = (read(&input), read(&out));
        let worst = compare(&a, &b, 1000, 10);
        assert!(worst.iter().all(|&w| w <= 1e-9), "{extra:?}: {worst:?}\n{printout}");
    }
}

/// A flat oval polygon fanned from one corner (thin, non-Delaunay
/// triangles) on a box, with texture coordinates projected from the
/// positions and written with six decimals, as Blender writes them: affine
/// only to about 1e-7. Within the default `--attribute-tolerance` the
/// polygon is flipped as a whole, as without attributes (no vertex added),
/// and the mapping moves by no more than the note says; with 0 it stays
/// exact and the fan is split instead.
#[test]
fn rounded_texture_on_a_fanned_polygon_is_flipped_within_the_tolerance() {
    let dir = tempfile::tempdir().unwrap();
    let n = 40;
    let mut obj = String::from("# oval prism, caps fanned from one corner\n");
    for z in [0.0, 1.0] {
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            writeln!(obj, "v {} {} {z}", 3.0 * a.cos(), a.sin()).unwrap();
        }
    }
    // Caps: planar projection (u, v) = (x/6 + 0.5, y/2 + 0.5), rounded.
    for z in 0..2 {
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            writeln!(
                obj,
                "vt {:.6} {:.6}",
                a.cos() / 2.0 + 0.5,
                a.sin() / 2.0 + 0.5 + z as f64
            )
            .unwrap();
        }
    }
    let (v, cap) = (
        |i: usize, z: usize| z * n + i % n + 1,
        |i: usize, z: usize| z * n + i % n + 1,
    );
    for i in 1..n - 1 {
        writeln!(
            obj,
            "f {}/{} {}/{} {}/{}",
            v(0, 0),
            cap(0, 0),
            v(i + 1, 0),
            cap(i + 1, 0),
            v(i, 0),
            cap(i, 0)
        )
        .unwrap();
        writeln!(
            obj,
            "f {}/{} {}/{} {}/{}",
            v(0, 1),
            cap(0, 1),
            v(i, 1),
            cap(i, 1),
            v(i + 1, 1),
            cap(i + 1, 1)
        )
        .unwrap();
    }
    // The sides: texture coordinates of their own (a seam along the rim).
    for i in 0..=n {
        writeln!(
            obj,
            "vt {:.6} 2.5\nvt {:.6} 3",
            i as f64 / n as f64,
            i as f64 / n as f64
        )
        .unwrap();
    }
    let side = |i: usize, top: usize| 2 * n + 2 * i + top + 1;
    for i in 0..n {
        let (a, b, c, d) = (v(i, 0), v(i + 1, 0), v(i + 1, 1), v(i, 1));
        let (ta, tb, tc, td) = (side(i, 0), side(i + 1, 0), side(i + 1, 1), side(i, 1));
        writeln!(obj, "f {a}/{ta} {b}/{tb} {c}/{tc}\nf {a}/{ta} {c}/{tc} {d}/{td}").unwrap();
    }
    let input = write(dir.path(), "oval.obj", &obj);
    let a = read(&input);

    let out = dir.path().join("out.obj");
    let printout = run(&input, &out, &[]);
    let plain = run(&input, &dir.path().join("plain.obj"), &["--drop-attributes"]);
    assert_eq!(work(&printout), work(&plain), "{printout}\n{plain}");
    assert!(work(&printout).0 == 0 && work(&printout).2 > 0, "{printout}");
    let note = printout
        .lines()
        .find(|l| l.contains("flipped as a whole"))
        .unwrap_or_else(|| panic!("no note: {printout}"));
    assert!(note.contains("2 flat regions (76 faces)"), "{note}");
    assert!(note.ends_with("(--attribute-tolerance 0 keeps them exact)"), "{note}");
    let bound: f64 = note
        .split("move by up to ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("{note}"));
    assert!(bound > 1e-9 && bound < 1e-5, "{note}");
    check(&input, &out);
    let worst = compare(&a, &read(&out), 1000, 11);
    assert!(worst[0] > 1e-9 && worst[0] <= bound, "{worst:?} against {note}");

    let exact = dir.path().join("exact.obj");
    let printout = run(&input, &exact, &["--attribute-tolerance", "0"]);
    // Every inner edge of the two fans (2 × 37) kept from flipping, and the
    // growth note says so.
    assert!(
        work(&printout).1 > 1000 && !printout.contains("flipped as a whole"),
        "{printout}"
    );
    assert!(
        printout.contains("74 flat input edge(s) are never flipped"),
        "{printout}"
    );
    check(&input, &exact);
    let worst = compare(&a, &read(&exact), 1000, 12);
    assert!(worst[0] <= 1e-9, "{worst:?}");
}

/// The note on regions flipped within the tolerance said that
/// `--attribute-tolerance 0` keeps their values exact; but a polygon of the
/// file is flipped inside at any tolerance, so on a cylinder whose textured
/// caps are 64-gons, as Blender writes them, 0 changed nothing but the note
/// (the same flips, its values following the new triangles). The note now
/// says so, and promises exactness only outside the file's polygons.
#[test]
fn the_tolerance_note_does_not_promise_exactness_inside_polygons() {
    let dir = tempfile::tempdir().unwrap();
    let n = 64;
    // An oval prism; its caps' texture coordinates a planar projection
    // written with six decimals (affine to about 1e-7 only). `fan_bottom`
    // writes the bottom cap as the triangles of a fan, the top always as a
    // 64-gon.
    let prism = |fan_bottom: bool| {
        let mut obj = String::new();
        for z in [0.0, 1.0] {
            for i in 0..n {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                let (x, y) = (3.0 * a.cos(), a.sin());
                writeln!(
                    obj,
                    "v {x:.6} {y:.6} {z}\nvt {:.6} {:.6}",
                    x / 6.0 + 0.5,
                    y / 2.0 + 0.5 + z
                )
                .unwrap();
            }
        }
        let c = |i: usize, z: usize| format!("{0}/{0}", z * n + i % n + 1);
        if fan_bottom {
            for i in 1..n - 1 {
                writeln!(obj, "f {} {} {}", c(0, 0), c(i + 1, 0), c(i, 0)).unwrap();
            }
        } else {
            let corners: Vec<String> = (0..n).rev().map(|i| c(i, 0)).collect();
            writeln!(obj, "f {}", corners.join(" ")).unwrap();
        }
        let corners: Vec<String> = (0..n).map(|i| c(i, 1)).collect();
        writeln!(obj, "f {}", corners.join(" ")).unwrap();
        // The sides, without texture coordinates.
        for i in 0..n {
            let (a, b) = (i + 1, (i + 1) % n + 1);
            writeln!(obj, "f {a} {b} {} {}", b + n, a + n).unwrap();
        }
        obj
    };
    let note_of = |printout: &str| -> String {
        printout
            .lines()
            .find(|l| l.contains("flipped as a whole"))
            .unwrap_or_else(|| panic!("no note: {printout}"))
            .to_string()
    };

    // Runs the prism; the default's output adds nothing and passes check,
    // and its note ends with `ending`. Returns the input's path and the printout.
    let with_note = |name: &str, fan_bottom: bool, ending: &str| {
        let input = write(dir.path(), &format!("{name}.obj"), &prism(fan_bottom));
        let out = dir.path().join(format!("{name}.out.obj"));
        let printout = run(&input, &out, &[]);
        assert_eq!(work(&printout).0, 0, "{printout}");
        let note = note_of(&printout);
        assert!(
            note.contains("2 flat regions (124 faces)") && note.ends_with(ending),
            "{note}"
        );
        check(&input, &out);
        (input, printout)
    };

    // Both caps 64-gons: 0 keeps nothing exact there.
    let (input, printout) = with_note(
        "polygons",
        false,
        "(polygons of the file, flipped inside at any --attribute-tolerance: the corners keep their values)",
    );
    let exact = run(&input, &dir.path().join("exact.obj"), &["--attribute-tolerance", "0"]);
    assert_eq!(work(&exact), work(&printout), "{exact}\n{printout}");
    assert!(
        exact.contains("2 polygon(s) of the file (124 triangles) may be flipped inside"),
        "{exact}"
    );

    // The bottom cap a fan of triangles of the file: 0 keeps that one exact
    // (by splitting its fan), not the top.
    let (input, _) = with_note(
        "mixed",
        true,
        "(--attribute-tolerance 0 keeps them exact but inside polygons of the file, whose corners keep their values)",
    );
    let exact = run(
        &input,
        &dir.path().join("mixed.exact.obj"),
        &["--attribute-tolerance", "0"],
    );
    assert!(work(&exact).0 > 100, "{exact}");
    assert!(
        exact.contains("1 polygon(s) of the file (62 triangles) may be flipped inside"),
        "{exact}"
    );
}

/// The tolerance is relative to each object's own values: a floor tiled
/// with texture coordinates up to 100 beside a small flat cap does not let
/// the cap's texture move a hundred times further than it would alone.
#[test]
fn one_objects_large_values_do_not_loosen_anothers_tolerance() {
    let dir = tempfile::tempdir().unwrap();
    // An oval cap fanned from one rim vertex, its texture coordinates off
    // an affine map by up to 3e-4 (a wobble, not rounding).
    let n = 24;
    let mut cap = String::from("o cap\n");
    for i in 0..n {
        let a = std::f64::consts::TAU * i as f64 / n as f64;
        let (x, y) = (2.0 * a.cos(), a.sin());
        writeln!(
            cap,
            "v {x} {y} 1\nvt {} {}",
            x / 4.0 + 0.5 + 3e-4 * (3.0 * x).sin(),
            y / 2.0 + 0.5
        )
        .unwrap();
    }
    for i in 2..n {
        writeln!(cap, "f 1/1 {i}/{i} {}/{}", i + 1, i + 1).unwrap();
    }
    // A separate floor, texture coordinates 0..100 (exactly affine).
    let mut floor = String::from("o floor\n");
    for (x, y) in [(-10, -10), (10, -10), (10, 10), (-10, 10)] {
        writeln!(floor, "v {x} {y} 0\nvt {} {}", 5 * (x + 10), 5 * (y + 10)).unwrap();
    }
    let m = n + 1;
    writeln!(floor, "f {m}/{m} {}/{} {}/{}", m + 1, m + 1, m + 2, m + 2).unwrap();
    writeln!(floor, "f {m}/{m} {}/{} {}/{}", m + 2, m + 2, m + 3, m + 3).unwrap();
    let alone = write(dir.path(), "cap.obj", &cap);
    let both = write(dir.path(), "both.obj", &(cap + &floor));
    let printout = run(&alone, &dir.path().join("cap.out.obj"), &[]);
    let with_floor = run(&both, &dir.path().join("both.out.obj"), &[]);
    assert!(work(&printout).0 > 0, "{printout}");
    assert_eq!(work(&printout), work(&with_floor), "{printout}\n{with_floor}");
    assert!(!with_floor.contains("flipped as a whole"), "{with_floor}");
    check(&both, &dir.path().join("both.out.obj"));
    // Tolerance 1e-3 lets the cap alone be flipped as a whole: the wobble
    // is what the default keeps exact.
    let loose = run(
        &alone,
        &dir.path().join("loose.obj"),
        &["--attribute-tolerance", "texcoords=1e-3"],
    );
    assert_eq!(work(&loose).0, 0, "{loose}");
    assert!(
        loose.contains("1 flat region (22 faces) may be flipped as a whole"),
        "{loose}"
    );
}

/// Faces without texture coordinates and normals (an object exported
/// without them) keep none, and the others keep theirs: the channel is not
/// dropped for the whole file. The two kinds of faces stay apart where they
/// meet in one plane, the fields are the same before and after on both,
/// and PLY, which stores values per vertex, leaves such channels out with
/// a note.
#[test]
fn faces_without_values_keep_none_and_the_others_keep_theirs() {
    let dir = tempfile::tempdir().unwrap();
    let grid = Grid::new(12, 5);
    // Not affine (so the textured half is split rather than flipped).
    let text = grid.obj(|p, _| [p.x * p.x / 64.0, p.y / 16.0], true, false, false);
    let mut obj = String::new();
    let mut t = 0;
    for line in text.lines() {
        if let Some(corners) = line.strip_prefix("f ") {
            if grid.right(t) {
                let plain: Vec<&str> = corners.split(' ').map(|c| c.split('/').next().unwrap()).collect();
                writeln!(obj, "f {}", plain.join(" ")).unwrap();
            } else {
                writeln!(obj, "{line}").unwrap();
            }
            t += 1;
        } else {
            writeln!(obj, "{line}").unwrap();
        }
    }
    let input = write(dir.path(), "half.obj", &obj);
    let out = dir.path().join("out.obj");
    let printout = run(&input, &out, &[]);
    let n = grid.triangles.len();
    let with = (0..n).filter(|&t| !grid.right(t)).count();
    let line = format!("texture coordinates (on {with} of {n} triangles), normals (on {with} of {n} triangles)");
    assert!(printout.contains(&line), "{printout}");
    assert!(!printout.contains("dropped"), "{printout}");
    assert!(work(&printout).1 > 0, "{printout}");
    check(&input, &out);
    let (a, b) = (read(&input), read(&out));
    let textured = |m: &InputMesh| {
        let ch = m.attributes.texcoords.as_ref().expect("texture coordinates kept");
        (0..m.triangles.len()).filter(|&t| !ch.corner(3 * t).is_empty()).count()
    };
    assert!(textured(&b) >= textured(&a) && textured(&b) < b.triangles.len());
    let worst = compare(&a, &b, 2000, 21);
    assert!(worst.iter().all(|&d| d <= 1e-9), "{worst:?}");
    // Faces without values are written without `/`.
    let written = std::fs::read_to_string(&out).unwrap();
    assert!(written.lines().any(|l| l.starts_with("f ") && !l.contains('/')));
    assert!(written.lines().any(|l| l.starts_with("f ") && l.contains('/')));
    // PLY has no "none" per vertex: both channels are left out, before the
    // construction, which then runs as without them.
    let ply = dir.path().join("out.ply");
    let printout = run(&input, &ply, &[]);
    let plain = run(&input, &dir.path().join("plain.obj"), &["--drop-attributes"]);
    assert!(
        printout.contains(
            "texture coordinates of only some faces, normals of only some faces, groups and materials left out: PLY \
             cannot hold them"
        ),
        "{printout}"
    );
    assert_eq!(work(&printout), work(&plain));
    check(&input, &ply);
    assert!(read(&ply).attributes.texcoords.is_none());
}

/// Runs delmesh on `input` with `--attribute-tolerance=value`, which must
/// be refused as a usage error (exit 2); returns its standard error.
fn tolerance_refused(input: &Path, value: &str) -> String {
    let out = delmesh()
        .arg("-i")
        .arg(input)
        .args(["-o", "-", &format!("--attribute-tolerance={value}")])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{value}: {stderr}");
    stderr
}

/// `--attribute-tolerance` takes a number from 0 to 1, and refuses others
/// before reading anything.
#[test]
fn attribute_tolerance_is_a_relative_number() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(dir.path(), "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    for bad in ["-1", "2", "nan", "x"] {
        let stderr = tolerance_refused(&input, bad);
        assert!(stderr.contains("is not a relative tolerance"), "{bad}: {stderr}");
    }
    run(&input, &dir.path().join("o.obj"), &["--attribute-tolerance", "1e-3"]);
}

/// OBJ colours written in 0..255 (as some exporters do) are taken as such
/// when a PLY (bytes) is written, with a note: they were clamped to 255.
#[test]
fn obj_colours_in_bytes_are_written_to_ply_as_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(
        dir.path(),
        "c.obj",
        "v 0 0 0 0 128 255\nv 1 0 0 10 20 30\nv 0 1 0 200 100 0\nv 0 0 1 1 2 3\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
    );
    let out = dir.path().join("c.ply");
    let printout = run(&input, &out, &[]);
    assert!(
        printout.contains("note    colours above 1 taken as 0-255"),
        "{printout}"
    );
    let colors = read(&out).attributes.colors.expect("colours");
    let first: Vec<f64> = colors
        .value(colors.corners[0])
        .iter()
        .map(|x| (x * 255.0).round())
        .collect();
    assert_eq!(first, [0.0, 128.0, 255.0]);
    // In 0..1 they are scaled, without a note.
    let unit = write(
        dir.path(),
        "u.obj",
        "v 0 0 0 0 0.5 1\nv 1 0 0 0 0 0\nv 0 1 0 0 0 0\nv 0 0 1 0 0 0\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
    );
    let printout = run(&unit, &dir.path().join("u.ply"), &[]);
    assert!(!printout.contains("0-255"), "{printout}");
    let colors = read(&dir.path().join("u.ply")).attributes.colors.expect("colours");
    let first: Vec<f64> = colors
        .value(colors.corners[0])
        .iter()
        .map(|x| (x * 255.0).round())
        .collect();
    assert_eq!(first, [0.0, 128.0, 255.0]);
}

/// `--attribute-tolerance` also takes per-kind values (`texcoords=`,
/// `normals=`, `colors=`/`colours=`), the others keeping their defaults.
#[test]
fn attribute_tolerance_takes_values_per_kind() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::data_dir()
        .join("attributes")
        .join("ply_uchar_colour_flat_grid.ply");
    let added = |flags: &[&str]| work(&run(&input, &dir.path().join("o.ply"), flags)).0;
    // Colours as bytes (a sheared flat grid with an 8-bit gradient): affine
    // within half an 8-bit step, which the default colour tolerance accepts.
    assert_eq!(added(&[]), 0);
    check(&input, &dir.path().join("o.ply"));
    // Exact colours keep the regions apart: the grid's thin faces get split.
    assert!(added(&["--attribute-tolerance", "colors=0"]) > 0);
    assert!(added(&["--attribute-tolerance", "colours=1e-3,texcoords=1e-5"]) > 0);
    // The defaults spelled out; exact texture coordinates (stored as f32,
    // so affine only within rounding) split too.
    assert_eq!(
        added(&["--attribute-tolerance", "texcoords=1e-5,normals=1e-3,colors=4e-3"]),
        0
    );
    assert!(added(&["--attribute-tolerance", "texcoords=0"]) > 0);
    // The grid's seam makes PLY write copies of vertices: the printout says
    // how many records the file holds, as its header does.
    let printout = run(&input, &dir.path().join("o.ply"), &[]);
    let bytes = std::fs::read(dir.path().join("o.ply")).unwrap();
    let header = String::from_utf8_lossy(&bytes[..bytes.len().min(1000)]).into_owned();
    let records = header.lines().find_map(|l| l.strip_prefix("element vertex ")).unwrap();
    assert!(
        printout.contains(&format!("note    the file holds {records} vertex records: ")),
        "{records}: {printout}"
    );
    for bad in ["uv=1e-3", "colors=2", "colors=", "colors=1e-3,"] {
        tolerance_refused(&input, bad);
    }
}

/// A conversion (`--no-refine`) to a format that cannot hold the attributes
/// says they are left out, and not that the mesh is refined without them.
#[test]
fn left_out_note_of_a_conversion_does_not_speak_of_refining() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::data_dir()
        .join("attributes")
        .join("oval_cylinder_smooth_normals.obj");
    let stl = run(&input, &dir.path().join("o.stl"), &["--no-refine"]);
    assert!(
        stl.contains("note    normals, groups, materials and smoothing groups left out: STL cannot hold them\n"),
        "{stl}"
    );
    assert!(!stl.contains("refined as"), "{stl}");
}

/// What the output's format cannot hold (PLY and OFF: groups, materials
/// and smoothing groups) is left out before the construction, with a note, and costs
/// no split; what it holds costs what it costs in OBJ: a smooth-shaded oval
/// cylinder (normals averaged across the flat caps' rims, as Blender
/// writes them, on caps that are 64-gons) keeps its normals as OBJ, PLY and
/// OFF. They are not one affine field over the caps, but the file gives
/// them at the caps' corners only, so the caps are flipped inside (see
/// [`polygons_keep_their_corners_values_and_are_flipped_inside`]): no
/// vertex added, as without them.
#[test]
fn attributes_the_output_cannot_hold_cost_no_splits() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::data_dir()
        .join("attributes")
        .join("oval_cylinder_smooth_normals.obj");
    let obj = run(&input, &dir.path().join("o.obj"), &[]);
    assert_eq!(work(&obj).0, 0, "{obj}");
    let plain = run(&input, &dir.path().join("plain.off"), &["--drop-attributes"]);
    assert_eq!(work(&plain).0, 0, "{plain}");
    check(&input, &dir.path().join("plain.off"));
    // PLY and OFF keep the normals (so the splits) and leave out the groups.
    for format in ["PLY", "OFF"] {
        let out = dir.path().join(format!("o.{}", format.to_lowercase()));
        let printout = run(&input, &out, &[]);
        assert!(
            printout.contains(&format!(
                "note    groups, materials and smoothing groups left out: {format} cannot hold them"
            )),
            "{printout}"
        );
        assert!(!printout.contains("not written"), "{printout}");
        assert_eq!(work(&printout), work(&obj), "{printout}");
        check(&input, &out);
        assert_corners_keep_their_values(&read(&input), &read(&out), Kind::Normal);
    }
    // batch leaves them out the same way.
    let out_dir = dir.path().join("b");
    let batch = delmesh()
        .args(["batch", "--format", "off", "-d"])
        .arg(&out_dir)
        .arg(&input)
        .output()
        .unwrap();
    assert!(batch.status.success(), "{}", String::from_utf8_lossy(&batch.stderr));
    let off_batch = std::fs::read(out_dir.join("oval_cylinder_smooth_normals.off")).unwrap();
    assert_eq!(off_batch, std::fs::read(dir.path().join("o.off")).unwrap());
}

/// Every output corner at an input vertex has one of the values the
/// input gives that vertex's corners (bit for bit).
fn assert_corners_keep_their_values(input: &InputMesh, output: &InputMesh, kind: Kind) {
    let key = |m: &InputMesh, c: usize| {
        let p = m.positions[m.triangles[c / 3][c % 3] as usize]
            .to_array()
            .map(f64::to_bits);
        let ch = channel(m, kind).unwrap_or_else(|| panic!("no {}", kind.name()));
        (p, ch.corner(c).iter().map(|x| x.to_bits()).collect::<Vec<u64>>())
    };
    let given: std::collections::HashSet<_> = (0..3 * input.triangles.len()).map(|c| key(input, c)).collect();
    let at_input: std::collections::HashSet<_> = given.iter().map(|(p, _)| *p).collect();
    let mut seen = 0;
    for c in 0..3 * output.triangles.len() {
        let (p, value) = key(output, c);
        if at_input.contains(&p) {
            assert!(
                given.contains(&(p, value.clone())),
                "{p:?}: {value:?} is not given there"
            );
            seen += 1;
        }
    }
    assert!(seen > 0);
}

/// A polygon of the file is given values at its corners only: how they
/// spread inside depends on how it is cut into triangles, delmesh's choice,
/// so its diagonals are flipped even where its values are not one affine
/// field over it, with a note. The smooth-shaded oval cylinder's 64-gon
/// caps (normals averaged with the sides', so not affine over the caps)
/// then need no vertex, as without normals (21,256 before), and every
/// corner keeps a normal the file gives it. The same caps written as
/// triangles (fans) are the file's own triangles, kept by splitting.
#[test]
fn polygons_keep_their_corners_values_and_are_flipped_inside() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::data_dir()
        .join("attributes")
        .join("oval_cylinder_smooth_normals.obj");
    let out = dir.path().join("o.obj");
    let printout = run(&input, &out, &[]);
    let plain_out = dir.path().join("plain.obj");
    let plain = run(&input, &plain_out, &["--drop-attributes"]);
    assert_eq!(work(&printout), work(&plain), "{printout}\n{plain}");
    assert_eq!(work(&printout).0, 0, "{printout}");
    assert!(
        printout.contains("note    2 polygon(s) of the file (124 triangles) may be flipped inside"),
        "{printout}"
    );
    assert!(printout.contains("adds at least 0 vertices"), "{printout}");
    check(&input, &out);
    let (a, b) = (read(&input), read(&out));
    assert_eq!(b.triangles, read(&plain_out).triangles);
    assert_corners_keep_their_values(&a, &b, Kind::Normal);
    // The same mesh with its caps written as triangles, fanned from their
    // first corners as CAD exporters write them: each is a face of the
    // file, whose values are its own.
    let mut triangulated = String::new();
    for line in std::fs::read_to_string(&input).unwrap().lines() {
        let corners: Vec<&str> = line.split_whitespace().skip(1).collect();
        if line.starts_with("f ") && corners.len() > 4 {
            for i in 1..corners.len() - 1 {
                writeln!(triangulated, "f {} {} {}", corners[0], corners[i], corners[i + 1]).unwrap();
            }
        } else {
            writeln!(triangulated, "{line}").unwrap();
        }
    }
    let triangles = write(dir.path(), "triangles.obj", &triangulated);
    let printout = run(&triangles, &dir.path().join("t.obj"), &[]);
    assert!(
        work(&printout).0 > 1000 && !printout.contains("polygon(s)"),
        "{printout}"
    );
    assert!(printout.contains("flat input edge(s) are never flipped"), "{printout}");
    check(&triangles, &dir.path().join("t.obj"));
    let worst = compare(&read(&triangles), &read(&dir.path().join("t.obj")), 1000, 13);
    assert!(worst[1] <= 1e-9, "{worst:?}");
}

/// Texture coordinates near ±f64::MAX: a vertex added between -1.7e308
/// and 1.7e308 got `vt inf` (`a + t·(b − a)` overflows), which delmesh's
/// own reader then refuses. Now every output value is finite and between
/// its edge's ends, in OBJ and PLY.
#[test]
fn huge_texture_coordinates_interpolate_to_finite_values() {
    let dir = tempfile::tempdir().unwrap();
    // The crate example's folded rhombus: its long diagonal (1-2) is split.
    let input = write(
        dir.path(),
        "huge.obj",
        "v -2 0 0\nv 2 0 0\nv 0 0.5 0\nv 0 -0.4 0.3\n\
         vt -1.7e308 0.5\nvt 1.7e308 0.5\nvt 0 1\nvt 0 0\n\
         f 1/1 2/2 3/3\nf 2/2 1/1 4/4\n",
    );
    for ext in ["obj", "ply"] {
        let out = dir.path().join(format!("out.{ext}"));
        let printout = run(&input, &out, &[]);
        assert!(work(&printout).1 >= 1, "{printout}");
        check(&input, &out);
        let m = read(&out);
        let uv = channel(&m, Kind::TexCoord).expect("texture coordinates kept");
        assert!(m.positions.len() > 4);
        for (c, &v) in m.triangles.iter().flatten().enumerate() {
            let value = uv.corner(c);
            assert!(value.iter().all(|x| x.is_finite()), "{ext}: vertex {v}: {value:?}");
            assert!(value[0].abs() <= 1.7e308, "{ext}: {value:?}");
        }
    }
}

/// MeshLab's textured PLY: texture coordinates per face corner (`property
/// list uchar float texcoord`, with `texnumber`) and the image in `comment
/// TextureFile`. They were dropped without a word; now they are read as
/// per-corner values (a seam kept as in OBJ), carried like OBJ's, and the
/// `TextureFile` comment is written to a PLY output (an OBJ output says it
/// cannot keep it).
#[test]
fn meshlab_wedge_texture_coordinates_and_texture_file() {
    let dir = tempfile::tempdir().unwrap();
    let grid = Grid::new(8, 3);
    // An affine map, shifted by 0.5 on the right half: a seam down the middle.
    let uv = |p: DVec3, right: bool| [p.x / 8.0 + if right { 0.5 } else { 0.0 }, p.y / 8.0];
    let header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\ncomment TextureFile grid tex.png\nelement vertex {}\nproperty double x\n\
             property double y\nproperty double z\nelement face {}\nproperty list uchar int vertex_indices\n\
             property list uchar float texcoord\nproperty int texnumber\nend_header\n",
            grid.positions.len(),
            grid.triangles.len()
        )
    };
    // ASCII, with face 1's texnumber and face 0's list length given.
    let ascii_with = |texnumber_1: i32, values_0: usize| {
        let mut ascii = header("ascii");
        for p in &grid.positions {
            writeln!(ascii, "{} {} {}", num(p.x), num(p.y), num(p.z)).unwrap();
        }
        for (t, tri) in grid.triangles.iter().enumerate() {
            let corners = tri.map(|v| uv(grid.positions[v as usize], grid.right(t)).map(|x| x as f32));
            let values: Vec<f32> = corners.iter().flatten().copied().collect();
            let values = if t == 0 { &values[..values_0] } else { &values[..] };
            write!(ascii, "3 {} {} {} {}", tri[0], tri[1], tri[2], values.len()).unwrap();
            for x in values {
                // (As f64: f32's shortest text, such as 0.15039063, is not
                // the f32's exact value, and would round the field.)
                write!(ascii, " {}", f64::from(*x)).unwrap();
            }
            writeln!(ascii, " {}", if t == 1 { texnumber_1 } else { 0 }).unwrap();
        }
        ascii
    };
    let ascii = ascii_with(0, 6);
    let mut binary = header("binary_little_endian").into_bytes();
    for p in &grid.positions {
        for c in p.to_array() {
            binary.extend_from_slice(&c.to_le_bytes());
        }
    }
    for (t, tri) in grid.triangles.iter().enumerate() {
        // Values exact in f32 (multiples of 1/512 below 2).
        let corners = tri.map(|v| uv(grid.positions[v as usize], grid.right(t)).map(|x| x as f32));
        binary.push(3);
        for v in tri {
            binary.extend_from_slice(&(*v as i32).to_le_bytes());
        }
        binary.push(6);
        for x in corners.iter().flatten() {
            binary.extend_from_slice(&x.to_le_bytes());
        }
        binary.extend_from_slice(&0i32.to_le_bytes());
    }
    let binary_path = dir.path().join("binary.ply");
    std::fs::write(&binary_path, &binary).unwrap();
    for input in [write(dir.path(), "ascii.ply", &ascii), binary_path] {
        let a = read(&input);
        let uv_in = channel(&a, Kind::TexCoord).expect("wedge texture coordinates read");
        assert_eq!(a.attributes.texture_files, ["grid tex.png"]);
        // Per corner: the seam's vertices have two values.
        assert_eq!(uv_in.corners.len(), 3 * a.triangles.len());
        for ext in ["ply", "obj", "off"] {
            let out = dir.path().join(format!("out.{ext}"));
            let printout = run(&input, &out, &[]);
            assert!(printout.contains("attributes: texture coordinates"), "{printout}");
            assert!(work(&printout).2 > 0, "{printout}");
            check(&input, &out);
            let b = read(&out);
            let worst = compare(&a, &b, 1000, 5);
            assert!(worst[0] <= 1e-9, "{ext}: {worst:?} {printout}");
            let bytes = std::fs::read(&out).unwrap();
            let text = String::from_utf8_lossy(&bytes);
            let note = "texture file grid tex.png (PLY comment TextureFile) not written";
            if ext == "ply" {
                let end = text.find("end_header").unwrap();
                assert!(
                    text[..end].contains("\ncomment TextureFile grid tex.png\n"),
                    "{}",
                    &text[..end]
                );
                assert_eq!(b.attributes.texture_files, ["grid tex.png"]);
                assert!(!printout.contains(note), "{printout}");
            } else {
                assert!(printout.contains(note), "{printout}");
                if ext == "off" {
                    assert!(
                        printout.contains(&format!("{note}: OFF cannot name a texture")),
                        "{printout}"
                    );
                }
            }
        }
    }
    // Several textures (texnumber 0 and 1): dropped, with a note saying why.
    let two = write(dir.path(), "two.ply", &ascii_with(1, 6));
    let printout = run(&two, &dir.path().join("two-out.ply"), &[]);
    assert!(
        printout.contains(
            "texture coordinates of the faces (PLY face property texcoord) dropped: the faces use several textures"
        ),
        "{printout}"
    );
    // A list of the wrong length: dropped, with a note naming the face.
    let short = write(dir.path(), "short.ply", &ascii_with(0, 5));
    let printout = run(&short, &dir.path().join("short-out.ply"), &[]);
    assert!(
        printout.contains("face 0 has 5 texcoord values for its 3 corners"),
        "{printout}"
    );
}

/// `usemtl` (or `o`) without a name ends the material (object) before it;
/// the output says so too, rather than leaving the faces after it in the
/// previous material.
#[test]
fn a_material_ended_by_usemtl_alone_stays_ended() {
    let dir = tempfile::tempdir().unwrap();
    let text = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.5\nv 2 0 0.2\no A\nusemtl red\nf 1 2 3\nusemtl\nf 2 4 3\no\nf 2 5 4\n";
    let input = write(dir.path(), "m.obj", text);
    let out = dir.path().join("out.obj");
    run(&input, &out, &[]);
    let written = std::fs::read_to_string(&out).unwrap();
    let statements: Vec<&str> = written.lines().filter(|l| !l.starts_with("v ")).collect();
    assert_eq!(
        statements,
        [
            "mtllib m.mtl",
            "o A",
            "usemtl red",
            "f 1 2 3",
            "usemtl",
            "f 2 4 3",
            "o",
            "f 2 5 4"
        ]
    );
    let (a, b) = (read(&input), read(&out));
    assert_eq!(a.attributes.groups, b.attributes.groups);
    assert_eq!(a.attributes.face_group, b.attributes.face_group);
}

/// A PLY input's float colours are written back as floats (its vertices
/// keep them as the type holds them), and 16-bit ones as `ushort`; 8-bit
/// ones stay 8-bit.
#[test]
fn ply_colours_keep_their_declared_type() {
    let dir = tempfile::tempdir().unwrap();
    let ply = |ty: &str, values: [[f64; 3]; 4]| {
        let mut text = format!(
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
             property {ty} red\nproperty {ty} green\nproperty {ty} blue\nelement face 2\n\
             property list uchar int vertex_indices\nend_header\n"
        );
        // Two thin faces folded along a long edge, which gets split.
        let positions = [[0.0, 0.0, 0.0], [8.0, 0.0, 0.0], [4.0, 0.5, 0.05], [4.0, -0.5, 0.05]];
        for (p, c) in positions.iter().zip(values) {
            writeln!(text, "{} {} {} {} {} {}", p[0], p[1], p[2], c[0], c[1], c[2]).unwrap();
        }
        text.push_str("3 0 1 2\n3 1 0 3\n");
        write(dir.path(), &format!("{ty}.ply"), &text)
    };
    let floats = [
        [0.1, 0.2, 0.3],
        [0.7, 0.123456, 0.9],
        [0.01, 0.5, 0.333],
        [1.0, 0.0, 0.25],
    ];
    let shorts = [
        [1.0, 2.0, 3.0],
        [65535.0, 0.0, 300.0],
        [7.0, 40000.0, 9.0],
        [0.0, 0.0, 0.0],
    ];
    for (ty, values, written) in [
        ("float", floats, "property float red\n"),
        ("ushort", shorts, "property ushort red\n"),
        (
            "uchar",
            [
                [10.0, 20.0, 30.0],
                [200.0, 0.0, 7.0],
                [1.0, 2.0, 3.0],
                [50.0, 60.0, 70.0],
            ],
            "property uchar red\n",
        ),
    ] {
        let input = ply(ty, values);
        let out = dir.path().join(format!("{ty}-out.ply"));
        let printout = run(&input, &out, &[]);
        assert!(work(&printout).1 > 0, "{printout}");
        check(&input, &out);
        let bytes = std::fs::read(&out).unwrap();
        let header = String::from_utf8_lossy(&bytes[..300]).into_owned();
        assert!(header.contains(written), "{ty}: {header}");
        let (a, b) = (read(&input), read(&out));
        // Input vertices keep their colours exactly; added ones are within
        // the type's step of the interpolated field.
        let step = match ty {
            "float" => 1e-7,
            "ushort" => 0.5 / 65535.0 + 1e-12,
            _ => 0.5 / 255.0 + 1e-12,
        };
        let colours = |m: &InputMesh| channel(m, Kind::Color).unwrap().clone();
        let (ca, cb) = (colours(&a), colours(&b));
        for (c, t) in b.triangles.iter().flatten().enumerate() {
            if let Some(v) = a.positions.iter().position(|&p| p == b.positions[*t as usize]) {
                let corner = a.triangles.iter().flatten().position(|&w| w as usize == v).unwrap();
                // (An ASCII `float` is read as written, and written as a float.)
                let expected: Vec<f64> = ca.corner(corner).iter().map(|&x| x as f32 as f64).collect();
                let expected = if ty == "float" {
                    expected
                } else {
                    ca.corner(corner).to_vec()
                };
                assert_eq!(cb.corner(c), expected, "{ty}: vertex {v}");
            }
        }
        let worst = compare(&a, &b, 500, 3);
        assert!(worst[2] <= step, "{ty}: {worst:?}");
    }
}

/// `--repair` carries texture coordinates through what it changes: faces it
/// reorients keep each corner's value at its own corner, and the faces it
/// cuts off a non-manifold edge keep theirs. The texture here is affine in
/// x and y (u = x/6, v = y/6) on a sheared, bumpy height field, with every fifth
/// face written the wrong way round and a fin on an interior edge: every
/// output corner, also at the vertices refining adds, must have the value
/// of its position, in OBJ and in PLY (whose copies at seams come back as
/// corners).
#[test]
fn repair_keeps_each_corners_texture_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let n = 6;
    let mut text = String::new();
    let vertex = |text: &mut String, x: f64, y: f64, z: f64| {
        text.push_str(&format!("v {x:?} {y:?} {z:?}\nvt {:?} {:?}\n", x / 6.0, y / 6.0));
    };
    for j in 0..=n {
        for i in 0..=n {
            let z = 2.0 * (((i * 7 + j * 3) % 5) as f64) / 5.0;
            // (Sheared: obtuse triangles, which refining must split or flip.)
            vertex(&mut text, i as f64 + 0.8 * j as f64, j as f64, z);
        }
    }
    // The fin's apex, above the middle of the interior edge (2,2)-(3,2).
    vertex(&mut text, 4.1, 2.0, 3.0);
    let id = |i: usize, j: usize| j * (n + 1) + i + 1;
    let mut face = 0;
    for j in 0..n {
        for i in 0..n {
            for t in [
                [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
            ] {
                face += 1;
                let t = if face % 5 == 0 { [t[0], t[2], t[1]] } else { t };
                text.push_str(&format!("f {0}/{0} {1}/{1} {2}/{2}\n", t[0], t[1], t[2]));
            }
        }
    }
    let apex = (n + 1) * (n + 1) + 1;
    text.push_str(&format!("f {0}/{0} {1}/{1} {2}/{2}\n", id(2, 2), id(3, 2), apex));
    let input = write(dir.path(), "bumpy.obj", &text);
    for ext in ["obj", "ply"] {
        let out = dir.path().join(format!("out.{ext}"));
        let printout = run(&input, &out, &["--repair", "--check"]);
        assert!(
            printout.contains("reoriented") && printout.contains("non-manifold edge"),
            "{printout}"
        );
        assert!(!printout.contains("dropped"), "{printout}");
        let output = read(&out);
        assert!(
            output.positions.len() > (n + 1) * (n + 1) + 1,
            "{ext}: nothing added: {printout}"
        );
        let texcoords = output.attributes.texcoords.as_ref().expect("texture coordinates");
        for (t, tri) in output.triangles.iter().enumerate() {
            for (k, &v) in tri.iter().enumerate() {
                let p = output.positions[v as usize];
                let uv = texcoords.corner(3 * t + k);
                assert!(
                    (uv[0] - p.x / 6.0).abs() < 1e-9 && (uv[1] - p.y / 6.0).abs() < 1e-9,
                    "{ext}: triangle {t} corner {k} at {p:?} has {uv:?}"
                );
            }
        }
    }
}

/// A face `--repair` drops takes its group with it: the output's groups are
/// those of the faces kept, and a mesh whose kept faces are all outside any
/// group is written without `g` or `usemtl` at all, as it would be read.
#[test]
fn repair_keeps_the_groups_of_the_faces_it_keeps() {
    let dir = tempfile::tempdir().unwrap();
    let square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.1\n";
    for (name, text, expected) in [
        // The duplicate, the only face of group b, goes.
        (
            "named.obj",
            format!("{square}g a\nf 1 2 3\nf 1 3 4\ng b\nf 1 2 3\n"),
            vec![Some("a")],
        ),
        // The duplicate, the only face in a group, goes: no group is left.
        (
            "none.obj",
            format!("{square}f 1 2 3\nf 1 3 4\ng b\nusemtl red\nf 1 2 3\n"),
            vec![],
        ),
    ] {
        let input = write(dir.path(), name, &text);
        let out = dir.path().join(format!("out-{name}"));
        let printout = run(&input, &out, &["--repair"]);
        assert!(printout.contains("duplicate face"), "{name}: {printout}");
        let written = std::fs::read_to_string(&out).unwrap();
        // As read with repair (what refining carries) and as written.
        let repaired = io::read_mesh(
            &input,
            &ReadOptions {
                repair: Some(RepairOptions::default()),
                ..Default::default()
            },
        )
        .unwrap();
        for (mesh, what) in [(repaired, "read"), (read(&out), "written")] {
            let groups: Vec<Option<&str>> = mesh.attributes.groups.iter().map(|g| g.group.as_deref()).collect();
            assert_eq!(groups, expected, "{name}, {what}: {written}");
            assert_eq!(
                mesh.attributes.face_group.is_empty(),
                expected.is_empty(),
                "{name}, {what}"
            );
        }
        assert!(
            !written.contains("g b") && !written.contains("usemtl"),
            "{name}: {written}"
        );
    }
}

/// A texture seam on an edge `--repair` cuts: three faces on one edge, the
/// middle one's texture coordinates (or colours) differing from the other
/// two's there. A PLY output gives its corners copies of the edge's
/// vertices (an OBJ output too, for colours), which `check` (seeing three
/// open file edges on one welded edge) must join to one of the two faces
/// running the other way, not keep apart.
#[test]
fn a_seam_on_an_edge_repair_cuts_passes_check() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(
        dir.path(),
        "fin.obj",
        "v 0 0 0\nv 1 0 0\nv 0.5 1 0\nv 0.5 -1 0\nv 0.5 0 1\n\
         vt 0 0\nvt 1 0\nvt 0.5 1\nvt 0 0.5\nvt 1 0.5\nvt 0.5 -1\nvt 0.5 2\n\
         f 2/1 1/2 3/3\nf 1/4 2/5 4/6\nf 2/1 1/2 5/7\n",
    );
    // The same with vertex colours, which an OBJ output copies too: the middle face's ends
    // are green copies that repair welds to the red ones.
    let colours = write(
        dir.path(),
        "colours.obj",
        "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 0.5 1 0 1 0 0\nv 0.5 -1 0 0 1 0\nv 0.5 0 1 1 0 0\n\
         v 0 0 0 0 1 0\nv 1 0 0 0 1 0\n\
         f 2 1 3\nf 6 7 4\nf 2 1 5\n",
    );
    let repaired = dir.path().join("repaired.obj");
    for input in [input, colours] {
        for ext in ["ply", "off", "obj"] {
            let out = dir.path().join(format!("out.{ext}"));
            let printout = run(&input, &out, &["--repair", "--repaired", repaired.to_str().unwrap()]);
            assert!(printout.contains("non-manifold edge"), "{printout}");
            if ext == "ply" {
                assert!(printout.contains("copies of vertices at attribute seams"), "{printout}");
            }
            if ext == "obj" && input.ends_with("colours.obj") {
                // (Two copies of the edge's ends: the green ones.)
                let written = std::fs::read_to_string(&out).unwrap();
                assert_eq!(written.lines().filter(|l| l.starts_with("v ")).count(), 9, "{written}");
            }
            check(&repaired, &out);
        }
    }
}

/// Colours that differ at a vertex only below what a byte holds are one value in a PLY file:
/// the vertex is written once (with a copy, the file would have two vertices there, alike in
/// everything, and a crack that `check` rightly reads as one), while colours a byte tells
/// apart still get their copies. An OFF output writes these colours as numbers, exactly, so
/// it copies the vertex in both cases.
#[test]
fn colours_alike_in_bytes_make_no_copy_in_ply() {
    let dir = tempfile::tempdir().unwrap();
    for (other, copies_in_ply) in [("0.5001", 0), ("0.9", 2)] {
        // A square folded along its diagonal, each half with its own copies of the diagonal's
        // ends (welded on reading), the second half's colour `other`.
        let input = write(
            dir.path(),
            "fold.obj",
            &format!(
                "v 0 0 0 0.5 0.5 0.5\nv 1 0 0 0.5 0.5 0.5\nv 1 1 0.2 0.5 0.5 0.5\nv 0 1 0 {other} 0.5 0.5\n\
                 v 0 0 0 {other} 0.5 0.5\nv 1 1 0.2 {other} 0.5 0.5\nf 1 2 3\nf 5 6 4\n"
            ),
        );
        for (ext, copies) in [("ply", copies_in_ply), ("off", 2)] {
            let out = dir.path().join(format!("fold-out.{ext}"));
            let printout = run(&input, &out, &[]);
            let vertices = read(&out).positions.len();
            let records = io::read_raw(&out).unwrap().positions.len();
            assert_eq!((vertices, records - vertices), (4, copies), "{other} {ext}: {printout}");
            check(&input, &out);
        }
    }
}

/// A name ending in a backslash (read from `o name\ `, the blank trimmed) is written so that it
/// does not continue on the next line (OBJ's line continuation would swallow the `g` after it):
/// the output's groups are the input's.
#[test]
fn a_name_ending_in_a_backslash_keeps_the_next_line() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(
        dir.path(),
        "slash.obj",
        "mtllib lib\\ \no thing\\ \nv -2 0 0\nv 2 0 0\nv 0 0.5 0\nv 0 -0.4 0.3\n\
         g part0\\ \nusemtl red\\ \nf 1 2 3\ng part1\nusemtl blue\nf 2 1 4\n",
    );
    let out = dir.path().join("slash-out.obj");
    run(&input, &out, &[]);
    let (a, b) = (read(&input), read(&out));
    assert_eq!(a.attributes.groups[0].object.as_deref(), Some("thing\\"));
    assert_eq!(a.attributes.groups[0].group.as_deref(), Some("part0\\"));
    assert_eq!(b.attributes.groups, a.attributes.groups);
    assert_eq!(b.attributes.mtllib, a.attributes.mtllib);
    check(&input, &out);
}
