//! `--stats-json` and `--stats-csv` against the field table of README.md:
//! every documented field is in the output with the documented type, every
//! field of the output is documented, and the CSV's columns are the run
//! fields in the documented order.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use assert_cmd::Command;
use serde_json::Value;

fn delmesh() -> Command {
    let mut c = Command::cargo_bin("delmesh").unwrap();
    c.env_remove("DELMESH_PROGRESS_DELAY_MS");
    c
}

/// The README's JSON field table: path (`runs[].faces`) → type
/// (`integer or null`), in order.
fn documented_fields() -> Vec<(String, String)> {
    let fields = table_fields("json-fields");
    assert!(fields.len() > 30, "{fields:?}");
    fields
}

/// The README's table between `<!-- NAME:begin -->` and `<!-- NAME:end -->`.
fn table_fields(name: &str) -> Vec<(String, String)> {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let begin = readme
        .find(&format!("<!-- {name}:begin -->"))
        .expect("README has the field table");
    let end = readme
        .find(&format!("<!-- {name}:end -->"))
        .expect("the field table ends");
    let mut fields = Vec::new();
    for line in readme[begin..end].lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // "| `path` | type | meaning |" → ["", "`path`", "type", "meaning", ""]
        if cells.len() >= 4 && cells[1].starts_with('`') {
            fields.push((cells[1].trim_matches('`').to_string(), cells[2].to_string()));
        }
    }
    fields
}

/// Whether `v` is of the documented type `ty` (`T` or `T or null`).
fn has_type(v: &Value, ty: &str) -> bool {
    let (base, nullable) = match ty.strip_suffix(" or null") {
        Some(b) => (b, true),
        None => (ty, false),
    };
    if v.is_null() {
        return nullable;
    }
    match base {
        "string" => v.is_string(),
        "integer" => v.is_u64(),
        "number" => v.is_number(),
        "boolean" => v.is_boolean(),
        "object" => v.is_object(),
        "array of strings" => v.as_array().is_some_and(|a| a.iter().all(Value::is_string)),
        "array of objects" => v.as_array().is_some_and(|a| a.iter().all(Value::is_object)),
        other => panic!("README uses an unknown type {other:?}"),
    }
}

/// Every path in `v`: objects' fields by name, arrays' elements as `[]`;
/// arrays of scalars are leaves.
fn paths(v: &Value, prefix: &str, out: &mut Vec<String>) {
    match v {
        Value::Object(map) => {
            for (k, x) in map {
                let p = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                out.push(p.clone());
                paths(x, &p, out);
            }
        }
        Value::Array(items) => {
            for x in items.iter().filter(|x| x.is_object()) {
                paths(x, &format!("{prefix}[]"), out);
            }
        }
        _ => {}
    }
}

/// The values at a documented path (several under `runs[]`).
fn lookup<'a>(v: &'a Value, path: &str) -> Vec<&'a Value> {
    let mut current = vec![v];
    for part in path.split('.') {
        let (name, each) = match part.strip_suffix("[]") {
            Some(n) => (n, true),
            None => (part, false),
        };
        let mut next = Vec::new();
        for c in current {
            let x = c
                .get(name)
                .unwrap_or_else(|| panic!("{path}: no field {name:?} in {c}"));
            if each {
                next.extend(x.as_array().unwrap_or_else(|| panic!("{path}: {name} is not an array")));
            } else {
                next.push(x);
            }
        }
        current = next;
    }
    current
}

/// Checks a document against the README both ways.
fn validate(doc: &Value) {
    validate_with(doc, &documented_fields(), None);
}

/// Checks `doc` against `fields` both ways, leaving out the paths under
/// `nested` (an array of documents checked on their own).
fn validate_with(doc: &Value, fields: &[(String, String)], nested: Option<&str>) {
    for (path, ty) in fields {
        for v in lookup(doc, path) {
            assert!(has_type(v, ty), "{path}: {v} is not {ty}");
        }
    }
    let mut found = Vec::new();
    paths(doc, "", &mut found);
    found.retain(|p| nested.is_none_or(|n| !p.starts_with(&format!("{n}[]."))));
    for p in found {
        assert!(
            fields.iter().any(|(f, _)| *f == p),
            "{p} is in the JSON but not in README's table"
        );
    }
}

