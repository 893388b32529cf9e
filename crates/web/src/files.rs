//! Scenes from files dropped onto the page (or picked in its file dialog):
//! a binary glTF (`.glb`), a `.gltf` whose buffers and images are embedded
//! (data URIs), or a TOML scene made of hikari's own shapes. Errors read
//! as the CLI's do: the file, the place, the problem.

use hikari_core::progress::Silent;
use hikari_core::scene::{LoadOptions, Scene, gltf};

/// One file as the browser handed it over.
pub struct DroppedFile {
    pub name: String,
    pub bytes: Vec<u8>,
}

/// The scene the dropped files make. Several files are one scene: the
/// first `.glb`, `.gltf` or `.toml` among them is the scene file.
pub fn scene_from_files(files: &[DroppedFile]) -> Result<Scene, String> {
    let extension = |f: &DroppedFile| f.name.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase());
    let Some(main) = files.iter().find(|f| matches!(extension(f).as_deref(), Some("glb" | "gltf" | "toml"))) else {
        let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
        return Err(format!("{}: not a scene (drop a .glb, a .gltf or a .toml scene file)", names.join(", ")));
    };
    match extension(main).as_deref() {
        Some("toml") => {
            let text = std::str::from_utf8(&main.bytes).map_err(|e| format!("{}: not UTF-8 text: {e}", main.name))?;
            // Meshes are named by path, which a page cannot read: only
            // hikari's own shapes load (said by the loader's own error).
            Scene::from_toml(text, &main.name, None).map_err(|e| e.to_string())
        }
        Some(kind) => {
            if kind == "glb" && !main.bytes.starts_with(b"glTF") {
                return Err(format!(
                    "{}: not a binary glTF file: it does not start with the `glTF` magic bytes",
                    main.name
                ));
            }
            gltf::scene_from_bytes(&main.bytes, &main.name, None, &LoadOptions::default(), &Silent)
                .map_err(|e| e.to_string())
        }
        None => unreachable!("the scene file has an extension"),
    }
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
        let scene = scene_from_files(&[file("notes.txt", b"hi".to_vec()), file("box.glb", glb)]).unwrap();
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
    fn a_toml_scene_with_an_error_points_at_it() {
        let error = error_of(&[file("mine.toml", b"[camera]\nfov = \"wide\"\n".to_vec())]);
        assert!(error.starts_with("mine.toml:"), "{error}");
    }
}
