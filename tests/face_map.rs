//! `--face-map`: every output face is checked against the input file's own
//! faces, by geometry alone: its centroid lies on the face its row names,
//! and a face said to be inside lies on it whole (its corners, and the
//! points between them and the centroid); a face said not to be inside a
//! triangle has a corner off it. Faces inside one input face cover no more
//! than its area. On the shipped meshes, flat fans (flipped across faces),
//! jittered flat grids, polygons, groups (an OBJ writes its faces group by
//! group), repair (faces dropped, the others keep their numbers), pruning,
//! STL and OFF input, PLY output and `batch --face-maps`.

mod common;

use assert_cmd::Command;
use glam::{DVec2, DVec3};
use std::path::Path;

fn delmesh() -> Command {
    Command::cargo_bin("delmesh").unwrap()
}

/// An OBJ's vertices and faces (polygons, 0-based corners), in file order.
fn obj(path: &Path) -> (Vec<DVec3>, Vec<Vec<usize>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let (mut v, mut f) = (Vec::new(), Vec::new());
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let x: Vec<f64> = words.take(3).map(|x| x.parse().unwrap()).collect();
                v.push(DVec3::new(x[0], x[1], x[2]));
            }
            Some("f") => f.push(
                words
                    .map(|w| {
                        let i: i64 = w.split('/').next().unwrap().parse().unwrap();
                        if i < 0 {
                            (v.len() as i64 + i) as usize
                        } else {
                            i as usize - 1
                        }
                    })
                    .collect(),
            ),
            _ => {}
        }
    }
    (v, f)
}

/// An ASCII STL's facets, as an OBJ's vertices (three per facet) and faces.
fn stl(path: &Path) -> (Vec<DVec3>, Vec<Vec<usize>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let v: Vec<DVec3> = (text.lines())
        .filter_map(|l| l.trim().strip_prefix("vertex "))
        .map(|l| {
            let x: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            DVec3::new(x[0], x[1], x[2])
        })
        .collect();
    let f = (0..v.len() / 3).map(|i| vec![3 * i, 3 * i + 1, 3 * i + 2]).collect();
    (v, f)
}

/// A polygon of the input, projected on its plane.
struct Face {
    /// Newell's normal, unit.
    normal: DVec3,
    /// A point of the plane.
    origin: DVec3,
    /// The corners, projected along the normal's largest axis.
    outline: Vec<DVec2>,
    axis: usize,
    area: f64,
}

impl Face {
    fn new(corners: &[DVec3]) -> Face {
        // (From the first corner: cross products of positions far from the
        // origin would cancel away a small face's area.)
        let mut n = DVec3::ZERO;
        for (i, &p) in corners.iter().enumerate() {
            n += (p - corners[0]).cross(corners[(i + 1) % corners.len()] - corners[0]);
        }
        let area = n.length() / 2.0;
        let normal = n.normalize();
        let a = normal.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        Face {
            normal,
            origin: corners[0],
            outline: corners.iter().map(|&p| project(p, axis)).collect(),
            axis,
            area,
        }
    }

