//! `-all` (every combination of DS, score and median, with its table and
//! `--chart`) and `--smallest` (many settings, pruned, the smallest kept).

use super::*;

/// `-all`: the sweep of [`sweep_combinations`], each file written as it is
/// made, then the reports and the chart.
pub(super) fn run_sweep(
    report: &Report,
    surface: &Surface,
    first_pass: &FirstPass,
    transfer: Option<&Transfer>,
) -> anyhow::Result<ExitCode> {
    let args = report.args;
    let reference = (args.check)
        .then(|| {
            CheckReference::new(
                report.input_path,
                report.input,
                report.output,
                args.settings.gabriel_boundary,
            )
        })
        .transpose()?;
    let sweep = Sweep {
        surface,
        first_pass,
        transfer,
        input: report.input,
        input_path: report.input_path,
        check: reference.as_ref(),
    };
    let (code, rows) = run_all(&sweep, report.output, args)?;
    let runs: Vec<stats_json::RunRecord> = rows
        .iter()
        .map(|r| stats_json::RunRecord {
            options: Some(r.options),
            output: r.file.display().to_string(),
            result: match &r.result {
                Ok(f) => Ok(stats_json::RunFigures {
                    vertices: f.vertices,
                    faces: f.faces,
                    added_vertices: f.added,
                    pruned: f.pruned,
                    stats: Some(f.stats),
                }),
                Err(e) => Err((error_kind(e), one_line(e))),
            },
            seconds: r.seconds,
        })
        .collect();
    report.write(&runs, true)?;
    if let Some(chart) = &args.chart {
        draw_chart(chart, report.input_path, &rows, args)?;
        if !args.quiet {
            say!("chart   {}", chart.display());
        }
    }
    Ok(code)
}

