//! `delmesh check --vertex-map --face-map`: the judge of the maps passes every
//! map delmesh writes (fixtures × settings, OBJ and PLY output, STL input,
//! a repaired input with `--original`), and fails maps damaged in each way it
//! looks for; `--check` judges the maps of a run (and of `batch`) before
//! putting them in place.

mod common;

use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn delmesh() -> Command {
    Command::cargo_bin("delmesh").unwrap()
}

/// Refines `input` into `dir/out.EXT` with `flags`, writing both maps;
/// returns the output's and the maps' paths.
fn refine(dir: &Path, input: &Path, ext: &str, flags: &[&str]) -> [PathBuf; 3] {
    let out = [format!("out.{ext}"), "v.csv".into(), "f.csv".into()].map(|n| dir.join(n));
    let run = delmesh()
        .arg("-q")
        .arg("-i")
        .arg(input)
        .arg("-o")
        .arg(&out[0])
        .arg("--vertex-map")
        .arg(&out[1])
        .arg("--face-map")
        .arg(&out[2])
        .args(flags)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    out
}

/// `delmesh check input output --vertex-map v --face-map f [extra]`: exit
/// status and standard output.
fn check(input: &Path, [output, v, f]: &[PathBuf; 3], extra: &[&str]) -> (bool, String) {
    let run = delmesh()
        .arg("check")
        .arg(input)
        .arg(output)
        .arg("--vertex-map")
        .arg(v)
        .arg("--face-map")
        .arg(f)
        .args(extra)
        .output()
        .unwrap();
    (run.status.success(), String::from_utf8_lossy(&run.stdout).into_owned())
}

#[test]
fn every_map_delmesh_writes_passes() {
    let dir = tempfile::tempdir().unwrap();
    let mut meshes = common::fixtures();
    meshes.push(common::data_dir().join("cad/rotor.obj"));
    meshes.push(common::data_dir().join("attributes/ply_uchar_colour_flat_grid.ply"));
    let mut across = 0;
    for mesh in &meshes {
        for flags in [&[][..], &["--prune"], &["--shells", "-s", "4"]] {
            for ext in ["obj", "ply"] {
                let files = refine(dir.path(), mesh, ext, flags);
                let (ok, stdout) = check(mesh, &files, &[]);
                assert!(ok, "{} {flags:?} {ext}:\n{stdout}", mesh.display());
                assert!(stdout.contains("; its maps are right"), "{stdout}");
                let rows = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap().lines().count() - 1;
                assert!(
                    stdout.contains(&format!("maps    vertex map: {} rows", rows("v.csv"))),
                    "{stdout}"
                );
                assert!(
                    stdout.contains(&format!("maps    face map: {} rows", rows("f.csv"))),
                    "{stdout}"
                );
                let map = std::fs::read_to_string(dir.path().join("f.csv")).unwrap();
                across += map.lines().filter(|l| l.ends_with(",0")).count();
            }
        }
    }
    // (The rotor's flat regions lay faces across input faces: those rows
    // were judged too.)
    assert!(across > 0);
}

#[test]
fn an_stl_input_is_numbered_by_its_facets() {
    let dir = tempfile::tempdir().unwrap();
    let stl = dir.path().join("bunny.stl");
    delmesh()
        .args(["-q", "--no-refine", "-i"])
        .arg(common::data_dir().join("bunny.obj"))
        .arg("-o")
        .arg(&stl)
        .assert()
        .success();
    let files = refine(dir.path(), &stl, "obj", &[]);
    let (ok, stdout) = check(&stl, &files, &[]);
    assert!(ok, "{stdout}");
    // Its vertex map counts facet corners (3f + k), well past the 1,839
    // positions the bunny has (the check found each the first at its
    // position).
    let map = std::fs::read_to_string(&files[1]).unwrap();
    let most = (map.lines().skip(1))
        .map(|row| row.split(',').nth(1).unwrap().parse::<usize>().unwrap())
        .max()
        .unwrap();
    assert!(most > 1839 * 2, "{most}");
}

