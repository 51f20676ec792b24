//! The scenes built into the binary, so that an installed `radiosity` (`cargo install`) needs no
//! source tree: the default Cornell box, the closed box and the shadow scene of the golden
//! images, and the paper's two rooms of `bench table1`. They load through the same checks as
//! files, under a path that says where they come from (`<built-in>/cornell/cornell.obj`).

use super::obj::{parse_obj, SceneError};
use super::Scene;
use std::path::{Path, PathBuf};

/// A scene's OBJ and MTL texts, as committed in scenes/NAME/NAME.obj and NAME.mtl.
pub struct BundledScene {
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

    pub fn load(&self) -> Result<Scene, SceneError> {
        let path = self.path();
        let mtl = path.with_extension("mtl");
        parse_obj(&path, self.obj, |file| {
            if file == mtl {
                Ok(self.mtl.as_bytes().to_vec())
            } else {
                Err(std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    "not among the built-in files",
                ))
            }
        })
    }
}

/// `path`'s scene, or the built-in Cornell box without one; with the path that names it.
pub fn load_or_default(path: Option<&Path>) -> Result<(Scene, PathBuf), SceneError> {
    match path {
        Some(p) => Ok((super::load_obj(p)?, p.to_path_buf())),
        None => Ok((cornell().load()?, cornell().path())),
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
