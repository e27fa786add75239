//! Text output on both cores: [`write_numbered_lines`] formats blocks of lines on
//! worker threads while the calling thread writes the finished ones in
//! order (the bytes are those of a sequential loop), and [`put_decimal`]
//! writes an index's digits without `fmt`; the vertex and face lines, and
//! the input's vertex lines formatted ahead while refining
//! ([`VertexLines`]). Shared by the OBJ and OFF writers.

use std::io::Write;

use super::Format;

/// "00", "01", .., "99": two digits per division.
const DIGIT_PAIRS: [u8; 200] = {
    let mut pairs = [0u8; 200];
    let mut i = 0;
    while i < 100 {
        pairs[2 * i] = b'0' + (i / 10) as u8;
        pairs[2 * i + 1] = b'0' + (i % 10) as u8;
        i += 1;
    }
    pairs
};

/// Writes the decimal digits of `v` into `buf` from `at`; returns how many.
/// Always inlined: the face writers' loops call it three times a line, and
/// the compiler stopped inlining it there once the loop was shared by OBJ
/// and OFF (2% more instructions for the armadillo's whole run).
#[inline(always)]
pub(crate) fn put_decimal(buf: &mut [u8], at: usize, mut v: u64) -> usize {
    let len = v.checked_ilog10().unwrap_or(0) as usize + 1;
    let mut i = at + len;
    while v >= 100 {
        let r = 2 * (v % 100) as usize;
        v /= 100;
        i -= 2;
        buf[i..i + 2].copy_from_slice(&DIGIT_PAIRS[r..r + 2]);
    }
    if v >= 10 {
        let r = 2 * v as usize;
        buf[i - 2..i].copy_from_slice(&DIGIT_PAIRS[r..r + 2]);
    } else {
        buf[i - 1] = b'0' + v as u8;
    }
    len
}

/// Appends the decimal digits of `v`.
pub(crate) fn push_decimal(line: &mut Vec<u8>, v: u64) {
    let mut digits = [0u8; 20];
    let len = put_decimal(&mut digits, 0, v);
    line.extend_from_slice(&digits[..len]);
}

/// Appends `lead` and the three indices of `t` plus `base`, each after a
/// blank (`f 1 2 3` for OBJ, from 1; `3 0 1 2` for OFF and PLY). The text
/// is built in a fixed-size array and appended with one fixed-size copy:
/// three variable-length copies per line, each a call into libc, cost more
/// than the digits (5% of the dragon's whole run). Always inlined: where
/// the OBJ writer formatted both kinds of lines in one loop the compiler
/// stopped inlining it, and the armadillo's OBJ took 9% more instructions.
#[inline(always)]
pub(crate) fn push_face(line: &mut Vec<u8>, lead: u8, t: &[u32; 3], base: u64) {
    // The lead, three times a blank and at most 11 digits (u32::MAX + 1).
    let mut buf = [0u8; 40];
    buf[0] = lead;
    let mut n = 1;
    for &v in t {
        buf[n] = b' ';
        n += 1 + put_decimal(&mut buf, n + 1, u64::from(v) + base);
    }
    let end = line.len() + n;
    line.extend_from_slice(&buf);
    line.truncate(end);
}

/// The most bytes handed to one `write`: a block of lines (about 1 MB) is
/// written in pieces of this size. ext4 takes a megabyte in one call
/// markedly slower than in sixteen (the forty-fifth session, on the AMD
/// EPYC host: the full dragon's write phase 0.13 -> 0.09 s, the system time
/// of a textured torus's run 0.27 -> 0.13 s); 16 and 64 KiB did best, and
/// 64 KiB is the output's `BufWriter` capacity, which passes a piece of
/// that size straight through.
pub(crate) const WRITE_PIECE: usize = 1 << 16;

/// Lines per block of [`write_numbered_lines`]: about 1 MB of text.
pub(crate) const BLOCK_LINES: usize = 1 << 14;

