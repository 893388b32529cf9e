//! # hikari-core
//!
//! The part of the hikari photon mapper that needs no GPU: the scene model
//! and its TOML and glTF 2.0 loaders, the glTF metallic–roughness BRDF
//! (`bsdf`) and textures, ray casting (BVH), sampling, photon tracing (also
//! through participating media, into a volume map), photon maps, the
//! radiance estimates, level of detail, and the CPU renderers `photon-cpu`
//! (the seed's fixed-radius pipeline) and `path` (ground truth).
//!
//! ```
//! use hikari_core::{photon, progress::Silent, render::photon_cpu, scene::Scene};
//!
//! let mut scene = Scene::load("cornell-box").unwrap();
//! scene.camera = scene.camera.with_resolution(16, 16).unwrap();
//! let traced = photon::trace_photons(&scene, &photon::TraceSettings { photons: 5_000, ..Default::default() }, &Silent);
//! let renderer = photon_cpu::PhotonCpuRenderer::new(&scene, &traced, &Default::default());
//! let (image, _) = renderer.render(&Silent);
//! assert!(image.mean() > 0.0);
//! ```
//!
//! ## Names used throughout
//!
//! * `dir`: a ray's or photon's propagation direction (unit).
//! * `wi`: unit direction from a point toward incoming light.
//! * `pdf`: a density with respect to solid angle unless stated otherwise.
//! * `beta`: path throughput; `power`/`flux`: watts per RGB channel.
//! * Normals "facing" a direction have been flipped to that side.

pub mod bsdf;
pub mod camera;
pub mod envmap;
pub mod estimate;
pub mod fuzz;
pub mod geometry;
pub mod light;
pub mod lod;
pub mod material;
pub mod medium;
pub mod output;
pub mod photon;
pub mod progress;
pub mod progressive;
pub mod render;
pub mod sampling;
pub mod scene;
#[doc(hidden)]
pub mod test_scenes;
pub mod texture;
