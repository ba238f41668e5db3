//! A small, repeatable random source for the unit tests (xorshift64):
//! many cheap values from a fixed seed, the same on every run.

/// Marsaglia's xorshift64 generator; the state must not be 0.
pub(crate) struct Xorshift(pub u64);

impl Xorshift {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A value in `0..n` (`n > 0`).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }

    /// A value in `-range..=range` (`range >= 0`).
    pub fn signed(&mut self, range: i64) -> i64 {
        self.below(2 * range as u64 + 1) as i64 - range
    }
}
