//! `delmesh batch`: many inputs in one process write exactly what one run
//! per input writes, a failing file does not stop the others, and what
//! would overwrite an input or collide is refused before any work.

mod common;

use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn delmesh() -> Command {
    Command::cargo_bin("delmesh").unwrap()
}

/// The shipped meshes (`data/*.obj` and the CAD rotor).
fn inputs() -> Vec<PathBuf> {
    let mut v = common::fixtures();
    v.push(common::data_dir().join("cad/rotor.obj"));
    v
}

/// Runs `delmesh batch ARGS`, returning (success, stdout, stderr).
fn batch<P: AsRef<std::ffi::OsStr>>(args: &[&str], files: &[P]) -> (bool, String, String) {
    let out = delmesh().arg("batch").args(args).args(files).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The lines of a batch's stdout without their timings.
fn without_seconds(stdout: &str) -> Vec<String> {
    stdout
        .lines()
        .map(|l| l.rsplit_once(" (").map_or(l, |(head, _)| head).to_string())
        .map(|l| l.split("; 0.").next().unwrap().to_string())
        .collect()
}

/// A book of three triangles on one edge (non-manifold: refused without
/// --repair), written into `dir`.
fn write_book(dir: &Path) -> PathBuf {
    let book = dir.join("book.obj");
    std::fs::write(
        &book,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
    )
    .unwrap();
    book
}

fn check_passes(input: &Path, output: &Path) {
    let out = delmesh().arg("check").arg(input).arg(output).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && stdout.contains("PASS"),
        "{}: {stdout}",
        output.display()
    );
}

#[test]
fn batch_writes_what_one_run_per_input_writes() {
    let files = inputs();
    for settings in [&[][..], &["--ds", "queue", "-s", "0", "--prune"][..]] {
        let dir = tempfile::tempdir().unwrap();
        let out_dir = dir.path().join("out");
        let mut args = vec!["-d", out_dir.to_str().unwrap(), "-j", "2"];
        args.extend_from_slice(settings);
        let (ok, stdout, stderr) = batch(&args, &files);
        assert!(ok, "{stdout}{stderr}");
        let lines: Vec<&str> = stdout.lines().collect();
        assert_eq!(lines.len(), files.len() + 1, "{stdout}");
        assert!(lines[files.len()].starts_with(&format!(
            "batch   {} files: {} written, 0 failed",
            files.len(),
            files.len()
        )));
        for (file, line) in files.iter().zip(&lines) {
            // Reported in the order given.
            assert!(line.starts_with(&format!("ok      {} -> ", file.display())), "{line}");
            let name = file.file_name().unwrap();
            let written = out_dir.join(name);
            let single = dir.path().join("single.obj");
            let status = delmesh()
                .arg("-q")
                .arg("-i")
                .arg(file)
                .arg("-o")
                .arg(&single)
                .args(settings)
                .output()
                .unwrap();
            assert!(status.status.success());
            assert_eq!(
                std::fs::read(&written).unwrap(),
                std::fs::read(&single).unwrap(),
                "{} {settings:?}: batch and single run differ",
                file.display()
            );
            check_passes(file, &written);
        }
    }
}

#[test]
fn batch_check_verifies_every_output() {
    let files = inputs();
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let (ok, stdout, stderr) = batch(&["-d", out_dir.to_str().unwrap(), "--check", "-s", "3"], &files);
    assert!(ok, "{stdout}{stderr}");
    assert_eq!(stdout.matches(", check PASS").count(), files.len(), "{stdout}");
    // The repaired input is what a repaired output is checked against.
    let book = write_book(dir.path());
    let (ok, stdout, stderr) = batch(&["-d", out_dir.to_str().unwrap(), "--check", "--repair"], &[&book]);
    assert!(ok, "{stdout}{stderr}");
    assert!(stdout.contains("check PASS"), "{stdout}");
    // Nothing but the outputs is left in the folder.
    let mut left: Vec<String> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    left.sort();
    assert!(left.is_empty(), "{left:?}");
}

