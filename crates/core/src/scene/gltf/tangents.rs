//! The tangents a normal texture is read in: the file's `TANGENT`, or where
//! it has none MikkTSpace's, as the glTF specification asks and as Blender
//! bakes and shades its normal maps.

use super::accessors;
use glam::{Vec2, Vec3, Vec4};
use gltf::accessor::DataType;

/// The primitive's `TANGENT` (xyz unit, w ±1), one per vertex; None
/// without one. `quantized`: KHR_mesh_quantization also allows normalized
/// bytes and shorts.
pub fn read(
    primitive: &gltf::Primitive,
    buffers: &[gltf::buffer::Data],
    count: usize,
    quantized: bool,
) -> Result<Option<Vec<Vec4>>, String> {
    let Some(a) = primitive.get(&gltf::Semantic::Tangents) else { return Ok(None) };
    let types: &[DataType] = if quantized { &[DataType::F32, DataType::I8, DataType::I16] } else { &[DataType::F32] };
    let tangents = accessors::read::<4>(&a, buffers, types).map_err(|m| format!("accessor {} {m}", a.index()))?;
    if tangents.len() != count {
        return Err("has a different count than POSITION".into());
    }
    if let Some((i, t)) = tangents.iter().enumerate().find(|(_, t)| !t.iter().all(|x| x.is_finite())) {
        return Err(format!("tangent {i} is not finite: {t:?}"));
    }
    Ok(Some(tangents.into_iter().map(Vec4::from).collect()))
}

/// Each triangle's corners' tangents from per-vertex ones.
pub fn per_corner(tangents: &[Vec4], triangles: &[[u32; 3]]) -> Vec<[Vec4; 3]> {
    triangles.iter().map(|t| t.map(|i| tangents[i as usize])).collect()
}

