//! What the GPU renderer needs from an adapter, written down once, and the
//! choice of adapter.
//!
//! Every format, downlevel flag and limit the passes rely on is listed here
//! and checked before a device is opened, so an adapter that cannot run the
//! renderer is refused with one line naming what it lacks (the CLI then
//! renders with `photon-cpu`) instead of failing inside a pipeline. The
//! optional features (32-bit float blending, timestamps) are chosen here too.

use wgpu::{DownlevelFlags, TextureFormat, TextureFormatFeatureFlags as F, TextureUsages as U};

/// Formats and what each must support.
pub const FORMATS: [(TextureFormat, U, &str); 2] = [
    // The G-buffer, the specular and resolve outputs: written as render
    // targets or storage textures, read by textureLoad. (Rendering to it is
    // optional: see `Capabilities::gbuffer_storage`.)
    (TextureFormat::Rgba32Float, U::TEXTURE_BINDING.union(U::STORAGE_BINDING), "G-buffer and compute outputs"),
    // Depth tests, and shadow distances written as depth and loaded later.
    (TextureFormat::Depth32Float, U::RENDER_ATTACHMENT.union(U::TEXTURE_BINDING), "depth and shadow maps"),
];

/// Downlevel flags and why each is needed.
pub const DOWNLEVEL: [(DownlevelFlags, &str); 4] = [
    (DownlevelFlags::COMPUTE_SHADERS, "compute shaders (LOD cull, specular ray tracing)"),
    (DownlevelFlags::INDIRECT_EXECUTION, "indirect draws (LOD-culled photon splats)"),
    (DownlevelFlags::VERTEX_STORAGE, "storage buffers in vertex shaders (region meshes)"),
    (DownlevelFlags::FRAGMENT_STORAGE, "storage buffers in fragment shaders (lights)"),
];

/// Storage buffers per stage that the tiled estimator's gather binds.
pub const TILED_STORAGE_BUFFERS: u32 = 10;

/// Why `ctx` cannot run a pass that binds `needed` storage buffers per
/// shader stage (`what`), if it cannot.
pub fn storage_buffer_shortfall(limits: &wgpu::Limits, needed: u32, what: &str) -> Option<String> {
    let offered = limits.max_storage_buffers_per_shader_stage;
    (offered < needed)
        .then(|| format!("{what} binds {needed} storage buffers per shader stage, and this adapter offers {offered}"))
}

/// The limits a frame needs whatever the scene; scene-dependent sizes are
/// checked by `GpuBudget::check` in `memory.rs`.
pub fn required_limits() -> wgpu::Limits {
    wgpu::Limits {
        // Four Rgba32Float G-buffer targets.
        max_color_attachments: 4,
        max_color_attachment_bytes_per_sample: 64,
        // WebGPU's default, which every browser offers (Chrome at most
        // 10): the GPU tracer and the mirror/glass pass bind 8, their
        // small tables packed into one buffer (`tables`); the tiled
        // estimator binds more and gives way to the raster splat where the
        // adapter has fewer (`TILED_STORAGE_BUFFERS`).
        max_storage_buffers_per_shader_stage: 8,
        max_storage_textures_per_shader_stage: 1,
        // The specular pass's bindings 0–19 and the tiled estimator's 0–18.
        max_bindings_per_bind_group: 20,
        max_compute_invocations_per_workgroup: 256,
        max_compute_workgroup_size_x: 256,
        max_compute_workgroup_storage_size: 1024,
        ..wgpu::Limits::downlevel_defaults()
    }
}

/// Shader loop iterations one invocation may run.
///
/// llvmpipe (lavapipe, and Mesa's GL on the CPU) ends every loop after one
/// pass once a shader has run 65,535 loop iterations, with no error. It
/// runs invocations in SIMD batches (8 lanes at 256 bits) and counts the
/// batch's iterations, which add up to at most the sum of its lanes' own
/// counts: so each lane gets the cap divided by the lanes (measured: at 1 M
/// photons a glass pixel whose lanes ran at most 52,312 iterations each
/// already lost its light). On hardware the budget keeps each invocation
/// short, well inside OS watchdogs.
pub fn loop_budget(info: &wgpu::AdapterInfo) -> u32 {
    if info.device_type == wgpu::DeviceType::Cpu {
        SOFTWARE_LOOP_CAP / software_lanes(&info.name)
    } else {
        HARDWARE_LOOP_BUDGET
    }
}

