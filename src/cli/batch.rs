//! `delmesh batch`: many inputs in one process, several at once.
//!
//! Each input is read, refined and written exactly as `delmesh -i INPUT -o
//! DIR/NAME` would (same settings, same bytes), on one of `-j` workers that
//! take the files in the order given. A file that fails is reported on one
//! line and the others go on; the exit status is 1 if any failed. Starting a
//! process costs about a millisecond, as much as refining a small mesh, so
//! a folder of small meshes goes several times faster this way than with a
//! shell loop.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use anyhow::{bail, Context};
use clap::ValueEnum;

use super::{
    check_maps, check_output, check_output_dir, count, failure_record, file_key, flat_regions_notes, fold_note,
    growth_note, longest_first_note, name_stuck_edge, near_coincident_note, one_line, refine_once, smallest,
    stage_face_map, stage_vertex_map, stuck_elsewhere, write_output, FirstPass, Settings,
};
use crate::stats_json::{self, FileDocument, RunRecord, RunSeconds};
use delmesh::attributes::Transfer;
use delmesh::face_map::FaceOrigins;
use delmesh::io;
use delmesh::refine::Options;

/// The arguments of `delmesh batch`.
#[derive(clap::Args, Debug)]
pub(super) struct BatchArgs {
    /// The meshes to refine: OBJ, OFF, PLY or STL, possibly gzip-compressed.
    /// A folder stands for the mesh files in it (by extension, in name
    /// order; not its subfolders, unless --recursive).
    #[arg(value_name = "INPUT", required = true)]
    inputs: Vec<PathBuf>,

    /// A folder given as INPUT stands for the mesh files in it and in its
    /// subfolders at any depth (each folder's files in name order, then its
    /// subfolders'), each written to the same subfolder of --out-dir
    /// (created as needed): a dataset's tree is mirrored. Symbolic links
    /// to folders are not followed, and the output folder is left out if
    /// it lies inside.
    #[arg(short = 'r', long = "recursive")]
    recursive: bool,

    /// Folder of the outputs (created if missing). Each is named after its
    /// input: the same name without `.gz`, with the extension of --format.
    /// Never an input's own path: that is refused before any work.
    #[arg(short = 'd', long = "out-dir", value_name = "DIR", required = true)]
    out_dir: PathBuf,

    /// Format of the outputs (default: each input's own, but OBJ for STL
    /// inputs, since STL holds f32 coordinates, and for names without a
    /// mesh extension).
    #[arg(long = "format", value_enum, value_name = "FORMAT")]
    format: Option<FormatArg>,

    #[command(flatten)]
    settings: Settings,

    /// How many files to refine at once (default: one per core); with
    /// --smallest, how many runs of a file at once. Each file's output
    /// never depends on it.
    #[arg(short = 'j', long = "jobs", value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u16).range(1..))]
    jobs: Option<u16>,

    /// Verify every output with `delmesh check` (against the input, or with
    /// --repair the repaired input) before counting it as written. An
    /// output that fails (or that the check cannot read) is renamed to
    /// NAME.rejected and the file counts as failed. Checking takes a few
    /// times longer than refining.
    #[arg(long = "check")]
    check: bool,

    /// Also write beside each output where its vertices come from, as the
    /// main command's --vertex-map does: NAME.vertex-map.csv for NAME.obj.
    #[arg(long = "vertex-maps")]
    vertex_maps: bool,

    /// Also write beside each output which input face each of its faces
    /// lies in, as the main command's --face-map does: NAME.face-map.csv for
    /// NAME.obj.
    #[arg(long = "face-maps")]
    face_maps: bool,

    /// With --repair: also write beside each output the repaired input it
    /// was made from, the mesh `delmesh check` compares it with, as the
    /// main command's --repaired does: NAME.repaired.obj for NAME.obj.
    #[arg(long = "repaired-inputs", requires = "repair")]
    repaired_inputs: bool,

    /// Skip the inputs whose output exists already, e.g. to resume an
    /// interrupted batch (outputs are written atomically, so an existing
    /// one is complete; with --vertex-maps, --face-maps or --repaired-inputs, only if
    /// those files exist too).
    #[arg(long = "skip-existing")]
    skip_existing: bool,

    /// Fewest added vertices, as the main command's --smallest: each file
    /// is refined with 24 settings, those within 4 times the fewest added
    /// vertices plus 1000 are pruned, and the smallest result is written
    /// (-ds, -s, -nomedian and --shells are ignored). The files are
    /// then taken one at a time, each with its 24 runs on all cores (or -j):
    /// one large file would otherwise hold up a core alone.
    #[arg(long = "smallest")]
    smallest: bool,

