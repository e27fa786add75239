//! A one-line progress display on stderr: the phase (reading, building,
//! refining, writing, or the `-all` sweep), its counts and the elapsed time,
//! redrawn in place ten times a second once the work has taken about a second.
//!
//! Hand-written rather than `indicatif`: the standard library already tells
//! whether stderr is a terminal (`IsTerminal`), and one `\r`-redrawn line
//! needs no terminal library; `indicatif` would bring `console`,
//! `unicode-width` and `portable-atomic` into the build for the same line.
//!
//! Counts come from [`on_refine`] (the refine loop's progress hook) and, for
//! reading and writing, from the bytes this process has read or written so
//! far (`/proc/self/io` on Linux; elsewhere only the elapsed time is shown).

use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering::Relaxed};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

use delmesh::prune::{PruneHook, PruneStats};
use delmesh::refine::{ProgressHook, Stats};

/// When to draw (`--progress`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum When {
    /// When stderr is a terminal (and `TERM` is not `dumb`).
    Auto,
    /// Always, even into a file or pipe.
    Always,
    /// Never.
    Never,
}

/// What is being done.
#[derive(Clone, Debug, Default)]
pub enum Phase {
    /// Nothing to show.
    #[default]
    Idle,
    /// Reading a file of `size` bytes (if known).
    Read {
        /// The file's name.
        name: String,
        /// Its size in bytes.
        size: Option<u64>,
    },
    /// Building the half-edge mesh.
    Build {
        /// Input faces.
        faces: usize,
    },
    /// Refining one run.
    Refine,
    /// Writing a file.
    Write {
        /// The file's name.
        name: String,
    },
    /// Several runs at once: the `-all` sweep or `--smallest`.
    Sweep {
        /// What the line starts with (`-all`, `--smallest`).
        label: &'static str,
        /// Runs in the sweep.
        total: usize,
    },
}

/// Refine counts per worker thread (the `-all` runs run at once).
const SLOTS: usize = 64;

struct Slot {
    splits: AtomicUsize,
    flips: AtomicUsize,
    pending: AtomicUsize,
    /// Pruning (`--prune`) has begun in this slot's run.
    pruning: AtomicBool,
    pass: AtomicUsize,
    removed: AtomicUsize,
    /// Added vertices the pass has still to visit.
    to_visit: AtomicUsize,
}

#[allow(clippy::declare_interior_mutable_const)]
const EMPTY_SLOT: Slot = Slot {
    splits: AtomicUsize::new(0),
    flips: AtomicUsize::new(0),
    pending: AtomicUsize::new(0),
    pruning: AtomicBool::new(false),
    pass: AtomicUsize::new(0),
    removed: AtomicUsize::new(0),
    to_visit: AtomicUsize::new(0),
};

impl Slot {
    fn reset(&self) {
        self.splits.store(0, Relaxed);
        self.flips.store(0, Relaxed);
        self.pending.store(0, Relaxed);
        self.pruning.store(false, Relaxed);
        self.pass.store(0, Relaxed);
        self.removed.store(0, Relaxed);
        self.to_visit.store(0, Relaxed);
    }
}
static SLOT_COUNTS: [Slot; SLOTS] = [EMPTY_SLOT; SLOTS];
static RUNS_DONE: AtomicUsize = AtomicUsize::new(0);
static ENABLED: AtomicBool = AtomicBool::new(false);

thread_local! {
    static MY_SLOT: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

struct State {
    phase: Phase,
    phase_start: Instant,
    /// Bytes read and written by the process when the phase began.
    io_at_start: Option<(u64, u64)>,
    /// Characters of the line on screen (0: none).
    drawn: usize,
}

static STATE: Mutex<Option<State>> = Mutex::new(None);
static START: Mutex<Option<Instant>> = Mutex::new(None);
static DELAY_MS: AtomicU64 = AtomicU64::new(1000);

fn state() -> MutexGuard<'static, Option<State>> {
    STATE.lock().unwrap_or_else(|p| p.into_inner())
}

/// Whether to draw, given `--progress` and `--quiet` (quiet always wins).
pub fn should_draw(when: When, quiet: bool) -> bool {
    if quiet {
        return false;
    }
    match when {
        When::Always => true,
        When::Never => false,
        When::Auto => std::io::stderr().is_terminal() && std::env::var_os("TERM").is_none_or(|t| t != "dumb"),
    }
}

