//! Algorithm 2 of Liu et al. 2015 with the DelMesh heuristics (SPEC §4):
//! flip flippable non-Delaunay edges, split the others at a chosen sample,
//! until every interior edge is Delaunay.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

use glam::{DVec2, DVec3};

use crate::error::{Error, NearCoincident, Result};
use crate::geometry::{self, DelaunayTest, EdgeFrame, ACCEPT_TOLERANCE, ALGORITHM_TOLERANCE, SEED_TOLERANCE};
use crate::hash::{position_key, FastMap};
use crate::mesh::{room_for_splits, EdgeId, HalfEdgeId, Surface, VertexId, NO_INPUT_EDGE};
use crate::samples::{self, Condition, EdgeSamples, SampleConstants, Score, Side, SplitQuery};

// The first pass of [`make_delaunay`] relies on it.
const _: () = assert!(ACCEPT_TOLERANCE > ALGORITHM_TOLERANCE);

/// The order in which non-Delaunay edges are taken (`-ds`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Worklist {
    /// Last in, first out.
    Stack,
    /// First in, first out.
    Queue,
    /// Longest edge first (3D length when pushed; ties: lower edge id).
    PriorityQueue,
}

/// The settings of one run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Options {
    /// The data structure DS.
    pub worklist: Worklist,
    /// The score of a sample.
    pub score: Score,
    /// Median of the best samples (`true`) or the first from the edge's start.
    pub median: bool,
    /// Among the best samples, the one nearest the concentric-shell point
    /// ([`samples::shell_target`]) instead: `median` is then ignored.
    pub shells: bool,
    /// Stop with [`Error::WorkLimit`] when a run needs more than this many
    /// added vertices (or more than [`FLIPS_PER_ADDED`] times as many
    /// flips): a run that needs exactly this many finishes.
    pub max_added: usize,
    /// Take edges in the `worklist` order to the end. If `false` (the
    /// default), a stack or queue run that has flipped more than
    /// [`FLIPS_PER_EDGE_BEFORE_LONGEST_FIRST`] times per edge of the mesh
    /// takes the rest longest edge first ([`Stats::longest_first_after`]),
    /// and [`make_delaunay`] first makes large flat regions Delaunay
    /// directly ([`crate::flat_regions`]). If `true`, every flip is
    /// Algorithm 2's, as in the report's tool.
    pub keep_order: bool,
    /// Called every [`PROGRESS_INTERVAL`] edges taken from DS; `None` costs
    /// nothing. It does not change the result: any two hooks compare equal.
    pub progress: Option<ProgressHook>,
}

/// How many edges are taken from DS between two calls of [`Options::progress`].
pub const PROGRESS_INTERVAL: u64 = 1 << 16;

/// A progress callback: given the figures so far and the number of edges
/// waiting in DS. `'static` so that [`Options`] stays `Copy`: pass a `fn`
/// item (`ProgressHook(&my_fn)`) or a leaked closure.
#[derive(Clone, Copy)]
pub struct ProgressHook(pub &'static (dyn Fn(&Stats, usize) + Sync));

impl std::fmt::Debug for ProgressHook {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ProgressHook")
    }
}

impl PartialEq for ProgressHook {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Eq for ProgressHook {}

impl std::hash::Hash for ProgressHook {
    fn hash<H: std::hash::Hasher>(&self, _: &mut H) {}
}

/// The default of [`Options::max_added`]: about 1.5 GB of mesh.
pub const DEFAULT_MAX_ADDED: usize = 10_000_000;

/// A run may flip at most this many times [`Options::max_added`]: settings
/// that split next to a vertex every time make flips grow quadratically
/// while the mesh stays small.
pub const FLIPS_PER_ADDED: usize = 3;

/// A stack or queue run that has flipped more than this many times per edge
/// of the mesh (counted as it grows) takes the rest of its edges longest
/// first, unless [`Options::keep_order`].
///
/// Flips alone cannot make the stack and the queue stop, but they can make
/// them slow: a flat polygon of n corners on an ellipse, fanned from one of
/// them (an oval cap of a CAD part), takes the stack about n²/12 flips (an
/// oval cylinder of 10,000 segments with two such caps: 16.7 million),
/// where longest edge first takes about n. Runs of the median
/// rule on the shipped meshes flip at most 0.4 times per edge (the most,
/// 2.9, is the queue with score 0 and no median, on the armadillo), so the
/// switch leaves them as they are; after it, the stack's flips on an oval
/// fanned from an end of its long axis grow linearly (not every flat
/// region's: the queue's grow faster there, and an oval fanned from another
/// corner, or a parabola fanned from one end, is quadratic in every order
/// tried, longest edge first included).
pub const FLIPS_PER_EDGE_BEFORE_LONGEST_FIRST: usize = 8;

impl Options {
    /// The given data structure, score and median rule, with the default
    /// vertex limit.
    pub fn new(worklist: Worklist, score: Score, median: bool) -> Self {
        Options {
            worklist,
            score,
            median,
            shells: false,
            max_added: DEFAULT_MAX_ADDED,
            keep_order: false,
            progress: None,
        }
    }
}

impl Default for Options {
    /// The report's best overall: stack, score 2, median.
    fn default() -> Self {
        Options::new(Worklist::Stack, Score::AlwaysCenter, true)
    }
}

/// What a run did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// The sample constants used.
    pub constants: Option<SampleConstants>,
    /// Edge splits (= added vertices).
    pub splits: usize,
    /// Edge flips.
    pub flips: usize,
    /// Interior edges with α + β > π + 1e-9 in the input.
    pub non_delaunay_before: usize,
    /// Interior edges with α + β > π + 1e-9 at the end (0 on success).
    pub non_delaunay_after: usize,
    /// Rounds of Algorithm 2: 1, plus one each time edges found stuck were
    /// taken again because their surroundings had changed.
    pub passes: usize,
    /// The flips after which a stack or queue run took the rest of its
    /// edges longest first (see [`FLIPS_PER_EDGE_BEFORE_LONGEST_FIRST`]);
    /// `None` if it kept its order.
    pub longest_first_after: Option<usize>,
}