    /// Also write the figures of every file as CSV, one row per input (the
    /// columns of the main command's --stats-csv; skipped inputs have none).
    #[arg(long = "stats-csv", value_name = "FILE")]
    stats_csv: Option<PathBuf>,

    /// Also write the figures of every file as JSON: for each input read,
    /// the document the main command's --stats-json writes for it; the
    /// inputs refused, with their errors; the inputs skipped.
    #[arg(long = "stats-json", value_name = "FILE")]
    stats_json: Option<PathBuf>,

    /// Print nothing but errors (one line per failed file).
    #[arg(short = 'q', long = "quiet")]
    quiet: bool,
}

/// An output format by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(super) enum FormatArg {
    /// Wavefront OBJ (texture coordinates, normals and groups carried).
    Obj,
    /// Object File Format.
    Off,
    /// Binary PLY.
    Ply,
    /// Binary STL: refused (its f32 coordinates cannot hold a refined mesh
    /// exactly).
    Stl,
}

impl FormatArg {
    fn extension(self) -> &'static str {
        match self {
            FormatArg::Obj => "obj",
            FormatArg::Off => "off",
            FormatArg::Ply => "ply",
            FormatArg::Stl => "stl",
        }
    }
}

/// The output file name of `input`: its name without `.gz`, with the
/// extension of `format`, or its own if delmesh writes that format exactly
/// (OBJ, OFF, PLY), or `obj` (STL inputs too: STL holds f32 coordinates).
fn output_name(input: &Path, format: Option<FormatArg>) -> Option<PathBuf> {
    let mut name = Path::new(input.file_name()?);
    if name.extension().is_some_and(|e| e.eq_ignore_ascii_case("gz")) {
        name = Path::new(name.file_stem()?);
    }
    // A name that is all extension (`.obj`: to `Path`, a hidden file
    // without one) has an empty stem, as the main command reads it.
    let (stem, own) = match (name.extension(), name.to_str().and_then(|n| n.strip_prefix('.'))) {
        (Some(e), _) => (name.file_stem()?, e.to_str()),
        (None, Some(e)) => (OsStr::new(""), Some(e)),
        (None, None) => (name.as_os_str(), None),
    };
    let own = own.and_then(|e| FormatArg::from_str(&e.to_ascii_lowercase(), true).ok());
    let exact = own.filter(|&f| f != FormatArg::Stl);
    let extension = format.or(exact).unwrap_or(FormatArg::Obj).extension();
    let stem = if own.is_some() { stem } else { name.as_os_str() };
    let mut out = stem.to_owned();
    out.push(".");
    out.push(extension);
    Some(PathBuf::from(out))
}

/// An input file, and the subfolder of the output folder its output goes
/// to (empty but with --recursive, for a file below a folder given).
#[derive(Clone, Debug, PartialEq)]
struct Input {
    path: PathBuf,
    subfolder: PathBuf,
}

/// Whether `path` has a mesh extension (`.obj`, `.off`, `.ply`, `.stl`,
/// each possibly `.gz`): by extension (ASCII), whatever the rest of the
/// name, so a name that is not UTF-8 is a mesh file like any other.
fn is_mesh_name(path: &Path) -> bool {
    path.file_name()
        .is_some_and(|n| io::formats::format_from_name(&n.to_string_lossy()).is_some())
}

/// The inputs: the files given, and in each folder given the files with a
/// mesh extension ([`is_mesh_name`]), in name order; with `recursive`,
/// then those in its subfolders at any depth, in the same order, without
/// following symbolic links to folders and leaving out `out_dir`.
fn expand(inputs: &[PathBuf], recursive: bool, out_dir: &Path) -> anyhow::Result<Vec<Input>> {
    let out_dir = std::fs::canonicalize(out_dir).ok();
    let mut files = Vec::new();
    for input in inputs {
        if !input.is_dir() {
            files.push(Input {
                path: input.clone(),
                subfolder: PathBuf::new(),
            });
            continue;
        }
        let mut found = Vec::new();
        mesh_files_below(input, Path::new(""), recursive, out_dir.as_deref(), &mut found)?;
        if found.is_empty() {
            if recursive {
                bail!("{}: no mesh files in this folder or its subfolders", input.display());
            }
            let mut below = Vec::new();
            // (Unreadable subfolders count as empty here: only a hint.)
            let _ = mesh_files_below(input, Path::new(""), true, out_dir.as_deref(), &mut below);
            if below.is_empty() {
                bail!("{}: no mesh files in this folder", input.display());
            }
            bail!(
                "{}: no mesh files in this folder ({} in its subfolders: --recursive takes them)",
                input.display(),
                below.len()
            );
        }
        found.sort_by(|a, b| (&a.subfolder, &a.path).cmp(&(&b.subfolder, &b.path)));
        files.extend(found);
    }
    Ok(files)
}

