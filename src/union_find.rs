//! Disjoint sets over `0..n` (union-find), shared by the construction's
//! region finding and figures and by `--repair`. (The judge, `check`, keeps
//! its own.)

/// Disjoint sets over `0..n`, `n < 2^32`; the root of a set is always its
/// smallest element, so the roots do not depend on the order of unions.
/// Finding halves the path it walks.
pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// `n` sets of one element each.
    pub(crate) fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    /// The root (smallest element) of `x`'s set.
    pub(crate) fn find(&mut self, x: usize) -> usize {
        let mut x = x;
        loop {
            let p = self.parent[x] as usize;
            if p == x {
                return x;
            }
            let grandparent = self.parent[p];
            self.parent[x] = grandparent;
            x = grandparent as usize;
        }
    }

    /// Joins the sets of `a` and `b`.
    pub(crate) fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra.max(rb)] = ra.min(rb) as u32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::UnionFind;

    #[test]
    fn roots_are_the_smallest_elements() {
        let mut sets = UnionFind::new(6);
        sets.union(4, 2);
        sets.union(5, 4);
        sets.union(3, 1);
        assert_eq!((0..6).map(|x| sets.find(x)).collect::<Vec<_>>(), [0, 1, 2, 1, 2, 2]);
        sets.union(5, 3);
        assert_eq!((0..6).map(|x| sets.find(x)).collect::<Vec<_>>(), [0, 1, 1, 1, 1, 1]);
    }
}