#[test]
fn with_repair_the_maps_number_the_original_file() {
    let dir = tempfile::tempdir().unwrap();
    let original = common::data_dir().join("repair/dragon-cut.obj");
    let repaired = dir.path().join("repaired.obj");
    let files = refine(
        dir.path(),
        &original,
        "obj",
        &["--repair", "--repaired", repaired.to_str().unwrap()],
    );
    let original_flag = ["--original", original.to_str().unwrap()];
    let (ok, stdout) = check(&repaired, &files, &original_flag);
    assert!(ok, "{stdout}");
    // Judged against the repaired file's numbering, they fail, and the
    // printout says what to give.
    let (ok, stdout) = check(&repaired, &files, &[]);
    assert!(!ok, "{stdout}");
    assert!(stdout.contains("is not the face map of"), "{stdout}");
    assert!(stdout.contains("give that one as --original FILE"), "{stdout}");
}

/// `text` with `f` applied to its rows (the header kept).
fn edit(text: &str, f: impl Fn(usize, &str) -> Option<String>) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    for (k, line) in lines.iter_mut().enumerate().skip(1) {
        if let Some(new) = f(k - 1, line) {
            *line = new;
        }
    }
    lines.join("\n") + "\n"
}

#[test]
fn damaged_maps_fail() {
    let dir = tempfile::tempdir().unwrap();
    let rotor = common::data_dir().join("cad/rotor.obj");
    let files = refine(dir.path(), &rotor, "obj", &[]);
    let vertex_map = std::fs::read_to_string(&files[1]).unwrap();
    let face_map = std::fs::read_to_string(&files[2]).unwrap();
    let cells = |line: &str| line.split(',').map(String::from).collect::<Vec<_>>();
    let added = (vertex_map.lines().skip(1))
        .position(|l| cells(l)[1] != cells(l)[2])
        .unwrap();
    let across = face_map.lines().skip(1).position(|l| l.ends_with(",0")).unwrap();
    let damages: Vec<(&str, String, String, &str)> = vec![
        (
            "t rounded to 12 digits",
            edit(&vertex_map, |k, l| {
                (k == added).then(|| {
                    let c = cells(l);
                    let t: f64 = c[3].parse().unwrap();
                    format!("{},{},{},{t:.12}", c[0], c[1], c[2])
                })
            }),
            face_map.clone(),
            "but a + t·(b − a) is",
        ),
        (
            "an added vertex's ends swapped",
            edit(&vertex_map, |k, l| {
                (k == added).then(|| {
                    let c = cells(l);
                    format!("{},{},{},{}", c[0], c[2], c[1], c[3])
                })
            }),
            face_map.clone(),
            "but a + t·(b − a) is",
        ),
        (
            "an input vertex renamed",
            edit(&vertex_map, |k, _| (k == 0).then(|| "0,1,1,0.0".into())),
            face_map.clone(),
            "output vertex 0 is at",
        ),
        (
            "a row left out",
            vertex_map[..vertex_map.trim_end().rfind('\n').unwrap() + 1].to_string(),
            face_map.clone(),
            "rows for the output's",
        ),
        (
            "a wrong header",
            vertex_map.replacen("output_index", "index", 1),
            face_map.clone(),
            "not the header",
        ),
        (
            "a face named after its neighbour",
            vertex_map.clone(),
            edit(&face_map, |k, l| {
                (k == 7).then(|| {
                    let c = cells(l);
                    let f: usize = c[1].parse().unwrap();
                    format!("{},{},{}", c[0], f + 1, c[2])
                })
            }),
            "is not on input face",
        ),
        (
            "every face said inside",
            vertex_map.clone(),
            edit(&face_map, |_, l| Some(l.replace(",0", ",1"))),
            "but its corner",
        ),
        (
            "an output index out of order",
            vertex_map.clone(),
            edit(&face_map, |k, l| {
                (k == across).then(|| l.replacen(&format!("{k},"), "0,", 1))
            }),
            "output_index 0, not",
        ),
        (
            "a face out of range",
            vertex_map.clone(),
            edit(&face_map, |k, l| (k == 3).then(|| format!("{},99999,1", cells(l)[0]))),
            "is not one of the input's",
        ),
    ];
    for (what, v, f, says) in damages {
        std::fs::write(&files[1], v).unwrap();
        std::fs::write(&files[2], f).unwrap();
        let (ok, stdout) = check(&rotor, &files, &[]);
        assert!(!ok, "{what}: passed\n{stdout}");
        assert!(stdout.contains(says), "{what}: {stdout}");
        assert!(
            stdout.contains("PASS    ") && stdout.contains("FAILED  "),
            "{what}: {stdout}"
        );
    }
}

