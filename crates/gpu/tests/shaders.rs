//! Every WGSL source parses and validates with naga, and every Rust struct
//! shared with WGSL has the size and field offsets naga computes.

use hikari_core::photon::Photon;
use hikari_gpu::direct::DirectParams;
use hikari_gpu::gbuffer::GBufferParams;
use hikari_gpu::lod::LodParams;
use hikari_gpu::photons::LodPhoton;
use hikari_gpu::scene_upload::{GpuSurface, GpuVertex};
use hikari_gpu::shadow::ShadowViewParams;
use hikari_gpu::shadow::light_samples::{GpuLight, GpuLightSample};
use hikari_gpu::splat::SplatParams;
use std::mem::{offset_of, size_of};

fn shaders() -> Vec<(&'static str, String)> {
    vec![
        ("gbuffer.wgsl", hikari_gpu::gbuffer::shader_source()),
        ("gbuffer.wgsl + gbuffer_storage.wgsl", hikari_gpu::gbuffer::storage_shader_source()),
        ("present.wgsl", hikari_gpu::present::shader_source()),
        ("splat.wgsl", hikari_gpu::splat::shader_source()),
        ("estimate.wgsl", hikari_gpu::wgsl::compose(&[&hikari_gpu::wgsl::ESTIMATE])),
        // Its includers bind the surfaces buffer (bsdf.wgsl reads the sheen table there).
        (
            "photon_brdf.wgsl",
            hikari_gpu::wgsl::compose(&[&hikari_gpu::wgsl::PHOTON_BRDF])
                + "@group(0) @binding(0) var<storage, read> surfaces: Surfaces;\n",
        ),
        ("shadow.wgsl", hikari_gpu::shadow::shader_source()),
        ("direct.wgsl", hikari_gpu::direct::shader_source()),
        ("lod.wgsl", hikari_gpu::lod::shader_source()),
        ("specular.wgsl", hikari_gpu::specular::shader_source()),
        ("resolve.wgsl", hikari_gpu::resolve::shader_source()),
        ("optical_depth.wgsl", hikari_gpu::media::optical_depth_shader_source()),
        ("volume.wgsl", hikari_gpu::volume::shader_source()),
        ("accumulate.wgsl", hikari_gpu::accumulate::SHADER.to_string()),
        ("trace.wgsl", hikari_gpu::trace::trace_shader_source()),
        ("compact.wgsl", hikari_gpu::trace::compact_shader_source()),
        ("tiled.wgsl (f32)", hikari_gpu::tiled::shader_source(wgpu::TextureFormat::Rgba32Float)),
        ("tiled.wgsl (f16)", hikari_gpu::tiled::shader_source(wgpu::TextureFormat::Rgba16Float)),
    ]
}

fn parse(name: &str, source: &str) -> naga::Module {
    let module =
        naga::front::wgsl::parse_str(source).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    module
}

#[test]
fn every_shader_validates() {
    for (name, source) in shaders() {
        parse(name, &source);
    }
}

/// The line of the first expression in `source` that mixes `&&` and `||`
/// without parentheses between them, which WGSL's grammar forbids and
/// Chromium's compiler (Tint) refuses while naga takes it (the web page's
/// shaders once failed so). Comments are skipped; each parenthesis or
/// bracket level, argument and statement is its own expression.
fn bare_mixed_logic(source: &str) -> Option<usize> {
    let mut levels = vec![(false, false)];
    for (number, line) in source.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("").as_bytes();
        let mut k = 0;
        while k < code.len() {
            let pair = code.get(k + 1) == Some(&code[k]);
            match code[k] {
                b'(' | b'[' => levels.push((false, false)),
                b')' | b']' => {
                    levels.pop();
                    if levels.is_empty() {
                        levels.push((false, false));
                    }
                }
                b';' | b'{' | b'}' | b',' => *levels.last_mut().unwrap() = (false, false),
                b'&' | b'|' if pair => {
                    let level = levels.last_mut().unwrap();
                    if code[k] == b'&' {
                        level.0 = true
                    } else {
                        level.1 = true
                    }
                    if level.0 && level.1 {
                        return Some(number + 1);
                    }
                    k += 1;
                }
                _ => {}
            }
            k += 1;
        }
    }
    None
}

