//! Meshes that change shape as a glTF file's animations play (glTF 2.0,
//! 3.7.2.2 and 3.7.3): morph targets whose weights are keyed (each adds its
//! weighted position and normal deltas), then skins whose joints move (each
//! vertex placed by the weighted sum of its joints' matrices, the joint's
//! world transform at that moment times its inverse bind matrix). The loader
//! poses a mesh once in the file's node transforms and weights; a
//! `DeformedMesh` keeps what it needs to pose it again at any time
//! (`Motion::Deformed`, applied by `Scene::posed`).

use super::keyframes::Keyframes;
use crate::geometry::{Triangle, TriangleNormals};
use glam::{Affine3A, Mat3, Mat4, Vec3};

/// Each vertex's joints and weights (weights normalised to sum 1); a vertex
/// without any is placed by the mesh's node instead.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Influences {
    /// Vertex v's entries are `entries[starts[v]..starts[v + 1]]`.
    pub starts: Vec<u32>,
    /// (joint index into the skin's joints, weight).
    pub entries: Vec<(u32, f32)>,
}

impl Influences {
    fn of(&self, v: usize) -> &[(u32, f32)] {
        &self.entries[self.starts[v] as usize..self.starts[v + 1] as usize]
    }
}

/// Vertices (and normals) placed by `matrices`, one per joint; vertices
/// without influences by `fallback`. Normals by each vertex's blended
/// matrix's inverse transpose, renormalised.
pub fn skin_vertices(
    positions: &[Vec3],
    normals: Option<&[Vec3]>,
    influences: &Influences,
    matrices: &[Mat4],
    fallback: Mat4,
) -> (Vec<Vec3>, Option<Vec<Vec3>>) {
    let mut placed = Vec::with_capacity(positions.len());
    let mut placed_normals = normals.map(|_| Vec::with_capacity(positions.len()));
    for (v, &p) in positions.iter().enumerate() {
        let entries = influences.of(v);
        let m = if entries.is_empty() {
            fallback
        } else {
            entries.iter().fold(Mat4::ZERO, |sum, &(joint, weight)| sum + matrices[joint as usize] * weight)
        };
        placed.push(m.transform_point3(p));
        if let (Some(out), Some(n)) = (placed_normals.as_mut(), normals) {
            out.push((Mat3::from_mat4(m).inverse().transpose() * n[v]).normalize_or_zero());
        }
    }
    (placed, placed_normals)
}

/// One joint of a skin.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    pub inverse_bind: Mat4,
    /// The joint node's world transform as loaded.
    pub rest_world: Mat4,
    /// How its world transform moves with the file's animations (None:
    /// nothing above or at it moves).
    pub motion: Option<Keyframes>,
}

/// Keyed morph-target weights (a glTF `weights` channel), looping over
/// the last key's time as node animations do.
#[derive(Clone, Debug, PartialEq)]
pub struct MorphWeights {
    pub times: Vec<f32>,
    /// One weight per target at each key.
    pub values: Vec<Vec<f32>>,
    /// STEP: each key's weights hold until the next; else linear.
    pub step: bool,
}

impl MorphWeights {
    /// The weights at `time`.
    pub fn at(&self, time: f32) -> Vec<f32> {
        let period = self.times.last().copied().unwrap_or(0.0);
        let t = if period > 0.0 { time.rem_euclid(period) } else { 0.0 };
        let i = self.times.partition_point(|&k| k <= t);
        if i == 0 {
            return self.values[0].clone();
        }
        if i >= self.times.len() {
            return self.values[self.times.len() - 1].clone();
        }
        let (t0, t1) = (self.times[i - 1], self.times[i]);
        if self.step || t1 <= t0 {
            return self.values[i - 1].clone();
        }
        let f = (t - t0) / (t1 - t0);
        self.values[i - 1].iter().zip(&self.values[i]).map(|(a, b)| a + (b - a) * f).collect()
    }
}

