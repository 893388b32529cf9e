//! The decoders against files the users' encoders wrote (testdata/README.md):
//! each compressed file must give the uncompressed file's triangles, normals
//! and texture coordinates, to within the encoder's quantization.

use crate::progress::Silent;
use crate::scene::files::SceneFiles;
use crate::scene::gltf::{Asset, asset_from_bytes};
use glam::{Affine3A, Vec2, Vec3};

fn load(name: &str, bytes: &[u8]) -> Result<Asset, String> {
    asset_from_bytes(bytes, name, SceneFiles::beside(None), Affine3A::IDENTITY, None, &Silent)
        .map_err(|e| e.to_string())
}

/// Every triangle's corners: (position, normal, where it reads its base
/// colour texture: gltfpack scales quantized coordinates back by a texture
/// transform).
fn corners(asset: &Asset) -> Vec<[(Vec3, Vec3, Vec2); 3]> {
    let mut out = Vec::new();
    for p in &asset.primitives {
        let textures = asset.material_textures[p.material as usize].as_ref();
        let texture = textures.and_then(|t| t.base_color).expect("the materials are textured");
        for (i, t) in p.triangles.iter().enumerate() {
            let normals = t.normals.as_ref().expect("the files have normals").0;
            let uvs = p.uvs.as_ref().expect("the materials are textured")[i];
            out.push(std::array::from_fn(|k| (t.v[k], normals[k], texture.transform.transform_point2(uvs[k]))));
        }
    }
    out
}

/// The largest differences (position, normal, texture coordinate) between
/// each of `file`'s triangles and the nearest of `reference`'s.
fn largest_differences(file: &[[(Vec3, Vec3, Vec2); 3]], reference: &[[(Vec3, Vec3, Vec2); 3]]) -> [f32; 3] {
    let centroid = |t: &[(Vec3, Vec3, Vec2); 3]| (t[0].0 + t[1].0 + t[2].0) / 3.0;
    let mut worst = [0.0f32; 3];
    for t in file {
        let c = centroid(t);
        let nearest =
            reference.iter().min_by(|a, b| (centroid(a) - c).length().total_cmp(&(centroid(b) - c).length())).unwrap();
        for corner in t {
            let r =
                nearest.iter().min_by(|a, b| (a.0 - corner.0).length().total_cmp(&(b.0 - corner.0).length())).unwrap();
            worst[0] = worst[0].max((r.0 - corner.0).length());
            worst[1] = worst[1].max((r.1 - corner.1).length());
            worst[2] = worst[2].max((r.2 - corner.2).length());
        }
    }
    worst
}

#[test]
fn compressed_files_give_the_uncompressed_geometry() {
    let plain = load("plain.glb", include_bytes!("testdata/plain.glb")).unwrap();
    let reference = corners(&plain);
    assert!(reference.len() > 500, "{} triangles", reference.len());
    let files: [(&str, &[u8], [f32; 3]); 5] = [
        // gltfpack: 14-bit positions over the 4 m plane, 8-bit octahedral
        // normals, 12-bit UVs (their steps, with room for rounding).
        ("quant.glb", include_bytes!("testdata/quant.glb"), [1e-3, 0.02, 1e-3]),
        ("meshopt.glb", include_bytes!("testdata/meshopt.glb"), [1e-3, 0.02, 1e-3]),
        ("meshopt_cc.glb", include_bytes!("testdata/meshopt_cc.glb"), [1e-3, 0.02, 1e-3]),
        // gltf-transform's Draco defaults: 14-bit positions, 10-bit normals,
        // 12-bit UVs.
        ("draco.glb", include_bytes!("testdata/draco.glb"), [1e-3, 0.02, 1e-3]),
        ("draco_seq.glb", include_bytes!("testdata/draco_seq.glb"), [1e-3, 0.02, 1e-3]),
    ];
    for (name, bytes, tolerance) in files {
        let asset = load(name, bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        let compressed = corners(&asset);
        assert_eq!(compressed.len(), reference.len(), "{name}: triangle count");
        let worst = largest_differences(&compressed, &reference);
        for (k, what) in ["position", "normal", "texture coordinate"].iter().enumerate() {
            assert!(
                worst[k] <= tolerance[k],
                "{name}: {what}s differ by up to {} (allowed {})",
                worst[k],
                tolerance[k]
            );
        }
        // And the other way round: no reference triangle is missing.
        let back = largest_differences(&reference, &compressed);
        assert!(back[0] <= tolerance[0], "{name}: a reference triangle is {} from any decoded one", back[0]);
        assert!(asset.notes.iter().all(|n| !n.contains("ignored")), "{name}: {:?}", asset.notes);
    }
}

/// `bytes` (a .glb) with its JSON changed by `edit`.
fn edited(bytes: &[u8], edit: impl FnOnce(&mut gltf::json::Value)) -> Vec<u8> {
    let glb = gltf::binary::Glb::from_slice(bytes).unwrap();
    let mut json: gltf::json::Value = gltf::json::deserialize::from_slice(&glb.json).unwrap();
    edit(&mut json);
    let root: gltf::json::Root = gltf::json::deserialize::from_value(json).unwrap();
    crate::scene::gltf::export::glb(&root, glb.bin.unwrap().into_owned())
}

#[test]
fn broken_compressed_data_is_a_located_error() {
    let meshopt = include_bytes!("testdata/meshopt.glb");
    fn ext(json: &mut gltf::json::Value) -> &mut gltf::json::Value {
        // View 0 is the texture; 1 the first compressed attribute stream.
        &mut json["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]
    }
    let cases: [(&str, Vec<u8>, &[&str]); 4] = [
        (
            "unknown filter",
            edited(meshopt, |j| ext(j)["filter"] = "SQUARE".into()),
            &["bufferViews[1].extensions.EXT_meshopt_compression", "unknown filter \"SQUARE\""],
        ),
        (
            "truncated stream",
            edited(meshopt, |j| {
                let length = ext(j)["byteLength"].as_u64().unwrap();
                ext(j)["byteLength"] = (length / 2).into();
            }),
            &["bufferViews[1].extensions.EXT_meshopt_compression", "cannot be decoded"],
        ),
        (
            "beyond its buffer",
            edited(meshopt, |j| ext(j)["byteOffset"] = 1_000_000.into()),
            &["bufferViews[1].extensions.EXT_meshopt_compression", "buffers[0]"],
        ),
        (
            "truncated Draco stream",
            edited(include_bytes!("testdata/draco.glb"), |j| {
                let view = j["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["bufferView"]
                    .as_u64()
                    .unwrap() as usize;
                j["bufferViews"][view]["byteLength"] = 12.into();
            }),
            &["meshes[0].primitives[0].extensions.KHR_draco_mesh_compression", "cannot decode the Draco stream"],
        ),
    ];
    for (what, bytes, words) in cases {
        let error = load("broken.glb", &bytes).err().unwrap_or_else(|| panic!("{what}: loaded"));
        for w in words {
            assert!(error.contains(w), "{what}: {error:?} does not say {w:?}");
        }
    }
}
