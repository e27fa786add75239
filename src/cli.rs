//! Command line: the report's flags (`-i`, `-o`, `-ds`, `-s`, `-nomedian`,
//! `-all`) exactly as its examples write them, GNU-style long options beside
//! them, and the `check` subcommand. Here one run, phase by phase, and what
//! it prints; the flags are in `args.rs`, `-all` and `--smallest` in
//! `sweep.rs`, `delmesh batch` in `batch.rs`, `--check` and `delmesh check`
//! in `judge.rs`, `delmesh render` in `render.rs`, the rules on which files
//! a run may read and write in `paths.rs`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use clap::{Parser, Subcommand, ValueEnum};

use crate::progress::{self, Phase};
use crate::stats_json;
use delmesh::check::maps::MapReport;
use delmesh::draw::{Format, Rgb};
use delmesh::face_map::{self, FaceOrigins};
use delmesh::flat_regions::FlatRegions;
use delmesh::io;
use delmesh::io::formats::RawMesh;

/// `println!` that never panics: a closed stdout (`delmesh ... | head`) must
/// not turn a finished run into a crash. The progress line, if any, is
/// cleared first. Each call prints one line: control characters in what it
/// quotes (a file name with a line feed in it) are escaped ([`escaped`]), as
/// in error messages, so that a script reading the printout line by line
/// reads each record whole.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let line = crate::cli::escaped(&format!($($arg)*), false);
        crate::progress::suspend(|| {
            if crate::cli::PRINTOUT_TO_STDERR.load(std::sync::atomic::Ordering::Relaxed) {
                let _ = writeln!(std::io::stderr(), "{line}");
            } else {
                let mut out = std::io::stdout().lock();
                let written = writeln!(out, "{line}").and_then(|()| out.flush());
                crate::cli::note_stdout_result(written);
            }
        });
    }};
}

/// The first error writing to standard output other than a closed pipe
/// (`delmesh batch ... | head` is no failure), such as a full disk: the
/// printout is what a script reads, so losing it fails the run (exit 1).
static STDOUT_ERROR: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// N of `--max-added Nx`, if the limit was given so (for the messages).
static RELATIVE_WORK_LIMIT: std::sync::OnceLock<f64> = std::sync::OnceLock::new();

/// Remembers a relative `--max-added` for [`one_line`].
fn note_work_limit(limit: args::WorkLimit) {
    if let args::WorkLimit::PerInputVertex(times) = limit {
        let _ = RELATIVE_WORK_LIMIT.set(times);
    }
}

/// Remembers `result` of a write to standard output (see [`STDOUT_ERROR`]).
/// A standard output closed at start ([`crate::stdout_closed`]) takes any
/// write: it is `/dev/null`.
pub(crate) fn note_stdout_result(result: std::io::Result<()>) {
    let error = match result {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Some(e.to_string()),
        _ if crate::stdout_closed() => Some(STDOUT_IS_CLOSED.to_string()),
        _ => None,
    };
    if let Some(e) = error {
        let mut first = STDOUT_ERROR.lock().unwrap_or_else(|p| p.into_inner());
        first.get_or_insert(e);
    }
}

/// Why nothing can be written to a standard output closed at start.
const STDOUT_IS_CLOSED: &str = "Bad file descriptor (it is closed)";

/// Refuses, before any work, a command that `writes` to standard output
/// (a file, or its printout) when standard output is closed (`>&-`): what
/// it wrote would vanish.
fn refuse_closed_stdout(writes: bool) -> anyhow::Result<()> {
    if writes && crate::stdout_closed() {
        bail!("standard output: cannot write: {STDOUT_IS_CLOSED}");
    }
    Ok(())
}

/// Set when a run writes a file to standard output (`-o -`, `--stats-json
/// /dev/stdout`, ...): its printout then goes to standard error, so that
/// what lands on standard output is that file alone.
pub(crate) static PRINTOUT_TO_STDERR: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// `eprintln!` that never panics, for the same reason; one line, escaped
/// as [`say!`] escapes.
macro_rules! complain {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let line = crate::cli::escaped(&format!($($arg)*), false);
        crate::progress::suspend(|| {
            let _ = writeln!(std::io::stderr(), "{line}");
        });
    }};
}
mod args;
mod batch;
mod judge;
mod paths;
mod render;
mod sweep;

use args::{legacy_args, Cli, Command, RunArgs, Settings};

use sweep::{combination_path, run_sweep, smallest, smallest_note, sweep_combinations};

use judge::*;
use paths::*;
use render::*;

use delmesh::attributes::{properties_named, Attributes, Group, Kind, Tolerances, Transfer, NO_VALUE};
use delmesh::mesh::{EdgeId, Surface};
use delmesh::prune::PruneStats;
use delmesh::refine::{self, Options, Stats, Worklist};
use delmesh::samples::Score;

/// Entry point: parse, run, print errors as one line, exit 1 on failure.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse_from(legacy_args(std::env::args_os())) {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    let result = match cli.command {
        Some(Command::Check {
            input,
            output,
            jobs,
            vertex_map,
            face_map,
            original,
            weld_tolerance,
            quiet,
            gabriel_boundary,
            json,
        }) => {
            if let Some(jobs) = jobs {
                delmesh::parallel::set_threads(usize::from(jobs));
            }
            let maps = MapFiles {
                vertex_map,
                face_map,
                original,
                weld_tolerance,
            };
            run_check(&input, &output, &maps, quiet, gabriel_boundary, json.as_deref())
        }
        Some(Command::Batch(args)) => batch::run_batch(&args),
        Some(Command::Completions { shell }) => {
            let mut cmd = <Cli as clap::CommandFactory>::command();
            let mut buf = Vec::new();
            clap_complete::generate(shell, &mut cmd, "delmesh", &mut buf);
            print_bytes(&buf)
        }
        Some(Command::Render {
            mesh,
            output,
            input,
            azimuth,
            elevation,
            size,
        }) => run_render(
            &mesh,
            &output,
            input.as_deref(),
            delmesh::render::View {
                azimuth,
                elevation,
                size,
            },
        ),
        Some(Command::Man) => {
            let mut buf = Vec::new();
            match clap_mangen::Man::new(<Cli as clap::CommandFactory>::command()).render(&mut buf) {
                Ok(()) => print_bytes(&buf),
                Err(e) => Err(e.into()),
            }
        }
        None => run(&cli.run),
    };
    match result {
        Ok(code) => with_stdout_checked(code),
        Err(e) => {
            complain!("delmesh: {}", one_line(&e));
            ExitCode::from(1)
        }
    }
}

/// Fails once the printout could not be written to standard output (see
/// [`STDOUT_ERROR`]), saying what became of `file` (`fate`: "not
/// written", "left as it was"): called before a file is put in place. A
/// run that exits 1 for its printout then has put nothing in place, and an
/// input to be rewritten in place is as it was.
pub(crate) fn printout_intact(file: &Path, fate: &str) -> anyhow::Result<()> {
    match STDOUT_ERROR.lock().unwrap_or_else(|p| p.into_inner()).as_deref() {
        Some(e) => bail!("standard output: cannot write: {e}; {} {fate}", file.display()),
        None => Ok(()),
    }
}

/// `code`, unless writing to standard output failed: then that error is
/// said and the exit status is 1.
fn with_stdout_checked(code: ExitCode) -> ExitCode {
    let error = STDOUT_ERROR.lock().unwrap_or_else(|p| p.into_inner()).take();
    match error {
        Some(e) => {
            complain!("delmesh: standard output: cannot write: {e}");
            ExitCode::from(1)
        }
        None => code,
    }
}

/// Writes generated text to stdout (a closed pipe is not an error; a full
/// disk is, see [`STDOUT_ERROR`]).
fn print_bytes(bytes: &[u8]) -> anyhow::Result<ExitCode> {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    note_stdout_result(out.write_all(bytes).and_then(|()| out.flush()));
    Ok(ExitCode::SUCCESS)
}

/// Prints a command-line parse error as one line, `delmesh: ...` like every
/// other error, and returns exit status 2 (clap's); help and version
/// requests are printed in full, as asked.
fn usage_error(e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion)
        || e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    {
        let printed = e.print().and_then(|()| std::io::Write::flush(&mut std::io::stdout()));
        if !e.use_stderr() {
            note_stdout_result(printed);
        }
        return with_stdout_checked(ExitCode::from(if e.use_stderr() { 2 } else { 0 }));
    }
    if let Some(file) = mesh_given_as_command(&e) {
        complain!("delmesh: {file:?} is not a command: give the mesh to refine with -i (delmesh -i {file} -o OUTPUT)");
        return ExitCode::from(2);
    }
    complain!("delmesh: {} (see --help)", usage_line(&e.to_string()));
    ExitCode::from(2)
}

/// The file a user gave where a command goes (`delmesh bunny.obj`): an
/// unknown command that is an existing file or has a mesh file's extension.
fn mesh_given_as_command(e: &clap::Error) -> Option<String> {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if e.kind() != ErrorKind::InvalidSubcommand {
        return None;
    }
    let Some(ContextValue::String(given)) = e.get(ContextKind::InvalidSubcommand) else {
        return None;
    };
    let path = Path::new(given.strip_suffix(".gz").unwrap_or(given));
    let mesh_extension = path
        .extension()
        .and_then(|x| x.to_str())
        .is_some_and(|x| ["obj", "off", "ply", "stl"].contains(&x.to_ascii_lowercase().as_str()));
    (mesh_extension || Path::new(given).is_file()).then(|| given.clone())
}

