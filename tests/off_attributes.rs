//! An OFF output keeps what an OFF file can hold (Geomview's
//! `[ST][C][N]OFF`): vertex normals, colours and texture coordinates,
//! written once per value at a seam, and face colours after each face's
//! indices. Reading the output back gives the input's values: bit for bit
//! at input vertices (8-bit colours stay 8-bit), the interpolation along
//! the input edge at added ones. What OFF cannot hold is left out with a
//! note. Every output passes `delmesh check` (the runs use `--check`).

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use common::{barycentric, channel, Rng};
use delmesh::attributes::{Attributes, Channel, FaceProperty, Kind, ValueType, VertexProperty, NO_VALUE};
use delmesh::io::{self, InputMesh, ReadOptions};
use glam::DVec3;

fn delmesh() -> Command {
    Command::cargo_bin("delmesh").unwrap()
}

/// Runs delmesh with `--check` on `input`, writing `output` (the input in
/// place if `None`); returns its printout.
fn run(input: &Path, output: Option<&Path>, extra: &[&str]) -> String {
    let mut command = delmesh();
    command.arg("-i").arg(input).arg("--check").args(extra);
    if let Some(output) = output {
        command.arg("-o").arg(output);
    }
    let out = command.output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "delmesh failed on {}: {text}{}",
        input.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("check   PASS"), "{text}");
    text
}

fn read(path: &Path) -> InputMesh {
    io::read_mesh(path, &ReadOptions::default()).unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The shortest text that reads back to `x`.
fn num(x: f64) -> String {
    format!("{x}")
}

/// A jittered grid folded into a roof along y = n/4 (cells 1 × 1/2, whose
/// diagonals are Delaunay or not by the jitter, which is small enough that
/// no face turns over), coordinates dyadic (each half exactly planar).
struct Roof {
    n: usize,
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

impl Roof {
    fn new(n: usize, seed: u64) -> Roof {
        assert!(n % 2 == 0);
        let mut rng = Rng::new(seed);
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (mut x, mut y) = (i as f64, j as f64 / 2.0);
                // (The fold's vertices stay on it, and those of the middle
                // column on x = n/2.)
                if i > 0 && i < n && j > 0 && j < n {
                    let (dx, dy) = (rng.below(49) as f64 - 24.0, rng.below(49) as f64 - 24.0);
                    if i != n / 2 {
                        x += dx / 256.0;
                    }
                    if j != n / 2 {
                        y += dy / 512.0;
                    }
                }
                positions.push(DVec3::new(x, y, (y - n as f64 / 4.0).abs() / 4.0));
            }
        }
        let triangles = common::grid_triangles(n);
        Roof {
            n,
            positions,
            triangles,
        }
    }

    fn centroid(&self, t: usize) -> DVec3 {
        self.triangles[t]
            .iter()
            .map(|&v| self.positions[v as usize])
            .sum::<DVec3>()
            / 3.0
    }

    /// Which quarter face `t` is in: 0..4 (right half: +1, upper: +2).
    fn quarter(&self, t: usize) -> usize {
        let c = self.centroid(t);
        let half = self.n as f64 / 2.0;
        usize::from(c.x > half) + 2 * usize::from(c.y > half / 2.0)
    }

    /// A number for face `t` that differs between the two faces of a cell
    /// and between quarters: as a face colour, it keeps every face apart
    /// (no flips), so that the thin cells' diagonals are split.
    fn face_number(&self, t: usize) -> usize {
        2 * self.quarter(t) + t % 2
    }

    /// OFF text: `keyword`, each vertex line `x y z` and `vertex(position,
    /// right)` (`right`: the vertex is right of column n/2), each face line
    /// its indices and `face(t)`. With `seam`, faces of the right half use
    /// copies of the vertices on column n/2 (listed after the others, at the
    /// same positions), whose `vertex` is given `right = true`.
    fn off(
        &self,
        keyword: &str,
        vertex: impl Fn(DVec3, bool) -> String,
        face: impl Fn(usize) -> String,
        seam: bool,
    ) -> String {
        let n = self.n;
        let mut lines: Vec<(DVec3, bool)> = (self.positions.iter().enumerate())
            .map(|(v, &p)| (p, v % (n + 1) > n / 2))
            .collect();
        let mut copy = vec![u32::MAX; self.positions.len()];
        if seam {
            for j in 0..=n {
                let v = j * (n + 1) + n / 2;
                copy[v] = lines.len() as u32;
                lines.push((self.positions[v], true));
            }
        }
        let mut text = format!("{keyword}\n{} {} 0\n", lines.len(), self.triangles.len());
        for &(p, right) in &lines {
            let extra = vertex(p, right);
            writeln!(text, "{} {} {} {extra}", num(p.x), num(p.y), num(p.z)).unwrap();
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            let right = self.quarter(t) % 2 == 1;
            let ids = tri.map(|v| match copy[v as usize] {
                c if right && c != u32::MAX => c,
                _ => v,
            });
            writeln!(text, "3 {} {} {} {}", ids[0], ids[1], ids[2], face(t)).unwrap();
        }
        text
    }
}

