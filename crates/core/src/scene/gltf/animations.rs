//! glTF node animations as keyframed motions (`scene::keyframes`): the
//! translation, rotation and scale channels of all the file's animations,
//! played together (Blender writes one animation per object's action);
//! where two animate the same property of a node (clips of one character),
//! the first wins, with a note. STEP and LINEAR interpolation (CUBICSPLINE
//! through its key values, linearly, with a note), and morph-target
//! weights (`scene::deformation::MorphWeights`).

use super::{accessors, error};
use crate::scene::SceneError;
use crate::scene::deformation::MorphWeights;
use crate::scene::keyframes::{Keyframes, NodeTrack, Track};
use glam::{Affine3A, Quat, Vec3};
use gltf::accessor::DataType;
use gltf::animation::{Interpolation, Property};
use std::collections::HashMap;

/// The channels of the file's animations, by node.
#[derive(Default)]
pub struct NodeChannels {
    tracks: HashMap<usize, Channels>,
    /// Each node's rest translation, rotation and scale.
    rest: Vec<(Vec3, Quat, Vec3)>,
}

#[derive(Default)]
struct Channels {
    translation: Option<Track<Vec3>>,
    rotation: Option<Track<Quat>>,
    scale: Option<Track<Vec3>>,
    weights: Option<MorphWeights>,
}