/// `--smallest`: refines with 24 settings (3 DS x scores 0-3 with the
/// median, 3 DS x scores 2 and 4 with shells, 3 DS x scores 2-3 without the
/// median), `jobs` at a time, prunes those whose result has at most
/// [`SMALLEST_PRUNE_RATIO`] times the fewest added vertices of any plus
/// [`SMALLEST_PRUNE_SLACK`] ([`worth_pruning`]), and
/// returns the settings and outcome with the fewest vertices (ties: the
/// first in that order, so the result does not depend on the number of
/// threads), with how many settings were pruned. Fails only if every setting
/// fails. Pruning takes at most `prune_passes` passes.
pub(super) fn smallest(
    surface: Surface,
    first_pass: &FirstPass,
    input_path: &Path,
    template: &Options,
    jobs: Option<u16>,
    prune_passes: usize,
) -> anyhow::Result<(Options, Outcome, usize)> {
    // In this order (ties keep the earlier settings' result): the median
    // runs; concentric shells (score 4 places the points on the shells
    // alone, score 2 only among its best samples); the runs without the
    // median, only with scores 2 and 3 (with 0 and 1 they can need billions
    // of vertices: the work limit).
    let worklists = [Worklist::Stack, Worklist::Queue, Worklist::PriorityQueue];
    let groups: [(&[Score], bool, bool); 3] = [
        (&Score::ALL[..4], true, false),
        (&[Score::AlwaysCenter, Score::Uniform], true, true),
        (&[Score::AlwaysCenter, Score::SplitAware], false, false),
    ];
    let mut settings = Vec::new();
    for (scores, median, shells) in groups {
        for worklist in worklists {
            for &score in scores {
                settings.push(Options {
                    worklist,
                    score,
                    median,
                    shells,
                    ..*template
                });
            }
        }
    }
    let threads = match jobs {
        Some(j) => usize::from(j),
        None => delmesh::parallel::cores(),
    }
    .max(1);
    // The runs share the cores: each scans on one thread (the chosen mesh
    // is then written with the threads `--jobs` allows again).
    delmesh::parallel::set_threads(1);
    // Each setting's error, if it failed: reported if every setting fails.
    let errors: Vec<std::sync::OnceLock<anyhow::Error>> = settings.iter().map(|_| std::sync::OnceLock::new()).collect();
    let fail = |i: usize, e: anyhow::Error| {
        let _ = errors[i].set(e);
    };
    // First every setting refines, unpruned: its added vertices. The runs
    // without the median come last, with a work limit (which also bounds
    // flips, at three per vertex: on CAD parts these runs flip a lot) of
    // SMALLEST_PRUNE_RATIO times the fewest vertices the others added, plus
    // 10,000: past it such a run would not be pruned (`worth_pruning`), and on some inputs
    // they would add millions of vertices (with 0 and 1, billions). The
    // shells runs with score 4 come first, and bound the splits of the
    // other median runs alike. Phases keep the result independent of the
    // number of threads.
    let added: Vec<std::sync::OnceLock<usize>> = settings.iter().map(|_| std::sync::OnceLock::new()).collect();
    // The results themselves, while their vertices add up to at most
    // SMALLEST_KEEP_VERTICES: those chosen for pruning are then not refined
    // again (on small meshes refining is a good part of the time).
    let kept: Vec<std::sync::Mutex<Option<Outcome>>> = settings.iter().map(|_| std::sync::Mutex::new(None)).collect();
    let kept_vertices = std::sync::atomic::AtomicUsize::new(0);
    let fewest = || added.iter().filter_map(|n| n.get().copied()).min();
    // The limit of the runs without the median, set after the others.
    let mut cap = usize::MAX;
    // The runs first made: concentric shells with score 4, which place
    // the points on the shells alone.
    let first = |i: usize| settings[i].shells && settings[i].score == Score::Uniform;
    // The limit on the splits of the other median runs, set after those: a
    // run that needs more than that many can win nothing, as it would not
    // be pruned (`worth_pruning`). On thin cells and slivers the median
    // runs (and shells with score 2) can add many times what score 4 adds
    // (a 4 × 20 height field of 1000:1 cells: 16,509 to 38,208 against
    // 6,233), and on larger such fields they go on for seconds each.
    let mut median_cap = usize::MAX;
    let options_of = |i: usize, cap: usize, median_cap: usize| {
        let mut options = settings[i];
        if !options.median {
            options.max_added = options.max_added.min(cap);
        } else if !first(i) {
            options.max_added = options.max_added.min(median_cap);
        }
        options
    };
    progress::phase(Phase::Sweep {
        label: "--smallest, refining",
        total: settings.len(),
    });
    let phases: [Vec<usize>; 3] = [
        (0..settings.len()).filter(|&i| first(i)).collect(),
        (0..settings.len())
            .filter(|&i| settings[i].median && !first(i))
            .collect(),
        (0..settings.len()).filter(|&i| !settings[i].median).collect(),
    ];
    for (phase, indices) in phases.iter().enumerate() {
        run_each(threads, indices, &|i| {
            let options = options_of(i, cap, median_cap);
            let mut result = refine_once(surface.clone(), first_pass, input_path, &options, None);
            // The median runs' limit is on splits only: one stopped by the
            // flips it brings along (three per split) is run again without
            // it, as it would have been.
            if let Err(e) = &result {
                if let Some(&delmesh::Error::WorkLimit { splits, limit, .. }) = e.downcast_ref::<delmesh::Error>() {
                    if options.median && limit < settings[i].max_added && splits < limit {
                        result = refine_once(surface.clone(), first_pass, input_path, &settings[i], None);
                    }
                }
            }
            match result {
                Ok(out) => {
                    let n = out.surface.positions.len() - out.surface.n_input_vertices;
                    added[i].set(n).expect("each setting runs once");
                    let size = out.surface.positions.len();
                    let fits = kept_vertices.fetch_update(
                        std::sync::atomic::Ordering::Relaxed,
                        std::sync::atomic::Ordering::Relaxed,
                        |k| Some(k + size).filter(|&k| k <= SMALLEST_KEEP_VERTICES),
                    );
                    if fits.is_ok() {
                        *kept[i].lock().unwrap_or_else(|p| p.into_inner()) = Some(out);
                    }
                }
                Err(e) => fail(i, e),
            }
        });
        // A limit of SMALLEST_PRUNE_RATIO times the fewest vertices so far
        // plus 10,000 is above what `worth_pruning` allows of the fewest at
        // the end, so the result is that of the runs without limits.
        match phase {
            0 => median_cap = fewest().map_or(usize::MAX, |f| SMALLEST_PRUNE_RATIO * f + 10_000),
            1 => cap = SMALLEST_PRUNE_RATIO * fewest().unwrap_or(0) + 10_000,
            _ => {}
        }
    }
    // Then those worth pruning are pruned (refined again if not kept: the
    // same result, the runs are deterministic). Pruning costs about a hundred
    // times refining and grows with the vertices it visits; a result many
    // times larger than the smallest would have to lose nearly all its
    // added vertices to win (CAD parts: the rotor's runs without the median
    // add 67,916 and 118,695 where the smallest adds 2,011, and pruned they
    // keep about 2,500, against 1,573; a height field of thin cells: 470,916
    // against 7,140, pruned in 158 s each).
    let fewest = fewest();
    let chosen: Vec<usize> = (0..settings.len())
        .filter(|&i| matches!((added[i].get(), fewest), (Some(&n), Some(f)) if worth_pruning(n, f)))
        .collect();
    for (i, out) in kept.iter().enumerate() {
        if !chosen.contains(&i) {
            *out.lock().unwrap_or_else(|p| p.into_inner()) = None;
        }
    }
    // The best so far, by (vertices, index of its settings).
    let best: std::sync::Mutex<Option<(usize, usize, Outcome)>> = std::sync::Mutex::new(None);
    progress::phase(Phase::Sweep {
        label: "--smallest, pruning",
        total: chosen.len(),
    });
    run_each(threads, &chosen, &|i| {
        // (A median run chosen here finished, within its limit or run
        // again without it: without the limit it gives the same result.)
        let options = options_of(i, cap, usize::MAX);
        let unpruned = match kept[i].lock().unwrap_or_else(|p| p.into_inner()).take() {
            Some(out) => Ok(out),
            None => refine_once(surface.clone(), first_pass, input_path, &options, None),
        };
        match unpruned.map(|out| prune_outcome(out, &options, prune_passes)) {
            Ok(out) => {
                let key = (out.surface.positions.len(), i);
                let mut best = best.lock().unwrap_or_else(|p| p.into_inner());
                if best.as_ref().is_none_or(|(n, j, _)| key < (*n, *j)) {
                    *best = Some((key.0, key.1, out));
                }
            }
            Err(e) => fail(i, e),
        }
    });
    delmesh::parallel::set_threads(jobs.map_or(0, usize::from));
    match best.into_inner().unwrap_or_else(|p| p.into_inner()) {
        Some((_, i, out)) => Ok((settings[i], out, chosen.len())),
        None => {
            // Every setting failed: the defaults' error says why (whichever
            // run failed first would depend on the threads).
            let defaults = Options::default();
            let i = settings
                .iter()
                .position(|o| {
                    (o.worklist, o.score, o.median, o.shells) == (defaults.worklist, defaults.score, true, false)
                })
                .expect("--smallest runs the defaults");
            let e = errors
                .into_iter()
                .nth(i)
                .and_then(std::sync::OnceLock::into_inner)
                .unwrap_or_else(|| anyhow::anyhow!("no setting ran"));
            Err(all_settings_failed(e, input_path))
        }
    }
}