/// Clap's multi-line message as one line: its `error: ` prefix, the usage
/// block, tips and the pointer to --help dropped, the rest joined.
fn usage_line(message: &str) -> String {
    let mut parts = Vec::new();
    let mut in_usage = false;
    for line in message.lines().map(str::trim) {
        if line.starts_with("Usage:") {
            in_usage = true;
            continue;
        }
        if line.is_empty() {
            in_usage = false;
            continue;
        }
        if in_usage || line.starts_with("tip:") || line.starts_with("For more information") {
            continue;
        }
        parts.push(line.strip_prefix("error: ").unwrap_or(line));
    }
    match parts.split_first() {
        Some((&"the following required arguments were not provided:", missing)) => {
            format!("missing {}", missing.join(", "))
        }
        _ => parts.join(" "),
    }
}

/// Whether `e` is edges stuck for a reason other settings may avoid (the
/// order of work, the samples chosen): not near-coincident vertices, whose
/// error already names the remedy (and where most settings stall).
pub(crate) fn stuck_elsewhere(e: &anyhow::Error) -> bool {
    matches!(
        e.downcast_ref(),
        Some(delmesh::Error::Unsplittable { near_coincident, .. }) if near_coincident.edges == 0
    )
}

/// The note on an input with near-coincident vertices
/// ([`delmesh::mesh::InputFigures::near_coincident_edges`]) when some are
/// so close (below [`CERTAIN_TROUBLE`] of their part's size) that refining
/// will take long or fail: printed before refining, so that the remedy is
/// known at once. Fewer, less close ones (the Stanford dragon scan has 4
/// edges 1e-8 m long, 3.7e-8 of its size, and refines as well welded or
/// not) are named only if a run fails.
pub(crate) fn near_coincident_note(figures: &delmesh::mesh::InputFigures) -> Option<String> {
    let near = delmesh::error::NearCoincident::of(figures);
    (near.edges > 0 && figures.near_coincident_ratio < CERTAIN_TROUBLE).then(|| {
        format!(
            "{} edge(s) shorter than {:.1e} (1e-7 of their part's size): near-coincident vertices, as marching cubes \
             leaves; refining around them can stall or add millions of vertices; {}",
            near.edges,
            near.shorter_than,
            near.remedy()
        )
    })
}

/// The note on an input whose surface folds flat onto itself
/// ([`Surface::folded_edges`]): how many edges, the first named as `input`'s
/// file numbers its vertices, and what follows. Such edges are never
/// flipped, so an inverted triangle of a flat mesh (a 2D mesh with a
/// flipped element) costs added vertices where flips alone would do: the
/// user should learn the cause, and that the output keeps the fold.
pub(crate) fn fold_note(surface: &Surface, input: &io::InputMesh) -> Option<String> {
    let [a, b] = surface.first_folded_edge?;
    Some(format!(
        "{} input edge(s) where the surface folds flat onto itself (the two faces in one plane, on the same side of \
         the edge: a face turned over in a flat part, or the rim of a flat two-sided sheet), the first between {} \
         and {}; such an edge is never flipped (a non-Delaunay one is split), and the output keeps the fold",
        surface.folded_edges,
        input.vertex_name(a.0),
        input.vertex_name(b.0)
    ))
}

/// The note on an output with [`GROWTH_NOTE`] or more added vertices per
/// input vertex: why (the smallest input angle), and what helps that the run
/// did not use: other settings (`shells`: the run had them), as `--shells
/// -s 4` adds 195 vertices where the defaults add 209,083 on a height field
/// of 1 x 0.001 cells, 43,331 for 158,125 on a box whose sides are fans of
/// obtuse slivers, though 19,448 for 7,051 on mpi_triang; pruning (`pruned`)
/// or `--smallest` (`smallest`: nothing else to suggest); a weld for marching
/// cubes output. The user who feeds the mesh to a solver should know before
/// paying for its size.
pub(crate) fn growth_note(surface: &Surface, shells: bool, pruned: bool, smallest: bool) -> Option<String> {
    let n = surface.n_input_vertices;
    let added = surface.positions.len().saturating_sub(n);
    (n > 0 && added >= GROWTH_NOTE * n).then(|| {
        let mut helps = String::new();
        if !smallest {
            if !shells {
                helps += "; other settings may add far fewer (try --shells -s 4, concentric shells)";
            }
            helps += if pruned {
                "; --smallest tries 24 settings and keeps the smallest"
            } else {
                "; --prune or --smallest remove many of them"
            };
        }
        // Flat parts that are not exactly flat, a cause too if any (a pass
        // over the edges, made only for an output this large), unless
        // near-coincident vertices are (the weld is then what helps).
        let nearly_flat = match surface.input_figures.near_coincident_edges {
            0 => match surface.nearly_flat_input_edges() {
                0 => String::new(),
                edges => format!("; {}", delmesh::error::nearly_flat_hint(edges)),
            },
            _ => String::new(),
        };
        let per_vertex = added as f64 / n as f64;
        let angle = sig(surface.input_figures.min_angle);
        // Flat edges that the attributes keep from flipping (their thin
        // triangles are split instead): the first cause to name if any
        // (the remedy costs nothing but the attributes), and then not the
        // weld of marching cubes output, which has none.
        match surface.flat_edges_apart {
            0 => format!(
                "{per_vertex:.0} added vertices per input vertex: the smallest input angle ({angle} rad) calls for \
                 vertices at its scale{nearly_flat}{helps}; marching cubes output loses the cause to a weld (README: \
                 Real-world meshes)"
            ),
            edges => format!(
                "{per_vertex:.0} added vertices per input vertex: {edges} flat input edge(s) are never flipped, as the \
                 attributes differ across them (a seam, a group or face property boundary, or values not one affine \
                 field there): \
                 --drop-attributes lets them flip; the smallest input angle ({angle} rad) calls for vertices at its \
                 scale{nearly_flat}{helps}"
            ),
        }
    })
}

/// When a stack or queue run switched to longest edge first: after how many
/// flips, why, and how to keep the order.
pub(crate) fn longest_first_note(stats: &refine::Stats) -> Option<String> {
    stats.longest_first_after.map(|flips| {
        format!(
            "after {flips} flips (over {} per edge) the rest was taken longest edge first, as by -ds pqueue: the stack \
             and the queue flip a large flat region far from Delaunay quadratically often (--keep-order keeps the order)",
            refine::FLIPS_PER_EDGE_BEFORE_LONGEST_FIRST
        )
    })
}

/// Added vertices per input vertex from which [`growth_note`] speaks: needle
/// meshes reach it (mpi_triang: 78 with the defaults; marching cubes output
/// up to 70), CAD parts with slivers stay below (the anchor 8, the rotor
/// 7.8), scans far below (the dragon 1.3).
const GROWTH_NOTE: usize = 10;

/// Edges shorter than this fraction of the mesh's size put its samples
/// below what doubles can place at its coordinates: [`near_coincident_note`].
const CERTAIN_TROUBLE: f64 = 1e-9;

/// Input vertices from which the main command formats the input's vertex
/// lines on a second thread while it refines. Below, starting the thread
/// costs more than it saves (interleaved runs: the bunny, elephant and
/// fandisk, 1,839–6,475 vertices, each 0.16–0.2 ms slower with it; the
/// armadillo, 26,002 vertices, 2 ms faster).
const FORMAT_AHEAD_MIN_VERTICES: usize = 10_000;

/// The error and its causes on one line.
fn one_line(e: &anyhow::Error) -> String {
    let mut s = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !s.contains(&c) {
            s.push_str(": ");
            s.push_str(&c);
        }
    }
    // A relative limit (`--max-added 20x`) is named as given, beside the
    // count it made for this input.
    let library_error = e.chain().find_map(|c| c.downcast_ref::<delmesh::Error>());
    if let (Some(delmesh::Error::WorkLimit { limit, .. }), Some(times)) = (library_error, RELATIVE_WORK_LIMIT.get()) {
        s = s.replacen(
            &format!("--max-added {limit})"),
            &format!("--max-added {times}x, {limit} for this input)"),
            1,
        );
    }
    // One line, and nothing that drives a terminal: a path or a header
    // name may hold control characters too (file tokens are escaped where
    // they are quoted, `io::formats::show`).
    elide_long_words(&escaped(&s, true))
}

/// The most characters without a space that a message keeps in a row.
const LONG_WORD: usize = 300;

/// `line` with each run of more than [`LONG_WORD`] characters without a
/// space (a path into a folder deeper than the system allows a path to
/// be, 4 KiB and more) cut to its first and last 140 around `...`: an
/// error stays a line that can be read.
fn elide_long_words(line: &str) -> String {
    if line.len() <= LONG_WORD {
        return line.to_string();
    }
    let mut out = String::with_capacity(line.len().min(4 * LONG_WORD));
    for (i, word) in line.split(' ').enumerate() {
        if i > 0 {
            out.push(' ');
        }
        let chars = word.chars().count();
        if chars <= LONG_WORD {
            out.push_str(word);
        } else {
            out.extend(word.chars().take(140));
            out.push_str("...");
            out.extend(word.chars().skip(chars - 140));
        }
    }
    out
}

/// `s` with its control characters escaped (`\n`, `\u{1b}`), or with line
/// feeds made spaces if `join_lines`.
pub(crate) fn escaped(s: &str, join_lines: bool) -> String {
    let mut line = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '\n' if join_lines => line.push(' '),
            c if c.is_control() => line.extend(c.escape_debug()),
            c => line.push(c),
        }
    }
    line
}

/// `x` with six significant digits, in plain notation where that reads well.
fn sig(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() {
        return format!("{x}");
    }
    if (1e-3..1e7).contains(&a) {
        let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.5e}")
    }
}

fn score_of(s: &str) -> Score {
    match s {
        "0" => Score::AllEqual,
        "1" => Score::WeightedCenter,
        "2" => Score::AlwaysCenter,
        "3" => Score::SplitAware,
        _ => Score::Uniform,
    }
}