/// `--repaired-inputs` writes beside each output the repaired input it was
/// made from, byte for byte what the main command's `--repaired` writes, and
/// the output checks against it; a file is finished only with it; a
/// repaired input whose name an output takes is refused before any work.
#[test]
fn repaired_inputs_are_written_beside_the_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let book = write_book(dir.path());
    let out_dir = dir.path().join("out");
    let d = out_dir.to_str().unwrap();
    let refused = delmesh()
        .args(["batch", "-d", d, "--repaired-inputs"])
        .arg(&book)
        .output()
        .unwrap();
    assert!(!refused.status.success() && !out_dir.exists());
    let json = dir.path().join("runs.json");
    let (ok, stdout, stderr) = batch(
        &[
            "-d",
            d,
            "--repair",
            "--repaired-inputs",
            "--stats-json",
            json.to_str().unwrap(),
        ],
        &[&book],
    );
    assert!(ok, "{stdout}{stderr}");
    let repaired = out_dir.join("book.repaired.obj");
    check_passes(&repaired, &out_dir.join("book.obj"));
    let one = dir.path().join("one");
    std::fs::create_dir(&one).unwrap();
    delmesh()
        .args(["-q", "--repair", "--repaired"])
        .arg(one.join("repaired.obj"))
        .arg("-i")
        .arg(&book)
        .arg("-o")
        .arg(one.join("book.obj"))
        .assert()
        .success();
    assert_eq!(
        std::fs::read(&repaired).unwrap(),
        std::fs::read(one.join("repaired.obj")).unwrap()
    );
    let doc = std::fs::read_to_string(&json).unwrap();
    assert!(
        doc.contains(&format!("\"repaired\": \"{}\"", repaired.display())),
        "{doc}"
    );
    // Without its repaired input, an output is not a finished file.
    std::fs::remove_file(&repaired).unwrap();
    let (ok, stdout, _) = batch(&["-d", d, "--repair", "--repaired-inputs", "--skip-existing"], &[&book]);
    assert!(ok && stdout.contains("1 written"), "{stdout}");
    assert!(repaired.exists());
    // An input named as another's repaired input would collide.
    let other = dir.path().join("two");
    std::fs::create_dir(&other).unwrap();
    std::fs::copy(&book, other.join("book.repaired.obj")).unwrap();
    let (ok, _, stderr) = batch(
        &["-d", d, "--repair", "--repaired-inputs"],
        &[book.clone(), other.join("book.repaired.obj")],
    );
    assert!(!ok && stderr.contains("book.repaired.obj"), "{stderr}");
}

#[test]
fn batch_output_does_not_depend_on_jobs() {
    let files = inputs();
    let dir = tempfile::tempdir().unwrap();
    let run = |jobs: &str| {
        let out_dir = dir.path().join(format!("out-{jobs}"));
        let (ok, stdout, stderr) = batch(&["-d", out_dir.to_str().unwrap(), "-j", jobs], &files);
        assert!(ok, "{stderr}");
        let contents: Vec<Vec<u8>> = files
            .iter()
            .map(|f| std::fs::read(out_dir.join(f.file_name().unwrap())).unwrap())
            .collect();
        let lines: Vec<String> = without_seconds(&stdout)
            .into_iter()
            .map(|l| l.replace(&format!("out-{jobs}"), "out"))
            .collect();
        (contents, lines)
    };
    let (one, one_lines) = run("1");
    let (two, two_lines) = run("2");
    assert_eq!(one, two);
    // The summary names the number of workers; every file's line is the same.
    let n = files.len();
    assert_eq!(one_lines[..n], two_lines[..n]);
}