/// The error of `--smallest` when none of its settings finished, from `e`,
/// the defaults' error: a work limit's hint then suggests no other
/// settings (all were tried), only what is left (see
/// `delmesh::error::Error::WorkLimit`).
pub(super) fn all_settings_failed(e: anyhow::Error, input_path: &Path) -> anyhow::Error {
    let e = match e.downcast_ref::<delmesh::Error>() {
        Some(&delmesh::Error::WorkLimit {
            splits,
            flips,
            limit,
            near_coincident,
            nearly_flat_edges,
            ..
        }) => anyhow::Error::new(delmesh::Error::WorkLimit {
            splits,
            flips,
            limit,
            median_score_2: true,
            shells: true,
            longest_first: true,
            near_coincident,
            nearly_flat_edges,
        }),
        // (Its own context, the path, is in the line already: `one_line`
        // leaves it out.)
        Some(delmesh::Error::Unsplittable { .. }) => e,
        _ => return e,
    };
    e.context(format!(
        "{}: none of the 24 settings of --smallest finished (each has the work limit); with the defaults (stack, score 2, median)",
        input_path.display()
    ))
}

/// Runs `run(i)` for each i of `indices`, in that order, `threads` at a
/// time, each counted as a run of the progress line's sweep.
fn run_each(threads: usize, indices: &[usize], run: &(dyn Fn(usize) + Sync)) {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let worker = |worker: usize| {
        progress::use_slot(worker);
        loop {
            let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let Some(&i) = indices.get(k) else {
                break;
            };
            run(i);
            progress::run_done();
        }
    };
    std::thread::scope(|scope| delmesh::parallel::spawn_workers(scope, threads.min(indices.len()), &worker));
}