/// Adds to `found` the mesh files in `folder` (which is `subfolder` below
/// the folder given), and with `recursive` those in its subfolders, except
/// in symbolic links to folders and in `out_dir` (canonical).
fn mesh_files_below(
    folder: &Path,
    subfolder: &Path,
    recursive: bool,
    out_dir: Option<&Path>,
    found: &mut Vec<Input>,
) -> anyhow::Result<()> {
    for entry in std::fs::read_dir(folder).with_context(|| folder.display().to_string())? {
        let entry = entry.with_context(|| folder.display().to_string())?;
        let path = entry.path();
        // The entry itself: a symbolic link is not a folder here.
        let real_folder = entry.file_type().is_ok_and(|t| t.is_dir());
        if real_folder {
            if recursive && out_dir.is_none_or(|out| std::fs::canonicalize(&path).ok().as_deref() != Some(out)) {
                mesh_files_below(&path, &subfolder.join(entry.file_name()), true, out_dir, found)?;
            }
        } else if is_mesh_name(&path) && !path.is_dir() {
            found.push(Input {
                path,
                subfolder: subfolder.to_owned(),
            });
        }
    }
    Ok(())
}

/// The output path of every input, in order; refuses two inputs with one
/// output, and an output that is an input.
fn plan(
    inputs: &[Input],
    out_dir: &Path,
    format: Option<FormatArg>,
    sides: impl Fn(&Path) -> Vec<PathBuf>,
) -> anyhow::Result<Vec<PathBuf>> {
    let canonical: HashSet<PathBuf> = inputs
        .iter()
        .filter_map(|p| std::fs::canonicalize(&p.path).ok())
        .collect();
    let paths: Vec<PathBuf> = inputs.iter().map(|p| p.path.clone()).collect();
    let ids = input_ids(&paths);
    let mut taken: HashMap<PathBuf, &Path> = HashMap::new();
    let mut outputs = Vec::with_capacity(inputs.len());
    for Input { path: input, subfolder } in inputs {
        let Some(name) = output_name(input, format) else {
            bail!("{}: not a file name", input.display());
        };
        let output = out_dir.join(subfolder).join(&name);
        let sides = sides(&output);
        for written in std::iter::once(&output).chain(&sides) {
            if let Some(first) = taken.insert(written.clone(), input) {
                bail!(
                    "{} and {} would both be written to {}",
                    first.display(),
                    input.display(),
                    written.display()
                );
            }
            // The file the output names, symbolic links followed (the
            // writer follows them too): none if its folder does not exist
            // yet, and then no input is in it.
            if super::file_key(written).is_some_and(|key| canonical.contains(&key))
                || io::FileId::of_output(written).is_some_and(|id| ids.contains(&id))
            {
                bail!("{}: would overwrite an input", written.display());
            }
        }
        outputs.push(output);
    }
    Ok(outputs)
}

/// The regular files `inputs` are (device and inode: an output reaching
/// one by another name, such as a hard link, would replace it too).
fn input_ids(inputs: &[PathBuf]) -> HashSet<io::FileId> {
    inputs.iter().filter_map(|p| io::FileId::of_path(p)).collect()
}

/// One file's result, as the summary line and the CSV row need it.
struct Done {
    record: RunRecord,
    /// Repair's lines, if it fixed anything.
    repairs: Vec<String>,
    /// Attribute notes of the reader and the writer.
    notes: Vec<String>,
    /// Wall seconds spent on the file, from reading to the check.
    seconds: f64,
    /// Whether the settings of `record` were chosen by --smallest.
    smallest: bool,
    /// With --check: which maps it found right, as the line says it
    /// (`; its maps are right`), or nothing.
    maps_checked: &'static str,
    /// With --stats-json, the file's document.
    doc: Option<FileDocument>,
}

/// The vertex map written beside `output` with --vertex-maps.
fn vertex_map_path(output: &Path) -> PathBuf {
    let mut name = output.file_stem().unwrap_or_default().to_owned();
    name.push(".vertex-map.csv");
    output.with_file_name(name)
}

