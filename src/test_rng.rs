//! The unit tests' random numbers: a small deterministic generator
//! (xorshift64), the same sequence for the same seed everywhere, so that the
//! tests need no `rand`. (The integration tests have their own, in
//! `tests/common`.)

/// xorshift64 from a non-zero seed.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    /// The next 64 random bits.
    pub(crate) fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// An integer in [-n, n], as a float.
    pub(crate) fn int(&mut self, n: u64) -> f64 {
        (self.next() % (2 * n + 1)) as f64 - n as f64
    }

    /// An integer in [0, n).
    pub(crate) fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    /// A float in [-0.5, 0.5) with 53 random bits.
    pub(crate) fn centered(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}