/// MikkTSpace's tangents of each triangle's corners (w: the side of the
/// image's up, w·(n × t)). Missing normals are the triangles' own (what
/// the renderers shade such a mesh with). The coordinates go in with v
/// turned up (1 − v), as Blender holds them: MikkTSpace's bitangent is
/// then the image's up, glTF's +Y, and the tangents are Blender's.
/// A corner MikkTSpace leaves without a tangent (a triangle with no area
/// in position or coordinates, alone) gets a zero one: its triangle falls
/// back to the frame of its own corners.
pub fn mikktspace(
    positions: &[Vec3],
    normals: Option<&[Vec3]>,
    uvs: &[Vec2],
    triangles: &[[u32; 3]],
) -> Vec<[Vec4; 3]> {
    struct Mesh<'a> {
        positions: &'a [Vec3],
        normals: Option<&'a [Vec3]>,
        uvs: &'a [Vec2],
        triangles: &'a [[u32; 3]],
        out: Vec<[Vec4; 3]>,
    }
    impl Mesh<'_> {
        fn vertex(&self, face: usize, vert: usize) -> usize {
            self.triangles[face][vert] as usize
        }
    }
    impl bevy_mikktspace::Geometry for Mesh<'_> {
        fn num_faces(&self) -> usize {
            self.triangles.len()
        }
        fn num_vertices_of_face(&self, _face: usize) -> usize {
            3
        }
        fn position(&self, face: usize, vert: usize) -> [f32; 3] {
            self.positions[self.vertex(face, vert)].to_array()
        }
        fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
            match self.normals {
                Some(n) => n[self.vertex(face, vert)].to_array(),
                None => {
                    let [a, b, c] = self.triangles[face].map(|i| self.positions[i as usize]);
                    (b - a).cross(c - a).normalize_or_zero().to_array()
                }
            }
        }
        fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
            let uv = self.uvs[self.vertex(face, vert)];
            [uv.x, 1.0 - uv.y]
        }
        fn set_tangent(&mut self, tangent: Option<bevy_mikktspace::TangentSpace>, face: usize, vert: usize) {
            self.out[face][vert] = tangent.map_or(Vec4::ZERO, |t| Vec4::from(t.tangent_encoded()));
        }
    }
    let mut mesh = Mesh { positions, normals, uvs, triangles, out: vec![[Vec4::ZERO; 3]; triangles.len()] };
    // The error type has no variants: generation cannot fail.
    let _ = bevy_mikktspace::generate_tangents(&mut mesh);
    mesh.out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square in the xy plane facing +z, two triangles, with
    /// coordinates `uv` at its corners (0,0), (1,0), (1,1), (0,1).
    fn square(uv: [Vec2; 4]) -> Vec<[Vec4; 3]> {
        let positions = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let normals = [Vec3::Z; 4];
        mikktspace(&positions, Some(&normals), &uv, &[[0, 1, 2], [0, 2, 3]])
    }

    fn assert_all(tangents: &[[Vec4; 3]], expected: Vec4) {
        for t in tangents.iter().flatten() {
            assert!((*t - expected).abs().max_element() < 1e-5, "{t} ≠ {expected}");
        }
    }

    #[test]
    fn the_tangent_follows_u_and_the_up_is_the_images_up() {
        // glTF's v points down the image: a square whose v grows toward −y
        // has its image upright, u along +x and the image's up along +y =
        // +1·(z × x).
        let upright = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
        assert_all(&square(upright), Vec4::new(1.0, 0.0, 0.0, 1.0));
    }

    #[test]
    fn a_mirrored_image_turns_the_side() {
        // The image flipped left to right: u along −x, its up still +y,
        // which is −1·(z × −x).
        let mirrored = [Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0), Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0)];
        assert_all(&square(mirrored), Vec4::new(-1.0, 0.0, 0.0, -1.0));
    }

    #[test]
    fn a_turned_image_turns_the_tangent() {
        // u grows along +y and v along +x: the image's up is −x.
        let turned = [Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0)];
        assert_all(&square(turned), Vec4::new(0.0, 1.0, 0.0, 1.0));
    }

    #[test]
    fn tangents_are_smooth_across_a_smooth_mesh() {
        // A strip bent around y, smooth normals, u along the bend: at the
        // shared edge both triangles' tangents are the same vector (a frame
        // per triangle would jump by the bend's angle).
        let bend = 0.4f32;
        let positions = [
            Vec3::new(-1.0, 0.0, -bend),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, -bend),
            Vec3::new(-1.0, 1.0, -bend),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, -bend),
        ];
        let n = |x: f32| Vec3::new(x * bend, 0.0, 1.0).normalize();
        let normals = [n(-1.0), n(0.0), n(1.0), n(-1.0), n(0.0), n(1.0)];
        let uvs =
            [0.0, 0.5, 1.0].map(|u| Vec2::new(u, 1.0)).into_iter().chain([0.0, 0.5, 1.0].map(|u| Vec2::new(u, 0.0)));
        let uvs: Vec<Vec2> = uvs.collect();
        let triangles = [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
        let t = mikktspace(&positions, Some(&normals), &uvs, &triangles);
        // Vertex 1 is corner 1 of triangle 0 and corner 0 of triangle 2.
        assert!((t[0][1] - t[2][0]).abs().max_element() < 1e-6, "{} vs {}", t[0][1], t[2][0]);
        assert!((t[0][1] - Vec4::new(1.0, 0.0, 0.0, 1.0)).abs().max_element() < 1e-5, "{}", t[0][1]);
        // Where the normal leans, the tangent leans with it (orthogonal).
        assert!(t[0][0].truncate().dot(normals[0]).abs() < 1e-5);
    }

    #[test]
    fn a_lone_degenerate_triangle_gets_no_tangent() {
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let uvs = [Vec2::ZERO; 3];
        let t = mikktspace(&positions, None, &uvs, &[[0, 1, 2]]);
        assert_eq!(t[0], [Vec4::ZERO; 3]);
    }
}