/// One morph target: its position deltas, and its normal deltas where it
/// has them.
pub type MorphTarget = (Vec<Vec3>, Option<Vec<Vec3>>);

/// Morph targets whose weights are keyed.
#[derive(Clone, Debug, PartialEq)]
pub struct Morph {
    pub targets: Vec<MorphTarget>,
    pub weights: MorphWeights,
}

/// `positions` and `normals` with `targets` added by `weights` (missing
/// weights are zero).
pub fn morph_vertices(
    positions: &[Vec3],
    normals: Option<&[Vec3]>,
    targets: &[MorphTarget],
    weights: &[f32],
) -> (Vec<Vec3>, Option<Vec<Vec3>>) {
    let mut positions = positions.to_vec();
    let mut normals = normals.map(<[Vec3]>::to_vec);
    for ((deltas, normal_deltas), &w) in targets.iter().zip(weights) {
        if w == 0.0 {
            continue;
        }
        positions.iter_mut().zip(deltas).for_each(|(p, d)| *p += w * *d);
        if let (Some(normals), Some(d)) = (normals.as_mut(), normal_deltas) {
            normals.iter_mut().zip(d).for_each(|(n, d)| *n += w * *d);
        }
    }
    (positions, normals)
}

/// A mesh as it can be posed at any time: morphed by keyed weights (if
/// `morph`), then skinned by its joints (if it has influences), else placed
/// by `fallback`.
#[derive(Clone, Debug, PartialEq)]
pub struct DeformedMesh {
    /// In the mesh's own space: morphed by the file's static weights where
    /// `morph` is None, unmorphed where it is Some.
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    /// The triangles the scene holds, in its order (vertex indices).
    pub triangles: Vec<[u32; 3]>,
    pub influences: Influences,
    pub joints: Vec<Joint>,
    /// Where vertices without weights go: the mesh's node as loaded.
    pub fallback: Mat4,
    pub morph: Option<Morph>,
}

impl DeformedMesh {
    /// Do the file's animations change its shape (keyed weights, or
    /// joints that move)?
    pub fn moves(&self) -> bool {
        self.morph.is_some() || self.joints.iter().any(|j| j.motion.is_some())
    }

    /// The joints' skinning matrices at `time`.
    fn matrices(&self, time: f32) -> Vec<Mat4> {
        self.joints
            .iter()
            .map(|j| {
                let world = match &j.motion {
                    Some(keys) => Mat4::from(keys.at(time)) * j.rest_world,
                    None => j.rest_world,
                };
                world * j.inverse_bind
            })
            .collect()
    }