/// Below this many lines [`write_numbered_lines`] formats them all on the
/// calling thread: starting a worker costs more than it saves there (from
/// 4,096 lines, the bunny's 6,458 took 0.2 ms longer, the rotor's 15,903
/// no less, on a 2-core Xeon virtual machine).
const PARALLEL_LINES: usize = 1 << 15;

/// The fewest lines per block when a file is cut finer than [`BLOCK_LINES`].
const MIN_BLOCK_LINES: usize = 1024;

/// Lines per block for `n` lines on `threads` threads: [`BLOCK_LINES`], or
/// fewer for a file of less than a few blocks a thread, so that a mesh of
/// some thousands of vertices still has its lines formatted on every core.
fn block_lines(n: usize, threads: usize) -> usize {
    n.div_ceil(4 * threads).clamp(MIN_BLOCK_LINES, BLOCK_LINES)
}

/// Writes lines `0..n`, line `i` appended to a buffer by `line(i, ..)`. Formatting
/// (shortest round-trip floats, mostly) costs more than writing, so on
/// several cores the lines are cut into blocks of [`BLOCK_LINES`] (fewer
/// lines for a small file, [`block_lines`]; none under [`PARALLEL_LINES`]
/// lines in all), which
/// worker threads (started once) format in turn while the calling thread
/// writes the finished ones in order, formatting too whenever the next one
/// is not ready: the bytes are exactly those of a sequential loop. Workers
/// stay at most two blocks each ahead of the writer, so memory stays a
/// few blocks per thread.
///
/// ```text
///   blocks   0 1 2 3 4 5 6 ...
///            ^written  ^next to format (< written + window)
/// ```
pub(crate) fn write_numbered_lines(
    w: &mut dyn Write,
    n: usize,
    line: impl Fn(usize, &mut Vec<u8>) + Sync,
) -> std::io::Result<()> {
    write_line_ranges(w, n, |lines, buffer| {
        for i in lines {
            line(i, buffer);
        }
    })
}

/// Appends "x y z" in shortest round-trip form (the coordinates are finite).
#[inline]
pub(crate) fn push_xyz(line: &mut Vec<u8>, num: &mut zmij::Buffer, p: &[f64; 3]) {
    for (k, &c) in p.iter().enumerate() {
        if k > 0 {
            line.push(b' ');
        }
        line.extend_from_slice(num.format_finite(c).as_bytes());
    }
}

/// Appends the line `x y z` of `p`: an OFF vertex line, OBJ's after `v `.
#[inline]
pub(crate) fn xyz_line(p: &[f64; 3], line: &mut Vec<u8>) {
    push_xyz(line, &mut zmij::Buffer::new(), p);
    line.push(b'\n');
}

/// Appends the OBJ line `v x y z` of `p`.
#[inline]
pub(crate) fn obj_vertex_line(p: &[f64; 3], line: &mut Vec<u8>) {
    line.push(b'v');
    line.push(b' ');
    xyz_line(p, line);
}

/// The vertex lines of the first vertices of a mesh, formatted ahead of
/// time for an OBJ (`v x y z`) or OFF (`x y z`) file: the CLI formats the
/// input's vertices (which refining never moves) on a spare core while the
/// main thread refines. A writer of another format than the lines' formats
/// every line itself.
#[derive(Clone, Debug, Default)]
pub struct VertexLines {
    count: usize,
    text: Vec<u8>,
    /// [`Format::Obj`] or [`Format::Off`]; none for the default (no
    /// lines) or a binary format.
    format: Option<Format>,
}

impl VertexLines {
    /// The vertex lines of `positions`, exactly as the writer of `format`
    /// writes them ([`super::obj::write_obj`], [`super::formats::write_off`]);
    /// none for a binary format (PLY, STL), which has no lines.
    pub fn new(positions: &[[f64; 3]], format: Format) -> VertexLines {
        let line = match format {
            Format::Obj => obj_vertex_line,
            Format::Off => xyz_line,
            Format::Ply | Format::Stl => return VertexLines::default(),
        };
        let mut text = Vec::with_capacity(64 * positions.len());
        for p in positions {
            line(p, &mut text);
        }
        VertexLines {
            count: positions.len(),
            text,
            format: Some(format),
        }
    }

