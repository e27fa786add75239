//! The `delmesh` command line; see `delmesh --help` and README.md.

mod cli;
mod progress;
mod stats_json;

fn main() -> std::process::ExitCode {
    keep_freed_memory();
    cli::main()
}

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