/// The input triangle whose interior holds `p` (the one it is most inside of).
fn containing_triangle(input: &InputMesh, p: DVec3) -> usize {
    let mut best = (f64::NEG_INFINITY, usize::MAX);
    for t in 0..input.triangles.len() {
        let (l, off_plane) = barycentric(input, t, p);
        let inside = l[0].min(l[1]).min(l[2]);
        if off_plane < 1e-9 && inside > best.0 {
            best = (inside, t);
        }
    }
    assert!(best.0 > -1e-9, "{p} is in no input face");
    best.1
}

/// Checks `kind` at every corner of `output` against the input's field: at
/// an input vertex, bit for bit its value in the input face beside the
/// corner; at an added vertex (on an input edge), within `tolerance` of
/// the input face's interpolation there. Returns how many corners are at
/// added vertices.
fn assert_carried(input: &InputMesh, output: &InputMesh, kind: Kind, tolerance: f64) -> usize {
    let name = kind.name();
    let before = channel(input, kind).unwrap_or_else(|| panic!("the input has no {name}"));
    let after = channel(output, kind).unwrap_or_else(|| panic!("the output has no {name}"));
    assert_eq!(after.dim, before.dim, "{name}");
    let mut added = 0;
    for (t, tri) in output.triangles.iter().enumerate() {
        let centroid = tri.iter().map(|&v| output.positions[v as usize]).sum::<DVec3>() / 3.0;
        for (k, &v) in tri.iter().enumerate() {
            let p = output.positions[v as usize];
            let value = after.corner(3 * t + k);
            // The input face beside the corner: the one holding a point of
            // the output face near it.
            let s = containing_triangle(input, p + 1e-6 * (centroid - p));
            let corners = input.triangles[s];
            match corners.iter().position(|&w| input.positions[w as usize] == p) {
                Some(j) => assert_eq!(value, before.corner(3 * s + j), "{name} at input vertex {p}"),
                None => {
                    added += 1;
                    let (l, _) = barycentric(input, s, p);
                    for (d, &x) in value.iter().enumerate() {
                        let expected: f64 = (0..3).map(|j| l[j] * before.corner(3 * s + j)[d]).sum();
                        assert!(
                            (x - expected).abs() <= tolerance,
                            "{name} at added vertex {p}: {value:?}, expected {expected} for number {d}"
                        );
                    }
                }
            }
        }
    }
    added
}