/// Prisms over random ovals of 256 to 2,000 corners (half of them with
/// their corners moved along them at random, half evenly spaced, four by
/// four on circles), tilted at random: large polygons that the reader cuts
/// as their constrained Delaunay triangulation, whose faces the face map's
/// judge finds through a grid. Each refines without an added vertex and its
/// maps pass; a cap's output face named after the other cap fails.
#[test]
fn maps_of_large_polygons_pass_and_fail_as_they_should() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = common::Rng::new(62);
    for k in 0..6 {
        let n = 256 + rng.below(1744) as usize;
        let (a, b) = (rng.range(2.0, 4.0), rng.range(0.5, 1.5));
        let jitter = if k % 2 == 0 { 0.8 } else { 0.0 };
        let cap: Vec<[f64; 2]> = (0..n)
            .map(|j| {
                let t = (j as f64 + jitter * rng.f64()) / n as f64 * std::f64::consts::TAU;
                [a * t.cos(), b * t.sin()]
            })
            .collect();
        let (obj, _) = common::tilted_prism_with_polygon_caps(&cap, rng.range(-0.5, 0.5), rng.range(-0.5, 0.5));
        let input = dir.path().join(format!("prism{k}.obj"));
        std::fs::write(&input, obj).unwrap();
        let files = refine(dir.path(), &input, "ply", &[]);
        let (ok, stdout) = check(&input, &files, &[]);
        assert!(ok && stdout.contains("its maps are right"), "{k}: {stdout}");
        assert!(stdout.contains(" (0 added), "), "{k}: {stdout}");
        if k == 0 {
            // The sides are faces 0 to n - 1, the caps n and n + 1.
            let face_map = std::fs::read_to_string(&files[2]).unwrap();
            let on_cap = format!(",{n},1");
            let moved = edit(&face_map, |_, l| {
                l.ends_with(&on_cap)
                    .then(|| l.replace(&on_cap, &format!(",{},1", n + 1)))
            });
            assert_ne!(moved, face_map);
            std::fs::write(&files[2], moved).unwrap();
            let (ok, stdout) = check(&input, &files, &[]);
            assert!(!ok && stdout.contains("is not on input face"), "{stdout}");
        }
    }
}

#[test]
fn a_vertex_defined_twice_is_named_by_its_first_definition() {
    let dir = tempfile::tempdir().unwrap();
    // The cube with its first corner defined again at the end, and the
    // faces using the copy.
    let cube = std::fs::read_to_string(common::data_dir().join("cube.obj")).unwrap();
    let first = cube.lines().find(|l| l.starts_with("v ")).unwrap().to_string();
    let n = cube.lines().filter(|l| l.starts_with("v ")).count();
    let mut text = String::new();
    for line in cube.lines() {
        if line.starts_with("f ") {
            let corners: Vec<String> = (line.split_whitespace().skip(1))
                .map(|w| if w == "1" { (n + 1).to_string() } else { w.to_string() })
                .collect();
            text += &format!("f {}\n", corners.join(" "));
        } else {
            text += &format!("{line}\n");
        }
    }
    text += &format!("{first}\n");
    let input = dir.path().join("twice.obj");
    std::fs::write(&input, text).unwrap();
    let files = refine(dir.path(), &input, "obj", &[]);
    assert!(check(&input, &files, &[]).0);
    // Naming the copy instead is refused.
    let map = std::fs::read_to_string(&files[1]).unwrap();
    let renamed = map.replacen("\n0,0,0,0.0\n", &format!("\n0,{n},{n},0.0\n"), 1);
    assert_ne!(renamed, map);
    std::fs::write(&files[1], renamed).unwrap();
    let (ok, stdout) = check(&input, &files, &[]);
    assert!(!ok);
    assert!(stdout.contains("is defined before as vertex 0"), "{stdout}");
}

