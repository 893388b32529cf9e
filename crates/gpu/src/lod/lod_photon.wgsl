// A photon that survived the LOD cull (photons::LodPhoton): the stored
// photon and its power scale; the splat's instance and the tiled
// estimator's input.

struct LodPhoton {
    position_x: f32,
    position_y: f32,
    position_z: f32,
    power_rgb9e5: u32,
    direction_and_class: u32,
    scale: f32,
}
