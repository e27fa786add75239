//! The `delmesh` command line; see `delmesh --help` and README.md.

mod cli;
#[cfg(target_arch = "x86_64")]
mod copy;
#[cfg(target_os = "linux")]
mod memory;
mod progress;
mod stats_json;

use std::sync::atomic::{AtomicBool, Ordering};

/// Lack of memory ends a run with one line and exit status 1, its
/// temporary files removed ([`memory`]).
#[cfg(target_os = "linux")]
#[global_allocator]
static ALLOCATOR: memory::Allocator = memory::Allocator;

fn main() -> std::process::ExitCode {
    keep_freed_memory();
    remove_temporary_files_on_signals();
    cli::main()
}

/// Names `path` as the file being worked on, for the line an exit for lack
/// of memory prints ([`memory::set_subject`]).
pub(crate) fn working_on(path: &std::path::Path) {
    #[cfg(target_os = "linux")]
    memory::set_subject(path);
    #[cfg(not(target_os = "linux"))]
    let _ = path;
}

/// Whether standard output was closed when the process started (`>&-`).
/// Rust's runtime then opens `/dev/null` in its place before `main`, where
/// whatever is written vanishes without an error; `cat` fails instead
/// ("Bad file descriptor"), and so does delmesh when it has anything to
/// write there.
static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);

/// See [`STDOUT_CLOSED`].
pub(crate) fn stdout_closed() -> bool {
    STDOUT_CLOSED.load(Ordering::Relaxed)
}

/// Notes [`STDOUT_CLOSED`]: run by the C library before `main`, hence
/// before Rust's runtime fills the gap.
#[cfg(target_os = "linux")]
#[used]
#[link_section = ".init_array"]
static NOTE_CLOSED_STDOUT: extern "C" fn() = {
    extern "C" fn note() {
        // SAFETY: F_GETFD only reads the descriptor's flags.
        if unsafe { libc::fcntl(1, libc::F_GETFD) } == -1 {
            STDOUT_CLOSED.store(true, Ordering::Relaxed);
        }
    }
    note
};

/// Ctrl-C (SIGINT), `kill` (SIGTERM), a closed terminal (SIGHUP), and the
/// other signals whose default is to end the process and that a run may
/// get (Ctrl-\ SIGQUIT, SIGUSR1/2, SIGALRM, SIGVTALRM, SIGPROF, a CPU
/// limit's SIGXCPU, `abort`'s SIGABRT, SIGTRAP, SIGSYS) end it as before,
/// but first remove the temporary file of any output being written
/// ([`delmesh::io::temporary`]): an interrupted run leaves nothing behind
/// (its outputs are either complete or absent anyway). A signal the parent
/// set to be ignored (`nohup`) stays ignored.
///
/// A file size limit's SIGXFSZ (`ulimit -f`) is ignored instead: a write
/// past the limit then fails with "File too large", which ends the run
/// like a full disk, with one line and exit status 1.
#[cfg(unix)]
fn remove_temporary_files_on_signals() {
    // SAFETY: sets a signal's disposition; called before any other thread
    // exists.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    extern "C" fn on_signal(signal: libc::c_int) {
        delmesh::io::temporary::remove_all();
        // SAFETY: signal and raise are async-signal-safe. The signal is
        // blocked while this handler runs: it is delivered, with its
        // default action (the process ends, killed by it), on return.
        unsafe {
            libc::signal(signal, libc::SIG_DFL);
            libc::raise(signal);
        }
    }
    for signal in [
        libc::SIGINT,
        libc::SIGTERM,
        libc::SIGHUP,
        libc::SIGQUIT,
        libc::SIGUSR1,
        libc::SIGUSR2,
        libc::SIGALRM,
        libc::SIGVTALRM,
        libc::SIGPROF,
        libc::SIGXCPU,
        libc::SIGABRT,
        libc::SIGTRAP,
        libc::SIGSYS,
    ] {
        // SAFETY: installs a handler that only does async-signal-safe work;
        // called before any other thread exists.
        unsafe {
            let mut old: libc::sigaction = std::mem::zeroed();
            if libc::sigaction(signal, std::ptr::null(), &mut old) == 0 && old.sa_sigaction != libc::SIG_IGN {
                libc::signal(signal, on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t);
            }
        }
    }
}

#[cfg(not(unix))]
fn remove_temporary_files_on_signals() {}

/// glibc's malloc hands blocks above 128 KiB back to the kernel when they are
/// freed, and each new one is then faulted in again page by page, at about
/// 2 µs a page in virtual machines like the one delmesh is measured on. A
/// run allocates and frees many such blocks in turn (the file's bytes, the
/// parsed polygons, the half-edge construction's lists, the output's text),
/// so keep freed memory in the heap for the next one: blocks up to 32 MiB
/// come from the heap and the heap is never trimmed. The peak memory does not
/// change (measured on the dragon); page faults fall by about a quarter.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn keep_freed_memory() {
    // SAFETY: mallopt only sets allocator parameters; it is called before
    // any other thread exists. A refused setting leaves glibc's default.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
        libc::mallopt(libc::M_TOP_PAD, 64 << 20);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn keep_freed_memory() {}