    /// Whether `p` lies on the face, within `tol`.
    fn holds(&self, p: DVec3, tol: f64) -> bool {
        if (p - self.origin).dot(self.normal).abs() > tol {
            return false;
        }
        let q = project(p, self.axis);
        let n = self.outline.len();
        let mut winding = 0i32;
        for i in 0..n {
            let (a, b) = (self.outline[i], self.outline[(i + 1) % n]);
            // On a side (the projection shrinks distances by at most √3).
            let t = ((q - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            if (a + t * (b - a) - q).length() <= tol {
                return true;
            }
            let left = (b - a).perp_dot(q - a);
            if a.y <= q.y && b.y > q.y && left > 0.0 {
                winding += 1;
            } else if a.y > q.y && b.y <= q.y && left < 0.0 {
                winding -= 1;
            }
        }
        winding != 0
    }
}

fn project(p: DVec3, axis: usize) -> DVec2 {
    match axis {
        0 => DVec2::new(p.y, p.z),
        1 => DVec2::new(p.z, p.x),
        _ => DVec2::new(p.x, p.y),
    }
}

/// Refines `input` into `out` (OBJ) with `flags` and the face map, checks
/// every row against the input's faces, and returns the rows and how many
/// are not inside.
fn verified(input: &Path, flags: &[&str]) -> (Vec<(usize, bool)>, usize) {
    let dir = tempfile::tempdir().unwrap();
    let (out, map) = (dir.path().join("out.obj"), dir.path().join("faces.csv"));
    let run = delmesh()
        .arg("-q")
        .arg("-i")
        .arg(input)
        .arg("-o")
        .arg(&out)
        .arg("--face-map")
        .arg(&map)
        .args(flags)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let (iv, ifaces) = if input.extension().is_some_and(|e| e == "stl") {
        stl(input)
    } else {
        obj(input)
    };
    let (ov, ofaces) = obj(&out);
    let (lo, hi) = iv
        .iter()
        .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let tol = 1e-9 * (hi - lo).length();
    let faces: Vec<Face> = ifaces
        .iter()
        .map(|f| Face::new(&f.iter().map(|&i| iv[i]).collect::<Vec<_>>()))
        .collect();
    let table = std::fs::read_to_string(&map).unwrap();
    let mut lines = table.lines();
    assert_eq!(lines.next(), Some("output_index,input_index,inside"));
    let mut rows = Vec::new();
    let mut covered = vec![0.0; faces.len()];
    let mut outside = 0;
    for (k, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), 3, "{line}");
        let (i, f): (usize, usize) = (cells[0].parse().unwrap(), cells[1].parse().unwrap());
        let inside = match cells[2] {
            "1" => true,
            "0" => false,
            other => panic!("inside is {other}"),
        };
        assert_eq!(i, k);
        let name = format!("{}: output face {k} (row {line})", input.display());
        let corners: Vec<DVec3> = ofaces[k].iter().map(|&v| ov[v]).collect();
        let c = (corners[0] + corners[1] + corners[2]) / 3.0;
        let face = &faces[f];
        assert!(face.holds(c, tol), "{name}: centroid {c} not on input face {f}");
        if inside {
            for &x in &corners {
                assert!(face.holds(x, tol), "{name}: corner {x} not on input face {f}");
                assert!(face.holds((x + c) / 2.0, tol), "{name}");
            }
            covered[f] += (corners[1] - corners[0]).cross(corners[2] - corners[0]).length() / 2.0;
        } else {
            outside += 1;
            if ifaces[f].len() == 3 {
                assert!(
                    corners.iter().any(|&x| !face.holds(x, tol)),
                    "{name}: said not inside, but its corners are all on the triangle"
                );
            }
        }
        rows.push((f, inside));
    }
    assert_eq!(rows.len(), ofaces.len(), "a row per output face");
    for (f, face) in faces.iter().enumerate() {
        assert!(
            covered[f] <= face.area * (1.0 + 1e-9) + tol * tol,
            "input face {f} covered beyond its area"
        );
    }
    (rows, outside)
}

/// The shipped meshes, with the default settings and pruned; the CAD rotor
/// (flat regions flipped across faces) also with --shells.
#[test]
fn every_output_face_lies_on_the_input_face_it_names() {
    let mut across = 0;
    for mesh in common::fixtures() {
        for flags in [&[][..], &["--prune"]] {
            across += verified(&mesh, flags).1;
        }
    }
    let rotor = common::data_dir().join("cad/rotor.obj");
    for flags in [&[][..], &["--prune"], &["--shells", "-s", "4"]] {
        let (rows, outside) = verified(&rotor, flags);
        assert!(outside > 0 && outside < rows.len() / 10, "{outside}");
        across += outside;
    }
    assert!(across > 0);
}

/// An oval 40-gon fanned from one corner (thin triangles far from
/// Delaunay, all coplanar): flips lay faces across the fan's triangles.
/// Written as one polygon, every face is inside it. (A regular polygon
/// would not do: its corners are cocircular, any fan of it Delaunay.)
#[test]
fn a_flat_fan_flips_across_its_faces_but_not_out_of_its_polygon() {
    let dir = tempfile::tempdir().unwrap();
    let n = 40;
    let mut text = String::new();
    for i in 0..n {
        let a = std::f64::consts::TAU * i as f64 / n as f64;
        text += &format!("v {} {} 0\n", 2.0 * a.cos(), a.sin());
    }
    // A cap below, so that the fan is not the whole mesh's boundary alone.
    text += "v 0 0 -1\n";
    let mut fan = text.clone();
    for i in 2..n {
        fan += &format!("f 1 {} {}\n", i, i + 1);
    }
    let mut polygon = text.clone();
    polygon += "f";
    for i in 1..=n {
        polygon += &format!(" {i}");
    }
    polygon += "\n";
    for body in [&mut fan, &mut polygon] {
        for i in 1..=n {
            body.push_str(&format!("f {} {} {}\n", i % n + 1, i, n + 1));
        }
    }
    let (fan_path, polygon_path) = (dir.path().join("fan.obj"), dir.path().join("polygon.obj"));
    std::fs::write(&fan_path, fan).unwrap();
    std::fs::write(&polygon_path, polygon).unwrap();
    let (rows, outside) = verified(&fan_path, &[]);
    assert!(outside > 10, "{outside} of {}", rows.len());
    let (rows, outside) = verified(&polygon_path, &[]);
    assert_eq!(outside, 0);
    // The polygon is face 0, the cone's faces 1..=n.
    assert!(rows.iter().filter(|r| r.0 == 0).count() >= n - 2);
}

