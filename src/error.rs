//! The library's typed error: every way an input can be refused, each naming
//! the file and the offending line, face, edge or vertex (SPEC §6).

use std::path::PathBuf;

use crate::mesh::{InputFigures, NEAR_COINCIDENT};

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
    #[error("{count} non-Delaunay edge(s) can be neither split (no sample point left inside them) nor flipped (the flip would fold a face or duplicate an edge); worst: {}{}{}", worst_edge.as_ref().map_or_else(String::new, |e| format!("{e}, ")), worst_text(*.worst_excess, worst_edge.as_ref().is_some_and(|e| e.boundary)), near_coincident.after_semicolon())]
    Unsplittable {
        /// How many edges are left non-Delaunay.
        count: usize,
        /// The largest α+β−π among them, in radians.
        worst_excess: f64,
        /// Where the edge with that excess lies.
        worst_edge: Option<StuckEdge>,
        /// The input's near-coincident vertices, the likely cause if any.
        near_coincident: NearCoincident,
    },
    /// The run reached its work limit (`--max-added` splits, or three times
    /// as many flips): some settings (the first best sample instead of the
    /// median, on inputs with tiny angles) approach the theoretical bound of
    /// billions of vertices, or flip quadratically often.
    #[error("stopped after {splits} splits and {flips} flips (the work limit of --max-added {limit}): these settings need too much on this input; {}", work_limit_hint((*splits, *flips), *limit, *median_score_2, *shells, *longest_first, near_coincident, *nearly_flat_edges))]
    WorkLimit {
        /// Splits done.
        splits: usize,
        /// Flips done.
        flips: usize,
        /// The `--max-added` limit.
        limit: usize,
        /// Whether the run used the median rule with score 2 (the
        /// defaults), which usually needs the fewest splits.
        median_score_2: bool,
        /// Whether the run used concentric shells (`--shells`), which
        /// usually needs the fewest splits around fans and cone tips.
        shells: bool,
        /// Whether the run took the longest edge first when it stopped
        /// (`-ds pqueue`, or a stack or queue run past
        /// [`crate::refine::FLIPS_PER_EDGE_BEFORE_LONGEST_FIRST`]), which
        /// flips a flat region far from Delaunay the fewest times.
        longest_first: bool,
        /// The input's near-coincident vertices, the likely cause if any.
        near_coincident: NearCoincident,
        /// Input edges between faces coplanar to within rounding but not
        /// exactly ([`crate::Surface::nearly_flat_input_edges`]), another
        /// likely cause if any.
        nearly_flat_edges: usize,
    },
    /// The run needed more splits than the mesh's 32-bit ids can number
    /// ([`crate::mesh::MAX_HALFEDGES`] half-edges in all, the input's and six
    /// a split): only a mesh of hundreds of millions of faces, with
    /// `--max-added` raised past its default, gets there.
    #[error("stopped after {splits} splits: the refined mesh would have more than {} half-edges, more than 32-bit ids can number", crate::mesh::MAX_HALFEDGES)]
    OutOfIds {
        /// Splits done.
        splits: usize,
    },
    /// A setting given to the library is out of its range: a tolerance that
    /// is NaN, negative or infinite (the command line refuses the same
    /// values when it parses its flags).
    #[error("{name} {value} is not {expected}")]
    Setting {
        /// The setting, as messages name it (`weld tolerance`,
        /// `texture coordinates tolerance`, ...).
        name: &'static str,
        /// The value given.
        value: f64,
        /// What it must be.
        expected: &'static str,
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

/// The input's edges between near-coincident vertices
/// ([`InputFigures::near_coincident_edges`]), as an error reports them:
/// where marching cubes leaves such edges (crowds of vertices around a grid
/// point, joined by needles), refining stalls or adds a hundred times the
/// input's vertices, and welding them is the remedy.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NearCoincident {
    /// How many edges are shorter than [`NEAR_COINCIDENT`] times their
    /// part's size ([`InputFigures::near_coincident_edges`]), all shorter
    /// than [`NearCoincident::shorter_than`].
    pub edges: usize,
    /// [`NEAR_COINCIDENT`] times the size of the largest part holding one,
    /// rounded up to two significant digits: a `--weld-tolerance` that
    /// merges them.
    pub shorter_than: f64,
    /// The shortest edge that is not near-coincident: when it is shorter
    /// than [`NearCoincident::shorter_than`] (a small part beside a large
    /// one), that weld would merge it too, and is not suggested.
    pub others_from: f64,
}

