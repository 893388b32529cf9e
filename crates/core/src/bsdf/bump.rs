//! Cycles' bump map correction (Blender's material setting "Bump Map
//! Correction", on by default): at a point whose normal a normal texture
//! bends, the diffuse lobes take a microfacet shadowing of the light's
//! direction seen from the smooth normal, as if the bent normal were the
//! mean of a GGX surface as rough as the bend (Conty Estevez, Lecocq and
//! Stein 2019, "A Microfacet-Based Shadowing Function to Solve the Bump
//! Terminator Problem"). Without it a normal-mapped surface lit from
//! grazing angles is a few per cent brighter than in Blender (normal_map.py:
//! path 1.036–1.045× Cycles on tilted tiles; 0.997–1.002× with it).

use super::ggx;
use glam::Vec3;

/// The shadowing of one normal-mapped point: its smooth normal and the
/// roughness α² = clamp(tan²θd / 8) of its bend θd.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BumpShadow {
    smooth: Vec3,
    alpha: f32,
}

impl BumpShadow {
    /// The point of smooth (interpolated) normal `smooth` bent to `bent`
    /// (both unit, in any one frame); None where the two agree (the term
    /// is 1 there, as Cycles skips it).
    pub fn new(smooth: Vec3, bent: Vec3) -> Option<BumpShadow> {
        let cos_d = smooth.dot(bent).abs();
        if cos_d >= 1.0 || smooth == bent {
            return None;
        }
        let alpha2 = (0.125 * (1.0 / (cos_d * cos_d) - 1.0)).clamp(0.0, 1.0);
        Some(BumpShadow { smooth, alpha: alpha2.sqrt() })
    }

    /// The diffuse lobes' factor for light from the unit direction `wi`
    /// (same frame as `new`'s normals): Smith's GGX masking G1 of |Ns·wi|,
    /// 0 in the smooth surface's plane.
    pub fn term(&self, wi: Vec3) -> f32 {
        let cos_i = self.smooth.dot(wi).abs();
        if cos_i >= 1.0 {
            return 1.0;
        }
        if cos_i < 1e-6 {
            return 0.0;
        }
        // G1 in a frame whose z is the smooth normal: only cos θi matters.
        ggx::g1(Vec3::new((1.0 - cos_i * cos_i).sqrt(), 0.0, cos_i), self.alpha)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// By hand: a bend of 34.8° (normal_map.py's tiles: (0.45, 0.35, 0.82))
    /// gives α² = tan²θd / 8 = 0.0602; light at 60° from the smooth normal
    /// keeps G1 = 2 / (1 + √(1 + 0.0602 · 3)) = 0.95853; the term is 1
    /// along the smooth normal, 0 in its plane, the same from either side,
    /// and there is none where nothing bends.
    #[test]
    fn the_term_is_ggx_masking_of_the_bend() {
        let bent = Vec3::new(0.45, 0.35, (1.0f32 - 0.45 * 0.45 - 0.35 * 0.35).sqrt());
        let b = BumpShadow::new(Vec3::Z, bent).unwrap();
        let tan2 = 1.0 / (bent.z * bent.z) - 1.0;
        assert!((b.alpha * b.alpha - tan2 / 8.0).abs() < 1e-6);
        let at_60 = Vec3::new(60f32.to_radians().sin(), 0.0, 0.5);
        let want = 2.0 / (1.0 + (1.0 + tan2 / 8.0 * 3.0).sqrt());
        assert!((b.term(at_60) - want).abs() < 1e-6, "{} against {want}", b.term(at_60));
        assert!((want - 0.95853).abs() < 1e-4, "{want}");
        assert_eq!(b.term(Vec3::Z), 1.0);
        assert_eq!(b.term(Vec3::X), 0.0);
        assert_eq!(b.term(-at_60), b.term(at_60));
        assert!(BumpShadow::new(Vec3::Z, Vec3::Z).is_none());
        // A bend of 70.5° (tan² = 8) or more: α = 1, G1 = 2 / (1 + √(1 + tan²θi)).
        let steep = BumpShadow::new(Vec3::Z, Vec3::new((8.0f32 / 9.0).sqrt(), 0.0, 1.0 / 3.0)).unwrap();
        assert!((steep.term(at_60) - 2.0 / (1.0 + 2.0)).abs() < 1e-5, "{}", steep.term(at_60));
    }
}
