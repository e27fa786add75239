//! Atomic writes: each file staged under a temporary name in its target's
//! folder and renamed over the target only once complete ([`stage`],
//! [`write_atomic`]); devices and pipes written into, links followed, `.gz`
//! compressed, `--sync` flushing to the disk before the rename.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

use super::*;

/// Whether [`write_atomic`] flushes each file to the disk before renaming
/// it (`--sync`); off by default.
static SYNC_WRITES: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Makes [`write_atomic`] call `fsync` on each file before its rename (the
/// CLI's `--sync`). Without it a write is still atomic for every reader and
/// against delmesh being killed or crashing (the output is the old file or
/// the whole new one); with it that also holds across a power loss or an
/// operating system crash, at the cost of waiting for the disk (4.5 ms for
/// the armadillo's output here, 65 ms for the dragon's).
pub fn set_sync_writes(sync: bool) {
    SYNC_WRITES.store(sync, std::sync::atomic::Ordering::Relaxed);
}

/// Whether `path` names something that exists and is neither a regular
/// file nor a folder (following symbolic links): a device such as
/// `/dev/null`, a terminal or pipe such as `/dev/stdout`, a FIFO. Such a
/// target is written into, never replaced.
pub fn is_stream(path: &Path) -> bool {
    standard_stream(path).is_some() || std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Which standard stream an output `path` names, 1 (stdout: `-` or its
/// usual names) or 2 (stderr): written through the process's own
/// descriptor, so that `--stats-json /dev/stdout > log` appends to `log`
/// instead of opening the file again at its start (or replacing it).
pub fn standard_stream(path: &Path) -> Option<u8> {
    let name = path.to_str()?;
    match name {
        "-" | "/dev/stdout" | "/dev/fd/1" | "/proc/self/fd/1" => Some(1),
        "/dev/stderr" | "/dev/fd/2" | "/proc/self/fd/2" => Some(2),
        _ => None,
    }
}

/// Whether an input `path` names standard input: `-` or its usual names.
/// It is read through the process's own descriptor (to its end), never
/// opened again by name: `/dev/stdin` redirected from a file would
/// otherwise name that file, and a run without `-o` rewrite it in place.
pub fn is_standard_input(path: &Path) -> bool {
    matches!(
        path.to_str(),
        Some("-" | "/dev/stdin" | "/dev/fd/0" | "/proc/self/fd/0")
    )
}

/// A regular file, as the system knows it: its device and inode numbers,
/// the same whatever name (a hard or symbolic link, `/dev/fd/3`) or open
/// descriptor (standard input redirected from it) reaches it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FileId {
    device: u64,
    inode: u64,
}

impl FileId {
    /// The identity of what `metadata` describes, if a regular file.
    fn of(metadata: &std::fs::Metadata) -> Option<FileId> {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            metadata.is_file().then(|| FileId {
                device: metadata.dev(),
                inode: metadata.ino(),
            })
        }
        #[cfg(not(unix))]
        {
            let _ = metadata;
            None
        }
    }

    /// The regular file `path` names (symbolic links followed); `None` for
    /// a file that does not exist, a folder, a device or a pipe.
    pub fn of_path(path: &Path) -> Option<FileId> {
        FileId::of(&std::fs::metadata(path).ok()?)
    }

    /// The regular file open as standard input (0), output (1) or error
    /// (2), if one is (`< m.obj`, `>> log`).
    pub fn of_standard(fd: u8) -> Option<FileId> {
        #[cfg(unix)]
        {
            use std::os::fd::AsFd;
            let fd = match fd {
                0 => std::io::stdin().as_fd().try_clone_to_owned(),
                1 => std::io::stdout().as_fd().try_clone_to_owned(),
                _ => std::io::stderr().as_fd().try_clone_to_owned(),
            };
            FileId::of(&std::fs::File::from(fd.ok()?).metadata().ok()?)
        }
        #[cfg(not(unix))]
        {
            let _ = fd;
            None
        }
    }

    /// The regular file an input `path` reads: standard input's for `-`
    /// and its names ([`is_standard_input`]).
    pub fn of_input(path: &Path) -> Option<FileId> {
        if is_standard_input(path) {
            FileId::of_standard(0)
        } else {
            FileId::of_path(path)
        }
    }

    /// The regular file an output `path` writes, if it exists: standard
    /// output's or error's for their names ([`standard_stream`]).
    pub fn of_output(path: &Path) -> Option<FileId> {
        match standard_stream(path) {
            Some(fd) => FileId::of_standard(fd),
            None => FileId::of_path(path),
        }
    }
}

/// The file a write to `path` replaces, and the folder its temporary file
/// goes in: a symbolic link is followed (the file it points to is
/// replaced, or created if the link dangles; the link kept), anything else
/// is `path` itself. A link that leads nowhere (a loop of links: `Too many
/// levels of symbolic links`) is an error, never replaced by a file.
pub fn write_target(path: &Path) -> std::io::Result<(PathBuf, PathBuf)> {
    let is_link = |p: &Path| std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_symlink());
    let target = if is_link(path) {
        match std::fs::canonicalize(path) {
            Ok(target) => target,
            Err(e) => dangling_link_target(path).ok_or(e)?,
        }
    } else {
        path.to_owned()
    };
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
        _ => PathBuf::from("."),
    };
    Ok((target, dir))
}

