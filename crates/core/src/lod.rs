//! Distance-based level of detail for photons (METHOD.md §6, eq. 6.1–6.4),
//! defined once here and mirrored in the GPU's lod.wgsl.
//!
//! Photons are split into `groups` (A) groups in storage order; a photon at
//! distance d from the eye has detail level Q (eq. 6.1); groups are culled in
//! order as Q grows, and the survivors' power is scaled so that, for photons
//! sharing the same Q, the total power is unchanged.

/// LOD settings: `near` (n) and `far` (f) in scene units, `groups` (A).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodSettings {
    pub near: f32,
    pub far: f32,
    pub groups: u32,
}

/// Hermite smoothstep: 0 below `e0`, 1 above `e1`.
pub fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    if e0 == e1 {
        return if x < e0 { 0.0 } else { 1.0 };
    }
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Q of eq. 6.1: smoothstep(n, f, d) if n ≤ f, else 1 − smoothstep(f, n, d).
pub fn detail_level(distance: f32, settings: &LodSettings) -> f32 {
    let (n, f) = (settings.near, settings.far);
    if n <= f { smoothstep(n, f, distance) } else { 1.0 - smoothstep(f, n, distance) }
}

/// The group C_p of photon `index` among `count`: A equal runs in storage order.
pub fn group_of(index: u32, count: u32, groups: u32) -> u32 {
    ((index as u64 * groups as u64) / count.max(1) as u64) as u32
}

/// Power scale s of eq. 6.4 (in the corrected form of METHOD.md §6) for a
/// photon of group `group` at detail level `q`: 1/(1−Q) while active, a
/// linear fade while Q crosses its group, 0 (culled, not drawn) beyond.
pub fn power_scale(q: f32, group: u32, groups: u32) -> f32 {
    let dq = 1.0 / groups as f32;
    let g = group as f32 / groups as f32;
    if q >= g + dq || q >= 1.0 {
        0.0
    } else if q <= g {
        1.0 / (1.0 - q)
    } else {
        (1.0 - (1.0 - g - dq) / (1.0 - q)) / dq
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For photons sharing the same Q, the scales sum to the photon count,
    /// exactly (up to rounding) for any Q in [0, 1), given whole groups.
    #[test]
    fn summed_scale_equals_photon_count() {
        let (count, groups) = (1200u32, 12u32);
        for i in 0..1000 {
            let q = i as f32 / 1000.0;
            let sum: f64 = (0..count).map(|p| power_scale(q, group_of(p, count, groups), groups) as f64).sum();
            assert!((sum - count as f64).abs() < 1e-3 * count as f64, "Q = {q}: sum {sum}");
        }
    }

    #[test]
    fn scale_is_continuous_in_q() {
        let groups = 8;
        for group in 0..groups {
            let mut last = power_scale(0.0, group, groups);
            for i in 1..10_000 {
                let s = power_scale(i as f32 / 10_000.0, group, groups);
                assert!((s - last).abs() < 0.05, "jump at group {group}, step {i}: {last} -> {s}");
                last = s;
            }
        }
    }

    #[test]
    fn detail_level_follows_eq_6_1() {
        let near_culled = LodSettings { near: 20.0, far: 7.0, groups: 10 };
        assert_eq!(detail_level(5.0, &near_culled), 1.0);
        assert_eq!(detail_level(25.0, &near_culled), 0.0);
        let far_culled = LodSettings { near: 0.0, far: 20.0, groups: 10 };
        assert_eq!(detail_level(0.0, &far_culled), 0.0);
        assert_eq!(detail_level(30.0, &far_culled), 1.0);
        assert!((detail_level(10.0, &far_culled) - 0.5).abs() < 1e-6);
    }
}
