//! Small index structures the rules share: counting sorts by row, compressed rows, union-find,
//! position keys.

use super::*;

/// Counting sort of `(row, item)` pairs by row (stable): returns the start of every row (plus
/// the end) and the items. Every row must be `< rows`.
fn group_by_row<T: Copy + Default>(rows: usize, pairs: &[(u32, T)]) -> (Vec<usize>, Vec<T>) {
    let mut starts = vec![0usize; rows + 1];
    for &(r, _) in pairs {
        starts[r as usize + 1] += 1;
    }
    for i in 1..starts.len() {
        starts[i] += starts[i - 1];
    }
    let mut next = starts.clone();
    let mut items = vec![T::default(); pairs.len()];
    for &(r, x) in pairs {
        items[next[r as usize]] = x;
        next[r as usize] += 1;
    }
    (starts, items)
}

/// Rows of `u32` stored flat (compressed sparse rows).
pub(super) struct Csr {
    pub(super) starts: Vec<usize>,
    pub(super) items: Vec<u32>,
}

impl Csr {
    /// Groups `(row, item)` pairs by row (counting sort; items keep their order).
    pub(super) fn from_pairs(rows: usize, pairs: &[(u32, u32)]) -> Csr {
        let (starts, items) = group_by_row(rows, pairs);
        Csr { starts, items }
    }

    /// The same rows, each sorted and without duplicates.
    pub(super) fn sorted_unique(mut self) -> Csr {
        let mut builder = CsrBuilder::default();
        for r in 0..self.starts.len() - 1 {
            let row = &mut self.items[self.starts[r]..self.starts[r + 1]];
            row.sort_unstable();
            let mut last = None;
            for &x in row.iter() {
                if last != Some(x) {
                    builder.items.push(x);
                    last = Some(x);
                }
            }
            builder.finish_row();
        }
        builder.build()
    }

    /// Row `r`.
    pub(super) fn row(&self, r: usize) -> &[u32] {
        &self.items[self.starts[r]..self.starts[r + 1]]
    }
}

/// Builds a [`Csr`] row by row.
pub(super) struct CsrBuilder {
    pub(super) starts: Vec<usize>,
    pub(super) items: Vec<u32>,
}

impl Default for CsrBuilder {
    fn default() -> Self {
        CsrBuilder {
            starts: vec![0],
            items: Vec::new(),
        }
    }
}

impl CsrBuilder {
    /// Appends items to the current row.
    pub(super) fn extend(&mut self, items: &[u32]) {
        self.items.extend_from_slice(items);
    }

    /// Ends the current row.
    pub(super) fn finish_row(&mut self) {
        self.starts.push(self.items.len());
    }

    pub(super) fn build(self) -> Csr {
        Csr {
            starts: self.starts,
            items: self.items,
        }
    }
}

/// Disjoint sets over `0..n` with path halving and union by size.
pub(super) struct UnionFind {
    pub(super) parent: Vec<u32>,
    pub(super) size: Vec<u32>,
}

impl UnionFind {
    pub(super) fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
            size: vec![1; n],
        }
    }

    pub(super) fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grandparent = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grandparent;
            x = grandparent;
        }
        x
    }

    pub(super) fn union(&mut self, a: u32, b: u32) {
        let (mut a, mut b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        if self.size[a as usize] < self.size[b as usize] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b as usize] = a;
        self.size[a as usize] += self.size[b as usize];
    }
}

/// The welding key of a position: its bit patterns, -0 read as 0
/// ([`crate::hash::position_key`], as the readers weld).
pub(super) fn bits(p: DVec3) -> [u64; 3] {
    crate::hash::position_key(p.to_array())
}
