//! `--prune`: removing added vertices again where the mesh stays Delaunay
//! without them.
//!
//! Algorithm 2 splits greedily: a vertex added early may no longer be needed
//! once later splits and flips have changed its neighbourhood. For each added
//! vertex p, on input edge E between its neighbours u and w along E, pruning
//!
//! 1. flips the edges from p into each of its two sides, one "ear" at a time,
//!    until p has a single neighbour x (resp. y) on each side;
//! 2. merges the two sub-edges u–p and p–w back into one (undoing a split);
//! 3. flips the flat regions around back to Delaunay (Lawson);
//!
//! and keeps the result only if every edge it touched is Delaunay; otherwise
//! every change is undone from a journal. When removing p alone fails,
//! pruning tries to replace p and the next one or two added vertices along E,
//! or p and one or two added neighbours, by one vertex fewer: it removes them
//! all, then runs Algorithm 2 locally (several split points in turn for the
//! first new vertex) with a budget of one split fewer than it removed. Only
//! added vertices are ever removed, and new ones lie on input edges (samples,
//! or for the first one possibly the middle of the best stretch between
//! them), so the geometry stays exactly the input's.
//!
//! ```text
//!        x1   x2                 x1---x2              x
//!         \   /                   \   /             /   \
//!     u----p----w   ==>   u-------p----w   ==>   u-------w
//!         /  \                     /  \            \   /
//!       y1    y2                 y1----y2            y
//! ```

use crate::geometry::{self, ALGORITHM_TOLERANCE};
use crate::mesh::{Carrier, EdgeId, HalfEdgeId, Saved, Surface, VertexId, ADJACENCY_LIMIT};
use crate::refine::{self, Options};
use crate::samples::{self, point_on_edge, EdgeSamples, Pieces, SampleConstants, Score};
use glam::DVec3;

/// What pruning did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PruneStats {
    /// Added vertices removed.
    pub removed: usize,
    /// Removals tried (including the undone ones).
    pub tried: usize,
    /// Flips kept.
    pub flips: usize,
    /// Passes over the added vertices.
    pub passes: usize,
}

/// Flips allowed in one removal attempt before it is given up.
const MAX_FLIPS_PER_TRY: usize = 4096;
/// At most this many consecutive added vertices of one input edge are
/// replaced by one fewer.
const MAX_GROUP: usize = 3;
/// Where along the sub-edge to split (as fractions) when no score's sample
/// works.
const SPREAD: [f64; 6] = [0.5, 0.35, 0.65, 0.2, 0.8, 0.1];
/// How many of the edges left non-Delaunay after a removal are tried as the
/// place of the first new vertex.
const FIRST_SPLITS: usize = 1;
// The first edges to split are taken from `FixedBad::edges`.
const _: () = assert!(FIRST_SPLITS <= MAX_GROUP + 1);
/// Triples are made of p and two of its this many nearest added neighbours.
const TRIPLE_NEIGHBOURS: usize = 4;
/// The sample choices tried, in turn, for the first vertex of a replacement.
const VARIANTS: [(Score, bool); 8] = [
    (Score::AlwaysCenter, true),
    (Score::SplitAware, true),
    (Score::AllEqual, true),
    (Score::WeightedCenter, true),
    (Score::AlwaysCenter, false),
    (Score::SplitAware, false),
    (Score::AllEqual, false),
    (Score::WeightedCenter, false),
];
/// Passes over all added vertices at most (each pass after the first only
/// finds what earlier removals made possible): [`prune`] stops earlier if a
/// pass removes nothing; [`prune_passes`] may stop sooner still.
pub const MAX_PASSES: usize = 8;