#[test]
fn a_failing_file_does_not_stop_the_others() {
    let dir = tempfile::tempdir().unwrap();
    let book = write_book(dir.path());
    let missing = dir.path().join("missing.obj");
    let cube = common::data_dir().join("cube.obj");
    let out_dir = dir.path().join("out");
    let csv = dir.path().join("runs.csv");
    let files = [book.clone(), missing.clone(), cube.clone()];
    let (ok, stdout, stderr) = batch(
        &["-d", out_dir.to_str().unwrap(), "--stats-csv", csv.to_str().unwrap()],
        &files,
    );
    assert!(!ok);
    let errors: Vec<&str> = stderr.lines().collect();
    assert_eq!(errors.len(), 2, "{stderr}");
    assert!(
        errors[0].starts_with(&format!("delmesh: {}", book.display())),
        "{stderr}"
    );
    assert!(
        errors[1].starts_with(&format!("delmesh: {}", missing.display())),
        "{stderr}"
    );
    assert!(stdout.contains("batch   3 files: 1 written, 2 failed"), "{stdout}");
    let written: Vec<_> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(written, ["cube.obj"]);
    check_passes(&cube, &out_dir.join("cube.obj"));
    // One CSV row per input, the main command's columns.
    let table = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = table.lines().collect();
    assert_eq!(rows.len(), 4, "{table}");
    assert!(rows[0].starts_with("input,data_structure,score,median,shells,output,ok,error_kind,error,"));
    let ok_cell = |row: &str| row.split(',').nth(6).unwrap().to_string();
    assert_eq!([1, 2, 3].map(|i| ok_cell(rows[i])), ["false", "false", "true"]);
    assert!(rows[1].starts_with(&book.display().to_string()));
    // With --repair the book goes through too.
    let (ok, stdout, stderr) = batch(&["-d", out_dir.to_str().unwrap(), "--repair"], &[&book]);
    assert!(ok, "{stdout}{stderr}");
    assert!(stdout.contains("repair: "), "{stdout}");
}

#[test]
fn collisions_and_overwrites_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir(&a).unwrap();
    std::fs::create_dir(&b).unwrap();
    let cube = common::data_dir().join("cube.obj");
    std::fs::copy(&cube, a.join("cube.obj")).unwrap();
    std::fs::copy(&cube, b.join("cube.obj")).unwrap();
    let out_dir = dir.path().join("out");
    let (ok, _, stderr) = batch(
        &["-d", out_dir.to_str().unwrap()],
        &[a.join("cube.obj"), b.join("cube.obj")],
    );
    assert!(!ok);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("would both be written to"), "{stderr}");
    assert!(!out_dir.exists(), "the output folder was created");
    // Into the input's own folder, in its own format: refused, input kept.
    let before = std::fs::read(a.join("cube.obj")).unwrap();
    let (ok, _, stderr) = batch(&["-d", a.to_str().unwrap()], &[a.join("cube.obj")]);
    assert!(!ok);
    assert!(stderr.contains("would overwrite an input"), "{stderr}");
    assert_eq!(std::fs::read(a.join("cube.obj")).unwrap(), before);
    // Vertex maps are named after the output's stem: a.obj and a.off would
    // share one.
    let off = dir.path().join("b/cube.off");
    let run = delmesh()
        .args(["-i", cube.to_str().unwrap(), "-o", off.to_str().unwrap(), "-q"])
        .output()
        .unwrap();
    assert!(run.status.success());
    let (ok, _, stderr) = batch(
        &["-d", out_dir.to_str().unwrap(), "--vertex-maps"],
        &[a.join("cube.obj"), off.clone()],
    );
    assert!(!ok);
    assert!(stderr.contains("cube.vertex-map.csv"), "{stderr}");
    let (ok, _, stderr) = batch(&["-d", out_dir.to_str().unwrap()], &[a.join("cube.obj"), off]);
    assert!(ok, "{stderr}");
    // A CSV that would replace an output is refused too.
    let (ok, _, stderr) = batch(
        &[
            "-d",
            out_dir.to_str().unwrap(),
            "--stats-csv",
            out_dir.join("cube.obj").to_str().unwrap(),
        ],
        &[a.join("cube.obj")],
    );
    assert!(!ok);
    assert!(stderr.contains("would overwrite an input or an output"), "{stderr}");
    // In another format it is a new file beside it.
    let (ok, _, stderr) = batch(&["-d", a.to_str().unwrap(), "--format", "off"], &[a.join("cube.obj")]);
    assert!(ok, "{stderr}");
    assert!(a.join("cube.off").exists());
    assert_eq!(std::fs::read(a.join("cube.obj")).unwrap(), before);
}

