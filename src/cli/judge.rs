//! `--check` and `delmesh check`: the judge run on the files a run wrote (and
//! on its maps), and what is done with an output that fails.

use super::*;

/// An output that `delmesh check` refused (`error_kind` "check").
#[derive(Debug)]
pub(super) struct CheckFailed(String);

impl std::fmt::Display for CheckFailed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for CheckFailed {}

/// Runs the judge on `output` against `input` (or against the repaired
/// input, written to a temporary file beside the output for the judge to
/// read); an output that fails, or that the judge cannot read, is renamed
/// to `<output>.rejected`.
/// With `keep_files`, the files the judge read come back too, for [`check_maps`].
/// `gabriel_boundary`: the run's `--gabriel-boundary`, which the judge then requires.
pub(super) fn check_output(
    input: &Path,
    mesh: &io::InputMesh,
    staged: io::Staged,
    output: &Path,
    keep_files: bool,
    gabriel_boundary: bool,
) -> anyhow::Result<(io::Staged, Option<CheckedFiles>)> {
    CheckReference::new(input, mesh, output, gabriel_boundary)?.check_keeping(staged, output, keep_files)
}

/// Why a file failed `--check`: its first failure line (of `failures`, not
/// empty) and how many more there are.
fn failed_the_check(failures: &[String]) -> String {
    let more = failures.len().saturating_sub(1);
    let and_more = if more > 0 {
        format!(" (and {more} more)")
    } else {
        String::new()
    };
    format!(
        "failed the check: {}{and_more}",
        failures.first().map_or("", String::as_str)
    )
}

/// Whether `input` cannot be read a second time: standard input, or
/// anything else that is not a regular file (a pipe, a device).
fn read_only_once(input: &Path) -> bool {
    io::is_standard_input(input) || std::fs::metadata(input).is_ok_and(|m| !m.is_file())
}

/// `--check` on the maps of a run that read `input` and wrote `output`
/// (staged, a file), with `--weld-tolerance weld_tolerance` (0 without):
/// each map staged (`None` where not asked for) is judged by `delmesh
/// check --vertex-map/--face-map` and handed back if right; one
/// that is wrong, or that the judge cannot read, is put at
/// `<map>.rejected` and the run fails. Maps the judge cannot read back (the
/// input or the map a stream) are not judged, with a note in `notes`. Also
/// returns what the printout's `check` line adds: which maps are right.
/// `files` are those the mesh's check read ([`check_output`]), if kept.
pub(super) fn check_maps(
    input: &Path,
    output: &Path,
    files: Option<CheckedFiles>,
    weld_tolerance: f64,
    vertex: Option<(io::Staged, &Path)>,
    face: Option<(io::Staged, &Path)>,
    notes: &mut Vec<String>,
) -> anyhow::Result<(Option<io::Staged>, Option<io::Staged>, &'static str)> {
    let stream = read_only_once(input);
    let mut unjudged = Vec::new();
    let mut judged = |map: &Option<(io::Staged, &Path)>, kind: &'static str| match map {
        Some((staged, _)) if stream || staged.is_in_place() => {
            unjudged.push(kind);
            None
        }
        Some((staged, _)) => Some(staged.path().to_path_buf()),
        None => None,
    };
    let (vertex_path, face_path) = (judged(&vertex, "vertex"), judged(&face, "face"));
    if !unjudged.is_empty() {
        let why = if stream {
            "the input cannot be read again"
        } else {
            "written to a stream"
        };
        notes.push(format!(
            "--check did not verify the {} map{} ({why}): delmesh check --{}-map reads the files",
            unjudged.join(" and "),
            if unjudged.len() == 1 { "" } else { "s" },
            unjudged[0]
        ));
    }
    let verified = match (&vertex_path, &face_path) {
        (Some(_), Some(_)) => "; its maps are right",
        (Some(_), None) => "; its vertex map is right",
        (None, Some(_)) => "; its face map is right",
        (None, None) => return Ok((vertex.map(|m| m.0), face.map(|m| m.0), "")),
    };
    let reports = match files {
        Some(files) => judge_maps_of(
            files,
            input,
            output,
            vertex_path.as_deref(),
            face_path.as_deref(),
            weld_tolerance,
        ),
        None => delmesh::check::maps::check_map_files(
            input,
            output,
            vertex_path.as_deref(),
            face_path.as_deref(),
            weld_tolerance,
        ),
    };
    let whys: [Option<String>; 2] = match reports {
        Ok((v, f)) => [v, f].map(|r| r.filter(|r| !r.passed()).map(|r| failed_the_check(&r.failures))),
        Err(e) => {
            let why = format!("the check could not read the files: {e}");
            [
                vertex_path.as_ref().map(|_| why.clone()),
                face_path.as_ref().map(|_| why),
            ]
        }
    };
    if whys.iter().all(Option::is_none) {
        return Ok((vertex.map(|m| m.0), face.map(|m| m.0), verified));
    }
    let mut errors = Vec::new();
    for (map, why) in [vertex, face].into_iter().zip(whys) {
        if let (Some((staged, path)), Some(why)) = (map, why) {
            let mut rejected = path.as_os_str().to_owned();
            rejected.push(".rejected");
            staged.commit_to(Path::new(&rejected))?;
            errors.push(format!(
                "{}: {why} (renamed to {})",
                path.display(),
                Path::new(&rejected).display()
            ));
        }
    }
    Err(CheckFailed(errors.join("; ")).into())
}

