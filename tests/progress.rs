//! The progress line: silent unless stderr is a terminal (assert_cmd captures
//! stderr, so it is not one) or `--progress always`; silent with `-q`; and
//! the refine loop's hook is called on long runs.

mod common;

use std::sync::atomic::{AtomicUsize, Ordering};

use assert_cmd::Command;
use delmesh::prune::{prune, prune_with_progress, PruneHook, PruneStats};
use delmesh::refine::{ProgressHook, Stats, PROGRESS_INTERVAL};
use delmesh::{make_delaunay, Options, Surface};
use glam::DVec3;

/// delmesh with the progress delay at zero: anything that could be drawn is.
fn delmesh() -> Command {
    let mut c = Command::cargo_bin("delmesh").unwrap();
    c.env("DELMESH_PROGRESS_DELAY_MS", "0");
    c
}

fn stderr_of(args: &[&str], dir: &std::path::Path) -> (bool, String) {
    let out = delmesh()
        .current_dir(dir)
        .arg("-i")
        .arg(common::data_dir().join("bunny.obj"))
        .args(args)
        .output()
        .unwrap();
    (out.status.success(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn not_a_terminal_means_no_progress_output() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["-o", "b.obj"][..],
        &["-o", "b.obj", "--progress", "auto"],
        &["-o", "all/b.obj", "-all"],
        &["-o", "b.obj", "-q", "--progress", "always"],
        &["-o", "all/b.obj", "-all", "-q", "--progress", "always"],
        &["-o", "b.obj", "--progress", "never"],
    ] {
        std::fs::create_dir_all(dir.path().join("all")).unwrap();
        let (ok, stderr) = stderr_of(args, dir.path());
        assert!(ok, "{args:?}: {stderr}");
        assert_eq!(stderr, "", "{args:?} printed on stderr");
    }
}

#[test]
fn progress_always_draws_each_phase_and_erases_it() {
    let dir = tempfile::tempdir().unwrap();
    // The same runs draw when asked to: the test above is not vacuous.
    let (ok, stderr) = stderr_of(&["-o", "b.obj", "--progress", "always"], dir.path());
    assert!(ok, "{stderr}");
    for phase in ["reading bunny.obj", "building the mesh", "refining", "writing b.obj"] {
        assert!(stderr.contains(phase), "no {phase:?} in {stderr:?}");
    }
    // Every drawing is a `\r` redraw, and the last thing left is blank.
    assert!(!stderr.contains('\n'), "{stderr:?}");
    assert!(stderr.ends_with('\r'), "{stderr:?}");
    let last = stderr.trim_end_matches('\r').rsplit('\r').next().unwrap();
    assert!(last.trim().is_empty(), "{last:?}");
    std::fs::create_dir(dir.path().join("all")).unwrap();
    let (ok, stderr) = stderr_of(&["-o", "all/b.obj", "-all", "--progress", "always"], dir.path());
    assert!(ok, "{stderr}");
    assert!(stderr.contains("/18 runs"), "{stderr:?}");
    // Pruning has a line of its own, and --smallest counts its runs: the 24
    // refinements, then the prunings.
    let (ok, stderr) = stderr_of(&["-o", "b.obj", "--prune", "--progress", "always"], dir.path());
    assert!(ok, "{stderr}");
    assert!(stderr.contains("pruning  pass 1"), "{stderr:?}");
    let (ok, stderr) = stderr_of(&["-o", "b.obj", "--smallest", "--progress", "always"], dir.path());
    assert!(ok, "{stderr}");
    assert!(
        stderr.contains("--smallest, refining [")
            && stderr.contains("/24 runs")
            && !stderr.contains("/18 runs")
            && stderr.contains("--smallest, pruning ["),
        "{stderr:?}"
    );
}

/// A wavy strip of long thin triangles: every diagonal is non-Delaunay and,
/// the surface being curved, must be split; many thousands of DS operations.
fn wavy_strip(nx: usize, ny: usize) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut rng = common::Rng::new(7);
    let mut p = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (x, y) = (i as f64, j as f64 * 0.15);
            p.push(DVec3::new(x, y, 0.3 * (x * 0.7).sin() + 0.01 * rng.f64()));
        }
    }
    let id = |i: usize, j: usize| (j * nx + i) as u32;
    let mut t = Vec::new();
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            t.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
            t.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (p, t)
}

static CALLS: AtomicUsize = AtomicUsize::new(0);
static LAST_SPLITS: AtomicUsize = AtomicUsize::new(0);

fn count_calls(stats: &Stats, _pending: usize) {
    CALLS.fetch_add(1, Ordering::Relaxed);
    LAST_SPLITS.store(stats.splits, Ordering::Relaxed);
}

#[test]
fn the_refine_hook_is_called_on_long_runs_and_changes_nothing() {
    let (p, t) = wavy_strip(90, 90);
    let mut with_hook = Surface::new(p.clone(), &t).unwrap();
    let mut without = Surface::new(p, &t).unwrap();
    let mut options = Options::default();
    let plain = make_delaunay(&mut without, &options).unwrap();
    options.progress = Some(ProgressHook(&count_calls));
    let hooked = make_delaunay(&mut with_hook, &options).unwrap();
    // The hook changes nothing in the result.
    assert_eq!(plain, hooked);
    assert_eq!(with_hook.positions, without.positions);
    let calls = CALLS.load(Ordering::Relaxed);
    let operations = (hooked.splits + hooked.flips) as u64;
    assert!(
        operations >= PROGRESS_INTERVAL,
        "the strip is too easy: {operations} operations"
    );
    assert!(calls >= 1, "{calls} calls for {operations} operations");
    assert!(LAST_SPLITS.load(Ordering::Relaxed) <= hooked.splits);
}

static PRUNE_CALLS: AtomicUsize = AtomicUsize::new(0);
static MOST_TO_VISIT: AtomicUsize = AtomicUsize::new(0);

fn count_prune_calls(_stats: &PruneStats, to_visit: usize) {
    PRUNE_CALLS.fetch_add(1, Ordering::Relaxed);
    MOST_TO_VISIT.fetch_max(to_visit, Ordering::Relaxed);
}

#[test]
fn the_prune_hook_is_called_and_changes_nothing() {
    let (p, t) = wavy_strip(40, 40);
    let mut a = Surface::new(p, &t).unwrap();
    let options = Options::default();
    let refined = make_delaunay(&mut a, &options).unwrap();
    let mut b = a.clone();
    let plain = prune(&mut a, &options);
    let hooked = prune_with_progress(&mut b, &options, Some(PruneHook(&count_prune_calls)));
    assert_eq!(plain, hooked);
    assert_eq!(a.positions, b.positions);
    assert!(plain.removed > 0, "nothing to prune: the test would see little");
    // At least once per pass, and never more vertices to visit than were added.
    assert!(PRUNE_CALLS.load(Ordering::Relaxed) >= plain.passes);
    assert!(MOST_TO_VISIT.load(Ordering::Relaxed) < refined.splits);
}
