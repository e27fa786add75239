//! Running out of memory ends a run like any other error: one line on
//! stderr, `delmesh: FILE: out of memory (...)`, and exit status 1, with
//! the temporary files of the outputs being written removed. Rust's own
//! handling prints two lines (a backtrace with `RUST_BACKTRACE=1`) and
//! aborts, leaving them behind; its hook for that is not stable, so the
//! global allocator ([`Allocator`]: the system's, checked) does it.
//!
//! The exit runs where an allocation just failed, on any thread, maybe
//! with a lock held: it allocates nothing and takes no lock. It reads the
//! file being worked on from a fixed buffer ([`set_subject`]), removes the
//! registered temporary files ([`delmesh::io::temporary::remove_all`], as
//! the signal handlers do), writes its line with `write` and leaves with
//! `_exit`.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::UnsafeCell;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};

/// The system allocator; when it has no memory to give, the run ends as
/// the module says instead of aborting. (The check is one comparison: the
/// armadillo's run takes the same time.)
pub struct Allocator;

// SAFETY: every call is the system allocator's, with the same arguments;
// a null result (no memory) never returns.
unsafe impl GlobalAlloc for Allocator {
    #[inline]
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc(layout);
        if p.is_null() {
            out_of_memory(layout.size());
        }
        p
    }

    #[inline]
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc_zeroed(layout);
        if p.is_null() {
            out_of_memory(layout.size());
        }
        p
    }

    #[inline]
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = System.realloc(ptr, layout, new_size);
        if p.is_null() {
            out_of_memory(new_size);
        }
        p
    }

    #[inline]
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

/// The longest name kept for the message, in bytes; a longer one keeps
/// its first and last [`NAME_END`] bytes around `...`.
const NAME_MAX: usize = 300;
/// See [`NAME_MAX`].
const NAME_END: usize = 140;

/// [`SUBJECT`]'s states: nothing in it, being written, ready to read.
const EMPTY: u8 = 0;
const WRITING: u8 = 1;
const READY: u8 = 2;

/// The file being worked on, for the message: `len` bytes of `name`,
/// readable while `state` is [`READY`].
struct Subject {
    state: AtomicU8,
    len: UnsafeCell<usize>,
    name: UnsafeCell<[u8; NAME_MAX]>,
}

// SAFETY: `len` and `name` are written only by the thread that moved
// `state` to WRITING, and read only while it is READY.
unsafe impl Sync for Subject {}

static SUBJECT: Subject = Subject {
    state: AtomicU8::new(EMPTY),
    len: UnsafeCell::new(0),
    name: UnsafeCell::new([0; NAME_MAX]),
};

/// Names `path` as the file being worked on, in the message an exit for
/// lack of memory prints (`batch`, working on several files at once,
/// names the one started last). Control characters become `?`; a name
/// longer than [`NAME_MAX`] bytes is cut in the middle.
pub fn set_subject(path: &Path) {
    let shown = path.display().to_string();
    let bytes = shown.as_bytes();
    // Another thread writing it: its name will do.
    let taken = (SUBJECT.state).fetch_update(Ordering::Acquire, Ordering::Relaxed, |s| {
        (s != WRITING).then_some(WRITING)
    });
    if taken.is_err() {
        return;
    }
    // SAFETY: this thread alone moved the state to WRITING.
    let (len, name) = unsafe { (&mut *SUBJECT.len.get(), &mut *SUBJECT.name.get()) };
    let mut n = 0;
    let mut push = |part: &[u8]| {
        for &b in part {
            name[n] = if b < 0x20 || b == 0x7f { b'?' } else { b };
            n += 1;
        }
    };
    if bytes.len() <= NAME_MAX {
        push(bytes);
    } else {
        push(&bytes[..NAME_END]);
        push(b"...");
        push(&bytes[bytes.len() - NAME_END..]);
    }
    *len = n;
    SUBJECT.state.store(READY, Ordering::Release);
}

/// Whether the exit has begun (on another thread, if this one gets here).
static EXITING: AtomicBool = AtomicBool::new(false);

/// Ends the process as the module says; `size` is the allocation that
/// failed, in bytes.
#[cold]
#[inline(never)]
fn out_of_memory(size: usize) -> ! {
    if EXITING.swap(true, Ordering::AcqRel) {
        // The first thread here says it and ends the process.
        loop {
            // SAFETY: pause only waits.
            unsafe {
                libc::pause();
            }
        }
    }
    delmesh::io::temporary::remove_all();
    let mut line = Line::default();
    if crate::progress::drawing() {
        // Over the progress line (at most 79 characters).
        line.push(b"\r");
        line.push(&[b' '; 80]);
        line.push(b"\r");
    }
    line.push(b"delmesh: ");
    if SUBJECT.state.load(Ordering::Acquire) == READY {
        // SAFETY: READY: `len` and `name` are written and stay so.
        let (len, name) = unsafe { (*SUBJECT.len.get(), &*SUBJECT.name.get()) };
        line.push(&name[..len]);
        line.push(b": ");
    }
    line.push(b"out of memory (could not allocate ");
    line.push_number(size);
    line.push(b" more bytes); no file was left half-written\n");
    let mut rest = &line.bytes[..line.len];
    while !rest.is_empty() {
        // SAFETY: writes bytes of a live buffer; `_exit` ends the process
        // without running anything that might allocate.
        let written = unsafe { libc::write(2, rest.as_ptr().cast(), rest.len()) };
        if written <= 0 {
            // SAFETY: reads this thread's errno.
            if written < 0 && unsafe { *libc::__errno_location() } == libc::EINTR {
                continue;
            }
            break;
        }
        rest = &rest[written as usize..];
    }
    // SAFETY: see above.
    unsafe { libc::_exit(1) }
}

/// The message, built on the stack.
struct Line {
    bytes: [u8; 640],
    len: usize,
}

impl Default for Line {
    fn default() -> Self {
        Line {
            bytes: [0; 640],
            len: 0,
        }
    }
}

impl Line {
    /// Appends `part`, as much of it as fits.
    fn push(&mut self, part: &[u8]) {
        let n = part.len().min(self.bytes.len() - self.len);
        self.bytes[self.len..self.len + n].copy_from_slice(&part[..n]);
        self.len += n;
    }

    /// Appends `n` in decimal.
    fn push_number(&mut self, mut n: usize) {
        let mut digits = [0u8; 20];
        let mut i = digits.len();
        loop {
            i -= 1;
            digits[i] = b'0' + (n % 10) as u8;
            n /= 10;
            if n == 0 {
                break;
            }
        }
        self.push(&digits[i..]);
    }
}
