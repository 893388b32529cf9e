// A stored photon as the tracer hands it to the compaction (trace::PhotonRecord).

struct PhotonRecord {
    path: u32,
    // Map (bits 0–1), diffuse bounces (8–15), sequence in the path (16–31).
    tag: u32,
    position_x: f32,
    position_y: f32,
    position_z: f32,
    power_rgb9e5: u32,
    direction_and_class: u32,
    _pad: u32,
}
