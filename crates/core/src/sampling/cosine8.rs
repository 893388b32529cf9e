//! Cosine-distributed directions about eight normals at once:
//! `local_to_world(cosine_hemisphere(u), n)` for eight lanes, in AVX2
//! where the CPU has it, to the bit (the same operations in the same
//! order, each rounding as the scalar one does; checked by a test).
//!
//! Why: a diffuse bounce's direction is one chain of ~40 dependent
//! operations (two square roots, the azimuth's polynomials, a division
//! for the frame) that takes ~120 cycles; one lane after another, a
//! chain overlapped only the next lane's, and perf found 45% of the path
//! step's time waiting at the ends of these chains. Eight lanes in one
//! chain of vector instructions pay for it once.

use super::{cosine_hemisphere, local_to_world};
use glam::{Vec2, Vec3};

/// Eight lanes of a vector, component by component.
pub type Lanes3 = [[f32; 8]; 3];

/// `local_to_world(cosine_hemisphere((u[0][i], u[1][i])), n_i)` for each
/// lane i.
pub fn cosine_directions(u: &[[f32; 8]; 2], n: &Lanes3) -> Lanes3 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 checked above.
        return unsafe { avx2::cosine_directions(u, n) };
    }
    scalar(u, n)
}

fn scalar(u: &[[f32; 8]; 2], n: &Lanes3) -> Lanes3 {
    let mut out = Lanes3::default();
    for i in 0..8 {
        let d = local_to_world(cosine_hemisphere(Vec2::new(u[0][i], u[1][i])), Vec3::new(n[0][i], n[1][i], n[2][i]));
        (out[0][i], out[1][i], out[2][i]) = (d.x, d.y, d.z);
    }
    out
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::Lanes3;
    use std::arch::x86_64::*;
    use std::f32::consts::PI;

    /// `unit_circle`, lane by lane: (cos 2πu, sin 2πu).
    #[target_feature(enable = "avx2")]
    fn unit_circle(u: __m256) -> (__m256, __m256) {
        let (mul, add, sub, s) = (_mm256_mul_ps, _mm256_add_ps, _mm256_sub_ps, _mm256_set1_ps);
        let x = mul(u, s(4.0));
        // `(x + 0.5) as i32`, which saturates: NaN to 0, too large to
        // i32::MAX (`cvtt` gives i32::MIN for both; too small is MIN).
        let shifted = add(x, s(0.5));
        let truncated = _mm256_cvttps_epi32(shifted);
        let too_large = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GE_OQ>(shifted, s(2_147_483_648.0)));
        let ordered = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_ORD_Q>(shifted, shifted));
        let quadrant = _mm256_and_si256(_mm256_blendv_epi8(truncated, _mm256_set1_epi32(i32::MAX), too_large), ordered);
        let a = mul(sub(x, _mm256_cvtepi32_ps(quadrant)), s(PI / 2.0));
        let a2 = mul(a, a);
        let sin = mul(
            a,
            add(
                s(1.0),
                mul(
                    a2,
                    add(
                        s(-1.0 / 6.0),
                        mul(a2, add(s(1.0 / 120.0), mul(a2, add(s(-1.0 / 5040.0), mul(a2, s(1.0 / 362_880.0)))))),
                    ),
                ),
            ),
        );
        let cos = add(
            s(1.0),
            mul(
                a2,
                add(s(-0.5), mul(a2, add(s(1.0 / 24.0), mul(a2, add(s(-1.0 / 720.0), mul(a2, s(1.0 / 40_320.0))))))),
            ),
        );
        let one = _mm256_set1_epi32(1);
        // All ones where the quadrant is odd; the sign bit where bit 1 is set.
        let odd = _mm256_sub_epi32(_mm256_setzero_si256(), _mm256_and_si256(quadrant, one));
        let half_turn = _mm256_slli_epi32::<30>(_mm256_and_si256(quadrant, _mm256_set1_epi32(2)));
        let (cos_bits, sin_bits) = (_mm256_castps_si256(cos), _mm256_castps_si256(sin));
        let minus_sin_bits = _mm256_xor_si256(sin_bits, _mm256_set1_epi32(i32::MIN));
        let x = _mm256_or_si256(_mm256_andnot_si256(odd, cos_bits), _mm256_and_si256(minus_sin_bits, odd));
        let y = _mm256_or_si256(_mm256_andnot_si256(odd, sin_bits), _mm256_and_si256(cos_bits, odd));
        (_mm256_castsi256_ps(_mm256_xor_si256(x, half_turn)), _mm256_castsi256_ps(_mm256_xor_si256(y, half_turn)))
    }

    /// `local_to_world(cosine_hemisphere(u), n)` lane by lane, with
    /// `orthonormal_basis`'s frame.
    #[target_feature(enable = "avx2")]
    pub fn cosine_directions(u: &[[f32; 8]; 2], n: &Lanes3) -> Lanes3 {
        let (mul, add, s) = (_mm256_mul_ps, _mm256_add_ps, _mm256_set1_ps);
        // SAFETY (loads and stores): rows of 8 floats.
        let ld = |row: &[f32; 8]| unsafe { _mm256_loadu_ps(row.as_ptr()) };
        let (u0, u1) = (ld(&u[0]), ld(&u[1]));
        let (nx, ny, nz) = (ld(&n[0]), ld(&n[1]), ld(&n[2]));
        // cosine_hemisphere
        let cos_theta = _mm256_sqrt_ps(_mm256_sub_ps(s(1.0), u0));
        let sin_theta = _mm256_sqrt_ps(u0);
        let (c, sn) = unit_circle(u1);
        let (lx, ly, lz) = (mul(c, sin_theta), mul(sn, sin_theta), cos_theta);
        // orthonormal_basis
        let sign_bit = s(-0.0);
        let sign = _mm256_or_ps(s(1.0), _mm256_and_ps(nz, sign_bit));
        let a = _mm256_div_ps(s(-1.0), add(sign, nz));
        let b = mul(mul(nx, ny), a);
        let neg = |v| _mm256_xor_ps(v, sign_bit);
        let t = [add(s(1.0), mul(mul(mul(sign, nx), nx), a)), mul(sign, b), mul(neg(sign), nx)];
        let bt = [b, add(sign, mul(mul(ny, ny), a)), neg(ny)];
        // t·x + b·y + n·z
        let axis = [nx, ny, nz];
        let mut out = Lanes3::default();
        for k in 0..3 {
            let v = add(add(mul(t[k], lx), mul(bt[k], ly)), mul(axis[k], lz));
            unsafe { _mm256_storeu_ps(out[k].as_mut_ptr(), v) };
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// Eight lanes at once give the scalar maths' bits, on random numbers
    /// and normals, normals along the axes (both signs of zero), and the
    /// edges of the numbers' range.
    #[test]
    fn eight_lanes_give_the_scalar_bits() {
        let mut rng = Rng::for_item(7, 0);
        let mut normals = vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        normals.push(Vec3::new(0.6, 0.8, -0.0));
        normals.push(Vec3::new(-0.6, 0.0, 0.8));
        let mut numbers = vec![0.0, 0.25, 0.5, 0.75, 0.999_999_94, 0.125, 1e-8, 0.875];
        for _ in 0..4000 {
            normals.push(crate::sampling::uniform_sphere(rng.next_2d()));
            numbers.push(rng.next_f32());
        }
        for chunk in 0..normals.len() / 8 {
            let lane = |i: usize| chunk * 8 + i;
            let u = [
                std::array::from_fn(|i| numbers[lane(i) % numbers.len()]),
                std::array::from_fn(|i| numbers[(lane(i) * 7 + 3) % numbers.len()]),
            ];
            let n: Lanes3 = std::array::from_fn(|k| std::array::from_fn(|i| normals[lane(i)][k]));
            let got = cosine_directions(&u, &n);
            let want = scalar(&u, &n);
            for (g, w) in got.iter().flatten().zip(want.iter().flatten()) {
                assert!(g.to_bits() == w.to_bits() || (g.is_nan() && w.is_nan()), "{got:?} vs {want:?}");
            }
        }
    }
}