/// Checks that every output face has the face colours (`red green blue
/// [alpha]`, in their type) of the input face holding its centroid.
fn assert_face_colors_carried(input: &InputMesh, output: &InputMesh, names: &[&str], ty: ValueType) {
    for &name in names {
        let find = |m: &InputMesh| {
            let p = m.attributes.face_properties.iter().find(|p| p.name == name);
            p.unwrap_or_else(|| panic!("no face property {name}")).clone()
        };
        let (before, after) = (find(input), find(output));
        assert_eq!((before.ty, after.ty), (ty, ty), "{name}");
        assert_eq!(after.values.len(), output.triangles.len());
        for (f, t) in output.triangles.iter().enumerate() {
            let centroid = t.iter().map(|&v| output.positions[v as usize]).sum::<DVec3>() / 3.0;
            assert_eq!(
                after.values[f],
                before.values[containing_triangle(input, centroid)],
                "{name} of face {f}"
            );
        }
    }
    let names_after: Vec<&str> = output
        .attributes
        .face_properties
        .iter()
        .map(|p| p.name.as_str())
        .collect();
    assert_eq!(names_after, names);
}

/// The output file's keyword, its vertex lines and its face lines, each as
/// its words.
fn off_lines(path: &Path) -> (String, Vec<Vec<String>>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let keyword = lines.next().unwrap().to_owned();
    let counts: Vec<usize> = lines.next().unwrap().split(' ').map(|w| w.parse().unwrap()).collect();
    let words = |l: &str| l.split(' ').map(str::to_owned).collect::<Vec<_>>();
    let vertices: Vec<_> = lines.by_ref().take(counts[0]).map(words).collect();
    let faces: Vec<_> = lines.by_ref().take(counts[1]).map(words).collect();
    assert_eq!((vertices.len(), faces.len()), (counts[0], counts[1]));
    assert_eq!(lines.next(), None, "nothing follows the faces");
    (keyword, vertices, faces)
}

/// Whether `word` is a whole number from 0 to 255, written as one.
fn is_byte(word: &str) -> bool {
    word.parse::<u8>().is_ok()
}

/// A COFF with 8-bit colours (3 numbers, and 4 as MeshLab and Open3D write
/// them) is written as COFF with whole numbers 0..255 again, as many per
/// vertex: the input's vertices keep their colours bit for bit when read
/// back, added vertices interpolate them within half an 8-bit step.
#[test]
fn coff_8_bit_colours_stay_8_bit() {
    let dir = tempfile::tempdir().unwrap();
    let roof = Roof::new(8, 3);
    for dim in [3, 4] {
        let colour = |p: DVec3, _| {
            // (Not affine: faces are split rather than flipped.)
            let (r, g) = ((p.x * p.x * 3.0).round(), (p.y * 60.0).round());
            match dim {
                3 => format!("{r} {g} 7"),
                _ => format!("{r} {g} 7 {}", 255.0 - (p.y * 8.0).round()),
            }
        };
        let input = write(
            dir.path(),
            &format!("c{dim}.off"),
            &roof.off("COFF", colour, |_| String::new(), false),
        );
        let out = dir.path().join(format!("c{dim}-out.off"));
        let printout = run(&input, Some(&out), &[]);
        assert!(
            !printout.contains("left out") && !printout.contains("not written"),
            "{printout}"
        );
        let (keyword, vertices, faces) = off_lines(&out);
        assert_eq!(keyword, "COFF");
        for line in &vertices {
            assert_eq!(line.len(), 3 + dim, "{line:?}");
            assert!(line[3..].iter().all(|w| is_byte(w)), "{line:?}");
        }
        assert!(faces.iter().all(|f| f.len() == 4), "no face colours");
        let (a, b) = (read(&input), read(&out));
        assert_eq!(b.attributes.color_type, Some(ValueType::U8));
        let added = assert_carried(&a, &b, Kind::Color, 0.5 / 255.0 + 1e-12);
        assert!(added > 0, "nothing added: {printout}");
        // Written again, the output is the same file.
        let again = dir.path().join(format!("c{dim}-again.off"));
        run(&out, Some(&again), &[]);
        assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
    }
}