/// Where the chain of symbolic links from `path` ends, when it ends at a
/// name that does not exist (a dangling link: writing through it creates
/// that file, as a shell's `>` does); `None` for a loop of links.
fn dangling_link_target(path: &Path) -> Option<PathBuf> {
    let mut p = path.to_owned();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&p).ok()?;
                p = match p.parent() {
                    Some(dir) if to.is_relative() => dir.join(to),
                    _ => to,
                };
            }
            Ok(_) => return None, // exists: `canonicalize` failed for another reason
            Err(_) => return Some(p),
        }
    }
    None
}

/// Writes what `fill` produces to `path` atomically: into a temporary file
/// in the same directory, renamed over `path` only when complete (flushed
/// to the disk first with [`set_sync_writes`]). On any error `path` is
/// untouched and the temporary file removed. A symbolic link is followed
/// and kept; a target that is not a regular file ([`is_stream`]: a device,
/// a pipe) is written into directly, there being no file to replace.
pub fn write_atomic(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    stage(path, fill)?.commit()
}

/// The first half of [`write_atomic`]: what `fill` produces, complete in a
/// temporary file beside `path` (or written into `path` if it is a stream,
/// which has no second half), to be renamed into place by
/// [`Staged::commit`] once whatever must come first has succeeded: a run
/// writes its side files, and checks its output, before it replaces its
/// input. The temporary file's name ends in `path`'s extension, so that a
/// reader takes it for the same format.
pub fn stage(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<Staged> {
    let err = |source| Error::Write {
        path: path.to_owned(),
        source,
    };
    let streamed = || Staged {
        path: path.to_owned(),
        file: None,
    };
    if let Some(fd) = standard_stream(path) {
        let mut w: Box<dyn Write> = if fd == 1 {
            Box::new(std::io::stdout().lock())
        } else {
            Box::new(std::io::stderr().lock())
        };
        fill_compressed_if_gz(path, &mut w, fill).map_err(err)?;
        w.flush().map_err(err)?;
        return Ok(streamed());
    }
    if is_stream(path) {
        let file = std::fs::OpenOptions::new().write(true).open(path).map_err(err)?;
        let mut w = BufWriter::with_capacity(1 << 16, file);
        fill_compressed_if_gz(path, &mut w, fill).map_err(err)?;
        w.flush().map_err(err)?;
        return Ok(streamed());
    }
    let (target, dir) = write_target(path).map_err(err)?;
    let path = target.as_path();
    let mut tmp =
        temporary::TempFile::create_in(&dir, ".delmesh-", &format!(".tmp{}", extensions(path))).map_err(err)?;
    // Removed by the signal handler if the run is interrupted; unregistered
    // when renamed into place, or removed (the `Staged` dropped).
    let registered = temporary::register(tmp.path());
    {
        // Small: the OBJ writer hands over blocks of about a megabyte, which
        // a buffer this size passes straight to the file instead of copying.
        let mut w = BufWriter::with_capacity(1 << 16, tmp.as_file_mut());
        fill_compressed_if_gz(path, &mut w, fill).map_err(err)?;
        w.flush().map_err(err)?;
    }
    if SYNC_WRITES.load(std::sync::atomic::Ordering::Relaxed) {
        tmp.as_file().sync_all().map_err(err)?;
    }
    // Keep the permissions of a file being replaced, and its owner and
    // group where allowed (a run as root rewriting a user's file in place
    // leaves it the user's); a new file gets 0644.
    let perms = match std::fs::metadata(path) {
        Ok(m) => {
            #[cfg(unix)]
            {
                use std::os::unix::fs::MetadataExt;
                // Refused (and harmless) unless root or a group change
                // to one of the caller's groups.
                let _ = std::os::unix::fs::fchown(tmp.as_file(), Some(m.uid()), Some(m.gid()));
            }
            Some(m.permissions())
        }
        Err(_) => new_file_permissions(),
    };
    if let Some(perms) = perms {
        tmp.as_file().set_permissions(perms).map_err(err)?;
    }
    Ok(Staged {
        path: target,
        file: Some((tmp, registered)),
    })
}

/// A file written by [`stage`], not yet in place; dropped uncommitted, its
/// temporary file is removed and the target left untouched.
#[must_use = "a staged file is removed unless committed"]
#[derive(Debug)]
pub struct Staged {
    /// The file the write is for (a symbolic link followed).
    path: PathBuf,
    /// The complete temporary file; `None` for a stream, written already.
    file: Option<(temporary::TempFile, temporary::Registration)>,
}

impl Staged {
    /// Where the complete bytes are now: the temporary file, or the stream.
    pub fn path(&self) -> &Path {
        self.file.as_ref().map_or(&self.path, |(tmp, _)| tmp.path())
    }

    /// Whether the bytes are where they were asked for already (a stream).
    pub fn is_in_place(&self) -> bool {
        self.file.is_none()
    }

    /// Renames the temporary file over the target (nothing for a stream).
    pub fn commit(self) -> Result<()> {
        self.commit_as(None)
    }

    /// Renames the temporary file to `other` instead of the target: where
    /// a run puts an output that failed its check.
    pub fn commit_to(self, other: &Path) -> Result<()> {
        self.commit_as(Some(other))
    }

    fn commit_as(self, other: Option<&Path>) -> Result<()> {
        let Some((tmp, _registered)) = self.file else {
            return Ok(());
        };
        let to = other.unwrap_or(&self.path);
        tmp.persist(to).map_err(|source| Error::Write {
            path: to.to_owned(),
            source,
        })?;
        Ok(())
    }
}

/// The extensions of `path`'s name that say its format (`.obj`,
/// `.ply.gz`), or nothing if it has none short enough.
fn extensions(path: &Path) -> String {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    match split_extensions(name) {
        (_, Some(ext)) if ext.len() <= 12 => format!(".{ext}"),
        _ => String::new(),
    }
}

/// A file name's stem and the extensions that say its format: `n.ply.gz`
/// gives `n` and `ply.gz`, `n.gz` gives `n` and `gz`, `n` and `.n` no
/// extension.
pub fn split_extensions(name: &str) -> (&str, Option<&str>) {
    let last = |n: &str| n.rfind('.').filter(|&i| i > 0);
    let Some(dot) = last(name) else {
        return (name, None);
    };
    let at = match last(&name[..dot]) {
        Some(inner) if name[dot + 1..].eq_ignore_ascii_case("gz") => inner,
        _ => dot,
    };
    (&name[..at], Some(&name[at + 1..]))
}

/// `fill(w)`, gzip-compressed if `path` ends in `.gz` (as the readers
/// accept it).
fn fill_compressed_if_gz(
    path: &Path,
    w: &mut dyn Write,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gz")) {
        return fill(w);
    }
    let mut gz = flate2::write::GzEncoder::new(w, flate2::Compression::default());
    fill(&mut gz)?;
    gz.finish()?;
    Ok(())
}

/// The permissions of a new output: 0644 on Unix (the temporary file was
/// made 0600); elsewhere the temporary file's own, a writable file's.
#[cfg(unix)]
fn new_file_permissions() -> Option<std::fs::Permissions> {
    use std::os::unix::fs::PermissionsExt;
    Some(std::fs::Permissions::from_mode(0o644))
}

/// See the Unix version.
#[cfg(not(unix))]
fn new_file_permissions() -> Option<std::fs::Permissions> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_leaves_target_alone_on_failure() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.obj");
        std::fs::write(&target, "old").unwrap();
        let r = write_atomic(&target, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "temporary file left behind"
        );
        write_atomic(&target, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
    }
}
