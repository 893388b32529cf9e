//! Randomised quasi-Monte Carlo samples for the path tracer: Owen-scrambled
//! Sobol points (Burley 2020, "Practical Hash-based Owen Scrambling", the
//! `sobol_burley` crate), padded in pairs of dimensions.
//!
//! Why: a pixel's samples drawn independently leave clumps and gaps in each
//! decision's square (the pixel's area, the first bounce's direction, the
//! next one's …); Sobol points fill every such square evenly, so the same
//! number of samples integrates the pixel with less error. On the Cornell
//! box with a point light under the ceiling, Mitsuba's stratified samplers
//! cut the error at 1,024 spp from 8.1% (independent) to 5.2% (BENCHMARKS.md).
//!
//! Padding: the path asks for numbers one or two at a time, in an order that
//! depends on what it meets. The k-th pair it asks for is the first two
//! dimensions of the Sobol sequence (a (0,2)-sequence: every 2^m points
//! fill every 2^a × 2^b grid of 2^m cells once) under a scramble seeded by
//! (stream, k); single numbers come two at a time from the two dimensions
//! of sets of their own (each a (0,1)-sequence). Only the first requests
//! get Sobol numbers (`SOBOL_PAIRS`, `SOBOL_SINGLE_SETS`); the rest of a
//! long path takes PCG numbers. Different sets are
//! independently randomised (Burley's padding; pbrt-v4's `PaddedSobolSampler`
//! does the same). Every sample is uniform in the unit cube whatever the
//! index, so estimates stay unbiased; distinct streams are independent
//! replicates.

use super::Sampler;
use super::rng::{Rng, mix64};
use glam::Vec2;
use sobol_burley::parts::{hash, owen_scramble_rev, u32_to_f32_norm};

/// Sobol indices per scramble: `sobol_burley` reaches 2^16; past that a
/// stream continues with fresh, independent scrambles (each a full net).
const BLOCK_BITS: u32 = 16;

/// Pairs and singles of a path drawn from Sobol sets; the numbers after
/// them come from a PCG stream. A set costs about 20 ns, which on paths
/// of a dozen requests was 15% of the path tracer's time, and the first
/// bounces hold what stratification gains: on the Cornell box (a point
/// light) the pixel and the first bounce's direction gave all of it
/// (relative error 17.5% → 14.4% at 256 spp), Sobol numbers for every
/// request no more (14.4%).
const SOBOL_PAIRS: u32 = 3;
/// Sets of two single numbers each.
const SOBOL_SINGLE_SETS: u32 = 2;

/// Sample `index` of the Sobol stream `stream`: one path's numbers.
#[derive(Clone, Debug)]
pub struct SobolSampler {
    index: u32,
    seed: u32,
    /// Pairs handed out so far.
    pairs: u32,
    /// Single numbers handed out so far, and the pair they come from.
    singles: u32,
    single_pair: Vec2,
    /// For the numbers past the Sobol sets.
    tail: Rng,
}

impl SobolSampler {
    /// Sample `index` of stream `stream` (e.g. one pixel of one seed).
    pub fn new(stream: u64, index: u64) -> Self {
        let block = index >> BLOCK_BITS;
        let seed = mix64(stream ^ block.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        SobolSampler {
            index: (index & ((1 << BLOCK_BITS) - 1)) as u32,
            seed: seed as u32,
            pairs: 0,
            singles: 0,
            single_pair: Vec2::ZERO,
            tail: Rng::for_item(seed, index),
        }
    }

    /// The sample's point of set `set` of kind `kind` (pairs or singles).
    #[inline]
    fn point(&self, kind: u32, set: u32) -> Vec2 {
        sobol_pair(self.index, self.seed ^ kind ^ set.wrapping_mul(0x2c1b_3c6d))
    }
}

const PAIRS: u32 = 0;
const SINGLES: u32 = 0x8000_0001;

impl Sampler for SobolSampler {
    #[inline]
    fn next_f32(&mut self) -> f32 {
        let (set, lane) = (self.singles / 2, self.singles % 2);
        self.singles += 1;
        if set >= SOBOL_SINGLE_SETS {
            return self.tail.next_f32();
        }
        if lane == 0 {
            self.single_pair = self.point(SINGLES, set);
            self.single_pair.x
        } else {
            self.single_pair.y
        }
    }

    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        self.pairs += 1;
        if self.pairs > SOBOL_PAIRS {
            return self.tail.next_2d();
        }
        self.point(PAIRS, self.pairs - 1)
    }
}

/// The reversed direction numbers of the Sobol sequence's second
/// dimension (its generator is Pascal's matrix mod 2: v₀ = ½,
/// vⱼ = vⱼ₋₁ ⊕ vⱼ₋₁/2), XOR-combined for every byte of an index: the low
/// byte's table, then the high byte's.
const fn second_dimension_tables() -> [[u32; 256]; 2] {
    let mut v = [0u32; 16];
    v[0] = 1 << 31;
    let mut j = 1;
    while j < 16 {
        v[j] = v[j - 1] ^ (v[j - 1] >> 1);
        j += 1;
    }
    let mut tables = [[0u32; 256]; 2];
    let mut byte = 0;
    while byte < 2 {
        let mut b = 0;
        while b < 256 {
            let (mut x, mut k) = (0u32, 0);
            while k < 8 {
                if b & (1 << k) != 0 {
                    x ^= v[8 * byte + k];
                }
                k += 1;
            }
            tables[byte][b] = x.reverse_bits();
            b += 1;
        }
        byte += 1;
    }
    tables
}