#[cfg(unix)]
#[test]
fn an_output_or_vertex_map_linked_to_an_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("cube.obj");
    std::fs::copy(common::data_dir().join("cube.obj"), &input).unwrap();
    let before = std::fs::read(&input).unwrap();
    // The output's name in the folder is a symbolic link to the input (the
    // writer follows links), then the vertex map's.
    for link in ["cube.obj", "cube.vertex-map.csv"] {
        let out_dir = dir.path().join(format!("out-{link}"));
        std::fs::create_dir(&out_dir).unwrap();
        std::os::unix::fs::symlink("../cube.obj", out_dir.join(link)).unwrap();
        let (ok, _, stderr) = batch(
            &["-d", out_dir.to_str().unwrap(), "--vertex-maps"],
            std::slice::from_ref(&input),
        );
        assert!(!ok, "{link}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains("would overwrite an input"), "{stderr}");
        assert_eq!(std::fs::read(&input).unwrap(), before, "{link}");
    }
    // A folder the run created is not left behind empty: after a refusal
    // (the CSV would replace the input), or when every input fails.
    let out_dir = dir.path().join("new");
    let (ok, _, _) = batch(
        &["-d", out_dir.to_str().unwrap(), "--stats-csv", input.to_str().unwrap()],
        std::slice::from_ref(&input),
    );
    assert!(!ok);
    assert!(!out_dir.exists(), "an empty output folder was left");
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\n").unwrap();
    let (ok, _, _) = batch(&["-d", out_dir.to_str().unwrap()], std::slice::from_ref(&bad));
    assert!(!ok);
    assert!(!out_dir.exists(), "an empty output folder was left");
}

#[test]
fn a_folder_stands_for_its_mesh_files() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    std::fs::create_dir_all(input.join("sub")).unwrap();
    let cube = common::data_dir().join("cube.obj");
    std::fs::copy(&cube, input.join("b.obj")).unwrap();
    std::fs::copy(&cube, input.join("sub/ignored.obj")).unwrap();
    std::fs::write(input.join("notes.txt"), "not a mesh").unwrap();
    // A gzip-compressed copy, with an upper-case extension.
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    std::io::Write::write_all(&mut gz, &std::fs::read(&cube).unwrap()).unwrap();
    std::fs::write(input.join("a.OBJ.gz"), gz.finish().unwrap()).unwrap();
    let out_dir = dir.path().join("out");
    let (ok, stdout, stderr) = batch(&["-d", out_dir.to_str().unwrap(), "--format", "ply"], &[&input]);
    assert!(ok, "{stdout}{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 3, "{stdout}");
    assert!(lines[0].starts_with(&format!("ok      {} -> ", input.join("a.OBJ.gz").display())));
    assert!(lines[1].starts_with(&format!("ok      {} -> ", input.join("b.obj").display())));
    let mut written: Vec<String> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    written.sort();
    assert_eq!(written, ["a.ply", "b.ply"]);
    check_passes(&cube, &out_dir.join("a.ply"));
    // A folder with no mesh in it is an error, not an empty success.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let (ok, _, stderr) = batch(&["-d", out_dir.to_str().unwrap()], &[empty]);
    assert!(!ok);
    assert!(stderr.contains("no mesh files"), "{stderr}");
}

