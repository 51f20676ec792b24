//! The scenes built into the binary, so that an installed `radiosity` (`cargo install`) needs no
//! source tree: the default Cornell box, the closed box and the shadow scene of the golden
//! images, and the paper's two rooms of `bench table1`. They load through the same checks as
//! files, under a path that says where they come from (`<built-in>/cornell/cornell.obj`).

use super::files::MaterialFiles;
use super::load::parse_scene;
use super::{LoadOptions, Scene, SceneError};
use std::path::{Path, PathBuf};

/// A scene's OBJ and MTL texts, as committed in scenes/NAME/NAME.obj and NAME.mtl.
pub struct BundledScene {
    /// Its name (`cornell`, `simple`, ...), also its folder's under scenes/.
    pub name: &'static str,
    obj: &'static str,
    mtl: &'static str,
}

macro_rules! bundled {
    ($name:literal) => {
        BundledScene {
            name: $name,
            obj: include_str!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/scenes/",
                $name,
                "/",
                $name,
                ".obj"
            )),
            mtl: include_str!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/scenes/",
                $name,
                "/",
                $name,
                ".mtl"
            )),
        }
    };
}

/// Every bundled scene; the first is the default.
pub static ALL: [BundledScene; 5] = [
    bundled!("cornell"),
    bundled!("box"),
    bundled!("shadow"),
    bundled!("simple"),
    bundled!("complex"),
];

/// The default scene: the Cornell box.
pub fn cornell() -> &'static BundledScene {
    &ALL[0]
}

/// The bundled scene called `name`, if there is one.
pub fn find(name: &str) -> Option<&'static BundledScene> {
    ALL.iter().find(|s| s.name == name)
}

impl BundledScene {
    /// The path that names it in messages and in stats.json: no file is there.
    pub fn path(&self) -> PathBuf {
        Path::new("<built-in>")
            .join(self.name)
            .join(format!("{}.obj", self.name))
    }

    /// Load it as `load_obj` would its files.
    pub fn load(&self) -> Result<Scene, SceneError> {
        self.load_with(&LoadOptions::default())
    }

    /// [`BundledScene::load`] with `options` applied (emission overrides).
    pub fn load_with(&self, options: &LoadOptions) -> Result<Scene, SceneError> {
        parse_scene(&self.path(), self.obj, self, options)
    }
}

/// A bundled scene's one library: its MTL text, under the path its `mtllib` line gives.
impl MaterialFiles for BundledScene {
    fn read(&self, file: &Path) -> std::io::Result<Vec<u8>> {
        if file == self.path().with_extension("mtl") {
            Ok(self.mtl.as_bytes().to_vec())
        } else {
            Err(std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "not among the built-in files",
            ))
        }
    }

    fn beside(&self) -> Vec<PathBuf> {
        vec![self.path().with_extension("mtl")]
    }

    fn built_in(&self) -> bool {
        true
    }
}

/// `path`'s scene, or the built-in Cornell box without one, with `options` applied; with the
/// path that names it.
pub fn load_or_default(
    path: Option<&Path>,
    options: &LoadOptions,
) -> Result<(Scene, PathBuf), SceneError> {
    match path {
        Some(p) => Ok((super::load_file_with(p, options)?, p.to_path_buf())),
        None => Ok((cornell().load_with(options)?, cornell().path())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The copies built in are the committed files, loaded the same way.
    #[test]
    fn bundled_scenes_load_as_their_files_do() {
        for s in &ALL {
            let file = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("scenes")
                .join(s.name)
                .join(format!("{}.obj", s.name));
            let (a, b) = (s.load().unwrap(), super::super::load_obj(&file).unwrap());
            assert_eq!(a.name, b.name);
            assert_eq!(a.vertex_count, b.vertex_count, "{}", s.name);
            assert_eq!(a.patch_size, b.patch_size, "{}", s.name);
            assert_eq!(format!("{:?}", a.camera), format!("{:?}", b.camera));
            assert_eq!(format!("{:?}", a.materials), format!("{:?}", b.materials));
            assert_eq!(format!("{:?}", a.polygons), format!("{:?}", b.polygons));
        }
        assert_eq!(
            cornell().path(),
            Path::new("<built-in>/cornell/cornell.obj")
        );
    }
}