/// llvmpipe's per-batch loop cap (65,535), with room for loops we do not count.
pub const SOFTWARE_LOOP_CAP: u32 = 64_000;
pub const HARDWARE_LOOP_BUDGET: u32 = 1 << 20;

/// SIMD lanes of a software adapter: llvmpipe names its vector width
/// ("llvmpipe (LLVM 15.0.6, 256 bits)"), 32-bit lanes; 16 when unknown.
pub fn software_lanes(name: &str) -> u32 {
    name.find(" bits")
        .and_then(|end| {
            let before = &name[..end];
            let start = before.rfind(|c: char| !c.is_ascii_digit()).map_or(0, |i| i + 1);
            before[start..].parse::<u32>().ok()
        })
        .map(|bits| (bits / 32).clamp(1, 64))
        .unwrap_or(16)
}

/// What a usable adapter offers beyond the requirements.
#[derive(Clone, Debug)]
pub struct Capabilities {
    /// Rgba32Float can be blended: the splats accumulate in it.
    pub float32_blend: bool,
    /// Rgba16Float is renderable and blendable (the fallback accumulation).
    pub float16_blend: bool,
    /// GPU timestamps can be written between passes.
    pub timestamps: bool,
    /// Rgba32Float is not renderable (Mesa's OpenGL), so the G-buffer is
    /// stored from the fragment shader after a depth pre-pass.
    pub gbuffer_storage: bool,
    /// R32Float is renderable: shadow maps use it (else R16Float).
    pub r32_renderable: bool,
    /// The G-buffer can keep a fifth target, the layer textures' texels
    /// (`gbuffer::LAYERS_FORMAT`; `layer_texels`).
    pub layer_texels: bool,
}

/// Whether an adapter of `limits` can keep the layer textures' texels in a
/// fifth G-buffer target of `format_usages` (Rgba32Uint's): as a render
/// target, 80 bytes of colour attachments a sample (Vulkan, DX12, GL and
/// lavapipe offer 128; Apple's Metal GPUs 64, where the layers are drawn
/// as their means); on the storage path, a fifth storage texture.
pub fn layer_texels(limits: &wgpu::Limits, format_usages: U, gbuffer_storage: bool) -> bool {
    if gbuffer_storage {
        limits.max_storage_textures_per_shader_stage >= 5 && format_usages.contains(U::STORAGE_BINDING)
    } else {
        limits.max_color_attachments >= 5
            && limits.max_color_attachment_bytes_per_sample >= 80
            && format_usages.contains(U::RENDER_ATTACHMENT)
    }
}

/// What the storage G-buffer needs beyond the common requirements.
const STORAGE_GBUFFER_FEATURES: wgpu::Features =
    wgpu::Features::CLEAR_TEXTURE.union(wgpu::Features::SHADER_EARLY_DEPTH_TEST);

impl Capabilities {
    /// The adapter's fit, or every missing requirement in one line.
    pub fn check(adapter: &wgpu::Adapter) -> Result<Capabilities, String> {
        let mut missing = Vec::new();
        let downlevel = adapter.get_downlevel_capabilities();
        for (flag, why) in DOWNLEVEL {
            if !downlevel.flags.contains(flag) {
                missing.push(why.to_string());
            }
        }
        for (format, usages, why) in FORMATS {
            let features = adapter.get_texture_format_features(format);
            if !features.allowed_usages.contains(usages) {
                missing.push(format!("{format:?} with {:?} ({why})", usages.difference(features.allowed_usages)));
            }
        }
        missing.extend(limit_shortfalls(&adapter.limits(), &required_limits()));
        let renders_float32 = adapter
            .get_texture_format_features(TextureFormat::Rgba32Float)
            .allowed_usages
            .contains(U::RENDER_ATTACHMENT);
        let gbuffer_storage = !renders_float32;
        let renderable =
            |format| adapter.get_texture_format_features(format).allowed_usages.contains(U::RENDER_ATTACHMENT);
        let r32_renderable = renderable(TextureFormat::R32Float);
        if !r32_renderable && !renderable(TextureFormat::R16Float) {
            missing.push("a renderable R32Float or R16Float (shadow maps)".into());
        }
        if gbuffer_storage {
            let why = "Rgba32Float render targets, or instead";
            if !adapter.features().contains(STORAGE_GBUFFER_FEATURES) {
                missing.push(format!("{why} {:?}", STORAGE_GBUFFER_FEATURES.difference(adapter.features())));
            }
            if !downlevel.flags.contains(DownlevelFlags::FRAGMENT_WRITABLE_STORAGE) {
                missing.push(format!("{why} storage writes in fragment shaders"));
            }
            if adapter.limits().max_storage_textures_per_shader_stage < 4 {
                missing.push(format!("{why} 4 storage textures per stage"));
            }
        }
        let blendable = |format| {
            let f = adapter.get_texture_format_features(format);
            f.allowed_usages.contains(U::RENDER_ATTACHMENT) && f.flags.contains(F::BLENDABLE)
        };
        let float32_blend =
            adapter.features().contains(wgpu::Features::FLOAT32_BLENDABLE) && blendable(TextureFormat::Rgba32Float);
        let float16_blend = blendable(TextureFormat::Rgba16Float);
        if !float32_blend && !float16_blend {
            missing.push("a blendable float render format (Rgba32Float or Rgba16Float) for photon splats".into());
        }
        if !missing.is_empty() {
            return Err(format!("lacks {}", missing.join("; ")));
        }
        let timestamps = adapter.features().contains(timestamp_features());
        let layer_usages = adapter.get_texture_format_features(TextureFormat::Rgba32Uint).allowed_usages;
        let layer_texels = layer_texels(&adapter.limits(), layer_usages, gbuffer_storage);
        Ok(Capabilities { float32_blend, float16_blend, timestamps, gbuffer_storage, r32_renderable, layer_texels })
    }