/// Colours that are not 8-bit (fractions, as Geomview writes them) are
/// written as they are, in shortest round-trip form and always with a
/// decimal point (`1.0`: MeshLab takes numbers without one for bytes):
/// read back bit for bit at input vertices, and as interpolated at added
/// ones.
#[test]
fn fractional_colours_are_written_as_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let roof = Roof::new(8, 4);
    let colour = |p: DVec3, _| {
        format!(
            "{} {} 1 {}",
            num(p.x * p.x / 64.0),
            num(p.y / 3.0),
            num(0.1 + p.y / 10.0)
        )
    };
    let input = write(dir.path(), "f.off", &roof.off("COFF", colour, |_| String::new(), false));
    let out = dir.path().join("f-out.off");
    run(&input, Some(&out), &[]);
    let (keyword, vertices, _) = off_lines(&out);
    assert_eq!(keyword, "COFF");
    for line in &vertices {
        assert_eq!(line.len(), 7, "{line:?}");
        assert!(line[3..].iter().all(|w| w.contains('.')), "{line:?}");
    }
    assert!(vertices.iter().any(|l| l[5] == "1.0"), "{vertices:?}");
    let (a, b) = (read(&input), read(&out));
    assert_eq!(b.attributes.color_type, None);
    assert!(assert_carried(&a, &b, Kind::Color, 1e-12) > 0);
}

/// NOFF normals with a seam (duplicate vertices down the middle whose
/// faces on either side give different normals): the output writes a
/// vertex once per normal at the same position, the copies last, and says
/// so; every face keeps its side's normals.
#[test]
fn noff_normals_with_a_seam_are_written_once_per_value() {
    let dir = tempfile::tempdir().unwrap();
    let roof = Roof::new(10, 5);
    let normal = |p: DVec3, right: bool| {
        let shift = if right { 0.5 } else { 0.0 };
        format!("{} {} 1", num(p.x * p.x / 256.0 + shift), num(-p.y / 64.0))
    };
    let input = write(dir.path(), "n.off", &roof.off("NOFF", normal, |_| String::new(), true));
    let out = dir.path().join("n-out.off");
    let printout = run(&input, Some(&out), &[]);
    let (keyword, vertices, _) = off_lines(&out);
    assert_eq!(keyword, "NOFF");
    assert!(vertices.iter().all(|l| l.len() == 6), "{vertices:?}");
    let (a, b) = (read(&input), read(&out));
    let copies = vertices.len() - b.positions.len();
    assert!(copies > roof.n, "{copies} copies");
    assert!(
        printout.contains(&format!(
            "note    the file holds {} vertex records: {copies} copies of vertices at attribute seams follow the mesh's {}, \
             as OFF gives a vertex one value per attribute\n",
            vertices.len(),
            b.positions.len()
        )),
        "{printout}"
    );
    // The copies repeat positions of the mesh's vertices, after them.
    for line in &vertices[b.positions.len()..] {
        assert!(
            vertices[..b.positions.len()].iter().any(|l| l[..3] == line[..3]),
            "{line:?}"
        );
    }
    assert!(assert_carried(&a, &b, Kind::Normal, 1e-12) > 0, "{printout}");
}

/// STOFF texture coordinates (not affine, so that faces are split rather
/// than flipped) reach the output as they were.
#[test]
fn stoff_texture_coordinates_are_kept() {
    let dir = tempfile::tempdir().unwrap();
    let roof = Roof::new(8, 6);
    let st = |p: DVec3, _| format!("{} {}", num(p.x * p.x / 64.0), num(p.y / 16.0 + p.x * p.y / 128.0));
    let input = write(dir.path(), "t.off", &roof.off("STOFF", st, |_| String::new(), false));
    let out = dir.path().join("t-out.off");
    let printout = run(&input, Some(&out), &[]);
    let (keyword, vertices, _) = off_lines(&out);
    assert_eq!(keyword, "STOFF");
    assert!(vertices.iter().all(|l| l.len() == 5), "{vertices:?}");
    let (a, b) = (read(&input), read(&out));
    let ply = dir.path().join("t-out.ply");
    run(&input, Some(&ply), &[]);
    assert!(assert_carried(&a, &read(&ply), Kind::TexCoord, 1e-12) > 0, "PLY");
    assert!(assert_carried(&a, &b, Kind::TexCoord, 1e-12) > 0, "{printout}");
}