fn score_name(s: Score) -> &'static str {
    match s {
        Score::AllEqual => "all equal",
        Score::WeightedCenter => "weighted center",
        Score::AlwaysCenter => "always center",
        Score::SplitAware => "split-aware",
        Score::Uniform => "uniform",
    }
}

fn ds_name(w: Worklist) -> &'static str {
    match w {
        Worklist::Stack => "stack",
        Worklist::Queue => "queue",
        Worklist::PriorityQueue => "priority queue",
    }
}

/// One refinement (with `--prune`, pruned): its mesh (`S`: the
/// [`Surface`], or once written only its [`SurfaceCounts`]), its work and
/// its seconds.
struct Run<S> {
    surface: S,
    stats: Stats,
    /// With --prune: what pruning removed.
    pruned: Option<PruneStats>,
    /// Seconds refining, pruning included.
    seconds: f64,
    /// Seconds pruning (a part of `seconds`).
    seconds_prune: f64,
}

/// A run with its refined surface.
type Outcome = Run<Surface>;

/// A run once its mesh is written and its maps staged: its figures without
/// the surface, which is freed before `--check` reads the files back (the
/// full dragon's run with `--check` peaked at 838 MB holding it beside the
/// judge's own memory, and at 521–559 MB without it).
type Finished = Run<SurfaceCounts>;

/// The counts of a refined surface that the record and the printout give.
#[derive(Clone, Copy)]
struct SurfaceCounts {
    /// Vertices of the output.
    vertices: usize,
    /// Faces of the output.
    faces: usize,
    /// Vertices added to the input's.
    added: usize,
}

impl<S> Run<S> {
    /// The seconds of this run, written in `seconds_write`.
    fn seconds(&self, seconds_write: f64) -> stats_json::RunSeconds {
        stats_json::RunSeconds {
            refine: self.seconds,
            prune: self.seconds_prune,
            write: seconds_write,
        }
    }
}

impl Outcome {
    /// The surface, and the rest of the run without it ([`Finished`]).
    fn finish(self) -> (Surface, Finished) {
        let s = &self.surface;
        let counts = SurfaceCounts {
            vertices: s.positions.len(),
            faces: s.topo.n_faces(),
            added: s.positions.len() - s.n_input_vertices,
        };
        let finished = Run {
            surface: counts,
            stats: self.stats,
            pruned: self.pruned,
            seconds: self.seconds,
            seconds_prune: self.seconds_prune,
        };
        (self.surface, finished)
    }
}

impl Finished {
    /// The record of this run, written to `output` in `seconds_write`.
    fn record(&self, options: Options, output: &Path, seconds_write: f64) -> stats_json::RunRecord {
        stats_json::RunRecord {
            options: Some(options),
            output: output.display().to_string(),
            result: Ok(stats_json::RunFigures {
                vertices: self.surface.vertices,
                faces: self.surface.faces,
                added_vertices: self.surface.added,
                pruned: self.pruned,
                stats: Some(self.stats),
            }),
            seconds: self.seconds(seconds_write),
        }
    }
}

/// The first pass of Algorithm 2 on the input, shared by the runs: its
/// non-Delaunay edges, and the seconds it took (counted in every run's
/// refine time); before it, unless `--keep-order`, large flat regions made
/// Delaunay directly (as [`refine::make_delaunay`] does; the flips of convex
/// ones are counted in every run's).
struct FirstPass {
    edges: Vec<EdgeId>,
    seconds: f64,
    flat: FlatRegions,
}

impl FirstPass {
    fn new(surface: &mut Surface, keep_order: bool) -> FirstPass {
        let t = Instant::now();
        let flat = match keep_order {
            true => FlatRegions::default(),
            false => delmesh::flat_regions::make_flat_regions_delaunay(surface),
        };
        let edges = refine::non_delaunay_edges(surface);
        FirstPass {
            edges,
            seconds: t.elapsed().as_secs_f64(),
            flat,
        }
    }
}

/// What the printout says of the flat regions the first pass made Delaunay
/// (none, one or two lines).
fn flat_regions_notes(flat: &FlatRegions) -> Vec<String> {
    let mut notes = Vec::new();
    let convex = &flat.convex;
    if convex.regions > 0 {
        notes.push(format!(
            "{} flipped to Delaunay directly ({} corners, {} flips; Algorithm 2's flips would take about the square of \
             the corners; --keep-order leaves them to it)",
            count(convex.regions, "convex flat region", "convex flat regions"),
            convex.corners,
            convex.flips
        ));
    }
    if flat.rebuilt > 0 {
        notes.push(format!(
            "{} rebuilt to Delaunay directly ({} vertices, as constrained Delaunay triangulations; Algorithm 2's \
             flips could take up to the square of the vertices; --keep-order leaves them to it)",
            count(flat.rebuilt, "flat region", "flat regions"),
            flat.rebuilt_vertices
        ));
    }
    notes
}

fn refine_once(
    mut surface: Surface,
    first_pass: &FirstPass,
    path: &Path,
    options: &Options,
    prune: Option<usize>,
) -> anyhow::Result<Outcome> {
    let start = Instant::now();
    let mut stats = refine::make_delaunay_from(&mut surface, options, &first_pass.edges)
        .with_context(|| path.display().to_string())?;
    stats.flips += first_pass.flat.flips();
    stats.non_delaunay_before = first_pass.flat.non_delaunay_before(stats.non_delaunay_before);
    let out = Outcome {
        surface,
        stats,
        pruned: None,
        seconds: first_pass.seconds + start.elapsed().as_secs_f64(),
        seconds_prune: 0.0,
    };
    Ok(match prune {
        Some(passes) => prune_outcome(out, options, passes),
        None => out,
    })
}

/// `e`, with the worst edge of an [`delmesh::Error::Unsplittable`] named
/// by the numbers `input`'s file gives its vertices.
pub(crate) fn name_stuck_edge(mut e: anyhow::Error, input: &io::InputMesh) -> anyhow::Error {
    if let Some(delmesh::Error::Unsplittable {
        worst_edge: Some(edge), ..
    }) = e.downcast_mut()
    {
        edge.name_vertices(|v| input.vertex_name(v));
    }
    e
}

/// Prunes the mesh of an unpruned `out` in at most `passes` passes.
fn prune_outcome(mut out: Outcome, options: &Options, passes: usize) -> Outcome {
    let start = Instant::now();
    out.pruned = Some(delmesh::prune::prune_passes(
        &mut out.surface,
        options,
        passes,
        progress::prune_hook(),
    ));
    out.seconds_prune = start.elapsed().as_secs_f64();
    out.seconds += out.seconds_prune;
    out
}

/// `n` and its noun, singular for one: `count(1, "face", "faces")` is
/// "1 face" (the printout's counts; `--stats-json` is the machine's).
pub(crate) fn count(n: usize, singular: &str, plural: &str) -> String {
    format!("{n} {}", if n == 1 { singular } else { plural })
}

/// The file name of `path`, for the progress line.
fn file_name(path: &Path) -> String {
    path.file_name()
        .map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned())
}

/// Writes `--vertex-map` for `surface`, read from `input` and written as
/// `written` says, under a temporary name ([`io::stage`]): a row per vertex
/// of the output file, the copies a PLY or OFF output makes at attribute seams
/// (and an OBJ for colours; last in the file) repeating the rows of the
/// vertices they copy.
fn stage_vertex_map(
    path: &Path,
    surface: &Surface,
    input: &io::InputMesh,
    written: &io::Written,
) -> anyhow::Result<io::Staged> {
    let mut sources = surface.vertex_sources();
    let copies: Vec<_> = written.copies_of.iter().map(|&v| sources[v as usize]).collect();
    sources.extend(copies);
    let table = stats_json::vertex_map_csv(&sources, &input.vertex_number);
    Ok(io::stage(path, |w| w.write_all(table.as_bytes()))?)
}

/// Writes `--face-map` for `surface`, whose input faces `origins` holds,
/// written as `written` says (a row per face of the output file, in its
/// order), under a temporary name ([`io::stage`]); with a note for the
/// printout when faces lie across several input faces.
fn stage_face_map(
    path: &Path,
    surface: &Surface,
    origins: &FaceOrigins,
    written: &io::Written,
) -> anyhow::Result<(io::Staged, Option<String>)> {
    let map = face_map::in_file_order(origins.apply(surface), &written.face_order);
    let across = map.iter().filter(|o| !o.inside).count();
    let note = (across > 0).then(|| {
        format!(
            "{across} of {} output faces lie across several input faces (flipped or rebuilt in flat regions): their face-map \
             rows name the face under their centroid, with inside 0",
            map.len()
        )
    });
    Ok((io::stage(path, |w| face_map::write_csv(w, &map))?, note))
}

/// Puts a run's output in place, then its side files ([`SideFiles`]), all
/// staged complete beforehand: a side file that could not be written left
/// nothing in place, and an output that cannot be put in place (a rename
/// refused) leaves the side files out too; nor is anything put in place
/// once the printout failed ([`printout_intact`]: the run's summary is
/// printed before this).
fn commit_all(mesh: io::Staged, output: &Path, side: SideFiles, in_place: bool) -> anyhow::Result<()> {
    let fate = match (mesh.is_in_place(), in_place) {
        (true, _) => "written (a stream or device), no other file",
        (false, true) => "left as it was",
        (false, false) => "not written",
    };
    printout_intact(output, fate)?;
    mesh.commit()?;
    for file in side {
        file.commit()
            .with_context(|| format!("{} is written, but", output.display()))?;
    }
    Ok(())
}

/// Side files (`--vertex-map`, `--face-map`, `--stats-json`, `--stats-csv`) staged under
/// temporary names, in the order they are put in place.
type SideFiles = Vec<io::Staged>;

