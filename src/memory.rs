//! Running out of memory ends a run like any other error: one line on
//! stderr, `delmesh: FILE: out of memory (...)`, and exit status 1, with
//! the temporary files of the outputs being written removed. Rust's own
//! handling prints two lines (a backtrace with `RUST_BACKTRACE=1`) and
//! aborts, leaving them behind; its hook for that is not stable, so the
//! global allocator ([`Allocator`]: the system's, checked; with musl, its
//! own size classes for blocks of 256 bytes or more, [`large`]) does it.
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
/// armadillo's run takes the same time.) With musl, blocks of
/// [`large::MIN`] bytes or more come from [`large`] instead.
pub struct Allocator;

/// Whether `layout` is served by [`large`]: with musl, from
/// [`large::MIN`] bytes on, at most that aligned (its blocks are aligned
/// to their class's size, or to a page). Decided by the layout alone, as
/// each call repeats it, so a block goes back to the allocator it came
/// from. (Compiled for glibc too, where it is always false, so that every
/// build checks the code.)
#[inline(always)]
fn is_large(layout: &Layout) -> bool {
    cfg!(target_env = "musl") && layout.size() >= large::MIN && layout.align() <= large::MIN
}

// SAFETY: every call is the system allocator's, with the same arguments, or
// [`large`]'s for the layouts `is_large` gives it (and a block is freed or
// resized with the layout it was made with); a null result (no memory)
// never returns.
unsafe impl GlobalAlloc for Allocator {
    #[inline]
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = if is_large(&layout) {
            large::alloc(layout.size(), false)
        } else {
            System.alloc(layout)
        };
        if p.is_null() {
            out_of_memory(layout.size());
        }
        p
    }

    #[inline]
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = if is_large(&layout) {
            large::alloc(layout.size(), true)
        } else {
            System.alloc_zeroed(layout)
        };
        if p.is_null() {
            out_of_memory(layout.size());
        }
        p
    }

    #[inline]
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let new_layout = Layout::from_size_align_unchecked(new_size, layout.align());
        let p = match (is_large(&layout), is_large(&new_layout)) {
            (false, false) => System.realloc(ptr, layout, new_size),
            (true, true) => large::realloc(ptr, layout.size(), new_size),
            _ => {
                let p = self.alloc(new_layout);
                std::ptr::copy_nonoverlapping(ptr, p, layout.size().min(new_size));
                self.dealloc(ptr, layout);
                p
            }
        };
        if p.is_null() {
            out_of_memory(new_size);
        }
        p
    }

    #[inline]
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if is_large(&layout) {
            large::dealloc(ptr, layout.size())
        } else {
            System.dealloc(ptr, layout)
        }
    }
}

/// Blocks of [`MIN`](large::MIN) bytes or more for the musl build. musl's
/// malloc maps its groups of blocks, and every block over 128 KiB, on their
/// own and unmaps them as soon as they empty; a run allocates and frees
/// many (the file's bytes, the parsed polygons, the half-edge
/// construction's lists, the output's text), and each new one is then
/// faulted in again page by page (the bunny's run: 85 `mmap` and 82
/// `munmap` calls). As glibc's heap does with `keep_freed_memory`'s
/// settings, freed blocks up to 16 MiB are kept for reuse here: each size
/// class (a power of two) has a list of free blocks, linked through their
/// first bytes. A block of a page or more is a mapping of its own (pages
/// never touched cost no memory) and grows by `mremap`, which moves pages
/// instead of copying bytes; smaller ones are cut from 64 KiB chunks. Past
/// 16 MiB, a block is mapped at its size and unmapped when freed.
///
/// The size a block was asked with is all it takes to free it: Rust's
/// allocator interface passes it back (`Layout`), so blocks carry no header.
mod large {
    use std::cell::UnsafeCell;
    use std::sync::atomic::{AtomicBool, Ordering};