/// With --recursive a folder stands for the mesh files in its whole tree,
/// and the tree is mirrored under the output folder: files of one name in
/// different subfolders (a dataset's `train/` and `test/`) no longer
/// collide. Each output is the main command's, byte for byte; symbolic
/// links to folders are not followed (a loop would never end), the output
/// folder inside the tree is left out (a second run reads the same files),
/// folders made for outputs that all failed are removed again, and
/// without the flag a folder whose meshes are all in subfolders says so.
#[cfg(unix)]
#[test]
fn recursive_mirrors_a_folder_tree() {
    let dir = tempfile::tempdir().unwrap();
    let tree = dir.path().join("data");
    for sub in ["train/deep", "test", "broken", "links"] {
        std::fs::create_dir_all(tree.join(sub)).unwrap();
    }
    let fixture = |name: &str| common::data_dir().join(name);
    std::fs::copy(fixture("cube.obj"), tree.join("train/model.obj")).unwrap();
    std::fs::copy(fixture("bunny.obj"), tree.join("test/model.obj")).unwrap();
    std::fs::copy(fixture("elephant.obj"), tree.join("train/deep/n.obj")).unwrap();
    write_book(&tree.join("broken"));
    std::os::unix::fs::symlink(&tree, tree.join("links/loop")).unwrap();
    let out_dir = tree.join("out");
    let out = out_dir.to_str().unwrap();

    let (ok, _, stderr) = batch(&["-d", out], &[&tree]);
    assert!(!ok);
    assert!(
        stderr.contains("no mesh files in this folder (4 in its subfolders: --recursive takes them)"),
        "{stderr}"
    );
    assert!(!out_dir.exists());

    for run in 0..2 {
        let (ok, stdout, stderr) = batch(&["-r", "-d", out], &[&tree]);
        assert!(!ok, "the book is refused without --repair");
        assert!(stderr.contains("book.obj"), "{stderr}");
        let lines = without_seconds(&stdout);
        let shown = |input: &str, output: &str| {
            format!(
                "ok      {} -> {}",
                tree.join(input).display(),
                out_dir.join(output).display()
            )
        };
        assert!(
            lines[0].starts_with(&shown("test/model.obj", "test/model.obj")),
            "{run}: {stdout}"
        );
        assert!(
            lines[1].starts_with(&shown("train/model.obj", "train/model.obj")),
            "{stdout}"
        );
        assert!(
            lines[2].starts_with(&shown("train/deep/n.obj", "train/deep/n.obj")),
            "{stdout}"
        );
        assert_eq!(lines.len(), 4, "{stdout}");
        assert!(lines[3].starts_with("batch   4 files: 3 written, 1 failed"), "{stdout}");
        // The failed file's folder is not left behind.
        assert!(!out_dir.join("broken").exists());
    }
    for (input, output) in [
        ("test/model.obj", "test/model.obj"),
        ("train/model.obj", "train/model.obj"),
        ("train/deep/n.obj", "train/deep/n.obj"),
    ] {
        let single = dir.path().join("single.obj");
        let run = delmesh()
            .arg("-q")
            .arg("-i")
            .arg(tree.join(input))
            .arg("-o")
            .arg(&single)
            .output()
            .unwrap();
        assert!(run.status.success());
        assert_eq!(
            std::fs::read(out_dir.join(output)).unwrap(),
            std::fs::read(&single).unwrap(),
            "{output}"
        );
        check_passes(&tree.join(input), &out_dir.join(output));
    }
}

#[test]
fn skip_existing_resumes_a_batch() {
    let files = inputs();
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let (ok, _, stderr) = batch(&["-d", out_dir.to_str().unwrap()], &files[..2]);
    assert!(ok, "{stderr}");
    let first = std::fs::read(out_dir.join(files[0].file_name().unwrap())).unwrap();
    // Make the second look stale: it must be left alone all the same.
    let second = out_dir.join(files[1].file_name().unwrap());
    std::fs::write(&second, "stale").unwrap();
    let csv = dir.path().join("runs.csv");
    let (ok, stdout, stderr) = batch(
        &[
            "-d",
            out_dir.to_str().unwrap(),
            "--skip-existing",
            "--stats-csv",
            csv.to_str().unwrap(),
        ],
        &files,
    );
    assert!(ok, "{stderr}");
    let n = files.len();
    assert_eq!(stdout.matches("skip    ").count(), 2, "{stdout}");
    assert!(
        stdout.contains(&format!("batch   {n} files: {} written, 2 skipped, 0 failed", n - 2)),
        "{stdout}"
    );
    assert_eq!(
        std::fs::read(out_dir.join(files[0].file_name().unwrap())).unwrap(),
        first
    );
    assert_eq!(std::fs::read_to_string(&second).unwrap(), "stale");
    for f in &files[2..] {
        check_passes(f, &out_dir.join(f.file_name().unwrap()));
    }
    // Only the files refined this time have a CSV row.
    assert_eq!(std::fs::read_to_string(&csv).unwrap().lines().count(), 1 + n - 2);
}