/// A flat grid with its inner corners moved at random (many thin,
/// non-Delaunay pairs flipped across faces), whole and with a quarter cut
/// out (an L: walks towards a centroid meet the inner corner's border).
#[test]
fn jittered_flat_grids_map_every_face() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = common::Rng::new(20261204);
    let n = 30;
    for cut in [false, true] {
        let mut text = String::new();
        for j in 0..=n {
            for i in 0..=n {
                let inner = |k: usize| k > 0 && k < n;
                let dx = if inner(i) { rng.range(-0.35, 0.35) } else { 0.0 };
                let dy = if inner(j) { rng.range(-0.35, 0.35) } else { 0.0 };
                text += &format!("v {} {} 0\n", i as f64 + dx, j as f64 + dy);
            }
        }
        for j in 0..n {
            for i in 0..n {
                if cut && i >= n / 2 && j >= n / 2 {
                    continue;
                }
                let a = j * (n + 1) + i + 1;
                let (b, c, d) = (a + 1, a + n + 1, a + n + 2);
                text += &format!("f {a} {b} {d}\nf {a} {d} {c}\n");
            }
        }
        let path = dir.path().join(format!("grid-{cut}.obj"));
        std::fs::write(&path, text).unwrap();
        let (rows, outside) = verified(&path, &[]);
        assert!(outside > rows.len() / 10, "{outside} of {}", rows.len());
    }
}

/// An OBJ of the vertices `v`, then `faces` (0-based corners), each after
/// the line `before(i)` gives face i.
fn obj_text(v: &[DVec3], faces: &[Vec<usize>], before: impl Fn(usize) -> String) -> String {
    let mut text = String::new();
    for p in v {
        text += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for (i, face) in faces.iter().enumerate() {
        text += &before(i);
        text += "f";
        for c in face {
            text += &format!(" {}", c + 1);
        }
        text += "\n";
    }
    text
}

/// Groups interleaved in the file: the OBJ output writes its faces group by
/// group, and the map follows the file's order.
#[test]
fn rows_follow_the_faces_as_the_output_file_orders_them() {
    let dir = tempfile::tempdir().unwrap();
    let cube = common::data_dir().join("cube.obj");
    let (v, f) = obj(&cube);
    let text = obj_text(&v, &f, |i| if i % 2 == 0 { "g even\n" } else { "g odd\n" }.to_string());
    let path = dir.path().join("grouped.obj");
    std::fs::write(&path, text).unwrap();
    let (rows, _) = verified(&path, &[]);
    // Even faces first: the first rows name even input faces.
    assert_eq!(rows[0].0 % 2, 0);
    assert_eq!(rows.last().unwrap().0 % 2, 1);
}

/// With --repair, faces dropped leave the others their numbers in the
/// file; an STL's faces are its facets.
#[test]
fn faces_keep_their_numbers_in_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let cube = common::data_dir().join("cube.obj");
    let (v, f) = obj(&cube);
    // A face that repeats a vertex first, and a duplicate face last: repair drops both.
    let mut damaged = vec![vec![0, 0, 1]];
    damaged.extend(f.iter().cloned());
    damaged.push(f[0].clone());
    let text = obj_text(&v, &damaged, |_| String::new());
    let path = dir.path().join("damaged.obj");
    std::fs::write(&path, text).unwrap();
    let (rows, _) = verified(&path, &["--repair"]);
    assert!(rows.iter().all(|r| r.0 != 0), "face 0 was dropped");
    // The cube as STL facets, its triangles non-Delaunay on each side.
    let mut solid = String::from("solid cube\n");
    for face in &f {
        solid += "facet normal 0 0 0\nouter loop\n";
        for &c in face {
            solid += &format!("vertex {} {} {}\n", v[c].x, v[c].y, v[c].z);
        }
        solid += "endloop\nendfacet\n";
    }
    solid += "endsolid cube\n";
    let stl_path = dir.path().join("cube.stl");
    std::fs::write(&stl_path, solid).unwrap();
    let (rows, _) = verified(&stl_path, &[]);
    // (A face flipped across two may be named by neither's centroid: not
    // every facet need be named.)
    assert!(rows.iter().all(|r| r.0 < f.len()));
}

