// The photon tracer's random streams on the GPU: hikari_core::sampling::Rng
// (PCG32, XSH-RR, seeded per path by SplitMix64) bit for bit. WGSL has no
// 64-bit integers, so a u64 is vec2<u32>(low, high).

const MIX_1: vec2<u32> = vec2<u32>(0x1ce4e5b9u, 0xbf58476du);
const MIX_2: vec2<u32> = vec2<u32>(0x133111ebu, 0x94d049bbu);
const PCG_MULTIPLIER: vec2<u32> = vec2<u32>(0x4c957f2du, 0x5851f42du);

// The full 64-bit product of two u32, from 16-bit halves.
fn mul_wide(a: u32, b: u32) -> vec2<u32> {
    let a0 = a & 0xffffu;
    let a1 = a >> 16u;
    let b0 = b & 0xffffu;
    let b1 = b >> 16u;
    let low = a0 * b0;
    let cross_1 = a0 * b1;
    let cross_2 = a1 * b0;
    let middle = (low >> 16u) + (cross_1 & 0xffffu) + (cross_2 & 0xffffu);
    return vec2<u32>((low & 0xffffu) | (middle << 16u), a1 * b1 + (cross_1 >> 16u) + (cross_2 >> 16u) + (middle >> 16u));
}

// a · b mod 2^64.
fn mul_u64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let r = mul_wide(a.x, b.x);
    return vec2<u32>(r.x, r.y + a.x * b.y + a.y * b.x);
}

fn add_u64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let low = a.x + b.x;
    return vec2<u32>(low, a.y + b.y + select(0u, 1u, low < a.x));
}

// a >> k for k in 1..=63.
fn shr_u64(a: vec2<u32>, k: u32) -> vec2<u32> {
    if (k >= 32u) {
        return vec2<u32>(a.y >> (k - 32u), 0u);
    }
    return vec2<u32>((a.x >> k) | (a.y << (32u - k)), a.y >> k);
}

// SplitMix64's finaliser (sampling::rng::mix64).
fn mix_u64(z0: vec2<u32>) -> vec2<u32> {
    var z = mul_u64(z0 ^ shr_u64(z0, 30u), MIX_1);
    z = mul_u64(z ^ shr_u64(z, 27u), MIX_2);
    return z ^ shr_u64(z, 31u);
}

struct Rng {
    state: vec2<u32>,
    increment: vec2<u32>,
}

fn rng_next_u32(rng: ptr<function, Rng>) -> u32 {
    let old = (*rng).state;
    (*rng).state = add_u64(mul_u64(old, PCG_MULTIPLIER), (*rng).increment);
    let xorshifted = shr_u64(shr_u64(old, 18u) ^ old, 27u).x;
    let rot = old.y >> 27u;
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

// Rng::for_item(seed, index), given mix64(seed) and the stream's increment
// (both computed once on the host).
fn rng_for_item(mixed_seed: vec2<u32>, increment: vec2<u32>, index: vec2<u32>) -> Rng {
    var rng = Rng(mix_u64(add_u64(index, mixed_seed)), increment);
    rng_next_u32(&rng);
    return rng;
}

// Uniform in [0, 1) from the top 24 bits (Rng::next_f32).
fn rng_next_f32(rng: ptr<function, Rng>) -> f32 {
    return f32(rng_next_u32(rng) >> 8u) * (1.0 / 16777216.0);
}

fn rng_next_2d(rng: ptr<function, Rng>) -> vec2<f32> {
    let x = rng_next_f32(rng);
    let y = rng_next_f32(rng);
    return vec2<f32>(x, y);
}

// Per-pixel random numbers for the passes that no CPU twin draws (the
// direct pass's and specular pass's samples of glossy lobes and area
// lights): PCG's output permutation as a hash (Jarzynski & Olano 2020,
// "Hash Functions for GPU Rendering"), fed back into itself.
fn hash_u32(x: u32) -> u32 {
    let state = x * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The stream of `pixel` in progressive pass `pass_index` for purpose `salt`.
fn pixel_stream(pixel: vec2<u32>, pass_index: u32, salt: u32) -> u32 {
    return hash_u32(hash_u32(hash_u32(pass_index ^ (salt * 0x9e3779b9u)) + pixel.x) + pixel.y);
}

// Uniform in [0, 1) from the top 24 bits of the next hash.
fn stream_next_f32(state: ptr<function, u32>) -> f32 {
    *state = hash_u32(*state);
    return f32(*state >> 8u) * (1.0 / 16777216.0);
}

fn stream_next_2d(state: ptr<function, u32>) -> vec2<f32> {
    let x = stream_next_f32(state);
    let y = stream_next_f32(state);
    return vec2<f32>(x, y);
}