/// Face colours (numbers after a face's indices), whole numbers 0..255 or
/// fractions with alpha, are written after each output face's indices as
/// they were, and each output face has those of the input face it lies in.
#[test]
fn face_colours_are_kept() {
    let dir = tempfile::tempdir().unwrap();
    let roof = Roof::new(8, 7);
    let bytes = |t: usize| format!("200 {} 30", 30 * roof.face_number(t));
    let fractions = |t: usize| format!("{} 0.5 1 0.75", num(0.125 * roof.face_number(t) as f64));
    for (name, face, names, ty) in [
        (
            "bytes",
            &bytes as &dyn Fn(usize) -> String,
            &["red", "green", "blue"][..],
            ValueType::U8,
        ),
        (
            "fractions",
            &fractions,
            &["red", "green", "blue", "alpha"],
            ValueType::F32,
        ),
    ] {
        let input = write(
            dir.path(),
            &format!("{name}.off"),
            &roof.off("OFF", |_, _| String::new(), face, false),
        );
        let out = dir.path().join(format!("{name}-out.off"));
        let printout = run(&input, Some(&out), &[]);
        assert!(
            printout.contains("attributes: face properties (red, green, blue"),
            "{printout}"
        );
        let (keyword, vertices, faces) = off_lines(&out);
        assert_eq!(keyword, "OFF");
        assert!(vertices.iter().all(|l| l.len() == 3));
        for f in &faces {
            assert_eq!(f.len(), 4 + names.len(), "{f:?}");
            let colour_words_ok = match ty {
                ValueType::U8 => f[4..].iter().all(|w| is_byte(w)),
                _ => f[4..].iter().all(|w| w.contains('.')),
            };
            assert!(colour_words_ok, "{name}: {f:?}");
        }
        let (a, b) = (read(&input), read(&out));
        assert!(b.triangles.len() > a.triangles.len(), "{printout}");
        assert_face_colors_carried(&a, &b, names, ty);
    }
}

/// A PLY input's face colours (`uchar red green blue`) reach an OFF output
/// after each face's indices; what OFF cannot hold (a vertex property, a
/// face label) is left out before the construction, with a note naming it.
#[test]
fn ply_face_colours_reach_an_off_output() {
    let dir = tempfile::tempdir().unwrap();
    let roof = Roof::new(8, 8);
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         property float quality\nelement face {}\nproperty list uchar int vertex_indices\nproperty uchar red\n\
         property uchar green\nproperty uchar blue\nproperty int segment\nend_header\n",
        roof.positions.len(),
        roof.triangles.len()
    );
    for p in &roof.positions {
        writeln!(text, "{} {} {} {}", num(p.x), num(p.y), num(p.z), num(p.x * 2.0)).unwrap();
    }
    for (t, tri) in roof.triangles.iter().enumerate() {
        let (k, q) = (roof.face_number(t), roof.quarter(t));
        writeln!(
            text,
            "3 {} {} {} {} 9 {} {}",
            tri[0],
            tri[1],
            tri[2],
            30 * k,
            255 - q,
            q / 2
        )
        .unwrap();
    }
    let input = write(dir.path(), "p.ply", &text);
    let out = dir.path().join("p.off");
    let printout = run(&input, Some(&out), &[]);
    assert!(
        printout.contains(
            "note    vertex property quality and face property segment left out: OFF cannot hold them (the mesh is \
             refined as without them)\n"
        ),
        "{printout}"
    );
    let (keyword, _, faces) = off_lines(&out);
    assert_eq!(keyword, "OFF");
    assert!(
        faces.iter().all(|f| f.len() == 7 && f[4..].iter().all(|w| is_byte(w))),
        "{faces:?}"
    );
    let (a, b) = (read(&input), read(&out));
    assert_face_colors_carried(&a, &b, &["red", "green", "blue"], ValueType::U8);
}