    /// The page size (4 KiB on Linux x86-64; a larger one only leaves
    /// the smallest mapped classes bigger than they need be).
    pub const PAGE: usize = 4096;
    /// The smallest block served here; smaller ones are musl's.
    pub const MIN: usize = 256;
    /// The largest block kept for reuse; larger ones are mapped at their
    /// size and unmapped when freed.
    const KEPT_MAX: usize = 16 << 20;
    /// What blocks under a page are cut from.
    const CHUNK: usize = 64 << 10;
    /// Size classes: [`MIN`]·2^c bytes for class c, up to [`KEPT_MAX`].
    const CLASSES: usize = (KEPT_MAX.trailing_zeros() - MIN.trailing_zeros() + 1) as usize;
    const _: () = assert!(MIN.is_power_of_two() && KEPT_MAX.is_power_of_two() && MIN << (CLASSES - 1) == KEPT_MAX);

    /// The free blocks of each class, behind a spin lock (held for a few
    /// instructions: a pop or a push).
    struct FreeLists {
        lock: AtomicBool,
        heads: UnsafeCell<[usize; CLASSES]>,
    }
    // SAFETY: `heads`, and the links in free blocks, are touched only with
    // `lock` held.
    unsafe impl Sync for FreeLists {}
    static FREE: FreeLists = FreeLists {
        lock: AtomicBool::new(false),
        heads: UnsafeCell::new([0; CLASSES]),
    };

    /// Runs `f` on the list heads, with the lock held. (Nothing in `f` may
    /// panic or allocate: the panic's message would wait for the lock.)
    fn locked<R>(f: impl FnOnce(&mut [usize; CLASSES]) -> R) -> R {
        while FREE
            .lock
            .compare_exchange_weak(false, true, Ordering::Acquire, Ordering::Relaxed)
            .is_err()
        {
            std::hint::spin_loop();
        }
        // SAFETY: the lock is held.
        let r = f(unsafe { &mut *FREE.heads.get() });
        FREE.lock.store(false, Ordering::Release);
        r
    }

    /// How a block of `size` bytes is held: in class `c` (of [`MIN`]·2^c
    /// bytes), or mapped at its size rounded to pages.
    #[derive(Clone, Copy, PartialEq)]
    enum Kind {
        Class(usize),
        Direct(usize),
    }

    impl Kind {
        fn of(size: usize) -> Option<Kind> {
            if size <= KEPT_MAX {
                // 2^bits is the smallest power of two ≥ size.
                let bits = usize::BITS - (size.max(MIN) - 1).leading_zeros();
                Some(Kind::Class((bits - MIN.trailing_zeros()) as usize))
            } else {
                size.checked_add(PAGE - 1).map(|n| Kind::Direct(n & !(PAGE - 1)))
            }
        }

        /// The bytes the block holds.
        fn len(self) -> usize {
            match self {
                Kind::Class(c) => MIN << c,
                Kind::Direct(len) => len,
            }
        }
    }

    /// A new mapping of `len` bytes (zeroed), or 0.
    unsafe fn map(len: usize) -> usize {
        let p = libc::mmap(
            std::ptr::null_mut(),
            len,
            libc::PROT_READ | libc::PROT_WRITE,
            libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
            -1,
            0,
        );
        if p == libc::MAP_FAILED {
            0
        } else {
            p as usize
        }
    }

    /// A block of `size` (≥ [`MIN`]) bytes, zeroed if asked, aligned to
    /// its class's size (≥ [`MIN`]) or to a page; null without memory.
    pub unsafe fn alloc(size: usize, zeroed: bool) -> *mut u8 {
        let Some(kind) = Kind::of(size) else {
            return std::ptr::null_mut();
        };
        let Kind::Class(c) = kind else {
            return map(kind.len()) as *mut u8;
        };
        let free = locked(|heads| {
            let p = heads[c];
            if p != 0 {
                // SAFETY: a listed free block holds the next one's address.
                heads[c] = unsafe { *(p as *const usize) };
            }
            p
        });
        if free != 0 {
            if zeroed {
                std::ptr::write_bytes(free as *mut u8, 0, size);
            }
            return free as *mut u8;
        }
        let len = kind.len();
        if len >= PAGE {
            return map(len) as *mut u8;
        }
        // A chunk cut into blocks of the class: the first is returned, the
        // others listed.
        let chunk = map(CHUNK);
        if chunk == 0 {
            return std::ptr::null_mut();
        }
        locked(|heads| {
            for b in (chunk + len..chunk + CHUNK).step_by(len) {
                // SAFETY: b is a block of the new chunk, which nobody else holds.
                unsafe { *(b as *mut usize) = heads[c] };
                heads[c] = b;
            }
        });
        chunk as *mut u8
    }