impl NearCoincident {
    /// The near-coincident edges of an input with these figures.
    pub fn of(figures: &InputFigures) -> NearCoincident {
        NearCoincident {
            edges: figures.near_coincident_edges,
            shorter_than: round_up_two_digits(NEAR_COINCIDENT * figures.near_coincident_part),
            others_from: figures.shortest_other_edge,
        }
    }

    /// Whether welding at [`NearCoincident::shorter_than`] merges no edge
    /// but the near-coincident ones.
    pub fn weld_is_safe(&self) -> bool {
        self.others_from >= self.shorter_than || self.others_from.is_nan()
    }

    /// What to do about them: the weld, or why no single weld distance
    /// merges them alone.
    pub fn remedy(&self) -> String {
        if self.weld_is_safe() {
            format!("--repair --weld-tolerance {:.1e} merges them", self.shorter_than)
        } else {
            format!(
                "a --repair --weld-tolerance that merges them ({:.1e}) would merge edges of smaller parts too (from \
                 {:.1e})",
                self.shorter_than, self.others_from
            )
        }
    }

    /// What they are and what to do about them, for an error's line.
    pub fn hint(&self) -> String {
        format!(
            "the input has {} edge(s) shorter than {:.1e} (near-coincident vertices, as marching cubes leaves): {}",
            self.edges,
            self.shorter_than,
            self.remedy()
        )
    }

    /// `"; "` and [`NearCoincident::hint`], or nothing when there are none.
    fn after_semicolon(&self) -> String {
        if self.edges == 0 {
            String::new()
        } else {
            format!("; {}", self.hint())
        }
    }
}

/// An edge of the refined mesh, as the input knows it: for
/// [`Error::Unsplittable`], which names the worst edge it leaves.
#[derive(Clone, Debug, PartialEq)]
pub struct StuckEdge {
    /// Its two ends.
    pub ends: [EdgeEnd; 2],
    /// Its middle.
    pub middle: [f64; 3],
    /// Whether it is a boundary edge (then tested with `--gabriel-boundary`:
    /// it faces an obtuse angle).
    pub boundary: bool,
    /// Its ends in words, once [`StuckEdge::name_vertices`] named the input
    /// vertices as the file does; until then "input vertex i", i an index
    /// into the input's positions.
    named: Option<String>,
}

/// One end of a [`StuckEdge`]: an input vertex, or a point added on an input
/// edge (both as indices into the input's positions).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeEnd {
    /// The input vertex with this index.
    Vertex(u32),
    /// A point of the input edge between these two input vertices.
    OnEdge(u32, u32),
}

impl StuckEdge {
    /// The edge with these ends and middle.
    pub fn new(ends: [EdgeEnd; 2], middle: [f64; 3]) -> StuckEdge {
        StuckEdge {
            ends,
            middle,
            boundary: false,
            named: None,
        }
    }

    /// The same edge, on the boundary (with `--gabriel-boundary`).
    pub fn on_boundary(self, boundary: bool) -> StuckEdge {
        StuckEdge { boundary, ..self }
    }

    /// Names the input vertices with `name` (the index into the input's
    /// positions to the words a message uses, such as the file's own
    /// number), in place of "input vertex i".
    pub fn name_vertices(&mut self, name: impl Fn(u32) -> String) {
        self.named = Some(self.describe(name));
    }