/// `delmesh check --vertex-map --face-map` on the maps at `vertex_map` and `face_map` of the
/// run that read `original` (`weld_tolerance`: its `--weld-tolerance`) and wrote `output`,
/// given the `files` a check of that output read: the original is read only if they lack it.
fn judge_maps_of(
    files: CheckedFiles,
    original: &Path,
    output: &Path,
    vertex_map: Option<&Path>,
    face_map: Option<&Path>,
    weld_tolerance: f64,
) -> Result<(Option<MapReport>, Option<MapReport>), delmesh::check::CheckError> {
    use delmesh::check::maps;
    let tables = maps::read_map_tables(vertex_map, face_map)?;
    let original = match files.input {
        Some(raw) => raw,
        None => delmesh::check::read_raw(original)?.0,
    };
    maps::check_maps_of(
        &original,
        &files.output,
        files.shares_vertices,
        output,
        &tables,
        weld_tolerance,
    )
}

/// The files a `--check` (or `delmesh check`) read, as they list their vertices and faces,
/// kept for judging the same run's maps, which would otherwise read them again.
#[derive(Debug)]
pub(super) struct CheckedFiles {
    /// The input's, when the judge read the input file itself (not a repaired copy, nor the
    /// copy of an input read only once).
    pub(super) input: Option<RawMesh>,
    /// The output's.
    pub(super) output: RawMesh,
    /// Whether the output's faces share vertices by index (not an STL).
    shares_vertices: bool,
}

/// What `--check` compares outputs with: the input file, or the mesh read
/// from it written once to a temporary file (removed when this is dropped,
/// or by the signal handler): with --repair the repaired input, and the
/// mesh of an input that cannot be read twice (standard input, a pipe).
pub(super) struct CheckReference<'a> {
    pub(super) input: &'a Path,
    pub(super) written: Option<(io::temporary::Registration, io::temporary::TempFile)>,
    /// Whether boundary edges must face no obtuse angle (`--gabriel-boundary`).
    pub(super) gabriel_boundary: bool,
}

impl<'a> CheckReference<'a> {
    /// The reference for outputs of `mesh`, read from `input`; a written
    /// one goes beside `output`. `gabriel_boundary`: the run's setting.
    pub(super) fn new(
        input: &'a Path,
        mesh: &io::InputMesh,
        output: &Path,
        gabriel_boundary: bool,
    ) -> anyhow::Result<Self> {
        // An input read only once (standard input, a pipe): the mesh read
        // from it is written once, as a repaired one is.
        let written = match mesh.repair {
            None if !read_only_once(input) => None,
            _ => {
                let dir = output
                    .parent()
                    .filter(|d| !d.as_os_str().is_empty())
                    .unwrap_or(Path::new("."));
                let file = io::temporary::TempFile::create_in(dir, ".delmesh-reference-", ".obj")
                    .with_context(|| dir.display().to_string())?;
                io::write_mesh(file.path(), &mesh.positions, &mesh.triangles)?;
                Some((io::temporary::register(file.path()), file))
            }
        };
        Ok(CheckReference {
            input,
            written,
            gabriel_boundary,
        })
    }