#[test]
fn no_shader_mixes_and_with_or_unparenthesised() {
    assert_eq!(bare_mixed_logic("let a = x && y\n    || z;"), Some(2));
    assert_eq!(bare_mixed_logic("let a = (x && y) || z; // a && b || c"), None);
    assert_eq!(bare_mixed_logic("f(x && y, z || w); if (a || b) { c = d && e; }"), None);
    for (name, source) in shaders() {
        if let Some(line) = bare_mixed_logic(&source) {
            panic!("{name}:{line}: && and || mixed without parentheses: {}", source.lines().nth(line - 1).unwrap());
        }
    }
}

/// (size, [(field, offset)]) of the WGSL struct `name` in `source`.
fn wgsl_layout(source: &str, name: &str) -> (u32, Vec<(String, u32)>) {
    let module = parse(name, source);
    for (_, ty) in module.types.iter() {
        if ty.name.as_deref() == Some(name) {
            if let naga::TypeInner::Struct { members, span } = &ty.inner {
                return (*span, members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect());
            }
        }
    }
    panic!("struct {name} not found");
}

macro_rules! assert_layout {
    ($source:expr, $wgsl:literal, $rust:ty, [$($field:ident),*]) => {{
        let (size, members) = wgsl_layout(&$source, $wgsl);
        assert_eq!(size as usize, size_of::<$rust>(), "size of {}", $wgsl);
        let rust = [$((stringify!($field), offset_of!($rust, $field))),*];
        assert_eq!(members.len(), rust.len(), "field count of {}", $wgsl);
        for ((wname, woff), (rname, roff)) in members.iter().zip(rust) {
            assert_eq!(wname, rname, "field order of {}", $wgsl);
            assert_eq!(*woff as usize, roff, "offset of {}.{}", $wgsl, wname);
        }
    }};
}