/// What the `run` line adds after `--smallest`, which pruned `pruned` of
/// its 24 settings.
pub(super) fn smallest_note(pruned: usize) -> String {
    if pruned == 24 {
        " (the smallest of 24 settings, all pruned: --smallest)".to_string()
    } else {
        format!(
            " (the smallest of 24 settings, --smallest; {pruned} pruned: the others failed or added more than \
             {SMALLEST_PRUNE_RATIO} times the fewest vertices plus {SMALLEST_PRUNE_SLACK})"
        )
    }
}

/// Whether `--smallest` prunes a setting that added `added` vertices where
/// the fewest of any setting is `fewest`: one that added many times more
/// would have to lose nearly all of them to win, and pruning costs in
/// proportion to the vertices it visits (the slack lets small results be
/// pruned whatever their ratio: 41 added vertices pruned to 7 win against
/// 10 pruned to 8 on one of `tests/regressions`).
fn worth_pruning(added: usize, fewest: usize) -> bool {
    added <= SMALLEST_PRUNE_RATIO * fewest + SMALLEST_PRUNE_SLACK
}

/// `--smallest` keeps the unpruned results of its settings in memory while
/// their vertices add up to at most this many (about 100 MB).
const SMALLEST_KEEP_VERTICES: usize = 500_000;

/// See [`worth_pruning`].
const SMALLEST_PRUNE_SLACK: usize = 1000;

/// See [`worth_pruning`].
const SMALLEST_PRUNE_RATIO: usize = 4;

/// The runs of `-all`: the 18 combinations, and with `--extended` score 3
/// with each DS, with and without the median.
pub(super) fn sweep_combinations(extended: bool) -> Vec<Options> {
    let mut combos = all_combinations();
    if extended {
        for worklist in [Worklist::Stack, Worklist::Queue, Worklist::PriorityQueue] {
            for median in [true, false] {
                combos.push(Options::new(worklist, Score::SplitAware, median));
            }
        }
    }
    combos
}

/// The 18 combinations, in the report's naming order.
pub(super) fn all_combinations() -> Vec<Options> {
    let mut v = Vec::new();
    for worklist in [Worklist::Stack, Worklist::Queue, Worklist::PriorityQueue] {
        for score in [Score::AllEqual, Score::WeightedCenter, Score::AlwaysCenter] {
            for median in [true, false] {
                v.push(Options::new(worklist, score, median));
            }
        }
    }
    v
}

