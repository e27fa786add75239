//! `delmesh render` to PNG and SVG, and the `-all --chart` bar chart: the
//! files decode, have the asked size, and show the marks they should.

mod common;

use std::path::Path;

use assert_cmd::Command;

fn delmesh() -> Command {
    Command::cargo_bin("delmesh").unwrap()
}

/// Width, height and RGB pixels of a PNG file.
fn decode_png(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let px = buf[..info.buffer_size()]
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    (info.width, info.height, px)
}

/// Runs a command that must succeed; its stdout.
fn stdout_of(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Pixels close to `color` (fully covered by a mark).
fn count_near(px: &[[u8; 3]], color: [u8; 3]) -> usize {
    px.iter()
        .filter(|p| p.iter().zip(color).all(|(&a, b)| a.abs_diff(b) < 24))
        .count()
}

const RED: [u8; 3] = [0xd6, 0x20, 0x20];
const BLUE: [u8; 3] = [0x1f, 0x5f, 0xd6];

#[test]
fn render_png_shows_red_before_and_blue_after() {
    let dir = tempfile::tempdir().unwrap();
    let bunny = common::data_dir().join("bunny.obj");
    let out = dir.path().join("b.obj");
    delmesh()
        .arg("-q")
        .arg("-i")
        .arg(&bunny)
        .arg("-o")
        .arg(&out)
        .assert()
        .success();
    let before = dir.path().join("before.png");
    let stdout = stdout_of(delmesh().arg("render").arg(&bunny).arg("-o").arg(&before).args([
        "--azimuth",
        "20",
        "--elevation",
        "10",
        "--size",
        "300",
    ]));
    assert!(stdout.contains("236 non-Delaunay edges (red)"), "{stdout}");
    let (w, h, px) = decode_png(&before);
    assert_eq!((w, h), (300, 300));
    assert!(count_near(&px, RED) > 50, "{} red pixels", count_near(&px, RED));
    assert_eq!(count_near(&px, BLUE), 0);
    let after = dir.path().join("AFTER.PNG");
    let stdout = stdout_of(
        delmesh()
            .arg("render")
            .arg(&out)
            .arg("-i")
            .arg(&bunny)
            .arg("-o")
            .arg(&after)
            .args(["--azimuth", "20", "--elevation", "10", "--size", "300"]),
    );
    assert!(
        stdout.contains("0 non-Delaunay edges") && stdout.contains("315 added"),
        "{stdout}"
    );
    let (_, _, px) = decode_png(&after);
    assert_eq!(count_near(&px, RED), 0);
    assert!(count_near(&px, BLUE) > 50, "{} blue pixels", count_near(&px, BLUE));
    // The same picture as SVG.
    let svg = dir.path().join("after.svg");
    delmesh()
        .arg("render")
        .arg(&out)
        .arg("-i")
        .arg(&bunny)
        .arg("-o")
        .arg(&svg)
        .assert()
        .success();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("#1f5fd6") && !text.contains("#d62020"));
    // Sizes out of range are refused by the parser.
    delmesh()
        .arg("render")
        .arg(&out)
        .arg("-o")
        .arg(&svg)
        .args(["--size", "10"])
        .assert()
        .failure();
}

#[test]
fn sweep_chart_has_a_bar_per_combination() {
    let dir = tempfile::tempdir().unwrap();
    let cube = common::data_dir().join("cube.obj");
    let (svg, png) = (dir.path().join("chart.svg"), dir.path().join("chart.png"));
    for chart in [&svg, &png] {
        delmesh()
            .arg("-q")
            .arg("-i")
            .arg(&cube)
            .arg("-o")
            .arg(dir.path().join("c.obj"))
            .arg("-all")
            .arg("--chart")
            .arg(chart)
            .assert()
            .success();
    }
    let text = std::fs::read_to_string(&svg).unwrap();
    for ds in [">stack  -s ", ">queue  -s ", ">pqueue -s "] {
        assert_eq!(text.matches(ds).count(), 6, "{ds}: {text}");
    }
    let no_median = text
        .lines()
        .filter(|l| l.contains(" -s ") && l.ends_with(" no median</text>"))
        .count();
    assert_eq!(no_median, 9, "{text}");
    assert!(text.contains("cube.obj: added vertices"));
    let (w, h, px) = decode_png(&png);
    assert!(w > 300 && h > 18 * 20, "{w} x {h}");
    assert!(px.iter().any(|p| p != &[255, 255, 255]));
    // Only with -all.
    let out = delmesh()
        .arg("-i")
        .arg(&cube)
        .arg("-o")
        .arg(dir.path().join("c.obj"))
        .arg("--chart")
        .arg(&svg)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--all"));
}