/// Without `-o` an OFF input is rewritten in place: with all it holds
/// (normals, colours and texture coordinates, `STCNOFF`, a seam, face
/// colours); `--drop-attributes` writes positions only.
#[test]
fn an_off_rewritten_in_place_keeps_its_attributes() {
    let dir = tempfile::tempdir().unwrap();
    let roof = Roof::new(8, 9);
    let vertex = |p: DVec3, right: bool| {
        let shift = if right { 0.25 } else { 0.0 };
        format!(
            "{} 0 1 {} 40 {} 255 {} {}",
            num(p.x / 16.0),
            (p.x * 20.0).round(),
            (p.y * 50.0).round(),
            num(p.x * p.x / 64.0 + shift),
            num(p.y / 8.0)
        )
    };
    let face = |t: usize| format!("{} 128 0", 30 * roof.face_number(t));
    let text = roof.off("STCNOFF", vertex, face, true);
    let original = write(dir.path(), "original.off", &text);
    let mesh = write(dir.path(), "mesh.off", &text);
    let printout = run(&mesh, None, &[]);
    assert!(printout.contains("mesh.off is a Delaunay mesh"), "{printout}");
    let (keyword, vertices, faces) = off_lines(&mesh);
    assert_eq!(keyword, "STCNOFF");
    assert!(vertices.iter().all(|l| l.len() == 3 + 3 + 4 + 2), "{vertices:?}");
    assert!(faces.iter().all(|f| f.len() == 7), "{faces:?}");
    let (a, b) = (read(&original), read(&mesh));
    assert!(b.triangles.len() > a.triangles.len(), "{printout}");
    assert!(vertices.len() > b.positions.len(), "no copies at the seam");
    for (kind, tolerance) in [
        (Kind::Normal, 1e-12),
        (Kind::Color, 0.5 / 255.0 + 1e-12),
        (Kind::TexCoord, 1e-12),
    ] {
        assert_carried(&a, &b, kind, tolerance);
    }
    assert_face_colors_carried(&a, &b, &["red", "green", "blue"], ValueType::U8);

    let plain = dir.path().join("plain.off");
    let printout = run(&original, Some(&plain), &["--drop-attributes"]);
    assert!(!printout.contains("attributes:"), "{printout}");
    let (keyword, vertices, faces) = off_lines(&plain);
    assert_eq!(keyword, "OFF");
    assert!(vertices.iter().all(|l| l.len() == 3) && faces.iter().all(|f| f.len() == 4));
    assert!(read(&plain).attributes.is_empty());
}

/// An OBJ's texture coordinates, normals and colours reach an OFF output
/// (its colours, fractions, as they are); its groups and materials, which
/// OFF cannot hold, are left out with a note.
#[test]
fn an_obj_written_as_off() {
    let dir = tempfile::tempdir().unwrap();
    let roof = Roof::new(6, 10);
    let mut obj = String::from("mtllib roof.mtl\no roof\n");
    for p in &roof.positions {
        let (x, y, z) = (num(p.x), num(p.y), num(p.z));
        writeln!(obj, "v {x} {y} {z} {} 0.5 1", num(p.x / 6.0)).unwrap();
        writeln!(obj, "vt {} {}", num(p.x * p.x / 36.0), num(p.y / 3.0)).unwrap();
        writeln!(obj, "vn 0 {} 1", num(p.y / 16.0)).unwrap();
    }
    for (t, tri) in roof.triangles.iter().enumerate() {
        if t == roof.triangles.len() / 2 {
            obj.push_str("usemtl other\n");
        }
        let [a, b, c] = tri.map(|v| v + 1);
        writeln!(obj, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}").unwrap();
    }
    let input = write(dir.path(), "roof.obj", &obj);
    let out = dir.path().join("roof.off");
    let printout = run(&input, Some(&out), &[]);
    assert!(
        printout.contains(
            "note    groups and materials left out: OFF cannot hold them (the mesh is refined as without them)\n"
        ),
        "{printout}"
    );
    let (keyword, vertices, _) = off_lines(&out);
    assert_eq!(keyword, "STCNOFF");
    assert!(vertices
        .iter()
        .all(|l| l.len() == 11 && l[6..9].iter().all(|w| w.contains('.'))));
    let (a, b) = (read(&input), read(&out));
    for kind in [Kind::TexCoord, Kind::Normal, Kind::Color] {
        assert_carried(&a, &b, kind, 1e-12);
    }
}