    fn describe(&self, name: impl Fn(u32) -> String) -> String {
        let end = |e: EdgeEnd| match e {
            EdgeEnd::Vertex(v) => name(v),
            EdgeEnd::OnEdge(a, b) => format!("a point added between {} and {}", name(a), name(b)),
        };
        // Six significant digits are enough to find it.
        let middle = self.middle.map(|x| format!("{x:.5e}").parse().unwrap_or(x));
        let middle = crate::io::number::point_text(middle);
        match self.ends {
            // Both ends added on one input edge: a piece of that edge.
            [EdgeEnd::OnEdge(a, b), EdgeEnd::OnEdge(c, d)] if [a.min(b), a.max(b)] == [c.min(d), c.max(d)] => {
                format!(
                    "a piece of the edge from {} to {} between two points added on it (its middle at {middle})",
                    name(a),
                    name(b)
                )
            }
            [first, second] if self.boundary => format!(
                "the boundary edge from {} to {} (its middle at {middle}), which faces an obtuse angle (--gabriel-boundary)",
                end(first),
                end(second)
            ),
            [first, second] => format!(
                "the edge from {} to {} (its middle at {middle})",
                end(first),
                end(second)
            ),
        }
    }
}

impl std::fmt::Display for StuckEdge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.named {
            Some(text) => f.write_str(text),
            None => f.write_str(&self.describe(|v| format!("input vertex {v}"))),
        }
    }
}

/// `x` > 0 rounded up to two significant digits (as `{:.1e}` prints them).
fn round_up_two_digits(x: f64) -> f64 {
    if !(x > 0.0 && x.is_finite()) {
        return x;
    }
    let unit = 10f64.powi(x.log10().floor() as i32 - 1);
    let up = (x / unit).ceil() * unit;
    // `{:.1e}` of `up` is two digits; parse them back, exactly as printed.
    let printed: f64 = format!("{up:.1e}").parse().unwrap_or(up);
    if printed >= x {
        printed
    } else {
        format!("{:.1e}", printed + unit).parse().unwrap_or(up)
    }
}

/// What input edges between faces coplanar to within rounding mean, for a
/// message: `count` of them ([`crate::Surface::nearly_flat_input_edges`]).
pub fn nearly_flat_hint(count: usize) -> String {
    format!(
        "{count} input edge(s) join faces that are coplanar to within rounding but not exactly (a flat part \
         rotated or tilted in floating point?): delmesh keeps the geometry exactly, so no flip crosses them, and \
         flat regions cut up so can need very many vertices; vertices exactly in their planes (a flat part \
         aligned with the axes) avoid it"
    )
}

/// Result with the library's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

/// The worst excess of [`Error::Unsplittable`] in words: not positive only
/// when the angles underflowed (a needle a subnormal distance from its edge).
fn worst_text(excess: f64, boundary: bool) -> String {
    if excess > 0.0 && boundary {
        format!("gamma-pi/2 = {excess:.3e} rad")
    } else if excess > 0.0 {
        format!("alpha+beta-pi = {excess:.3e} rad")
    } else {
        "angles too thin for f64 to measure (coordinates differ by subnormal amounts)".into()
    }
}

/// Flips per split up to which a run that stopped on its flips near
/// near-coincident vertices is blamed on them in [`work_limit_hint`]
/// (refining makes about one flip per split; a flat region fanned from a
/// corner, hundreds).
const SPLIT_DRIVEN_FLIPS_PER_SPLIT: usize = 10;

