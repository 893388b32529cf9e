//! Photons: the compact stored record, photon tracing and photon maps.
//!
//! A stored [`Photon`] costs 20 bytes, like Jensen's: position (3 × f32),
//! power as RGB9E5 shared-exponent floats relative to the map's power unit
//! (so the 9-bit mantissas never run out of range whatever the scene's
//! wattage), and the incident direction as a 15+15-bit octahedral code whose
//! top two bits hold the photon's path class.

mod encoding;
pub use encoding::{decode_octahedral, encode_octahedral, octahedral_direction, octahedral_square};
mod map;
mod trace;
mod volume_map;

pub use map::PhotonMap;
pub use trace::{TraceSettings, TraceStats, TracedPhotons, trace_photons};
pub use volume_map::{VolumePhoton, VolumePhotonMap};

use crate::material::Rgb;
use glam::Vec3;

/// Which light paths a stored photon ends: the partition of METHOD.md §2.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum PathClass {
    /// L D: first diffuse hit straight from the light (direct light renders it).
    Direct = 0,
    /// L S+ D: through one or more specular bounces only (the caustic map).
    Caustic = 1,
    /// At least one diffuse bounce (or volume scattering) before this hit
    /// (the global-map estimate).
    Indirect = 2,
}

/// A stored photon: 20 bytes, `#[repr(C)]` so it can be uploaded as is.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Photon {
    pub position: [f32; 3],
    /// Power in units of the map's `power_unit`, RGB9E5-encoded.
    pub power_rgb9e5: u32,
    /// Bits 0–29: octahedral incident direction; bits 30–31: `PathClass`
    /// in the surface maps, the phase slot (`medium::Media::phases`) of the
    /// medium that scattered it in the volume map.
    pub direction_and_class: u32,
}

impl Photon {
    #[inline]
    pub fn new(position: Vec3, power_in_units: Rgb, direction: Vec3, class: PathClass) -> Self {
        Photon {
            position: position.to_array(),
            power_rgb9e5: encoding::encode_rgb9e5(power_in_units),
            direction_and_class: encoding::encode_octahedral_15(direction) | ((class as u32) << 30),
        }
    }

    /// A scattering event in a medium (the volume map), with the phase slot
    /// of the medium that scattered it.
    pub fn volume(position: Vec3, power_in_units: Rgb, direction: Vec3, phase_slot: u8) -> Self {
        debug_assert!((phase_slot as usize) < crate::medium::MAX_PHASES);
        Photon {
            position: position.to_array(),
            power_rgb9e5: encoding::encode_rgb9e5(power_in_units),
            direction_and_class: encoding::encode_octahedral_15(direction) | ((phase_slot as u32 & 3) << 30),
        }
    }

    pub fn position(&self) -> Vec3 {
        Vec3::from_array(self.position)
    }

    /// Power in units of the map's power unit (multiply by it for watts).
    pub fn power_in_units(&self) -> Rgb {
        encoding::decode_rgb9e5(self.power_rgb9e5)
    }

    /// Unit propagation direction of the photon when it arrived.
    pub fn direction(&self) -> Vec3 {
        encoding::decode_octahedral_15(self.direction_and_class & 0x3fff_ffff)
    }

    pub fn class(&self) -> PathClass {
        match self.direction_and_class >> 30 {
            0 => PathClass::Direct,
            1 => PathClass::Caustic,
            // Surface photons never hold 3.
            _ => PathClass::Indirect,
        }
    }

    /// Volume-map photons: which phase function scattered this one.
    pub fn phase_slot(&self) -> usize {
        (self.direction_and_class >> 30) as usize
    }
}

const _: () = assert!(std::mem::size_of::<Photon>() == 20);