/// A progress callback for [`prune_with_progress`]: the figures so far and
/// how many added vertices the current pass has still to visit. `'static`
/// like [`crate::refine::ProgressHook`].
#[derive(Clone, Copy)]
pub struct PruneHook(pub &'static (dyn Fn(&PruneStats, usize) + Sync));

/// How many added vertices are visited between two calls of a [`PruneHook`].
pub const PRUNE_PROGRESS_INTERVAL: usize = 1 << 12;

/// Removes added vertices of the Delaunay mesh `surface` wherever it stays
/// Delaunay with fewer, and compacts the mesh (the remaining vertices keep
/// their order). `surface` must be the result of a successful
/// [`crate::make_delaunay`]; `options` choose the samples of the local
/// re-refinements (their work limit is not used).
pub fn prune(surface: &mut Surface, options: &Options) -> PruneStats {
    prune_with_progress(surface, options, None)
}

/// [`prune`], calling `hook` (if any) every [`PRUNE_PROGRESS_INTERVAL`]
/// added vertices visited; the result does not depend on it.
pub fn prune_with_progress(surface: &mut Surface, options: &Options, hook: Option<PruneHook>) -> PruneStats {
    prune_passes(surface, options, MAX_PASSES, hook)
}

/// [`prune_with_progress`], in at most `passes` passes (1 to
/// [`MAX_PASSES`]) over the added vertices. The first pass removes most of
/// what pruning removes, in a fraction of its time: the later ones revisit
/// only vertices near a removal, but try pairs and triples there again.
/// With fewer passes the result is what the full run had after as many.
pub fn prune_passes(surface: &mut Surface, options: &Options, passes: usize, hook: Option<PruneHook>) -> PruneStats {
    let max_passes = passes.clamp(1, MAX_PASSES);
    let constants = refine::sample_constants(surface);
    let mut run = Pruner {
        constants,
        options: *options,
        s: surface,
        journal: Vec::new(),
        inputs: Vec::new(),
        touched: Vec::new(),
        in_touched: Vec::new(),
        changes: Vec::new(),
        stack: Vec::new(),
        queued: Vec::new(),
        verdict: Vec::new(),
        stats: PruneStats::default(),
        flips: 0,
        splits: 0,
        detached: 0,
        doomed: false,
        dirty: Vec::new(),
    };
    let first_added = run.s.n_input_vertices;
    // After the first pass, only vertices near a kept change can have become
    // removable.
    run.dirty = vec![true; run.s.topo.n_vertices()];
    while run.stats.passes < max_passes {
        run.stats.passes += 1;
        let before = run.stats.removed;
        // Newest first: a vertex added late was placed knowing the others.
        for v in (first_added..run.s.topo.n_vertices()).rev() {
            if let Some(PruneHook(hook)) = hook {
                if (v - first_added) % PRUNE_PROGRESS_INTERVAL == 0 {
                    hook(&run.stats, v - first_added);
                }
            }
            let v = VertexId(v as u32);
            if run.dirty.get(v.idx()).copied().unwrap_or(true) && !run.s.topo.is_dead_vertex(v) {
                run.dirty[v.idx()] = false;
                run.try_remove(v);
            }
        }
        if run.stats.removed == before {
            break;
        }
    }
    run.s.compact();
    run.stats
}

/// Calls `f` on each added vertex joined to `p` by an edge, counter-clockwise
/// from `p`'s first outgoing half-edge (no allocation: [`Pruner::keep`] asks
/// this around every edge a kept attempt touched).
fn for_each_added_neighbour(s: &Surface, p: VertexId, mut f: impl FnMut(VertexId)) {
    let topo = &s.topo;
    let first = topo.vertex_he(p);
    let mut h = first;
    loop {
        let v = topo.dest(h);
        if v.idx() >= s.n_input_vertices {
            f(v);
        }
        h = topo.rotate_ccw(h);
        if h.is_none() || h == first {
            return;
        }
    }
}

struct Pruner<'a> {
    s: &'a mut Surface,
    constants: SampleConstants,
    options: Options,
    /// Topology entries to restore if the current attempt fails.
    journal: Vec<Saved>,
    /// Input-edge labels to restore (flips clear them).
    inputs: Vec<(EdgeId, u32)>,
    /// Edges whose Delaunay status the attempt may have changed, each once,
    /// in the order first touched.
    touched: Vec<EdgeId>,
    /// Whether each edge is in `touched`.
    in_touched: Vec<bool>,
    /// Every touch of the try, repeats included, with the verdict the edge
    /// had just before it: undoing to a mark puts these back, latest first,
    /// so that each edge touched since has the verdict it had at the mark
    /// (its quad is the mark's again). A trial split undone thus leaves
    /// what the `settle` before it found, for the next trial.
    changes: Vec<(EdgeId, Option<bool>)>,
    stack: Vec<EdgeId>,
    /// Whether each edge is in `stack`.
    queued: Vec<bool>,
    /// What `settle` found of each edge of `touched` since it last changed:
    /// `Some(true)` non-Delaunay, `Some(false)` Delaunay, `None` not known
    /// (every change to an edge's quad goes through [`Pruner::touch`], which
    /// forgets it; undoing puts back what it was at the mark, see
    /// `changes`). Saves testing unchanged edges again each time `settle`
    /// runs in one try.
    verdict: Vec<Option<bool>>,
    stats: PruneStats,
    /// Flips of the current attempt.
    flips: usize,
    /// Splits of the current attempt.
    splits: usize,
    /// Vertices removed by the current attempt.
    detached: usize,
    /// Debug builds: whether a settle of the current attempt (since the
    /// last undo) found more non-flippable edges non-Delaunay than splits
    /// left, so that the attempt must fail (release builds stop there).
    doomed: bool,
    /// Vertices worth trying (again) in the next pass.
    dirty: Vec<bool>,
}