/// `render` never writes its picture over a mesh: not over the mesh it
/// draws, not over the `--input` original, and not to a mesh file name
/// (a slip that would leave an SVG where a mesh is expected). Each is a
/// one-line error, exit 1, with the file untouched.
#[test]
fn render_never_replaces_a_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("m.obj");
    let original = dir.path().join("orig.obj");
    std::fs::copy(common::data_dir().join("cube.obj"), &mesh).unwrap();
    std::fs::copy(common::data_dir().join("cube.obj"), &original).unwrap();
    let bytes = std::fs::read(&mesh).unwrap();
    let same_mesh = dir.path().join(".").join("m.obj");
    let picture_ply = dir.path().join("pic.ply");
    let cases: [(Vec<&Path>, &str); 4] = [
        (
            vec![&mesh, Path::new("-o"), &mesh],
            "the picture would overwrite the input",
        ),
        (
            vec![&mesh, Path::new("-o"), &same_mesh],
            "the picture would overwrite the input",
        ),
        (
            vec![&mesh, Path::new("-i"), &original, Path::new("-o"), &original],
            "the picture would overwrite the input",
        ),
        (
            vec![&mesh, Path::new("-o"), &picture_ply],
            "not a mesh: name it .svg or .png",
        ),
    ];
    for (args, expected) in cases {
        let out = delmesh().arg("render").args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert_eq!(std::fs::read(&mesh).unwrap(), bytes);
        assert_eq!(std::fs::read(&original).unwrap(), bytes);
    }
    assert!(!picture_ply.exists());
}

/// The view's angles: an elevation beyond ±90 degrees is refused (it drew
/// nothing), and an azimuth of many turns draws as its last turn does.
#[test]
fn view_angles_out_of_range_are_refused_or_reduced() {
    let dir = tempfile::tempdir().unwrap();
    let bunny = common::data_dir().join("bunny.obj");
    let svg = dir.path().join("b.svg");
    for elevation in ["91", "-90.5", "1e308"] {
        let out = delmesh()
            .arg("render")
            .arg(&bunny)
            .arg("-o")
            .arg(&svg)
            .args(["--elevation", elevation])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains("is not an elevation from -90 to 90 degrees"),
            "{stderr}"
        );
        assert!(!svg.exists());
    }
    let drawn = |azimuth: &str| {
        let stdout = stdout_of(delmesh().arg("render").arg(&bunny).arg("-o").arg(&svg).args([
            "--azimuth",
            azimuth,
            "--elevation",
            "90",
        ]));
        stdout
            .split(": ")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .to_string()
    };
    assert_eq!(drawn("3630"), drawn("30"));
    assert_ne!(drawn("1e308"), "0");
}

/// A picture's name says its format: `.png` PNG, `.svg` (or no extension)
/// SVG, either one compressed before `.gz`; any other extension (`.jpg`,
/// `.svgz`) is refused in one line before any work, for `render` and
/// `--chart` alike, where an SVG was once written under it (and `.png.gz`
/// got a compressed SVG).
#[test]
fn a_pictures_name_says_its_format() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = common::data_dir().join("cube.obj");
    let gunzip = |path: &Path| {
        let mut text = Vec::new();
        std::io::Read::read_to_end(
            &mut flate2::read::GzDecoder::new(std::fs::File::open(path).unwrap()),
            &mut text,
        )
        .unwrap();
        text
    };
    for (name, png, gz) in [
        ("a.png", true, false),
        ("b.PNG", true, false),
        ("c.png.gz", true, true),
        ("d.svg", false, false),
        ("e", false, false),
        ("f.svg.gz", false, true),
    ] {
        let path = dir.path().join(name);
        stdout_of(delmesh().arg("render").arg(&mesh).arg("-o").arg(&path));
        let bytes = if gz {
            gunzip(&path)
        } else {
            std::fs::read(&path).unwrap()
        };
        let magic: &[u8] = if png { b"\x89PNG" } else { b"<svg" };
        assert!(bytes.starts_with(magic), "{name}");
    }
    for name in ["g.jpg", "h.svgz", "i.pdf.gz"] {
        let path = dir.path().join(name);
        let out = delmesh()
            .arg("render")
            .arg(&mesh)
            .arg("-o")
            .arg(&path)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains("draws SVG and PNG pictures only"), "{stderr}");
        assert!(!path.exists());
    }
    let out_mesh = dir.path().join("m.obj");
    let chart = dir.path().join("chart.jpg");
    let out = delmesh()
        .args(["-all", "-i"])
        .arg(&mesh)
        .arg("-o")
        .arg(&out_mesh)
        .arg("--chart")
        .arg(&chart)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("--chart"), "{stderr}");
    assert!(stderr.contains("draws SVG and PNG pictures only"), "{stderr}");
    assert!(!chart.exists() && !dir.path().join("m-s-0-m.obj").exists());
}