/// What an error writing a side file becomes once the mesh went to a
/// stream (standard output, a device), where it cannot be taken back: says
/// that the mesh is written and complete. Other errors as they are: the
/// mesh is not yet in place then ([`io::Staged`]).
fn mesh_streamed<'a>(staged: &io::Staged, output: &'a Path) -> impl Fn(anyhow::Error) -> anyhow::Error + Copy + 'a {
    let streamed = staged.is_in_place();
    move |e| {
        if streamed {
            e.context(format!("{} is written and complete, but", output.display()))
        } else {
            e
        }
    }
}

/// The record of a run of `options` that failed with `e`, after its phases took
/// `seconds` (those that did not run: 0).
pub(crate) fn failure_record(
    options: Options,
    output: &Path,
    e: &anyhow::Error,
    seconds: stats_json::RunSeconds,
) -> stats_json::RunRecord {
    stats_json::RunRecord {
        options: Some(options),
        output: output.display().to_string(),
        result: Err((error_kind(e), one_line(e))),
        seconds,
    }
}

/// A short name for why a run failed (`error_kind` in the JSON and CSV).
fn error_kind(e: &anyhow::Error) -> &'static str {
    match e.downcast_ref::<delmesh::Error>() {
        Some(delmesh::Error::WorkLimit { .. }) => "work_limit",
        Some(delmesh::Error::Unsplittable { .. }) => "unsplittable",
        Some(delmesh::Error::OutOfIds { .. }) => "out_of_ids",
        Some(delmesh::Error::Write { .. }) => "write",
        _ if e.downcast_ref::<CheckFailed>().is_some() => "check",
        _ => "other",
    }
}

/// A run's input, read and built, and where it goes: what the printout,
/// `--stats-json` and `--stats-csv` need besides the runs themselves.
struct Report<'a> {
    args: &'a RunArgs,
    input_path: &'a Path,
    input: &'a io::InputMesh,
    figures: delmesh::mesh::InputFigures,
    folded_edges: usize,
    lower_bound: usize,
    constants: delmesh::samples::SampleConstants,
    output: &'a Path,
    t0: Instant,
    read_s: f64,
    build_s: f64,
    /// With `--face-map`: the input's faces, taken before refinement.
    face_origins: Option<&'a FaceOrigins<'a>>,
}

impl Report<'_> {
    /// Writes the JSON and CSV files asked for; returns the total seconds
    /// they give (the summary prints the same).
    fn write(&self, runs: &[stats_json::RunRecord], refined: bool) -> anyhow::Result<f64> {
        let (total, files) = self.stage(runs, refined)?;
        for file in files {
            file.commit()?;
        }
        Ok(total)
    }

    /// [`Report::write`], the files left staged (under temporary names) for
    /// the caller to put in place.
    fn stage(&self, runs: &[stats_json::RunRecord], refined: bool) -> anyhow::Result<(f64, SideFiles)> {
        let mut files = SideFiles::new();
        let total = self.t0.elapsed().as_secs_f64();
        if let Some(json) = &self.args.stats_json {
            let inv = stats_json::Invocation {
                input_path: self.input_path,
                input: self.input,
                figures: self.figures,
                lower_bound: self.lower_bound,
                folded_edges: self.folded_edges,
                output: self.output,
                repaired: self.args.repaired.as_deref(),
                refined,
                gabriel_boundary: self.args.settings.gabriel_boundary,
                seconds_read: self.read_s,
                seconds_build: self.build_s,
                seconds_total: total,
            };
            let doc = stats_json::document(&inv, self.constants, runs);
            files.push(io::stage(json, |w| w.write_all(doc.as_bytes()))?);
        }
        if let Some(csv) = &self.args.stats_csv {
            let table = stats_json::csv(self.input_path, runs);
            files.push(io::stage(csv, |w| w.write_all(table.as_bytes()))?);
        }
        Ok((total, files))
    }
}

/// The main command: read and build the input, then refine it once, with
/// every setting of `-all`, or not at all (`--no-refine`), and write what
/// was asked. Everything that can be refused before the work is
/// ([`destinations`]), and nothing is put in place before the run has
/// succeeded.
fn run(args: &RunArgs) -> anyhow::Result<ExitCode> {
    let Some(input_path) = args.input.as_deref() else {
        bail!("no input: give one with -i FILE")
    };
    let (output, in_place) = destinations(args, input_path)?;
    io::set_sync_writes(args.settings.sync);
    note_work_limit(args.settings.max_added);
    if let Some(jobs) = args.jobs {
        delmesh::parallel::set_threads(usize::from(jobs));
    }
    crate::working_on(input_path);
    let _progress = progress::start(progress::should_draw(args.progress, args.quiet));
    let t0 = Instant::now();
    progress::phase(Phase::Read {
        name: file_name(input_path),
        size: std::fs::metadata(input_path).ok().map(|m| m.len()),
    });
    let mut input = args
        .settings
        .read(input_path, &output, !args.no_refine, args.face_map.is_some())?;
    let read_s = t0.elapsed().as_secs_f64();
    let t_build = Instant::now();
    progress::phase(Phase::Build {
        faces: input.triangles.len(),
    });
    let mut surface = args.settings.build(&mut input, input_path)?;
    let transfer =
        (!input.attributes.is_empty()).then(|| Transfer::new(input.attributes.clone(), &input.triangles, &surface));
    let face_origins = args
        .face_map
        .is_some()
        .then(|| FaceOrigins::new(&input.triangles, &input.triangle_polygon, &surface));
    let build_s = t_build.elapsed().as_secs_f64();
    progress::phase(Phase::Idle);
    // The input's non-Delaunay edges: the first pass of every run, and where
    // the lower bound is counted.
    let first_pass = FirstPass::new(&mut surface, args.settings.keep_order || args.no_refine);
    let lower_bound = surface.added_vertex_lower_bound_among(&first_pass.edges);
    if !args.quiet {
        say_input(input_path, &input, &surface, lower_bound, transfer.as_ref());
        for note in flat_regions_notes(&first_pass.flat) {
            say!("note    {note}");
        }
    }
    // The repaired input: with -all put in place now (the sweep writes its
    // files as it goes), otherwise staged and put in place with the other
    // side files at the end, so that a run that fails leaves none.
    let mut repaired_staged = None;
    if let Some(repaired) = &args.repaired {
        progress::phase(Phase::Write {
            name: file_name(repaired),
        });
        let staged = io::stage_mesh_after(repaired, &Default::default(), &input.positions, &input.triangles)?;
        progress::phase(Phase::Idle);
        if args.all {
            printout_intact(repaired, "not written")?;
            staged.commit()?;
            say_repaired(args);
        } else {
            repaired_staged = Some(staged);
        }
    }
    let report = Report {
        args,
        input_path,
        input: &input,
        figures: surface.input_figures,
        folded_edges: surface.folded_edges,
        lower_bound,
        constants: refine::sample_constants(&surface),
        output: &output,
        t0,
        read_s,
        build_s,
        face_origins: face_origins.as_ref(),
    };
    let side: SideFiles = repaired_staged.into_iter().collect();
    if args.all {
        run_sweep(&report, &surface, &first_pass, transfer.as_ref())
    } else if args.no_refine {
        run_unrefined(&report, &surface, transfer.as_ref(), side, in_place)
    } else {
        run_refined(&report, surface, &first_pass, transfer.as_ref(), side, in_place)
    }
}

/// The output mesh of the main command (the input itself when rewritten in
/// place, `-` for standard output), and whether it rewrites the input in
/// place; or why the run is refused before any work: a folder that cannot
/// be written, two of its files that are one, a printout that would go
/// into its input or nowhere, a format that cannot hold what it would get.
fn destinations(args: &RunArgs, input_path: &Path) -> anyhow::Result<(PathBuf, bool)> {
    let from_stdin = io::is_standard_input(input_path);
    // Without -o the output is the input, rewritten in place; standard
    // input has no file to rewrite, so its mesh goes to standard output.
    let output = match &args.output {
        Some(o) => o.clone(),
        None if from_stdin => PathBuf::from("-"),
        None => input_path.to_owned(),
    };
    if args.all && io::is_stream(&output) {
        bail!(
            "-all writes {} files named after -o: give -o a file name, not a stream or device",
            sweep_combinations(args.extended).len()
        );
    }
    if args.output.is_none() && !from_stdin {
        // The output would be the input: the input is what is wrong (a
        // missing one is said as with -o, not as a missing output).
        if let Err(source) = std::fs::metadata(input_path) {
            return Err(delmesh::Error::Read {
                path: input_path.to_owned(),
                source,
            }
            .into());
        }
    }
    if !from_stdin && input_path.is_dir() {
        bail!(
            "{}: cannot read: it is a folder, not a mesh file (`delmesh batch -d OUT_FOLDER {}` refines the meshes in it)",
            input_path.display(),
            input_path.display()
        );
    }
    check_output_dir(&output)?;
    // Every file this run writes, with what it is: no two may be one file.
    let mut written: Vec<(String, PathBuf)> = Vec::new();
    if args.all {
        for o in sweep_combinations(args.extended) {
            let path = combination_path(&output, &o);
            // (Each name: one may be a folder, or a link that leads nowhere.)
            check_output_dir(&path)?;
            written.push(("an -all output".into(), path));
        }
    } else {
        written.push(("the output".into(), output.clone()));
    }
    let meshes = written.len();
    let extras = [
        ("--repaired", &args.repaired),
        ("--stats-json", &args.stats_json),
        ("--stats-csv", &args.stats_csv),
        ("--chart", &args.chart),
        ("--vertex-map", &args.vertex_map),
        ("--face-map", &args.face_map),
    ];
    for (flag, path) in extras {
        if let Some(path) = path {
            check_output_dir(path)?;
            written.push((flag.into(), path.clone()));
        }
    }
    // With --check, an output that fails goes to OUTPUT.rejected instead:
    // that name may not be the input or another file of the run either.
    if args.check {
        for i in 0..meshes {
            let mut rejected = written[i].1.as_os_str().to_owned();
            rejected.push(".rejected");
            written.push(("the rejected output (--check)".into(), rejected.into()));
        }
    }
    // (Without -o the output is the input, rewritten in place by design.)
    let in_place = (args.output.is_none() && !args.all && !from_stdin).then_some(0);
    refuse_same_files(input_path, in_place, &written)?;
    if let Some(chart) = &args.chart {
        Format::of_picture(chart, &format!("--chart {}", chart.display())).map_err(anyhow::Error::msg)?;
    }
    // Any output on standard output: the printout goes to standard error.
    if written.iter().any(|(_, p)| io::standard_stream(p) == Some(1)) {
        PRINTOUT_TO_STDERR.store(true, std::sync::atomic::Ordering::Relaxed);
    }
    refuse_printout_into_inputs(&[input_path], args.quiet)?;
    let printout_to_stdout = !args.quiet && !PRINTOUT_TO_STDERR.load(std::sync::atomic::Ordering::Relaxed);
    refuse_closed_stdout(printout_to_stdout || written.iter().any(|(_, p)| io::standard_stream(p) == Some(1)))?;
    if in_place.is_some() && !std::fs::metadata(input_path).is_ok_and(|m| m.is_file()) {
        bail!(
            "{}: not a regular file, so it cannot be rewritten in place; give an output with -o",
            input_path.display()
        );
    }
    if args.check && io::is_stream(&output) {
        bail!("{}: --check needs an output file it can read back", output.display());
    }
    if !args.no_refine && io::output_format(&output) == io::Format::Stl {
        bail!("{}: {STL_REFUSED}", output.display());
    }
    // The repaired input is what `check` compares outputs with: it must
    // hold the mesh exactly, which STL's f32 cannot (nor its triangle soup
    // the copies repair makes to cut a surface apart).
    if let Some(repaired) = &args.repaired {
        if io::output_format(repaired) == io::Format::Stl {
            bail!(
                "{}: --repaired cannot be STL (its f32 coordinates and welded soup cannot hold the repaired mesh exactly): use OBJ, OFF or PLY",
                repaired.display()
            );
        }
    }
    let compressed = input_path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gz"));
    if in_place.is_some() && compressed {
        bail!(
            "{}: cannot rewrite this input in place; give an output with -o",
            input_path.display()
        );
    }
    Ok((output, in_place.is_some()))
}