static SECOND_DIMENSION: [[u32; 256]; 2] = second_dimension_tables();

/// Point `index` (< 2^16) of the first two Sobol dimensions under the
/// Owen scramble and index shuffle of `seed`: exactly
/// `(sobol_burley::sample(index, 0, seed), sobol_burley::sample(index, 1, seed))`,
/// its steps written out for two dimensions with the second one read from
/// tables (the crate's per-bit loop branches on every index bit; this is
/// 2× faster).
#[inline]
fn sobol_pair(index: u32, seed: u32) -> Vec2 {
    let shuffled = owen_scramble_rev(index.reverse_bits(), hash(seed ^ 0x79c6_8e4a)).reverse_bits() & 0xffff;
    // The first dimension is the index's bits reversed: reversed back, the index.
    let x_rev = shuffled;
    let y_rev = SECOND_DIMENSION[0][(shuffled & 255) as usize] ^ SECOND_DIMENSION[1][(shuffled >> 8) as usize];
    let scramble = seed.wrapping_mul(0x9c8f_2d3b);
    let x = owen_scramble_rev(x_rev, hash(scramble ^ 0x912f_69ba)).reverse_bits();
    let y = owen_scramble_rev(y_rev, hash(scramble ^ 0x174f_18ab)).reverse_bits();
    Vec2::new(u32_to_f32_norm(x), u32_to_f32_norm(y))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// Numbers lie in [0, 1) and a stream repeats exactly.
    #[test]
    fn samples_are_unit_and_reproducible() {
        for index in [0u64, 1, 77, 65_535, 65_536, 1 << 20] {
            let draw = || {
                let mut s = SobolSampler::new(12, index);
                (0..40).map(|i| if i % 3 == 0 { s.next_2d().x } else { s.next_f32() }).collect::<Vec<_>>()
            };
            let a = draw();
            assert!(a.iter().all(|x| (0.0..1.0).contains(x)), "{a:?}");
            assert_eq!(a, draw());
        }
    }

    /// The two-dimensional points are the crate's, bit for bit.
    #[test]
    fn pairs_are_sobol_burleys_first_two_dimensions() {
        for seed in [0u32, 7, 0xdead_beef] {
            for index in (0..4096).chain([65_535]) {
                let p = sobol_pair(index, seed);
                assert_eq!(p, Vec2::new(sobol_burley::sample(index, 0, seed), sobol_burley::sample(index, 1, seed)));
            }
        }
    }

    /// The first 256 samples are stratified: every pair `next_2d` hands
    /// out falls once in each of the 16 × 16 cells, and every single
    /// number once in each of 256 intervals, for the first requests, the
    /// tenth, with the two kinds interleaved, and past the first block.
    #[test]
    fn pairs_and_singles_are_stratified() {
        for (stream, first) in [(3u64, 0u64), (4, 1 << 16)] {
            for request in [0usize, 1, 2, SOBOL_PAIRS.min(2 * SOBOL_SINGLE_SETS) as usize - 1] {
                let (mut cells, mut bins) = ([0u32; 256], [0u32; 256]);
                for i in 0..256 {
                    let mut s = SobolSampler::new(stream, first + i);
                    let (mut p, mut x) = (Vec2::ZERO, 0.0);
                    for _ in 0..=request {
                        (p, x) = (s.next_2d(), s.next_f32());
                    }
                    cells[(p.x * 16.0) as usize + 16 * (p.y * 16.0) as usize] += 1;
                    bins[(x * 256.0) as usize] += 1;
                }
                assert!(cells.iter().all(|&c| c == 1), "stream {stream}, pair {request}: {cells:?}");
                assert!(bins.iter().all(|&c| c == 1), "stream {stream}, single {request}: {bins:?}");
            }
        }
    }

    /// The point of it: a pixel-sized integral with an edge (the fraction
    /// of the unit square under a slanted line, 64 samples) has several
    /// times less error with the Sobol stream than with independent
    /// numbers, measured over 400 streams; and both are unbiased.
    #[test]
    fn an_edge_integral_has_less_error_than_with_independent_numbers() {
        let inside = |p: Vec2| if p.y < 0.3 + 0.37 * p.x { 1.0 } else { 0.0 };
        let exact = 0.3 + 0.37 / 2.0;
        let (mut sobol_sq, mut random_sq, mut sobol_sum) = (0.0f64, 0.0f64, 0.0f64);
        let streams = 400;
        for stream in 0..streams {
            let mut rng = Rng::for_item(9, stream);
            let (mut a, mut b) = (0.0, 0.0);
            for i in 0..64 {
                a += inside(SobolSampler::new(stream, i).next_2d());
                b += inside(rng.next_2d());
            }
            let (a, b) = (a / 64.0 - exact, b / 64.0 - exact);
            sobol_sq += a * a;
            random_sq += b * b;
            sobol_sum += a;
        }
        let (sobol, random) = ((sobol_sq / streams as f64).sqrt(), (random_sq / streams as f64).sqrt());
        eprintln!("edge integral, RMS error of 64 samples: Sobol {sobol:.5}, independent {random:.5}");
        assert!(sobol < random / 3.0, "Sobol {sobol} vs independent {random}");
        // The mean error over 400 streams: within 4 standard errors of 0.
        assert!((sobol_sum / streams as f64).abs() < 4.0 * sobol / (streams as f64).sqrt());
    }
}
