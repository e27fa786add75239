//! A fast, well-mixed hasher for the hash maps keyed by coordinate bit
//! patterns (welding), which are built once per vertex: SipHash would
//! dominate them. The finish step (murmur3's fmix64) spreads the bits, so
//! coordinates whose low mantissa bits are all zero (integer grids) do not
//! collide.

use std::hash::{BuildHasherDefault, Hasher};

/// FxHash-style multiply-rotate hashing with a murmur3 finish.
#[derive(Default, Clone, Copy)]
pub struct FastHasher {
    hash: u64,
}

impl FastHasher {
    const SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

    fn add(&mut self, word: u64) {
        self.hash = (self.hash.rotate_left(5) ^ word).wrapping_mul(Self::SEED);
    }
}

impl Hasher for FastHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.add(u64::from_le_bytes(word));
        }
    }

    fn write_u64(&mut self, value: u64) {
        self.add(value);
    }

    fn finish(&self) -> u64 {
        // murmur3 fmix64: spreads the weak low bits of the multiplicative hash.
        let mut h = self.hash;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    }
}

/// Builds [`FastHasher`]s.
pub type FastBuild = BuildHasherDefault<FastHasher>;

/// A `HashMap` with [`FastHasher`].
pub type FastMap<K, V> = std::collections::HashMap<K, V, FastBuild>;

/// The welding key of a position: its coordinates' bit patterns, with
/// `-0.0` read as `0.0` (the same point; a file may write either, as a
/// rotation or a `%g` of a tiny negative leaves it). Every weld by
/// position (the readers', `check`'s, `repair`'s) and every lookup of a
/// position among welded ones uses it, so that they agree.
#[inline]
pub fn position_key(p: [f64; 3]) -> [u64; 3] {
    p.map(|x| (x + 0.0).to_bits())
}
