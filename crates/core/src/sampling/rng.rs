//! A small counter-seeded PCG32 generator.
//!
//! Written here rather than taken from a crate because every photon path and
//! every pixel seeds its own stream from `(seed, index)`: that is what makes
//! results identical whatever the thread count, and the same few lines can be
//! mirrored in WGSL when photon tracing moves to the GPU.

/// PCG32 (O'Neill, XSH-RR variant): 64-bit state, 32-bit output.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    increment: u64,
}

const MULTIPLIER: u64 = 6364136223846793005;

/// SplitMix64 finaliser: spreads nearby counters over the whole state space.
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d049bb133111eb);
    z ^ (z >> 31)
}

impl Rng {
    /// A stream for work item `index` of a run seeded with `seed`.
    pub fn for_item(seed: u64, index: u64) -> Self {
        let (mixed_seed, increment) = Rng::seed_constants(seed);
        let mut rng = Rng { state: mix64(index.wrapping_add(mixed_seed)), increment };
        rng.next_u32();
        rng
    }

    /// What every stream of a run shares: mix64(seed) and the PCG increment.
    /// The GPU tracer (random.wgsl) takes these and does the rest per path.
    pub fn seed_constants(seed: u64) -> (u64, u64) {
        (mix64(seed), (mix64(seed ^ 0x9e3779b97f4a7c15) << 1) | 1)
    }

    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(MULTIPLIER).wrapping_add(self.increment);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in [0, 1): the top 24 bits, so every value is exact in f32.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Two uniforms in [0, 1).
    pub fn next_2d(&mut self) -> glam::Vec2 {
        glam::Vec2::new(self.next_f32(), self.next_f32())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<u32> = (0..4).map(|_| Rng::for_item(7, 3).next_u32()).collect();
        assert!(a.iter().all(|&x| x == a[0]));
        let mut r1 = Rng::for_item(7, 3);
        let mut r2 = Rng::for_item(7, 4);
        let same = (0..64).filter(|_| r1.next_u32() == r2.next_u32()).count();
        assert!(same < 2);
    }

    #[test]
    fn uniform_mean_and_range() {
        let mut rng = Rng::for_item(1, 0);
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let x = rng.next_f32();
            assert!((0.0..1.0).contains(&x));
            sum += x as f64;
        }
        assert!((sum / n as f64 - 0.5).abs() < 0.005);
    }
}