/// What to try after [`Error::WorkLimit`]: a low limit can be raised; a run
/// stopped by its flips (few splits) is a large flat region far from
/// Delaunay, which the stack and queue flip quadratically often (a polygon
/// of n corners on an ellipse fanned from one corner: about n²/12 flips
/// with the stack, n longest edge first), unless it already took the
/// longest edge first (some regions, such as a fan along a parabola, are
/// quadratic in any order);
/// a run stopped by its splits needs other settings, unless it already used
/// the ones that usually split least, or the input has near-coincident
/// vertices, around which most settings split (and flip) without end: a
/// run near them that made a split per [`SPLIT_DRIVEN_FLIPS_PER_SPLIT`]
/// flips or more is theirs whichever budget ran out first. A hint never
/// suggests what the run already used.
fn work_limit_hint(
    (splits, flips): (usize, usize),
    limit: usize,
    median_score_2: bool,
    shells: bool,
    longest_first: bool,
    near_coincident: &NearCoincident,
    nearly_flat_edges: usize,
) -> String {
    // Near-coincident vertices, where known, are the cause to name.
    let nearly_flat = if nearly_flat_edges == 0 || near_coincident.edges > 0 {
        String::new()
    } else {
        format!("; {}", nearly_flat_hint(nearly_flat_edges))
    };
    // Stopped by its flips: a flat region, whose flips outnumber the splits
    // by hundreds, unless near-coincident vertices made splits and flips
    // a few to one.
    let many_splits = splits.saturating_mul(SPLIT_DRIVEN_FLIPS_PER_SPLIT) >= flips;
    let flat_region = splits < limit && !(near_coincident.edges > 0 && many_splits);
    let general = if limit < 1000 {
        "raise --max-added"
    } else if flat_region {
        if !longest_first {
            "a large flat region far from Delaunay (such as a polygon of thousands of corners fanned from one) takes \
             the stack and the queue quadratically many flips; --ds pqueue (longest edge first) usually takes far fewer"
        } else if !median_score_2 && !shells {
            // Longest first already: what is left to change is the sample rule.
            "the median rule (the default) with -s 2 usually needs far less"
        } else {
            "some flat regions far from Delaunay (such as a polygon fanned along a parabola) take quadratically many \
             flips in any order; raise --max-added if that much work is expected"
        }
    } else if near_coincident.edges > 0 {
        // The cause, and what to do about it, are known.
        return near_coincident.hint();
    } else if shells {
        "inputs with nearly degenerate triangles (see the smallest angle) need vertices at their own tiny scale; \
         raise --max-added if that many is expected (about 170 bytes of memory each)"
    } else if !median_score_2 {
        "the median rule (the default) with -s 2 usually needs far less"
    } else {
        "inputs with nearly degenerate triangles (see the smallest angle) need vertices at their own tiny scale; \
         --shells -s 4 (concentric shells) often needs far fewer around fans, cone tips and thin cells; raise \
         --max-added if that many is expected (about 170 bytes of memory each)"
    };
    format!("{general}{}{nearly_flat}", near_coincident.after_semicolon())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stuck_edges_are_named_by_their_ends() {
        let name = |v: u32| format!("vertex {}", v + 1);
        let mut piece = StuckEdge::new([EdgeEnd::OnEdge(3, 8), EdgeEnd::OnEdge(8, 3)], [0.5, 0.0, 1.0]);
        piece.name_vertices(name);
        assert_eq!(
            piece.to_string(),
            "a piece of the edge from vertex 4 to vertex 9 between two points added on it (its middle at (0.5, 0, 1))"
        );
        let mut across = StuckEdge::new([EdgeEnd::Vertex(4), EdgeEnd::OnEdge(0, 1)], [0.25, 0.5, 0.0]);
        across.name_vertices(name);
        assert_eq!(
            across.to_string(),
            "the edge from vertex 5 to a point added between vertex 1 and vertex 2 (its middle at (0.25, 0.5, 0))"
        );
        let two_edges = StuckEdge::new([EdgeEnd::OnEdge(0, 1), EdgeEnd::OnEdge(1, 2)], [1.0, 2.0, 3.0]);
        assert_eq!(
            two_edges.to_string(),
            "the edge from a point added between input vertex 0 and input vertex 1 to a point added between \
             input vertex 1 and input vertex 2 (its middle at (1, 2, 3))"
        );
    }

    #[test]
    fn weld_suggestions_are_rounded_up_to_two_digits() {
        for (x, up) in [
            (2.4487e-9, 2.5e-9),
            (2.5e-9, 2.5e-9),
            (1e-9, 1e-9),
            (9.96e-9, 1e-8),
            (3.4641e-12, 3.5e-12),
        ] {
            let got = round_up_two_digits(x);
            assert_eq!(got, up, "{x}");
            assert!(got >= x);
            assert_eq!(format!("{got:.1e}").parse::<f64>().unwrap(), got);
        }
    }

    #[test]
    fn a_flip_bound_stop_never_suggests_the_order_it_used() {
        let stop = |longest_first, median_score_2| {
            Error::WorkLimit {
                splits: 194_557,
                flips: 30_000_000,
                limit: 10_000_000,
                median_score_2,
                shells: false,
                longest_first,
                near_coincident: NearCoincident::default(),
                nearly_flat_edges: 0,
            }
            .to_string()
        };
        for median_score_2 in [false, true] {
            assert!(stop(false, median_score_2).contains("--ds pqueue (longest edge first)"));
        }
        let pqueue = stop(true, false);
        assert!(
            !pqueue.contains("pqueue")
                && pqueue.ends_with("the median rule (the default) with -s 2 usually needs far less"),
            "{pqueue}"
        );
        let defaults = stop(true, true);
        assert!(
            !defaults.contains("pqueue")
                && !defaults.contains("-s 2")
                && defaults.contains("quadratically many flips in any order; raise --max-added"),
            "{defaults}"
        );
    }

    #[test]
    fn a_flip_bound_stop_among_near_coincident_vertices_names_the_weld() {
        let stop = |splits| {
            Error::WorkLimit {
                splits,
                flips: 30_000_000,
                limit: 10_000_000,
                median_score_2: true,
                shells: false,
                longest_first: false,
                near_coincident: NearCoincident {
                    edges: 470,
                    shorter_than: 2.5e-7,
                    others_from: f64::NAN,
                },
                nearly_flat_edges: 0,
            }
            .to_string()
        };
        // Millions of splits beside the flips (a marching-cubes torus with
        // --repair): the near-coincident vertices alone.
        let weld = stop(6_647_283);
        assert!(
            weld.ends_with(
                "too much on this input; the input has 470 edge(s) shorter than 2.5e-7 (near-coincident vertices, \
                 as marching cubes leaves): --repair --weld-tolerance 2.5e-7 merges them"
            ),
            "{weld}"
        );
        // Flips by the hundred a split: a flat region first, the weld after.
        let flat = stop(194_557);
        assert!(
            flat.contains("--ds pqueue (longest edge first) usually takes far fewer; the input has 470 edge(s)"),
            "{flat}"
        );
    }

    #[test]
    fn a_split_bound_stop_says_what_the_settings_cannot_fix() {
        let stop = |median_score_2, edges| {
            Error::WorkLimit {
                splits: 10_000,
                flips: 5,
                limit: 10_000,
                median_score_2,
                shells: false,
                longest_first: false,
                near_coincident: NearCoincident {
                    edges,
                    shorter_than: 2.5e-9,
                    others_from: 1e-3,
                },
                nearly_flat_edges: 0,
            }
            .to_string()
        };
        // Other settings than the defaults: the defaults.
        assert!(stop(false, 0).ends_with("the median rule (the default) with -s 2 usually needs far less"));
        // The defaults already: not themselves again, but shells.
        let defaults = stop(true, 0);
        assert!(
            !defaults.contains("-s 2") && defaults.contains("raise --max-added") && defaults.contains("--shells -s 4"),
            "{defaults}"
        );
        // Shells already: neither the defaults nor shells again.
        let shells = Error::WorkLimit {
            splits: 10_000,
            flips: 5,
            limit: 10_000,
            median_score_2: false,
            shells: true,
            longest_first: false,
            near_coincident: NearCoincident::default(),
            nearly_flat_edges: 0,
        }
        .to_string();
        assert!(
            !shells.contains("-s 2") && !shells.contains("--shells") && shells.contains("raise --max-added"),
            "{shells}"
        );
        // Near-coincident vertices: the weld, whatever the settings.
        for median_score_2 in [false, true] {
            let weld = stop(median_score_2, 7);
            assert!(
                weld.ends_with(
                    "the input has 7 edge(s) shorter than 2.5e-9 (near-coincident vertices, as marching \
                     cubes leaves): --repair --weld-tolerance 2.5e-9 merges them"
                ),
                "{weld}"
            );
            assert!(!weld.contains("-s 2"), "{weld}");
        }
    }
}
