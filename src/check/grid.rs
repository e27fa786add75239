//! The spatial hash over pieces of the input edges, with octrees in crowded cells, that finds
//! the input edges containing a point.

use super::*;

/// A spatial hash over the input edges: every edge is cut into pieces no longer than the cell
/// size, and each piece (its bounding box grown by twice the edge's tolerance) is registered in
/// every cell it overlaps. Cells are hashed into a table of buckets stored as one flat array (CSR).
///
/// Crowded cells where output points fall (around a vertex of high valence, which every one of
/// its edges crosses) are refined by octrees, [`CellTrees`]: a point there is tested against the
/// edges of its leaf instead of the whole bucket.
///
/// Cell coordinates are computed in a frame scaled by an exact power of two (`scale`, 1 unless
/// coordinates exceed 2^1000), so that no difference of coordinates can overflow.
pub(super) struct EdgeGrid {
    pub(super) frame: GridFrame,
    pub(super) mask: usize,
    pub(super) starts: Vec<usize>,
    pub(super) items: Vec<u32>,
    pub(super) trees: CellTrees,
}

/// The geometry of an [`EdgeGrid`], in the scaled frame `q = p * scale`.
pub(super) struct GridFrame {
    pub(super) scale: f64,
    /// Lowest corner of the edges' bounding box, in the scaled frame.
    pub(super) origin: DVec3,
    /// Cell size in the scaled frame.
    pub(super) cell: f64,
    /// Deepest level of the [`CellTrees`]: at most [`TREE_DEPTH`], and cells of that level
    /// (`cell / 2^depth`) stay at least four times the largest edge tolerance.
    pub(super) depth_limit: u32,
}

impl GridFrame {
    /// Chooses the frame for the edges that [`can_contain_points`]. The cell size is the median
    /// edge length, but at least a quarter of the mean length (so long edges make at most 5E
    /// pieces in total), at least four times the largest edge tolerance (so a grown piece spans
    /// at most 3 cells per axis) and at least `1e-9` of the extent (so cell coordinates stay far
    /// inside `i64`).
    pub(super) fn new(mesh: &Mesh3, edges: &[Edge]) -> GridFrame {
        let usable = || {
            edges
                .iter()
                .map(|e| (mesh.positions[e.lo as usize], mesh.positions[e.hi as usize]))
                .filter(|&segment| can_contain_points(segment))
        };
        let largest = usable()
            .map(|(a, b)| a.abs().max(b.abs()).max_element())
            .fold(0.0, f64::max);
        let scale = if largest > 2f64.powi(1000) { 2f64.powi(-24) } else { 1.0 };
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        let mut lengths = Vec::new();
        for (a, b) in usable() {
            let (a, b) = (a * scale, b * scale);
            lo = lo.min(a).min(b);
            hi = hi.max(a).max(b);
            lengths.push((b - a).length());
        }
        if lengths.is_empty() {
            return GridFrame {
                scale,
                origin: DVec3::ZERO,
                cell: 1.0,
                depth_limit: 0,
            };
        }
        let mean = lengths.iter().sum::<f64>() / lengths.len() as f64;
        let mid = lengths.len() / 2;
        let median = *lengths.select_nth_unstable_by(mid, f64::total_cmp).1;
        let smallest = 4.0 * ON_EDGE_TOLERANCE * largest.max(1e-300) * scale;
        let mut cell = median.max(mean / 4.0).max(smallest).max((hi - lo).max_element() * 1e-9);
        if !(cell.is_finite() && cell > 0.0 && (1.0 / cell).is_finite()) {
            cell = 1.0;
        }
        let depth_limit = (0..TREE_DEPTH)
            .take_while(|&d| cell / (2u64 << d) as f64 >= smallest)
            .count() as u32;
        GridFrame {
            scale,
            origin: lo,
            cell,
            depth_limit,
        }
    }

