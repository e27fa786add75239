//! The library's typed error: every way an input can be refused, each naming
//! the file and the offending line, face, edge or vertex (SPEC §6).

use std::path::PathBuf;

/// Why delmesh refused an input or could not finish.
///
/// `Display` gives the one-line message the command line prints.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The file could not be opened or read.
    #[error("{path}: cannot read: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The file is not a (text) OBJ file, or a line of it is malformed.
    #[error("{path}:{line}: {what}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong with the line.
        what: String,
    },
    /// The mesh is well-formed OBJ but not an input the algorithm accepts
    /// (no faces, degenerate or non-manifold, inconsistently oriented).
    #[error("{path}: {what}")]
    Mesh {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the line, face, edge or vertex.
        what: String,
    },
    /// Some non-Delaunay edge can be neither split (no sample left strictly
    /// inside it) nor flipped (the flip would fold a face or duplicate an
    /// edge), so the algorithm cannot make it Delaunay.
    #[error("{count} non-Delaunay edge(s) can be neither split (no sample point left inside them) nor flipped (the flip would fold a face or duplicate an edge); worst: {}", worst_text(*.worst_excess))]
    Unsplittable {
        /// How many edges are left non-Delaunay.
        count: usize,
        /// The largest α+β−π among them, in radians.
        worst_excess: f64,
    },
    /// The run reached its work limit (`--max-added` splits, or three times
    /// as many flips): some settings (the first best sample instead of the
    /// median, on inputs with tiny angles) approach the theoretical bound of
    /// billions of vertices, or flip quadratically often.
    #[error("stopped after {splits} splits and {flips} flips (the work limit of --max-added {limit}): these settings need too much on this input; {}", work_limit_hint(*splits, *limit))]
    WorkLimit {
        /// Splits done.
        splits: usize,
        /// Flips done.
        flips: usize,
        /// The `--max-added` limit.
        limit: usize,
    },
    /// An output file could not be written.
    #[error("{path}: cannot write: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
}

/// Result with the library's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

/// The worst excess of [`Error::Unsplittable`] in words: not positive only
/// when the angles underflowed (a needle a subnormal distance from its edge).
fn worst_text(excess: f64) -> String {
    if excess > 0.0 {
        format!("alpha+beta-pi = {excess:.3e} rad")
    } else {
        "angles too thin for f64 to measure (coordinates differ by subnormal amounts)".into()
    }
}

/// What to try after [`Error::WorkLimit`]: a low limit can be raised; a run
/// stopped by its flips (few splits) is a large flat region far from
/// Delaunay, which the stack and queue flip quadratically often (a polygon
/// of n corners fanned from one corner: about n²/12 flips with the stack,
/// n longest edge first); otherwise the settings add too many vertices.
fn work_limit_hint(splits: usize, limit: usize) -> &'static str {
    if limit < 1000 {
        "raise --max-added"
    } else if splits < limit {
        "a large flat region far from Delaunay (such as a polygon of thousands of corners fanned from one) takes the \
         stack and the queue quadratically many flips; --ds pqueue (longest edge first) usually takes far fewer"
    } else {
        "the median rule (the default) with -s 2 usually needs far less"
    }
}
