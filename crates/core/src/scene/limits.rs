//! The valid range of every number in a scene file, written down once
//! (docs/scene-format.md, "Limits", lists the same values).
//!
//! The ranges are chosen so that every quantity derived from a scene stays
//! finite in 32-bit floats: with every point within ±`MAX_COORD` the scene's
//! bounding box, its diagonal (≤ 3.5e6), squared lengths (≤ 1.2e13), areas and
//! light powers (≤ 1e6 · 4π² · 3e12 ≈ 1.2e20) are all far below f32::MAX ≈ 3.4e38,
//! and with lengths ≥ `MIN_LENGTH` no default photon radius squares to zero.

/// Largest magnitude of any coordinate, in scene units: positions, corners,
/// centres, edges, translations, OBJ vertices, and every vertex after a
/// mesh's scale, rotation and translation. Also the largest magnitude of any
/// other number in the file unless its own range is tighter.
pub const MAX_COORD: f32 = 1e6;

/// Smallest radius, box side or mesh scale factor (scene units / factor).
pub const MIN_LENGTH: f32 = 1e-6;

/// Smallest |edge_u × edge_v| of a quad (object or light).
pub const MIN_QUAD_AREA: f32 = 1e-12;

/// Largest component of a light's `intensity` (W/sr), `radiance`
/// (W/(m² sr); also the environment's) or `irradiance` (W/m²). The largest
/// power, an environment's L·4π·πr² over a scene of radius r ≤ 1.75e6, is
/// about 1.2e20 W.
pub const MAX_EMISSION: f32 = 1e6;

/// Smallest total power (mean over channels) of a light, in watts: below it a
/// light is taken to emit nothing (its photons would carry denormal flux).
pub const MIN_LIGHT_POWER: f32 = 1e-20;

/// Range of a glass `ior` (ratio).
pub const IOR: (f32, f32) = (0.01, 100.0);

/// Range of the camera's full vertical field of view, degrees.
pub const FOV_Y: (f32, f32) = (0.01, 179.0);

/// Range of a spot light's `cutoff_angle`, degrees.
pub const CUTOFF_ANGLE: (f32, f32) = (0.01, 90.0);

/// Largest component of a medium's `sigma_a` or `sigma_s` (1 / scene unit);
/// a non-zero component must be at least `MIN_SIGMA`.
pub const MAX_SIGMA: f32 = 1e6;
pub const MIN_SIGMA: f32 = 1e-6;

/// Largest image side in pixels (the CLI's `--resolution` allows the same).
pub const MAX_SIDE: u32 = 16384;

/// Largest image, in pixels (8192 × 8192): a float RGB image of this size
/// takes 768 MiB, and the renderers keep a few per-pixel buffers.
pub const MAX_PIXELS: u64 = 1 << 26;

/// Range of an animation's `period`, seconds.
pub const PERIOD: (f32, f32) = (1e-3, 1e6);
