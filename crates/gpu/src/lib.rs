//! # hikari-gpu
//!
//! The seed's method on the GPU with wgpu (METHOD.md §4): the scene is
//! rasterized once into a G-buffer, then every photon is drawn as one
//! instanced quad covering the screen footprint of its radius-r sphere, and
//! the fragment shader adds that photon's contribution at the pixel's surface
//! point. The estimate is the one of `hikari_core::estimate`, mirrored in
//! `wgsl/estimate.wgsl`; the twin tests hold the two to the same numbers.
//! `tiled` computes the same sums in compute shaders over screen tiles, and
//! `trace` traces the photons themselves in a compute shader, the CPU
//! tracer's twin.
//!
//! Each pass is a small struct with its pipeline, its shader beside it;
//! WGSL shared between passes is in `wgsl`, composed once per shader.
//!
//! The glTF metallic–roughness BRDF is `wgsl/bsdf.wgsl`, pinned to
//! `hikari_core::bsdf` by a test: glossy surfaces weight photons by it in
//! both estimators, take direct light through it, sample it in the photon
//! tracer and follow their smoother lobes in the specular pass.
//!
//! Every pipeline is specialised to what its scene uses (`features`:
//! textures, cut-outs, glossy surfaces, skies and emissive meshes, sky
//! images, media), through pipeline-overridable constants the shaders test
//! before their per-surface fields: a software rasterizer runs both sides
//! of every branch, so a Lambertian box would otherwise pay for every
//! material a glTF file can hold. The splat's quads bound their photon's
//! sphere exactly on screen and lie at its front depth, so the G-buffer's
//! depth test skips pixels whose surface lies nearer before they shade; its
//! vertex shader trims each quad to the 16-pixel tiles whose depth range
//! (`splat::depth_tiles`) meets the sphere's.
//!
//! Textures (`textures`) are one storage buffer of 8-bit texels with their
//! mip chains, sampled by `textures.wgsl` with the CPU's filter: in the
//! G-buffer (mip-mapped by the pixel's footprint), the shadow maps and
//! the ray-traced passes (level 0), cut-outs (alphaMode MASK) and
//! stochastic transparency (BLEND) included.

pub mod accumulate;
pub mod binding;
pub mod block;
pub mod capabilities;
pub mod context;
pub mod direct;
pub mod features;
pub mod gbuffer;
pub mod lod;
pub mod media;
pub mod memory;
pub mod photons;
pub mod points;
pub mod readback;
pub mod renderer;
pub mod resolve;
pub mod scene_upload;
pub mod shadow;
pub mod specular;
pub mod splat;
pub mod tables;
pub mod textures;
pub mod trace;
pub mod volume;
pub mod wgsl;

pub use context::{GpuContext, GpuError};
pub use renderer::{GpuRenderer, GpuSettings};

pub mod photon_grid;
pub mod present;
#[doc(hidden)]
pub mod test_support;
pub mod tiled;