    /// Integer cell coordinates of a point (monotone in each coordinate).
    pub(super) fn cell_of(&self, p: DVec3) -> [i64; 3] {
        self.fine_cell(p, 0)
    }

    /// Integer coordinates of a point in the cells of level `depth` of the [`CellTrees`]
    /// (`cell / 2^depth`; level 0 is the grid's): monotone in each coordinate, and a point in
    /// cell `k` of level `d` is in cell `2k` or `2k + 1` of level `d + 1`, per axis (the scaled
    /// coordinate is multiplied by a power of two, exactly, before rounding down).
    fn fine_cell(&self, p: DVec3, depth: u32) -> [i64; 3] {
        let q = (p * self.scale - self.origin) / self.cell * (1u64 << depth) as f64;
        [floor_to_i64(q.x), floor_to_i64(q.y), floor_to_i64(q.z)]
    }

    /// Which child of its node of level `depth - 1` holds a point (see [`TreeNode`]): the
    /// parities of its cell coordinates at level `depth`.
    fn child_of(&self, p: DVec3, depth: u32) -> usize {
        let c = self.fine_cell(p, depth);
        (0..3).map(|axis| ((c[axis] & 1) as usize) << axis).sum()
    }

    /// How many pieces edge `(a, b)` is cut into at level 0 (each at most a cell long, unless
    /// the edge is longer than 10^7 cells).
    fn pieces(&self, (a, b): (DVec3, DVec3)) -> u64 {
        let length = (b - a).length() * self.scale;
        (length / self.cell).ceil().clamp(1.0, 1e7) as u64
    }
}

