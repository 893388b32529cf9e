//! WGSL shared between passes, written once: each piece is a [`Module`]
//! naming the modules it needs, and [`compose`] writes a shader's source
//! with every module it uses exactly once, requirements first.
//!
//! Written here rather than taken from naga_oil or wesl: composition is all
//! the project needs (no per-module namespaces or conditional code), and
//! those crates pin other naga versions than wgpu 30's.

/// A piece of WGSL and the modules it calls into.
pub struct Module {
    pub name: &'static str,
    pub source: &'static str,
    pub requires: &'static [&'static Module],
}

/// The source of a shader made of `modules` (the pass's own module last):
/// each module and its requirements once, requirements before users.
pub fn compose(modules: &[&Module]) -> String {
    fn visit(module: &Module, written: &mut Vec<&'static str>, out: &mut String) {
        if written.contains(&module.name) {
            return;
        }
        for required in module.requires {
            visit(required, written, out);
        }
        written.push(module.name);
        out.push_str("// ---- ");
        out.push_str(module.name);
        out.push_str(" ----\n");
        out.push_str(module.source);
        out.push('\n');
    }
    let mut written = Vec::new();
    let mut out = String::new();
    for module in modules {
        visit(module, &mut written, &mut out);
    }
    out
}

pub static CONSTANTS: Module = Module { name: "constants.wgsl", source: include_str!("constants.wgsl"), requires: &[] };

/// The stored photon's encodings (hikari_core::photon::encoding).
pub static PHOTON_ENCODING: Module =
    Module { name: "photon_encoding.wgsl", source: include_str!("photon_encoding.wgsl"), requires: &[] };

/// PCG32 streams (hikari_core::sampling::Rng).
pub static RANDOM: Module = Module { name: "random.wgsl", source: include_str!("random.wgsl"), requires: &[] };

/// Direction and phase sampling (hikari_core::sampling, medium::phase).
pub static SAMPLING: Module =
    Module { name: "sampling.wgsl", source: include_str!("sampling.wgsl"), requires: &[&CONSTANTS] };

/// Fresnel and refraction (hikari_core::material).
pub static OPTICS: Module = Module { name: "optics.wgsl", source: include_str!("optics.wgsl"), requires: &[] };

/// The per-surface material record (scene_upload::GpuSurface).
pub static SURFACE: Module =
    Module { name: "surface.wgsl", source: include_str!("surface.wgsl"), requires: &[&crate::features::FEATURES] };

/// The glTF metallic–roughness BRDF (hikari_core::bsdf), and a surface's.
pub static BSDF: Module = Module {
    name: "bsdf.wgsl",
    source: include_str!("bsdf.wgsl"),
    requires: &[&CONSTANTS, &SAMPLING, &OPTICS, &SURFACE],
};

/// Glass, smooth or rough (hikari_core::bsdf::dielectric).
pub static DIELECTRIC: Module =
    Module { name: "dielectric.wgsl", source: include_str!("dielectric.wgsl"), requires: &[&BSDF, &OPTICS] };

/// Mitsuba's spot falloff (hikari_core::light::spot_falloff).
pub static SPOT: Module = Module { name: "spot.wgsl", source: include_str!("spot.wgsl"), requires: &[] };

/// Watertight ray–region-triangle crossings (hikari_core::medium::region).
pub static REGION_CROSSING: Module =
    Module { name: "region_crossing.wgsl", source: include_str!("region_crossing.wgsl"), requires: &[] };

/// Closest hits in the flat BVH (hikari_core::geometry::FlatBvh).
pub static BVH: Module = Module { name: "bvh.wgsl", source: include_str!("bvh.wgsl"), requires: &[] };

/// The geometric and shading normals at a BVH hit (Accel::intersect's),
/// from the includer's `flat_shading`.
pub static HIT_NORMALS: Module =
    Module { name: "hit_normals.wgsl", source: include_str!("hit_normals.wgsl"), requires: &[&BVH, &OPTICS] };

/// `prim_is_there` for bvh.wgsl: the alpha test of cut-outs (alphaMode
/// MASK) and BLEND surfaces at a candidate hit of the ray from `o` along
/// `d`, as `Accel` tests it. The includer declares `prims`, `surfaces` and
/// `texture_data`.
pub static CUT_OUTS: Module = Module {
    name: "cut_outs",
    source: "fn prim_is_there(prim: u32, b: vec2<f32>, o: vec3<f32>, d: vec3<f32>) -> bool {\n\
             if (!CUT_OUTS) { return true; }\n\
             let p = prims[prim];\n\
             if (p.is_sphere != 0u) { return true; }\n\
             let s = surfaces.all[p.surface];\n\
             if (s.alpha_cutoff < 0.0) { return true; }\n\
             let alpha = surface_point(s, primitive_uv(prim, b), vec2<f32>(0.0), vec2<f32>(0.0)).alpha;\n\
             return is_there_for_ray(s, alpha, o, d, p.source);\n\
             }\n",
    requires: &[&crate::textures::SURFACE_POINT],
};

/// Prefix sums across workgroups for order-keeping compaction.
pub static PREFIX_SUM: Module =
    Module { name: "prefix_sum.wgsl", source: include_str!("prefix_sum.wgsl"), requires: &[] };
/// `SCAN_WORKGROUP` in prefix_sum.wgsl (a test reads it back from the WGSL).
pub const SCAN_WORKGROUP: u32 = 256;

/// One volume photon's chord and in-scattering (hikari_core::estimate).
pub static VOLUME_CHORD: Module = Module {
    name: "volume_chord.wgsl",
    source: include_str!("volume_chord.wgsl"),
    requires: &[&CONSTANTS, &PHOTON_ENCODING, &crate::media::MEDIA],
};

/// The radiance estimate (hikari_core::estimate).
pub static ESTIMATE: Module = Module {
    name: "estimate.wgsl",
    source: include_str!("estimate.wgsl"),
    requires: &[&CONSTANTS, &PHOTON_ENCODING, &crate::gbuffer::geometric_normal::GEOMETRIC_NORMAL],
};

/// A photon's weight at a glossy point (the gathered lobes of bsdf.wgsl), for
/// the passes that estimate over glossy surfaces (they bind `surfaces`).
pub static PHOTON_BRDF: Module = Module {
    name: "photon_brdf.wgsl",
    source: include_str!("photon_brdf.wgsl"),
    requires: &[&ESTIMATE, &SURFACE, &BSDF],
};

/// `loop_iteration()` for the passes whose loops the host bounds exactly
/// (shared WGSL calls it in every loop; the specular pass and the tracer count).
pub static UNCOUNTED_LOOPS: Module =
    Module { name: "uncounted_loops", source: "fn loop_iteration() -> bool { return true; }\n", requires: &[] };

/// `vs_fullscreen`: one triangle over the screen (`binding::fullscreen_pipeline`).
pub static FULLSCREEN: Module =
    Module { name: "fullscreen.wgsl", source: include_str!("fullscreen.wgsl"), requires: &[] };

#[cfg(test)]
mod tests {
    use super::*;

    static A: Module = Module { name: "a", source: "A", requires: &[] };
    static B: Module = Module { name: "b", source: "B", requires: &[&A] };
    static C: Module = Module { name: "c", source: "C", requires: &[&A, &B] };

    #[test]
    fn each_module_once_requirements_first() {
        let out = compose(&[&C, &B, &A]);
        let order: Vec<&str> = out.lines().filter(|l| !l.starts_with("//")).collect();
        assert_eq!(order, ["A", "B", "C"]);
    }
}