/// The CSV rows as header → cell maps, after checking the header.
fn read_csv(text: &str) -> Vec<BTreeMap<String, String>> {
    let mut lines = text.lines();
    let header: Vec<String> = split_csv(lines.next().expect("a header"));
    let mut expected = vec!["input".to_string()];
    expected.extend(
        documented_fields()
            .into_iter()
            .filter_map(|(p, _)| p.strip_prefix("runs[].").map(str::to_string)),
    );
    assert_eq!(
        header, expected,
        "CSV columns are `input` and the documented run fields"
    );
    lines
        .map(|l| {
            let cells = split_csv(l);
            assert_eq!(cells.len(), header.len(), "{l}");
            header.iter().cloned().zip(cells).collect()
        })
        .collect()
}

/// Splits one CSV line (RFC 4180 quoting).
fn split_csv(line: &str) -> Vec<String> {
    let mut cells = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                cells.last_mut().unwrap().push('"');
            }
            '"' => quoted = !quoted,
            ',' if !quoted => cells.push(String::new()),
            c => cells.last_mut().unwrap().push(c),
        }
    }
    cells
}

/// The CSV cell a JSON value becomes.
fn cell_of(v: &Value) -> String {
    match v {
        Value::Null => String::new(),
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Checks that each CSV row holds its JSON run record.
fn csv_matches_json(rows: &[BTreeMap<String, String>], doc: &Value) {
    let runs = doc["runs"].as_array().unwrap();
    assert_eq!(rows.len(), runs.len());
    for (row, run) in rows.iter().zip(runs) {
        assert_eq!(row["input"], doc["input"]["path"].as_str().unwrap());
        for (k, v) in run.as_object().unwrap() {
            let cell = &row[k];
            match v {
                Value::Number(n) if !n.is_u64() => {
                    let x: f64 = cell.parse().unwrap();
                    assert_eq!(x, n.as_f64().unwrap(), "{k}");
                }
                _ => assert_eq!(*cell, cell_of(v), "{k}"),
            }
        }
    }
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Runs delmesh on the bunny with `extra` flags, `--stats-json` and
/// `--stats-csv`; checks that it succeeds, that the JSON document is valid
/// and that the CSV matches it. Returns the printout and the document.
fn bunny_with_stats(extra: &[&str]) -> (String, Value) {
    let dir = tempfile::tempdir().unwrap();
    let (json, csv) = (dir.path().join("s.json"), dir.path().join("s.csv"));
    let out = delmesh()
        .arg("-i")
        .arg(common::data_dir().join("bunny.obj"))
        .arg("-o")
        .arg(dir.path().join("b.obj"))
        .args(extra)
        .arg("--stats-json")
        .arg(&json)
        .arg("--stats-csv")
        .arg(&csv)
        .output()
        .unwrap();
    assert!(out.status.success());
    let doc = read_json(&json);
    validate(&doc);
    csv_matches_json(&read_csv(&std::fs::read_to_string(&csv).unwrap()), &doc);
    (String::from_utf8_lossy(&out.stdout).into_owned(), doc)
}

#[test]
fn single_run_json_and_csv_match_the_readme_and_the_summary() {
    let (stdout, doc) = bunny_with_stats(&[]);
    // Every figure of the printed summary is in the JSON.
    let input = &doc["input"];
    let run = &doc["runs"][0];
    let sig = |x: &Value| {
        // The summary prints six significant digits.
        let x = x.as_f64().unwrap();
        let decimals = (5 - x.abs().log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    };
    let c = &doc["constants"];
    let s = &doc["seconds"];
    for expected in [
        format!(
            "{} vertices, {} faces ({} triangles); min angle {} rad; edge length {} .. {}",
            input["vertices"],
            input["faces"],
            input["triangles"],
            sig(&input["min_angle_rad"]),
            sig(&input["min_edge"]),
            sig(&input["max_edge"])
        ),
        "run     stack, always center, median".to_string(),
        format!("samples rho_v {}, rho_e {}", sig(&c["rho_v"]), sig(&c["rho_e"])),
        format!(
            "{} vertices, {} faces, {} added vertices",
            run["vertices"], run["faces"], run["added_vertices"]
        ),
        format!(
            "work    {} splits, {} flips; non-Delaunay edges: {} before, {} after",
            run["splits"], run["flips"], run["non_delaunay_before"], run["non_delaunay_after"]
        ),
        format!(
            "seconds {:.4} total (read {:.4}, build {:.4}, refine {:.4}, write {:.4})",
            s["total"].as_f64().unwrap(),
            s["read"].as_f64().unwrap(),
            s["build"].as_f64().unwrap(),
            s["refine"].as_f64().unwrap(),
            s["write"].as_f64().unwrap()
        ),
    ] {
        assert!(stdout.contains(&expected), "missing {expected:?} in\n{stdout}");
    }
    assert_eq!(s["refine"], run["seconds_refine"]);
    assert_eq!(doc["refined"], true);
    assert_eq!(doc["gabriel_boundary"], false);
    assert!(doc["repair"].is_null() && doc["repaired"].is_null());
    if cfg!(target_os = "linux") {
        assert!(doc["peak_memory_bytes"].as_u64().unwrap() > 1_000_000);
    }
}

#[test]
fn sweep_json_and_csv_have_the_18_runs_of_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let (json, csv) = (dir.path().join("s.json"), dir.path().join("sweep.csv"));
    let out = delmesh()
        .arg("-i")
        .arg(common::data_dir().join("cube.obj"))
        .arg("-o")
        .arg(dir.path().join("c.obj"))
        .arg("-all")
        .arg("--stats-json")
        .arg(&json)
        .arg("--sweep-csv")
        .arg(&csv)
        .output()
        .unwrap();
    assert!(out.status.success());
    let doc = read_json(&json);
    validate(&doc);
    let rows = read_csv(&std::fs::read_to_string(&csv).unwrap());
    csv_matches_json(&rows, &doc);
    let runs = doc["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 18);
    // In the printed table's order, each row's figures as printed.
    let stdout = String::from_utf8_lossy(&out.stdout);
    let table: Vec<&str> = stdout
        .lines()
        .filter(|l| l.ends_with(".obj") && !l.starts_with("input"))
        .collect();
    assert_eq!(table.len(), 18);
    for (line, run) in table.iter().zip(runs) {
        let file = Path::new(run["output"].as_str().unwrap()).file_name().unwrap();
        assert!(line.ends_with(file.to_str().unwrap()), "{line} vs {run}");
        let numbers: Vec<&str> = line.split_whitespace().collect();
        let n = numbers.len();
        assert_eq!(numbers[n - 7], run["faces"].to_string(), "{line}");
        assert_eq!(numbers[n - 6], run["vertices"].to_string(), "{line}");
        assert_eq!(numbers[n - 5], run["added_vertices"].to_string(), "{line}");
        assert_eq!(numbers[n - 4], run["splits"].to_string(), "{line}");
        assert_eq!(numbers[n - 3], run["flips"].to_string(), "{line}");
    }
    let mut combos: Vec<String> = runs
        .iter()
        .map(|r| format!("{}{}{}", r["data_structure"], r["score"], r["median"]))
        .collect();
    combos.sort();
    combos.dedup();
    assert_eq!(combos.len(), 18);
}

#[test]
fn no_refine_repair_and_failed_runs_are_recorded() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("s.json");
    // --no-refine: one record without settings.
    delmesh()
        .arg("-q")
        .arg("-i")
        .arg(common::data_dir().join("cube.obj"))
        .arg("-o")
        .arg(dir.path().join("c.off"))
        .arg("--no-refine")
        .arg("--stats-json")
        .arg(&json)
        .assert()
        .success();
    let doc = read_json(&json);
    validate(&doc);
    assert_eq!(doc["refined"], false);
    let r = &doc["runs"][0];
    assert!(r["data_structure"].is_null() && r["non_delaunay_before"].is_null());
    assert_eq!(r["added_vertices"], 0);
    // --repair: the repair lines.
    let obj = dir.path().join("dirty.obj");
    let cube = std::fs::read_to_string(common::data_dir().join("cube.obj")).unwrap();
    std::fs::write(&obj, format!("{cube}\nf 1 1 2\n")).unwrap();
    delmesh()
        .arg("-q")
        .arg("-i")
        .arg(&obj)
        .arg("-o")
        .arg(dir.path().join("c.obj"))
        .arg("--repair")
        .arg("--repaired")
        .arg(dir.path().join("r.obj"))
        .arg("--stats-json")
        .arg(&json)
        .assert()
        .success();
    let doc = read_json(&json);
    validate(&doc);
    assert!(!doc["repair"].as_array().unwrap().is_empty(), "{}", doc["repair"]);
    assert!(doc["repaired"].as_str().unwrap().ends_with("r.obj"));
    // A run that stops at the work limit: exit 1, no mesh, a record that says why.
    let csv = dir.path().join("s.csv");
    let out = dir.path().join("never.obj");
    let o = delmesh()
        .arg("-i")
        .arg(common::data_dir().join("bunny.obj"))
        .arg("-o")
        .arg(&out)
        .args(["--max-added", "3"])
        .arg("--stats-json")
        .arg(&json)
        .arg("--stats-csv")
        .arg(&csv)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(!out.exists());
    let doc = read_json(&json);
    validate(&doc);
    let r = &doc["runs"][0];
    assert_eq!(r["ok"], false);
    assert_eq!(r["error_kind"], "work_limit");
    assert!(r["error"].as_str().unwrap().contains("work limit"));
    assert!(r["vertices"].is_null());
    // The seconds it refined before it stopped (they were summed over the
    // runs that succeeded only, and written as -0.0); no write, no prune: 0.
    let s = &doc["seconds"];
    assert!(s["refine"].as_f64().unwrap() > 0.0, "{s}");
    assert_eq!(s["refine"], r["seconds_refine"]);
    for zero in [&s["write"], &s["prune"], &r["seconds_write"], &r["seconds_prune"]] {
        assert_eq!(zero.as_f64(), Some(0.0), "{doc}");
    }
    let text = std::fs::read_to_string(&json).unwrap() + &std::fs::read_to_string(&csv).unwrap();
    assert!(!text.contains("-0.0") && !text.contains(": -0,"), "{text}");
    csv_matches_json(&read_csv(&std::fs::read_to_string(&csv).unwrap()), &doc);
    // A refused input writes neither.
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\n").unwrap();
    std::fs::remove_file(&json).unwrap();
    delmesh()
        .arg("-i")
        .arg(&bad)
        .arg("-o")
        .arg(dir.path().join("x.obj"))
        .arg("--stats-json")
        .arg(&json)
        .assert()
        .code(1);
    assert!(!json.exists());
}

/// With `--prune`, what the `prune` line prints is in the JSON and the CSV:
/// removed, tried, flips, passes, and the seconds pruning took (a part of
/// refining's).
#[test]
fn pruning_figures_are_recorded() {
    let (stdout, doc) = bunny_with_stats(&["--prune"]);
    let (run, s) = (&doc["runs"][0], &doc["seconds"]);
    let passes = run["prune_passes"].as_u64().unwrap();
    let expected = format!(
        "prune   removed {} of {} added vertices ({} tried, {} flips, {} pass{})",
        run["pruned_vertices"],
        run["splits"],
        run["prune_tried"],
        run["prune_flips"],
        passes,
        if passes == 1 { "" } else { "es" }
    );
    assert!(stdout.contains(&expected), "missing {expected:?} in\n{stdout}");
    let (prune, refine) = (s["prune"].as_f64().unwrap(), s["refine"].as_f64().unwrap());
    assert!(prune > 0.0 && prune <= refine, "{s}");
    assert_eq!(s["prune"], run["seconds_prune"]);
    // Without --prune: null figures, 0 seconds.
    let (_, doc) = bunny_with_stats(&[]);
    let run = &doc["runs"][0];
    assert!(run["prune_tried"].is_null() && run["prune_passes"].is_null());
    assert_eq!(doc["seconds"]["prune"].as_f64(), Some(0.0));
}

#[test]
fn readme_types_are_the_known_ones() {
    for (path, ty) in documented_fields() {
        let base = ty.strip_suffix(" or null").unwrap_or(&ty);
        assert!(
            [
                "string",
                "integer",
                "number",
                "boolean",
                "object",
                "array of strings",
                "array of objects"
            ]
            .contains(&base),
            "{path}: {ty}"
        );
    }
}

/// A document without what changes from run to run: seconds and memory.
fn without_timings(mut doc: Value) -> Value {
    let o = doc.as_object_mut().unwrap();
    o.remove("seconds");
    o.remove("peak_memory_bytes");
    for run in o["runs"].as_array_mut().unwrap() {
        let r = run.as_object_mut().unwrap();
        r.remove("seconds_refine");
        r.remove("seconds_write");
        r.remove("seconds_prune");
    }
    doc
}

/// `batch --stats-json`: for each input read, the main command's document
/// for it (the same figures, also for a run that fails), the refused and
/// skipped inputs, all as the README's tables say, and the CSV agreeing.
#[test]
fn batch_json_holds_each_files_main_document() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let book = dir.path().join("book.obj");
    std::fs::write(
        &book,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
    )
    .unwrap();
    let missing = dir.path().join("missing.obj");
    let stuck = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions/bug-refine-theta-min-zero-needle.obj");
    let (cube, bunny, elephant) = (
        common::data_dir().join("cube.obj"),
        common::data_dir().join("bunny.obj"),
        common::data_dir().join("elephant.obj"),
    );
    // The elephant is done already: --skip-existing leaves it.
    let out = delmesh()
        .args(["batch", "-q", "-d"])
        .arg(&out_dir)
        .arg(&elephant)
        .output()
        .unwrap();
    assert!(out.status.success());
    let (json, csv) = (dir.path().join("b.json"), dir.path().join("b.csv"));
    let files = [&book, &cube, &missing, &stuck, &elephant, &bunny];
    let out = delmesh()
        .args(["batch", "--skip-existing", "-d"])
        .arg(&out_dir)
        .arg("--stats-json")
        .arg(&json)
        .arg("--stats-csv")
        .arg(&csv)
        .args(files)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    let doc = read_json(&json);
    validate_with(&doc, &table_fields("batch-json-fields"), Some("files"));
    let docs = doc["files"].as_array().unwrap();
    for d in docs {
        validate(d);
        assert!(d["peak_memory_bytes"].is_null());
    }
    // The refused inputs, with the errors printed for them.
    let refused = doc["refused"].as_array().unwrap();
    assert_eq!(refused.len(), 2, "{doc}");
    for (r, path) in refused.iter().zip([&book, &missing]) {
        assert_eq!(r["input"], path.display().to_string());
        let error = r["error"].as_str().unwrap();
        assert!(error.starts_with(&path.display().to_string()), "{error}");
        assert!(
            stderr.lines().any(|l| l.starts_with(&format!("delmesh: {error}"))),
            "{stderr}"
        );
    }
    assert_eq!(doc["skipped"], serde_json::json!([elephant.display().to_string()]));
    // Each file's document is the main command's, figure for figure.
    let read = [&cube, &stuck, &bunny];
    assert_eq!(docs.len(), read.len(), "{doc}");
    for (d, input) in docs.iter().zip(read) {
        let single = dir.path().join("single.json");
        let output = out_dir.join(input.file_name().unwrap());
        delmesh()
            .arg("-q")
            .arg("-i")
            .arg(input)
            .arg("-o")
            .arg(&output)
            .arg("--stats-json")
            .arg(&single)
            .output()
            .unwrap();
        assert_eq!(
            without_timings(d.clone()),
            without_timings(read_json(&single)),
            "{}",
            input.display()
        );
    }
    assert_eq!(docs[1]["runs"][0]["ok"], false);
    assert_eq!(docs[1]["runs"][0]["error_kind"], "unsplittable");
    // The failed file's refining took time, and is counted; it wrote nothing.
    let (s, r) = (&docs[1]["seconds"], &docs[1]["runs"][0]);
    assert!(s["refine"].as_f64().unwrap() > 0.0, "{s}");
    assert_eq!(s["refine"], r["seconds_refine"]);
    assert_eq!(s["write"].as_f64(), Some(0.0));
    assert_eq!(docs[2]["runs"][0]["ok"], true);
    // The CSV has the same runs (and rows for the refused inputs).
    let rows = read_csv(&std::fs::read_to_string(&csv).unwrap());
    assert_eq!(rows.len(), 5);
    for (d, input) in docs.iter().zip(read) {
        let row: Vec<_> = rows
            .iter()
            .filter(|r| r["input"] == input.display().to_string())
            .cloned()
            .collect();
        csv_matches_json(&row, d);
    }
}

/// `batch --stats-json` may not name the CSV's file, an input or an output.
#[test]
fn batch_json_overwrites_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let cube = dir.path().join("cube.obj");
    std::fs::copy(common::data_dir().join("cube.obj"), &cube).unwrap();
    let before = std::fs::read(&cube).unwrap();
    let out_dir = dir.path().join("out");
    let same = dir.path().join("s.txt");
    for args in [
        vec!["--stats-json".into(), cube.clone()],
        vec!["--stats-json".into(), out_dir.join("cube.obj")],
        vec!["--stats-json".into(), same.clone(), "--stats-csv".into(), same.clone()],
    ] {
        let out = delmesh()
            .args(["batch", "-d"])
            .arg(&out_dir)
            .args(&args)
            .arg(&cube)
            .output()
            .unwrap();
        assert!(!out.status.success(), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(!out_dir.join("cube.obj").exists() && !same.exists(), "{args:?}");
    }
    assert_eq!(std::fs::read(&cube).unwrap(), before);
}

/// `check --json` against the README's table both ways, on a run with both maps: every
/// figure as the run's own `--stats-json` and the printout say.
#[test]
fn check_json_matches_the_readme_table_and_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let bunny = common::data_dir().join("bunny.obj");
    let out = dir.path().join("out.obj");
    let (v, f) = (dir.path().join("v.csv"), dir.path().join("f.csv"));
    let (stats, verdict) = (dir.path().join("s.json"), dir.path().join("c.json"));
    let status = delmesh()
        .arg("-q")
        .arg("-i")
        .arg(&bunny)
        .arg("-o")
        .arg(&out)
        .arg("--vertex-map")
        .arg(&v)
        .arg("--face-map")
        .arg(&f)
        .arg("--stats-json")
        .arg(&stats)
        .output()
        .unwrap()
        .status;
    assert!(status.success());
    let run: Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    let printout = delmesh()
        .arg("check")
        .arg(&bunny)
        .arg(&out)
        .arg("--vertex-map")
        .arg(&v)
        .arg("--face-map")
        .arg(&f)
        .arg("--json")
        .arg(&verdict)
        .output()
        .unwrap();
    assert!(printout.status.success());
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&verdict).unwrap()).unwrap();
    let fields = table_fields("check-json-fields");
    assert!(fields.len() > 30, "{fields:?}");
    validate_with(&doc, &fields, None);
    assert_eq!(doc["passed"], true);
    assert_eq!(doc["output"]["added_vertices"], run["runs"][0]["added_vertices"]);
    assert_eq!(doc["output"]["vertices"], run["runs"][0]["vertices"]);
    assert_eq!(doc["output"]["faces"], run["runs"][0]["faces"]);
    assert_eq!(doc["input"]["vertices"], run["input"]["vertices"]);
    assert_eq!(doc["edges"]["non_delaunay"], 0);
    assert_eq!(doc["failures"], serde_json::json!([]));
    assert_eq!(doc["failure_counts"], serde_json::json!([]));
    assert_eq!(doc["vertex_map"]["rows"], doc["output"]["vertices"]);
    assert_eq!(doc["face_map"]["rows"], doc["output"]["faces"]);
    assert_eq!(doc["vertex_map"]["passed"], true);
    let text = String::from_utf8_lossy(&printout.stdout);
    let max = doc["edges"]["max_excess_rad"].as_f64().unwrap();
    assert!(text.contains(&format!("(max alpha+beta-pi {max:.3e} rad)")), "{text}");
}