/// The data structure DS: each edge at most once at a time.
struct Ds {
    kind: Worklist,
    list: VecDeque<EdgeId>,
    heap: BinaryHeap<(u64, Reverse<u32>)>,
    /// Per edge: whether it is queued, and if so what its last Delaunay test
    /// said, made when it was queued or its quad last changed (`None`: to
    /// be tested when taken). One byte per edge.
    slots: Vec<Slot>,
}

/// An edge's place in [`Ds`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    /// Not queued.
    Free,
    /// Queued, with the test of its quad as it is now, if known.
    Queued(Option<DelaunayTest>),
}

impl Ds {
    fn new(kind: Worklist, n_edges: usize) -> Self {
        Ds {
            kind,
            list: VecDeque::new(),
            heap: BinaryHeap::new(),
            slots: vec![Slot::Free; n_edges],
        }
    }

    /// Queues `e` unless it is queued already, and records `test`, the
    /// test of its quad as it is now (`None` if not made); `length` (its 3D
    /// length) is called only by the priority queue.
    fn push(&mut self, e: EdgeId, test: Option<DelaunayTest>, length: impl FnOnce() -> f64) {
        if e.idx() >= self.slots.len() {
            self.slots.resize(e.idx() + 1, Slot::Free);
        }
        if std::mem::replace(&mut self.slots[e.idx()], Slot::Queued(test)) != Slot::Free {
            return;
        }
        match self.kind {
            Worklist::Stack | Worklist::Queue => self.list.push_back(e),
            // Lengths are non-negative, so their bit patterns sort like them.
            Worklist::PriorityQueue => self.heap.push((length().to_bits(), Reverse(e.0))),
        }
    }

    /// Records `test` (as [`Ds::push`]) for `e` if it is queued.
    #[inline]
    fn retested(&mut self, e: EdgeId, test: Option<DelaunayTest>) {
        if let Some(slot @ Slot::Queued(_)) = self.slots.get_mut(e.idx()) {
            *slot = Slot::Queued(test);
        }
    }

    /// The next edge, with the last test of its quad if known.
    fn pop(&mut self) -> Option<(EdgeId, Option<DelaunayTest>)> {
        let e = match self.kind {
            Worklist::Stack => self.list.pop_back(),
            Worklist::Queue => self.list.pop_front(),
            Worklist::PriorityQueue => self.heap.pop().map(|(_, Reverse(e))| EdgeId(e)),
        }?;
        match std::mem::replace(&mut self.slots[e.idx()], Slot::Free) {
            Slot::Queued(test) => Some((e, test)),
            Slot::Free => Some((e, None)), // (cannot happen: a queued edge has its slot)
        }
    }

    fn len(&self) -> usize {
        self.list.len() + self.heap.len()
    }

    /// Takes the queued edges, and every edge pushed from now on, longest
    /// first (`length`: an edge's 3D length).
    fn switch_to_longest_first(&mut self, length: impl Fn(EdgeId) -> f64) {
        self.kind = Worklist::PriorityQueue;
        self.heap = (self.list.drain(..))
            .map(|e| (length(e).to_bits(), Reverse(e.0)))
            .collect();
    }
}

/// The sample constants of a mesh, from its input's smallest angle and
/// shortest edge.
pub fn sample_constants(surface: &Surface) -> SampleConstants {
    let f = surface.input_figures;
    SampleConstants::with_sine(f.min_angle, f.min_angle_sin, f.min_edge)
}