/// The face map written beside `output` with --face-maps.
fn face_map_path(output: &Path) -> PathBuf {
    let mut name = output.file_stem().unwrap_or_default().to_owned();
    name.push(".face-map.csv");
    output.with_file_name(name)
}

/// The repaired input written beside `output` with --repaired-inputs, in
/// the output's format: NAME.repaired.obj for NAME.obj.
fn repaired_path(output: &Path) -> PathBuf {
    let mut name = output.file_stem().unwrap_or_default().to_owned();
    name.push(".repaired");
    if let Some(ext) = output.extension() {
        name.push(".");
        name.push(ext);
    }
    output.with_file_name(name)
}

/// The files written beside `output` and put in place with it (with
/// --vertex-maps, --face-maps, --repaired-inputs): an output stands for a finished file.
fn side_paths(output: &Path, args: &BatchArgs) -> Vec<PathBuf> {
    let mut sides = Vec::new();
    if args.vertex_maps {
        sides.push(vertex_map_path(output));
    }
    if args.face_maps {
        sides.push(face_map_path(output));
    }
    if args.repaired_inputs {
        sides.push(repaired_path(output));
    }
    sides
}

/// Why a file was not written: the error, and with --stats-json the
/// file's document (`None` if the input was refused: not read or built).
struct Failed {
    error: anyhow::Error,
    doc: Option<FileDocument>,
    refused: bool,
    /// The seconds of the phases that ran (until the failure).
    seconds: RunSeconds,
}

/// Reads, refines and writes one file, as the main command would (and
/// checks it, with `check`); with --stats-json, also makes the document the
/// main command would write for it.
fn refine_file(input: &Path, output: &Path, args: &BatchArgs, options: &Options) -> Result<Done, Failed> {
    let t0 = Instant::now();
    let read = || -> anyhow::Result<_> {
        // A folder in an output's place fails this file alone, before any
        // work (the others are written).
        if output.is_dir() {
            bail!("{}: output is a folder, not a file", output.display());
        }
        if let Some(folder) = side_paths(output, args).into_iter().find(|p| p.is_dir()) {
            bail!(
                "{}: is a folder, not a file ({} not written)",
                folder.display(),
                output.display()
            );
        }
        let mut mesh = args.settings.read(input, output, true, args.face_maps)?;
        let read_s = t0.elapsed().as_secs_f64();
        let t_build = Instant::now();
        let surface = args.settings.build(&mut mesh, input)?;
        Ok((mesh, surface, read_s, t_build.elapsed().as_secs_f64()))
    };
    let (mut mesh, mut surface, read_s, build_s) = read().map_err(|error| Failed {
        error,
        doc: None,
        refused: true,
        seconds: RunSeconds::default(),
    })?;
    let options = &Options {
        max_added: args.settings.max_added.for_input(surface.n_input_vertices),
        ..*options
    };
    let (figures, folded_edges) = (surface.input_figures, surface.folded_edges);
    let constants = delmesh::refine::sample_constants(&surface);
    let first_pass = FirstPass::new(&mut surface, args.settings.keep_order);
    let json = args.stats_json.is_some();
    let lower_bound = if json {
        surface.added_vertex_lower_bound_among(&first_pass.edges)
    } else {
        0
    };
    let mut seconds = RunSeconds::default();
    let result = refine_read(
        &mut mesh,
        surface,
        &first_pass,
        input,
        output,
        args,
        options,
        &mut seconds,
    );
    let repaired = (args.repaired_inputs && result.is_ok()).then(|| repaired_path(output));
    let doc = json.then(|| {
        let failure;
        let record = match &result {
            Ok(done) => &done.record,
            Err(e) => {
                failure = failure_record(*options, output, e, seconds);
                &failure
            }
        };
        let inv = stats_json::Invocation {
            input_path: input,
            input: &mesh,
            figures,
            lower_bound,
            folded_edges,
            output,
            repaired: repaired.as_deref(),
            refined: true,
            gabriel_boundary: args.settings.gabriel_boundary,
            seconds_read: read_s,
            seconds_build: build_s,
            seconds_total: t0.elapsed().as_secs_f64(),
        };
        FileDocument::new(&inv, constants, std::slice::from_ref(record))
    });
    match result {
        Ok(mut done) => {
            done.seconds = t0.elapsed().as_secs_f64();
            done.doc = doc;
            Ok(done)
        }
        Err(error) => Err(Failed {
            error,
            doc,
            refused: false,
            seconds,
        }),
    }
}