/// `x.floor() as i64` (saturating, and 0 for NaN), without calling `floor`: the conversion
/// truncates, and a negative non-integer is one above its floor.
pub(super) fn floor_to_i64(x: f64) -> i64 {
    let t = x as i64;
    if t as f64 > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// The point at `k / n` along edge `(a, b)`: where piece `k` of `n` equal pieces starts. Piece
/// `k` of `n` is the union of pieces `2k` and `2k + 1` of `2n`, and shares its ends with them
/// bit for bit (the same fractions, correctly rounded).
fn piece_end((a, b): (DVec3, DVec3), k: u64, n: u64) -> DVec3 {
    a.lerp(b, k as f64 / n as f64)
}

/// The bounding box of piece `k` of `n` equal pieces of edge `(a, b)`, grown by `grow`.
fn piece_box(segment: (DVec3, DVec3), k: u64, n: u64, grow: DVec3) -> (DVec3, DVec3) {
    let (p0, p1) = (piece_end(segment, k, n), piece_end(segment, k + 1, n));
    (p0.min(p1) - grow, p0.max(p1) + grow)
}

/// The growth of the pieces' boxes of edge `(a, b)`: twice its tolerance, which covers every
/// accepted point plus any rounding of the pieces.
fn piece_growth((a, b): (DVec3, DVec3)) -> DVec3 {
    DVec3::splat(2.0 * edge_tolerance(a, b))
}

impl EdgeGrid {
    /// Builds the hash (two passes over the edges: count, then fill), then the trees of its
    /// crowded cells where the `points` to be looked up fall (the trees' shape depends on them,
    /// what [`EdgeGrid::edges_containing`] returns does not).
    pub(super) fn new(mesh: &Mesh3, edges: &[Edge], points: &[DVec3]) -> EdgeGrid {
        let buckets = edges.len().max(64).next_power_of_two();
        let mut grid = EdgeGrid {
            frame: GridFrame::new(mesh, edges),
            mask: buckets - 1,
            starts: Vec::new(),
            items: Vec::new(),
            trees: CellTrees::default(),
        };
        let segment = |e: &Edge| (mesh.positions[e.lo as usize], mesh.positions[e.hi as usize]);
        let mut counts = vec![0usize; buckets + 1];
        for e in edges {
            grid.for_each_bucket(segment(e), |k| counts[k + 1] += 1);
        }
        for i in 1..counts.len() {
            counts[i] += counts[i - 1];
        }
        let mut next = counts.clone();
        let mut items = vec![0u32; counts[buckets]];
        for (i, e) in edges.iter().enumerate() {
            grid.for_each_bucket(segment(e), |k| {
                items[next[k]] = i as u32;
                next[k] += 1;
            });
        }
        grid.starts = counts;
        grid.items = items;
        grid.trees = CellTrees::new(&grid, mesh, edges, points);
        grid
    }

    /// The bucket of a cell: the cells of a block of 16 x 16 x 16 get buckets in one run of 4096
    /// (the low 12 bits), and blocks a well-mixed hash of their coordinates (the others), so that
    /// nearby pieces and points (edges and vertices come in file order, mostly near the previous
    /// ones) count and look up nearby buckets, which stay in cache. The low bits are the cell's
    /// place in its block XOR bits of the block's hash: a flat or thin mesh fills a few of each
    /// block's 4096 places, and blocks that share a run would otherwise pile into the same few
    /// buckets (`check` of a strip of 200,000 thin quads refined to 2 million faces took a
    /// quarter longer so).
    fn bucket(&self, c: [i64; 3]) -> usize {
        let low = (c[0] & 15) | (c[1] & 15) << 4 | (c[2] & 15) << 8;
        let block = c.map(|x| (x >> 4) as u64);
        let h = block[0].wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ block[1].wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
            ^ block[2].wrapping_mul(0x1656_67B1_9E37_79F9);
        let h = (h ^ (h >> 31)).wrapping_mul(0xD6E8_FEB8_6659_FD93);
        ((h ^ (h >> 32)) << 12 ^ (low as u64 ^ h >> 52)) as usize & self.mask
    }

    /// The edges registered in the bucket of a cell (an edge may come more than once).
    pub(super) fn bucket_items(&self, c: [i64; 3]) -> &[u32] {
        let k = self.bucket(c);
        &self.items[self.starts[k]..self.starts[k + 1]]
    }

    /// Calls `f` with the bucket of every cell overlapped by the grown pieces of edge `(a, b)`
    /// (a bucket may come more than once). Edges that cannot contain points are skipped.
    fn for_each_bucket(&self, segment: (DVec3, DVec3), mut f: impl FnMut(usize)) {
        self.for_each_cell(segment, |_, c| f(self.bucket(c)));
    }

    /// Calls `f(k, c)` for every piece `k` of edge `(a, b)` (of [`GridFrame::pieces`]) and every
    /// cell `c` its grown box overlaps. Edges that cannot contain points are skipped.
    fn for_each_cell(&self, segment: (DVec3, DVec3), mut f: impl FnMut(u64, [i64; 3])) {
        if !can_contain_points(segment) {
            return;
        }
        let grow = piece_growth(segment);
        let pieces = self.frame.pieces(segment);
        for k in 0..pieces {
            let (lo, hi) = piece_box(segment, k, pieces, grow);
            let (lo, hi) = (self.frame.cell_of(lo), self.frame.cell_of(hi));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        f(k, [x, y, z]);
                    }
                }
            }
        }
    }

    /// The input edges that may contain `p` (with repeats): those of its leaf where its cell is
    /// refined, else those of its cell's bucket. Every edge that contains `p` within its
    /// tolerance is among them.
    pub(super) fn candidates(&self, p: DVec3) -> &[u32] {
        let c = self.frame.cell_of(p);
        let bucket = self.bucket_items(c);
        if bucket.len() > CROWDED {
            if let Some(leaf) = self.trees.leaf(&self.frame, c, p) {
                return leaf;
            }
        }
        bucket
    }

    /// Fills `out` with the (sorted, unique) input edges that contain `p` and are nearest to it:
    /// of the edges within the on-edge tolerance, those within [`NEAREST_EDGE_SLACK`] of the
    /// smallest distance. A point computed on one edge is within roundoff of it; where another
    /// edge passes within the tolerance (near a shared vertex, or an edge nearly along it), that
    /// edge and its regions are not the point's: taking them as well let faces of one region be
    /// assigned to a nearly coplanar neighbour, and areas seem to move between them.
    pub(super) fn edges_containing(&self, mesh: &Mesh3, edges: &[Edge], p: DVec3, out: &mut Vec<u32>) {
        nearest_edges_containing(mesh, edges, self.candidates(p), p, out);
    }

    /// Fills `out` with the (sorted, unique) input boundary edges (one face) that contain `p`
    /// within the on-edge tolerance, nearest or not: where an output edge runs along the
    /// boundary is judged leniently, so that a point computed on a boundary edge near a needle's
    /// tip, nearer still to the needle's other edge, is not taken off the boundary.
    pub(super) fn boundary_edges_containing(&self, mesh: &Mesh3, edges: &[Edge], p: DVec3, out: &mut Vec<u32>) {
        out.clear();
        for &e in self.candidates(p) {
            let edge = &edges[e as usize];
            let (a, b) = (mesh.positions[edge.lo as usize], mesh.positions[edge.hi as usize]);
            if edge.is_boundary() && distance_on_edge(p, a, b).is_some() {
                out.push(e);
            }
        }
        out.sort_unstable();
        out.dedup();
    }
}