/// A failing check's JSON on standard output (the printout on standard error): every failure
/// counted by kind, past the 20 lines printed; the maps absent are null.
#[test]
fn check_json_counts_every_failure_and_goes_to_standard_output() {
    // The bunny against itself: its 236 non-Delaunay edges.
    let bunny = common::data_dir().join("bunny.obj");
    let out = delmesh()
        .arg("check")
        .arg(&bunny)
        .arg(&bunny)
        .args(["--json", "-"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let doc: Value = serde_json::from_slice(&out.stdout).expect("standard output is the JSON alone");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("FAILED"), "{stderr}");
    let fields: Vec<(String, String)> = table_fields("check-json-fields")
        .into_iter()
        .filter(|(p, _)| !p.starts_with("vertex_map.") && !p.starts_with("face_map."))
        .collect();
    validate_with(&doc, &fields, None);
    assert_eq!(doc["passed"], false);
    assert_eq!(doc["edges"]["non_delaunay"], 236);
    assert_eq!(
        doc["failure_counts"],
        serde_json::json!([{"kind": "non-Delaunay edge", "count": 236}])
    );
    let failures = doc["failures"].as_array().unwrap();
    assert_eq!(failures.len(), 21);
    assert_eq!(failures[20], "... and 216 more non-Delaunay edge failures");
    assert!(doc["vertex_map"].is_null() && doc["face_map"].is_null() && doc["original"].is_null());
}

/// `check --json` refuses, before the work, a FILE that the check reads, and writes nothing
/// when a file cannot be read.
#[test]
fn check_json_overwrites_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let cube = dir.path().join("cube.obj");
    std::fs::copy(common::data_dir().join("cube.obj"), &cube).unwrap();
    let before = std::fs::read(&cube).unwrap();
    let verdict = dir.path().join("c.json");
    for (args, said) in [
        (
            vec![cube.clone(), cube.clone(), "--json".into(), cube.clone()],
            "would overwrite INPUT",
        ),
        (
            vec![
                cube.clone(),
                dir.path().join("missing.obj"),
                "--json".into(),
                verdict.clone(),
            ],
            "missing.obj",
        ),
        (
            vec![
                cube.clone(),
                cube.clone(),
                "--json".into(),
                dir.path().join("no/c.json"),
            ],
            "does not exist",
        ),
    ] {
        let out = delmesh().arg("check").args(&args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains(said), "{stderr}");
        assert!(!verdict.exists(), "{args:?}");
    }
    assert_eq!(std::fs::read(&cube).unwrap(), before);
}

/// The README names every kind of failure `check --json` counts (`invalid input` comes only
/// from the library's `check_meshes`), and no other.
#[test]
fn readme_lists_the_check_failure_kinds() {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let row = readme
        .lines()
        .find(|l| l.starts_with("| `failure_counts[].kind` |"))
        .expect("the kinds' row");
    let listed: Vec<&str> = row.split('`').skip(3).step_by(2).collect();
    let known: Vec<&str> = delmesh::check::FAILURE_KINDS
        .into_iter()
        .filter(|&k| k != "invalid input")
        .collect();
    assert_eq!(listed, known, "{row}");
}
