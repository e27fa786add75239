//! `--stats-json FILE` and `--stats-csv FILE`: every figure a run prints,
//! plus the sample constants, per-phase seconds and peak memory, with stable
//! field names (documented, field by field, in README.md; a test checks the
//! two agree). JSON: one object for the invocation with one record per run
//! (18 with `-all`); CSV: one row per run, its columns the run record's.
//!
//! Written by hand, without serde: the values are flat numbers, strings,
//! booleans and nulls, and serde's derive would add a proc-macro crate to the
//! build for this one file.

use std::fmt::Write as _;
use std::path::Path;

use delmesh::check::maps::MapReport;
use delmesh::check::CheckReport;
use delmesh::io::InputMesh;
use delmesh::mesh::InputFigures;
use delmesh::prune::PruneStats;
use delmesh::refine::{Options, Stats, Worklist};
use delmesh::samples::{SampleConstants, Score};

/// One refinement's figures (one per combination with `-all`).
pub struct RunRecord {
    /// Settings of the run; `None` with `--no-refine`.
    pub options: Option<Options>,
    /// The file written (or that would have been).
    pub output: String,
    /// `Err((kind, message))` if the run failed.
    pub result: Result<RunFigures, (&'static str, String)>,
    /// How long its phases took: also of a failed run, until it failed.
    pub seconds: RunSeconds,
}

/// Wall-clock seconds of a run's phases: 0 for a phase that did not run; a
/// run that failed has those of the phases it ran, until it failed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunSeconds {
    /// Refining, pruning included.
    pub refine: f64,
    /// Pruning (with `--prune`), a part of `refine`.
    pub prune: f64,
    /// Writing the output mesh (until it is complete under its temporary
    /// name).
    pub write: f64,
}

/// The figures of a successful run.
pub struct RunFigures {
    /// Output vertices.
    pub vertices: usize,
    /// Output faces.
    pub faces: usize,
    /// Vertices not in the input.
    pub added_vertices: usize,
    /// With `--prune`: what pruning did (the figures its line prints).
    pub pruned: Option<PruneStats>,
    /// Work done; `None` with `--no-refine`.
    pub stats: Option<Stats>,
}

/// What the whole invocation read and how long it took.
pub struct Invocation<'a> {
    /// The input file.
    pub input_path: &'a Path,
    /// The input as read.
    pub input: &'a InputMesh,
    /// Its smallest angle and edge lengths.
    pub figures: InputFigures,
    /// `Surface::added_vertex_lower_bound` of the input.
    pub lower_bound: usize,
    /// `Surface::folded_edges` of the input.
    pub folded_edges: usize,
    /// `-o` (the input when rewritten in place).
    pub output: &'a Path,
    /// `--repaired`, if given.
    pub repaired: Option<&'a Path>,
    /// False with `--no-refine`.
    pub refined: bool,
    /// `--gabriel-boundary`: boundary edges refined to face no obtuse angle.
    pub gabriel_boundary: bool,
    /// Seconds reading (and repairing).
    pub seconds_read: f64,
    /// Seconds building the half-edge mesh.
    pub seconds_build: f64,
    /// Seconds for everything.
    pub seconds_total: f64,
}

