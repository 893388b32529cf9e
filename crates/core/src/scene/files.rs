//! Where a scene file's references to other files are read from: the OBJ
//! meshes, glTF files and sky images a TOML scene names, and the buffers
//! and images a `.gltf` refers to by URI.

use std::path::Path;

/// A file handed over beside the scene file (e.g. dropped onto the web
/// page with it), known by its name alone.
pub struct GivenFile {
    pub name: String,
    pub bytes: Vec<u8>,
}

#[derive(Clone, Copy)]
pub enum SceneFiles<'a> {
    /// Nowhere: a scene given as bytes alone; a reference is an error.
    None,
    /// The folder the scene file is in; references are paths relative to it.
    Folder(&'a Path),
    /// Files given with the scene: a reference names one of them by its
    /// last path component (folders are not kept when files are dropped).
    Given(&'a [GivenFile]),
}

impl<'a> SceneFiles<'a> {
    /// The folder a scene file was read from; none: the working directory.
    pub fn beside(folder: Option<&'a Path>) -> Self {
        SceneFiles::Folder(folder.unwrap_or(Path::new("")))
    }

    /// The bytes of `reference` (a path or, with `uri`, a relative URI
    /// whose %-escapes are decoded), or why not.
    pub fn read(&self, reference: &str, uri: bool) -> Result<Vec<u8>, String> {
        let decoded;
        let reference = if uri {
            decoded = urlencoding::decode(reference).map_err(|e| format!("\"{reference}\" is not a valid URI: {e}"))?;
            decoded.as_ref()
        } else {
            reference
        };
        match self {
            SceneFiles::None => {
                Err(format!("refers to file \"{reference}\", but the scene was not read from a folder"))
            }
            SceneFiles::Folder(folder) => {
                let path = folder.join(reference);
                if !path.is_file() {
                    return Err(format!("cannot read {}: file not found", path.display()));
                }
                std::fs::read(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))
            }
            SceneFiles::Given(files) => {
                let name = reference.rsplit(['/', '\\']).next().unwrap_or(reference);
                files.iter().find(|f| f.name == name).map(|f| f.bytes.clone()).ok_or_else(|| {
                    format!("refers to file \"{reference}\", which is not among the files given (drop it with the scene file)")
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn given_files_are_found_by_name_and_missing_ones_named() {
        let files = [GivenFile { name: "my mesh.obj".into(), bytes: b"v 0 0 0".to_vec() }];
        let given = SceneFiles::Given(&files);
        assert_eq!(given.read("meshes/my mesh.obj", false).unwrap(), b"v 0 0 0");
        assert_eq!(given.read("my%20mesh.obj", true).unwrap(), b"v 0 0 0");
        let error = given.read("other.bin", true).unwrap_err();
        assert!(error.contains("\"other.bin\", which is not among the files given"), "{error}");
        let error = SceneFiles::None.read("a.bin", true).unwrap_err();
        assert!(error.contains("not read from a folder"), "{error}");
    }

    #[test]
    fn folder_files_are_read_beside_the_scene() {
        let dir = std::env::temp_dir().join(format!("hikari-scene-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("a b.bin"), [1, 2, 3]).unwrap();
        let folder = SceneFiles::Folder(&dir);
        assert_eq!(folder.read("a%20b.bin", true).unwrap(), [1, 2, 3]);
        assert!(folder.read("missing.bin", false).unwrap_err().contains("not found"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
