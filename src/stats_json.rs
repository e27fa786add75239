//! `--stats-json FILE`: every figure a run prints, plus the sample constants,
//! per-phase seconds and peak memory, as one JSON object with stable field
//! names (documented in README.md). Written by hand: the values are flat
//! numbers, strings, booleans and nulls.

use std::fmt::Write as _;
use std::path::Path;

use delmesh::io::InputMesh;
use delmesh::mesh::InputFigures;
use delmesh::refine::{Options, Stats, Worklist};
use delmesh::samples::{SampleConstants, Score};

/// One refinement's figures (one per combination with `-all`).
pub struct RunRecord {
    /// Settings of the run.
    pub options: Options,
    /// The file written (or that would have been).
    pub output: String,
    /// `Err(message)` if the run failed.
    pub result: Result<RunFigures, String>,
}

/// The figures of a successful run.
pub struct RunFigures {
    /// Output vertices and faces.
    pub vertices: usize,
    /// Output faces.
    pub faces: usize,
    /// Work done.
    pub stats: Stats,
    /// Seconds spent refining and writing.
    pub seconds_refine: f64,
    /// See `seconds_refine`.
    pub seconds_write: f64,
}

/// What the whole invocation read and how long it took.
pub struct Invocation<'a> {
    /// The input file.
    pub input_path: &'a Path,
    /// The input as read.
    pub input: &'a InputMesh,
    /// Its smallest angle and edge lengths.
    pub figures: InputFigures,
    /// Seconds reading and building.
    pub seconds_read: f64,
    /// See `seconds_read`.
    pub seconds_build: f64,
    /// Seconds for everything.
    pub seconds_total: f64,
}

fn num(x: f64) -> String {
    if x.is_finite() {
        ryu::Buffer::new().format_finite(x).to_string()
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

fn ds_key(w: Worklist) -> &'static str {
    match w {
        Worklist::Stack => "stack",
        Worklist::Queue => "queue",
        Worklist::PriorityQueue => "pqueue",
    }
}

fn score_key(s: Score) -> u32 {
    match s {
        Score::AllEqual => 0,
        Score::WeightedCenter => 1,
        Score::AlwaysCenter => 2,
        Score::SplitAware => 3,
    }
}

/// The JSON document for an invocation and its runs.
pub fn document(inv: &Invocation, constants: SampleConstants, runs: &[RunRecord]) -> String {
    let i = inv.input;
    let f = inv.figures;
    let mut s = String::new();
    let _ = write!(
        s,
        "{{\n  \"delmesh_version\": {},\n  \"input\": {{\"path\": {}, \"vertices\": {}, \"faces\": {}, \"triangles\": {}, \
         \"welded_vertices\": {}, \"unreferenced_vertices\": {}, \"min_angle_rad\": {}, \"min_edge\": {}, \"max_edge\": {}}},\n",
        string(env!("CARGO_PKG_VERSION")),
        string(&inv.input_path.display().to_string()),
        i.positions.len(),
        i.faces_in_file,
        i.triangles.len(),
        i.welded,
        i.unreferenced,
        num(f.min_angle),
        num(f.min_edge),
        num(f.max_edge)
    );
    let repair = match &i.repair {
        None => "null".to_string(),
        Some(r) => format!(
            "[{}]",
            r.lines().iter().map(|l| string(l)).collect::<Vec<_>>().join(", ")
        ),
    };
    let _ = writeln!(s, "  \"repair\": {repair},");
    let _ = writeln!(
        s,
        "  \"constants\": {{\"theta_min\": {}, \"l_min\": {}, \"rho_v\": {}, \"rho_e\": {}}},",
        num(constants.theta_min),
        num(constants.l_min),
        num(constants.rho_v),
        num(constants.rho_e)
    );
    let _ = writeln!(
        s,
        "  \"seconds\": {{\"read\": {}, \"build\": {}, \"total\": {}}},",
        num(inv.seconds_read),
        num(inv.seconds_build),
        num(inv.seconds_total)
    );
    let peak = peak_memory_bytes().map_or("null".to_string(), |b| b.to_string());
    let _ = writeln!(s, "  \"peak_memory_bytes\": {peak},");
    s.push_str("  \"runs\": [");
    for (k, r) in runs.iter().enumerate() {
        s.push_str(if k == 0 { "\n" } else { ",\n" });
        let o = &r.options;
        let _ = write!(
            s,
            "    {{\"data_structure\": {}, \"score\": {}, \"median\": {}, \"output\": {}, ",
            string(ds_key(o.worklist)),
            score_key(o.score),
            o.median,
            string(&r.output)
        );
        match &r.result {
            Ok(x) => {
                let st = &x.stats;
                let _ = write!(
                    s,
                    "\"ok\": true, \"error\": null, \"vertices\": {}, \"faces\": {}, \"added_vertices\": {}, \"splits\": {}, \
                     \"flips\": {}, \"non_delaunay_before\": {}, \"non_delaunay_after\": {}, \"passes\": {}, \
                     \"seconds_refine\": {}, \"seconds_write\": {}}}",
                    x.vertices,
                    x.faces,
                    x.vertices - i.positions.len(),
                    st.splits,
                    st.flips,
                    st.non_delaunay_before,
                    st.non_delaunay_after,
                    st.passes,
                    num(x.seconds_refine),
                    num(x.seconds_write)
                );
            }
            Err(e) => {
                let _ = write!(s, "\"ok\": false, \"error\": {}}}", string(e));
            }
        }
    }
    s.push_str("\n  ]\n}\n");
    s
}
