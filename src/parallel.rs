//! Passes over large meshes, split between threads: each thread takes one
//! contiguous range of the items (and writes, if anything, only what its
//! range owns) and the results are put back in order, so they never depend
//! on the number of threads. The one thread
//! setting here also governs the OBJ writer's formatting threads.

use std::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Passes over fewer items than this run on the calling thread: starting a
/// thread (tens of microseconds) would cost more than it saves.
pub const MIN_PARALLEL_ITEMS: usize = 1 << 15;

/// How many threads a pass uses: 0 (the default) means one per core, up to 8.
static THREADS: AtomicUsize = AtomicUsize::new(0);

/// Sets how many threads each pass (and the OBJ writer) uses (0: one per
/// core, up to 8). The CLI sets it from `--jobs`, and to 1 while several
/// runs already share the cores.
pub fn set_threads(n: usize) {
    THREADS.store(n, Ordering::Relaxed);
}

/// The number of cores this process may use (asked once: the answer comes
/// from reading cgroup files).
pub fn cores() -> usize {
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |t| t.get()))
}

/// The most threads a pass uses, whatever [`set_threads`] asked: more
/// than cores gain nothing, and thousands could exhaust the system's
/// thread limit.
pub const MAX_THREADS: usize = 64;

/// The threads a pass uses, as set by [`set_threads`].
pub fn threads() -> usize {
    match THREADS.load(Ordering::Relaxed) {
        0 => cores().min(8),
        t => t.min(MAX_THREADS),
    }
}

/// Starts `f` on a new thread of `scope`; `None` if the system refuses
/// (a thread limit, no memory for a stack): every caller then does the
/// work on its own thread instead, so such a limit costs speed, never a
/// failure.
///
/// [`refuse_threads`], or the environment variable `DELMESH_NO_THREADS=1`,
/// makes every start fail as a thread limit would: the tests run the
/// fallbacks so.
pub fn try_spawn<'scope, T: Send + 'scope>(
    scope: &'scope std::thread::Scope<'scope, '_>,
    f: impl FnOnce() -> T + Send + 'scope,
) -> Option<std::thread::ScopedJoinHandle<'scope, T>> {
    static FROM_ENV: std::sync::Once = std::sync::Once::new();
    FROM_ENV.call_once(|| {
        if std::env::var_os("DELMESH_NO_THREADS").is_some_and(|v| v == "1") {
            refuse_threads(true);
        }
    });
    if REFUSE_THREADS.load(Ordering::Relaxed) {
        return None;
    }
    std::thread::Builder::new().spawn_scoped(scope, f).ok()
}

static REFUSE_THREADS: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Held by the tests that change the thread settings ([`set_threads`],
/// [`refuse_threads`]): the settings are global and tests run at once, so
/// one test's `refuse_threads(false)` could land inside another's
/// refusal.
#[cfg(test)]
pub(crate) fn settings_lock_for_tests() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    LOCK.lock().unwrap_or_else(|p| p.into_inner())
}

/// Makes [`try_spawn`] fail (`true`) or try again (`false`): for testing
/// that every result is the same when no thread can be started.
pub fn refuse_threads(refuse: bool) {
    REFUSE_THREADS.store(refuse, Ordering::Relaxed);
}

/// Starts `n` workers in `scope`, worker `k` running `worker(k)`, for
/// workers that share their work (each takes the next item from a common
/// counter until none is left): one that cannot be started only leaves
/// more to the others. If none can, the calling thread runs `worker(0)`
/// itself before returning (and with `n` = 1 it always does). Returns
/// which workers run (or ran).
pub fn spawn_workers<'scope, F: Fn(usize) + Sync>(
    scope: &'scope std::thread::Scope<'scope, '_>,
    n: usize,
    worker: &'scope F,
) -> Vec<bool> {
    let mut started: Vec<bool> = if n > 1 {
        (0..n).map(|k| try_spawn(scope, move || worker(k)).is_some()).collect()
    } else {
        vec![false; n.max(1)]
    };
    if !started.contains(&true) {
        worker(0);
        started[0] = true;
    }
    started
}

/// The threads a pass over `n` items uses.
fn threads_for(n: usize) -> usize {
    if n < MIN_PARALLEL_ITEMS {
        1
    } else {
        threads()
    }
}

/// `f` applied to consecutive ranges covering `0..n` (one per thread, the
/// last ones possibly empty), in order.
pub fn map_ranges<T: Send>(n: usize, f: impl Fn(Range<usize>) -> T + Sync) -> Vec<T> {
    let threads = threads_for(n);
    if threads == 1 {
        return vec![f(0..n)];
    }
    let chunk = n.div_ceil(threads);
    let f = &f;
    let range = |i: usize| (i * chunk).min(n)..((i + 1) * chunk).min(n);
    std::thread::scope(|scope| {
        let parts: Vec<_> = (1..threads)
            .map(|i| (i, try_spawn(scope, move || f(range(i)))))
            .collect();
        let mut results = vec![f(range(0))];
        results.extend(parts.into_iter().map(|(i, part)| match part {
            Some(part) => part.join().expect("a pass does not panic"),
            None => f(range(i)),
        }));
        results
    })
}

