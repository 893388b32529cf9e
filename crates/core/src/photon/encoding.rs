//! Bit-exact encodings of photon power and direction. The GPU decodes the
//! same bits with the same arithmetic, so both sides see identical photons.

use glam::{Vec2, Vec3};

const MANTISSA_BITS: i32 = 9;
const EXP_BIAS: i32 = 15;

/// Shared-exponent RGB (the RGB9E5 format of GL/Vulkan): 9-bit mantissas,
/// 5-bit exponent; error ≤ 2⁻⁹ of the largest channel.
#[inline]
pub fn encode_rgb9e5(c: Vec3) -> u32 {
    const MAX_VALUE: f32 = 511.0 / 512.0 * 65536.0;
    let c = c.clamp(Vec3::ZERO, Vec3::splat(MAX_VALUE));
    let max_c = c.max_element();
    // Below the smallest representable step: zero (also catches NaN, which clamp keeps).
    if !(max_c >= 2f32.powi(-EXP_BIAS - MANTISSA_BITS)) {
        return 0;
    }
    // floor(log2(max_c)) from the float's exponent bits (max_c is normal here).
    let floor_log2 = ((max_c.to_bits() >> 23) & 0xff) as i32 - 127;
    let mut exp = floor_log2.max(-EXP_BIAS - 1) + 1 + EXP_BIAS;
    let mut inv_scale = pow2(MANTISSA_BITS + EXP_BIAS - exp);
    if (max_c * inv_scale + 0.5) as u32 == 1 << MANTISSA_BITS {
        exp += 1;
        inv_scale *= 0.5;
    }
    // Round half up; inputs are non-negative and scaling by 2^k is exact.
    let q = |x: f32| ((x * inv_scale + 0.5) as u32).min((1 << MANTISSA_BITS) - 1);
    q(c.x) | (q(c.y) << 9) | (q(c.z) << 18) | ((exp as u32) << 27)
}

/// 2^k for the normal-float range, exactly, from the exponent bits.
fn pow2(k: i32) -> f32 {
    f32::from_bits(((k + 127) as u32) << 23)
}

pub fn decode_rgb9e5(bits: u32) -> Vec3 {
    let scale = pow2((bits >> 27) as i32 - EXP_BIAS - MANTISSA_BITS);
    Vec3::new((bits & 511) as f32, ((bits >> 9) & 511) as f32, ((bits >> 18) & 511) as f32) * scale
}

/// The octahedral map: a unit direction's point in the square [-1, 1]²
/// (each code quantises the square its own way).
#[inline]
pub fn octahedral_square(d: Vec3) -> Vec2 {
    let d = d / (d.x.abs() + d.y.abs() + d.z.abs());
    let mut p = Vec2::new(d.x, d.y);
    if d.z < 0.0 {
        p = (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * Vec2::new(p.x.signum(), p.y.signum());
    }
    p.clamp(Vec2::NEG_ONE, Vec2::ONE)
}

/// The direction at point `p` of the octahedral map's square.
#[inline]
pub fn octahedral_direction(p: Vec2) -> Vec3 {
    let z = 1.0 - p.x.abs() - p.y.abs();
    let t = (-z).max(0.0);
    let x = p.x + if p.x >= 0.0 { -t } else { t };
    let y = p.y + if p.y >= 0.0 { -t } else { t };
    Vec3::new(x, y, z).normalize()
}

/// A unit direction's octahedral point quantised to `bits` per axis, x in
/// the low `bits` and y above (`bits` at most 16).
#[inline]
pub fn encode_octahedral(d: Vec3, bits: u32) -> u32 {
    let mask = (1u32 << bits) - 1;
    let q = |x: f32| ((x * 0.5 + 0.5) * mask as f32 + 0.5) as u32 & mask;
    let p = octahedral_square(d);
    q(p.x) | (q(p.y) << bits)
}

/// The direction of [`encode_octahedral`]'s code of `bits` per axis.
#[inline]
pub fn decode_octahedral(code: u32, bits: u32) -> Vec3 {
    let mask = (1u32 << bits) - 1;
    octahedral_direction(Vec2::new((code & mask) as f32, ((code >> bits) & mask) as f32) / mask as f32 * 2.0 - 1.0)
}

/// The photon's direction code: 15 + 15 bits.
#[inline]
pub fn encode_octahedral_15(d: Vec3) -> u32 {
    encode_octahedral(d, 15)
}

#[inline]
pub fn decode_octahedral_15(bits: u32) -> Vec3 {
    decode_octahedral(bits, 15)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Rng, uniform_sphere};

    #[test]
    fn rgb9e5_round_trips_within_its_precision() {
        let mut rng = Rng::for_item(21, 0);
        for _ in 0..10_000 {
            let scale = 2f32.powf(rng.next_f32() * 20.0 - 10.0);
            let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * scale;
            let back = decode_rgb9e5(encode_rgb9e5(c));
            let err = (back - c).abs().max_element() / c.max_element();
            assert!(err <= 1.0 / 512.0 + 1e-6, "{c} -> {back}");
        }
        assert_eq!(decode_rgb9e5(encode_rgb9e5(Vec3::ZERO)), Vec3::ZERO);
        assert_eq!(decode_rgb9e5(encode_rgb9e5(Vec3::ONE)), Vec3::ONE);
    }

    #[test]
    fn octahedral_round_trip_is_accurate() {
        let mut rng = Rng::for_item(22, 0);
        for _ in 0..10_000 {
            let d = uniform_sphere(rng.next_2d());
            let back = decode_octahedral_15(encode_octahedral_15(d));
            assert!((d - back).length() < 3e-4, "{d} -> {back}");
        }
    }
}