    /// Runs the judge on `staged`, the file written for `output`, and
    /// hands it back if it passes; puts it at `<output>.rejected` if it
    /// fails, or if the judge cannot read the files ([`CheckFailed`]): an
    /// output is put under its name only once verified, and an input
    /// rewritten in place is replaced only then.
    pub(super) fn check(&self, staged: io::Staged, output: &Path) -> anyhow::Result<io::Staged> {
        self.check_keeping(staged, output, false).map(|(staged, _)| staged)
    }

    /// [`CheckReference::check`], keeping the files it read when `keep` (for judging the
    /// run's maps next, see [`check_maps`]).
    fn check_keeping(
        &self,
        staged: io::Staged,
        output: &Path,
        keep: bool,
    ) -> anyhow::Result<(io::Staged, Option<CheckedFiles>)> {
        let reference = self.written.as_ref().map_or(self.input, |(_, f)| f.path());
        // (The input's raw mesh numbers what the maps number only when it is the input file.)
        let input_file = self.written.is_none();
        let kept = keep.then_some(
            move |input: RawMesh, output: RawMesh, shares_vertices: bool| CheckedFiles {
                input: input_file.then_some(input),
                output,
                shares_vertices,
            },
        );
        let checked = delmesh::check::check_files_with(reference, staged.path(), kept).map(|(mut report, files)| {
            if self.gabriel_boundary {
                report.require_gabriel_boundary();
            }
            (report, files)
        });
        let why = match checked {
            Ok((report, files)) if report.passed() => return Ok((staged, files)),
            Ok((report, _)) => failed_the_check(&report.failures),
            Err(e) => format!("the check could not read the files: {e}"),
        };
        let mut rejected = output.as_os_str().to_owned();
        rejected.push(".rejected");
        staged.commit_to(Path::new(&rejected))?;
        Err(CheckFailed(format!(
            "{}: {why} (renamed to {})",
            output.display(),
            Path::new(&rejected).display()
        ))
        .into())
    }
}

/// The maps `delmesh check` is asked to verify, and the file they number.
pub(super) struct MapFiles {
    pub(super) vertex_map: Option<PathBuf>,
    pub(super) face_map: Option<PathBuf>,
    /// The file the run read (`--original`); INPUT when not given.
    pub(super) original: Option<PathBuf>,
    /// The run's `--weld-tolerance` (0 without).
    pub(super) weld_tolerance: f64,
}

impl MapFiles {
    pub(super) fn any(&self) -> bool {
        self.vertex_map.is_some() || self.face_map.is_some()
    }
}