/// [`refine_file`] once the input is read and built; `seconds` gets the
/// seconds of the phases as they end (those of a failed run too).
#[allow(clippy::too_many_arguments)]
fn refine_read(
    mesh: &mut io::InputMesh,
    surface: delmesh::Surface,
    first_pass: &FirstPass,
    input: &Path,
    output: &Path,
    args: &BatchArgs,
    options: &Options,
    seconds: &mut RunSeconds,
) -> anyhow::Result<Done> {
    let start = Instant::now();
    let failed_after = |seconds: &mut RunSeconds| seconds.refine = first_pass.seconds + start.elapsed().as_secs_f64();
    let transfer = (!mesh.attributes.is_empty())
        .then(|| Transfer::new(std::mem::take(&mut mesh.attributes), &mesh.triangles, &surface));
    let face_origins = args
        .face_maps
        .then(|| FaceOrigins::new(&mesh.triangles, &mesh.triangle_polygon, &surface));
    let (options, out) = if args.smallest {
        let start = Instant::now();
        let passes = args.settings.prune().unwrap_or(delmesh::prune::MAX_PASSES);
        let (options, mut out, _) = smallest(surface, first_pass, input, options, args.jobs, passes).map_err(|e| {
            failed_after(seconds);
            name_stuck_edge(e, mesh)
        })?;
        out.seconds = start.elapsed().as_secs_f64(); // all 24 runs
        (options, out)
    } else {
        (
            *options,
            refine_once(surface, first_pass, input, options, args.settings.prune()).map_err(|e| {
                failed_after(seconds);
                name_stuck_edge(e, mesh)
            })?,
        )
    };
    let t_write = Instant::now();
    let mut notes = std::mem::take(&mut mesh.notes);
    notes.extend(near_coincident_note(&out.surface.input_figures));
    notes.extend(fold_note(&out.surface, mesh));
    notes.extend(growth_note(
        &out.surface,
        options.shells,
        out.pruned.is_some(),
        args.smallest,
    ));
    notes.extend(flat_regions_notes(&first_pass.flat));
    notes.extend(longest_first_note(&out.stats));
    *seconds = out.seconds(0.0);
    let written = write_output(
        output,
        input,
        mesh,
        &out.surface,
        transfer.as_ref(),
        &Default::default(),
    );
    let seconds_write = t_write.elapsed().as_secs_f64();
    seconds.write = seconds_write;
    let (written, mut staged) = written?;
    notes.extend(written.notes.iter().cloned());
    // An output stands for a finished file (--skip-existing skips it): it
    // is put in place only with its maps (checked with it) and repaired
    // input.
    let (vertex_path, face_path) = (vertex_map_path(output), face_map_path(output));
    let not_written = || format!("{} not written", output.display());
    let mut vertex_map = None;
    if args.vertex_maps {
        let map = stage_vertex_map(&vertex_path, &out.surface, mesh, &written).with_context(not_written)?;
        vertex_map = Some((map, vertex_path.as_path()));
    }
    let mut face_map = None;
    if let Some(origins) = &face_origins {
        let (map, note) = stage_face_map(&face_path, &out.surface, origins, &written).with_context(not_written)?;
        notes.extend(note);
        face_map = Some((map, face_path.as_path()));
    }
    // The rest reads the files: the surface (and what was carried over to
    // it) goes before the judge reads them back.
    let (surface, out) = out.finish();
    drop((surface, transfer, face_origins));
    let mut checked_files = None;
    if args.check {
        let keep_files = args.vertex_maps || args.face_maps;
        (staged, checked_files) =
            check_output(input, mesh, staged, output, keep_files, args.settings.gabriel_boundary)?;
    }
    let (vertex_map, face_map, maps_checked) = if args.check {
        check_maps(
            input,
            staged.path(),
            checked_files,
            args.settings.weld_tolerance,
            vertex_map,
            face_map,
            &mut notes,
        )?
    } else {
        (vertex_map.map(|m| m.0), face_map.map(|m| m.0), "")
    };
    for map in vertex_map.into_iter().chain(face_map) {
        map.commit().with_context(not_written)?;
    }
    if args.repaired_inputs {
        io::stage_mesh_after(
            &repaired_path(output),
            &Default::default(),
            &mesh.positions,
            &mesh.triangles,
        )
        .and_then(|repaired| repaired.commit())
        .with_context(|| format!("{} not written", output.display()))?;
    }
    staged.commit()?;
    Ok(Done {
        record: out.record(options, output, seconds_write),
        smallest: args.smallest,
        maps_checked,
        repairs: mesh.repair.as_ref().map(|r| r.lines()).unwrap_or_default(),
        notes,
        seconds: 0.0, // set by refine_file
        doc: None,
    })
}

