//! The temporary files being written, so that a run interrupted by a
//! signal (Ctrl-C, `kill`, a closed terminal) removes them before it dies:
//! [`write_atomic`](super::write_atomic) writes each output into a hidden
//! `.delmesh-*.tmp` file beside it, which only the final rename makes the
//! output.
//!
//! The binary's signal handler calls [`remove_all`], which may run at any
//! instant on any thread, so it only reads atomics and fixed buffers and
//! calls `unlink`: no lock, no allocation. Registration copies the path
//! into one of [`SLOTS`] buffers (a path too long, or all slots taken, is
//! simply not registered: the file is then left behind, as before).

#[cfg(unix)]
use std::cell::UnsafeCell;
use std::path::{Path, PathBuf};
#[cfg(unix)]
use std::sync::atomic::{AtomicU8, Ordering};

/// Files that can be registered at once (one per thread writing).
pub const SLOTS: usize = 64;
/// The longest path registered, in bytes.
#[cfg(unix)]
const MAX_PATH: usize = 4096;

#[cfg(unix)]
const FREE: u8 = 0;
#[cfg(unix)]
const FILLING: u8 = 1;
#[cfg(unix)]
const READY: u8 = 2;

/// One registered path: `state` says whether `path` holds one (a
/// NUL-terminated byte string) and may be read.
#[cfg(unix)]
struct Slot {
    state: AtomicU8,
    path: UnsafeCell<[u8; MAX_PATH]>,
}

// SAFETY: `path` is written only by the thread that moved `state` from
// FREE to FILLING, and read only while `state` is READY.
#[cfg(unix)]
unsafe impl Sync for Slot {}

#[cfg(unix)]
#[allow(clippy::declare_interior_mutable_const)]
const EMPTY: Slot = Slot {
    state: AtomicU8::new(FREE),
    path: UnsafeCell::new([0; MAX_PATH]),
};

/// 256 KiB of zeros in the executable's bss: no page is touched until used.
#[cfg(unix)]
static REGISTERED: [Slot; SLOTS] = [EMPTY; SLOTS];

/// A registered file; dropping it unregisters the file (once it has been
/// renamed into place or removed).
#[must_use = "the file is unregistered when this is dropped"]
#[derive(Debug)]
pub struct Registration {
    #[cfg(unix)]
    slot: Option<usize>,
}

/// Registers `path`, a temporary file just created, for [`remove_all`].
pub fn register(path: &Path) -> Registration {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let bytes = path.as_os_str().as_bytes();
        if bytes.len() >= MAX_PATH || bytes.contains(&0) {
            return Registration { slot: None };
        }
        for (i, slot) in REGISTERED.iter().enumerate() {
            if slot
                .state
                .compare_exchange(FREE, FILLING, Ordering::Acquire, Ordering::Relaxed)
                .is_ok()
            {
                // SAFETY: this thread alone moved the slot to FILLING.
                let buffer = unsafe { &mut *slot.path.get() };
                buffer[..bytes.len()].copy_from_slice(bytes);
                buffer[bytes.len()] = 0;
                slot.state.store(READY, Ordering::Release);
                return Registration { slot: Some(i) };
            }
        }
        Registration { slot: None }
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        Registration {}
    }
}

impl Drop for Registration {
    fn drop(&mut self) {
        #[cfg(unix)]
        if let Some(i) = self.slot {
            REGISTERED[i].state.store(FREE, Ordering::Release);
        }
    }
}

/// Removes every registered file. Async-signal-safe: atomics and `unlink`
/// only, for a signal handler.
pub fn remove_all() {
    #[cfg(unix)]
    for slot in &REGISTERED {
        if slot.state.load(Ordering::Acquire) == READY {
            // SAFETY: a READY slot holds a NUL-terminated path.
            unsafe {
                unlink(slot.path.get().cast());
            }
        }
    }
}

#[cfg(unix)]
extern "C" {
    fn unlink(path: *const std::ffi::c_char) -> std::ffi::c_int;
}

