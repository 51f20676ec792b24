//! What the reconstruction pass hands its programs: the texture units, in one table that both
//! binds the textures and sets `glsl/reconstruct.frag`'s samplers, and the uniforms, the
//! shooters' one array element per shooter.

use super::patch_data::PolygonPlanes;
use crate::gl::Program;
use crate::solver::{FormFactorKind, Shooter, SolveOptions, VisibilityKind, MAX_SHOOTERS_PER_PASS};

/// The texture unit of each texture `glsl/reconstruct.frag` samples (named after its sampler).
pub(crate) struct TextureUnits {
    /// `HemiItemBuffer[k]`: shooter k's item buffer.
    pub item_buffers: [u32; MAX_SHOOTERS_PER_PASS as usize],
    /// `LightmapRadiosity`: the radiosity lightmap as the last copy left it.
    pub lightmap_radiosity: u32,
    /// `LightmapUnshot`: the unshot lightmap as the last copy left it.
    pub lightmap_unshot: u32,
    /// `PolygonPlanes`: each polygon's plane, for the robust test.
    pub polygon_planes: u32,
    /// `PatchPosition`, `PatchNormal`, `PatchReflectance`: the receivers' side of the factor.
    pub patch_position: u32,
    pub patch_normal: u32,
    pub patch_reflectance: u32,
}

/// The pass's texture units: shooter 0's item buffer on unit 0 (the paper's one), the lightmaps,
/// planes and patch data on 1 to 6, the other shooters' item buffers on 7 and up.
pub(crate) const UNITS: TextureUnits = TextureUnits {
    item_buffers: [0, 7, 8, 9, 10, 11, 12, 13],
    lightmap_radiosity: 1,
    lightmap_unshot: 2,
    polygon_planes: 3,
    patch_position: 4,
    patch_normal: 5,
    patch_reflectance: 6,
};

/// The uniforms of one pass, the shooters' as arrays of one element per shooter (the corners:
/// `MAX_CORNERS` each), ready to be given to each program the pass draws with.
pub(crate) struct Uniforms<'a> {
    texels: Vec<i32>,
    remainders: Vec<f32>,
    hemi_res: Vec<i32>,
    views: Vec<f32>,
    positions: Vec<f32>,
    normals: Vec<f32>,
    energies: Vec<f32>,
    ids: Vec<f32>,
    corners: Vec<f32>,
    corner_counts: Vec<i32>,
    areas: Vec<f32>,
    /// `UNITS.item_buffers` of the shooters.
    item_units: Vec<i32>,
    options: &'a SolveOptions,
    planes: &'a PolygonPlanes,
}

/// `f`'s values for each of `shooters`, one after another: a uniform array's contents.
fn per_shooter<T, const N: usize>(shooters: &[Shooter], f: impl Fn(&Shooter) -> [T; N]) -> Vec<T> {
    shooters.iter().flat_map(f).collect()
}

impl<'a> Uniforms<'a> {
    /// The uniforms for `shooters` (every slot of the programs filled) under `options`.
    pub fn new(shooters: &[Shooter], options: &'a SolveOptions, planes: &'a PolygonPlanes) -> Self {
        Uniforms {
            texels: per_shooter(shooters, |s| s.texels.map(|t| t as i32)),
            remainders: per_shooter(shooters, |s| s.remainder.to_array()),
            hemi_res: per_shooter(shooters, |s| [s.hemi_res as i32]),
            views: per_shooter(shooters, |s| s.view().to_cols_array()),
            positions: per_shooter(shooters, |s| s.position.to_array()),
            normals: per_shooter(shooters, |s| s.normal.to_array()),
            energies: per_shooter(shooters, |s| s.energy.to_array()),
            ids: per_shooter(shooters, |s| [s.polygon as f32]),
            corners: (shooters.iter())
                .flat_map(|s| s.corners.iter().flat_map(|v| v.to_array()))
                .collect(),
            corner_counts: per_shooter(shooters, |s| [s.corner_count as i32]),
            areas: per_shooter(shooters, |s| [s.area]),
            item_units: (UNITS.item_buffers[..shooters.len()].iter())
                .map(|&u| u as i32)
                .collect(),
            options,
            planes,
        }
    }

    /// Use `p` and give it the uniforms: samplers, shooters, choices, planes.
    pub fn set(&self, p: &Program) {
        let unit = |u: u32| u as i32;
        p.use_program();
        p.set_i32("PatchPosition", unit(UNITS.patch_position));
        p.set_i32("PatchNormal", unit(UNITS.patch_normal));
        p.set_i32("PatchReflectance", unit(UNITS.patch_reflectance));
        p.set_i32("LightmapRadiosity", unit(UNITS.lightmap_radiosity));
        p.set_i32("LightmapUnshot", unit(UNITS.lightmap_unshot));
        p.set_i32("PolygonPlanes", unit(UNITS.polygon_planes));
        p.set_i32_array("HemiItemBuffer", &self.item_units);
        p.set_ivec4_array("ShooterTexels", &self.texels);
        p.set_vec3_array("ShooterRemainder", &self.remainders);
        p.set_i32_array("HemiRes", &self.hemi_res);
        p.set_mat4_array("ShooterView", &self.views);
        p.set_vec3_array("ShootPos", &self.positions);
        p.set_vec3_array("ShootNormal", &self.normals);
        p.set_vec3_array("ShootEnergy", &self.energies);
        p.set_f32_array("ShooterId", &self.ids);
        p.set_vec3_array("ShootCorners", &self.corners);
        p.set_i32_array("ShootCornerCount", &self.corner_counts);
        p.set_f32_array("ShootArea", &self.areas);
        let options = self.options;
        let polygon = options.form_factor == FormFactorKind::Polygon;
        p.set_i32("FormFactorKind", polygon as i32);
        let hemicube = options.visibility == VisibilityKind::Hemicube;
        p.set_i32("HemiCube", hemicube as i32);
        p.set_i32("Robust", options.robust_visibility as i32);
        let planes = &self.planes.texture;
        p.set_i32("PlanesWidth", planes.width);
        p.set_i32("PlanesShift", planes.width.trailing_zeros() as i32);
        p.set_f32("PlaneSlack", self.planes.slack);
    }
}