/// The six conditions of splitting the interior edge `e` = (a, b), taken from
/// its first half-edge, at a point p at distance x from a: the halves (a, p),
/// (p, b) and the outer edges (a, c), (c, b), (b, d), (d, a) stay Delaunay.
/// `beyond` are the apexes of the triangles across the outer edges, in that
/// order (`None` on the boundary).
pub fn split_conditions([a, b, c, d]: [DVec3; 4], beyond: [Option<DVec3>; 4]) -> ([Condition; 2], [Condition; 4]) {
    let frame = EdgeFrame::new(a, b);
    let len = frame.length;
    let (c2, d2) = (frame.unfold(c, true), frame.unfold(d, false));
    let halves = [
        Condition {
            side: Side::AtMost,
            breakpoint: geometry::second_axis_crossing(0.0, c2, d2),
        },
        Condition {
            side: Side::AtLeast,
            breakpoint: geometry::second_axis_crossing(len, c2, d2),
        },
    ];
    // Outer edge (anchor, other): anchor a or b, other c or d, x the apex
    // beyond it. Split at p, the edge stays Delaunay while the angles facing
    // it at p and at x sum to at most π: up to where the circle through
    // anchor, other and x meets the line ab again (inscribed angles). By the
    // law of sines in the triangle (anchor, p, other), that point is at
    // oₓ − o_y·cot X from the anchor, along ab towards the other end of e,
    // where (oₓ, o_y), o_y ≥ 0, is `other` in the quad's plane, measured
    // in that direction and away from ab, and X is the angle at x. No
    // unfolding of the face beyond: one cross product, one division.
    //
    //             other
    //            /  |  `.
    //           /   |o_y `. x      X: the angle at x facing (anchor, other)
    //          /    |      |
    //   anchor *----+------p------ line ab
    //          |-oₓ-|
    let k = 1.0 / len; // (scale-free: keeps products of tiny or huge coordinates in range)
    let cot_at = |x: DVec3, anchor: DVec3, other: DVec3| {
        let (u, v) = ((anchor - x) * k, (other - x) * k);
        u.dot(v) / u.cross(v).length()
    };
    let outer = |side, from_a: bool, anchor: DVec3, (other3, other2): (DVec3, DVec2), beyond: Option<DVec3>| {
        let breakpoint = beyond.map_or(f64::NAN, |x| {
            let reach = other2.y.abs() * cot_at(x, anchor, other3);
            if from_a {
                other2.x - reach
            } else {
                other2.x + reach
            }
        });
        Condition { side, breakpoint }
    };
    let outer = [
        outer(Side::AtLeast, true, a, (c, c2), beyond[0]),
        outer(Side::AtMost, false, b, (c, c2), beyond[1]),
        outer(Side::AtMost, false, b, (d, d2), beyond[2]),
        outer(Side::AtLeast, true, a, (d, d2), beyond[3]),
    ];
    (halves, outer)
}

/// Runs Algorithm 2 on `surface` until every interior edge is Delaunay
/// (within [`ALGORITHM_TOLERANCE`]; an input edge within
/// [`SEED_TOLERANCE`] whose quad nothing changes is left as it is).
///
/// Unless [`Options::keep_order`], large flat regions are first made
/// Delaunay directly ([`crate::flat_regions::make_flat_regions_delaunay`]:
/// convex ones flipped, counted in [`Stats::flips`]; others rebuilt).
///
/// Fails with [`Error::Unsplittable`] if some non-Delaunay sub-edge has no
/// sample left inside it; it never loops.
pub fn make_delaunay(surface: &mut Surface, options: &Options) -> Result<Stats> {
    let flat = match options.keep_order {
        true => Default::default(),
        false => crate::flat_regions::make_flat_regions_delaunay(surface),
    };
    let first_pass = non_delaunay_edges(surface);
    let mut stats = make_delaunay_from(surface, options, &first_pass)?;
    stats.flips += flat.flips();
    stats.non_delaunay_before = flat.non_delaunay_before(stats.non_delaunay_before);
    Ok(stats)
}