/// Draws until the guard is dropped (then clears the line). Does nothing
/// unless `enabled`. `DELMESH_PROGRESS_DELAY_MS` overrides the one-second
/// delay before the first drawing.
pub fn start(enabled: bool) -> Guard {
    if !enabled {
        return Guard { ticker: None };
    }
    if let Some(ms) = std::env::var("DELMESH_PROGRESS_DELAY_MS")
        .ok()
        .and_then(|v| v.trim().parse().ok())
    {
        DELAY_MS.store(ms, Relaxed);
    }
    *START.lock().unwrap_or_else(|p| p.into_inner()) = Some(Instant::now());
    *state() = Some(State {
        phase: Phase::Idle,
        phase_start: Instant::now(),
        io_at_start: None,
        drawn: 0,
    });
    ENABLED.store(true, Relaxed);
    let stop = std::sync::Arc::new(AtomicBool::new(false));
    let stop2 = stop.clone();
    let ticker = std::thread::Builder::new()
        .name("progress".into())
        .spawn(move || {
            while !stop2.load(Relaxed) {
                // Woken early when the guard drops: no wait at exit.
                std::thread::park_timeout(Duration::from_millis(100));
                if !stop2.load(Relaxed) {
                    tick();
                }
            }
        })
        .ok();
    Guard {
        ticker: ticker.map(|t| (stop, t)),
    }
}

/// Stops the display and clears its line when dropped.
pub struct Guard {
    ticker: Option<(std::sync::Arc<AtomicBool>, std::thread::JoinHandle<()>)>,
}

impl Drop for Guard {
    fn drop(&mut self) {
        if let Some((stop, t)) = self.ticker.take() {
            stop.store(true, Relaxed);
            t.thread().unpark();
            let _ = t.join();
            ENABLED.store(false, Relaxed);
            let mut st = state();
            clear(&mut st);
            *st = None;
        }
    }
}

/// The refine hook to put in `Options::progress` when drawing, else `None`.
pub fn refine_hook() -> Option<ProgressHook> {
    ENABLED.load(Relaxed).then_some(ProgressHook(&on_refine))
}

/// The refine loop's progress hook: records the counts of this thread's run.
pub fn on_refine(stats: &Stats, pending: usize) {
    let slot = &SLOT_COUNTS[MY_SLOT.with(|s| s.get()) % SLOTS];
    slot.splits.store(stats.splits, Relaxed);
    slot.flips.store(stats.flips, Relaxed);
    slot.pending.store(pending, Relaxed);
}

/// The prune hook to pass to `prune_with_progress` when drawing, else `None`.
pub fn prune_hook() -> Option<PruneHook> {
    ENABLED.load(Relaxed).then_some(PruneHook(&on_prune))
}

/// The pruning progress hook: records the counts of this thread's run.
pub fn on_prune(stats: &PruneStats, to_visit: usize) {
    let slot = &SLOT_COUNTS[MY_SLOT.with(|s| s.get()) % SLOTS];
    slot.pruning.store(true, Relaxed);
    slot.pass.store(stats.passes, Relaxed);
    slot.removed.store(stats.removed, Relaxed);
    slot.to_visit.store(to_visit, Relaxed);
    // Called every few thousand vertices (milliseconds apart): draw now, so
    // that even a short pruning shows once the delay has passed.
    tick();
}

/// Makes the calling thread report its refine counts in slot `k` (one per
/// `-all` worker), starting from zero.
pub fn use_slot(k: usize) {
    MY_SLOT.with(|s| s.set(k));
    reset_slot();
}

fn reset_slot() {
    SLOT_COUNTS[MY_SLOT.with(|s| s.get()) % SLOTS].reset();
}

/// One `-all` run has ended (its thread's counts go back to zero).
pub fn run_done() {
    RUNS_DONE.fetch_add(1, Relaxed);
    reset_slot();
}

/// Enters a new phase.
pub fn phase(p: Phase) {
    if !ENABLED.load(Relaxed) {
        return;
    }
    if matches!(p, Phase::Refine | Phase::Sweep { .. }) {
        for slot in &SLOT_COUNTS {
            slot.reset();
        }
        RUNS_DONE.store(0, Relaxed);
    }
    let mut st = state();
    if let Some(s) = st.as_mut() {
        s.phase = p;
        s.phase_start = Instant::now();
        s.io_at_start = io_counters();
    }
    drop(st);
    tick();
}

/// Whether a progress line may be on the screen (drawn, at most 79
/// characters): read without a lock, by the out-of-memory exit (Linux
/// only, as that exit is).
#[cfg(target_os = "linux")]
pub fn drawing() -> bool {
    ENABLED.load(Relaxed)
}

/// Runs `f` (which prints to stdout or stderr) with the progress line
/// cleared, so the two never mix on one terminal line.
pub fn suspend<T>(f: impl FnOnce() -> T) -> T {
    let mut st = state();
    clear(&mut st);
    let out = f();
    drop(st);
    out
}

