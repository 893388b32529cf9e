//! The G-buffer's geometric normal, in its position's w (0 where no
//! surface is seen): 1 where the shading normal is the geometric one
//! (`estimate::is_bent` false), else −(1 + an octahedral code of 12 + 12
//! bits), an integer down to −2^24, exact in f32. The photon gathers weigh
//! `estimate::shading_normal_factor` with it, as photon-cpu does. Its
//! albedo's alpha keeps the material kind the passes and tests read, and
//! at a point a normal texture bends, the smooth normal it was bent from
//! (`pack_kind`), for the diffuse lobes' bump shadowing. geometric_normal.wgsl is the GPU's half; this
//! Rust one reads a G-buffer back (the twin tests).

use glam::Vec3;
use hikari_core::estimate::is_bent;
use hikari_core::photon::{decode_octahedral, encode_octahedral};

/// The WGSL half (`pack_geometric_normal`, `unpack_geometric_normal`, `is_bent`).
pub static GEOMETRIC_NORMAL: crate::wgsl::Module = crate::wgsl::Module {
    name: "geometric_normal.wgsl",
    source: include_str!("geometric_normal.wgsl"),
    requires: &[&crate::wgsl::PHOTON_ENCODING],
};

/// What position.w stores where a surface shading with `ns` across `ng`
/// (unit, on the same side) is seen.
pub fn pack_geometric_normal(ns: Vec3, ng: Vec3) -> f32 {
    if !is_bent(ns, ng) { 1.0 } else { -((1 + encode_octahedral(ng, 12)) as f32) }
}

/// The geometric normal from a seen pixel's position.w and its shading
/// normal `ns`.
pub fn unpack_geometric_normal(packed: f32, ns: Vec3) -> Vec3 {
    if packed > 0.0 { ns } else { decode_octahedral((-packed) as u32 - 1, 12) }
}

/// The kinds albedo.a's smooth-normal code steps over.
pub const KIND_CODES: u32 = 8;

/// What albedo.a stores for `kind` at a point of unit smooth normal
/// `smooth` that a normal texture bent where `bumped`: the kind, plus
/// KIND_CODES · (1 + its 10 + 10-bit octahedral code) where bumped.
pub fn pack_kind(kind: u32, smooth: Vec3, bumped: bool) -> f32 {
    if !bumped { kind as f32 } else { (kind + KIND_CODES * (1 + encode_octahedral(smooth, 10))) as f32 }
}

/// The kind from albedo.a.
pub fn pixel_kind(packed: f32) -> u32 {
    packed as u32 % KIND_CODES
}

/// The smooth normal from albedo.a; None where no normal texture bent it.
pub fn pixel_smooth_normal(packed: f32) -> Option<Vec3> {
    let code = packed as u32 / KIND_CODES;
    (code > 0).then(|| decode_octahedral(code - 1, 10))
}

#[cfg(test)]
mod tests {
    use super::*;
    use hikari_core::sampling::{Rng, uniform_sphere};

    #[test]
    fn a_geometric_normal_comes_back_within_its_codes_step() {
        let mut rng = Rng::for_item(5, 0);
        for _ in 0..10_000 {
            let ng = uniform_sphere(rng.next_2d());
            let ns = (ng + uniform_sphere(rng.next_2d()) * 0.3).normalize();
            if !is_bent(ns, ng) {
                continue; // pushed along ng itself
            }
            let packed = pack_geometric_normal(ns, ng);
            assert!((-16_777_216.0..=-1.0).contains(&packed) && packed.fract() == 0.0, "{packed}");
            let back = unpack_geometric_normal(packed, ns);
            // 12 bits over [-1, 1]: steps of 1/2048, under 0.1° of arc.
            assert!(back.dot(ng) > (0.1f32).to_radians().cos(), "{ng} -> {back}");
        }
    }

    #[test]
    fn a_flat_point_stores_one_and_gives_back_its_shading_normal() {
        let n = Vec3::new(0.3, -0.4, 0.866).normalize();
        assert_eq!(pack_geometric_normal(n, n), 1.0);
        assert_eq!(unpack_geometric_normal(1.0, n), n);
        // Rounding of an interpolated normal that equals the face's is flat too.
        let nearly = (n + Vec3::splat(1e-4)).normalize();
        assert_eq!(pack_geometric_normal(nearly, n), 1.0);
    }

    #[test]
    fn the_kind_and_a_smooth_normal_share_albedo_alpha() {
        let mut rng = Rng::for_item(6, 0);
        for kind in 0..KIND_CODES {
            assert_eq!(pack_kind(kind, Vec3::Z, false), kind as f32);
            assert_eq!((pixel_kind(kind as f32), pixel_smooth_normal(kind as f32)), (kind, None));
            for _ in 0..2_000 {
                let n = uniform_sphere(rng.next_2d());
                let packed = pack_kind(kind, n, true);
                assert!(packed < 16_777_216.0 && packed.fract() == 0.0, "{packed}");
                assert_eq!(pixel_kind(packed), kind);
                // 10 bits over [-1, 1]: steps of 1/512, under 0.4° of arc.
                let back = pixel_smooth_normal(packed).expect("a smooth normal");
                assert!(back.dot(n) > (0.4f32).to_radians().cos(), "{n} -> {back}");
            }
        }
    }
}
