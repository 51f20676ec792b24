//! Why a scene does not load. Every message names the file, and the line or the object where
//! there is one. The limits the messages cite live here too, so that the loader's modules
//! (`mtl`, `load`, `emission`) import this one and it imports none of them.

/// Smallest and largest scene (bounding-box diagonal, scene units) solved accurately.
pub const MIN_SCENE_SIZE: f32 = 1e-5;
pub const MAX_SCENE_SIZE: f32 = 1e6;

/// Largest emitted radiance accepted: beyond it power sums (radiance × area × π, summed over
/// a scene) approach the f32 range and the picture turns to NaN.
pub const MAX_KE: f32 = 1e15;

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("cannot read scene file {path}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}{line}: {what}")]
    Parse {
        path: String,
        line: String,
        what: String,
    },
    #[error(
        "{path}: the scene has no emitter: no material has a positive Ke. Its materials, \
         largest area first: {materials}. Make one emit light with `--emit NAME=R,G,B` \
         (emitted radiance, as `Ke R G B` in the MTL file)"
    )]
    NoEmitter {
        path: String,
        /// Each material with its face count and total area, largest area first.
        materials: String,
    },
    #[error("{path}: cannot use the material library {mtl}: {reason}")]
    Material {
        path: String,
        mtl: String,
        reason: String,
    },
    #[error(
        "{path}: the scene is {size:e} units across (bounding-box diagonal); scenes from \
         {MIN_SCENE_SIZE:e} to {MAX_SCENE_SIZE:e} units are solved accurately (f32 positions, \
         areas and form factors). Scale the scene into that range"
    )]
    Scale { path: String, size: f32 },
    #[error(
        "{path}: the emitting material(s) {materials} have no face with a non-zero area, so \
         nothing emits: no face uses them, or theirs have zero area ({skipped} zero-area face(s) \
         skipped in the scene)"
    )]
    EmitterZeroArea {
        path: String,
        materials: String,
        skipped: usize,
    },
    #[error("{path}: the scene has no polygons with a non-zero area")]
    Empty { path: String },
    /// An emission override names a material the scene does not have.
    #[error("{path}: {source}")]
    Emit { path: String, source: EmissionError },
}

/// An emission override the scene cannot take.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum EmissionError {
    #[error(
        "cannot make the material '{name}' emit: the scene has no material of that name. Its \
         materials: {materials}"
    )]
    UnknownMaterial { name: String, materials: String },
    #[error(
        "cannot make the material '{name}' emit {ke:?}: emitted radiance needs three numbers in \
         [0, {MAX_KE:e}]"
    )]
    Radiance { name: String, ke: [f32; 3] },
}
