//! Why a scene does not load. Every message names the file, and the line or the object where
//! there is one. The limits the messages cite live here too, so that the loader's modules
//! (`mtl`, `load`, `emission`) import this one and it imports none of them.

/// Smallest and largest scene (bounding-box diagonal, scene units) solved accurately.
pub const MIN_SCENE_SIZE: f32 = 1e-5;
/// See `MIN_SCENE_SIZE`: the largest.
pub const MAX_SCENE_SIZE: f32 = 1e6;

/// Largest emitted radiance accepted: beyond it power sums (radiance × area × π, summed over
/// a scene) approach the f32 range and the picture turns to NaN.
pub const MAX_KE: f32 = 1e15;

/// Why a scene does not load, with the file and the line or object.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file cannot be read.
    #[error("cannot read scene file {path}")]
    Read {
        /// The scene file, as messages show it.
        path: String,
        /// The reading's error.
        source: std::io::Error,
    },
    /// A line of the OBJ or MTL file that cannot be read.
    #[error("{path}{line}: {what}")]
    Parse {
        /// The file, as messages show it.
        path: String,
        /// ":LINE", or empty when no line is to blame.
        line: String,
        /// What is wrong.
        what: String,
    },
    /// No material emits.
    #[error(
        "{path}: the scene has no emitter: no material has a positive Ke. Its materials, \
         largest area first: {materials}. Make one emit light with `--emit NAME=R,G,B` \
         (emitted radiance, as `Ke R G B` in the MTL file), or light a scene open to the sky \
         with `--sky R,G,B`"
    )]
    NoEmitter {
        /// The scene file, as messages show it.
        path: String,
        /// Each material with its face count and total area, largest area first.
        materials: String,
    },
    /// A material library that cannot be used.
    #[error("{path}: cannot use the material library {mtl}: {reason}")]
    Material {
        /// The scene file, as messages show it.
        path: String,
        /// The library as the `mtllib` line names it.
        mtl: String,
        /// Why it cannot be used.
        reason: String,
    },
    /// A scene too small or too large for f32 geometry.
    #[error(
        "{path}: the scene is {size:e} units across (bounding-box diagonal); scenes from \
         {MIN_SCENE_SIZE:e} to {MAX_SCENE_SIZE:e} units are solved accurately (f32 positions, \
         areas and form factors). Scale the scene into that range"
    )]
    Scale {
        /// The scene file, as messages show it.
        path: String,
        /// Its bounding-box diagonal, scene units.
        size: f32,
    },
    /// Emitting materials with no face of non-zero area.
    #[error(
        "{path}: the emitting material(s) {materials} have no face with a non-zero area, so \
         nothing emits: no face uses them, or theirs have zero area ({skipped} zero-area face(s) \
         skipped in the scene)"
    )]
    EmitterZeroArea {
        /// The scene file, as messages show it.
        path: String,
        /// The emitting materials.
        materials: String,
        /// Zero-area faces skipped in the whole scene.
        skipped: usize,
    },
    /// No polygon of non-zero area.
    #[error("{path}: the scene has no polygons with a non-zero area")]
    Empty {
        /// The scene file, as messages show it.
        path: String,
    },
    /// An emission override names a material the scene does not have.
    #[error("{path}: {source}")]
    Emit {
        /// The scene file, as messages show it.
        path: String,
        /// What the override asked for.
        source: EmissionError,
    },
}

/// An emission override the scene cannot take.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum EmissionError {
    /// No material of that name.
    #[error(
        "cannot make the material '{name}' emit: the scene has no material of that name. Its \
         materials: {materials}"
    )]
    UnknownMaterial {
        /// The name asked for.
        name: String,
        /// The scene's materials (the first few, the rest counted).
        materials: String,
    },
    /// A radiance outside [0, `MAX_KE`] or not finite.
    #[error(
        "cannot make the material '{name}' emit {ke:?}: emitted radiance needs three numbers in \
         [0, {MAX_KE:e}]"
    )]
    Radiance {
        /// The material.
        name: String,
        /// The radiance asked for.
        ke: [f32; 3],
    },
}