/// Of the `candidates` (input edges, repeats allowed), the ones that contain `p` and are nearest
/// to it, sorted and unique, into `out` (see [`EdgeGrid::edges_containing`]). The answer is the
/// same for every set of candidates that includes all the edges containing `p`.
pub(super) fn nearest_edges_containing(mesh: &Mesh3, edges: &[Edge], candidates: &[u32], p: DVec3, out: &mut Vec<u32>) {
    out.clear();
    let distance = |e: u32| {
        let edge = &edges[e as usize];
        let (a, b) = (mesh.positions[edge.lo as usize], mesh.positions[edge.hi as usize]);
        let slack = NEAREST_EDGE_SLACK * a.abs().max_element().max(b.abs().max_element());
        distance_on_edge(p, a, b).map(|d| (d, slack))
    };
    // The edges containing `p` and the nearest distance, then of those edges the ones near
    // it: the second pass computes again only the few distances of the edges found, and
    // nothing is allocated per point.
    let mut nearest = f64::INFINITY;
    for &e in candidates {
        if let Some((d, _)) = distance(e) {
            nearest = nearest.min(d);
            out.push(e);
        }
    }
    out.retain(|&e| distance(e).is_some_and(|(d, slack)| d <= nearest + slack));
    out.sort_unstable();
    out.dedup();
}

/// A bucket of an [`EdgeGrid`] with more entries than this is crowded: its cells where output
/// points fall get a [`CellTrees`] octree.
pub(super) const CROWDED: usize = 64;

/// A tree node with at most this many edges stays a leaf.
const LEAF_EDGES: usize = 32;

/// A tree node with at most this many points to look up stays a leaf: testing them against all
/// its edges costs less than dividing it.
const LEAF_POINTS: usize = 8;

/// The deepest level of a [`CellTrees`] octree (cells of `cell / 2^29`). Pieces of level `d`
/// number at most `10^7 * 2^d < 2^53` per edge, so their indices and fractions stay exact.
const TREE_DEPTH: u32 = 29;

/// Roots are cells less than this many cells from the grid's origin: the coordinates of their
/// points at the deepest level, below `(2^33 + 1) * 2^29`, stay exact in `f64` and within
/// `i64`, so that a point's cell at each level is one of the two halves, per axis, of its cell
/// at the level above.
const ROOT_RANGE: u64 = 1 << 33;

/// The spans of pieces that dividing tree nodes makes are at most this many per entry of the grid
/// and point looked up: the bound of the trees' memory.
pub(super) const TREE_BUDGET: usize = 8;