impl Pruner<'_> {
    /// Tries to remove `p` alone, then to replace it and the next added
    /// vertices along its input edge, or it and one or two added neighbours,
    /// by one vertex fewer; keeps the first attempt that succeeds.
    ///
    /// Every attempt begins by detaching `p` from the same mesh (a failed
    /// one is undone entirely), so that is done once: each attempt undoes
    /// back to just after it. Likewise a neighbour `q1` is detached once for
    /// its pair (p, q1) and its triples (p, q1, q2). The attempts and their
    /// outcomes are those of starting each one afresh. The pair of p and the
    /// next vertex along its input edge is the group of two along the edge
    /// again: when that failed, the pair is counted as tried and failed
    /// without being made again.
    fn try_remove(&mut self, p: VertexId) {
        let Carrier::Edge { edge: input, .. } = self.s.carriers[p.idx()] else {
            return;
        };
        // Pairs and triples below: p with its nearest added neighbours.
        let mut neighbours = self.added_neighbours(p);
        let at = self.s.positions[p.idx()];
        neighbours.sort_by(|&a, &b| {
            let da = self.s.positions[a.idx()].distance_squared(at);
            da.total_cmp(&self.s.positions[b.idx()].distance_squared(at))
        });
        self.begin_attempts();
        // The next vertex along the input edge, seen before p goes.
        let along = self.along_input(p, input).map(|[_, to_w]| self.s.topo.dest(to_w));
        let after_p = self.detach(p, input).then(|| self.mark());
        let mut kept = false;
        // The next vertex, if p and it were tried as a group of two and
        // failed: the pair of p and it below is the same attempt.
        let mut failed_with_next = None;
        for group in 1..=MAX_GROUP {
            let Some(next) = along else {
                self.stats.tried += 1; // the first attempt finds no group
                break;
            };
            let r = self.conclude(after_p, |me| me.replace_after(next, input, group));
            if group == 2 && !matches!(r, Attempt::Kept) {
                failed_with_next = Some(next);
            }
            kept = matches!(r, Attempt::Kept);
            if !matches!(r, Attempt::Failed) {
                break;
            }
        }
        // Pairs: p and an added neighbour (often a vertex that a split at p
        // made necessary) replaced by one vertex; then triples: p and two
        // added neighbours replaced by two. Each q1 is detached once for its
        // pair and its triples, which undo back to just after it (as every
        // attempt undoes back to just after p): the attempts and their
        // outcomes are those of detaching q1 afresh for each.
        'pairs: for (i, &q1) in neighbours.iter().enumerate() {
            if kept {
                break;
            }
            let partners = match i < TRIPLE_NEIGHBOURS {
                true => &neighbours[i + 1..neighbours.len().min(TRIPLE_NEIGHBOURS)],
                false => &[][..],
            };
            // Detaching q1 and refining with one split, from just after p,
            // is what the group of two did if q1 is the next vertex: when
            // that failed, the pair is counted as failed and not made again
            // (and q1 is detached only if a triple needs it).
            let pair_failed = failed_with_next == Some(q1);
            let after_q1 = match pair_failed && partners.is_empty() {
                true => None,
                false => after_p.and_then(|_| self.detach_added(q1).then(|| self.mark())),
            };
            let pair_start = after_q1.filter(|_| !pair_failed);
            kept = matches!(self.conclude(pair_start, |me| me.rebuild(1)), Attempt::Kept);
            for &q2 in partners {
                if kept {
                    break 'pairs;
                }
                kept = matches!(self.conclude(after_q1, |me| me.replace_with(q2)), Attempt::Kept);
            }
            // Back to just after p (also when q1 could not be detached).
            if let (false, Some(mark)) = (kept, after_p) {
                self.undo_to(mark);
            }
        }
        if !kept {
            self.undo_to(Mark::default());
        }
    }

    /// Counts one attempt and runs `rest` of it if its first vertices were
    /// detached (`start`, the mark just after; `None`: one could not be, or
    /// the attempt is known to fail, and it fails); keeps it, or undoes back
    /// to `start`.
    fn conclude(&mut self, start: Option<Mark>, rest: impl FnOnce(&mut Self) -> Attempt) -> Attempt {
        self.stats.tried += 1;
        let Some(mark) = start else {
            return Attempt::Failed;
        };
        let r = rest(self);
        if let Attempt::Kept = r {
            self.keep();
        } else {
            self.undo_to(mark);
        }
        r
    }

    /// With `p` detached: detaches `next` and the added vertices after it
    /// along `input`, up to `group` vertices with p, then refines locally
    /// with at most `group - 1` splits.
    fn replace_after(&mut self, next: VertexId, input: u32, group: usize) -> Attempt {
        let mut v = next;
        for _ in 1..group {
            if !matches!(self.s.carriers[v.idx()], Carrier::Edge { edge, .. } if edge == input) {
                return Attempt::NoGroup;
            }
            let Some([_, to_w]) = self.along_input(v, input) else {
                return Attempt::NoGroup;
            };
            let after = self.s.topo.dest(to_w);
            if !self.detach(v, input) {
                return Attempt::Failed;
            }
            v = after;
        }
        self.rebuild(group - 1)
    }

    /// With `p` and `q1` detached: detaches the added vertex `q2` too, then
    /// refines locally with at most two splits.
    fn replace_with(&mut self, q2: VertexId) -> Attempt {
        if !self.detach_added(q2) {
            return Attempt::Failed;
        }
        self.rebuild(2)
    }

    /// Detaches the added vertex `v` on its own input edge ([`Pruner::detach`]).
    fn detach_added(&mut self, v: VertexId) -> bool {
        match self.s.carriers[v.idx()] {
            Carrier::Edge { edge, .. } => self.detach(v, edge),
            _ => false,
        }
    }

    /// The added vertices joined to `p` by an edge.
    fn added_neighbours(&self, p: VertexId) -> Vec<VertexId> {
        let mut out = Vec::new();
        for_each_added_neighbour(self.s, p, |v| out.push(v));
        out
    }

    /// Starts the attempts at removing one vertex from a clean journal.
    fn begin_attempts(&mut self) {
        self.journal.clear();
        self.inputs.clear();
        self.rewind_touches(Mark::default());
        self.flips = 0;
        self.splits = 0;
        self.detached = 0;
        self.doomed = false;
    }

    /// Keeps the current attempt: counts it, and marks the vertices near
    /// every edge it touched for the next pass.
    fn keep(&mut self) {
        self.stats.removed += self.detached - self.splits;
        self.stats.flips += self.flips;
        self.dirty.resize(self.s.topo.n_vertices(), true);
        for i in 0..self.touched.len() {
            let e = self.touched[i];
            if self.s.topo.is_dead_edge(e) {
                continue;
            }
            let h = e.halfedge();
            for v in [self.s.topo.origin(h), self.s.topo.dest(h)] {
                let dirty = &mut self.dirty;
                dirty[v.idx()] = true;
                for_each_added_neighbour(self.s, v, |w| dirty[w.idx()] = true);
            }
        }
    }

    /// Where the current attempt stands, to undo back to.
    fn mark(&self) -> Mark {
        Mark {
            journal: self.journal.len(),
            inputs: self.inputs.len(),
            touched: self.touched.len(),
            changes: self.changes.len(),
            splits: self.splits,
            flips: self.flips,
            detached: self.detached,
            doomed: self.doomed,
        }
    }

    /// Undoes every change of the current attempt made after `mark`.
    fn undo_to(&mut self, mark: Mark) {
        self.s.topo.restore(&self.journal[mark.journal..]);
        for &(e, label) in self.inputs[mark.inputs..].iter().rev() {
            self.s.edge_input[e.idx()] = label;
        }
        self.journal.truncate(mark.journal);
        self.inputs.truncate(mark.inputs);
        self.rewind_touches(mark);
        self.splits = mark.splits;
        self.flips = mark.flips;
        self.detached = mark.detached;
        self.doomed = mark.doomed;
        let topo = &self.s.topo;
        let (nv, ne, nf) = (topo.n_vertices(), topo.n_edges(), topo.n_faces());
        self.s.positions.truncate(nv);
        self.s.carriers.truncate(nv);
        self.s.edge_input.truncate(ne);
        self.s.face_region.truncate(nf);
    }

    /// Flips `p` down to degree four and merges its two sub-edges, saving
    /// every change; `false` if that cannot be done.
    fn detach(&mut self, p: VertexId, input: u32) -> bool {
        // A vertex on the boundary (split there with `gabriel_boundary`) has
        // one side: it stays.
        if self.s.topo.is_boundary_he(self.s.topo.vertex_he(p).twin()) {
            return false;
        }
        let Some([to_u, to_w]) = self.along_input(p, input) else {
            return false;
        };
        for side_start in [to_u, to_w] {
            if !self.reduce_side(p, input, side_start) {
                return false;
            }
        }
        let (u, w) = (self.s.topo.dest(to_u), self.s.topo.dest(to_w));
        // Merging would duplicate an edge u–w that exists already (the
        // surface folds back on itself there); not knowing refuses too.
        if self.s.topo.are_adjacent_within_either(u, w, ADJACENCY_LIMIT) != Some(false) {
            return false;
        }
        // Save what unsplit writes: the twelve half-edges around p, its four
        // faces and its five vertices.
        let topo = &self.s.topo;
        let hu = to_u.twin();
        let mut hes = Vec::with_capacity(12);
        let mut h = to_u;
        for _ in 0..4 {
            let n = topo.next(h);
            hes.extend([h, n, topo.next(n)]);
            h = topo.rotate_ccw(h);
        }
        let faces = [hes[0], hes[3], hes[6], hes[9]].map(|h| topo.face(h));
        let verts = [p, u, w, topo.dest(topo.next(to_u)), topo.dest(topo.next(to_w))];
        topo.save(&hes, &faces, &verts, &mut self.journal);
        if self.s.topo.unsplit(hu).is_none() {
            return false;
        }
        self.detached += 1;
        // The two merged faces: (u, w, x) on hu's side, (w, u, y) on its twin's.
        // Their corners were never joined so before: each must have its
        // region's orientation, exactly (the caller undoes on failure).
        for h in [hu, hu.twin()] {
            let f = self.s.topo.face(h);
            if !f.is_none() && !self.s.face_is_proper(f) {
                return false;
            }
        }
        for h in [hu, hu.twin()] {
            let n = self.s.topo.next(h);
            let next = self.s.topo.next(n);
            self.touch([h.edge(), n.edge(), next.edge()]);
        }
        true
    }

    /// The two outgoing half-edges of `p` that lie on `input`, in the order
    /// where the first one's counter-clockwise side is the first side.
    fn along_input(&self, p: VertexId, input: u32) -> Option<[HalfEdgeId; 2]> {
        let topo = &self.s.topo;
        let first = topo.vertex_he(p);
        let mut found = [HalfEdgeId::NONE; 2];
        let mut count = 0;
        let mut h = first;
        loop {
            if self.s.edge_input[h.edge().idx()] == input {
                if count == 2 {
                    return None;
                }
                found[count] = h;
                count += 1;
            }
            h = topo.rotate_ccw(h);
            if h.is_none() {
                return None; // p is on the boundary: never split there
            }
            if h == first {
                break;
            }
        }
        (count == 2).then_some(found)
    }

    /// Flips edges out of p, counter-clockwise after `start` up to the next
    /// edge on the input edge, until one neighbour is left between them.
    fn reduce_side(&mut self, p: VertexId, input: u32, start: HalfEdgeId) -> bool {
        let on_input = |me: &Self, h: HalfEdgeId| me.s.edge_input[h.edge().idx()] == input;
        loop {
            // The interior neighbours' half-edges follow `start` counter-
            // clockwise up to the other sub-edge of p.
            let first = self.s.topo.rotate_ccw(start);
            debug_assert_eq!(self.s.topo.origin(first), p);
            if on_input(self, first) {
                return false; // no neighbour on this side
            }
            if on_input(self, self.s.topo.rotate_ccw(first)) {
                return true; // exactly one: done
            }
            // Flip the first ear: any ear would do, the Lawson pass after the
            // merge makes the region Delaunay again.
            let mut h = first;
            let mut walked = 0;
            while !self.ear_flip_is_valid(h.edge()) {
                h = self.s.topo.rotate_ccw(h);
                walked += 1;
                if on_input(self, h) || walked > 4096 {
                    return false; // no ear on this side
                }
            }
            if self.flip(h.edge()).is_none() {
                return false;
            }
        }
    }

    /// Whether flipping `e` keeps both new faces strictly on their region's
    /// side (the quad is convex) and makes no duplicate edge.
    fn ear_flip_is_valid(&self, e: EdgeId) -> bool {
        let s = &*self.s;
        let h = e.halfedge();
        let [a3, b3, c3, d3] = s.edge_quad(e);
        let plane = s.region_plane[s.face_region[s.topo.face(h).idx()] as usize];
        if !plane.is_proper([d3, c3, a3]) || !plane.is_proper([c3, d3, b3]) {
            return false;
        }
        let (c, d) = (s.topo.apex(h), s.topo.apex(h.twin()));
        s.topo.are_adjacent_within_either(c, d, ADJACENCY_LIMIT) == Some(false)
    }

    /// Saves what a split of `e` writes (the six half-edges of its two
    /// faces, the faces, and the vertex ends `ends` of `e` whose outgoing
    /// half-edge may move); returns the four edges around `e`. (A flip is
    /// saved by [`crate::mesh::Topology::flip_record`].)
    fn save_quad(&mut self, e: EdgeId, ends: &[VertexId]) -> [EdgeId; 4] {
        let topo = &self.s.topo;
        let (h, t) = (e.halfedge(), e.halfedge().twin());
        let [h2, h1, t2, t1] = topo.outer_halfedges(e);
        let faces = [topo.face(h), topo.face(t)];
        topo.save(&[h, t, h1, h2, t1, t2], &faces, ends, &mut self.journal);
        [h1.edge(), h2.edge(), t1.edge(), t2.edge()]
    }

    /// Flips `e`, saving what it changes; returns the four edges around
    /// it, or `None` past the flip budget.
    fn flip(&mut self, e: EdgeId) -> Option<[EdgeId; 4]> {
        if self.flips >= MAX_FLIPS_PER_TRY {
            return None;
        }
        let [h2, h1, t2, t1] = self.s.topo.outer_halfedges(e);
        let around = [h1.edge(), h2.edge(), t1.edge(), t2.edge()];
        self.journal.push(self.s.topo.flip_record(e));
        self.inputs.push((e, self.s.edge_input[e.idx()]));
        self.s.flip(e);
        self.flips += 1;
        self.touch([e]);
        self.touch(around);
        Some(around)
    }

    /// Records that the quads of `edges` changed: their Delaunay status
    /// must be found again.
    fn touch(&mut self, edges: impl IntoIterator<Item = EdgeId>) {
        let n = self.s.topo.n_edges();
        if self.verdict.len() < n {
            self.verdict.resize(n, None);
            self.in_touched.resize(n, false);
        }
        for e in edges {
            self.changes.push((e, self.verdict[e.idx()].take()));
            if !self.in_touched[e.idx()] {
                self.in_touched[e.idx()] = true;
                self.touched.push(e);
            }
        }
    }

    /// Drops what was touched after `mark` (undone, or a new try from the
    /// default mark), each edge touched since getting back the verdict it
    /// had at the mark. (At the default mark, the start of a try, no edge
    /// has one: every verdict comes from the try's `settle`, of an edge it
    /// touched.)
    fn rewind_touches(&mut self, mark: Mark) {
        let from = mark.changes.min(self.changes.len());
        for &(e, before) in self.changes[from..].iter().rev() {
            self.verdict[e.idx()] = before;
        }
        for &e in &self.touched[mark.touched.min(self.touched.len())..] {
            if let Some(t) = self.in_touched.get_mut(e.idx()) {
                *t = false;
            }
        }
        self.changes.truncate(mark.changes);
        self.touched.truncate(mark.touched);
    }

    /// Splits `e` at parameter `t` of its input edge, saving what it changes.
    fn split(&mut self, e: EdgeId, t: f64) {
        // Lengths first: undone last, after the entries of the quad.
        self.journal.push(self.s.topo.lengths());
        let end = [self.s.topo.dest(e.halfedge())];
        let around = self.save_quad(e, &end);
        let n = self.s.topo.n_edges() as u32;
        self.s.split(e, t);
        self.splits += 1;
        self.touch([e, EdgeId(n), EdgeId(n + 1), EdgeId(n + 2)]);
        self.touch(around);
    }

    /// Flips the touched edges' regions back to Delaunay (Lawson, each edge
    /// at most once in the stack at a time). Returns the first touched edge
    /// still non-Delaunay, or `Err` if the attempt cannot succeed: past the
    /// flip budget, or once more non-flippable edges are found non-Delaunay
    /// than the `splits_left` splits the budget leaves.
    ///
    /// Such an edge stays non-Delaunay until a vertex is added on it, so
    /// each needs a split of its own. Its quad changes only when a face
    /// beside it does, and each such change gives it, on that side, an apex
    /// that sees it under a larger angle: a flip of another edge g of the
    /// face, made because g's other apex y lies inside the face's
    /// circumcircle (on the same side of the edge as the old apex c, which
    /// lies on that circle), or a split of g, whose new vertex lies on g,
    /// inside the circle too. So its opposite angles only grow.
    ///
    /// ```text
    ///     c ------- y          c ------- y
    ///     |  \      |          |      /  |     g = c-b flipped to a-y:
    ///     |    g    |   ==>    |    /    |     the apex of a-b moves from
    ///     |      \  |          |  /      |     c to y
    ///     a ------- b          a ------- b
    /// ```
    ///
    /// Debug builds (every test) do not stop there: they settle to the end,
    /// check that each such edge is still non-Delaunay, and flag the attempt
    /// ([`Pruner::doomed`]) for the callers to check that it fails.
    ///
    /// Edges whose status is known ([`Pruner::verdict`]) are not taken
    /// again when nothing changed them since they were found Delaunay, or
    /// non-Delaunay and not flippable: taking them would do nothing, and
    /// leaving them out of the stack keeps the order of the others, and the
    /// result. (Whether a flip is valid can change without the edge's quad
    /// changing, so flippable ones are taken again.)
    fn settle(&mut self, splits_left: usize) -> Result<Option<EdgeId>, ()> {
        self.stack.clear();
        let n = self.s.topo.n_edges();
        if self.queued.len() < n {
            self.queued.resize(n, false);
        }
        if self.verdict.len() < n {
            self.verdict.resize(n, None);
        }
        // The non-flippable edges found non-Delaunay (only debug builds go
        // past `splits_left` of them).
        let mut found = FixedBad::default();
        for i in 0..self.touched.len() {
            let e = self.touched[i];
            // Skipped: an edge found Delaunay, or non-Delaunay but not
            // flippable, since it last changed (taking it would do nothing).
            // A flippable non-Delaunay one is taken again: its flip may have
            // become valid (a c-d edge elsewhere flipped away).
            let settled = match self.verdict[e.idx()] {
                None => false,
                Some(bad) => !bad || !self.s.is_flippable(e),
            };
            if settled
                && self.verdict[e.idx()] == Some(true)
                && !self.s.topo.is_dead_edge(e)
                && (found.add(e, splits_left) || !self.s.topo.is_interior(e))
            {
                self.unqueue_all();
                return Err(());
            }
            if !self.queued[e.idx()] && !settled {
                self.queued[e.idx()] = true;
                self.stack.push(e);
            }
        }
        while let Some(e) = self.stack.pop() {
            self.queued[e.idx()] = false;
            if self.s.topo.is_dead_edge(e) {
                continue;
            }
            let bad = self.s.is_non_delaunay(e, ALGORITHM_TOLERANCE);
            self.verdict[e.idx()] = Some(bad);
            if !bad {
                continue;
            }
            if !self.s.is_flippable(e) {
                // A boundary edge facing an obtuse angle (`gabriel_boundary`
                // only) would need a split on the boundary, which pruning
                // does not make: the attempt fails.
                if found.add(e, splits_left) || !self.s.topo.is_interior(e) {
                    self.unqueue_all();
                    return Err(());
                }
                continue;
            }
            if !self.s.flip_is_valid(e) {
                continue;
            }
            let Some(around) = self.flip(e) else {
                self.unqueue_all();
                return Err(());
            };
            for x in around {
                if !self.queued[x.idx()] {
                    self.queued[x.idx()] = true;
                    self.stack.push(x);
                }
            }
        }
        // Debug builds (every test) check that every verdict kept is what
        // the test says now.
        #[cfg(debug_assertions)]
        for &e in &self.touched {
            if let (false, Some(bad)) = (self.s.topo.is_dead_edge(e), self.verdict[e.idx()]) {
                assert_eq!(bad, self.s.is_non_delaunay(e, ALGORITHM_TOLERANCE), "stale verdict");
            }
        }
        let s = &*self.s;
        let verdict = &self.verdict;
        let first_bad = (self.touched.iter().copied()).find(|&e| {
            !s.topo.is_dead_edge(e) && verdict[e.idx()].unwrap_or_else(|| s.is_non_delaunay(e, ALGORITHM_TOLERANCE))
        });
        // (Debug builds check the claim above.)
        #[cfg(debug_assertions)]
        for &e in found.edges() {
            assert!(
                s.is_non_delaunay(e, ALGORITHM_TOLERANCE),
                "flips mended a non-flippable edge"
            );
        }
        self.doomed |= found.count > splits_left;
        Ok(first_bad)
    }

    /// Empties the stack of [`Pruner::settle`] when it stops early.
    fn unqueue_all(&mut self) {
        for &x in &self.stack {
            self.queued[x.idx()] = false;
        }
        self.stack.clear();
    }

    /// Algorithm 2 on the touched edges, with at most `budget` splits in the
    /// whole attempt; `true` if every touched edge ends Delaunay. Splits
    /// wait until no flip is left to do: flips change the apexes of the
    /// non-flippable edges, and so where their samples are taken.
    fn refine_locally(&mut self, budget: usize) -> bool {
        loop {
            let bad = match self.settle(budget.saturating_sub(self.splits)) {
                Err(()) => return false,
                Ok(None) => {
                    debug_assert!(!self.doomed, "a local refinement found hopeless ended Delaunay");
                    return true;
                }
                Ok(Some(bad)) => bad,
            };
            if self.splits >= budget || self.s.is_flippable(bad) {
                return false;
            }
            let Some(choice) = refine::choose_sample(self.s, &self.constants, &self.options, bad) else {
                return false;
            };
            self.split(bad, choice.t);
        }
    }

    /// After removing vertices: settles, then, for each of the first few
    /// edges left non-Delaunay, splits it at each candidate sample in turn
    /// ([`Pruner::candidates`]) and refines on, with at most `budget` splits
    /// in all; keeps the first that ends Delaunay.
    fn rebuild(&mut self, budget: usize) -> Attempt {
        match self.settle(budget.saturating_sub(self.splits)) {
            Err(()) => return Attempt::Failed,
            Ok(None) => return Attempt::Kept,
            Ok(Some(_)) if budget == 0 => return Attempt::Failed,
            Ok(Some(_)) => {}
        }
        // Splits the ids have no room for (a mesh of hundreds of millions of
        // faces, refined up to that room) are not tried.
        if self.s.topo.split_room() < budget.saturating_sub(self.splits) {
            return Attempt::Failed;
        }
        // (More non-flippable edges non-Delaunay than splits left made the
        // settle fail: see `FixedBad`.)
        let left = self.left_after_settle();
        let mark = self.mark();
        // Splits the budget leaves after the first.
        let after_first = budget.saturating_sub(self.splits + 1);
        // The first non-flippable edges left non-Delaunay, in the order
        // touched: `left` has found them.
        for &bad in &left.edges()[..left.edges().len().min(FIRST_SPLITS)] {
            let candidates = self.candidates(bad);
            for &t in candidates.as_slice() {
                if self.split_is_doomed(bad, t, &left, after_first) {
                    // Debug builds (every test) check the claim: the trial
                    // itself fails, and leaves nothing behind once undone.
                    #[cfg(debug_assertions)]
                    {
                        self.split(bad, t);
                        assert!(!self.refine_locally(budget), "a doomed split ended Delaunay");
                        self.undo_to(mark);
                    }
                    continue;
                }
                self.split(bad, t);
                if self.refine_locally(budget) {
                    debug_assert!(!self.doomed, "an attempt found hopeless ended Delaunay");
                    return Attempt::Kept;
                }
                self.undo_to(mark);
            }
        }
        Attempt::Failed
    }

    /// The non-flippable touched edges left non-Delaunay just after
    /// [`Pruner::settle`], in the order touched: each needs a split of its
    /// own (see [`FixedBad`]).
    fn left_after_settle(&self) -> FixedBad {
        let s = &*self.s;
        let mut left = FixedBad::default();
        for &e in &self.touched {
            let bad = || self.verdict[e.idx()].unwrap_or_else(|| s.is_non_delaunay(e, ALGORITHM_TOLERANCE));
            if !s.topo.is_dead_edge(e) && !s.is_flippable(e) && bad() {
                left.note(e);
            }
        }
        left
    }

    /// Whether splitting the non-flippable edge `bad` at `t` certainly
    /// leaves more edges non-Delaunay than the `splits_after` splits the
    /// budget leaves can mend: then the trial would fail, and is skipped
    /// (the result is the same, only sooner). `left`: what the settle before
    /// it left ([`Pruner::left_after_settle`]). Six edges are looked at,
    /// those whose quads the split makes:
    ///
    /// ```text
    ///          x1     x0
    ///           \ c  /          the halves a-p, p-b; the outer edges
    ///        b ---p--- a        a-c, c-b, b-d, d-a with the apexes
    ///           / d  \          x0..x3 beyond them
    ///          x2     x3
    /// ```
    ///
    /// The halves are not flippable (as `bad` is not). A non-flippable edge
    /// of the six that the split leaves non-Delaunay, with the apexes it has
    /// then, stays so until a vertex is added on it (see
    /// [`Pruner::settle`]): each needs a split of its own, as does each other
    /// edge in `left`. The test here is the one `settle` makes, on the same
    /// four positions (it is symmetric in the edge's ends and in its apexes).
    fn split_is_doomed(&self, bad: EdgeId, t: f64, left: &FixedBad, splits_after: usize) -> bool {
        // The other edges already waiting for a split of their own.
        let others = left.count.saturating_sub(1);
        if others > splits_after {
            return true;
        }
        let s = &*self.s;
        let topo = &s.topo;
        let [a, b, c, d] = s.edge_quad(bad);
        let [e0, e1] = s.input_edge_ends(s.edge_input[bad.idx()]);
        let p = point_on_edge(e0, e1, t);
        let bad_edge = |q: [DVec3; 4]| geometry::is_non_delaunay(q[0], q[1], q[2], q[3], ALGORITHM_TOLERANCE);
        let mut needed = others;
        // The halves a-p and p-b.
        for quad in [[a, p, c, d], [p, b, c, d]] {
            if bad_edge(quad) {
                needed += 1;
                if needed > splits_after {
                    return true;
                }
            }
        }
        // Outer edge i runs between `ends[i]`; its new apex on this side is p.
        let outer = topo.outer_halfedges(bad); // c→a, b→c, d→b, a→d
        let ends = [[c, a], [b, c], [d, b], [a, d]];
        for i in 0..4 {
            let beyond = outer[i].twin();
            if s.is_flippable(outer[i].edge()) || topo.face(beyond).is_none() {
                continue;
            }
            let apex = s.positions[topo.apex(beyond).idx()];
            if !left.edges().contains(&outer[i].edge()) && bad_edge([ends[i][0], ends[i][1], p, apex]) {
                needed += 1;
                if needed > splits_after {
                    return true;
                }
            }
        }
        false
    }

    /// Where to split the non-flippable edge `bad`: the sample each of
    /// [`VARIANTS`] would choose, then a few samples spread along it (the six
    /// conditions the scores weigh see only the quad, not the other vertices
    /// around), then the middle of the stretch where score 2 is best, which
    /// need not be a sample ([`samples::best_interval_middle`]); each
    /// parameter once.
    fn candidates(&self, bad: EdgeId) -> Candidates {
        let mut ts = Candidates::default();
        // One query and one cut into pieces for all variants (the unfolding
        // and the searches are most of the cost: only the scoring differs).
        // A parameter already listed passed `split_is_valid`, so it is not
        // tested again; the middle of the sub-edge is the same for all.
        // `between`: the middle of the best stretch for score 2, which need
        // not be a sample, tried last.
        let mut between = None;
        refine::with_split_query(self.s, &self.constants, bad, true, |q| {
            q.score = Score::AlwaysCenter;
            between = samples::best_interval_middle(q);
            let Some(pieces) = Pieces::new(q) else {
                return; // no sample inside the sub-edge
            };
            let valid = |t: f64| self.s.split_is_valid(bad, t);
            let mut middle = None;
            for (score, median) in VARIANTS {
                q.score = score;
                q.median = median;
                let t = pieces.choose(q).t;
                let t = if ts.contains(t) || valid(t) {
                    t
                } else {
                    match *middle.get_or_insert_with(|| Some(pieces.middle().t).filter(|&t| valid(t))) {
                        Some(t) => t,
                        None => continue,
                    }
                };
                if !ts.contains(t) {
                    ts.push(t);
                }
            }
        });
        let input = self.s.edge_input[bad.idx()];
        let h = bad.halfedge();
        let (a, b) = (self.s.topo.origin(h), self.s.topo.dest(h));
        let (ta, tb) = (self.s.param_on(a, input), self.s.param_on(b, input));
        let (lo, hi) = (ta.min(tb), ta.max(tb));
        let ends = self.s.input_edge_ends(input);
        let samples = EdgeSamples::new((ends[1] - ends[0]).length(), &self.constants);
        let (pa, pb) = (self.s.positions[a.idx()], self.s.positions[b.idx()]);
        for f in SPREAD {
            let t = samples.t(samples.nearest(lo + f * (hi - lo)));
            let p = point_on_edge(ends[0], ends[1], t);
            if t > lo && t < hi && !ts.contains(t) && p != pa && p != pb && self.s.split_is_valid(bad, t) {
                ts.push(t);
            }
        }
        if let Some(t) = between {
            let p = point_on_edge(ends[0], ends[1], t);
            if !ts.contains(t) && p != pa && p != pb && self.s.split_is_valid(bad, t) {
                ts.push(t);
            }
        }
        ts
    }
}

