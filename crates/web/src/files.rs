//! Scenes from files dropped onto the page (or picked in its file dialog):
//! a binary glTF (`.glb`); a `.gltf` with the buffers and images it refers
//! to dropped beside it (or embedded as data URIs); or a TOML scene with
//! the OBJ meshes, glTF files and sky image it names. Several files are one
//! scene, found by name (`SceneFiles::Given`). Errors read as the CLI's do:
//! the file, the place, the problem.

use hikari_core::progress::Silent;
pub use hikari_core::scene::files::GivenFile as DroppedFile;
use hikari_core::scene::files::SceneFiles;
use hikari_core::scene::{LoadOptions, Scene, gltf};

/// The scene the dropped files make, and its file's name: the first
/// `.glb`, `.gltf` or `.toml` among them is the scene file, the others
/// what it refers to.
pub fn scene_from_files(files: &[DroppedFile]) -> Result<(String, Scene), String> {
    let extension = |f: &DroppedFile| f.name.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase());
    let Some(main) = files.iter().find(|f| matches!(extension(f).as_deref(), Some("glb" | "gltf" | "toml"))) else {
        let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
        return Err(format!("{}: not a scene (drop a .glb, a .gltf or a .toml scene file)", names.join(", ")));
    };
    let given = SceneFiles::Given(files);
    let scene = match extension(main).as_deref() {
        Some("toml") => {
            let text = std::str::from_utf8(&main.bytes).map_err(|e| format!("{}: not UTF-8 text: {e}", main.name))?;
            Scene::from_toml_with_files(text, &main.name, given).map_err(|e| e.to_string())
        }
        Some(_) => gltf::scene_from_bytes(&main.bytes, &main.name, given, &LoadOptions::default(), &Silent)
            .map_err(|e| e.to_string()),
        None => unreachable!("the scene file has an extension"),
    }?;
    Ok((main.name.clone(), scene))
}

#[cfg(test)]
mod tests {
    use super::*;
    use hikari_core::scene::gltf::export::scene_to_glb;

    fn error_of(files: &[DroppedFile]) -> String {
        match scene_from_files(files) {
            Ok(_) => panic!("the files loaded"),
            Err(e) => e,
        }
    }

    fn file(name: &str, bytes: Vec<u8>) -> DroppedFile {
        DroppedFile { name: name.into(), bytes }
    }

    #[test]
    fn a_dropped_glb_loads() {
        let glb = scene_to_glb(&Scene::load("cornell-box").unwrap()).unwrap();
        let (name, scene) = scene_from_files(&[file("notes.txt", b"hi".to_vec()), file("box.glb", glb)]).unwrap();
        assert_eq!(name, "box.glb");
        assert!(!scene.lights.is_empty());
        assert!(scene.diagonal() > 0.0);
    }

    #[test]
    fn a_broken_glb_names_the_file_and_the_problem() {
        let mut glb = scene_to_glb(&Scene::load("cornell-box").unwrap()).unwrap();
        glb.truncate(glb.len() / 2);
        let error = error_of(&[file("broken.glb", glb)]);
        assert!(error.starts_with("broken.glb"), "{error}");
        let error = error_of(&[file("fake.glb", b"PK\x03\x04".to_vec())]);
        assert!(error.contains("fake.glb: not a binary glTF file"), "{error}");
    }

    #[test]
    fn files_without_a_scene_say_what_to_drop() {
        let error = error_of(&[file("photo.png", vec![1, 2, 3])]);
        assert_eq!(error, "photo.png: not a scene (drop a .glb, a .gltf or a .toml scene file)");
    }

    #[test]
    fn a_gltf_dropped_with_its_files_loads_and_a_missing_one_is_named() {
        let files: Vec<DroppedFile> = hikari_core::test_scenes::gltf_textures::checker_gltf_files()
            .into_iter()
            .map(|(name, bytes)| file(&name, bytes))
            .collect();
        let (name, scene) = scene_from_files(&files).unwrap();
        assert_eq!(name, "checker.gltf");
        assert_eq!(scene.texturing.as_ref().map(|t| t.images.len()), Some(1));
        let error = error_of(&files[..1]);
        assert!(error.starts_with("checker.gltf"), "{error}");
        assert!(error.contains("\"checker.bin\", which is not among the files given"), "{error}");
    }

    #[test]
    fn a_toml_scene_dropped_with_its_mesh_loads() {
        let toml = hikari_core::scene::builtin::source("cornell-box").unwrap().to_string();
        let mesh = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        let toml =
            format!("{toml}\n[[object]]\nmesh = \"my/tri.obj\"\nmaterial = \"white\"\ntranslate = [0.0, 0.2, 0.0]\n");
        let with_mesh = [file("box.toml", toml.clone().into_bytes()), file("tri.obj", mesh.as_bytes().to_vec())];
        let base = Scene::load("cornell-box").unwrap();
        let (_, scene) = scene_from_files(&with_mesh).unwrap();
        assert_eq!(scene.accel.triangles().count(), base.accel.triangles().count() + 1);
        let error = error_of(&with_mesh[..1]);
        assert!(error.starts_with("box.toml:"), "{error}");
        assert!(error.contains("\"my/tri.obj\", which is not among the files given"), "{error}");
    }

    #[test]
    fn a_toml_scene_with_an_error_points_at_it() {
        let error = error_of(&[file("mine.toml", b"[camera]\nfov = \"wide\"\n".to_vec())]);
        assert!(error.starts_with("mine.toml:"), "{error}");
    }
}