/// Octrees refining crowded cells of an [`EdgeGrid`]. A cell whose bucket holds more than
/// [`CROWDED`] entries and where more than [`LEAF_POINTS`] of the points to be looked up fall
/// becomes a root, holding the level-0 pieces of the edges whose grown boxes overlap it. A node
/// is divided into its eight half-size children while it holds more than [`LEAF_EDGES`] edges
/// and more than [`LEAF_POINTS`] points, above the frame's `depth_limit`: every piece longer
/// than the children is cut in two halves (the pieces of the next level; pieces of level 0 are
/// at most a cell long, unless the edge is longer than 10^7 cells), and each piece goes to every
/// child that its box, grown by twice the edge's tolerance as in the grid, overlaps in the cells
/// of the next level. A node keeps the pieces of one edge as one [`Span`], from the first to the
/// last that overlap it (the ones between, if any do not, are kept too): a few pieces, since
/// they are not much shorter than the node unless the edge is. Only the children where points
/// fall are built: a point in another child, like a point in a cell that is not a root, is
/// tested against its cell's bucket. The trees' shape depends on the points; the edges found
/// never do.
///
/// Conservative like the grid: an edge containing a point within its tolerance has, at every
/// level, a piece whose grown box contains the point (the pieces of a level cover the edge, and
/// the box is grown by twice the tolerance); cell coordinates are monotone, so at every depth the
/// point's cell is within the range of cells of such a box. The root holds such a piece of level
/// 0, as the grid does; if a node holds such a piece, the piece itself, or the one of its halves
/// that contains the point, goes to the point's child. By induction, the point's leaf holds the
/// edge.
///
/// Memory, linear in the grid's entries `G` and the points `P`: the roots hold at most one span
/// per entry of the grid, and nodes are divided only while the spans made by dividing stay
/// within `TREE_BUDGET * (G + P)` (dividing a node of `m` spans makes at most `8 m`, one per
/// edge and child), so at most `(1 + TREE_BUDGET) * (G + P)` spans are ever made; the leaves
/// keep one edge per span; a division makes eight nodes and needs more than [`LEAF_EDGES`]
/// spans. While the trees are built, each point is in one node waiting to be built.
#[derive(Default)]
pub(super) struct CellTrees {
    /// The root node of each refined cell.
    pub(super) roots: FastMap<[i64; 3], usize>,
    pub(super) nodes: Vec<TreeNode>,
    /// The edges of the leaves (unique per leaf).
    pub(super) edges: Vec<u32>,
    /// How many pieces the divisions placed in children (a measure of the work, for the tests).
    #[cfg(test)]
    pub(super) pieces_placed: usize,
}

/// A node of [`CellTrees`]: a leaf (`children == 0`) with edges `edges[start..end]`, or an inner
/// node whose children are `children + i`, where bits 0, 1, 2 of `i` say whether the child is
/// the upper half in x, y, z.
#[derive(Clone, Copy)]
pub(super) struct TreeNode {
    children: usize,
    pub(super) start: usize,
    pub(super) end: usize,
}

impl TreeNode {
    /// A leaf where no point fell when the trees were built: it keeps no edges, and a point
    /// there is tested against its cell's bucket.
    const UNREFINED: TreeNode = TreeNode {
        children: 0,
        start: usize::MAX,
        end: usize::MAX,
    };
}

/// Pieces `first..=last` of an input edge, of its `pieces << level` equal pieces (see
/// [`GridFrame::pieces`]).
#[derive(Clone, Copy)]
struct Span {
    pub(super) edge: u32,
    pub(super) level: u32,
    pub(super) first: u64,
    pub(super) last: u64,
}

/// A tree node waiting to be built: its index, level, cell coordinates at that level, spans
/// (one per edge) and points.
struct Pending {
    node: usize,
    depth: u32,
    pub(super) cell: [i64; 3],
    spans: Vec<Span>,
    pub(super) points: Vec<DVec3>,
}