/// A file created under a new name, removed when dropped unless
/// [`persist`](TempFile::persist)ed. Its path is the folder as given
/// joined with the name: a relative folder stays relative, so that the
/// file can be made where `cp` can (in a folder whose absolute path is
/// longer than the system allows a path to be), and the signal handler
/// can remove it there (delmesh never changes its current folder).
#[derive(Debug)]
pub struct TempFile {
    file: std::fs::File,
    path: PathBuf,
    /// Renamed into place: nothing to remove.
    persisted: bool,
}

impl TempFile {
    /// Creates `PREFIX` + 12 random hex digits + `SUFFIX` in `dir`, new
    /// (never an existing file or link), readable and writable by its
    /// owner only.
    pub fn create_in(dir: &Path, prefix: &str, suffix: &str) -> std::io::Result<TempFile> {
        use std::hash::{BuildHasher, Hasher};
        use std::sync::atomic::{AtomicU64, Ordering};
        /// Names tried so far by this process: each name is new.
        static TRIED: AtomicU64 = AtomicU64::new(0);
        let random = std::collections::hash_map::RandomState::new();
        let mut options = std::fs::OpenOptions::new();
        options.read(true).write(true).create_new(true);
        #[cfg(unix)]
        std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o600);
        let mut last = None;
        for _ in 0..64 {
            let mut h = random.build_hasher();
            h.write_u64(TRIED.fetch_add(1, Ordering::Relaxed));
            h.write_u32(std::process::id());
            let name = format!("{prefix}{:012x}{suffix}", h.finish() >> 16);
            let path = dir.join(name);
            match options.open(&path) {
                Ok(file) => {
                    return Ok(TempFile {
                        file,
                        path,
                        persisted: false,
                    })
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => last = Some(e),
                Err(e) => return Err(e),
            }
        }
        Err(last.unwrap_or_else(|| std::io::ErrorKind::AlreadyExists.into()))
    }

    /// Where the file is.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The open file.
    pub fn as_file(&self) -> &std::fs::File {
        &self.file
    }

    /// The open file, to write.
    pub fn as_file_mut(&mut self) -> &mut std::fs::File {
        &mut self.file
    }

    /// Renames the file to `to` (replacing what is there); on an error it
    /// is still removed when dropped.
    pub fn persist(mut self, to: &Path) -> std::io::Result<()> {
        std::fs::rename(&self.path, to)?;
        self.persisted = true;
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.persisted {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(unix)]
    #[test]
    fn registered_files_are_removed_and_unregistered_ones_kept() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.tmp"), dir.path().join("b.tmp"));
        std::fs::write(&a, "a").unwrap();
        std::fs::write(&b, "b").unwrap();
        let registered = register(&a);
        drop(register(&b)); // registered, then unregistered
        remove_all();
        assert!(!a.exists() && b.exists());
        drop(registered);
        // Slots are reused: more registrations than slots, one at a time.
        for _ in 0..3 * SLOTS {
            let r = register(&b);
            assert!(r.slot.is_some());
        }
        assert!(b.exists());
    }

    #[test]
    fn temporary_files_are_new_relative_and_removed_unless_persisted() {
        let dir = tempfile::tempdir().unwrap();
        let a = TempFile::create_in(dir.path(), ".delmesh-", ".tmp").unwrap();
        let b = TempFile::create_in(dir.path(), ".delmesh-", ".tmp").unwrap();
        assert_ne!(a.path(), b.path());
        let name = a.path().file_name().unwrap().to_str().unwrap().to_owned();
        assert!(
            name.starts_with(".delmesh-") && name.ends_with(".tmp") && name.len() == 25,
            "{name}"
        );
        let kept = dir.path().join("kept");
        a.persist(&kept).unwrap();
        let b_path = b.path().to_owned();
        drop(b);
        assert!(kept.exists() && !b_path.exists());
        let relative = TempFile::create_in(Path::new("."), ".delmesh-test-", ".tmp").unwrap();
        assert!(relative.path().is_relative() && relative.path().exists());
    }
}