/// A folder removed when this is dropped, if it is empty then.
struct RemovedIfEmpty(PathBuf);

impl Drop for RemovedIfEmpty {
    fn drop(&mut self) {
        // Fails, harmlessly, on a folder with anything in it.
        let _ = std::fs::remove_dir(&self.0);
    }
}

/// Creates the folders of `outputs` below `out_dir` that do not exist yet;
/// returns them, to be removed again if empty, deepest first.
fn create_subfolders(out_dir: &Path, outputs: &[PathBuf]) -> anyhow::Result<Vec<RemovedIfEmpty>> {
    let mut created = Vec::new();
    let folders: std::collections::BTreeSet<&Path> = outputs.iter().filter_map(|p| p.parent()).collect();
    for folder in folders {
        let Ok(below) = folder.strip_prefix(out_dir) else {
            continue;
        };
        let mut at = out_dir.to_owned();
        for part in below.components() {
            at.push(part);
            if !at.exists() {
                if let Err(e) = std::fs::create_dir(&at) {
                    created.reverse(); // removed deepest first
                    return Err(
                        anyhow::Error::new(e).context(format!("{}: cannot create the output folder", at.display()))
                    );
                }
                created.push(RemovedIfEmpty(at.clone()));
            }
        }
    }
    created.reverse();
    Ok(created)
}