    /// The block `ptr` of `old` bytes, resized to `size` (both ≥ [`MIN`]):
    /// the same block if its class holds `size`, moved by `mremap` if both
    /// are mappings of their own, else copied into a new one; null without
    /// memory (the old block is then still valid).
    pub unsafe fn realloc(ptr: *mut u8, old: usize, size: usize) -> *mut u8 {
        let (Some(from), Some(to)) = (Kind::of(old), Kind::of(size)) else {
            return std::ptr::null_mut();
        };
        if from == to {
            return ptr;
        }
        if from.len() >= PAGE && to.len() >= PAGE {
            let p = libc::mremap(ptr.cast(), from.len(), to.len(), libc::MREMAP_MAYMOVE);
            return if p == libc::MAP_FAILED {
                std::ptr::null_mut()
            } else {
                p.cast()
            };
        }
        let p = alloc(size, false);
        if !p.is_null() {
            std::ptr::copy_nonoverlapping(ptr, p, old.min(size));
            dealloc(ptr, old);
        }
        p
    }

    /// Frees the block `ptr` of `size` bytes: listed for reuse, or unmapped
    /// past [`KEPT_MAX`].
    pub unsafe fn dealloc(ptr: *mut u8, size: usize) {
        match Kind::of(size) {
            Some(Kind::Class(c)) => locked(|heads| {
                // SAFETY: the block is free: its first bytes hold the link.
                unsafe { *(ptr as *mut usize) = heads[c] };
                heads[c] = ptr as usize;
            }),
            Some(Kind::Direct(len)) => {
                libc::munmap(ptr.cast(), len);
            }
            None => {}
        }
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

#[cfg(test)]
mod tests {
    use super::large;

    /// The musl build's blocks (compiled and tested on every build): blocks
    /// of every kind keep their bytes through growing and shrinking across
    /// kinds, a freed block is the next of its class handed out, zeroed
    /// when asked, and blocks past the kept sizes are mapped and unmapped.
    #[test]
    fn large_blocks_keep_their_bytes_and_are_reused() {
        // SAFETY: every block is used within its size and freed once, with
        // the size it has.
        unsafe {
            let fill = |p: *mut u8, n: usize, seed: u8| {
                for i in 0..n {
                    *p.add(i) = seed.wrapping_add((i % 251) as u8);
                }
            };
            let holds =
                |p: *const u8, n: usize, seed: u8| (0..n).all(|i| *p.add(i) == seed.wrapping_add((i % 251) as u8));
            let sizes = [256, 300, 4095, 4096, 5000, 65536, 1 << 20, (16 << 20) + 1, 40 << 20];
            for (k, &a) in sizes.iter().enumerate() {
                for &b in &sizes {
                    let p = large::alloc(a, false);
                    assert!(!p.is_null() && p as usize % large::MIN == 0);
                    fill(p, a, k as u8);
                    let q = large::realloc(p, a, b);
                    assert!(!q.is_null());
                    assert!(holds(q, a.min(b), k as u8), "{a} -> {b}");
                    fill(q, b, 7);
                    large::dealloc(q, b);
                }
            }
            // Reuse, zeroed on request.
            let p = large::alloc(10_000, false);
            fill(p, 10_000, 1);
            large::dealloc(p, 10_000);
            let q = large::alloc(9_000, true);
            assert_eq!(q, p, "the freed block of the class is handed out again");
            assert!((0..9_000).all(|i| *q.add(i) == 0));
            large::dealloc(q, 9_000);
        }
    }
}