#[test]
fn shared_structs_match_wgsl_layouts() {
    let gbuffer = hikari_gpu::gbuffer::shader_source();
    assert_layout!(gbuffer, "GBufferParams", GBufferParams, [clip_from_world, camera_position, blend_seed]);
    assert_layout!(
        gbuffer,
        "Surface",
        GpuSurface,
        [
            albedo,
            kind,
            emission,
            ior,
            specular,
            two_sided,
            metallic,
            roughness,
            specular_factor,
            glossy,
            emission_per_texel,
            alpha_cutoff,
            base_color_texture,
            metallic_roughness_texture,
            emissive_texture,
            alpha_factor,
            normal_texture,
            normal_scale,
            clearcoat,
            clearcoat_roughness,
            dielectric_f0,
            sheen_roughness,
            transmission,
            transmission_texture,
            sheen_color,
            transmission_ior,
            specular_color,
            layer_textures
        ]
    );
    let splat = hikari_gpu::splat::shader_source();
    assert_layout!(
        splat,
        "SplatParams",
        SplatParams,
        [clip_from_world, radius, power_unit, normal_test, _pad, camera_position, _pad1]
    );
    let shadow = hikari_gpu::shadow::shader_source();
    assert_layout!(shadow, "ShadowView", ShadowViewParams, [clip_from_world, light_position, direction, blend_seed]);
    let direct = hikari_gpu::direct::shader_source();
    assert_layout!(direct, "DirectParams", DirectParams, [light_count, shadow_size, bias, pass_index]);
    assert_layout!(direct, "ShadowView", ShadowViewParams, [clip_from_world, light_position, direction, blend_seed]);
    assert_layout!(
        direct,
        "Light",
        GpuLight,
        [
            position,
            kind,
            emission,
            first_sample,
            axis,
            sample_count,
            edge_v,
            cutoff,
            falloff_start,
            sample_area,
            two_sided,
            mapped,
            first_triangle,
            triangle_count
        ]
    );
    assert_layout!(direct, "LightSample", GpuLightSample, [position, first_view, direction, view_count, weight, _pad]);
    let specular = hikari_gpu::specular::shader_source();
    assert_layout!(
        specular,
        "SpecularParams",
        hikari_gpu::specular::SpecularParams,
        [
            width,
            height,
            normal_test,
            power_unit,
            camera_position,
            tan_half_fov,
            camera_right,
            aspect,
            camera_up,
            epsilon,
            camera_forward,
            max_depth,
            global_radius,
            global_buckets,
            global_start_offset,
            global_photon_offset,
            caustic_radius,
            caustic_buckets,
            caustic_start_offset,
            caustic_photon_offset,
            volume_radius,
            volume_buckets,
            volume_start_offset,
            volume_photon_offset,
            volume_min,
            jitter_x,
            volume_max,
            jitter_y,
            sky_radiance,
            light_table,
            sample_table,
            view_table,
            region_table,
            environment_table,
            shading_table,
            _pad0,
            _pad1,
            _pad2
        ]
    );
    assert_layout!(specular, "FlatNode", hikari_core::geometry::FlatNode, [min, prim_count, max, first]);
    assert_layout!(specular, "FlatPrim", hikari_core::geometry::FlatPrim, [a, is_sphere, b, surface, c, source]);
    assert_layout!(
        specular,
        "SliceParams",
        hikari_gpu::specular::SliceParams,
        [index, count, iteration_budget, pass_index]
    );
    let resolve = hikari_gpu::resolve::shader_source();
    let (size, members) = wgsl_layout(&resolve, "Terms");
    assert_eq!(size as usize, size_of::<hikari_gpu::resolve::Terms>());
    assert_eq!(members[4], ("volume".to_string(), offset_of!(hikari_gpu::resolve::Terms, volume) as u32));
    let present = hikari_gpu::present::shader_source();
    assert_layout!(present, "PresentParams", hikari_gpu::present::PresentParams, [scale, encode_srgb, mode, _pad1]);
    let volume = hikari_gpu::volume::shader_source();
    assert_layout!(
        volume,
        "VolumeParams",
        hikari_gpu::volume::VolumeParams,
        [clip_from_world, radius, power_unit, _pad0, _pad1]
    );
    assert_layout!(
        volume,
        "MediaParams",
        hikari_gpu::media::MediaParams,
        [
            global_sigma_t,
            region_triangles,
            forward,
            tan_half_fov,
            right,
            aspect,
            up,
            slices,
            camera_position,
            max_distance,
            phases,
            image_size,
            jitter,
            distant_disc
        ]
    );
    assert_layout!(volume, "RegionTriangle", hikari_gpu::media::RegionTriangle, [a, b, c, sigma_t]);
    use hikari_gpu::trace::{CompactParams, PhotonRecord, TraceLight, TraceMedium, TraceParams, TraceTriangle};
    let trace = hikari_gpu::trace::trace_shader_source();
    assert_layout!(
        trace,
        "TraceParams",
        TraceParams,
        [
            mixed_seed,
            increment,
            first_path,
            paths,
            max_bounces,
            light_count,
            epsilon,
            record_capacity,
            iteration_budget,
            medium_count,
            global_mask,
            region_triangles,
            _pad0,
            distant_disc,
            light_table,
            medium_table,
            region_table,
            emissive_table
        ]
    );
    assert_layout!(
        trace,
        "TraceLight",
        TraceLight,
        [
            origin,
            kind,
            axis,
            radius,
            edge_v,
            cos_cutoff,
            normal,
            cutoff,
            power,
            falloff_start,
            probability,
            first_triangle,
            triangle_count,
            two_sided,
            sky_image,
            _pad0,
            _pad1,
            _pad2
        ]
    );
    assert_layout!(
        trace,
        "TraceTriangle",
        TraceTriangle,
        [v0, cumulative_area, v1, start_area, v2, _pad0, normal, _pad1]
    );
    assert_layout!(
        trace,
        "TraceMedium",
        TraceMedium,
        [sigma_t, phase_slot, sigma_s, phase_kind, phase_parameter, _pad0, _pad1, _pad2]
    );
    assert_layout!(
        trace,
        "TraceRegionTriangle",
        hikari_gpu::trace::TraceRegionTriangle,
        [a, medium, b, _pad0, c, _pad1]
    );
    let record_fields = |source: &String| {
        assert_layout!(
            source,
            "PhotonRecord",
            PhotonRecord,
            [path, tag, position_x, position_y, position_z, power_rgb9e5, direction_and_class, _pad]
        );
    };
    record_fields(&trace);
    let compact = hikari_gpu::trace::compact_shader_source();
    record_fields(&compact);
    assert_layout!(compact, "CompactParams", CompactParams, [elements, paths, record_capacity, workgroups]);
    assert_layout!(
        trace,
        "FlatShading",
        hikari_core::geometry::FlatShading,
        [geometric_normal, has_vertex_normals, vertex_normals]
    );
    let tiled = hikari_gpu::tiled::shader_source(wgpu::TextureFormat::Rgba32Float);
    assert_layout!(
        tiled,
        "TiledParams",
        hikari_gpu::tiled::TiledParams,
        [
            clip_from_world,
            radius,
            power_unit,
            normal_test,
            width,
            height,
            tiles_x,
            tiles_y,
            list_capacity,
            scan_workgroups,
            slice_start,
            slice_length,
            last_slice,
            loop_budget,
            _pad0,
            _pad1,
            _pad2
        ]
    );
    assert_layout!(
        tiled,
        "LodPhoton",
        LodPhoton,
        [position_x, position_y, position_z, power_rgb9e5, direction_and_class, scale]
    );
    let lod = hikari_gpu::lod::shader_source();
    assert_layout!(
        lod,
        "LodParams",
        LodParams,
        [eye, near, far, groups, count, enabled, workgroups, _pad0, _pad1, _pad2]
    );
    assert_layout!(
        lod,
        "LodPhoton",
        LodPhoton,
        [position_x, position_y, position_z, power_rgb9e5, direction_and_class, scale]
    );
}

