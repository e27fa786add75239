//! Read-only passes over large meshes, split between threads: each thread
//! takes one contiguous range of the items and the results are put back in
//! order, so they never depend on the number of threads. The one thread
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

/// The threads a pass uses, as set by [`set_threads`].
pub fn threads() -> usize {
    match THREADS.load(Ordering::Relaxed) {
        0 => cores().min(8),
        t => t,
    }
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
    std::thread::scope(|scope| {
        let parts: Vec<_> = (1..threads)
            .map(|i| scope.spawn(move || f((i * chunk).min(n)..((i + 1) * chunk).min(n))))
            .collect();
        let mut results = vec![f(0..chunk.min(n))];
        results.extend(parts.into_iter().map(|p| p.join().expect("a pass does not panic")));
        results
    })
}

/// The items `i` of `0..n` for which `keep(i)` holds, in increasing order.
pub fn filter_indices(n: usize, keep: impl Fn(usize) -> bool + Sync) -> Vec<u32> {
    let parts = map_ranges(n, |r| r.filter(|&i| keep(i)).map(|i| i as u32).collect::<Vec<u32>>());
    parts.into_iter().flatten().collect()
}

/// `f(i)` for every `i` of `0..n`, in order.
pub fn map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let parts = map_ranges(n, |r| r.map(&f).collect::<Vec<T>>());
    parts.into_iter().flatten().collect()
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
    std::thread::scope(|scope| {
        let second = scope.spawn(b);
        let first = a();
        match second.join() {
            Ok(second) => (first, second),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_do_not_depend_on_threads() {
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