/// `batch --smallest` writes for each file what `delmesh --smallest` writes,
/// names the settings it kept, and does not depend on -j; each output
/// passes the check.
#[test]
fn batch_smallest_writes_what_one_smallest_run_writes() {
    let files = common::fixtures();
    let dir = tempfile::tempdir().unwrap();
    let mut outputs = Vec::new();
    for jobs in ["1", "2"] {
        let out_dir = dir.path().join(format!("out{jobs}"));
        let (ok, stdout, stderr) = batch(&["-d", out_dir.to_str().unwrap(), "--smallest", "-j", jobs], &files);
        assert!(ok, "{stdout}{stderr}");
        let lines: Vec<&str> = stdout.lines().collect();
        assert_eq!(lines.len(), files.len() + 1, "{stdout}");
        for line in &lines[..files.len()] {
            assert!(line.contains(" pruned) [smallest: "), "{line}");
        }
        assert!(lines[files.len()].contains("(one file at a time, "), "{stdout}");
        outputs.push(out_dir);
    }
    for file in &files {
        let name = file.file_name().unwrap();
        let single = dir.path().join("single.obj");
        let run = delmesh()
            .args(["-q", "--smallest", "-i"])
            .arg(file)
            .arg("-o")
            .arg(&single)
            .output()
            .unwrap();
        assert!(run.status.success());
        for out_dir in &outputs {
            assert_eq!(
                std::fs::read(out_dir.join(name)).unwrap(),
                std::fs::read(&single).unwrap(),
                "{}: batch --smallest and delmesh --smallest differ",
                file.display()
            );
        }
        check_passes(file, &outputs[0].join(name));
    }
}

/// Runs `batch` on the one file `input` (with a CSV), which must stop with
/// stuck edges: the batch fails, says so on one line, and the CSV keeps the
/// kind of error. Returns that line.
fn batch_stuck(input: &Path, out_dir: &Path, csv: &Path) -> String {
    let (ok, stdout, stderr) = batch(
        &["-d", out_dir.to_str().unwrap(), "--stats-csv", csv.to_str().unwrap()],
        &[input],
    );
    assert!(!ok, "{stdout}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    let rows = std::fs::read_to_string(csv).unwrap();
    assert!(rows.contains(",unsplittable,"), "{rows}");
    stderr
}

/// A file stuck with the given settings is reported on one line that points
/// to --smallest; with it, the file is written and passes the check.
#[test]
fn batch_points_a_stuck_file_to_smallest() {
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions/bug-refine-theta-min-zero-needle.obj");
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let stderr = batch_stuck(&input, &out_dir, &dir.path().join("runs.csv"));
    assert!(
        stderr.contains("neither split") && stderr.contains("--smallest"),
        "{stderr}"
    );
    let (ok, stdout, stderr) = batch(&["-d", out_dir.to_str().unwrap(), "--smallest"], &[&input]);
    assert!(ok, "{stdout}{stderr}");
    check_passes(&input, &out_dir.join(input.file_name().unwrap()));
}

/// A file stuck at near-coincident vertices is reported with the weld that
/// merges them, not --smallest (most settings stall there); welded,
/// it is written with no note on them, and passes the check against the
/// repaired input.
#[test]
fn batch_names_the_weld_for_near_coincident_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::marching_sphere_obj(dir.path(), 8, 1e-10);
    let out_dir = dir.path().join("out");
    let stderr = batch_stuck(&input, &out_dir, &dir.path().join("runs.csv"));
    assert!(
        stderr.contains("neither split")
            && stderr.contains("--repair --weld-tolerance 2.5e-7 merges them")
            && !stderr.contains("--smallest"),
        "{stderr}"
    );
    let weld = ["--repair", "--weld-tolerance", "2.5e-7"];
    let (ok, stdout, stderr) = batch(&[&["-d", out_dir.to_str().unwrap()][..], &weld].concat(), &[&input]);
    assert!(ok, "{stdout}{stderr}");
    assert!(!stdout.contains("near-coincident"), "{stdout}");
    let repaired = dir.path().join("repaired.obj");
    delmesh()
        .args(weld)
        .args(["--no-refine", "-q", "-i"])
        .arg(&input)
        .arg("-o")
        .arg(&repaired)
        .assert()
        .success();
    check_passes(&repaired, &out_dir.join("sphere.obj"));
}

