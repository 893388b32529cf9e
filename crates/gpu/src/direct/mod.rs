//! The direct-light pass: a fullscreen pass shading every visible diffuse
//! pixel from all shadow-mapped light samples.

use crate::features::SceneFeatures;
use crate::gbuffer::GBuffer;
use crate::shadow::ShadowMaps;
use crate::shadow::light_samples::GpuLights;
use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

/// Light evaluation shared with the specular pass; needs the includer's bindings.
pub static LIGHT_EVAL: crate::wgsl::Module = crate::wgsl::Module {
    name: "light_eval.wgsl",
    source: include_str!("light_eval.wgsl"),
    requires: &[
        &crate::wgsl::CONSTANTS,
        &crate::wgsl::SPOT,
        &crate::shadow::SHADOW_VIEW,
        &crate::wgsl::RANDOM,
        &crate::wgsl::SAMPLING,
        &crate::wgsl::BSDF,
        &crate::features::FEATURES,
    ],
};

/// light_eval.wgsl's lights, samples and views from the includer's arrays
/// `lights`, `samples` and `views`.
pub static LIGHT_ARRAYS: crate::wgsl::Module = crate::wgsl::Module {
    name: "light_arrays",
    source: "fn light_record(i: u32) -> Light {\n    return lights[i];\n}\n\
             fn light_sample(i: u32) -> LightSample {\n    return samples[i];\n}\n\
             fn shadow_view(i: u32) -> ShadowView {\n    return views[i];\n}\n",
    requires: &[&LIGHT_EVAL],
};

pub fn shader_source() -> String {
    use crate::wgsl::{FULLSCREEN, Module, UNCOUNTED_LOOPS, compose};
    static DIRECT: Module = Module { name: "direct.wgsl", source: include_str!("direct.wgsl"), requires: &[] };
    compose(&[
        &UNCOUNTED_LOOPS,
        &FULLSCREEN,
        &crate::media::MEDIA,
        &crate::media::REGION_ARRAY,
        &crate::wgsl::SURFACE,
        &LIGHT_EVAL,
        &LIGHT_ARRAYS,
        &crate::gbuffer::geometric_normal::GEOMETRIC_NORMAL,
        &crate::gbuffer::layer_texels::LAYER_TEXELS,
        &DIRECT,
    ])
}

/// Light and BRDF samples per area light at a glossy point (`AREA_SAMPLES`
/// in light_eval.wgsl; a test reads it back).
pub const AREA_SAMPLES: u32 = 4;

/// Emissive meshes of at most this many triangles take BRDF samples at a
/// glossy point too (`MESH_MIS_TRIANGLES` in light_eval.wgsl).
pub const MESH_MIS_TRIANGLES: u32 = 64;

/// Loop iterations one pixel of the direct pass runs at most: per light,
/// the quad's 4 corners, then per sample (every light's, the sky's
/// directions and a mesh's points included) the region triangles crossed
/// on the way to the light (light_eval.wgsl's `direct_radiance` and
/// `sampled_radiance`). A glossy point adds `AREA_SAMPLES` for a sphere or
/// quad light (`area_glossy`), for the sky (`sky_glossy`) a search of its
/// directions and the region triangles toward the nearest, per sample, and
/// for an emissive mesh (`mesh_glossy`) per sample a binary search of its
/// triangles and, on small meshes, a test of each, then its points again.
pub fn loop_iterations(lights: &GpuLights, region_triangles: usize) -> u64 {
    use crate::shadow::light_samples::kind;
    let regions = region_triangles as u64;
    let area = AREA_SAMPLES as u64;
    lights
        .lights
        .iter()
        .map(|l| {
            let samples = l.sample_count as u64;
            let glossy = match l.kind {
                kind::SPHERE | kind::QUAD => area,
                kind::ENVIRONMENT => area * (1 + samples + regions),
                kind::MESH => {
                    let triangles = l.triangle_count as u64;
                    let search = 64 - triangles.leading_zeros() as u64;
                    let tests = if l.triangle_count <= MESH_MIS_TRIANGLES { triangles } else { 0 };
                    area * (1 + search + tests) + samples * (1 + regions)
                }
                _ => 0,
            };
            1 + 4 + samples * (1 + regions) + glossy
        })
        .sum()
}

/// Mirrors `DirectParams` in direct.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct DirectParams {
    pub light_count: u32,
    pub shadow_size: u32,
    pub bias: f32,
    /// The progressive pass (from 1): the direct pass's random streams.
    pub pass_index: u32,
}