/// [`make_delaunay`], given the result of its first pass,
/// [`non_delaunay_edges`]`(surface)`: several runs on copies of one mesh (and
/// [`Surface::added_vertex_lower_bound_among`]) can share it. It makes no
/// flat region Delaunay directly itself: call
/// [`crate::flat_regions::make_flat_regions_delaunay`] before the first
/// pass, as [`make_delaunay`] does.
pub fn make_delaunay_from(surface: &mut Surface, options: &Options, first_pass: &[EdgeId]) -> Result<Stats> {
    let constants = sample_constants(surface);
    let split_limit = options.max_added.min(surface.topo.split_room());
    let mut run = Run {
        s: surface,
        options: *options,
        constants,
        stats: Stats::default(),
        stuck: FastMap::default(),
        occupied: None,
        over_limit: false,
        split_limit,
    };
    run.stats.constants = Some(constants);
    // Room for about one split per edge (at least 16,384), as a freshly
    // built mesh already has (`room_for_splits`: then this copies nothing):
    // untouched capacity costs no memory, and typical runs then never copy
    // their arrays.
    run.s
        .reserve_splits(room_for_splits(run.s.topo.n_faces()).min(options.max_added));
    let mut ds = Ds::new(options.worklist, run.s.topo.n_edges());
    // First pass: count the input's non-Delaunay edges and fill DS.
    for &e in first_pass {
        // The test every other count makes (`Surface::count_non_delaunay_among`): an edge
        // whose angles underflow counts too (sin(α + β − π) = 0 where both angles are nearly
        // π, which `geometry::exceeds` alone reads as Delaunay).
        run.stats.non_delaunay_before += run.s.is_non_delaunay(e, ACCEPT_TOLERANCE) as usize;
        ds.push(e, None, || run.s.edge_length(e));
    }
    // Debug builds (every test): the input's edges left alone by the first
    // pass though over ALGORITHM_TOLERANCE, with their quads, for the check
    // after the loop.
    #[cfg(debug_assertions)]
    let left_alone: Vec<(EdgeId, [VertexId; 4])> = (0..run.s.topo.n_edges() as u32)
        .map(EdgeId)
        .filter(|&e| run.s.is_non_delaunay(e, ALGORITHM_TOLERANCE) && first_pass.binary_search(&e).is_err())
        .map(|e| (e, run.quad(e)))
        .collect();
    let mut taken: u64 = 0;
    loop {
        run.stats.passes += 1;
        while let Some((e, test)) = ds.pop() {
            run.process(e, test, &mut ds);
            taken += 1;
            if run.stats.flips > FLIPS_PER_EDGE_BEFORE_LONGEST_FIRST * run.s.topo.n_edges()
                && ds.kind != Worklist::PriorityQueue
                && !options.keep_order
            {
                run.stats.longest_first_after = Some(run.stats.flips);
                ds.switch_to_longest_first(|e| run.s.edge_length(e));
            }
            if taken % PROGRESS_INTERVAL == 0 {
                if let Some(ProgressHook(hook)) = options.progress {
                    hook(&run.stats, ds.len());
                }
            }
            if run.over_limit {
                let (splits, flips) = (run.stats.splits, run.stats.flips);
                if splits >= run.split_limit && run.split_limit < options.max_added {
                    return Err(Error::OutOfIds { splits });
                }
                return Err(Error::WorkLimit {
                    splits,
                    flips,
                    limit: options.max_added,
                    median_score_2: options.median && options.score == Score::AlwaysCenter,
                    shells: options.shells,
                    longest_first: ds.kind == Worklist::PriorityQueue,
                    near_coincident: NearCoincident::of(&run.s.input_figures),
                    nearly_flat_edges: run.s.nearly_flat_input_edges(),
                });
            }
        }
        // DS is empty. An edge's Delaunay status depends on its quad alone,
        // and every flip and split queues each edge whose quad it changes
        // (`process`), so the only non-Delaunay edges left are stuck ones.
        // Those whose neighbourhood changed since (only an apex beyond their
        // quad moved, or they would have been queued) may have become
        // splittable: take them again.
        let mut again: Vec<EdgeId> = run.stuck.keys().copied().filter(|&e| !run.is_stuck(e)).collect();
        // (The map's order is not the run's to decide.)
        again.sort_unstable();
        // Those now Delaunay are stuck no more: dropped from the map, which
        // changes no decision (a change to one's quad queues it, as for any
        // edge) but keeps this scan short. Kept, they piled up where each
        // pass ends after a split or two (a stuck edge beside a crowd of
        // near-coincident vertices), and the scans grew quadratic: 20,000
        // splits once took 6 s.
        again.retain(|&e| {
            let bad = run.s.is_non_delaunay(e, ALGORITHM_TOLERANCE);
            if !bad {
                run.stuck.remove(&e);
            }
            bad
        });
        // Debug builds (every test): the map holds non-Delaunay edges only
        // (one unchanged since it was found stuck has the quad it had then).
        #[cfg(debug_assertions)]
        for &e in run.stuck.keys() {
            assert!(
                run.s.is_non_delaunay(e, ALGORITHM_TOLERANCE),
                "a stuck edge, now Delaunay, left in the map"
            );
        }
        if again.is_empty() {
            break;
        }
        for e in again {
            ds.push(e, None, || run.s.edge_length(e));
        }
    }
    // The claim above, checked by a full pass in debug builds (every test):
    // an edge over ALGORITHM_TOLERANCE is stuck, or one the first pass left
    // alone (within SEED_TOLERANCE) with its quad as it was.
    #[cfg(debug_assertions)]
    for e in (0..run.s.topo.n_edges() as u32).map(EdgeId) {
        if !run.s.topo.is_dead_edge(e) && run.s.is_non_delaunay(e, ALGORITHM_TOLERANCE) && !run.is_stuck(e) {
            let alone = left_alone.binary_search_by_key(&e, |&(x, _)| x);
            assert!(
                alone.is_ok_and(|i| left_alone[i].1 == run.quad(e)),
                "a non-Delaunay edge was neither queued nor stuck"
            );
        }
    }
    // Every edge is now within ALGORITHM_TOLERANCE except stuck ones, which
    // may still be within the acceptance tolerance: they alone are counted.
    if !run.stuck.is_empty() {
        let mut stuck: Vec<EdgeId> = run.stuck.keys().copied().collect();
        stuck.sort_unstable(); // the map's order: not the run's to decide
        let (after, worst, worst_edge) = run.s.worst_non_delaunay_among(stuck, ACCEPT_TOLERANCE);
        run.stats.non_delaunay_after = after;
        if after > 0 {
            return Err(Error::Unsplittable {
                count: after,
                worst_excess: worst,
                worst_edge: worst_edge.map(|e| run.s.stuck_edge(e)),
                near_coincident: NearCoincident::of(&run.s.input_figures),
            });
        }
    }
    Ok(run.stats)
}