/// A folder's files are found by extension whatever the rest of their
/// name: one whose name is not UTF-8 was skipped without a word (it was
/// refined when named directly). Its output keeps the name's bytes.
#[cfg(unix)]
#[test]
fn a_folder_includes_names_that_are_not_utf8() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir(&inputs).unwrap();
    let odd = std::ffi::OsStr::from_bytes(b"bad\xff.obj");
    std::fs::copy(common::data_dir().join("cube.obj"), inputs.join(odd)).unwrap();
    std::fs::copy(common::data_dir().join("cube.obj"), inputs.join("plain.obj")).unwrap();
    let out = dir.path().join("out");
    let (ok, stdout, stderr) = batch(&["-q", "-d", out.to_str().unwrap()], &[&inputs]);
    assert!(ok, "{stdout}{stderr}");
    assert!(out.join(odd).exists() && out.join("plain.obj").exists());
}

/// With --vertex-maps a file is finished only with its map: when the map
/// cannot be written the output is not put in place (it would stand as
/// finished, and --skip-existing then never make the map), and
/// --skip-existing redoes a file whose map is missing.
#[test]
fn an_output_without_its_vertex_map_is_not_finished() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cube = common::data_dir().join("cube.obj");
    let map = out.join("cube.vertex-map.csv");
    std::fs::create_dir_all(&map).unwrap(); // a folder where the map goes
    let d = out.to_str().unwrap();
    let (ok, _, stderr) = batch(&["-q", "-d", d, "--vertex-maps"], &[&cube]);
    assert!(!ok);
    assert!(
        stderr.contains("cube.vertex-map.csv: is a folder, not a file (") && stderr.contains("cube.obj not written)"),
        "{stderr}"
    );
    assert!(!out.join("cube.obj").exists());
    std::fs::remove_dir(&map).unwrap();
    let (ok, _, stderr) = batch(&["-q", "-d", d], &[&cube]);
    assert!(ok, "{stderr}");
    assert!(!map.exists());
    let (ok, stdout, stderr) = batch(&["-d", d, "--vertex-maps", "--skip-existing"], &[&cube]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("1 written, 0 skipped"), "{stdout}");
    assert!(map.exists());
    let (ok, stdout, _) = batch(&["-d", d, "--vertex-maps", "--skip-existing"], &[&cube]);
    assert!(ok && stdout.contains("0 written, 1 skipped"), "{stdout}");
}

/// A folder where one output goes fails that file alone, before reading it,
/// whichever place it has in the batch; --skip-existing does not take the
/// folder for a finished file.
#[test]
fn a_folder_in_an_outputs_place_fails_that_file_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cube = common::data_dir().join("cube.obj");
    let bunny = common::data_dir().join("bunny.obj");
    let d = out.to_str().unwrap();
    for (folder, written) in [("cube.obj", "bunny.obj"), ("bunny.obj", "cube.obj")] {
        std::fs::create_dir_all(out.join(folder)).unwrap();
        for extra in [&[][..], &["--skip-existing"][..]] {
            let args: Vec<&str> = ["-d", d].iter().copied().chain(extra.iter().copied()).collect();
            let (ok, stdout, stderr) = batch(&args, &[&cube, &bunny]);
            assert!(!ok, "{stdout}");
            let message = format!(
                "delmesh: {}: output is a folder, not a file",
                out.join(folder).display()
            );
            assert_eq!(stderr.trim_end(), message);
            assert!(stdout.contains("1 failed"), "{stdout}");
            assert!(out.join(folder).is_dir());
            check_passes(&common::data_dir().join(written), &out.join(written));
        }
        std::fs::remove_dir_all(&out).unwrap();
    }
}