/// `gabriel_boundary`: also require boundary edges to face no obtuse angle
/// (`check --gabriel-boundary`); `json`: also write the verdict there
/// (`check --json`).
pub(super) fn run_check(
    input: &Path,
    output: &Path,
    maps: &MapFiles,
    quiet: bool,
    gabriel_boundary: bool,
    json: Option<&Path>,
) -> anyhow::Result<ExitCode> {
    let t0 = std::time::Instant::now();
    if maps.original.is_some() && !maps.any() {
        bail!("--original names the file the maps number: give --vertex-map or --face-map with it");
    }
    if maps.weld_tolerance > 0.0 && maps.face_map.is_none() {
        bail!("--weld-tolerance is the run's, for judging its face map: give --face-map with it");
    }
    let original = maps.original.as_deref().unwrap_or(input);
    let mut read: Vec<(&str, &Path)> = vec![("INPUT", input), ("OUTPUT", output)];
    if maps.any() {
        // (The maps number INPUT as read for the check, unless --original names another file.)
        read.extend(maps.original.as_deref().map(|o| ("--original", o)));
        read.extend(maps.vertex_map.as_deref().map(|m| ("--vertex-map", m)));
        read.extend(maps.face_map.as_deref().map(|m| ("--face-map", m)));
    }
    let from_stdin: Vec<&str> = read
        .iter()
        .filter(|(_, p)| io::is_standard_input(p))
        .map(|(n, _)| *n)
        .collect();
    if from_stdin.len() > 1 {
        bail!(
            "{} are {} standard input: at most one of them can be `-`",
            from_stdin.join(" and "),
            if from_stdin.len() == 2 { "both" } else { "all" }
        );
    }
    let paths: Vec<&Path> = read.iter().map(|(_, p)| *p).collect();
    if let Some(json) = json {
        // Refused before the work: a file the check reads, or a folder that is not there.
        let written = [("--json".to_string(), json.to_path_buf())];
        for (what, path) in &read {
            refuse_same_files(path, None, &written).map_err(|_| {
                anyhow::anyhow!(
                    "{}: --json would overwrite {what}, a file the check reads",
                    json.display()
                )
            })?;
        }
        check_output_dir(json)?;
        // The JSON on standard output is alone there.
        if io::standard_stream(json) == Some(1) {
            PRINTOUT_TO_STDERR.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    }
    // (Even with --quiet: a failure's lines would still go there.)
    refuse_printout_into_inputs(&paths, false)?;
    refuse_closed_stdout(!quiet)?;
    crate::working_on(output);
    // The maps are judged on the two files as the check reads them (read once: a big mesh
    // takes longer to read than its maps to judge), INPUT's replaced by --original's.
    let judge_maps = |input_raw: RawMesh, output_raw: RawMesh, shares_vertices: bool| {
        let files = CheckedFiles {
            input: maps.original.is_none().then_some(input_raw),
            output: output_raw,
            shares_vertices,
        };
        let (vertex_map, face_map) = (maps.vertex_map.as_deref(), maps.face_map.as_deref());
        judge_maps_of(files, original, output, vertex_map, face_map, maps.weld_tolerance)
    };
    let (mut report, map_reports) = delmesh::check::check_files_with(input, output, maps.any().then_some(judge_maps))?;
    if gabriel_boundary {
        report.require_gabriel_boundary();
    }
    let (vertex_report, face_report) = map_reports.transpose()?.unwrap_or((None, None));
    // With --quiet, a check that passes prints nothing, and one that fails
    // only its FAIL and FAILED lines and the notes that say why.
    macro_rules! inform {
        ($($arg:tt)*) => {
            if !quiet {
                say!($($arg)*);
            }
        };
    }
    inform!(
        "check   {} ({} added), {}, {}; non-Delaunay edges: {} (max alpha+beta-pi {})",
        count(report.output_vertices, "vertex", "vertices"),
        report.added_vertices,
        count(report.output_faces, "face", "faces"),
        count(report.interior_edges, "interior edge", "interior edges"),
        report.non_delaunay_edges,
        report.max_excess_text()
    );
    if gabriel_boundary && report.boundary_edges == 0 {
        inform!("check   no boundary edge");
    } else if gabriel_boundary {
        inform!(
            "check   {}; facing an obtuse angle: {} (max gamma-pi/2 {})",
            count(report.boundary_edges, "boundary edge", "boundary edges"),
            report.non_gabriel_boundary_edges,
            report.max_boundary_excess_text()
        );
    }
    if report.unused_vertices > 0 {
        let n = report.unused_vertices;
        let (noun, verb) = if n == 1 { ("vertex", "is") } else { ("vertices", "are") };
        inform!("note    {n} output {noun} {verb} in no face (a Laplacian gets an empty row for each)");
    }
    // An output written with rounded numbers (`%f`, PLY `float`): every vertex moved, and the
    // failures alone do not say why (shown with --quiet too, as a note that says why).
    let (misplaced, short) = report.misplaced_vertices;
    if misplaced > 0 && short * 10 >= misplaced * 9 {
        say!(
            "note    {short} of the {} off the input's edges {} only rounded coordinates (32-bit floats, or at most {} significant digits): {} looks written with rounded numbers, which moves every vertex off the input; check compares coordinates bit for bit (delmesh writes each in the shortest form that reads back exactly)",
            count(misplaced, "output vertex", "output vertices"),
            if short == 1 { "has" } else { "have" },
            delmesh::check::SHORT_DIGITS,
            output.display()
        );
    }
    // The refined mesh given first: OUTPUT then has no vertex of its own
    // and lacks INPUT's added ones (and the order of its vertices says
    // nothing).
    let swapped = !report.passed() && report.added_vertices == 0 && report.output_vertices < report.input_vertices;
    if swapped {
        say!(
            "note    {} has no vertex that {} lacks, and lacks {} of its vertices: are the two swapped? (delmesh check ORIGINAL REFINED)",
            output.display(),
            input.display(),
            report.input_vertices - report.output_vertices
        );
    } else if let Some((output, input)) = &report.first_reordered_vertex_names {
        inform!(
            "note    the output does not begin with the input's vertices in their order (output {output} is not input {input}): per-vertex data of the input does not carry over by number"
        );
    }
    if let Some(r) = &vertex_report {
        inform!(
            "maps    vertex map: {}, each output vertex rebuilt bit for bit from two vertices of {}",
            count(r.rows, "row", "rows"),
            original.display()
        );
    }
    if let Some(r) = &face_report {
        inform!(
            "maps    face map: {}, each output face on the face of {} it names ({} said inside it, {} not)",
            count(r.rows, "row", "rows"),
            original.display(),
            r.rows - r.not_inside,
            r.not_inside
        );
    }
    for f in &report.failures {
        say!("FAIL    {f}");
    }
    let map_failures: Vec<&String> = [&vertex_report, &face_report]
        .into_iter()
        .flatten()
        .flat_map(|r| &r.failures)
        .collect();
    for f in &map_failures {
        say!("FAIL    {f}");
    }
    if report.passed() {
        let and_maps = match (&maps.vertex_map, &maps.face_map) {
            _ if !map_failures.is_empty() => "",
            (Some(_), Some(_)) => "; its maps are right",
            (Some(_), None) => "; its vertex map is right",
            (None, Some(_)) => "; its face map is right",
            (None, None) => "",
        };
        inform!(
            "PASS    {} is a Delaunay mesh{} with the geometry of {}{and_maps}",
            output.display(),
            gabriel_text(gabriel_boundary),
            input.display()
        );
    } else {
        say!(
            "FAILED  {} is not a Delaunay mesh{} with the geometry of {}",
            output.display(),
            gabriel_text(gabriel_boundary),
            input.display()
        );
    }
    for (kind, path, r) in [
        ("vertex", &maps.vertex_map, &vertex_report),
        ("face", &maps.face_map, &face_report),
    ] {
        if let (Some(path), Some(r)) = (path, r) {
            if !r.passed() {
                say!(
                    "FAILED  {} is not the {kind} map of {} from {}",
                    path.display(),
                    output.display(),
                    original.display()
                );
            }
        }
    }
    if !map_failures.is_empty() && maps.original.is_none() {
        say!("note    the maps number the file the run read (-i): when INPUT is another (the --repaired file), give that one as --original FILE (and a run's --weld-tolerance as well)");
    }
    if let Some(json) = json {
        let record = stats_json::CheckRecord {
            input,
            output,
            report: &report,
            gabriel_boundary,
            vertex_map: maps.vertex_map.as_deref().zip(vertex_report.as_ref()),
            face_map: maps.face_map.as_deref().zip(face_report.as_ref()),
            original: maps.original.as_deref(),
            seconds: t0.elapsed().as_secs_f64(),
        };
        let doc = stats_json::check_document(&record);
        io::write_atomic(json, |w| w.write_all(doc.as_bytes()))?;
    }
    Ok(if report.passed() && map_failures.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
