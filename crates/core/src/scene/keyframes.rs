//! Keyframed node motion, as glTF animations give it: translation,
//! rotation and scale channels sampled with step or linear interpolation
//! (spherical for rotations), on a chain of nodes from a root down to the
//! node that carries a mesh or a light. The animation loops over its
//! length.

use glam::{Affine3A, Quat, Vec3};

/// Key times (seconds, increasing) and a value at each.
#[derive(Clone, Debug, PartialEq)]
pub struct Track<T> {
    pub times: Vec<f32>,
    pub values: Vec<T>,
    /// STEP: each value holds until the next key; else linear.
    pub step: bool,
}

impl<T: Copy> Track<T> {
    /// The value at `t`: the first before the first key, the last after
    /// the last, between keys by `mix` (or held, for step tracks).
    fn at(&self, t: f32, mix: impl Fn(T, T, f32) -> T) -> T {
        let i = self.times.partition_point(|&k| k <= t);
        if i == 0 {
            return self.values[0];
        }
        if i >= self.times.len() {
            return self.values[self.times.len() - 1];
        }
        let (t0, t1) = (self.times[i - 1], self.times[i]);
        if self.step || t1 <= t0 {
            return self.values[i - 1];
        }
        mix(self.values[i - 1], self.values[i], (t - t0) / (t1 - t0))
    }

    fn end(&self) -> f32 {
        self.times.last().copied().unwrap_or(0.0)
    }
}

/// One node of the chain: its rest transform and the channels that replace
/// parts of it.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeTrack {
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
    pub translation_track: Option<Track<Vec3>>,
    pub rotation_track: Option<Track<Quat>>,
    pub scale_track: Option<Track<Vec3>>,
}

impl NodeTrack {
    /// The node's local transform at `t`.
    fn local(&self, t: f32) -> Affine3A {
        let translation = self.translation_track.as_ref().map_or(self.translation, |k| k.at(t, Vec3::lerp));
        let rotation = self.rotation_track.as_ref().map_or(self.rotation, |k| k.at(t, Quat::slerp)).normalize();
        let scale = self.scale_track.as_ref().map_or(self.scale, |k| k.at(t, Vec3::lerp));
        Affine3A::from_scale_rotation_translation(scale, rotation, translation)
    }

    fn end(&self) -> f32 {
        let ends = [
            self.translation_track.as_ref().map(Track::end),
            self.rotation_track.as_ref().map(Track::end),
            self.scale_track.as_ref().map(Track::end),
        ];
        ends.into_iter().flatten().fold(0.0, f32::max)
    }
}

/// The motion of everything under one node: where its world transform has
/// gone at time t, relative to where it was when the scene was loaded.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframes {
    /// What sits above the chain's root (the file's placement in a scene).
    pub above: Affine3A,
    /// Root first.
    pub chain: Vec<NodeTrack>,
    /// The loaded world transform, inverted: the loaded triangles are
    /// already in world space.
    pub rest_inverse: Affine3A,
    /// The loop's length, seconds (the last key of any channel).
    pub period: f32,
}

impl Keyframes {
    /// `chain` with its length taken from its channels; None if nothing in
    /// it moves or its loaded transform cannot be inverted.
    pub fn new(above: Affine3A, chain: Vec<NodeTrack>, rest: Affine3A) -> Option<Keyframes> {
        let period = chain.iter().map(NodeTrack::end).fold(0.0, f32::max);
        let invertible = rest.matrix3.determinant().abs() > 1e-20;
        (period > 0.0 && invertible).then(|| Keyframes { above, chain, rest_inverse: rest.inverse(), period })
    }

    /// The transform taking the loaded world position to the one at `time`
    /// seconds (looping).
    pub fn at(&self, time: f32) -> Affine3A {
        let t = time.rem_euclid(self.period);
        let world = self.chain.iter().fold(self.above, |m, node| m * node.local(t));
        world * self.rest_inverse
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn still(translation: Vec3) -> NodeTrack {
        NodeTrack {
            translation,
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
            translation_track: None,
            rotation_track: None,
            scale_track: None,
        }
    }

    #[test]
    fn linear_and_step_tracks_interpolate_and_hold() {
        let track = Track { times: vec![1.0, 3.0], values: vec![Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0)], step: false };
        assert_eq!(track.at(0.0, Vec3::lerp), Vec3::ZERO);
        assert_eq!(track.at(2.0, Vec3::lerp), Vec3::new(2.0, 0.0, 0.0));
        assert_eq!(track.at(5.0, Vec3::lerp), Vec3::new(4.0, 0.0, 0.0));
        let step = Track { step: true, ..track };
        assert_eq!(step.at(2.9, Vec3::lerp), Vec3::ZERO);
        assert_eq!(step.at(3.0, Vec3::lerp), Vec3::new(4.0, 0.0, 0.0));
    }

    /// A child 2 units along x from a parent that turns a quarter about +y
    /// between t = 0 and 1: at t = 1 the child has gone from (2, 0, 0) to
    /// (0, 0, −2), and at t = 0 (and after a whole loop) nothing has moved.
    #[test]
    fn a_turning_parent_carries_its_child() {
        let mut parent = still(Vec3::ZERO);
        parent.rotation_track = Some(Track {
            times: vec![0.0, 1.0],
            values: vec![Quat::IDENTITY, Quat::from_rotation_y(std::f32::consts::FRAC_PI_2)],
            step: false,
        });
        let child = still(Vec3::new(2.0, 0.0, 0.0));
        let rest = Affine3A::from_translation(Vec3::new(2.0, 0.0, 0.0));
        let k = Keyframes::new(Affine3A::IDENTITY, vec![parent, child], rest).unwrap();
        assert_eq!(k.period, 1.0);
        let p = Vec3::new(2.0, 0.0, 0.0);
        assert!((k.at(0.0).transform_point3(p) - p).length() < 1e-6);
        let half = k.at(0.5).transform_point3(p);
        let s = std::f32::consts::FRAC_1_SQRT_2 * 2.0;
        assert!((half - Vec3::new(s, 0.0, -s)).length() < 1e-5, "{half}");
        // t = 1 wraps to the loop's start.
        assert!((k.at(0.999_9).transform_point3(p) - Vec3::new(0.0, 0.0, -2.0)).length() < 1e-3);
        assert!((k.at(1.0).transform_point3(p) - p).length() < 1e-5);
        assert!(Keyframes::new(Affine3A::IDENTITY, vec![still(Vec3::ONE)], rest).is_none(), "nothing moves");
    }
}