    /// The features to request for a device.
    pub fn features(&self) -> wgpu::Features {
        let mut features = wgpu::Features::empty();
        if self.float32_blend {
            features |= wgpu::Features::FLOAT32_BLENDABLE;
        }
        if self.timestamps {
            features |= timestamp_features();
        }
        if self.gbuffer_storage {
            features |= STORAGE_GBUFFER_FEATURES;
        }
        features
    }

    /// Format of the additive radiance targets.
    pub fn radiance_format(&self) -> TextureFormat {
        if self.float32_blend { TextureFormat::Rgba32Float } else { TextureFormat::Rgba16Float }
    }
}

fn timestamp_features() -> wgpu::Features {
    wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
}

/// The limits of `needed` that `offered` does not reach, as `name offered < needed`.
pub fn limit_shortfalls(offered: &wgpu::Limits, needed: &wgpu::Limits) -> Vec<String> {
    let mut short = Vec::new();
    needed.check_limits_with_fail_fn(offered, false, |name, needed, offered| {
        short.push(format!("limit {name} {offered} < {needed}"));
    });
    short
}

/// Adapters in the order they are tried: hardware GPUs before software ones
/// and native APIs (Vulkan, Metal, DX12) before OpenGL.
pub fn preference(info: &wgpu::AdapterInfo) -> (u8, u8) {
    let kind = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    };
    let api = match info.backend {
        wgpu::Backend::Vulkan | wgpu::Backend::Metal | wgpu::Backend::Dx12 => 0,
        _ => 1,
    };
    (kind, api)
}

/// The environment variable that picks the adapter (docs/cluster.md): a
/// number is an index in the order of [`preference`] (0: the first), other
/// text a part of the adapter's name or its PCI bus id (lspci's or
/// nvidia-smi's form, "17:00.0" or "00000000:17:00.0"), case ignored.
pub const ADAPTER_VARIABLE: &str = "HIKARI_GPU";