/// The split parameters [`Pruner::candidates`] lists, in order, each once
/// (a fixed array: this runs for every removal attempt).
#[derive(Default)]
struct Candidates {
    ts: [f64; VARIANTS.len() + SPREAD.len() + 1],
    len: usize,
}

impl Candidates {
    fn contains(&self, t: f64) -> bool {
        self.ts[..self.len].contains(&t)
    }

    fn push(&mut self, t: f64) {
        self.ts[self.len] = t;
        self.len += 1;
    }

    fn as_slice(&self) -> &[f64] {
        &self.ts[..self.len]
    }
}

/// Distinct non-flippable edges found non-Delaunay, by a settle as it goes
/// or after it ([`Pruner::left_after_settle`]): the first few, in the order
/// noted, and how many.
///
/// Each lies between two regions, and stays non-Delaunay until a vertex is
/// added on it: flips and splits beside it only give it apexes that see it
/// under larger angles (see [`Pruner::settle`], which fails as soon as there
/// are more of them than splits left). So each needs a split of its own.
struct FixedBad {
    edges: [EdgeId; MAX_GROUP + 1],
    count: usize,
}

impl Default for FixedBad {
    fn default() -> Self {
        FixedBad {
            edges: [EdgeId::NONE; MAX_GROUP + 1],
            count: 0,
        }
    }
}