/// The interior edges of `s` non-Delaunay by more than
/// [`SEED_TOLERANCE`] (the first pass of [`make_delaunay`]), in increasing
/// order. Read-only, so on large meshes each available core takes a
/// contiguous range of edges; the result does not depend on how many do.
pub fn non_delaunay_edges(s: &Surface) -> Vec<EdgeId> {
    let edges = crate::parallel::filter_indices(s.topo.n_edges(), |e| {
        s.is_non_delaunay(EdgeId(e as u32), SEED_TOLERANCE)
    });
    edges.into_iter().map(EdgeId).collect()
}

struct Run<'a> {
    s: &'a mut Surface,
    options: Options,
    constants: SampleConstants,
    stats: Stats,
    /// Edges found non-Delaunay that could be neither flipped nor split,
    /// with their [`Run::neighbourhood`] at the time (few: a map).
    stuck: FastMap<EdgeId, [VertexId; 8]>,
    /// Set when an edge needed a split or flip past the work limit
    /// ([`Options::max_added`]) or a split past the ids' room
    /// ([`crate::mesh::Topology::split_room`]), which was then not made.
    over_limit: bool,
    /// The most splits the run may make: [`Options::max_added`], or fewer
    /// where the ids would run out first.
    split_limit: usize,
    /// The positions of the mesh's vertices ([`position_key`]), made at the
    /// first split of a boundary edge (`gabriel_boundary`) and kept up
    /// since: such a split must not land on a vertex of another part of a
    /// surface that overlaps itself (a boundary edge of a fan folded over,
    /// running through a vertex), where the two would be one point.
    occupied: Option<std::collections::HashSet<[u64; 3], crate::hash::FastBuild>>,
}