impl Pending {
    /// A node with nothing in it yet.
    pub(super) fn new(node: usize, depth: u32, cell: [i64; 3]) -> Pending {
        Pending {
            node,
            depth,
            cell,
            spans: Vec::new(),
            points: Vec::new(),
        }
    }

    /// Adds piece `index` of level `level` of `edge`: to the last span if it is the edge's
    /// (pieces of an edge come together, of one level, in increasing order), else as a new span.
    pub(super) fn add(&mut self, edge: u32, level: u32, index: u64) {
        match self.spans.last_mut() {
            Some(span) if span.edge == edge => span.last = span.last.max(index),
            _ => self.spans.push(Span {
                edge,
                level,
                first: index,
                last: index,
            }),
        }
    }
}

impl CellTrees {
    /// The trees of the crowded cells of `grid` where more than [`LEAF_POINTS`] of `points` fall.
    pub(super) fn new(grid: &EdgeGrid, mesh: &Mesh3, edges: &[Edge], points: &[DVec3]) -> CellTrees {
        let mut trees = CellTrees::default();
        let mut work = Self::roots(grid, points);
        if work.is_empty() {
            return trees;
        }
        for (i, root) in work.iter_mut().enumerate() {
            root.node = i;
            trees.roots.insert(root.cell, i);
        }
        trees.nodes = vec![TreeNode::UNREFINED; work.len()];
        let segment = |e: u32| {
            let e = &edges[e as usize];
            (mesh.positions[e.lo as usize], mesh.positions[e.hi as usize])
        };
        // Only the edges of the roots' buckets can overlap a root (the grid registered every
        // edge in the bucket of every cell it overlaps): they are walked, in increasing order
        // as all edges were, instead of every edge of the mesh.
        let mut near: Vec<u32> = work
            .iter()
            .flat_map(|root| grid.bucket_items(root.cell))
            .copied()
            .collect();
        near.sort_unstable();
        near.dedup();
        for e in near {
            grid.for_each_cell(segment(e), |index, c| {
                if grid.bucket_items(c).len() > CROWDED {
                    if let Some(&root) = trees.roots.get(&c) {
                        work[root].add(e, 0, index);
                    }
                }
            });
        }
        let budget = TREE_BUDGET * (grid.items.len() + points.len());
        let mut made = 0;
        let mut queue: std::collections::VecDeque<Pending> = work.into();
        while let Some(node) = queue.pop_front() {
            let divide = node.spans.len() > LEAF_EDGES
                && node.points.len() > LEAF_POINTS
                && node.depth < grid.frame.depth_limit
                && made + 8 * node.spans.len() <= budget;
            if divide {
                let children = trees.divide(&grid.frame, node, segment);
                made += children.iter().map(|c| c.spans.len()).sum::<usize>();
                queue.extend(children);
            } else {
                trees.make_leaf(node);
            }
        }
        trees
    }

    /// The crowded cells of `grid` where more than [`LEAF_POINTS`] of `points` fall (within
    /// [`ROOT_RANGE`]), with their points, in the order of their first point.
    fn roots(grid: &EdgeGrid, points: &[DVec3]) -> Vec<Pending> {
        let mut index: FastMap<[i64; 3], usize> = FastMap::default();
        let mut roots: Vec<Pending> = Vec::new();
        for &p in points {
            let c = grid.frame.cell_of(p);
            if c.iter().any(|x| x.unsigned_abs() >= ROOT_RANGE) || grid.bucket_items(c).len() <= CROWDED {
                continue;
            }
            let i = *index.entry(c).or_insert_with(|| {
                roots.push(Pending::new(0, 0, c));
                roots.len() - 1
            });
            roots[i].points.push(p);
        }
        roots.retain(|r| r.points.len() > LEAF_POINTS);
        roots
    }