/// The items `i` of `0..n` for which `keep(i)` holds, in increasing order.
pub fn filter_indices(n: usize, keep: impl Fn(usize) -> bool + Sync) -> Vec<u32> {
    concat(map_ranges(n, |r| {
        r.filter(|&i| keep(i)).map(|i| i as u32).collect::<Vec<u32>>()
    }))
}

/// `f(i)` for every `i` of `0..n`, in order.
pub fn map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    concat(map_ranges(n, |r| r.map(&f).collect::<Vec<T>>()))
}

/// The parts one after the other: the only part itself when there is one
/// (every pass over a small mesh), else one copy of each part's block.
pub(crate) fn concat<T>(parts: Vec<Vec<T>>) -> Vec<T> {
    let mut parts = parts.into_iter();
    let Some(mut all) = parts.next() else {
        return Vec::new();
    };
    let rest: Vec<Vec<T>> = parts.collect();
    all.reserve_exact(rest.iter().map(Vec::len).sum());
    for mut part in rest {
        all.append(&mut part);
    }
    all
}

/// `(a(), b())`: `b` on a second thread when `worth_it` and more than one
/// thread is allowed, else one after the other. For two independent pieces
/// of work (the judge reads its two files at once); the results do not
/// depend on which way they ran.
pub fn join<A: Send, B: Send>(worth_it: bool, a: impl FnOnce() -> A + Send, b: impl FnOnce() -> B + Send) -> (A, B) {
    if !worth_it || threads() < 2 {
        let first = a();
        return (first, b());
    }
    // `b` goes to the thread inside an Option, so that it is still here if
    // the thread cannot be started.
    let b = std::sync::Mutex::new(Some(b));
    std::thread::scope(|scope| {
        let run_b = || b.lock().unwrap_or_else(|p| p.into_inner()).take().map(|b| b());
        let second = try_spawn(scope, run_b);
        let first = a();
        let second = match second.map(|s| s.join()) {
            Some(Ok(second)) => second,
            Some(Err(panic)) => std::panic::resume_unwind(panic),
            None => run_b(),
        };
        (first, second.expect("b runs once"))
    })
}

/// What `run` gives on `threads` threads, and with no thread allowed to
/// start (the calling thread does all the work): for tests of work split
/// between threads.
#[cfg(test)]
pub(crate) fn threaded_and_alone<T>(threads: usize, run: impl Fn() -> T) -> (T, T) {
    let _settings = settings_lock_for_tests();
    set_threads(threads);
    let threaded = run();
    refuse_threads(true);
    let alone = run();
    refuse_threads(false);
    set_threads(0);
    (threaded, alone)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_do_not_depend_on_threads() {
        let _settings = settings_lock_for_tests();
        let n = 3 * MIN_PARALLEL_ITEMS + 7;
        let keep = |i: usize| i % 7 == 3;
        let expected: Vec<u32> = (0..n).filter(|&i| keep(i)).map(|i| i as u32).collect();
        let squares: Vec<u64> = (0..n as u64).map(|i| i * i).collect();
        for threads in [1, 2, 3, 8] {
            set_threads(threads);
            assert_eq!(filter_indices(n, keep), expected);
            assert_eq!(map(n, |i| (i * i) as u64), squares);
            assert_eq!(map_ranges(n, |r| r.len()).iter().sum::<usize>(), n);
        }
        // The same when no thread can be started (a thread limit).
        refuse_threads(true);
        set_threads(4);
        assert_eq!(filter_indices(n, keep), expected);
        assert_eq!(map(n, |i| (i * i) as u64), squares);
        assert_eq!(join(true, || map(n, |i| i % 3), || 7), (map(n, |i| i % 3), 7));
        let ran = std::sync::Mutex::new(Vec::new());
        let worker = |k: usize| ran.lock().unwrap().push(k);
        let started = std::thread::scope(|scope| spawn_workers(scope, 3, &worker));
        assert_eq!(started, vec![true, false, false]);
        assert_eq!(*ran.lock().unwrap(), vec![0]);
        refuse_threads(false);
        set_threads(0);
        assert_eq!(filter_indices(10, keep), vec![3]);
        for worth_it in [false, true] {
            assert_eq!(
                join(worth_it, || map(n, |i| i % 3), || filter_indices(n, keep)),
                (map(n, |i| i % 3), expected.clone())
            );
        }
    }
}