fn clear(st: &mut Option<State>) {
    if let Some(s) = st.as_mut() {
        if s.drawn > 0 {
            let mut e = std::io::stderr().lock();
            let _ = write!(e, "\r{}\r", " ".repeat(s.drawn));
            let _ = e.flush();
            s.drawn = 0;
        }
    }
}

/// Bytes read and written by this process so far (Linux).
fn io_counters() -> Option<(u64, u64)> {
    let text = std::fs::read_to_string("/proc/self/io").ok()?;
    let field = |name: &str| -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(name))?;
        line[name.len()..].trim().parse().ok()
    };
    Some((field("rchar:")?, field("wchar:")?))
}

/// Redraws the line if the work has gone on long enough.
fn tick() {
    let Some(start) = *START.lock().unwrap_or_else(|p| p.into_inner()) else {
        return;
    };
    if start.elapsed() < Duration::from_millis(DELAY_MS.load(Relaxed)) {
        return;
    }
    let mut st = state();
    let Some(s) = st.as_mut() else { return };
    let line = describe(s);
    if line.is_empty() {
        clear(&mut st);
        return;
    }
    let line: String = line.chars().take(79).collect();
    let width = line.chars().count();
    let pad = s.drawn.saturating_sub(width);
    let mut e = std::io::stderr().lock();
    let _ = write!(e, "\r{line}{}", " ".repeat(pad));
    let _ = e.flush();
    s.drawn = width + pad;
}

/// The progress line for the current phase.
fn describe(s: &State) -> String {
    let secs = s.phase_start.elapsed().as_secs_f64();
    let io = match (s.io_at_start, io_counters()) {
        (Some((r0, w0)), Some((r, w))) => Some((r.saturating_sub(r0), w.saturating_sub(w0))),
        _ => None,
    };
    let (splits, flips, pending) = SLOT_COUNTS.iter().fold((0, 0, 0), |(a, b, c), x| {
        (
            a + x.splits.load(Relaxed),
            b + x.flips.load(Relaxed),
            c + x.pending.load(Relaxed),
        )
    });
    match &s.phase {
        Phase::Idle => String::new(),
        Phase::Read { name, size } => match (io, size) {
            (Some((r, _)), Some(size)) => format!(
                "reading {name}  {} of {}  {secs:.1} s",
                megabytes(r.min(*size)),
                megabytes(*size)
            ),
            (_, Some(size)) => format!("reading {name}  {}  {secs:.1} s", megabytes(*size)),
            _ => format!("reading {name}  {secs:.1} s"),
        },
        Phase::Build { faces } => format!("building the mesh  {} faces  {secs:.1} s", count(*faces)),
        // One run (not a sweep): slot 0 only.
        Phase::Refine if SLOT_COUNTS[0].pruning.load(Relaxed) => {
            let slot = &SLOT_COUNTS[0];
            format!(
                "pruning  pass {}  {} removed  {} to visit  {secs:.1} s",
                slot.pass.load(Relaxed),
                count(slot.removed.load(Relaxed)),
                count(slot.to_visit.load(Relaxed))
            )
        }
        Phase::Refine if splits + flips + pending == 0 => format!("refining  {secs:.1} s"),
        Phase::Refine => format!(
            "refining  {} splits  {} flips  {} edges waiting  {secs:.1} s",
            count(splits),
            count(flips),
            count(pending)
        ),
        Phase::Write { name } => match io {
            Some((_, w)) => format!("writing {name}  {}  {secs:.1} s", megabytes(w)),
            None => format!("writing {name}  {secs:.1} s"),
        },
        Phase::Sweep { label, total } => {
            let done = RUNS_DONE.load(Relaxed).min(*total);
            let bar_len = 12;
            let filled = (done * bar_len).checked_div(*total).unwrap_or(0);
            let bar = format!("{}{}", "#".repeat(filled), ".".repeat(bar_len - filled));
            if splits + flips == 0 {
                format!("{label} [{bar}] {done}/{total} runs | {secs:.0} s")
            } else {
                format!(
                    "{label} [{bar}] {done}/{total} runs | running: {} splits {} flips | {secs:.0} s",
                    count(splits),
                    count(flips)
                )
            }
        }
    }
}

fn megabytes(b: u64) -> String {
    format!("{:.1} MB", b as f64 / 1e6)
}

/// `n` with thin thousands separators (`1,234,567`).
fn count(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_have_separators() {
        assert_eq!(count(0), "0");
        assert_eq!(count(999), "999");
        assert_eq!(count(1000), "1,000");
        assert_eq!(count(1234567), "1,234,567");
    }

    #[test]
    fn quiet_and_never_draw_nothing() {
        assert!(!should_draw(When::Always, true));
        assert!(!should_draw(When::Never, false));
        assert!(should_draw(When::Always, false));
    }
}
