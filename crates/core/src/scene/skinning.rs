//! Meshes bent by skins whose joints move (glTF 2.0, 3.7.3): each vertex
//! placed by the weighted sum of its joints' matrices, the joint's world
//! transform at that moment times its inverse bind matrix. The loader poses
//! a skinned mesh once in the file's node transforms; a `SkinnedMesh` keeps
//! what it needs to pose it again at any time of the file's animations
//! (`Motion::Skinned`, applied by `Scene::posed`).

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

/// A skinned mesh as it can be posed at any time.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinnedMesh {
    /// In the mesh's own space, morph targets applied.
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    /// The triangles the scene holds, in its order (vertex indices).
    pub triangles: Vec<[u32; 3]>,
    pub influences: Influences,
    pub joints: Vec<Joint>,
    /// Where vertices without weights go: the mesh's node as loaded.
    pub fallback: Mat4,
}

impl SkinnedMesh {
    /// Do the file's animations move any of its joints?
    pub fn moves(&self) -> bool {
        self.joints.iter().any(|j| j.motion.is_some())
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
        let (positions, normals) = skin_vertices(
            &self.positions,
            self.normals.as_deref(),
            &self.influences,
            &self.matrices(time),
            self.fallback,
        );
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
        let mesh = SkinnedMesh {
            positions: vec![Vec3::X, Vec3::X, Vec3::new(0.0, 0.0, 1.0)],
            normals: Some(vec![Vec3::X, Vec3::X, Vec3::Z]),
            triangles: vec![[0, 1, 2]],
            influences: Influences { starts: vec![0, 1, 3, 3], entries: vec![(0, 1.0), (0, 0.5), (1, 0.5)] },
            joints: vec![joint(Some(keys)), joint(None)],
            fallback: Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0)),
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