pub struct DirectPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl DirectPass {
    /// Specialised to what a scene with `features` uses.
    pub fn new(device: &wgpu::Device, target_format: wgpu::TextureFormat, features: SceneFeatures) -> Self {
        let source = shader_source();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("direct.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.as_str().into()),
        });
        use crate::binding::{storage, texture, uniform};
        use wgpu::TextureViewDimension::D2;
        let entry = |b, ty| crate::binding::entry(b, wgpu::ShaderStages::FRAGMENT, ty);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("direct"),
            entries: &[
                entry(0, uniform()),
                entry(1, storage(true)),
                entry(2, storage(true)),
                entry(3, storage(true)),
                entry(4, texture(wgpu::TextureViewDimension::D2Array)),
                entry(5, texture(D2)),
                entry(6, texture(D2)),
                entry(7, texture(D2)),
                entry(8, uniform()),
                entry(9, storage(true)),
                entry(10, storage(true)),
                entry(11, texture(D2)),
                entry(12, crate::binding::texture_uint()),
            ],
        });
        let pipeline_layout = crate::binding::pipeline_layout(device, "direct", &layout);
        let constants = features.constants(&source);
        let pipeline = crate::binding::fullscreen_pipeline_with(
            device,
            "direct",
            &pipeline_layout,
            &module,
            target_format,
            &constants,
        );
        DirectPass { pipeline, layout }
    }

    /// The bind group of frames over `gbuffer` of a scene with `surfaces`
    /// and these lights, shadow maps and media, made once per scene (only
    /// the pass number changes between frames: `record`).
    #[allow(clippy::too_many_arguments)]
    pub fn bind(
        &self,
        device: &wgpu::Device,
        gbuffer: &GBuffer,
        surfaces: &wgpu::Buffer,
        lights: &GpuLights,
        maps: &ShadowMaps,
        bias: f32,
        media: &crate::media::GpuMedia,
    ) -> DirectBinding {
        let params =
            DirectParams { light_count: lights.lights.len() as u32, shadow_size: maps.size, bias, pass_index: 1 };
        let uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("direct params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        // Rewritten when a progressive pass draws new light samples.
        let storage = |label, bytes: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            })
        };
        // A scene always has a light, so neither array is empty.
        let lights_buffer = storage("lights", bytemuck::cast_slice(&lights.lights));
        let samples_buffer = storage("light samples", bytemuck::cast_slice(&lights.samples));
        let maps_view = maps.texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (position, normal, albedo) = (view(&gbuffer.position), view(&gbuffer.normal), view(&gbuffer.albedo));
        let (emission, layers) = (view(&gbuffer.emission), view(&gbuffer.layers));
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("direct"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: lights_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: samples_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: maps.views_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&maps_view) },
                wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&position) },
                wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::TextureView(&normal) },
                wgpu::BindGroupEntry { binding: 7, resource: wgpu::BindingResource::TextureView(&albedo) },
                wgpu::BindGroupEntry { binding: 8, resource: media.params_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 9, resource: media.regions.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 10, resource: surfaces.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 11, resource: wgpu::BindingResource::TextureView(&emission) },
                wgpu::BindGroupEntry { binding: 12, resource: wgpu::BindingResource::TextureView(&layers) },
            ],
        });
        DirectBinding { bind_group, uniforms, params, samples: samples_buffer }
    }

    /// Shades with `lights`' samples from the next frame on: another
    /// pass's samples of the lights the binding was made with (the same
    /// count, `GpuLights::sampled`).
    pub fn set_samples(&self, queue: &wgpu::Queue, binding: &DirectBinding, lights: &GpuLights) {
        queue.write_buffer(&binding.samples, 0, bytemuck::cast_slice(&lights.samples));
    }

    /// Shades every pixel of `target` for progressive pass `pass`.
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        binding: &DirectBinding,
        pass_index: u32,
        target: &wgpu::TextureView,
    ) {
        let params = DirectParams { pass_index, ..binding.params };
        queue.write_buffer(&binding.uniforms, 0, bytemuck::bytes_of(&params));
        let mut pass = crate::binding::color_pass(encoder, "direct light", target, true);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &binding.bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// A `DirectPass`'s state for one scene, kept between frames.
pub struct DirectBinding {
    bind_group: wgpu::BindGroup,
    uniforms: wgpu::Buffer,
    params: DirectParams,
    samples: wgpu::Buffer,
}

#[cfg(test)]
mod tests {
    /// `AREA_SAMPLES` and `MESH_MIS_TRIANGLES` are the WGSL's.
    #[test]
    fn constants_match_the_wgsl() {
        for line in [
            format!("const AREA_SAMPLES: u32 = {}u;", super::AREA_SAMPLES),
            format!("const MESH_MIS_TRIANGLES: u32 = {}u;", super::MESH_MIS_TRIANGLES),
        ] {
            assert!(include_str!("light_eval.wgsl").contains(&line), "light_eval.wgsl lacks `{line}`");
        }
    }
}
