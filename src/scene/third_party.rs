//! Where scenes made by other people are found. They are never committed to this repository
//! (each has its own licence; `scenes/third_party/README.md` says where each is published): a
//! user or CI puts them in one folder, named by `RADIOSITY_SCENES`, or else the folder
//! `shared/scenes/third_party` beside the checkout (the layout of this project's workplace).

use std::path::{Path, PathBuf};

/// The environment variable that names the folder of third-party scenes.
pub const SCENES_VAR: &str = "RADIOSITY_SCENES";

/// The folder of third-party scenes: `$RADIOSITY_SCENES` if set (whether or not it exists, so that
/// a wrong setting is reported rather than silently replaced), else `shared/scenes/third_party` in
/// the folder that holds the working directory's checkout or the one this program was built from,
/// if it exists.
pub fn dir() -> Option<PathBuf> {
    if let Some(set) = std::env::var_os(SCENES_VAR).filter(|v| !v.is_empty()) {
        return Some(PathBuf::from(set));
    }
    // The workplace keeps them in a folder `shared` next to the checkout.
    let beside = |root: &Path| {
        root.join("..")
            .join("shared")
            .join("scenes")
            .join("third_party")
    };
    [
        beside(Path::new(".")),
        beside(Path::new(env!("CARGO_MANIFEST_DIR"))),
    ]
    .into_iter()
    .find(|d| d.is_dir())
}

/// Where each scene is published, by its folder, for the message about a missing one.
const PUBLISHED: [(&str, &str); 7] = [
    (
        "cornell-box",
        "the McGuire Computer Graphics Archive, CornellBox.zip (CC BY 3.0)",
    ),
    (
        "cornell-box-family",
        "the McGuire Computer Graphics Archive, CornellBox.zip (CC BY 3.0)",
    ),
    (
        "tinyobjloader-cornell-box",
        "tinyobjloader/tinyobjloader on GitHub, models/cornell_box.obj (MIT)",
    ),
    (
        "lost-empire",
        "the McGuire Computer Graphics Archive, lost_empire.zip (CC BY 3.0)",
    ),
    (
        "living-room",
        "the Global-Illuminati decimation of McGuire's living room on GitHub (CC BY 3.0, MIT)",
    ),
    (
        "conference-room",
        "the McGuire Computer Graphics Archive, conference.zip (public domain)",
    ),
    (
        "zdm2",
        "Calinou/game-maps-obj (the OBJ) and godotengine/godot-demo-projects (the glTF) on GitHub (CC BY 4.0)",
    ),
];

/// Where the scene at `relative` (below the folder) is published, if this project knows it.
pub fn published(relative: &str) -> Option<&'static str> {
    let folder = relative.split(['/', '\\']).next()?;
    PUBLISHED
        .iter()
        .find(|(f, _)| *f == folder)
        .map(|(_, where_)| *where_)
}

/// The path of the third-party scene file `relative` (e.g. `lost-empire/lost_empire.obj`), or
/// one clear message naming the file, where it was looked for and where it is published.
pub fn find(relative: &str) -> Result<PathBuf, String> {
    let source = published(relative)
        .map(|p| format!(" It is published in {p}; see scenes/third_party/README.md."))
        .unwrap_or_else(|| " See scenes/third_party/README.md.".into());
    let Some(dir) = dir() else {
        return Err(format!(
            "third-party scene {relative} not found: set {SCENES_VAR} to the folder that holds \
             the third-party scenes (there is no shared/scenes/third_party beside the checkout).\
             {source}"
        ));
    };
    let path = dir.join(relative);
    if path.is_file() {
        Ok(path)
    } else {
        Err(format!(
            "third-party scene {relative} not found in {} ({}).{source}",
            dir.display(),
            if std::env::var_os(SCENES_VAR).is_some() {
                format!("from {SCENES_VAR}")
            } else {
                "beside the checkout".into()
            }
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_scene_is_named_with_where_it_is_published() {
        let err = find("lost-empire/no-such-file.obj").unwrap_err();
        assert!(err.contains("lost-empire/no-such-file.obj"), "{err}");
        assert!(err.contains("lost_empire.zip"), "{err}");
        assert_eq!(published("zdm2/zdm2.glb"), Some(PUBLISHED[6].1));
        assert_eq!(published("nowhere/x.obj"), None);
    }
}