/// Prints the input's lines of the summary: its counts and figures, the
/// lower bound, what repair did or the renumbering, its attributes, notes.
fn say_input(
    input_path: &Path,
    input: &io::InputMesh,
    surface: &Surface,
    lower_bound: usize,
    transfer: Option<&Transfer>,
) {
    let figures = surface.input_figures;
    // With --repair the counts are the repaired mesh's (what is refined),
    // said so; the file's faces in brackets.
    let counts = if input.repair.is_some() {
        format!(
            "{}, {} after repair ({} in the file)",
            count(input.positions.len(), "vertex", "vertices"),
            count(input.triangles.len(), "triangle", "triangles"),
            count(input.faces_in_file, "face", "faces")
        )
    } else {
        format!(
            "{}, {} ({})",
            count(input.positions.len(), "vertex", "vertices"),
            count(input.faces_in_file, "face", "faces"),
            count(input.triangles.len(), "triangle", "triangles")
        )
    };
    say!(
        "input   {}: {counts}; min angle {} rad; edge length {} .. {}",
        input_path.display(),
        sig(figures.min_angle),
        sig(figures.min_edge),
        sig(figures.max_edge)
    );
    // Flat edges the attributes keep apart count as if they were not flat:
    // the bound is then for meshes that keep the attributes.
    let kept = match (surface.flat_edges_apart, lower_bound) {
        (0, _) => "",
        (_, 0) => " and these attributes",
        _ => " and these attributes (--drop-attributes lets every flat edge flip)",
    };
    say!(
        "bound   any Delaunay mesh with this geometry{kept} adds at least {}",
        count(lower_bound, "vertex", "vertices")
    );
    if let Some(report) = &input.repair {
        if report.is_clean() {
            say!("repair  nothing to repair");
        }
        for line in report.lines() {
            say!("repair  {line}");
        }
    } else if input.welded > 0 || input.unreferenced > 0 {
        say!("        {}", renumbered_line(input.welded, input.unreferenced));
    }
    if let Some(t) = transfer {
        say!("        attributes: {}", describe_attributes(t.input()));
    }
    let notes = [near_coincident_note(&figures), fold_note(surface, input)];
    for note in input.notes.iter().chain(notes.iter().flatten()) {
        say!("note    {note}");
    }
}

/// The summary's line for `--repaired`, unless `--quiet`.
fn say_repaired(args: &RunArgs) {
    if let (Some(repaired), false) = (&args.repaired, args.quiet) {
        say!("        repaired input written to {}", repaired.display());
    }
}

/// `--no-refine`: the input written as read (converted, repaired), with
/// its side files (`side`: the repaired input, if any, staged).
fn run_unrefined(
    report: &Report,
    surface: &Surface,
    transfer: Option<&Transfer>,
    mut side: SideFiles,
    in_place: bool,
) -> anyhow::Result<ExitCode> {
    let (args, output) = (report.args, report.output);
    let t1 = Instant::now();
    progress::phase(Phase::Write {
        name: file_name(output),
    });
    let (written, staged) = write_output(
        output,
        report.input_path,
        report.input,
        surface,
        transfer,
        &Default::default(),
    )?;
    let write_s = t1.elapsed().as_secs_f64();
    progress::phase(Phase::Idle);
    // The side files before the mesh is put in place (as in `run_refined`).
    let streamed = mesh_streamed(&staged, output);
    if let Some(map) = &args.vertex_map {
        side.push(stage_vertex_map(map, surface, report.input, &written).map_err(streamed)?);
    }
    if let (Some(map), Some(origins)) = (&args.face_map, report.face_origins) {
        side.push(stage_face_map(map, surface, origins, &written).map_err(streamed)?.0);
    }
    let run = stats_json::RunRecord {
        options: None,
        output: output.display().to_string(),
        result: Ok(stats_json::RunFigures {
            vertices: surface.positions.len(),
            faces: surface.topo.n_faces(),
            added_vertices: 0,
            pruned: None,
            stats: None,
        }),
        seconds: stats_json::RunSeconds {
            write: write_s,
            ..Default::default()
        },
    };
    let (total, reports) = report.stage(&[run], false).map_err(streamed)?;
    side.extend(reports);
    // The summary before the files are put in place: a printout that
    // cannot be written leaves them out (`commit_all`).
    if !args.quiet {
        for note in &written.notes {
            say!("note    {note}");
        }
        say!(
            "output  {}: {}, {} (not refined: --no-refine)",
            output.display(),
            count(surface.positions.len(), "vertex", "vertices"),
            count(surface.topo.n_faces(), "face", "faces")
        );
        say_repaired(args);
        say!(
            "seconds {:.4} total (read {:.4}, build {:.4}, write {:.4})",
            total,
            report.read_s,
            report.build_s,
            write_s
        );
    }
    commit_all(staged, output, side, in_place)?;
    Ok(ExitCode::SUCCESS)
}