    /// The lines formatted, and how many, if they are `format`'s: else none
    /// (the writer formats them all).
    pub(crate) fn text_for(&self, format: Format) -> (usize, &[u8]) {
        match self.format == Some(format) {
            true => (self.count, &self.text),
            false => (0, &[]),
        }
    }
}

/// The lines of `vertices`, then those of `triangles`, in one run of lines
/// ([`write_line_ranges`]), so that both kinds are formatted at once on
/// several cores: `vertex_line` and `face_line` append one line each (OBJ's
/// or OFF's). Each kind's part of a block is a loop of its own
/// ([`each_line`]).
pub(crate) fn write_vertex_and_face_lines(
    w: &mut dyn Write,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    vertex_line: impl Fn(&[f64; 3], &mut Vec<u8>) + Sync + Copy,
    face_line: impl Fn(&[u32; 3], &mut Vec<u8>) + Sync + Copy,
) -> std::io::Result<()> {
    let nv = vertices.len();
    write_line_ranges(w, nv + triangles.len(), |lines, buffer| {
        each_line(&vertices[lines.start.min(nv)..lines.end.min(nv)], buffer, vertex_line);
        each_line(
            &triangles[lines.start.max(nv) - nv..lines.end.max(nv) - nv],
            buffer,
            face_line,
        );
    })
}

/// Appends `line(item, ..)` for each of `items`: one kind of line's loop,
/// kept out of line so that the line's formatting is inlined into it.
#[inline(never)]
fn each_line<T>(items: &[T], buffer: &mut Vec<u8>, line: impl Fn(&T, &mut Vec<u8>)) {
    for item in items {
        line(item, buffer);
    }
}