/// `<stem>-<s|q|p>-<0|1|2>[-m].obj` beside `output`.
pub(super) fn combination_path(output: &Path, o: &Options) -> PathBuf {
    // A compressed name keeps its format's extension too: `n.ply.gz` gives
    // `n-s-2-m.ply.gz` (gzipped PLY), not `n.ply-s-2-m.gz` (gzipped OBJ).
    let name = output
        .file_name()
        .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
    let (stem, ext) = match io::split_extensions(&name) {
        (stem, Some(ext)) => (stem, ext),
        (stem, None) => (stem, "obj"),
    };
    let ds = match o.worklist {
        Worklist::Stack => "s",
        Worklist::Queue => "q",
        Worklist::PriorityQueue => "p",
    };
    let score = stats_json::score_key(o.score);
    let name = format!("{stem}-{ds}-{score}{}.{ext}", if o.median { "-m" } else { "" });
    output.with_file_name(name)
}

/// One row of the `-all` summary.
struct Row {
    options: Options,
    file: PathBuf,
    result: anyhow::Result<RowFigures>,
    /// Its phases' seconds, also if it failed (until it did).
    seconds: stats_json::RunSeconds,
}

struct RowFigures {
    faces: usize,
    vertices: usize,
    added: usize,
    pruned: Option<PruneStats>,
    stats: Stats,
}

/// What every run of an `-all` sweep shares.
struct Sweep<'a> {
    surface: &'a Surface,
    first_pass: &'a FirstPass,
    transfer: Option<&'a Transfer>,
    /// The input as read (to name its vertices in messages).
    input: &'a io::InputMesh,
    input_path: &'a Path,
    /// With --check: what each written file is checked against.
    check: Option<&'a CheckReference<'a>>,
}

/// Refines one combination and writes its file (atomically), checked with
/// --check; `seconds` gets the seconds of its phases as they end (those of
/// a failed run too).
fn run_combination(
    sweep: &Sweep,
    options: &Options,
    prune: Option<usize>,
    file: &Path,
    seconds: &mut stats_json::RunSeconds,
) -> anyhow::Result<RowFigures> {
    let start = Instant::now();
    let out = refine_once(
        sweep.surface.clone(),
        sweep.first_pass,
        sweep.input_path,
        options,
        prune,
    )
    .map_err(|e| {
        seconds.refine = sweep.first_pass.seconds + start.elapsed().as_secs_f64();
        name_stuck_edge(e, sweep.input)
    })?;
    *seconds = out.seconds(0.0);
    let t = Instant::now();
    let written = write_output(
        file,
        sweep.input_path,
        sweep.input,
        &out.surface,
        sweep.transfer,
        &Default::default(),
    );
    seconds.write = t.elapsed().as_secs_f64();
    let (_, mut staged) = written?;
    // The surface goes before the judge reads the file back.
    let (surface, out) = out.finish();
    drop(surface);
    if let Some(reference) = sweep.check {
        staged = reference.check(staged, file)?;
    }
    printout_intact(file, "not written")?;
    staged.commit()?;
    Ok(RowFigures {
        faces: out.surface.faces,
        vertices: out.surface.vertices,
        added: out.surface.added,
        pruned: out.pruned,
        stats: out.stats,
    })
}