/// One refinement (or `--smallest`'s best of 24), pruned if asked, written
/// and checked if asked, with its side files (`side`: the repaired input,
/// if any, staged).
fn run_refined(
    report: &Report,
    surface: Surface,
    first_pass: &FirstPass,
    transfer: Option<&Transfer>,
    mut side: SideFiles,
    in_place: bool,
) -> anyhow::Result<ExitCode> {
    let (args, input_path, input, output) = (report.args, report.input_path, report.input, report.output);
    let mut options = args.settings.options(surface.n_input_vertices);
    options.progress = progress::refine_hook();
    progress::phase(Phase::Refine);
    let mut vertex_lines = io::VertexLines::default();
    let mut pruned_settings = 0;
    // (A failed run's record has the seconds it refined.)
    let refine_start = Instant::now();
    let result = if args.smallest {
        let start = Instant::now();
        let passes = args.settings.prune().unwrap_or(delmesh::prune::MAX_PASSES);
        smallest(surface, first_pass, input_path, &options, args.jobs, passes).map(|(o, mut out, pruned)| {
            options = o;
            pruned_settings = pruned;
            out.seconds = start.elapsed().as_secs_f64(); // all 24 runs
            out
        })
    } else {
        // The input's vertex lines do not change: on a spare core, format
        // them while this thread refines (OBJ or OFF output without
        // attributes), unless the mesh is too small to repay starting the
        // thread. (The size first: asking for the cores reads cgroup files.)
        let format = io::output_format(output);
        let ahead = input.positions.len() >= FORMAT_AHEAD_MIN_VERTICES
            && transfer.is_none()
            && matches!(format, io::Format::Obj | io::Format::Off)
            && args.jobs.is_none_or(|j| j > 1)
            && delmesh::parallel::cores() > 1;
        std::thread::scope(|scope| {
            // (None if the thread cannot be started: the writer then
            // formats the lines itself.)
            let lines = ahead
                .then(|| {
                    let positions: &[[f64; 3]] = bytemuck::cast_slice(&input.positions);
                    delmesh::parallel::try_spawn(scope, move || io::VertexLines::new(positions, format))
                })
                .flatten();
            let out = refine_once(surface, first_pass, input_path, &options, args.settings.prune());
            vertex_lines = lines
                .map(|h| h.join().expect("formatting does not panic"))
                .unwrap_or_default();
            out
        })
    };
    let out = match result {
        Ok(out) => out,
        Err(e) => {
            let e = name_stuck_edge(e, input);
            progress::phase(Phase::Idle);
            let seconds = stats_json::RunSeconds {
                refine: first_pass.seconds + refine_start.elapsed().as_secs_f64(),
                ..Default::default()
            };
            report.write(&[failure_record(options, output, &e, seconds)], true)?;
            // Which edges get stuck depends on the order of work and the
            // samples chosen: other settings often get through.
            if stuck_elsewhere(&e) && !args.smallest {
                return Err(anyhow::anyhow!(
                    "{}; other settings may get through (--smallest tries 24 and keeps the smallest that does)",
                    one_line(&e)
                ));
            }
            return Err(e);
        }
    };
    let t1 = Instant::now();
    progress::phase(Phase::Write {
        name: file_name(output),
    });
    let (mut written, mut staged) = write_output(output, input_path, input, &out.surface, transfer, &vertex_lines)?;
    let write_s = t1.elapsed().as_secs_f64();
    progress::phase(Phase::Idle);
    drop(vertex_lines);
    // The mesh is complete under a temporary name: the side files are
    // written before it is checked and put in place, so that a side file
    // that cannot be written leaves no output, and the input of a run in
    // place untouched. (A mesh written to a stream is there already.)
    let streamed = mesh_streamed(&staged, output);
    let mut vertex_map = None;
    if let Some(map) = &args.vertex_map {
        vertex_map = Some((
            stage_vertex_map(map, &out.surface, input, &written).map_err(streamed)?,
            map.as_path(),
        ));
    }
    let mut face_map = None;
    if let (Some(map), Some(origins)) = (&args.face_map, report.face_origins) {
        let (staged_map, note) = stage_face_map(map, &out.surface, origins, &written).map_err(streamed)?;
        face_map = Some((staged_map, map.as_path()));
        written.notes.extend(note);
    }
    // (For the printout only: a pass over the edges when the mesh grew a
    // lot.)
    let growth = (!args.quiet)
        .then(|| growth_note(&out.surface, options.shells, out.pruned.is_some(), args.smallest))
        .flatten();
    // Everything else reads the files: the surface goes before the judge
    // reads them back.
    let (surface, out) = out.finish();
    drop(surface);
    let t_check = Instant::now();
    let mut checked_files = None;
    if args.check {
        let keep_files = args.vertex_map.is_some() || args.face_map.is_some();
        staged = match check_output(
            input_path,
            input,
            staged,
            output,
            keep_files,
            args.settings.gabriel_boundary,
        ) {
            Ok((staged, files)) => {
                checked_files = files;
                staged
            }
            Err(e) => {
                report.write(&[failure_record(options, output, &e, out.seconds(write_s))], true)?;
                return Err(e);
            }
        };
    }
    let check_s = t_check.elapsed().as_secs_f64();
    let t_maps = Instant::now();
    let (vertex_map, face_map, maps_checked) = if args.check {
        match check_maps(
            input_path,
            staged.path(),
            checked_files,
            args.settings.weld_tolerance,
            vertex_map,
            face_map,
            &mut written.notes,
        ) {
            Ok(maps) => maps,
            Err(e) => {
                report.write(&[failure_record(options, output, &e, out.seconds(write_s))], true)?;
                return Err(e);
            }
        }
    } else {
        (vertex_map.map(|m| m.0), face_map.map(|m| m.0), "")
    };
    side.extend(vertex_map);
    side.extend(face_map);
    let check_s = check_s + t_maps.elapsed().as_secs_f64();
    let run = out.record(options, output, write_s);
    let (total, reports) = report.stage(&[run], true).map_err(streamed)?;
    side.extend(reports);
    // The summary before the files are put in place: a printout that cannot
    // be written leaves them out (`commit_all`), and an input to be
    // rewritten as it was.
    if !args.quiet {
        let seconds = [total, write_s, check_s];
        let notes = SummaryNotes {
            notes: &written.notes,
            growth: growth.as_deref(),
            maps_checked,
        };
        say_refined(report, &out, &options, pruned_settings, notes, seconds);
    }
    commit_all(staged, output, side, in_place)?;
    Ok(ExitCode::SUCCESS)
}

/// How `--check`'s line names what was verified beyond the Delaunay
/// property (`--gabriel-boundary`).
fn gabriel_text(gabriel_boundary: bool) -> &'static str {
    if gabriel_boundary {
        " with a Gabriel boundary"
    } else {
        ""
    }
}

/// What a refined run adds to its summary beside its figures.
struct SummaryNotes<'a> {
    /// The writer's notes.
    notes: &'a [String],
    /// The note on growth ([`growth_note`]), if any.
    growth: Option<&'a str>,
    /// The end of the `check` line: which maps `--check` found right (see
    /// [`check_maps`]).
    maps_checked: &'a str,
}

/// Prints the summary's lines of a refined run `out` made with `options`
/// (with `--smallest`, the best of its settings, `pruned_settings` of
/// them pruned): settings, constants, the writer's notes, the output's
/// counts, the work, pruning, the note on growth, the check, and `seconds`
/// (total, writing, checking).
fn say_refined(
    report: &Report,
    out: &Finished,
    options: &Options,
    pruned_settings: usize,
    SummaryNotes {
        notes,
        growth,
        maps_checked,
    }: SummaryNotes,
    [total, write_s, check_s]: [f64; 3],
) {
    let args = report.args;
    let s = &out.stats;
    let c = s.constants.unwrap_or(delmesh::samples::SampleConstants::new(0.0, 0.0));
    say!(
        "run     {}, {}, {}{}{}",
        ds_name(options.worklist),
        score_name(options.score),
        match (options.shells, options.median) {
            (true, _) => "shells",
            (false, true) => "median",
            (false, false) => "no median",
        },
        if args.settings.gabriel_boundary {
            ", Gabriel boundary"
        } else {
            ""
        },
        if args.smallest {
            smallest_note(pruned_settings)
        } else {
            String::new()
        }
    );
    say!("samples rho_v {}, rho_e {}", sig(c.rho_v), sig(c.rho_e));
    for note in notes {
        say!("note    {note}");
    }
    say!(
        "output  {}: {}, {}, {}",
        report.output.display(),
        count(out.surface.vertices, "vertex", "vertices"),
        count(out.surface.faces, "face", "faces"),
        count(out.surface.added, "added vertex", "added vertices")
    );
    say_repaired(args);
    say!(
        "work    {}, {}; non-Delaunay edges: {} before, {} after",
        count(s.splits, "split", "splits"),
        count(s.flips, "flip", "flips"),
        s.non_delaunay_before,
        s.non_delaunay_after
    );
    if let Some(note) = longest_first_note(s) {
        say!("note    {note}");
    }
    if let Some(p) = &out.pruned {
        say!(
            "prune   removed {} of {} ({} tried, {}, {})",
            p.removed,
            count(s.splits, "added vertex", "added vertices"),
            p.tried,
            count(p.flips, "flip", "flips"),
            count(p.passes, "pass", "passes")
        );
    }
    if let Some(note) = growth {
        say!("note    {note}");
    }
    if args.check {
        say!(
            "check   PASS: {} is a Delaunay mesh{} with the geometry of {}{}{maps_checked}",
            report.output.display(),
            gabriel_text(args.settings.gabriel_boundary),
            report.input_path.display(),
            if report.input.repair.is_some() {
                " (as repaired)"
            } else {
                ""
            }
        );
    }
    say!(
        "seconds {:.4} total (read {:.4}, build {:.4}, refine {:.4}, write {:.4}{})",
        total,
        report.read_s,
        report.build_s,
        out.seconds,
        write_s,
        if args.check {
            format!(", check {check_s:.4}")
        } else {
            String::new()
        }
    );
}

/// Why a refined mesh is never written as STL: every output must pass
/// `delmesh check`, and rounded coordinates cannot.
pub(crate) const STL_REFUSED: &str = "STL stores f32 coordinates: the added vertices would be rounded off \
     the input's edges, so the output would have neither the input's exact geometry nor the Delaunay \
     property; write OBJ, OFF or PLY (STL is written only with --no-refine)";

/// The note for an STL output (with --no-refine): the format cannot hold
/// every coordinate.
const STL_NOTE: &str = "STL stores f32 coordinates: input coordinates that need more bits are rounded \
     (OBJ, OFF and PLY keep every coordinate)";