/// [`write_numbered_lines`], the lines of each block appended by one call
/// `lines(range, ..)`: a writer of two kinds of lines in one run loops over
/// each kind's part of the block on its own (a test per line which kind it
/// is cost the armadillo's OBJ 11% more instructions).
pub(crate) fn write_line_ranges(
    w: &mut dyn Write,
    n: usize,
    lines: impl Fn(std::ops::Range<usize>, &mut Vec<u8>) + Sync,
) -> std::io::Result<()> {
    use std::sync::{Condvar, Mutex, PoisonError};
    // (A small file needs no thread, nor asking how many there may be: that
    // reads cgroup files.)
    let (threads, block_lines) = if n < PARALLEL_LINES {
        (1, n.max(1))
    } else {
        let threads = crate::parallel::threads();
        (threads, block_lines(n, threads))
    };
    let n_blocks = n.div_ceil(block_lines);
    let threads = threads.min(n_blocks);
    let fill = |block: usize, buffer: &mut Vec<u8>| {
        let block = block * block_lines..((block + 1) * block_lines).min(n);
        buffer.clear();
        // About 64 bytes a line (three shortest round-trip coordinates):
        // growing by doubling would copy the block once or twice more.
        buffer.reserve(64 * block.len());
        lines(block, buffer);
    };
    if threads <= 1 {
        let mut buffer = Vec::new();
        for block in 0..n_blocks {
            fill(block, &mut buffer);
            write_in_pieces(w, &buffer)?;
        }
        return Ok(());
    }
    let window = 2 * threads;
    /// What the writer and the workers share.
    struct Shared {
        /// The next block nobody formats yet.
        next: usize,
        /// Blocks written so far.
        written: usize,
        /// Formatted blocks not yet written, block b at b % window.
        ready: Vec<Option<Vec<u8>>>,
        /// Buffers written out, for reuse.
        spare: Vec<Vec<u8>>,
        /// The writer is done (finished, or failed) or a thread panicked
        /// (the writer or a worker): everybody stops.
        stop: bool,
    }
    let shared = Mutex::new(Shared {
        next: 0,
        written: 0,
        ready: vec![None; window],
        spare: Vec::new(),
        stop: false,
    });
    let changed = Condvar::new();
    let lock = || shared.lock().unwrap_or_else(PoisonError::into_inner);
    let wait = |guard| changed.wait(guard).unwrap_or_else(PoisonError::into_inner);
    // Claims the next block if it is within the window: its number and a buffer.
    let claim = |s: &mut Shared| {
        (s.next < n_blocks && s.next < s.written + window).then(|| {
            s.next += 1;
            (s.next - 1, s.spare.pop().unwrap_or_default())
        })
    };
    let deliver = |block: usize, buffer: Vec<u8>| {
        lock().ready[block % window] = Some(buffer);
        changed.notify_all();
    };
    // A panic in `line` on any thread stops the others (which could be
    // waiting for it), and the scope then resumes it.
    struct StopOnPanic<'a>(&'a Mutex<Shared>, &'a Condvar);
    impl Drop for StopOnPanic<'_> {
        fn drop(&mut self) {
            if std::thread::panicking() {
                self.0.lock().unwrap_or_else(PoisonError::into_inner).stop = true;
                self.1.notify_all();
            }
        }
    }
    let worker = || {
        let _guard = StopOnPanic(&shared, &changed);
        loop {
            let mut s = lock();
            let (block, mut buffer) = loop {
                if s.stop || s.next >= n_blocks {
                    return;
                }
                match claim(&mut s) {
                    Some(job) => break job,
                    None => s = wait(s),
                }
            };
            drop(s);
            fill(block, &mut buffer);
            deliver(block, buffer);
        }
    };
    std::thread::scope(|scope| {
        for _ in 1..threads {
            // One that cannot start leaves its blocks to the others.
            let _ = crate::parallel::try_spawn(scope, worker);
        }
        let _guard = StopOnPanic(&shared, &changed);
        let result = (|| {
            let mut s = lock();
            while s.written < n_blocks && !s.stop {
                let slot = s.written % window;
                if let Some(buffer) = s.ready[slot].take() {
                    drop(s);
                    write_in_pieces(w, &buffer)?;
                    s = lock();
                    s.spare.push(buffer);
                    s.written += 1;
                    changed.notify_all();
                } else if let Some((block, mut buffer)) = claim(&mut s) {
                    drop(s);
                    fill(block, &mut buffer);
                    deliver(block, buffer);
                    s = lock();
                } else {
                    s = wait(s);
                }
            }
            Ok(())
        })();
        lock().stop = true;
        changed.notify_all();
        result
    })
}