/// Runs the `-all` sweep on all cores (each file written, and with
/// --check checked, as soon as its run ends) and prints its table; exit
/// status 1 if a combination failed.
fn run_all(sweep: &Sweep, output: &Path, args: &RunArgs) -> anyhow::Result<(ExitCode, Vec<Row>)> {
    let combos: Vec<Options> = sweep_combinations(args.extended)
        .into_iter()
        .map(|o| Options {
            max_added: args.settings.max_added.for_input(sweep.surface.n_input_vertices),
            keep_order: args.settings.keep_order,
            progress: progress::refine_hook(),
            ..o
        })
        .collect();
    // The combinations run on all cores; each run is independent and
    // deterministic, so every file equals what a sequential run writes. Each
    // file is written as soon as its run ends: only the figures are kept.
    let threads = delmesh::parallel::cores().min(combos.len());
    let threads = match args.jobs {
        Some(j) => usize::from(j).min(combos.len()),
        None => threads,
    };
    // The combinations already share the cores: each writes and scans on one
    // thread (so that `--jobs 1` really uses one core).
    delmesh::parallel::set_threads(1);
    // Longest first, so that no core is left with a long run at the end: the
    // runs without the median and with "all equal" (then "weighted center")
    // split next to vertices and often take most of the sweep. Only the
    // order of work changes; files and table do not.
    let mut order: Vec<usize> = (0..combos.len()).collect();
    order.sort_by_key(|&i| {
        let o = &combos[i];
        (
            o.median,
            !matches!(o.score, Score::AllEqual),
            !matches!(o.score, Score::WeightedCenter),
        )
    });
    let rows = std::sync::Mutex::new(Vec::with_capacity(combos.len()));
    progress::phase(Phase::Sweep {
        label: "-all",
        total: combos.len(),
    });
    run_each(threads, &order, &|i| {
        let options = &combos[i];
        let file = combination_path(output, options);
        let mut seconds = stats_json::RunSeconds::default();
        let result = run_combination(sweep, options, args.settings.prune(), &file, &mut seconds);
        rows.lock().unwrap_or_else(|p| p.into_inner()).push(Row {
            options: *options,
            file,
            result,
            seconds,
        });
    });
    progress::phase(Phase::Idle);
    let mut rows = rows.into_inner().unwrap_or_else(|p| p.into_inner());
    // Sorted by faces as the report's tables; failed runs last.
    rows.sort_by_key(|r| {
        (
            r.result.as_ref().map_or(usize::MAX, |f| f.faces),
            combos.iter().position(|o| *o == r.options),
        )
    });
    let failed = rows.iter().filter(|r| r.result.is_err()).count();
    if !args.quiet {
        say!(
            "{:<15} {:<16} {:<6} {:>9} {:>9} {:>8} {:>8} {:>8} {:>9}  file",
            "data structure",
            "weight",
            "median",
            "faces",
            "vertices",
            "added",
            "splits",
            "flips",
            "seconds"
        );
        for r in &rows {
            let name = r.file.file_name().map(|f| f.to_string_lossy()).unwrap_or_default();
            let head = format!(
                "{:<15} {:<16} {:<6}",
                ds_name(r.options.worklist),
                score_name(r.options.score),
                if r.options.median { "yes" } else { "no" }
            );
            match &r.result {
                Ok(f) => say!(
                    "{head} {:>9} {:>9} {:>8} {:>8} {:>8} {:>9.4}  {name}",
                    f.faces,
                    f.vertices,
                    f.added,
                    f.stats.splits,
                    f.stats.flips,
                    r.seconds.refine
                ),
                Err(e) if e.downcast_ref::<CheckFailed>().is_some() => {
                    say!("{head} {:>9}  {}", "rejected", one_line(e))
                }
                Err(e) => say!("{head} {:>9}  not written: {}", "failed", one_line(e)),
            }
        }
        let switched: Vec<_> = (rows.iter())
            .filter(|r| r.result.as_ref().is_ok_and(|f| f.stats.longest_first_after.is_some()))
            .map(|r| r.file.file_name().map(|f| f.to_string_lossy()).unwrap_or_default())
            .collect();
        if !switched.is_empty() {
            say!(
                "note    {} last edges longest first, after more than {} flips per edge \
                 (--keep-order keeps the order): {}",
                match switched.len() {
                    1 => "1 run took its".to_string(),
                    n => format!("{n} runs took their"),
                },
                refine::FLIPS_PER_EDGE_BEFORE_LONGEST_FIRST,
                switched.join(", ")
            );
        }
        if args.check && failed == 0 {
            say!(
                "check   PASS: each of the {} files is a Delaunay mesh{} with the geometry of {}",
                rows.len(),
                gabriel_text(args.settings.gabriel_boundary),
                sweep.input_path.display()
            );
        }
    }
    if failed > 0 {
        let table = if args.quiet {
            "the table, without -q, says why"
        } else {
            "see the table"
        };
        let others = if failed == rows.len() {
            "none was written"
        } else {
            "the others were written"
        };
        complain!(
            "delmesh: {failed} of {} combinations failed ({table}); {others}",
            rows.len()
        );
        return Ok((ExitCode::from(1), rows));
    }
    Ok((ExitCode::SUCCESS, rows))
}

