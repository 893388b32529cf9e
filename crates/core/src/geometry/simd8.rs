//! The box and triangle tests in eight AVX2 lanes, written once for both
//! eight-lane traversals: `packet` (eight rays against one box or
//! triangle, broadcast) and `wide` (one ray, broadcast, against eight
//! boxes or triangles). Callers must have checked that the CPU has AVX2.

#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

/// Three coordinates, eight lanes each.
pub(super) type V3 = [__m256; 3];

/// Eight copies of a point or vector.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn splat3(v: [f32; 3]) -> V3 {
    [_mm256_set1_ps(v[0]), _mm256_set1_ps(v[1]), _mm256_set1_ps(v[2])]
}

/// Loads three rows of eight floats.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn load3(rows: &[[f32; 8]; 3]) -> V3 {
    // SAFETY: each row holds 8 floats.
    unsafe { [_mm256_loadu_ps(rows[0].as_ptr()), _mm256_loadu_ps(rows[1].as_ptr()), _mm256_loadu_ps(rows[2].as_ptr())] }
}

/// 1 / each of eight direction components, for the slab test: a
/// component under 1e-20 in magnitude counts as ±1e-20 (its sign kept), so
/// the test never sees 0·∞. A packet inverts its eight rays' components,
/// a single ray its three in one division (`wide`).
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn inverse_direction(d: __m256) -> __m256 {
    let (sign_bit, tiny) = (_mm256_set1_ps(-0.0), _mm256_set1_ps(1e-20));
    let small = _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_andnot_ps(sign_bit, d), tiny);
    let safe = _mm256_blendv_ps(d, _mm256_or_ps(tiny, _mm256_and_ps(d, sign_bit)), small);
    _mm256_div_ps(_mm256_set1_ps(1.0), safe)
}

/// The slab test of rays `origin + t·dir` (with `inv_dir` from
/// [`inverse_direction`]) against boxes [`lo`, `hi`], clipped to
/// [0, `t_max`]: (near distance, lanes that meet their box). The far
/// distance is widened by 2 ulps' worth so rounding never culls a box a ray
/// grazes (flat boxes of axis-aligned walls).
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn slab(lo: V3, hi: V3, origin: V3, inv_dir: V3, t_max: __m256) -> (__m256, __m256) {
    let (mul, sub, min, max) = (_mm256_mul_ps, _mm256_sub_ps, _mm256_min_ps, _mm256_max_ps);
    let t0x = mul(sub(lo[0], origin[0]), inv_dir[0]);
    let t1x = mul(sub(hi[0], origin[0]), inv_dir[0]);
    let t0y = mul(sub(lo[1], origin[1]), inv_dir[1]);
    let t1y = mul(sub(hi[1], origin[1]), inv_dir[1]);
    let t0z = mul(sub(lo[2], origin[2]), inv_dir[2]);
    let t1z = mul(sub(hi[2], origin[2]), inv_dir[2]);
    let near = max(max(min(t0x, t1x), min(t0y, t1y)), max(min(t0z, t1z), _mm256_setzero_ps()));
    let far = min(
        mul(min(min(max(t0x, t1x), max(t0y, t1y)), max(t0z, t1z)), _mm256_set1_ps(1.0 + 4.0 * f32::EPSILON)),
        t_max,
    );
    (near, _mm256_cmp_ps::<_CMP_LE_OQ>(near, far))
}

/// Möller–Trumbore with precomputed edges, as `PackedPrim::intersect` does
/// it for one ray and one triangle (the same operations in the same order,
/// so each lane finds the same t to the bit): (lanes hit in (`t_min`,
/// `t_max`), t, b1, b2). A NaN triangle or ray misses.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn triangle(origin: V3, dir: V3, a: V3, e1: V3, e2: V3, t_min: f32, t_max: __m256) -> [__m256; 4] {
    let (mul, sub, add) = (_mm256_mul_ps, _mm256_sub_ps, _mm256_add_ps);
    let s = _mm256_set1_ps;
    // p = dir × e2, in glam's order: (y·z' − y'·z, z·x' − z'·x, x·y' − x'·y).
    let px = sub(mul(dir[1], e2[2]), mul(e2[1], dir[2]));
    let py = sub(mul(dir[2], e2[0]), mul(e2[2], dir[0]));
    let pz = sub(mul(dir[0], e2[1]), mul(e2[0], dir[1]));
    let det = add(add(mul(e1[0], px), mul(e1[1], py)), mul(e1[2], pz));
    let inv = _mm256_div_ps(s(1.0), det);
    let sx = sub(origin[0], a[0]);
    let sy = sub(origin[1], a[1]);
    let sz = sub(origin[2], a[2]);
    let b1 = mul(add(add(mul(sx, px), mul(sy, py)), mul(sz, pz)), inv);
    // q = s × e1
    let qx = sub(mul(sy, e1[2]), mul(e1[1], sz));
    let qy = sub(mul(sz, e1[0]), mul(e1[2], sx));
    let qz = sub(mul(sx, e1[1]), mul(e1[0], sy));
    let b2 = mul(add(add(mul(dir[0], qx), mul(dir[1], qy)), mul(dir[2], qz)), inv);
    let t = mul(add(add(mul(e2[0], qx), mul(e2[1], qy)), mul(e2[2], qz)), inv);
    let zero = _mm256_setzero_ps();
    let inside = _mm256_and_ps(
        _mm256_and_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(b1, zero), _mm256_cmp_ps::<_CMP_GE_OQ>(b2, zero)),
        _mm256_cmp_ps::<_CMP_LE_OQ>(add(b1, b2), s(1.0)),
    );
    let within = _mm256_and_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(t, s(t_min)), _mm256_cmp_ps::<_CMP_LT_OQ>(t, t_max));
    [_mm256_and_ps(inside, within), t, b1, b2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rule as scalar code.
    fn slab_safe(d: f32) -> f32 {
        if d.abs() < 1e-20 { 1e-20f32.copysign(d) } else { d }
    }

    /// The eight-lane inverse is the scalar rule's, bit for bit, on the
    /// components that matter: zeros of both signs, values either side of
    /// the 1e-20 floor, infinities, NaN and ordinary ones.
    #[test]
    fn inverse_direction_is_one_over_slab_safe() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let cases =
            [0.0, -0.0, 1e-21, -1e-21, 1e-20, -1e-20, 2e-20, -3e-19, f32::INFINITY, f32::NEG_INFINITY, 0.5, -0.75];
        let nan = [f32::NAN, -f32::NAN, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, 1.0, -1.0, 1e30, -1e-45];
        for lanes in cases.chunks(8).map(|c| std::array::from_fn::<f32, 8, _>(|i| c[i % c.len()])).chain([nan]) {
            let mut got = [0.0f32; 8];
            // SAFETY: AVX2 checked above; both arrays hold 8 floats.
            unsafe { _mm256_storeu_ps(got.as_mut_ptr(), inverse_direction(_mm256_loadu_ps(lanes.as_ptr()))) };
            for (d, g) in lanes.iter().zip(got) {
                let want = 1.0 / slab_safe(*d);
                assert!(
                    g.to_bits() == want.to_bits() || (g.is_nan() && want.is_nan()),
                    "1/{d:e}: {g:e}, want {want:e}"
                );
            }
        }
    }
}