/// Writes a refined (or not) surface, with the input's attributes carried
/// by `transfer` if there are any; returns notes on attributes not written
/// (and on STL's rounding) and the vertex copies a PLY or OFF output made.
/// `done`: the OBJ or OFF lines of the input's vertices if formatted
/// already (else empty).
fn write_output(
    path: &Path,
    input: &Path,
    mesh: &io::InputMesh,
    surface: &Surface,
    transfer: Option<&Transfer>,
    done: &io::VertexLines,
) -> anyhow::Result<(io::Written, io::Staged)> {
    let triangles = surface.triangles();
    let mut libraries_moved = Vec::new();
    let format = io::output_format(path);
    let attributes = transfer.map(|t| {
        let mut attributes = t.apply(surface);
        if format == io::Format::Obj {
            libraries_moved = rebase_material_libraries(&mut attributes.mtllib, input, path);
        }
        attributes
    });
    // The vertices at shared positions (added ones, and input ones that
    // `--repair` cut apart), counted once if asked (a pass over the
    // positions).
    let counted = std::cell::OnceCell::new();
    let counted = || *counted.get_or_init(|| surface.vertices_at_shared_positions());
    let (shared, cut) = (|| counted().added, || counted().input);
    // A stream cannot be taken back once written: there a file that would
    // be refused (below) is found before, by writing it first to a
    // temporary file.
    if let Some(a) = attributes.as_ref().filter(|_| io::is_stream(path)) {
        if shared() > 0 || cut() > 0 {
            let dir = std::env::temp_dir();
            let file = io::temporary::TempFile::create_in(
                &dir,
                ".delmesh-",
                &format!(".{}", format.name().to_ascii_lowercase()),
            )
            .with_context(|| dir.display().to_string())?;
            let copies = io::write_mesh_with_attributes(file.path(), &surface.positions, &triangles, a)?.copies_of;
            refuse_shared_positions(path, surface.positions.len(), shared, &triangles, Some(a), &copies)?;
            refuse_misread_copies(path, file.path(), surface, mesh, &triangles, Some(a), cut, &copies)?;
        }
    }
    let (mut written, staged) = match &attributes {
        None => (
            io::Written::default(),
            io::stage_mesh_after(path, done, &surface.positions, &triangles)?,
        ),
        Some(attributes) => io::stage_mesh_with_attributes(path, &surface.positions, &triangles, attributes)?,
    };
    refuse_shared_positions(
        path,
        surface.positions.len(),
        shared,
        &triangles,
        attributes.as_ref(),
        &written.copies_of,
    )?;
    if !io::is_stream(path) {
        refuse_misread_copies(
            path,
            staged.path(),
            surface,
            mesh,
            &triangles,
            attributes.as_ref(),
            cut,
            &written.copies_of,
        )?;
    }
    drop(attributes);
    written.notes.extend(libraries_moved);
    if format == io::Format::Stl {
        written.notes.push(STL_NOTE.to_string());
    }
    if !written.copies_of.is_empty() {
        // (The `output` line counts the mesh's vertices; a reader of the
        // file counts its records.)
        let (what, per) = if format == io::Format::Obj {
            ("with several colours", "one colour")
        } else {
            ("at attribute seams", "one value per attribute")
        };
        written.notes.push(format!(
            "the file holds {} vertex records: {} copies of vertices {what} follow the mesh's {}, as {} gives a \
             vertex {per}",
            surface.positions.len() + written.copies_of.len(),
            written.copies_of.len(),
            surface.positions.len(),
            format.name()
        ));
    }
    if let Some(ext) = unknown_extension(path) {
        written.notes.push(format!(
            "{}: .{ext} is not a mesh extension delmesh writes (.obj, .off, .ply): written as OBJ",
            path.display()
        ));
    }
    Ok((written, staged))
}

/// Refuses the output `path` if the file copies vertices (`copies`, as
/// [`io::Written::copies_of`]: at seams, or an OBJ's for colours) and added
/// vertices of the `n`-vertex surface share a position (`shared()` of them,
/// [`Surface::vertices_at_shared_positions`]: the sheets of an edge
/// `--repair` cut, split at one sample): told apart in a file only by their
/// index, they are read back welded with the copies, and would fail
/// `check`. The line says whether OBJ is a way out (an OBJ copies a vertex
/// only for its colours, so not where they differ at a vertex).
fn refuse_shared_positions(
    path: &Path,
    n: usize,
    shared: impl Fn() -> usize,
    triangles: &[[u32; 3]],
    attributes: Option<&delmesh::attributes::Attributes>,
    copies: &[u32],
) -> anyhow::Result<()> {
    if copies.is_empty() {
        return Ok(());
    }
    let shared = shared();
    if shared == 0 {
        return Ok(());
    }
    let format = io::output_format(path);
    let (copied, instead) = what_is_copied(format, n, triangles, attributes);
    anyhow::bail!(
        "{}: {} {} a position with another vertex (such as the sheets of an edge cut apart by --repair, split at \
         one point), which {} cannot keep apart where it copies {copied}; {instead}use --drop-attributes",
        path.display(),
        count(shared, "added vertex", "added vertices"),
        if shared == 1 { "shares" } else { "share" },
        format.name(),
    );
}

/// What a file of `format` copies, in the refusals' words, and whether OBJ
/// is a way out: an OBJ copies a vertex only for its colours, so not where
/// they differ at a vertex (`n` vertices, `triangles`, `attributes`).
fn what_is_copied(
    format: io::Format,
    n: usize,
    triangles: &[[u32; 3]],
    attributes: Option<&delmesh::attributes::Attributes>,
) -> (&'static str, &'static str) {
    let obj_copies = (attributes.and_then(|a| a.colors.as_ref()))
        .is_some_and(|c| delmesh::attributes::PerVertex::new(n, triangles, &[c]).source.len() > n);
    match format {
        io::Format::Obj => ("vertices with several colours", ""),
        _ if obj_copies => ("vertices at attribute seams", ""),
        _ => ("vertices at attribute seams", "write OBJ, or "),
    }
}

/// Refuses the output `path` if its file (at `file`) copies vertices
/// (`copies`: at seams, or an OBJ's for colours) and input vertices share a
/// position (`cut()` of them, [`Surface::vertices_at_shared_positions`]:
/// the copies `--repair` makes where it cuts), unless the file, read back as
/// `check` reads an output of `mesh` (the input as read, and repaired), has
/// the shape of the mesh written ([`delmesh::check::Mesh3::reads_back_as`]). Told apart only by their
/// index, such vertices are welded on reading with the copies of the others
/// at their position, and which copies are one vertex is then a guess; a
/// file guessed wrong would fail `check` (a fuzz finding of the
/// seventy-fourth session: two components where the mesh has one).
#[allow(clippy::too_many_arguments)]
fn refuse_misread_copies(
    path: &Path,
    file: &Path,
    surface: &Surface,
    mesh: &io::InputMesh,
    triangles: &[[u32; 3]],
    attributes: Option<&delmesh::attributes::Attributes>,
    cut: impl Fn() -> usize,
    copies: &[u32],
) -> anyhow::Result<()> {
    if copies.is_empty() || cut() == 0 {
        return Ok(());
    }
    let written = delmesh::check::Mesh3 {
        positions: surface.positions.clone(),
        triangles: triangles.to_vec(),
    };
    // (Aimed at the input, as `check` reads the output against it: not at the mesh written,
    // which would tell the reading which sheet of a cut edge was split.)
    let input = delmesh::check::Mesh3 {
        positions: mesh.positions.clone(),
        triangles: mesh.triangles.clone(),
    };
    if delmesh::check::Mesh3::reads_back_as(file, &written, &input).unwrap_or(false) {
        return Ok(());
    }
    let format = io::output_format(path);
    let (copied, instead) = what_is_copied(format, surface.positions.len(), triangles, attributes);
    anyhow::bail!(
        "{}: {} share a position with another (the copies --repair makes where it cuts the surface apart), which \
         {} cannot keep apart where it copies {copied}: the file would not read back as this mesh; {instead}use \
         --drop-attributes",
        path.display(),
        count(cut(), "input vertex", "input vertices"),
        format.name(),
    );
}

/// The extension of `path` (before any `.gz`) if it has one that names no
/// mesh format: the file is then written as OBJ, which its name does not
/// say (a name without an extension is OBJ as documented, and a device or
/// stream has none that matters).
fn unknown_extension(path: &Path) -> Option<String> {
    if io::is_stream(path) {
        return None;
    }
    let name = path.file_name()?.to_str()?;
    let stem = name.strip_suffix(".gz").unwrap_or(name);
    let (before, ext) = stem.rsplit_once('.')?;
    (!before.is_empty() && !ext.is_empty() && io::formats::format_from_name(stem).is_none()).then(|| ext.to_string())
}

/// What reading did to the input's numbering: `welded` vertices at the
/// position of an earlier one, `unused` ones no face uses. The output
/// numbers the input's vertices without them, so that data kept per vertex
/// by the file's numbers must follow `--vertex-map`.
fn renumbered_line(welded: usize, unused: usize) -> String {
    let count = |n: usize, what: &str| format!("{n} {what} vert{}", if n == 1 { "ex" } else { "ices" });
    let mut parts = Vec::new();
    if welded > 0 {
        parts.push(format!("welded {}", count(welded, "duplicate")));
    }
    if unused > 0 {
        parts.push(format!("dropped {}", count(unused, "unused")));
    }
    format!(
        "{}: the output numbers the input's vertices without {} (--vertex-map gives each vertex its number in the \
         input file)",
        parts.join(", "),
        if welded + unused == 1 { "it" } else { "them" }
    )
}