/// The library's writer, given attributes an OFF cannot hold as they are
/// (a channel of only some faces, face colours of mixed types, a lone
/// alpha of another type, a vertex property, colours of 2 numbers), writes
/// what it can and names the rest, or refuses; it never panics.
#[test]
fn the_library_writes_what_an_off_can_hold_and_names_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let positions = [DVec3::ZERO, DVec3::X, DVec3::ONE.with_z(0.0), DVec3::Y];
    let triangles = [[0, 1, 2], [0, 2, 3]];
    let channel = |dim: usize, values: Vec<f64>, corners: Vec<u32>| Channel { dim, values, corners };
    let face = |name: &str, ty: ValueType| FaceProperty {
        name: name.to_owned(),
        ty,
        values: vec![10.0, 20.0],
    };
    let path = dir.path().join("lib.off");
    let write = |a: &Attributes| io::write_mesh_with_attributes(&path, &positions, &triangles, a);

    // Texture coordinates of one number get t = 0; normals of one face are
    // left out; face colours of mixed types too; alpha of another type too.
    let a = Attributes {
        texcoords: Some(channel(1, vec![0.0, 0.5, 1.0, 0.25], vec![0, 1, 2, 0, 2, 3])),
        normals: Some(channel(
            3,
            vec![0.0, 0.0, 1.0],
            vec![0, 0, 0, NO_VALUE, NO_VALUE, NO_VALUE],
        )),
        properties: vec![VertexProperty {
            name: "quality".to_owned(),
            ty: ValueType::F32,
            channel: Some(channel(1, vec![1.0], vec![0; 6])),
        }],
        face_properties: vec![
            face("red", ValueType::U8),
            face("green", ValueType::U8),
            face("blue", ValueType::U8),
            face("alpha", ValueType::F32),
        ],
        ..Attributes::default()
    };
    let written = write(&a).unwrap();
    assert_eq!(
        written.notes,
        [
            "normals of only some faces, vertex property quality and face property alpha not written: OFF cannot hold \
          them"
        ]
    );
    let (keyword, vertices, faces) = off_lines(&path);
    assert_eq!(keyword, "STOFF");
    assert_eq!(vertices[1], ["1.0", "0.0", "0.0", "0.5", "0.0"]);
    assert_eq!(faces[1], ["3", "0", "2", "3", "20", "20", "20"]);

    let mixed = Attributes {
        face_properties: vec![
            face("red", ValueType::U8),
            face("green", ValueType::F32),
            face("blue", ValueType::U8),
        ],
        ..Attributes::default()
    };
    assert_eq!(
        write(&mixed).unwrap().notes,
        ["face properties (red, green, blue) not written: OFF cannot hold them"]
    );
    assert_eq!(off_lines(&path).0, "OFF");

    let two = Attributes {
        colors: Some(channel(2, vec![0.5, 0.5], vec![0; 6])),
        ..Attributes::default()
    };
    let e = write(&two).unwrap_err().to_string();
    assert!(e.contains("colours of 2 numbers (3 or 4)"), "{e}");
}

/// Whole-number colours beyond 255 are not bytes: they are kept as they
/// are (not divided by 255), and written back as they were read.
#[test]
fn colours_beyond_255_are_not_taken_for_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(
        dir.path(),
        "c.off",
        "COFF\n3 1 0\n0 0 0 300 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n",
    );
    let colours = |m: &InputMesh| channel(m, Kind::Color).unwrap().values.clone();
    assert_eq!(colours(&read(&input))[..3], [300.0, 0.0, 0.0]);
    let output = dir.path().join("o.off");
    run(&input, Some(&output), &[]);
    assert_eq!(colours(&read(&output)), colours(&read(&input)));
}