/// `delmesh batch`.
pub(super) fn run_batch(args: &BatchArgs) -> anyhow::Result<ExitCode> {
    let t0 = Instant::now();
    io::set_sync_writes(args.settings.sync);
    super::note_work_limit(args.settings.max_added);
    if args.format == Some(FormatArg::Stl) {
        bail!("--format stl: {}", super::STL_REFUSED);
    }
    // A file's output is named after it, and standard input has no name.
    if let Some(stdin) = args.inputs.iter().find(|p| io::is_standard_input(p)) {
        bail!(
            "{}: batch reads mesh files, not standard input (delmesh -i - -o OUTPUT refines a mesh from it)",
            stdin.display()
        );
    }
    let listed = expand(&args.inputs, args.recursive, &args.out_dir)?;
    let outputs = plan(&listed, &args.out_dir, args.format, |out| side_paths(out, args))?;
    let inputs: Vec<PathBuf> = listed.into_iter().map(|input| input.path).collect();
    if args.out_dir.exists() && !args.out_dir.is_dir() {
        bail!(
            "{}: the output folder names a file, not a folder",
            args.out_dir.display()
        );
    }
    // A folder this run creates is removed again if nothing ends up in it
    // (a refusal below, or every input failing).
    let _created = (!args.out_dir.exists()).then(|| RemovedIfEmpty(args.out_dir.clone()));
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("{}: cannot create the output folder", args.out_dir.display()))?;
    // With --recursive, the subfolders of the outputs: those this run
    // creates are removed again, deepest first, if nothing ends up in them.
    let _subfolders = create_subfolders(&args.out_dir, &outputs)?;
    // Whether the folder can be written in, probed beside the first output
    // that is not a folder itself (one that is fails on its own, below).
    if let Some(output) = outputs.iter().find(|p| !p.is_dir()) {
        check_output_dir(output)?;
    }
    let reports = [&args.stats_csv, &args.stats_json].map(|p| p.as_ref().and_then(|p| file_key(p)));
    if reports[0].is_some() && reports[0] == reports[1] {
        bail!(
            "{}: --stats-csv and --stats-json name one file",
            args.stats_json
                .as_ref()
                .map_or(String::new(), |p| p.display().to_string())
        );
    }
    let ids = input_ids(&inputs);
    for report in [&args.stats_csv, &args.stats_json].into_iter().flatten() {
        check_output_dir(report)?;
        let target = file_key(report);
        let is_input = inputs.iter().any(|p| std::fs::canonicalize(p).ok() == target)
            || io::FileId::of_output(report).is_some_and(|id| ids.contains(&id));
        let side = |p: &PathBuf| target.is_some() && side_paths(p, args).iter().any(|s| file_key(s) == target);
        if is_input || outputs.iter().any(|p| file_key(p) == target || side(p)) {
            bail!(
                "{}: would overwrite an input or an output (or a file beside one)",
                report.display()
            );
        }
    }
    let paths: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    super::refuse_printout_into_inputs(&paths, args.quiet)?;
    let report_to_stdout = [&args.stats_csv, &args.stats_json]
        .into_iter()
        .flatten()
        .any(|p| io::standard_stream(p) == Some(1));
    super::refuse_closed_stdout(!args.quiet || report_to_stdout)?;
    let n = inputs.len();
    let workers = if args.smallest {
        1
    } else {
        args.jobs.map_or_else(delmesh::parallel::cores, usize::from).clamp(1, n)
    };
    // Files share the cores: each runs on one thread. A lone worker keeps
    // the passes over all edges parallel (within -j).
    delmesh::parallel::set_threads(if workers > 1 {
        1
    } else {
        args.jobs.map_or(0, usize::from)
    });
    // (A relative work limit is set file by file, in `refine_file`: these
    // options name the settings of the files refused before refining.)
    let options = args.settings.options(0);
    let next = AtomicUsize::new(0);
    let (tx, rx) = std::sync::mpsc::channel();
    // The CSV rows: (input index, record), in order.
    let mut records: Vec<(usize, RunRecord)> = Vec::with_capacity(n);
    // --stats-json: the documents of the files read, the inputs refused
    // (with their errors) and those skipped, in order.
    let mut docs: Vec<FileDocument> = Vec::new();
    let (mut refused, mut skipped_paths): (Vec<(String, String)>, Vec<String>) = Default::default();
    let (mut failed, mut skipped, mut added) = (0usize, 0usize, 0usize);
    // Worker k sends with its own clone of `tx`, taken from `senders[k]`;
    // the results end when every clone is dropped.
    let senders: Vec<_> = (0..workers.max(1))
        .map(|_| std::sync::Mutex::new(Some(tx.clone())))
        .collect();
    drop(tx);
    let take = |k: usize| senders[k].lock().unwrap_or_else(|p| p.into_inner()).take();
    let worker = |k: usize| {
        let Some(tx) = take(k) else { return };
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            if i >= n {
                break;
            }
            // (A folder in a file's place is not a finished file.)
            let written = |p: &Path| p.exists() && !p.is_dir();
            let finished = |out: &Path| written(out) && side_paths(out, args).iter().all(|s| written(s));
            let done = if args.skip_existing && finished(&outputs[i]) {
                Ok(None)
            } else {
                crate::working_on(&inputs[i]);
                refine_file(&inputs[i], &outputs[i], args, &options).map(Some)
            };
            if tx.send((i, done)).is_err() {
                break;
            }
        }
    };
    std::thread::scope(|scope| {
        // (If no thread can be started, this runs every file first, then
        // reports them: the channel holds any number.)
        let started = delmesh::parallel::spawn_workers(scope, workers.max(1), &worker);
        // A worker that never started never takes its sender: drop it here.
        for (k, _) in started.iter().enumerate().filter(|(_, &s)| !s) {
            drop(take(k));
        }
        // Report in the order given, whatever order the files finish in.
        let mut waiting = BTreeMap::new();
        let mut reported = 0;
        for (i, done) in rx {
            waiting.insert(i, done);
            while let Some(done) = waiting.remove(&reported) {
                let i = reported;
                reported += 1;
                match done {
                    Ok(Some(mut done)) => {
                        docs.extend(done.doc.take());
                        let f = done.record.result.as_ref().ok();
                        added += f.map_or(0, |f| f.added_vertices);
                        if !args.quiet {
                            report_done(&inputs[i], &done, args.check);
                        }
                        records.push((i, done.record));
                    }
                    Ok(None) => {
                        skipped += 1;
                        skipped_paths.push(inputs[i].display().to_string());
                        if !args.quiet {
                            say!("skip    {} -> {}: exists", inputs[i].display(), outputs[i].display());
                        }
                    }
                    Err(Failed {
                        error: e,
                        doc,
                        refused: not_read,
                        seconds,
                    }) => {
                        failed += 1;
                        docs.extend(doc);
                        if not_read {
                            refused.push((inputs[i].display().to_string(), one_line(&e)));
                        }
                        // Which edges get stuck depends on the settings (as
                        // the main command says too).
                        let hint = if stuck_elsewhere(&e) && !args.smallest {
                            "; other settings may get through (--smallest)"
                        } else {
                            ""
                        };
                        complain!("delmesh: {}{hint}", one_line(&e));
                        records.push((i, failure_record(options, &outputs[i], &e, seconds)));
                    }
                }
            }
        }
    });
    // The summary line says what was written even when a report cannot be
    // (its error then follows, and the exit status is 1).
    let reports = (|| -> anyhow::Result<()> {
        if let Some(csv) = &args.stats_csv {
            let rows: Vec<(&Path, &RunRecord)> = records.iter().map(|(i, r)| (inputs[*i].as_path(), r)).collect();
            let table = stats_json::csv_rows(&rows);
            io::write_atomic(csv, |w| w.write_all(table.as_bytes()))?;
        }
        if let Some(json) = &args.stats_json {
            let doc = stats_json::batch_document(docs, &refused, &skipped_paths, t0.elapsed().as_secs_f64());
            io::write_atomic(json, |w| w.write_all(doc.as_bytes()))?;
        }
        Ok(())
    })();
    if !args.quiet {
        say!(
            "batch   {}: {} written, {}{} failed; {}; {:.3} s ({})",
            count(n, "file", "files"),
            n - failed - skipped,
            if args.skip_existing {
                format!("{skipped} skipped, ")
            } else {
                String::new()
            },
            failed,
            count(added, "added vertex", "added vertices"),
            t0.elapsed().as_secs_f64(),
            if args.smallest {
                let runs = args.jobs.map_or_else(delmesh::parallel::cores, usize::from);
                format!(
                    "one file at a time, {runs} run{} at once",
                    if runs == 1 { "" } else { "s" }
                )
            } else {
                format!("{workers} at a time")
            }
        );
    }
    reports?;
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// The line of a file written (and, with `checked`, passed by the check).
fn report_done(input: &Path, done: &Done, checked: bool) {
    let Ok(f) = &done.record.result else { return };
    let mut line = format!(
        "ok      {} -> {}: {}, {}, {}",
        input.display(),
        done.record.output,
        count(f.vertices, "vertex", "vertices"),
        count(f.faces, "face", "faces"),
        count(f.added_vertices, "added vertex", "added vertices")
    );
    if let Some(pruned) = f.pruned.map(|p| p.removed) {
        line += &format!(" ({pruned} pruned)");
    }
    if let (true, Some(o)) = (done.smallest, done.record.options) {
        line += &format!(
            " [smallest: {}, {}, {}]",
            super::ds_name(o.worklist),
            super::score_name(o.score),
            if o.median { "median" } else { "no median" }
        );
    }
    if checked {
        line += ", check PASS";
        line += done.maps_checked;
    }
    if !done.repairs.is_empty() {
        line += &format!("; repair: {}", done.repairs.join(", "));
    }
    if !done.notes.is_empty() {
        line += &format!("; note: {}", done.notes.join("; "));
    }
    // (File names may hold line feeds and other control characters: `say!`
    // escapes them, so that each file gets one line.)
    say!("{line} ({:.4} s)", done.seconds);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_names() {
        let name = |p: &str, f| output_name(Path::new(p), f).map(|p| p.display().to_string());
        assert_eq!(name("a/bunny.obj", None).as_deref(), Some("bunny.obj"));
        assert_eq!(name("a/Dragon.PLY.gz", None).as_deref(), Some("Dragon.ply"));
        assert_eq!(
            name("a/dragon.ply.gz", Some(FormatArg::Obj)).as_deref(),
            Some("dragon.obj")
        );
        assert_eq!(name("part.stl", Some(FormatArg::Off)).as_deref(), Some("part.off"));
        assert_eq!(name("part.stl", None).as_deref(), Some("part.obj"));
        assert_eq!(name("part.STL.gz", Some(FormatArg::Stl)).as_deref(), Some("part.stl"));
        assert_eq!(name("a.off.gz", None).as_deref(), Some("a.off"));
        assert_eq!(name("scan.v2", None).as_deref(), Some("scan.v2.obj"));
        assert_eq!(name("mesh", None).as_deref(), Some("mesh.obj"));
        assert_eq!(name("mesh.gz", None).as_deref(), Some("mesh.obj"));
        assert_eq!(name("..", None), None);
        // All extension: the main command reads `.obj` as OBJ and writes
        // `-o .ply` as PLY.
        assert_eq!(name("a/.obj", None).as_deref(), Some(".obj"));
        assert_eq!(name(".PLY.gz", None).as_deref(), Some(".ply"));
        assert_eq!(name(".obj", Some(FormatArg::Off)).as_deref(), Some(".off"));
        assert_eq!(name(".stl", None).as_deref(), Some(".obj"));
        assert_eq!(name(".hidden", None).as_deref(), Some(".hidden.obj"));
    }
}