/// The face map of `input` refined into `output` (its map beside it).
fn map_of(input: &Path, output: &Path) -> String {
    let mut map = output.as_os_str().to_owned();
    map.push(".csv");
    delmesh()
        .args(["-q", "-i"])
        .arg(input)
        .arg("-o")
        .arg(output)
        .arg("--face-map")
        .arg(&map)
        .assert()
        .success();
    std::fs::read_to_string(&map).unwrap()
}

/// An OFF input numbers its faces as the OBJ it was written from: the
/// maps are the same.
#[test]
fn an_off_input_numbers_its_faces_in_file_order() {
    let dir = tempfile::tempdir().unwrap();
    let rotor = common::data_dir().join("cad/rotor.obj");
    let (v, f) = obj(&rotor);
    let mut off = format!("OFF\n{} {} 0\n", v.len(), f.len());
    for p in &v {
        off += &format!("{} {} {}\n", p.x, p.y, p.z);
    }
    for face in &f {
        off += &format!("{}", face.len());
        for c in face {
            off += &format!(" {c}");
        }
        off += "\n";
    }
    let off_path = dir.path().join("rotor.off");
    std::fs::write(&off_path, off).unwrap();
    assert_eq!(
        map_of(&rotor, &dir.path().join("out.obj")),
        map_of(&off_path, &dir.path().join("out.obj"))
    );
}

/// The map of a PLY output is that of the OBJ output (PLY keeps the faces'
/// order), and batch --face-maps writes the main command's map.
#[test]
fn ply_outputs_and_batch_write_the_same_map() {
    let dir = tempfile::tempdir().unwrap();
    let rotor = common::data_dir().join("cad/rotor.obj");
    let mut maps: Vec<String> = (["out.obj", "out.ply"].iter())
        .map(|out| map_of(&rotor, &dir.path().join(out)))
        .collect();
    let out_dir = dir.path().join("batch");
    delmesh()
        .args(["batch", "-q", "--face-maps", "-d"])
        .arg(&out_dir)
        .arg(&rotor)
        .assert()
        .success();
    maps.push(std::fs::read_to_string(out_dir.join("rotor.face-map.csv")).unwrap());
    assert_eq!(maps[0], maps[1]);
    assert_eq!(maps[0], maps[2]);
}

/// Every OBJ of a folder (the project's shared meshes), with the default
/// settings, --prune and --shells -s 4 (or the FACE_MAP_FLAGS): run with
/// `FACE_MAP_MESHES=../shared/meshes cargo test --release --test face_map -- --ignored`.
#[test]
#[ignore = "a tool: checks the face maps of the meshes in FACE_MAP_MESHES"]
fn meshes_of_a_folder() {
    let Ok(folder) = std::env::var("FACE_MAP_MESHES") else {
        eprintln!("FACE_MAP_MESHES not set; skipped");
        return;
    };
    let mut meshes: Vec<_> = std::fs::read_dir(folder)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    meshes.sort();
    // FACE_MAP_FLAGS="-ds pqueue -s 0" runs those settings instead.
    let given = std::env::var("FACE_MAP_FLAGS").ok();
    let given: Option<Vec<&str>> = given.as_deref().map(|f| f.split_whitespace().collect());
    let settings: Vec<&[&str]> = match &given {
        Some(flags) => vec![&flags[..]],
        None => vec![&[], &["--prune"], &["--shells", "-s", "4"]],
    };
    for mesh in meshes {
        for &flags in &settings {
            let (rows, outside) = verified(&mesh, flags);
            eprintln!("{} {flags:?}: {} faces, {outside} across", mesh.display(), rows.len());
        }
    }
}