/// Writes `bytes` to `w` [`WRITE_PIECE`] bytes at a time.
pub(crate) fn write_in_pieces(w: &mut dyn Write, bytes: &[u8]) -> std::io::Result<()> {
    for piece in bytes.chunks(WRITE_PIECE) {
        w.write_all(piece)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One line per item of `items`, appended by `line`.
    fn write_lines<T: Sync>(
        w: &mut dyn Write,
        items: &[T],
        line: impl Fn(&T, &mut Vec<u8>) + Sync,
    ) -> std::io::Result<()> {
        write_numbered_lines(w, items.len(), |i, buffer| line(&items[i], buffer))
    }

    /// A sink that takes `limit` bytes, then fails; optionally slowly, so
    /// that the formatting threads run a full window ahead of it.
    struct Sink {
        bytes: Vec<u8>,
        limit: usize,
        slow: bool,
    }

    impl Write for Sink {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            if self.slow {
                std::thread::sleep(std::time::Duration::from_millis(2));
            }
            if self.bytes.len() + buf.len() > self.limit {
                return Err(std::io::Error::other("disk full"));
            }
            self.bytes.extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn blocks_are_written_in_order_past_the_window_and_failures_stop_the_threads() {
        // More blocks than the formatting threads may run ahead (two each).
        let items: Vec<u32> = (0..13 * BLOCK_LINES as u32 + 77).collect();
        let line = |i: &u32, out: &mut Vec<u8>| push_decimal(out, u64::from(*i));
        let expected: Vec<u8> = {
            let mut out = Vec::new();
            items.iter().for_each(|i| line(i, &mut out));
            out
        };
        let _settings = crate::parallel::settings_lock_for_tests();
        for threads in [1, 2, 3] {
            crate::parallel::set_threads(threads);
            for slow in [false, true] {
                let mut sink = Sink {
                    bytes: Vec::new(),
                    limit: usize::MAX,
                    slow,
                };
                write_lines(&mut sink, &items, line).unwrap();
                assert!(sink.bytes == expected, "{threads} threads, slow {slow}");
                // A write that fails half way is the result, and returns.
                let mut sink = Sink {
                    bytes: Vec::new(),
                    limit: expected.len() / 2,
                    slow,
                };
                let error = write_lines(&mut sink, &items, line).unwrap_err();
                assert_eq!(error.to_string(), "disk full");
                assert!(expected.starts_with(&sink.bytes));
            }
            // A panic while formatting reaches the caller instead of leaving
            // the writer waiting for a block that never comes.
            let panicking = |i: &u32, out: &mut Vec<u8>| {
                assert!(*i != 5 * BLOCK_LINES as u32 + 3, "formatting failed");
                line(i, out)
            };
            let mut sink = Sink {
                bytes: Vec::new(),
                limit: usize::MAX,
                slow: false,
            };
            let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let _ = write_lines(&mut sink, &items, panicking);
            }));
            assert!(caught.is_err(), "{threads} threads");
        }
        crate::parallel::set_threads(0);
    }

    /// The OFF writer (all four extras) and the ASCII PLY writer give the
    /// same bytes whether their lines are formatted on threads or not, over
    /// several blocks, and read back to what was written.
    #[test]
    fn off_and_ascii_ply_lines_are_the_same_whether_or_not_threads_start() {
        use crate::io::formats::{self, ColorText, OffColors, OffExtras};
        let n = 2 * BLOCK_LINES + 9;
        let positions: Vec<[f64; 3]> = (0..n)
            .map(|i| [i as f64 * 0.1, (i % 7) as f64, -1e-7 * i as f64])
            .collect();
        let triangles: Vec<[u32; 3]> = (0..n as u32 - 2).map(|i| [i, i + 1, i + 2]).collect();
        let colors = |count: usize, text| OffColors {
            dim: 4,
            text,
            values: (0..4 * count).map(|k| (k % 256) as f64).collect(),
        };
        let extras = OffExtras {
            normals: Some((0..3 * n).map(|k| (k as f64).sin()).collect()),
            colors: Some(colors(n, ColorText::Bytes)),
            texcoords: Some((0..2 * n).map(|k| k as f64 / 3.0).collect()),
            face_colors: Some(colors(triangles.len(), ColorText::Floats)),
        };
        let bytes: Vec<[u8; 3]> = (0..n).map(|i| [i as u8, (i / 3) as u8, 7]).collect();
        let write = || {
            let (mut off, mut ply) = (Vec::new(), Vec::new());
            formats::write_off_with(&mut off, &positions, &triangles, &extras).unwrap();
            formats::write_ply_ascii(&mut ply, &positions, &triangles, Some(&bytes)).unwrap();
            (off, ply)
        };
        let (threaded, alone) = crate::parallel::threaded_and_alone(3, write);
        assert!(threaded == alone);
        let off = formats::read_off(&threaded.0).unwrap();
        assert_eq!(off.positions, positions);
        assert_eq!(off.face_start.len(), triangles.len() + 1);
        let ply = formats::read_ply(&threaded.1).unwrap();
        assert_eq!(ply.positions, positions);
        assert_eq!(ply.face_start.len(), triangles.len() + 1);
    }
}