/// A JSON value.
enum Json {
    Null,
    Bool(bool),
    Int(u64),
    Num(f64),
    Str(String),
    Arr(Vec<Json>),
    Obj(Vec<(&'static str, Json)>),
}

impl Json {
    fn opt_int(x: Option<usize>) -> Json {
        x.map_or(Json::Null, |x| Json::Int(x as u64))
    }

    fn write(&self, out: &mut String, indent: usize) {
        match self {
            Json::Null => out.push_str("null"),
            Json::Bool(b) => out.push_str(if *b { "true" } else { "false" }),
            Json::Int(i) => {
                let _ = write!(out, "{i}");
            }
            Json::Num(x) => out.push_str(&num(*x)),
            Json::Str(s) => out.push_str(&string(s)),
            Json::Arr(items) => {
                if items.is_empty() {
                    out.push_str("[]");
                    return;
                }
                out.push('[');
                for (k, item) in items.iter().enumerate() {
                    out.push_str(if k == 0 { "\n" } else { ",\n" });
                    out.push_str(&" ".repeat(indent + 2));
                    item.write(out, indent + 2);
                }
                out.push('\n');
                out.push_str(&" ".repeat(indent));
                out.push(']');
            }
            Json::Obj(fields) => {
                // Objects of scalars on one line; others one field a line.
                let flat = fields.iter().all(|(_, v)| !matches!(v, Json::Arr(_) | Json::Obj(_)));
                out.push('{');
                for (k, (name, value)) in fields.iter().enumerate() {
                    if flat {
                        out.push_str(if k == 0 { "" } else { ", " });
                    } else {
                        out.push_str(if k == 0 { "\n" } else { ",\n" });
                        out.push_str(&" ".repeat(indent + 2));
                    }
                    out.push_str(&string(name));
                    out.push_str(": ");
                    value.write(out, indent + 2);
                }
                if !flat {
                    out.push('\n');
                    out.push_str(&" ".repeat(indent));
                }
                out.push('}');
            }
        }
    }

    /// The value as a CSV cell (empty for null).
    fn csv_cell(&self) -> String {
        match self {
            Json::Null | Json::Arr(_) | Json::Obj(_) => String::new(),
            Json::Bool(b) => b.to_string(),
            Json::Int(i) => i.to_string(),
            Json::Num(x) if x.is_finite() => num(*x),
            Json::Num(_) => String::new(),
            Json::Str(s) if s.contains([',', '"', '\n', '\r']) => format!("\"{}\"", s.replace('"', "\"\"")),
            Json::Str(s) => s.clone(),
        }
    }
}

/// A number in shortest round-trip form; `-0` is written as `0` (no figure
/// is negative: an empty sum gives -0), a non-finite one as `null`.
fn num(x: f64) -> String {
    let x = if x == 0.0 { 0.0 } else { x };
    if x.is_finite() {
        zmij::Buffer::new().format_finite(x).to_string()
    } else {
        "null".into()
    }
}

fn string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Peak resident memory of this process in bytes (Linux), if known.
pub fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// `stack`, `queue` or `pqueue`, as `-ds` spells them.
pub fn ds_key(w: Worklist) -> &'static str {
    match w {
        Worklist::Stack => "stack",
        Worklist::Queue => "queue",
        Worklist::PriorityQueue => "pqueue",
    }
}

/// The `-s` number of a score.
pub fn score_key(s: Score) -> u32 {
    match s {
        Score::AllEqual => 0,
        Score::WeightedCenter => 1,
        Score::AlwaysCenter => 2,
        Score::SplitAware => 3,
        Score::Uniform => 4,
    }
}

/// The fields of a run record, in order: also the CSV columns after `input`
/// (fields added later come last, so that the earlier columns keep their
/// places).
pub const RUN_FIELDS: [&str; 24] = [
    "data_structure",
    "score",
    "median",
    "shells",
    "output",
    "ok",
    "error_kind",
    "error",
    "vertices",
    "faces",
    "added_vertices",
    "pruned_vertices",
    "splits",
    "flips",
    "non_delaunay_before",
    "non_delaunay_after",
    "passes",
    "longest_first_after_flips",
    "seconds_refine",
    "seconds_write",
    "prune_tried",
    "prune_flips",
    "prune_passes",
    "seconds_prune",
];

fn run_object(r: &RunRecord) -> Json {
    let o = r.options.as_ref();
    let mut fields = vec![
        (
            "data_structure",
            o.map_or(Json::Null, |o| Json::Str(ds_key(o.worklist).into())),
        ),
        ("score", o.map_or(Json::Null, |o| Json::Int(score_key(o.score).into()))),
        ("median", o.map_or(Json::Null, |o| Json::Bool(o.median))),
        ("shells", o.map_or(Json::Null, |o| Json::Bool(o.shells))),
        ("output", Json::Str(r.output.clone())),
        ("ok", Json::Bool(r.result.is_ok())),
        (
            "error_kind",
            r.result.as_ref().err().map_or(Json::Null, |e| Json::Str(e.0.into())),
        ),
        (
            "error",
            r.result.as_ref().err().map_or(Json::Null, |e| Json::Str(e.1.clone())),
        ),
    ];
    let f = r.result.as_ref().ok();
    let st = f.and_then(|f| f.stats);
    let done = f.map(|f| f.stats.unwrap_or_default());
    let pruned = f.and_then(|f| f.pruned);
    fields.extend([
        ("vertices", Json::opt_int(f.map(|f| f.vertices))),
        ("faces", Json::opt_int(f.map(|f| f.faces))),
        ("added_vertices", Json::opt_int(f.map(|f| f.added_vertices))),
        ("pruned_vertices", Json::opt_int(pruned.map(|p| p.removed))),
        ("splits", Json::opt_int(done.map(|s| s.splits))),
        ("flips", Json::opt_int(done.map(|s| s.flips))),
        ("non_delaunay_before", Json::opt_int(st.map(|s| s.non_delaunay_before))),
        ("non_delaunay_after", Json::opt_int(st.map(|s| s.non_delaunay_after))),
        ("passes", Json::opt_int(done.map(|s| s.passes))),
        (
            "longest_first_after_flips",
            Json::opt_int(done.and_then(|s| s.longest_first_after)),
        ),
        ("seconds_refine", Json::Num(r.seconds.refine)),
        ("seconds_write", Json::Num(r.seconds.write)),
        ("prune_tried", Json::opt_int(pruned.map(|p| p.tried))),
        ("prune_flips", Json::opt_int(pruned.map(|p| p.flips))),
        ("prune_passes", Json::opt_int(pruned.map(|p| p.passes))),
        ("seconds_prune", Json::Num(r.seconds.prune)),
    ]);
    Json::Obj(fields)
}

/// The JSON document for an invocation and its runs.
pub fn document(inv: &Invocation, constants: SampleConstants, runs: &[RunRecord]) -> String {
    text(&document_value(inv, constants, runs, peak_memory_bytes()))
}

/// A document as the file holds it, ending with a newline.
fn text(doc: &Json) -> String {
    let mut s = String::new();
    doc.write(&mut s, 0);
    s.push('\n');
    s
}

/// One file's part of `batch --stats-json`: the document the main command
/// writes for it, but with `peak_memory_bytes` null (the process's peak,
/// shared by the files, is given once for the batch).
pub struct FileDocument(Json);

impl FileDocument {
    /// The document of one input of a batch.
    pub fn new(inv: &Invocation, constants: SampleConstants, runs: &[RunRecord]) -> Self {
        FileDocument(document_value(inv, constants, runs, None))
    }
}

/// The `batch --stats-json` document: a [`FileDocument`] per input read
/// (in the order given), the inputs refused with their one-line errors,
/// the inputs skipped (`--skip-existing`), the batch's seconds and the
/// process's peak memory.
pub fn batch_document(
    files: Vec<FileDocument>,
    refused: &[(String, String)],
    skipped: &[String],
    seconds_total: f64,
) -> String {
    let doc = Json::Obj(vec![
        ("delmesh_version", Json::Str(env!("CARGO_PKG_VERSION").into())),
        ("files", Json::Arr(files.into_iter().map(|f| f.0).collect())),
        (
            "refused",
            Json::Arr(
                refused
                    .iter()
                    .map(|(input, error)| {
                        Json::Obj(vec![
                            ("input", Json::Str(input.clone())),
                            ("error", Json::Str(error.clone())),
                        ])
                    })
                    .collect(),
            ),
        ),
        (
            "skipped",
            Json::Arr(skipped.iter().map(|p| Json::Str(p.clone())).collect()),
        ),
        ("seconds_total", Json::Num(seconds_total)),
        ("peak_memory_bytes", peak_memory_bytes().map_or(Json::Null, Json::Int)),
    ]);
    text(&doc)
}

fn document_value(inv: &Invocation, constants: SampleConstants, runs: &[RunRecord], peak_memory: Option<u64>) -> Json {
    let i = inv.input;
    let f = inv.figures;
    // Summed over every run, failed ones too (from +0: an empty `sum` of
    // floats is -0).
    let seconds_of = |g: fn(&RunSeconds) -> f64| runs.iter().map(|r| g(&r.seconds)).fold(0.0, |a, b| a + b);
    Json::Obj(vec![
        ("delmesh_version", Json::Str(env!("CARGO_PKG_VERSION").into())),
        (
            "input",
            Json::Obj(vec![
                ("path", Json::Str(inv.input_path.display().to_string())),
                ("vertices", Json::Int(i.positions.len() as u64)),
                ("faces", Json::Int(i.faces_in_file as u64)),
                ("triangles", Json::Int(i.triangles.len() as u64)),
                ("welded_vertices", Json::Int(i.welded as u64)),
                ("unreferenced_vertices", Json::Int(i.unreferenced as u64)),
                ("min_angle_rad", Json::Num(f.min_angle)),
                ("min_edge", Json::Num(f.min_edge)),
                ("max_edge", Json::Num(f.max_edge)),
                ("near_coincident_edges", Json::Int(f.near_coincident_edges as u64)),
                ("folded_edges", Json::Int(inv.folded_edges as u64)),
                ("added_vertices_lower_bound", Json::Int(inv.lower_bound as u64)),
            ]),
        ),
        (
            "repair",
            i.repair.as_ref().map_or(Json::Null, |r| {
                Json::Arr(r.lines().into_iter().map(|l| Json::Str(l.to_string())).collect())
            }),
        ),
        (
            "repaired",
            inv.repaired.map_or(Json::Null, |p| Json::Str(p.display().to_string())),
        ),
        ("output", Json::Str(inv.output.display().to_string())),
        ("refined", Json::Bool(inv.refined)),
        ("gabriel_boundary", Json::Bool(inv.gabriel_boundary)),
        (
            "constants",
            Json::Obj(vec![
                ("theta_min", Json::Num(constants.theta_min)),
                ("l_min", Json::Num(constants.l_min)),
                ("rho_v", Json::Num(constants.rho_v)),
                ("rho_e", Json::Num(constants.rho_e)),
            ]),
        ),
        (
            "seconds",
            Json::Obj(vec![
                ("read", Json::Num(inv.seconds_read)),
                ("build", Json::Num(inv.seconds_build)),
                ("refine", Json::Num(seconds_of(|s| s.refine))),
                ("prune", Json::Num(seconds_of(|s| s.prune))),
                ("write", Json::Num(seconds_of(|s| s.write))),
                ("total", Json::Num(inv.seconds_total)),
            ]),
        ),
        ("peak_memory_bytes", peak_memory.map_or(Json::Null, Json::Int)),
        ("runs", Json::Arr(runs.iter().map(run_object).collect())),
    ])
}

/// What `delmesh check --json FILE` records of one check (fields documented in README.md, the
/// check JSON table).
pub struct CheckRecord<'a> {
    /// INPUT as given.
    pub input: &'a Path,
    /// OUTPUT as given.
    pub output: &'a Path,
    /// The verdict on the mesh.
    pub report: &'a CheckReport,
    /// `--gabriel-boundary`: boundary edges facing an obtuse angle were failures.
    pub gabriel_boundary: bool,
    /// `--vertex-map` and its verdict, if given.
    pub vertex_map: Option<(&'a Path, &'a MapReport)>,
    /// `--face-map` and its verdict, if given.
    pub face_map: Option<(&'a Path, &'a MapReport)>,
    /// `--original`, if given.
    pub original: Option<&'a Path>,
    /// Seconds for the whole check.
    pub seconds: f64,
}

