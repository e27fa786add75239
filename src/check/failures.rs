//! The failure lines of a report, grouped by kind (at most `MAX_LINES_PER_KIND` each).

use super::*;

pub(super) const KIND_INDEX: &str = "invalid index or coordinate";
pub(super) const KIND_DEGENERATE: &str = "degenerate face";
pub(super) const KIND_MANIFOLD: &str = "non-manifold or misoriented feature";
pub(super) const KIND_MISSING: &str = "missing input vertex";
pub(super) const KIND_VERTEX: &str = "misplaced output vertex";
pub(super) const KIND_FACE: &str = "face outside a planar region";
pub(super) const KIND_AREA: &str = "region area change";
pub(super) const KIND_TOPOLOGY: &str = "topology change";
pub(super) const KIND_BOUNDARY: &str = "boundary change";
/// An input that cannot be judged ([`check_meshes`] only: files give an error instead).
pub(super) const KIND_INVALID_INPUT: &str = "invalid input";
/// Output vertices apart in the file at one position (reported by `check_files_with`).
pub(super) const KIND_CRACK: &str = "crack";
/// Boundary edges facing an obtuse angle, failures with `check --gabriel-boundary` only.
pub(super) const KIND_NOT_GABRIEL: &str = "boundary edge facing an obtuse angle";
pub(super) const KIND_DELAUNAY: &str = "non-Delaunay edge";

/// Every kind of failure a check of files can report ([`CheckReport::failure_counts`]), in the
/// order of the rules; `invalid input` only from [`check_meshes`].
pub const FAILURE_KINDS: [&str; 13] = [
    KIND_INDEX,
    KIND_DEGENERATE,
    KIND_MANIFOLD,
    KIND_MISSING,
    KIND_VERTEX,
    KIND_FACE,
    KIND_AREA,
    KIND_TOPOLOGY,
    KIND_BOUNDARY,
    KIND_DELAUNAY,
    KIND_CRACK,
    KIND_NOT_GABRIEL,
    KIND_INVALID_INPUT,
];

/// Collects failure lines, keeping at most [`MAX_LINES_PER_KIND`] per kind.
#[derive(Default)]
pub(super) struct Failures {
    pub(super) lines: Vec<String>,
    /// Kinds in order of first appearance, with their total count.
    pub(super) counts: Vec<(&'static str, usize)>,
}

impl Failures {
    /// Records one failure; the line is only formatted when it will be kept.
    pub(super) fn push(&mut self, kind: &'static str, line: impl FnOnce() -> String) {
        let i = match self.counts.iter().position(|(k, _)| *k == kind) {
            Some(i) => i,
            None => {
                self.counts.push((kind, 0));
                self.counts.len() - 1
            }
        };
        self.counts[i].1 += 1;
        if self.counts[i].1 <= MAX_LINES_PER_KIND {
            self.lines.push(line());
        }
    }

    pub(super) fn is_empty(&self) -> bool {
        self.counts.is_empty()
    }

    /// Number of failures recorded so far (kept or not).
    pub(super) fn total(&self) -> usize {
        self.counts.iter().map(|(_, c)| c).sum()
    }

    /// The kept lines plus one `... and N more` line per overflowing kind.
    pub(super) fn finish(mut self) -> Vec<String> {
        for (kind, count) in &self.counts {
            if *count > MAX_LINES_PER_KIND {
                let more = count - MAX_LINES_PER_KIND;
                self.lines.push(format!("... and {more} more {kind} failures"));
            }
        }
        self.lines
    }

    /// The first `n` lines joined, for an error message.
    pub(super) fn summary(self, n: usize) -> String {
        let total = self.total();
        let lines = self.finish();
        let mut text = lines.iter().take(n).cloned().collect::<Vec<_>>().join("; ");
        if total > n {
            text.push_str(&format!(" (and {} more problems)", total - n));
        }
        text
    }
}