/// Vertex attributes are laid out by hand (vertex_attr_array! would pack
/// them tightly): the arrays the pipelines use match the Rust structs.
#[test]
fn vertex_attribute_offsets_match_rust_structs() {
    let offsets = |attrs: &[wgpu::VertexAttribute]| attrs.iter().map(|a| a.offset as usize).collect::<Vec<_>>();
    // The LOD pass reads stored photons as 5 words each.
    assert_eq!(size_of::<Photon>(), 20);
    assert_eq!(
        (offset_of!(Photon, position), offset_of!(Photon, power_rgb9e5), offset_of!(Photon, direction_and_class)),
        (0, 12, 16)
    );
    assert_eq!(
        offsets(&hikari_gpu::photons::PHOTON_ATTRIBUTES),
        [
            offset_of!(LodPhoton, position_x),
            offset_of!(LodPhoton, power_rgb9e5),
            offset_of!(LodPhoton, direction_and_class),
            offset_of!(LodPhoton, scale)
        ]
    );
    assert_eq!(
        offsets(&hikari_gpu::gbuffer::VERTEX_ATTRIBUTES),
        [
            offset_of!(GpuVertex, position),
            offset_of!(GpuVertex, normal),
            offset_of!(GpuVertex, geometric_normal),
            offset_of!(GpuVertex, surface),
            offset_of!(GpuVertex, uv),
            offset_of!(GpuVertex, tangent)
        ]
    );
}