/// What attributes an input has, for the printout.
fn describe_attributes(a: &Attributes) -> String {
    let mut parts: Vec<String> = a
        .channels()
        .filter(|(k, _)| !matches!(k, Kind::Property(_)))
        .map(|(k, ch)| {
            let faces = ch.corners.len() / 3;
            let with = ch.corners.chunks_exact(3).filter(|t| t[0] != NO_VALUE).count();
            if with < faces {
                format!("{} (on {with} of {faces} triangles)", k.name())
            } else {
                k.name().to_string()
            }
        })
        .collect();
    let vertex: Vec<&str> = a
        .channels()
        .filter_map(|(k, _)| match k {
            Kind::Property(i) => Some(a.properties[i as usize].name.as_str()),
            _ => None,
        })
        .collect();
    let face: Vec<&str> = a.face_properties.iter().map(|p| p.name.as_str()).collect();
    parts.extend(properties_named("vertex", &vertex));
    parts.extend(properties_named("face", &face));
    if !a.groups.is_empty() {
        // Distinct combinations of `o`, `g`, `usemtl` and `s`, named by
        // what the file has of them.
        let n = a.groups.len();
        let s = if n == 1 { "" } else { "s" };
        let named = a.groups.iter().any(Group::is_named);
        let smoothing = a.groups.iter().any(|g| g.smoothing.is_some());
        parts.push(match (named, smoothing) {
            (true, true) => format!("{n} group{s}/material{s}/smoothing group{s}"),
            (false, true) => format!("{n} smoothing group{s}"),
            _ => format!("{n} group{s}/material{s}"),
        });
    }
    if !a.mtllib.is_empty() {
        parts.push("mtllib".into());
    }
    parts.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use args::finite_degrees;
    use sweep::{all_combinations, all_settings_failed};

    #[test]
    fn smallest_failing_everywhere_names_the_defaults_and_the_path_once() {
        let stuck = anyhow::Error::new(delmesh::Error::Unsplittable {
            count: 2,
            worst_excess: 0.5,
            worst_edge: None,
            near_coincident: Default::default(),
        })
        .context("m.obj");
        let line = one_line(&all_settings_failed(stuck, Path::new("m.obj")));
        assert!(
            line.starts_with(
                "m.obj: none of the 24 settings of --smallest finished (each has the work limit); with the \
                 defaults (stack, score 2, median): 2 non-Delaunay edge(s) can be neither split"
            ),
            "{line}"
        );
        assert_eq!(line.matches("m.obj").count(), 1, "{line}");
    }

    fn args(s: &str) -> Vec<String> {
        legacy_args(s.split_whitespace().map(Into::into))
            .into_iter()
            .map(|a| a.into_string().unwrap())
            .collect()
    }

    #[test]
    fn render_angles_must_be_finite() {
        assert_eq!(finite_degrees("-30.5"), Ok(-30.5));
        for bad in ["nan", "inf", "-inf", "1e999", "ten"] {
            assert!(finite_degrees(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn long_words_are_elided_in_messages() {
        let long = format!("/{}/m.obj", "e".repeat(5000));
        let line = one_line(&anyhow::anyhow!("{long}: cannot read: File name too long"));
        assert!(line.len() < 320, "{}", line.len());
        assert!(
            line.starts_with("/eee")
                && line.contains("eee...eee")
                && line.ends_with("/m.obj: cannot read: File name too long")
        );
        let short = "a.obj: cannot read: No such file or directory";
        assert_eq!(one_line(&anyhow::anyhow!("{short}")), short);
    }

    #[test]
    fn legacy_flags_are_rewritten() {
        assert_eq!(
            args("delmesh -i e.obj -o out/e.obj -s 2 -ds pqueue"),
            ["delmesh", "-i", "e.obj", "-o", "out/e.obj", "-s", "2", "--ds", "pqueue"]
        );
        assert_eq!(
            args("delmesh -i -all -nomedian -all"),
            ["delmesh", "-i", "-all", "--nomedian", "--all"]
        );
    }

    #[test]
    fn combination_names() {
        let o = Options::new(Worklist::Stack, Score::AllEqual, true);
        assert_eq!(
            combination_path(Path::new("output/elephant.obj"), &o),
            Path::new("output/elephant-s-0-m.obj")
        );
        let o = Options::new(Worklist::PriorityQueue, Score::AlwaysCenter, false);
        assert_eq!(combination_path(Path::new("e.obj"), &o), Path::new("e-p-2.obj"));
        assert_eq!(
            combination_path(Path::new("d/n.ply.gz"), &o),
            Path::new("d/n-p-2.ply.gz")
        );
        assert_eq!(combination_path(Path::new("n.OBJ.GZ"), &o), Path::new("n-p-2.OBJ.GZ"));
        assert_eq!(combination_path(Path::new("n.gz"), &o), Path::new("n-p-2.gz"));
        assert_eq!(combination_path(Path::new("n"), &o), Path::new("n-p-2.obj"));
        assert_eq!(all_combinations().len(), 18);
    }

    #[test]
    fn an_output_that_fails_the_check_is_renamed_and_reported() {
        let dir = tempfile::tempdir().unwrap();
        let cube = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj");
        let mut mesh = io::read_mesh(&cube, &Default::default()).unwrap();
        // The input itself is not Delaunay (delmesh adds 5 vertices to it).
        let output = dir.path().join("cube.obj");
        std::fs::copy(&cube, &output).unwrap();
        let stage = |path: &Path, positions: &[glam::DVec3], triangles: &[[u32; 3]]| {
            io::stage_mesh_after(path, &Default::default(), positions, triangles).unwrap()
        };
        let staged = stage(&output, &mesh.positions, &mesh.triangles);
        let e = check_output(&cube, &mesh, staged, &output, false, false).unwrap_err();
        assert!(e.downcast_ref::<CheckFailed>().is_some(), "{e}");
        assert!(e.to_string().contains("failed the check"), "{e}");
        // The file it would have replaced is untouched (a run in place
        // keeps its input); the rejected one is beside it.
        assert_eq!(std::fs::read(&output).unwrap(), std::fs::read(&cube).unwrap());
        assert!(dir.path().join("cube.obj.rejected").exists());
        std::fs::remove_file(&output).unwrap();
        // A refined one passes and stays.
        let surface = {
            let mut s = io::build_surface(&mut mesh, &cube).unwrap();
            delmesh::make_delaunay(&mut s, &Default::default()).unwrap();
            s
        };
        let staged = stage(&output, &surface.positions, &surface.triangles());
        check_output(&cube, &mesh, staged, &output, false, false)
            .unwrap()
            .0
            .commit()
            .unwrap();
        assert!(output.exists());
        std::fs::remove_file(&output).unwrap();
        // One the judge cannot verify (here: its reference is unreadable)
        // is not put in place as if verified either.
        let missing = dir.path().join("missing.obj");
        let staged = stage(&output, &surface.positions, &surface.triangles());
        let e = check_output(&missing, &mesh, staged, &output, true, false).unwrap_err();
        assert!(e.downcast_ref::<CheckFailed>().is_some(), "{e}");
        assert!(e.to_string().contains("the check could not read the files"), "{e}");
        assert!(!output.exists());
        assert!(dir.path().join("cube.obj.rejected").exists());
    }

    #[test]
    fn maps_that_fail_the_check_are_renamed_and_reported() {
        let dir = tempfile::tempdir().unwrap();
        let cube = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cube.obj");
        let mut mesh = io::read_mesh(&cube, &Default::default()).unwrap();
        let mut surface = io::build_surface(&mut mesh, &cube).unwrap();
        let origins = FaceOrigins::new(&mesh.triangles, &mesh.triangle_polygon, &surface);
        delmesh::make_delaunay(&mut surface, &Default::default()).unwrap();
        let output = dir.path().join("cube.obj");
        let staged =
            io::stage_mesh_after(&output, &Default::default(), &surface.positions, &surface.triangles()).unwrap();
        let written = io::Written::default();
        let (vertex_path, face_path) = (dir.path().join("v.csv"), dir.path().join("f.csv"));
        let maps = || {
            let vertex = stage_vertex_map(&vertex_path, &surface, &mesh, &written).unwrap();
            let (face, _) = stage_face_map(&face_path, &surface, &origins, &written).unwrap();
            (Some((vertex, vertex_path.as_path())), Some((face, face_path.as_path())))
        };
        // Right maps are handed back, and said right.
        let (vertex, face) = maps();
        let mut notes = Vec::new();
        let (v, f, said) = check_maps(&cube, staged.path(), None, 0.0, vertex, face, &mut notes).unwrap();
        assert_eq!(said, "; its maps are right");
        assert!(v.is_some() && f.is_some() && notes.is_empty());
        // A vertex map with a row moved: renamed, the run fails, and the
        // face map (right) is not put in place either.
        let (vertex, face) = maps();
        let text = std::fs::read_to_string(vertex.as_ref().unwrap().0.path()).unwrap();
        let wrong = text.replacen("\n0,0,0,0.0\n", "\n0,1,1,0.0\n", 1);
        assert_ne!(wrong, text);
        let moved = io::stage(&vertex_path, |w| w.write_all(wrong.as_bytes())).unwrap();
        let e = check_maps(
            &cube,
            staged.path(),
            None,
            0.0,
            Some((moved, &vertex_path)),
            face,
            &mut notes,
        )
        .unwrap_err();
        assert!(e.downcast_ref::<CheckFailed>().is_some(), "{e}");
        assert!(
            e.to_string().contains("v.csv: failed the check: vertex map line 2"),
            "{e}"
        );
        assert!(dir.path().join("v.csv.rejected").exists());
        assert!(!vertex_path.exists() && !face_path.exists());
        // One the judge cannot read against (the input gone) neither.
        let (vertex, face) = maps();
        let missing = dir.path().join("missing.obj");
        let e = check_maps(&missing, staged.path(), None, 0.0, vertex, face, &mut notes).unwrap_err();
        assert!(e.to_string().contains("the check could not read the files"), "{e}");
        assert!(dir.path().join("f.csv.rejected").exists());
        drop(v);
        drop(f);
        // With the files the mesh's check read (as `--check` with maps runs): the same verdicts.
        std::fs::remove_file(dir.path().join("f.csv.rejected")).unwrap();
        std::fs::remove_file(dir.path().join("v.csv.rejected")).unwrap();
        let checked = |staged: io::Staged| {
            let (staged, files) = check_output(&cube, &mesh, staged, &output, true, false).unwrap();
            (staged, files.expect("kept"))
        };
        let (staged, files) = checked(staged);
        assert!(files.input.is_some(), "the input file itself was read");
        let (vertex, face) = maps();
        let (v, f, said) = check_maps(&cube, staged.path(), Some(files), 0.0, vertex, face, &mut notes).unwrap();
        assert_eq!(said, "; its maps are right");
        assert!(v.is_some() && f.is_some() && notes.is_empty());
        drop((v, f));
        let (staged, files) = checked(staged);
        let (_, face) = maps();
        let moved = io::stage(&vertex_path, |w| w.write_all(wrong.as_bytes())).unwrap();
        let e = check_maps(
            &cube,
            staged.path(),
            Some(files),
            0.0,
            Some((moved, &vertex_path)),
            face,
            &mut notes,
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("v.csv: failed the check: vertex map line 2"),
            "{e}"
        );
        assert!(dir.path().join("v.csv.rejected").exists());
        assert!(!vertex_path.exists() && !face_path.exists());
    }
}