/// The JSON document of a check ([`CheckRecord`]).
pub fn check_document(c: &CheckRecord) -> String {
    let r = c.report;
    let strings = |lines: &[String]| Json::Arr(lines.iter().map(|l| Json::Str(l.clone())).collect());
    let map = |m: Option<(&Path, &MapReport)>, face: bool| {
        m.map_or(Json::Null, |(path, m)| {
            let mut fields = vec![
                ("path", Json::Str(path.display().to_string())),
                ("rows", Json::Int(m.rows as u64)),
            ];
            if face {
                fields.push(("not_inside", Json::Int(m.not_inside as u64)));
            }
            fields.push(("passed", Json::Bool(m.passed())));
            fields.push(("failures", strings(&m.failures)));
            Json::Obj(fields)
        })
    };
    let maps_pass = [c.vertex_map, c.face_map].iter().flatten().all(|(_, m)| m.passed());
    // An excess over no edge at all (-inf) is null.
    let excess = |x: f64, edges: usize| if edges == 0 { Json::Null } else { Json::Num(x) };
    let doc = Json::Obj(vec![
        ("delmesh_version", Json::Str(env!("CARGO_PKG_VERSION").into())),
        ("passed", Json::Bool(r.passed() && maps_pass)),
        (
            "input",
            Json::Obj(vec![
                ("path", Json::Str(c.input.display().to_string())),
                ("vertices", Json::Int(r.input_vertices as u64)),
                ("faces", Json::Int(r.input_faces as u64)),
                ("planar_regions", Json::Int(r.input_regions as u64)),
            ]),
        ),
        (
            "output",
            Json::Obj(vec![
                ("path", Json::Str(c.output.display().to_string())),
                ("vertices", Json::Int(r.output_vertices as u64)),
                ("faces", Json::Int(r.output_faces as u64)),
                ("added_vertices", Json::Int(r.added_vertices as u64)),
                ("unused_vertices", Json::Int(r.unused_vertices as u64)),
                ("misplaced_vertices", Json::Int(r.misplaced_vertices.0 as u64)),
                ("misplaced_vertices_rounded", Json::Int(r.misplaced_vertices.1 as u64)),
                ("first_reordered_vertex", Json::opt_int(r.first_reordered_vertex)),
            ]),
        ),
        ("gabriel_boundary", Json::Bool(c.gabriel_boundary)),
        (
            "edges",
            Json::Obj(vec![
                ("interior", Json::Int(r.interior_edges as u64)),
                ("non_delaunay", Json::Int(r.non_delaunay_edges as u64)),
                ("max_excess_rad", excess(r.max_excess, r.interior_edges)),
                ("boundary", Json::Int(r.boundary_edges as u64)),
                ("boundary_facing_obtuse", Json::Int(r.non_gabriel_boundary_edges as u64)),
                (
                    "max_boundary_excess_rad",
                    excess(r.max_boundary_excess, r.boundary_edges),
                ),
            ]),
        ),
        ("failures", strings(&r.failures)),
        (
            "failure_counts",
            Json::Arr(
                (r.failure_counts.iter())
                    .map(|&(kind, count)| {
                        Json::Obj(vec![
                            ("kind", Json::Str(kind.into())),
                            ("count", Json::Int(count as u64)),
                        ])
                    })
                    .collect(),
            ),
        ),
        (
            "original",
            c.original.map_or(Json::Null, |p| Json::Str(p.display().to_string())),
        ),
        ("vertex_map", map(c.vertex_map, false)),
        ("face_map", map(c.face_map, true)),
        ("seconds", Json::Num(c.seconds)),
    ]);
    text(&doc)
}