impl FixedBad {
    /// Notes `e`, once while there is room for it (past the room, only the
    /// count grows).
    fn note(&mut self, e: EdgeId) {
        if self.edges().contains(&e) {
            return;
        }
        if let Some(slot) = self.edges.get_mut(self.count) {
            *slot = e;
        }
        self.count += 1;
    }

    /// [`FixedBad::note`], and whether a settle stops: more than
    /// `splits_left` noted, in release builds (debug builds go on, see
    /// [`Pruner::settle`]). `splits_left` is below the room kept, so the
    /// count is exact up to where it matters.
    fn add(&mut self, e: EdgeId, splits_left: usize) -> bool {
        debug_assert!(splits_left < self.edges.len());
        self.note(e);
        self.count > splits_left && !cfg!(debug_assertions)
    }

    /// The first ones noted.
    fn edges(&self) -> &[EdgeId] {
        &self.edges[..self.count.min(self.edges.len())]
    }
}

/// A point of the current attempt's journal.
#[derive(Clone, Copy, Default)]
struct Mark {
    journal: usize,
    inputs: usize,
    touched: usize,
    changes: usize,
    splits: usize,
    flips: usize,
    detached: usize,
    doomed: bool,
}

/// How one removal attempt ended.
enum Attempt {
    /// Kept: the mesh is Delaunay with fewer vertices.
    Kept,
    /// Undo it; a larger group may still work.
    Failed,
    /// Undo it; there is no larger group to try.
    NoGroup,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each edge is counted once; past the room kept, only the count grows;
    /// a settle stops (release builds) once the count exceeds the splits
    /// left, never before.
    #[test]
    fn fixed_bad_edges_are_counted_once_each() {
        let mut found = FixedBad::default();
        for (i, e) in [3, 3, 7, 3, 7].into_iter().enumerate() {
            assert!(!found.add(EdgeId(e), 2), "add {i}");
        }
        assert_eq!(found.count, 2);
        assert_eq!(found.edges(), &[EdgeId(3), EdgeId(7)]);
        // The third distinct edge is one more than two splits can mend.
        assert_eq!(found.add(EdgeId(9), 2), !cfg!(debug_assertions));
        assert_eq!(found.count, 3);
        for e in [11, 12, 13] {
            found.add(EdgeId(e), 2);
        }
        assert_eq!(found.count, 6);
        assert_eq!(found.edges(), &[EdgeId(3), EdgeId(7), EdgeId(9), EdgeId(11)]);
        // With no split left, the first one ends the settle.
        let mut found = FixedBad::default();
        assert_eq!(found.add(EdgeId(5), 0), !cfg!(debug_assertions));
    }
}