/// Reads every animation; notes what is ignored or approximated.
pub fn read(
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    file: &str,
    notes: &mut Vec<String>,
) -> Result<NodeChannels, SceneError> {
    let rest = doc
        .nodes()
        .map(|n| {
            let (t, r, s) = n.transform().decomposed();
            (Vec3::from(t), Quat::from_array(r).normalize(), Vec3::from(s))
        })
        .collect();
    let mut out = NodeChannels { tracks: HashMap::new(), rest };
    let (mut cubic, mut conflicts) = (false, 0);
    let channels = doc.animations().flat_map(|a| a.channels().enumerate().map(move |(c, ch)| (a.index(), c, ch)));
    for (animation, c, channel) in channels {
        let at = format!("animations[{animation}].channels[{c}]");
        let sampler = channel.sampler();
        let keys = |a: gltf::Accessor, what: &str| -> Result<Vec<f32>, SceneError> {
            accessors::read::<1>(&a, buffers, &[DataType::F32])
                .map(|v| v.into_iter().map(|[x]| x).collect())
                .map_err(|m| error(file, format!("{at}.sampler ({what}, accessor {})", a.index()), m))
        };
        let times = keys(sampler.input(), "input")?;
        if times.is_empty() || times.iter().any(|t| !t.is_finite()) || times.windows(2).any(|w| w[1] < w[0]) {
            return Err(error(file, format!("{at}.sampler"), "key times must be finite and increasing"));
        }
        let interpolation = sampler.interpolation();
        cubic |= interpolation == Interpolation::CubicSpline;
        // A cubic spline stores (in-tangent, value, out-tangent) per key.
        let stride = if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
        let pick = |n: usize| -> Result<Vec<usize>, SceneError> {
            if n != times.len() * stride {
                return Err(error(
                    file,
                    format!("{at}.sampler"),
                    format!("{n} output values for {} key times ({interpolation:?})", times.len()),
                ));
            }
            Ok((0..times.len()).map(|k| k * stride + stride / 2).collect())
        };
        let step = interpolation == Interpolation::Step;
        let output = sampler.output();
        let read_err = |m: String| error(file, format!("{at}.sampler (output, accessor {})", output.index()), m);
        let finite = |ok: bool| {
            if ok { Ok(()) } else { Err(error(file, format!("{at}.sampler"), "an output value is not finite")) }
        };
        let node = channel.target().node().index();
        let entry = out.tracks.entry(node).or_default();
        let taken = match channel.target().property() {
            Property::Translation => entry.translation.is_some(),
            Property::Rotation => entry.rotation.is_some(),
            Property::Scale => entry.scale.is_some(),
            Property::MorphTargetWeights => entry.weights.is_some(),
        };
        if taken {
            conflicts += 1;
            continue;
        }
        match channel.target().property() {
            Property::Translation | Property::Scale => {
                let values = accessors::read::<3>(&output, buffers, &[DataType::F32]).map_err(read_err)?;
                let values: Vec<Vec3> = pick(values.len())?.into_iter().map(|i| Vec3::from(values[i])).collect();
                finite(values.iter().all(|v| v.is_finite()))?;
                let track = Some(Track { times: times.clone(), values, step });
                if channel.target().property() == Property::Translation {
                    entry.translation = track;
                } else {
                    entry.scale = track;
                }
            }
            Property::Rotation => {
                let allowed = [DataType::F32, DataType::I8, DataType::U8, DataType::I16, DataType::U16];
                let values = accessors::read::<4>(&output, buffers, &allowed).map_err(read_err)?;
                let values: Vec<Quat> =
                    pick(values.len())?.into_iter().map(|i| Quat::from_array(values[i]).normalize()).collect();
                finite(values.iter().all(|q| q.is_finite()))?;
                entry.rotation = Some(Track { times: times.clone(), values, step });
            }
            Property::MorphTargetWeights => {
                let allowed = [DataType::F32, DataType::I8, DataType::U8, DataType::I16, DataType::U16];
                let values = accessors::read::<1>(&output, buffers, &allowed).map_err(read_err)?;
                // One weight per morph target at each key (three for a cubic spline).
                let per_key = times.len() * stride;
                if !values.len().is_multiple_of(per_key) {
                    return Err(error(
                        file,
                        format!("{at}.sampler"),
                        format!("{} weights are not a whole number per key time ({} keys)", values.len(), times.len()),
                    ));
                }
                let targets = values.len() / per_key;
                let keyed: Vec<Vec<f32>> = (0..times.len())
                    .map(|k| {
                        let first = (k * stride + stride / 2) * targets;
                        values[first..first + targets].iter().map(|[w]| *w).collect()
                    })
                    .collect();
                finite(keyed.iter().flatten().all(|w| w.is_finite()))?;
                entry.weights = Some(MorphWeights { times: times.clone(), values: keyed, step });
            }
        }
    }
    if conflicts > 0 {
        notes.push(format!(
            "{conflicts} animation channel(s) animate what an earlier animation already does (clips of one object): the first plays"
        ));
    }
    if cubic {
        notes.push("cubic-spline animation keys are interpolated linearly".into());
    }
    Ok(out)
}

impl NodeChannels {
    /// The keyed morph-target weights of `node`, if an animation keys them.
    pub fn weights(&self, node: usize) -> Option<&MorphWeights> {
        self.tracks.get(&node)?.weights.as_ref()
    }

    /// The motion of whatever sits at the end of `path` (node indices, root
    /// first) placed by `above`: None if nothing on the path moves.
    pub fn keyframes(&self, above: Affine3A, path: &[usize]) -> Option<Keyframes> {
        if !path.iter().any(|n| self.tracks.contains_key(n)) {
            return None;
        }
        let chain: Vec<NodeTrack> = path
            .iter()
            .map(|&n| {
                let (translation, rotation, scale) = self.rest[n];
                let channels = self.tracks.get(&n);
                NodeTrack {
                    translation,
                    rotation,
                    scale,
                    translation_track: channels.and_then(|c| c.translation.clone()),
                    rotation_track: channels.and_then(|c| c.rotation.clone()),
                    scale_track: channels.and_then(|c| c.scale.clone()),
                }
            })
            .collect();
        let rest = path.iter().fold(above, |m, &n| {
            let (t, r, s) = self.rest[n];
            m * Affine3A::from_scale_rotation_translation(s, r, t)
        });
        Keyframes::new(above, chain, rest)
    }
}