impl Run<'_> {
    /// The four vertices of interior edge `e`'s quad: its ends, then the
    /// apexes of its two faces.
    #[cfg(debug_assertions)]
    fn quad(&self, e: EdgeId) -> [VertexId; 4] {
        let (topo, h) = (&self.s.topo, e.halfedge());
        [topo.origin(h), topo.dest(h), topo.apex(h), topo.apex(h.twin())]
    }

    /// Whether `e` was found stuck and its neighbourhood has not changed
    /// since, so that processing it again would change nothing.
    fn is_stuck(&self, e: EdgeId) -> bool {
        self.stuck.get(&e).is_some_and(|n| *n == self.neighbourhood(e))
    }

    /// Remembers that `e` can be neither flipped nor split as things are.
    fn mark_stuck(&mut self, e: EdgeId) {
        let n = self.neighbourhood(e);
        self.stuck.insert(e, n);
    }

    /// Everything [`Run::process`] reads about `e`: its quad and the apexes
    /// beyond its four outer edges ([`VertexId::NONE`] past a boundary).
    /// Positions never move and a face's region follows from its vertices,
    /// so the same neighbourhood means the same decision, with one
    /// exception: a flip refused because c and d are joined elsewhere
    /// (where a region overlaps itself). Such an edge stays stuck until its
    /// neighbourhood changes, even if the joining edge goes away (retrying
    /// those at the end of each pass changed nothing on 40 jittered
    /// two-sided grids).
    ///
    /// ```text
    ///          x1     x0
    ///           \ c  /
    ///        b ---h--- a      e = a-b; quad (a, b, c, d);
    ///           / d  \        x0..x3 beyond the outer edges
    ///          x2     x3
    /// ```
    fn neighbourhood(&self, e: EdgeId) -> [VertexId; 8] {
        let topo = &self.s.topo;
        let h = e.halfedge();
        // (A boundary edge, tested with `gabriel_boundary`, has one side.)
        let beyond = |x: HalfEdgeId| match x.is_none() {
            true => VertexId::NONE,
            false => topo.apex(x.twin()),
        };
        let [x0, x1, x2, x3] = match topo.is_interior(e) {
            true => topo.outer_halfedges(e).map(beyond),
            false => topo.outer_halfedges_of_faces(e).map(beyond),
        };
        [
            topo.origin(h),
            topo.dest(h),
            topo.apex(h),
            topo.apex(h.twin()),
            x0,
            x1,
            x2,
            x3,
        ]
    }

    /// Queues `e` if it is non-Delaunay, after a flip or split changed its
    /// quad; if it is queued already, records the new test (so that taking
    /// it needs none). Stuck edges are left, and tested again if taken.
    #[inline(always)]
    fn push_if_bad(&self, ds: &mut Ds, e: EdgeId) {
        if self.is_stuck(e) {
            ds.retested(e, None);
            return;
        }
        match self.s.delaunay_test(e, ALGORITHM_TOLERANCE) {
            DelaunayTest::Delaunay => ds.retested(e, Some(DelaunayTest::Delaunay)),
            test => ds.push(e, Some(test), || self.s.edge_length(e)),
        }
    }

    /// Flips or splits `e`, taken from DS, if it is non-Delaunay; `known` is
    /// the test of its quad as it is now, if DS has it (every flip and split
    /// tests the edges whose quads it changes: [`Run::push_if_bad`]).
    fn process(&mut self, e: EdgeId, known: Option<DelaunayTest>, ds: &mut Ds) {
        let test = known.unwrap_or_else(|| self.s.delaunay_test(e, ALGORITHM_TOLERANCE));
        debug_assert_eq!(
            test,
            self.s.delaunay_test(e, ALGORITHM_TOLERANCE),
            "DS kept a stale test"
        );
        match test {
            DelaunayTest::Delaunay => return,
            DelaunayTest::NonDelaunay => {}
            DelaunayTest::Underflow => {
                // Nothing to decide with: flipping or splitting would act on
                // noise (and splitting such a needle makes more of them).
                // Left for the final count, which refuses it.
                self.mark_stuck(e);
                return;
            }
        }
        if !self.s.topo.is_interior(e) {
            // Only with `gabriel_boundary`: a boundary edge facing an obtuse
            // angle, which no flip can change.
            self.split_boundary_edge(e, ds);
            return;
        }
        let around = self.s.topo.outer_halfedges(e).map(|x| x.edge());
        let flippable = self.s.is_flippable(e);
        if flippable && self.s.flip_is_valid(e) {
            if self.stats.flips >= FLIPS_PER_ADDED.saturating_mul(self.options.max_added) {
                self.over_limit = true;
                return;
            }
            self.s.flip(e);
            self.stats.flips += 1;
            // The new diagonal itself is Delaunay: `flip_is_valid` tested it
            // with the same positions (the test is symmetric in the edge's
            // direction and in its two apexes, bit for bit).
            for x in around {
                self.push_if_bad(ds, x);
            }
            return;
        }
        if flippable && self.s.edge_input[e.idx()] == NO_INPUT_EDGE {
            // The flip would duplicate an edge c–d that lies on an input
            // edge (a region that overlaps itself: the two sheets of a flat
            // two-sided plate, whose Delaunay triangulations want the same
            // edges between the rim's vertices): that edge is split instead,
            // at a sample, and `e` taken again (its flip is then possible).
            //
            //     this sheet:        the other sheet:
            //          c                  c
            //         / \                 |
            //        a---b                m      c-d split at m: then
            //         \ /                 |      e = a-b flips into c-d
            //          d                  d
            if let Some(blocking) = self.s.edge_blocking_flip(e) {
                if self.s.topo.is_interior(blocking) && self.s.edge_input[blocking.idx()] != NO_INPUT_EDGE {
                    if let Some(choice) = self.choose_sample(blocking) {
                        self.split_at(blocking, choice.t, ds);
                        self.push_if_bad(ds, e);
                        return;
                    }
                }
            }
            // A numerically degenerate quad, and no input edge to split:
            // leave the edge for the final count.
            self.mark_stuck(e);
            return;
        }
        // Not flippable, or a flip would fold a face or duplicate an edge
        // (a region that overlaps itself, as where the surface folds flat
        // onto itself; or rounding in a needle quad): an edge on an input
        // edge is split instead, at a sample like any other.
        match self.choose_sample(e) {
            Some(choice) => self.split_at(e, choice.t, ds),
            None => self.mark_stuck(e),
        }
    }

    /// Splits the interior edge `e` at `t` along its input edge (unless the
    /// work limit is reached), and queues the edges whose quads changed.
    fn split_at(&mut self, e: EdgeId, t: f64, ds: &mut Ds) {
        if self.stats.splits >= self.split_limit {
            self.over_limit = true;
            return;
        }
        let around = self.s.topo.outer_halfedges(e).map(|x| x.edge());
        let n = self.s.topo.n_edges() as u32;
        let p = self.s.split(e, t);
        self.stats.splits += 1;
        self.occupy(p);
        for x in [e, EdgeId(n), EdgeId(n + 1), EdgeId(n + 2)].into_iter().chain(around) {
            self.push_if_bad(ds, x);
        }
    }

    /// The sample at which to split the edge `e`, which cannot be flipped (validly).
    fn choose_sample(&self, e: EdgeId) -> Option<samples::Choice> {
        choose_sample(self.s, &self.constants, &self.options, e)
    }

    /// Adds the new vertex `p` to [`Run::occupied`], once that is kept.
    fn occupy(&mut self, p: VertexId) {
        if let Some(occupied) = &mut self.occupied {
            occupied.insert(position_key(self.s.positions[p.idx()].to_array()));
        }
    }

    /// Splits the boundary edge `e`, found facing an obtuse angle (with
    /// [`Surface::gabriel_boundary`]), at the sample the run's settings
    /// choose ([`choose_boundary_sample`]), and queues the edges whose
    /// faces changed.
    fn split_boundary_edge(&mut self, e: EdgeId, ds: &mut Ds) {
        let s = &*self.s;
        let occupied =
            (self.occupied).get_or_insert_with(|| s.positions.iter().map(|p| position_key(p.to_array())).collect());
        let free = |p: DVec3| !occupied.contains(&position_key(p.to_array()));
        let Some(choice) = choose_boundary_sample(s, &self.constants, &self.options, e, free) else {
            self.mark_stuck(e);
            return;
        };
        if self.stats.splits >= self.split_limit {
            self.over_limit = true;
            return;
        }
        let topo = &self.s.topo;
        let around = topo.outer_halfedges_of_faces(e);
        let n = topo.n_edges() as u32;
        let p = self.s.split_boundary(e, choice.t);
        self.stats.splits += 1;
        self.occupy(p);
        let outer = around.into_iter().filter(|x| !x.is_none()).map(|x| x.edge());
        for x in [e, EdgeId(n), EdgeId(n + 1)].into_iter().chain(outer) {
            self.push_if_bad(ds, x);
        }
    }
}

