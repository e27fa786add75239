//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

/// A small deterministic PRNG (xorshift64*), so tests need no `rand`.
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }
    /// Uniform integer in 0..n.
    pub fn below(&mut self, n: u64) -> u64 {
        ((self.f64() * n as f64) as u64).min(n - 1)
    }
}

/// The `data/` folder of the crate.
pub fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data")
}

/// Every `.obj` in `data/`, sorted.
pub fn fixtures() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(data_dir())
        .expect("data/ exists")
        .map(|e| e.expect("readable data/").path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    v.sort();
    v
}

/// A Möbius band of `n` quads, radius 2, half-width `w`: its `2n` vertices (a top and a bottom
/// one per step) and its quads `[top, bottom, next bottom, next top]`. After a full turn top
/// and bottom swap, so no orientation of the quads is consistent.
pub fn moebius_band(n: usize, w: f64) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let mut positions = Vec::new();
    for i in 0..n {
        let theta = std::f64::consts::TAU * i as f64 / n as f64;
        let phi = theta / 2.0;
        let centre = [2.0 * theta.cos(), 2.0 * theta.sin(), 0.0];
        let dir = [phi.cos() * theta.cos(), phi.cos() * theta.sin(), phi.sin()];
        positions.push([0, 1, 2].map(|k| centre[k] + w * dir[k]));
        positions.push([0, 1, 2].map(|k| centre[k] - w * dir[k]));
    }
    let quads = (0..n)
        .map(|i| {
            let (top, bottom) = (2 * i as u32, 2 * i as u32 + 1);
            let (next_top, next_bottom) = if i + 1 < n { (top + 2, bottom + 2) } else { (1, 0) };
            [top, bottom, next_bottom, next_top]
        })
        .collect();
    (positions, quads)
}

/// The corners of the unit cube: corner `i` at `(i & 1, (i >> 1) & 1, (i >> 2) & 1)`.
pub fn cube_corners() -> Vec<[f64; 3]> {
    (0..8u32).map(|i| [0, 1, 2].map(|k| f64::from((i >> k) & 1))).collect()
}

/// The quads of the unit cube of [`cube_corners`], each counter-clockwise seen from outside.
pub const CUBE_QUADS: [[u32; 4]; 6] = [
    [0, 2, 3, 1],
    [4, 5, 7, 6],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 4, 6, 2],
    [1, 3, 7, 5],
];

/// The checker's report on the refined surface `s` against the input it was built from.
pub fn check_refined(input: &delmesh::io::InputMesh, s: &delmesh::mesh::Surface) -> delmesh::check::CheckReport {
    use delmesh::check::{check_meshes, Mesh3};
    check_meshes(
        &Mesh3 {
            positions: input.positions.clone(),
            triangles: input.triangles.clone(),
        },
        &Mesh3 {
            positions: s.positions.clone(),
            triangles: s.triangles(),
        },
    )
}

/// A cone-like fan of `n` triangles (`n` a multiple of 4, at least 4) around one apex vertex of
/// valence `n`, like the disks and cones of CAD exports: the apex at the origin (vertex 0) and a
/// closed rim whose points step through radii 1, 1/10, 1/100, 1/10 at heights -1, -1/10, 0,
/// 1/20. The triangles are not coplanar and the long spokes face angles near π, so refinement
/// must split spokes, adding several vertices on each, most of them close to the apex (at
/// distances 0.0078 to 0.14).
pub fn cone_fan(n: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    assert!(n >= 4 && n % 4 == 0, "the rim's pattern has period 4");
    const RIM: [(f64, f64); 4] = [(1.0, -1.0), (0.1, -0.1), (0.01, 0.0), (0.1, 0.05)];
    let mut positions = vec![[0.0, 0.0, 0.0]];
    for i in 0..n {
        let theta = std::f64::consts::TAU * i as f64 / n as f64;
        let (radius, height) = RIM[i % 4];
        positions.push([radius * theta.cos(), radius * theta.sin(), height]);
    }
    let triangles = (0..n as u32).map(|i| [0, 1 + i, 1 + (i + 1) % n as u32]).collect();
    (positions, triangles)
}