#[test]
fn the_run_check_judges_the_maps() {
    let dir = tempfile::tempdir().unwrap();
    let rotor = common::data_dir().join("cad/rotor.obj");
    let run = |extra: &[&str]| {
        delmesh()
            .arg("-i")
            .arg(&rotor)
            .arg("-o")
            .arg(dir.path().join("r.obj"))
            .args(["--check", "--vertex-map"])
            .arg(dir.path().join("v.csv"))
            .arg("--face-map")
            .arg(dir.path().join("f.csv"))
            .args(extra)
            .output()
            .unwrap()
    };
    let out = run(&[]);
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("with the geometry of") && stdout.contains("; its maps are right"),
        "{stdout}"
    );
    // From standard input the maps cannot be judged: said so.
    let out = delmesh()
        .args(["-i", "-", "-o"])
        .arg(dir.path().join("r.obj"))
        .args(["--check", "--vertex-map"])
        .arg(dir.path().join("v.csv"))
        .write_stdin(std::fs::read(&rotor).unwrap())
        .output()
        .unwrap();
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("--check did not verify the vertex map (the input cannot be read again)"),
        "{stdout}"
    );
    assert!(!stdout.contains("its vertex map is right"), "{stdout}");
    // batch --check judges the maps it writes.
    let out_dir = dir.path().join("batch");
    let out = delmesh()
        .args(["batch", "--check", "--vertex-maps", "--face-maps", "-d"])
        .arg(&out_dir)
        .arg(&rotor)
        .output()
        .unwrap();
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("check PASS; its maps are right"), "{stdout}");
    let files = [
        out_dir.join("rotor.obj"),
        out_dir.join("rotor.vertex-map.csv"),
        out_dir.join("rotor.face-map.csv"),
    ];
    assert!(check(&rotor, &files, &[]).0);
}

/// INPUT read from standard input is read once, for the check and the maps both: the maps
/// are judged against it (a damaged one fails), not refused.
#[test]
fn the_maps_are_judged_against_an_input_on_standard_input() {
    let dir = tempfile::tempdir().unwrap();
    let bunny = common::data_dir().join("bunny.obj");
    let files = refine(dir.path(), &bunny, "obj", &[]);
    let from_stdin = |files: &[PathBuf; 3]| {
        let run = delmesh()
            .arg("check")
            .arg("-")
            .arg(&files[0])
            .arg("--vertex-map")
            .arg(&files[1])
            .arg("--face-map")
            .arg(&files[2])
            .pipe_stdin(&bunny)
            .unwrap()
            .output()
            .unwrap();
        (run.status.code(), String::from_utf8_lossy(&run.stdout).into_owned())
    };
    let (code, stdout) = from_stdin(&files);
    assert_eq!(code, Some(0), "{stdout}");
    assert!(stdout.contains("; its maps are right"), "{stdout}");
    // A row changed fails.
    let map = std::fs::read_to_string(&files[1]).unwrap();
    let damaged = map.replacen("\n5,5,5,0.0\n", "\n5,6,6,0.0\n", 1);
    assert_ne!(damaged, map);
    std::fs::write(&files[1], damaged).unwrap();
    let (code, stdout) = from_stdin(&files);
    assert_eq!(code, Some(1), "{stdout}");
    assert!(stdout.contains("vertex map line 7"), "{stdout}");
}