/// The sample at which the boundary edge `e` of `s` is split when its one
/// opposite angle is obtuse (with [`Surface::gabriel_boundary`]): chosen as
/// for an interior edge ([`choose_sample`]: the run's score, median or
/// shells), the two halves' conditions being that each faces a right or
/// acute angle, and the outer edges' that the two other edges of its face
/// stay Delaunay. `None` if no sample inside gives valid faces at a point
/// `free` says no vertex is at.
///
/// ```text
///              c            the half a-m faces a right or acute angle at c
///            / | \          iff m is no farther along ab than |ac|^2 / p,
///           /  |  \         and m-b iff m is no nearer than p - h^2/(L - p),
///          /   |h  \        where (p, h) is c in the frame of ab: between
///         a ---+----- b     the two lies the foot of the altitude from c
///              p            (each half then faces an acute angle)
/// ```
pub(crate) fn choose_boundary_sample(
    s: &Surface,
    constants: &SampleConstants,
    options: &Options,
    e: EdgeId,
    free: impl Fn(DVec3) -> bool,
) -> Option<samples::Choice> {
    let input = s.edge_input[e.idx()];
    let h = s.boundary_side(e)?;
    if input == NO_INPUT_EDGE {
        return None; // cannot happen: a boundary edge lies on an input edge
    }
    let topo = &s.topo;
    let (a, b, c) = (topo.origin(h), topo.dest(h), topo.apex(h));
    let [pa, pb, pc] = [a, b, c].map(|v| s.positions[v.idx()]);
    // The face's other two edges, as `Topology::outer_halfedges` lists the
    // first side's: c→a, then b→c.
    let outer_halfedges = [topo.next(topo.next(h)), topo.next(h)];
    let beyond = outer_halfedges.map(|x| {
        let v = topo.apex(x.twin());
        (!v.is_none()).then(|| s.positions[v.idx()])
    });
    // The outer edges' conditions as for an interior edge (the missing side's
    // two, with nothing beyond, always hold).
    let (_, outer) = split_conditions([pa, pb, pc, pc], [beyond[0], beyond[1], None, None]);
    let frame = EdgeFrame::new(pa, pb);
    let len = frame.length;
    let c2 = frame.unfold(pc, true);
    let halves = [
        Condition {
            side: Side::AtMost,
            breakpoint: if c2.x > 0.0 {
                c2.length_squared() / c2.x
            } else {
                f64::NAN
            },
        },
        Condition {
            side: Side::AtLeast,
            breakpoint: if len - c2.x > 0.0 {
                c2.x - c2.y * c2.y / (len - c2.x)
            } else {
                f64::NAN
            },
        },
    ];
    let ends = s.input_edge_ends(input);
    let edge_samples = EdgeSamples::new((ends[1] - ends[0]).length(), constants);
    let flippable = options.score == Score::SplitAware;
    let query = SplitQuery {
        samples: &edge_samples,
        edge_ends: ends,
        t_a: s.param_on(a, input),
        t_b: s.param_on(b, input),
        pos_a: pa,
        pos_b: pb,
        halves,
        outer,
        outer_flippable: match flippable {
            true => [
                s.is_flippable(outer_halfedges[0].edge()),
                s.is_flippable(outer_halfedges[1].edge()),
                false,
                false,
            ],
            false => [false; 4],
        },
        score: options.score,
        median: options.median,
        shells: options.shells,
    };
    choose_valid_where(s, e, &query, |t| free(samples::point_on_edge(ends[0], ends[1], t)))
}

