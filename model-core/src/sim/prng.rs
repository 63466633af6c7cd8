//! A small seeded pseudo-random generator (xorshift32 with a splitmix-style seed scrambler):
//! reproducible families of plants and noise, no state beyond one `u32`.

/// Xorshift32 generator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Prng {
    state: u32,
}

/// Mixes a 32-bit value (a finaliser in the style of splitmix/murmur): neighbouring inputs give
/// unrelated outputs. Used to derive per-tooth errors from (seed, tooth) without storage.
pub fn mix32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

impl Prng {
    /// A generator from any seed (0 included).
    pub fn new(seed: u32) -> Self {
        let s = mix32(seed ^ 0x9e37_79b9);
        Self {
            state: if s == 0 { 0x1234_5678 } else { s },
        }
    }

    /// Next raw value.
    pub fn next_u32(&mut self) -> u32 {
        let mut x = self.state;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.state = x;
        x
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Uniform in `[-1, 1)`.
    pub fn symmetric(&mut self) -> f32 {
        2.0 * self.unit() - 1.0
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
}

/// Uniform in `[-1, 1)` from a hash of `(seed, index)`.
pub fn hashed_symmetric(seed: u32, index: u32) -> f32 {
    let h = mix32(seed ^ mix32(index.wrapping_add(0x51ed_270b)));
    (h >> 8) as f32 * (2.0 / 16_777_216.0) - 1.0
}
