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
//! all, then runs Algorithm 2 locally (several sample choices in turn) with a
//! budget of one split fewer than it removed. Only added vertices
//! are ever removed, and new ones are samples of input edges, so the geometry
//! stays exactly the input's.
//!
//! ```text
//!        x1   x2                 x1---x2              x
//!         \   /                   \   /             /   \
//!     u----p----w   ==>   u-------p----w   ==>   u-------w
//!         /  \                     /  \            \   /
//!       y1    y2                 y1----y2            y
//! ```

use crate::geometry::ALGORITHM_TOLERANCE;
use crate::mesh::{Carrier, EdgeId, HalfEdgeId, Saved, Surface, VertexId};
use crate::refine::{self, Options};
use crate::samples::{point_on_edge, EdgeSamples, SampleConstants, Score};

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
/// finds what earlier removals made possible).
const MAX_PASSES: usize = 8;

/// Removes added vertices of the Delaunay mesh `surface` wherever it stays
/// Delaunay with fewer, and compacts the mesh (the remaining vertices keep
/// their order). `surface` must be the result of a successful
/// [`crate::make_delaunay`]; `options` choose the samples of the local
/// re-refinements (their work limit is not used).
pub fn prune(surface: &mut Surface, options: &Options) -> PruneStats {
    let constants = refine::sample_constants(surface);
    let mut run = Pruner {
        constants,
        options: *options,
        s: surface,
        journal: Vec::new(),
        inputs: Vec::new(),
        touched: Vec::new(),
        stack: Vec::new(),
        queued: Vec::new(),
        stats: PruneStats::default(),
        flips: 0,
        splits: 0,
        detached: 0,
        dirty: Vec::new(),
    };
    let first_added = run.s.n_input_vertices;
    // After the first pass, only vertices near a kept change can have become
    // removable.
    run.dirty = vec![true; run.s.topo.n_vertices()];
    while run.stats.passes < MAX_PASSES {
        run.stats.passes += 1;
        let before = run.stats.removed;
        // Newest first: a vertex added late was placed knowing the others.
        for v in (first_added..run.s.topo.n_vertices()).rev() {
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

struct Pruner<'a> {
    s: &'a mut Surface,
    constants: SampleConstants,
    options: Options,
    /// Topology entries to restore if the current attempt fails.
    journal: Vec<Saved>,
    /// Input-edge labels to restore (flips clear them).
    inputs: Vec<(EdgeId, u32)>,
    /// Edges whose Delaunay status the attempt may have changed.
    touched: Vec<EdgeId>,
    stack: Vec<EdgeId>,
    /// Whether each edge is in `stack`.
    queued: Vec<bool>,
    stats: PruneStats,
    /// Flips of the current attempt.
    flips: usize,
    /// Splits of the current attempt.
    splits: usize,
    /// Vertices removed by the current attempt.
    detached: usize,
    /// Vertices worth trying (again) in the next pass.
    dirty: Vec<bool>,
}

impl Pruner<'_> {
    /// Tries to remove `p` alone, then to replace it and the next added
    /// vertices along its input edge, or it and one added neighbour, by one
    /// vertex fewer; keeps the first attempt that succeeds.
    fn try_remove(&mut self, p: VertexId) {
        let Carrier::Edge { edge: input, .. } = self.s.carriers[p.idx()] else {
            return;
        };
        for group in 1..=MAX_GROUP {
            match self.attempt(|me| me.replace(p, input, group)) {
                Attempt::Kept => return,
                Attempt::Failed => {}
                Attempt::NoGroup => break,
            }
        }
        // Pairs: p and an added neighbour (often a vertex that a split at p
        // made necessary) replaced by one vertex; then triples: p and two
        // added neighbours replaced by two.
        let mut neighbours = self.added_neighbours(p);
        let at = self.s.positions[p.idx()];
        neighbours.sort_by(|&a, &b| {
            let da = self.s.positions[a.idx()].distance_squared(at);
            da.total_cmp(&self.s.positions[b.idx()].distance_squared(at))
        });
        for (i, &q1) in neighbours.iter().enumerate() {
            if self.try_replace(&[(p, input), (q1, 0)]) {
                return;
            }
            if i >= TRIPLE_NEIGHBOURS {
                continue;
            }
            for &q2 in &neighbours[i + 1..neighbours.len().min(TRIPLE_NEIGHBOURS)] {
                if self.try_replace(&[(p, input), (q1, 0), (q2, 0)]) {
                    return;
                }
            }
        }
    }

    /// One attempt at replacing the added vertices `group` (with their input
    /// edges; 0 = read from the carrier) by one vertex fewer.
    fn try_replace(&mut self, group: &[(VertexId, u32)]) -> bool {
        let r = self.attempt(|me| {
            for &(v, input) in group {
                let input = match me.s.carriers[v.idx()] {
                    Carrier::Edge { edge, .. } if input == 0 || edge == input => edge,
                    _ => return Attempt::Failed,
                };
                if !me.detach(v, input) {
                    return Attempt::Failed;
                }
            }
            me.rebuild(group.len() - 1)
        });
        matches!(r, Attempt::Kept)
    }

    /// The added vertices joined to `p` by an edge.
    fn added_neighbours(&self, p: VertexId) -> Vec<VertexId> {
        let topo = &self.s.topo;
        let first = topo.vertex_he(p);
        let mut h = first;
        let mut out = Vec::new();
        loop {
            let v = topo.dest(h);
            if v.idx() >= self.s.n_input_vertices {
                out.push(v);
            }
            h = topo.rotate_ccw(h);
            if h.is_none() || h == first {
                return out;
            }
        }
    }

    /// Runs one attempt from a clean journal; keeps it or undoes it.
    fn attempt(&mut self, f: impl FnOnce(&mut Self) -> Attempt) -> Attempt {
        self.journal.clear();
        self.inputs.clear();
        self.touched.clear();
        self.flips = 0;
        self.splits = 0;
        self.stats.tried += 1;
        let r = f(self);
        if let Attempt::Kept = r {
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
                    self.dirty[v.idx()] = true;
                    for w in self.added_neighbours(v) {
                        self.dirty[w.idx()] = true;
                    }
                }
            }
        } else {
            self.undo_to(Mark::default());
        }
        self.detached = 0;
        r
    }

    /// Where the current attempt stands, to undo back to.
    fn mark(&self) -> Mark {
        Mark {
            journal: self.journal.len(),
            inputs: self.inputs.len(),
            touched: self.touched.len(),
            splits: self.splits,
            flips: self.flips,
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
        self.touched.truncate(mark.touched);
        self.splits = mark.splits;
        self.flips = mark.flips;
        let topo = &self.s.topo;
        let (nv, ne, nf) = (topo.n_vertices(), topo.n_edges(), topo.n_faces());
        self.s.positions.truncate(nv);
        self.s.carriers.truncate(nv);
        self.s.edge_input.truncate(ne);
        self.s.face_region.truncate(nf);
    }

    /// Removes `p` and the `group - 1` added vertices after it along `input`,
    /// then refines locally with at most `group - 1` splits.
    fn replace(&mut self, p: VertexId, input: u32, group: usize) -> Attempt {
        let mut v = p;
        for i in 0..group {
            let Some([_, to_w]) = self.along_input(v, input) else {
                return Attempt::NoGroup;
            };
            let next = self.s.topo.dest(to_w);
            if !self.detach(v, input) {
                return Attempt::Failed;
            }
            if i + 1 < group {
                if !matches!(self.s.carriers[next.idx()], Carrier::Edge { edge, .. } if edge == input) {
                    return Attempt::NoGroup;
                }
                v = next;
            }
        }
        self.rebuild(group - 1)
    }

    /// Flips `p` down to degree four and merges its two sub-edges, saving
    /// every change; `false` if that cannot be done.
    fn detach(&mut self, p: VertexId, input: u32) -> bool {
        let Some([to_u, to_w]) = self.along_input(p, input) else {
            return false;
        };
        for side_start in [to_u, to_w] {
            if !self.reduce_side(p, input, side_start) {
                return false;
            }
        }
        let (u, w) = (self.s.topo.dest(to_u), self.s.topo.dest(to_w));
        if self.s.topo.are_adjacent_within(u, w, 64) != Some(false) {
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
            self.touched.extend([h.edge(), n.edge(), self.s.topo.next(n).edge()]);
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
            if !self.flip(h.edge()) {
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
        s.topo.are_adjacent_within(c, d, 64) == Some(false)
    }

    /// Saves what a flip or a split of `e` writes (the six half-edges of its
    /// two faces, the faces, and the vertex ends `ends` of `e` whose outgoing
    /// half-edge may move); returns the four edges around `e`.
    fn save_quad(&mut self, e: EdgeId, ends: &[VertexId]) -> [EdgeId; 4] {
        let topo = &self.s.topo;
        let (h, t) = (e.halfedge(), e.halfedge().twin());
        let [h2, h1, t2, t1] = topo.outer_halfedges(e);
        let faces = [topo.face(h), topo.face(t)];
        topo.save(&[h, t, h1, h2, t1, t2], &faces, ends, &mut self.journal);
        [h1.edge(), h2.edge(), t1.edge(), t2.edge()]
    }

    /// Flips `e`, saving what it changes; `false` past the flip budget.
    fn flip(&mut self, e: EdgeId) -> bool {
        if self.flips >= MAX_FLIPS_PER_TRY {
            return false;
        }
        let h = e.halfedge();
        let ends = [self.s.topo.origin(h), self.s.topo.dest(h)];
        let around = self.save_quad(e, &ends);
        self.inputs.push((e, self.s.edge_input[e.idx()]));
        self.s.flip(e);
        self.flips += 1;
        self.touched.push(e);
        self.touched.extend(around);
        true
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
        self.touched.extend([e, EdgeId(n), EdgeId(n + 1), EdgeId(n + 2)]);
        self.touched.extend(around);
    }

    /// Flips the touched edges' regions back to Delaunay (Lawson, each edge
    /// at most once in the stack at a time). Returns the first touched edge
    /// still non-Delaunay, or `Err` past the flip budget.
    fn settle(&mut self) -> Result<Option<EdgeId>, ()> {
        self.stack.clear();
        let n = self.s.topo.n_edges();
        if self.queued.len() < n {
            self.queued.resize(n, false);
        }
        for i in 0..self.touched.len() {
            let e = self.touched[i];
            if !self.queued[e.idx()] {
                self.queued[e.idx()] = true;
                self.stack.push(e);
            }
        }
        while let Some(e) = self.stack.pop() {
            self.queued[e.idx()] = false;
            if self.s.topo.is_dead_edge(e)
                || !self.s.is_non_delaunay(e, ALGORITHM_TOLERANCE)
                || !self.s.is_flippable(e)
                || !self.s.flip_is_valid(e)
            {
                continue;
            }
            let before = self.touched.len();
            if !self.flip(e) {
                for &x in &self.stack {
                    self.queued[x.idx()] = false;
                }
                return Err(());
            }
            for i in before + 1..self.touched.len() {
                let x = self.touched[i];
                if !self.queued[x.idx()] {
                    self.queued[x.idx()] = true;
                    self.stack.push(x);
                }
            }
        }
        Ok((self.touched.iter().copied())
            .find(|&e| !self.s.topo.is_dead_edge(e) && self.s.is_non_delaunay(e, ALGORITHM_TOLERANCE)))
    }

    /// Algorithm 2 on the touched edges, with at most `budget` splits in the
    /// whole attempt; `true` if every touched edge ends Delaunay. A
    /// non-flippable edge may be bad for a while: a later flip can give it a
    /// better opposite vertex, so splits wait until no flip is left to do.
    fn refine_locally(&mut self, budget: usize) -> bool {
        loop {
            let bad = match self.settle() {
                Err(()) => return false,
                Ok(None) => return true,
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
        match self.settle() {
            Err(()) => return Attempt::Failed,
            Ok(None) => return Attempt::Kept,
            Ok(Some(_)) if budget == 0 => return Attempt::Failed,
            Ok(Some(_)) => {}
        }
        let mut bad_edges: Vec<EdgeId> = Vec::new();
        for &e in &self.touched {
            if bad_edges.len() == FIRST_SPLITS {
                break;
            }
            if !self.s.topo.is_dead_edge(e)
                && !bad_edges.contains(&e)
                && !self.s.is_flippable(e)
                && self.s.is_non_delaunay(e, ALGORITHM_TOLERANCE)
            {
                bad_edges.push(e);
            }
        }
        let mark = self.mark();
        for bad in bad_edges {
            for t in self.candidates(bad) {
                self.split(bad, t);
                if self.refine_locally(budget) {
                    return Attempt::Kept;
                }
                self.undo_to(mark);
            }
        }
        Attempt::Failed
    }

    /// Where to split the non-flippable edge `bad`: the sample each of
    /// [`VARIANTS`] would choose, then a few samples spread along it (the six
    /// conditions the scores weigh see only the quad, not the other vertices
    /// around); each parameter once.
    fn candidates(&self, bad: EdgeId) -> Vec<f64> {
        let mut ts: Vec<f64> = Vec::with_capacity(VARIANTS.len() + SPREAD.len());
        for (score, median) in VARIANTS {
            let options = Options {
                score,
                median,
                ..self.options
            };
            if let Some(choice) = refine::choose_sample(self.s, &self.constants, &options, bad) {
                if !ts.contains(&choice.t) {
                    ts.push(choice.t);
                }
            }
        }
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
            if t > lo && t < hi && !ts.contains(&t) && p != pa && p != pb && self.s.split_is_valid(bad, t) {
                ts.push(t);
            }
        }
        ts
    }
}

/// A point of the current attempt's journal.
#[derive(Clone, Copy, Default)]
struct Mark {
    journal: usize,
    inputs: usize,
    touched: usize,
    splits: usize,
    flips: usize,
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