    /// Makes `node` a leaf holding the edges of its spans.
    fn make_leaf(&mut self, node: Pending) {
        let start = self.edges.len();
        self.edges.extend(node.spans.iter().map(|s| s.edge));
        self.nodes[node.node] = TreeNode {
            children: 0,
            start,
            end: self.edges.len(),
        };
    }

    /// Divides `node` into its eight children and returns those where points fall, to be built;
    /// the others are left unrefined.
    fn divide(&mut self, frame: &GridFrame, node: Pending, segment: impl Fn(u32) -> (DVec3, DVec3)) -> Vec<Pending> {
        let first = self.nodes.len();
        self.nodes.resize(first + 8, TreeNode::UNREFINED);
        self.nodes[node.node].children = first;
        let depth = node.depth + 1;
        let base = node.cell.map(|x| 2 * x);
        let mut children: Vec<Pending> = (0..8)
            .map(|i| {
                Pending::new(
                    first + i,
                    depth,
                    [0, 1, 2].map(|axis| base[axis] + ((i >> axis) & 1) as i64),
                )
            })
            .collect();
        for p in node.points {
            children[frame.child_of(p, depth)].points.push(p);
        }
        let size = frame.cell / (1u64 << depth) as f64;
        for span in node.spans {
            let segment = segment(span.edge);
            let pieces = frame.pieces(segment);
            // Pieces longer than the children are cut in halves, the pieces of the next level;
            // shorter ones are kept whole.
            let length = (segment.1 - segment.0).length() * frame.scale / (pieces << span.level) as f64;
            let (level, first, last) = if length > size {
                (span.level + 1, 2 * span.first, 2 * span.last + 1)
            } else {
                (span.level, span.first, span.last)
            };
            let (grow, n) = (piece_growth(segment), pieces << level);
            #[cfg(test)]
            {
                self.pieces_placed += (last - first + 1) as usize;
            }
            // The cells of a piece's grown box (`piece_box`) reach from the lower to the upper of
            // its ends' grown cells, per axis (cells are monotone, and so is rounding): each end
            // is computed once for the two pieces it bounds.
            let end = |k: u64| {
                let p = piece_end(segment, k, n);
                (frame.fine_cell(p - grow, depth), frame.fine_cell(p + grow, depth))
            };
            let mut start = end(first);
            for index in first..=last {
                let stop = end(index + 1);
                let lo = [0, 1, 2].map(|axis| start.0[axis].min(stop.0[axis]));
                let hi = [0, 1, 2].map(|axis| start.1[axis].max(stop.1[axis]));
                start = stop;
                let range = |axis: usize| {
                    lo[axis].saturating_sub(base[axis]).max(0)..=hi[axis].saturating_sub(base[axis]).min(1)
                };
                for x in range(0) {
                    for y in range(1) {
                        for z in range(2) {
                            let child = &mut children[(x | y << 1 | z << 2) as usize];
                            if !child.points.is_empty() {
                                child.add(span.edge, level, index);
                            }
                        }
                    }
                }
            }
        }
        children.retain(|c| !c.points.is_empty());
        children
    }

    /// The edges of the leaf holding `p`, in cell `c` of the grid, if that cell is refined.
    fn leaf(&self, frame: &GridFrame, c: [i64; 3], p: DVec3) -> Option<&[u32]> {
        let mut node = self.nodes[*self.roots.get(&c)?];
        let mut depth = 0;
        while node.children != 0 {
            depth += 1;
            node = self.nodes[node.children + frame.child_of(p, depth)];
        }
        self.edges.get(node.start..node.end)
    }
}

/// Whether [`distance_on_edge`] can accept any point on segment `(a, b)`: its squared length
/// must be positive and finite (an overflowing length makes the test refuse everything). Other
/// edges are left out of the grid, which keeps its geometry finite.
fn can_contain_points((a, b): (DVec3, DVec3)) -> bool {
    let len2 = (b - a).length_squared();
    len2 > 0.0 && len2.is_finite()
}