    /// The mesh's triangles at `time`, moved by `then` (the surface's rigid
    /// edits and motions), in the order the scene holds them.
    pub fn triangles_at(&self, time: f32, then: &Affine3A) -> Vec<Triangle> {
        let morphed = self
            .morph
            .as_ref()
            .map(|m| morph_vertices(&self.positions, self.normals.as_deref(), &m.targets, &m.weights.at(time)));
        let (positions, normals) = match &morphed {
            Some((p, n)) => (p.as_slice(), n.as_deref()),
            None => (self.positions.as_slice(), self.normals.as_deref()),
        };
        let (positions, normals) =
            skin_vertices(positions, normals, &self.influences, &self.matrices(time), self.fallback);
        let linear = Mat3::from(then.matrix3);
        self.triangles
            .iter()
            .map(|&t| Triangle {
                v: t.map(|i| then.transform_point3(positions[i as usize])),
                normals: normals
                    .as_ref()
                    .map(|n| TriangleNormals(t.map(|i| (linear * n[i as usize]).normalize_or_zero()))),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::keyframes::{NodeTrack, Track};
    use glam::Quat;

    /// One joint at the origin turning a quarter about +z between t = 0
    /// and 1, bound where it stands (inverse bind = identity); a vertex at
    /// (1, 0, 0) fully on it, one half on it and half on a still joint, one
    /// without weights. At t = 1 the first has gone to (0, 1, 0), the
    /// second to the mean of (0, 1, 0) and (1, 0, 0), the third stays.
    #[test]
    fn joints_that_turn_carry_their_vertices() {
        let turn = NodeTrack {
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
            translation_track: None,
            rotation_track: Some(Track {
                times: vec![0.0, 1.0, 2.0],
                values: vec![Quat::IDENTITY, Quat::from_rotation_z(std::f32::consts::FRAC_PI_2), Quat::IDENTITY],
                step: false,
            }),
            scale_track: None,
        };
        let keys = Keyframes::new(Affine3A::IDENTITY, vec![turn], Affine3A::IDENTITY).unwrap();
        let joint = |motion| Joint { inverse_bind: Mat4::IDENTITY, rest_world: Mat4::IDENTITY, motion };
        let mesh = DeformedMesh {
            positions: vec![Vec3::X, Vec3::X, Vec3::new(0.0, 0.0, 1.0)],
            normals: Some(vec![Vec3::X, Vec3::X, Vec3::Z]),
            triangles: vec![[0, 1, 2]],
            influences: Influences { starts: vec![0, 1, 3, 3], entries: vec![(0, 1.0), (0, 0.5), (1, 0.5)] },
            joints: vec![joint(Some(keys)), joint(None)],
            fallback: Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0)),
            morph: None,
        };
        assert!(mesh.moves());
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-5;
        let at = |t: f32| mesh.triangles_at(t, &Affine3A::IDENTITY)[0];
        let [a, b, c] = at(1.0).v;
        assert!(close(a, Vec3::Y), "{a}");
        assert!(close(b, Vec3::new(0.5, 0.5, 0.0)), "{b}");
        assert!(close(c, Vec3::new(0.0, 0.0, 6.0)), "{c}");
        assert!(close(at(1.0).normals.unwrap().0[0], Vec3::Y));
        // At t = 0 (and after the 2 s loop) nothing has turned.
        assert!(close(at(0.0).v[0], Vec3::X) && close(at(2.0).v[0], Vec3::X));
        // A rigid edit moves the bent mesh.
        let moved = mesh.triangles_at(1.0, &Affine3A::from_translation(Vec3::Z));
        assert!(close(moved[0].v[0], Vec3::new(0.0, 1.0, 1.0)));
    }
}

#[cfg(test)]
mod morph_tests {
    use super::*;

    /// Two targets keyed (0, 0) → (1, 0.5) over 2 s, linear, on a mesh
    /// without a skin placed 3 up: at t = 1 a vertex has moved by ½ of the
    /// first delta and ¼ of the second; a step track holds the first key.
    #[test]
    fn keyed_weights_morph_the_mesh() {
        let weights = MorphWeights { times: vec![0.0, 2.0], values: vec![vec![0.0, 0.0], vec![1.0, 0.5]], step: false };
        assert_eq!(weights.at(1.0), vec![0.5, 0.25]);
        let mesh = DeformedMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: None,
            triangles: vec![[0, 1, 2]],
            influences: Influences { starts: vec![0; 4], entries: Vec::new() },
            joints: Vec::new(),
            fallback: Mat4::from_translation(Vec3::Y * 3.0),
            morph: Some(Morph {
                targets: vec![(vec![Vec3::Z; 3], None), (vec![Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::ZERO], None)],
                weights: weights.clone(),
            }),
        };
        assert!(mesh.moves());
        let v = mesh.triangles_at(1.0, &Affine3A::IDENTITY)[0].v;
        assert!((v[0] - Vec3::new(0.0, 3.0, 1.5)).length() < 1e-6, "{}", v[0]);
        assert!((v[1] - Vec3::new(1.0, 3.0, 0.5)).length() < 1e-6, "{}", v[1]);
        let step = MorphWeights { step: true, ..weights };
        assert_eq!(step.at(1.9), vec![0.0, 0.0]);
    }
}