#[test]
fn a_report_that_cannot_be_written_fails_after_the_summary() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let cube = common::data_dir().join("cube.obj");
    for flag in ["--stats-json", "--stats-csv"] {
        let (ok, stdout, stderr) = batch(&["--out-dir", out_dir.to_str().unwrap(), flag, "/dev/full"], &[&cube]);
        assert!(!ok, "{flag}: {stderr}");
        assert!(
            stdout.contains("batch   1 file: 1 written, 0 failed"),
            "{flag}: {stdout}"
        );
        assert_eq!(stderr.lines().count(), 1, "{flag}: {stderr}");
        assert!(stderr.contains("/dev/full: cannot write"), "{flag}: {stderr}");
        assert!(out_dir.join("cube.obj").exists());
    }
}

/// A file name with a line feed in it gets one escaped line, not two.
#[test]
fn file_names_with_line_feeds_keep_to_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let (inp, out) = (dir.path().join("in"), dir.path().join("out"));
    std::fs::create_dir_all(&inp).unwrap();
    std::fs::copy(common::data_dir().join("cube.obj"), inp.join("a\nb.obj")).unwrap();
    let out_arg = out.to_str().unwrap();
    let (ok, stdout, stderr) = batch(&["-d", out_arg], &[&inp]);
    assert!(ok, "{stderr}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("ok"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(line.contains("a\\nb.obj -> ") && line.ends_with(" s)"), "{stdout}");
    assert!(out.join("a\nb.obj").exists());
}

/// Standard input has no name to name an output after: `-` is refused
/// before any work, not written to `OUT/-.obj`.
#[test]
fn standard_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    for dash in ["-", "/dev/stdin"] {
        let run = Command::cargo_bin("delmesh")
            .unwrap()
            .args(["batch", "-d"])
            .arg(&out)
            .arg(dash)
            .write_stdin(std::fs::read(common::data_dir().join("bunny.obj")).unwrap())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains("batch reads mesh files, not standard input"),
            "{stderr}"
        );
        assert!(!out.exists());
    }
}

/// The reader's notes (data after the faces a header declares, so faces
/// may be missing) are printed with `--repair` and `--drop-attributes` too,
/// by `batch` and by the main command: the repair path started a fresh list
/// and dropped them, and `--drop-attributes` cleared all notes.
#[test]
fn the_readers_notes_are_kept_with_repair_and_without_attributes() {
    let dir = tempfile::tempdir().unwrap();
    let off = dir.path().join("tetra.off");
    std::fs::write(
        &off,
        "OFF\n4 3 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n",
    )
    .unwrap();
    let note = "line 10: data after the 3 faces the OFF header declares ignored";
    let out_dir = dir.path().join("out");
    for flags in [&[][..], &["--repair"], &["--drop-attributes"]] {
        let (ok, stdout, stderr) = batch(&[&["-d", out_dir.to_str().unwrap()][..], flags].concat(), &[&off]);
        assert!(ok, "{stdout}{stderr}");
        assert!(stdout.contains(&format!("note: {note}")), "{flags:?}: {stdout}");
        let run = delmesh()
            .args(flags)
            .arg("-i")
            .arg(&off)
            .arg("-o")
            .arg(dir.path().join("tetra.obj"))
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&run.stdout);
        assert!(run.status.success(), "{stdout}");
        assert!(stdout.contains(&format!("note    {note}")), "{flags:?}: {stdout}");
    }
}