/// Whether `info`, at `index` in the order of preference, is the adapter
/// `wanted` (the value of [`ADAPTER_VARIABLE`]) names.
pub fn is_wanted(wanted: &str, index: usize, info: &wgpu::AdapterInfo) -> bool {
    let wanted = wanted.trim().to_ascii_lowercase();
    if let Ok(i) = wanted.parse::<usize>() {
        return i == index;
    }
    // A bus id's domain is written with 4 or 8 digits: compare bus:device.function.
    let bus = |id: &str| {
        let mut parts = id.rsplitn(3, ':');
        let (function, bus) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
        format!("{bus}:{function}")
    };
    let bus_id = info.device_pci_bus_id.to_ascii_lowercase();
    !wanted.is_empty()
        && (info.name.to_ascii_lowercase().contains(&wanted)
            || (!bus_id.is_empty() && wanted.contains(':') && bus(&bus_id) == bus(&wanted)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_variable_names_an_adapter_by_index_name_or_bus() {
        let gpu = wgpu::AdapterInfo {
            name: "NVIDIA H100 80GB HBM3".into(),
            device_pci_bus_id: "0000:17:00.0".into(),
            ..wgpu::AdapterInfo::new(wgpu::DeviceType::DiscreteGpu, wgpu::Backend::Vulkan)
        };
        for wanted in ["1", "h100", "NVIDIA", "17:00.0", "00000000:17:00.0", "0000:17:00.0"] {
            assert!(is_wanted(wanted, 1, &gpu), "{wanted}");
        }
        for wanted in ["0", "llvmpipe", "18:00.0", "00000000:18:00.0", "", " "] {
            assert!(!is_wanted(wanted, 1, &gpu), "{wanted}");
        }
        let no_bus = wgpu::AdapterInfo { device_pci_bus_id: String::new(), ..gpu };
        assert!(!is_wanted("17:00.0", 1, &no_bus));
    }

    fn info(device_type: wgpu::DeviceType, backend: wgpu::Backend) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            name: String::new(),
            vendor: 0,
            device: 0,
            device_type,
            driver: String::new(),
            driver_info: String::new(),
            backend,
            ..wgpu::AdapterInfo::new(device_type, backend)
        }
    }

    #[test]
    fn hardware_and_native_apis_come_first() {
        use wgpu::{Backend, DeviceType};
        let mut adapters = [
            info(DeviceType::Cpu, Backend::Gl),
            info(DeviceType::Cpu, Backend::Vulkan),
            info(DeviceType::IntegratedGpu, Backend::Gl),
            info(DeviceType::DiscreteGpu, Backend::Vulkan),
            info(DeviceType::IntegratedGpu, Backend::Vulkan),
        ];
        adapters.sort_by_key(preference);
        let order: Vec<_> = adapters.iter().map(|a| (a.device_type, a.backend)).collect();
        assert_eq!(
            order,
            [
                (DeviceType::DiscreteGpu, Backend::Vulkan),
                (DeviceType::IntegratedGpu, Backend::Vulkan),
                (DeviceType::IntegratedGpu, Backend::Gl),
                (DeviceType::Cpu, Backend::Vulkan),
                (DeviceType::Cpu, Backend::Gl),
            ]
        );
    }

    /// Apple's 64 bytes a sample hold the four G-buffer targets, not the
    /// fifth; the storage path needs a fifth storage texture.
    #[test]
    fn the_layer_texels_need_a_fifth_target() {
        let both = U::RENDER_ATTACHMENT | U::STORAGE_BINDING;
        let roomy = wgpu::Limits {
            max_color_attachments: 8,
            max_color_attachment_bytes_per_sample: 128,
            max_storage_textures_per_shader_stage: 8,
            ..wgpu::Limits::default()
        };
        assert!(layer_texels(&roomy, both, false) && layer_texels(&roomy, both, true));
        let apple = wgpu::Limits { max_color_attachment_bytes_per_sample: 64, ..roomy.clone() };
        assert!(!layer_texels(&apple, both, false) && layer_texels(&apple, both, true));
        let four = wgpu::Limits { max_storage_textures_per_shader_stage: 4, ..roomy.clone() };
        assert!(layer_texels(&four, both, false) && !layer_texels(&four, both, true));
        assert!(!layer_texels(&roomy, U::STORAGE_BINDING, false) && !layer_texels(&roomy, U::RENDER_ATTACHMENT, true));
    }

    #[test]
    fn shortfalls_name_the_limit() {
        let offered = wgpu::Limits { max_storage_buffers_per_shader_stage: 4, ..wgpu::Limits::default() };
        let short = limit_shortfalls(&offered, &required_limits());
        assert!(short.iter().any(|s| s.contains("max_storage_buffers_per_shader_stage 4 < 8")), "{short:?}");
        assert!(limit_shortfalls(&required_limits(), &required_limits()).is_empty());
    }

    #[test]
    fn software_adapters_share_the_llvmpipe_loop_cap_among_their_lanes() {
        const { assert!(SOFTWARE_LOOP_CAP < 65_535) };
        assert_eq!(software_lanes("llvmpipe (LLVM 15.0.6, 256 bits)"), 8);
        assert_eq!(software_lanes("llvmpipe (LLVM 17.0.2, 512 bits)"), 16);
        assert_eq!(software_lanes("SwiftShader Device"), 16);
        let cpu = wgpu::AdapterInfo {
            name: "llvmpipe (LLVM 15.0.6, 256 bits)".into(),
            ..info(wgpu::DeviceType::Cpu, wgpu::Backend::Vulkan)
        };
        assert_eq!(loop_budget(&cpu), 8_000);
        assert_eq!(loop_budget(&info(wgpu::DeviceType::DiscreteGpu, wgpu::Backend::Vulkan)), HARDWARE_LOOP_BUDGET);
    }
}