/// The CSV table of the runs: a header, then one row per run; the columns
/// are `input` (the input path) and the fields of a run record.
pub fn csv(input_path: &Path, runs: &[RunRecord]) -> String {
    let rows: Vec<(&Path, &RunRecord)> = runs.iter().map(|r| (input_path, r)).collect();
    csv_rows(&rows)
}

/// [`csv`] for runs of several inputs (`delmesh batch`): one row per
/// (input, run), the same columns.
pub fn csv_rows(rows: &[(&Path, &RunRecord)]) -> String {
    let mut s = format!("input,{}\n", RUN_FIELDS.join(","));
    for (input_path, r) in rows {
        let input = Json::Str(input_path.display().to_string()).csv_cell();
        let Json::Obj(fields) = run_object(r) else { continue };
        let cells: Vec<String> = fields.iter().map(|(_, v)| v.csv_cell()).collect();
        let _ = writeln!(s, "{input},{}", cells.join(","));
    }
    s
}

/// `--vertex-map`: one row per output vertex, in the output's order,
/// `output_index,input_index_a,input_index_b,t` (0-based; the input indices
/// count the input file's vertices, `vertex_number` being each mesh
/// vertex's 1-based number there). Input vertices are `a,a,0`.
pub fn vertex_map_csv(sources: &[(u32, u32, f64)], vertex_number: &[u32]) -> String {
    let file_index = |v: u32| vertex_number.get(v as usize).map_or(v, |n| n - 1);
    let mut s = String::with_capacity(24 * sources.len() + 48);
    s.push_str("output_index,input_index_a,input_index_b,t\n");
    for (i, &(a, b, t)) in sources.iter().enumerate() {
        let _ = writeln!(s, "{i},{},{},{}", file_index(a), file_index(b), num(t));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_records_have_the_csv_columns_in_order() {
        let ok = RunRecord {
            options: Some(Options::default()),
            output: "a,\"b\".obj".into(),
            result: Ok(RunFigures {
                vertices: 5,
                faces: 6,
                added_vertices: 1,
                pruned: None,
                stats: Some(Stats::default()),
            }),
            seconds: RunSeconds {
                refine: 0.5,
                prune: 0.0,
                write: f64::NAN,
            },
        };
        let failed = RunRecord {
            options: None,
            output: "c.obj".into(),
            result: Err(("work_limit", "stopped".into())),
            seconds: RunSeconds {
                refine: 0.25,
                prune: -0.0,
                write: 0.0,
            },
        };
        for r in [&ok, &failed] {
            let Json::Obj(fields) = run_object(r) else { panic!() };
            let names: Vec<&str> = fields.iter().map(|(n, _)| *n).collect();
            assert_eq!(names, RUN_FIELDS);
        }
        let table = csv(Path::new("in.obj"), &[ok, failed]);
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(
            lines[1].starts_with("in.obj,stack,2,true,false,\"a,\"\"b\"\".obj\",true,,,5,6,1,"),
            "{}",
            lines[1]
        );
        assert!(lines[1].ends_with(",0.5,,,,,0.0"), "{}", lines[1]);
        // A failed run has the seconds of what ran; no -0 anywhere.
        assert!(lines[2].ends_with(",0.25,0.0,,,,0.0"), "{}", lines[2]);
        assert!(
            lines[2].starts_with("in.obj,,,,,c.obj,false,work_limit,stopped,,"),
            "{}",
            lines[2]
        );
        assert_eq!(csv(Path::new("x"), &[]).lines().count(), 1);
    }
}