#[test]
fn the_map_flags_are_refused_where_they_cannot_work() {
    let bunny = common::data_dir().join("bunny.obj");
    let fails = |args: &[&str], says: &str| {
        let out = delmesh().arg("check").args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    };
    let b = bunny.to_str().unwrap();
    fails(&["--original", b, b, b], "--original names the file the maps number");
    fails(
        &[b, "-", "--vertex-map", "-"],
        "OUTPUT and --vertex-map are both standard input",
    );
    fails(&[b, b, "--vertex-map", "/nonexistent/v.csv"], "/nonexistent/v.csv");
    // An STL output (`--no-refine` converts to one) rounds to f32 and has
    // no vertex list: its maps cannot be judged, and the judge says so.
    let dir = tempfile::tempdir().unwrap();
    let stl = dir.path().join("bunny.stl");
    let map = dir.path().join("v.csv");
    delmesh()
        .args(["-q", "--no-refine", "-i", b, "-o"])
        .arg(&stl)
        .arg("--vertex-map")
        .arg(&map)
        .assert()
        .success();
    let (s, m) = (stl.to_str().unwrap(), map.to_str().unwrap());
    fails(&[b, s, "--vertex-map", m], "an STL output has no vertex list");
}

/// A wavy grid cut down the middle, one side's seam moved 1e-4 off the
/// other's: `--repair --weld-tolerance 1e-3` closes it, moving input
/// faces, and the face map is judged where the weld moved them.
#[test]
fn a_weld_tolerance_moves_the_faces_the_map_is_judged_on() {
    let dir = tempfile::tempdir().unwrap();
    let (n, half) = (10, 5);
    let mut text = String::new();
    let mut index = std::collections::HashMap::new();
    for side in 0..2 {
        for j in 0..=n {
            for i in 0..=half {
                let (x, y) = ((i + side * half) as f64, j as f64);
                let dx = if side == 1 && i == 0 { 1e-4 } else { 0.0 };
                let z = 0.04 * (((i + side * half) * 7 + j * 3) % 5) as f64;
                text += &format!("v {} {y} {z}\n", x + dx);
                index.insert((side, i, j), index.len() + 1);
            }
        }
        for j in 0..n {
            for i in 0..half {
                let v = |di: usize, dj: usize| index[&(side, i + di, j + dj)];
                text += &format!(
                    "f {} {} {}\nf {} {} {}\n",
                    v(0, 0),
                    v(1, 0),
                    v(1, 1),
                    v(0, 0),
                    v(1, 1),
                    v(0, 1)
                );
            }
        }
    }
    let input = dir.path().join("crack.obj");
    std::fs::write(&input, text).unwrap();
    let repaired = dir.path().join("repaired.obj");
    let flags = [
        "--repair",
        "--weld-tolerance",
        "1e-3",
        "--repaired",
        repaired.to_str().unwrap(),
        "--check",
    ];
    let files = refine(dir.path(), &input, "obj", &flags);
    let original = ["--original", input.to_str().unwrap()];
    let (ok, stdout) = check(
        &repaired,
        &files,
        &[&original[..], &["--weld-tolerance", "1e-3"]].concat(),
    );
    assert!(ok, "{stdout}");
    // Judged where the file has them, faces along the seam are off.
    let (ok, stdout) = check(&repaired, &files, &original);
    assert!(!ok, "{stdout}");
    assert!(stdout.contains("is not on input face"), "{stdout}");
}

/// Faces that overlap in the input (a polygon given twice, which --repair
/// drops as a duplicate): an output face lies on both, and the map names
/// one of them for faces of either; that is no failure.
#[test]
fn overlapping_input_faces_may_share_output_faces() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("twice.obj");
    std::fs::write(
        &input,
        "v 0 0 0\nv 0 0 0\nv 1 0 0\nv 0.5 0 0.47438821025089206\nv 1.3 0.9 0\nv 0.5 1.5 0\n\
         v -0.3 0.9 0\nf 1 2 3 4 5\nf 2 1 6\nf 1 2 3 4 5\nf 3 2 7\n",
    )
    .unwrap();
    let repaired = dir.path().join("repaired.obj");
    let files = refine(
        dir.path(),
        &input,
        "obj",
        &["--repair", "--repaired", repaired.to_str().unwrap(), "--check"],
    );
    let (ok, stdout) = check(&repaired, &files, &["--original", input.to_str().unwrap()]);
    assert!(ok, "{stdout}");
}