/// The colour of a score's bars in the `-all` chart; lighter without median.
fn chart_color(o: &Options) -> Rgb {
    let (r, g, b) = match o.score {
        Score::AllEqual => (0x4c, 0x72, 0xb0),
        Score::WeightedCenter => (0xdd, 0x84, 0x52),
        Score::AlwaysCenter => (0x55, 0xa8, 0x68),
        Score::SplitAware => (0x81, 0x72, 0xb3),
        Score::Uniform => (0x93, 0x78, 0x60),
    };
    if o.median {
        Rgb(r, g, b)
    } else {
        let light = |c: u8| ((c as u16 + 2 * 255) / 3) as u8;
        Rgb(light(r), light(g), light(b))
    }
}

/// `--chart`: the added vertices of each `-all` combination, in the table's order.
fn draw_chart(path: &Path, input_path: &Path, rows: &[Row], args: &RunArgs) -> anyhow::Result<()> {
    let bars: Vec<delmesh::render::Bar> = rows
        .iter()
        .map(|r| {
            let o = &r.options;
            let label = format!(
                "{:<6} -s {} {}",
                stats_json::ds_key(o.worklist),
                stats_json::score_key(o.score),
                if o.median { "median" } else { "no median" }
            );
            let (value, note) = match &r.result {
                Ok(f) => (Some(f.added as f64), f.added.to_string()),
                Err(e) => (
                    None,
                    match e.downcast_ref::<delmesh::Error>() {
                        Some(delmesh::Error::WorkLimit { .. }) => "failed: work limit".to_string(),
                        Some(delmesh::Error::Unsplittable { count, .. }) => {
                            format!("failed: {} can't be split", super::count(*count, "edge", "edges"))
                        }
                        _ => "failed".to_string(),
                    },
                ),
            };
            delmesh::render::Bar {
                label,
                value,
                color: chart_color(o),
                note,
            }
        })
        .collect();
    let scores: &[Score] = if args.extended {
        &[
            Score::AllEqual,
            Score::WeightedCenter,
            Score::AlwaysCenter,
            Score::SplitAware,
        ]
    } else {
        &[Score::AllEqual, Score::WeightedCenter, Score::AlwaysCenter]
    };
    let legend: Vec<(String, Rgb)> = (scores.iter().copied())
        .map(|score| {
            let o = Options::new(Worklist::Stack, score, true);
            (format!("-s {}", stats_json::score_key(score)), chart_color(&o))
        })
        .chain(std::iter::once((
            "lighter: no median".to_string(),
            chart_color(&Options::new(Worklist::Stack, Score::AlwaysCenter, false)),
        )))
        .collect();
    let title = format!(
        "{}: added vertices, -all{}{} (fewest first)",
        file_name(input_path),
        if args.extended { " --extended" } else { "" },
        if args.settings.prune().is_some() {
            " --prune"
        } else {
            ""
        }
    );
    let canvas = delmesh::render::bar_chart(&title, &bars, &legend);
    let bytes = canvas
        .encode(Format::of_picture(path, &path.display().to_string()).map_err(anyhow::Error::msg)?)
        .with_context(|| path.display().to_string())?;
    io::write_atomic(path, |w| w.write_all(&bytes))?;
    Ok(())
}