/// The sample at which Algorithm 2 splits the non-Delaunay edge `e` of `s`
/// (not flippable, or not validly) with these settings (`None`: no sample
/// left in it whose rounded position gives valid faces, see
/// [`Surface::split_is_valid`]).
pub(crate) fn choose_sample(
    s: &Surface,
    constants: &SampleConstants,
    options: &Options,
    e: EdgeId,
) -> Option<samples::Choice> {
    // Only the split-aware score reads which outer edges are flippable:
    // skip the face lookups otherwise.
    let flippable = options.score == Score::SplitAware;
    with_split_query(s, constants, e, flippable, |query| {
        query.score = options.score;
        query.median = options.median;
        query.shells = options.shells;
        choose_valid(s, e, query)
    })
    .flatten()
}

/// Builds the [`SplitQuery`] of the non-flippable edge `e` (its six
/// conditions, the samples of its input edge; which outer edges can be
/// flipped only if `flippable`, else none) and hands it to `f`, which may
/// set the score and median rule and choose several times: the costly part,
/// unfolding the quad and its neighbours, is done once. `None` if `e` lies
/// on no input edge.
pub(crate) fn with_split_query<R>(
    s: &Surface,
    constants: &SampleConstants,
    e: EdgeId,
    flippable: bool,
    f: impl FnOnce(&mut SplitQuery) -> R,
) -> Option<R> {
    let input = s.edge_input[e.idx()];
    if input == NO_INPUT_EDGE {
        return None; // cannot happen: such edges lie inside a region
    }
    let topo = &s.topo;
    let h = e.halfedge();
    let (a, b) = (topo.origin(h), topo.dest(h));
    let quad = s.edge_quad(e);
    let outer_halfedges = topo.outer_halfedges(e);
    let beyond = outer_halfedges.map(|x| {
        let v = topo.apex(x.twin());
        (!v.is_none()).then(|| s.positions[v.idx()])
    });
    let (halves, outer) = split_conditions(quad, beyond);
    let ends = s.input_edge_ends(input);
    let edge_samples = EdgeSamples::new((ends[1] - ends[0]).length(), constants);
    let mut query = SplitQuery {
        samples: &edge_samples,
        edge_ends: ends,
        t_a: s.param_on(a, input),
        t_b: s.param_on(b, input),
        pos_a: quad[0],
        pos_b: quad[1],
        halves,
        outer,
        outer_flippable: if flippable {
            outer_halfedges.map(|x| s.is_flippable(x.edge()))
        } else {
            [false; 4]
        },
        score: Score::AlwaysCenter,
        median: true,
        shells: false,
    };
    Some(f(&mut query))
}

/// The sample `query` chooses on edge `e` of `s`, if its rounded position
/// makes properly oriented faces; if not (it lies within rounding of a
/// vertex or of a line through one), the middle of the sub-edge, the best
/// hope, if that does.
pub(crate) fn choose_valid(s: &Surface, e: EdgeId, query: &SplitQuery) -> Option<samples::Choice> {
    choose_valid_where(s, e, query, |_| true)
}

/// [`choose_valid`], with one more condition on the sample's parameter.
fn choose_valid_where(
    s: &Surface,
    e: EdgeId,
    query: &SplitQuery,
    also: impl Fn(f64) -> bool,
) -> Option<samples::Choice> {
    let valid = |c: &samples::Choice| s.split_is_valid(e, c.t) && also(c.t);
    let pieces = samples::Pieces::new(query)?;
    Some(pieces.choose(query))
        .filter(valid)
        .or_else(|| Some(pieces.middle()).filter(valid))
}
