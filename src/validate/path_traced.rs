//! An independent reference for the Cornell box: a plain Monte Carlo path tracer on the CPU.
//!
//! Paths start at a polygon's patch centres and bounce in cosine-weighted directions; at every
//! vertex the light is sampled on its area (next-event estimation), and from the fourth bounce on
//! Russian roulette ends a path with the probability its throughput has lost (at least 5 %).
//! Emission is only counted through the light's direct term, so the radiance found is a
//! receiver's. It shares nothing with the radiosity solvers but the scene and the ray casting
//! (`scene::bvh::Bvh`), so it can judge both.
//!
//! [`Reference::new`] gives each polygon's mean radiance over its patch centres with the relative
//! standard error of that mean (eight independent batches); [`compare`] sets a radiosity atlas
//! beside it, region by region ([`cornell_region`]). `tests/path_traced.rs` holds the default
//! mode to 3 % in every region with it, and `radiosity bench guard` reports every configuration's
//! worst region.

use crate::patches::PatchLayout;
use crate::random::Rng;
use crate::scene::bvh::Bvh;
use crate::scene::Scene;
use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::PI;

/// Independent batches per polygon: the spread of their means gives the standard error.
pub const BATCHES: usize = 8;

/// Paths per patch centre of the Cornell reference of the tests and `bench guard`: with them the
/// darkest face's reference is good to about 1 %.
pub const CORNELL_PATHS: usize = 1024;

/// Patches of the Cornell layout the reference and the compared solutions use (the default
/// layout, `Resolution::Patches`).
pub const CORNELL_PATCHES: u32 = 4096;

/// Why a scene or an atlas cannot be compared with the path tracer.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PathTracedError {
    /// Not exactly one emitting polygon (how many there are).
    #[error("the path tracer needs exactly one emitting polygon (it samples that one light); the scene has {0}")]
    Lights(usize),
    /// The light is not a parallelogram.
    #[error(
        "the light, polygon {polygon} (object '{object}'), has {corners} corners and is not a \
         parallelogram; the path tracer samples the light as one"
    )]
    LightShape {
        /// The light's polygon.
        polygon: usize,
        /// Its object in the file.
        object: String,
        /// Its corners.
        corners: usize,
    },
    /// Fewer paths per patch centre than batches (how many were asked for).
    #[error(
        "the path tracer needs at least {BATCHES} paths per patch centre (one per batch), not {0}"
    )]
    Paths(usize),
    /// A polygon outside the Cornell box's regions.
    #[error(
        "polygon {polygon} (object '{object}') is in none of the Cornell box's regions (floor, \
         ceiling, back_wall, red_wall, green_wall, short_block, tall_block)"
    )]
    NotCornell {
        /// The polygon.
        polygon: usize,
        /// Its object in the file.
        object: String,
    },
    /// An atlas that does not match the layout.
    #[error("the atlas has {got} floats; the layout's {width}x{height} RGBA atlas has {expected}")]
    AtlasSize {
        /// Floats given.
        got: usize,
        /// Floats the layout's atlas has.
        expected: usize,
        /// The atlas's width, texels.
        width: u32,
        /// The atlas's height, texels.
        height: u32,
    },
    /// A reference for another scene.
    #[error("the reference has {got} polygons; the scene has {expected}")]
    ReferenceSize {
        /// The reference's polygons.
        got: usize,
        /// The scene's polygons.
        expected: usize,
    },
}

fn cosine_direction(n: Vec3, rng: &mut Rng) -> Vec3 {
    let (u1, u2) = (rng.uniform(), rng.uniform());
    let r = u1.sqrt();
    let phi = 2.0 * PI * u2;
    let (t, b) = n.any_orthonormal_pair();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}

/// Irradiance / π from the light, sampled on its area (next event estimation).
fn direct(
    scene: &Scene,
    bvh: &Bvh,
    light: usize,
    x: Vec3,
    n: Vec3,
    skip: u32,
    rng: &mut Rng,
) -> Vec3 {
    let l = &scene.polygons[light];
    let (a, b, d) = (l.vertices[0], l.vertices[1], l.vertices[3]);
    let y = a + (b - a) * rng.uniform() + (d - a) * rng.uniform();
    let w = y - x;
    let r2 = w.length_squared();
    let w = w / r2.sqrt();
    let (ci, cl) = (n.dot(w), -l.normal.dot(w));
    if ci <= 0.0 || cl <= 0.0 || bvh.occluded(x, y, skip, light as u32) {
        return Vec3::ZERO;
    }
    scene.material(l).ke * (ci * cl * l.area / (PI * r2))
}

/// Outgoing radiance at x on polygon p (emission excluded: these are receivers).
fn radiance(scene: &Scene, bvh: &Bvh, light: usize, p: usize, x: Vec3, rng: &mut Rng) -> Vec3 {
    let (mut total, mut throughput) = (Vec3::ZERO, scene.material(&scene.polygons[p]).kd);
    let (mut x, mut p) = (x, p);
    for bounce in 0..64 {
        let n = scene.polygons[p].normal;
        total += throughput * direct(scene, bvh, light, x, n, p as u32, rng);
        if bounce >= 3 {
            let survive = throughput.max_element().min(0.95);
            if rng.uniform() >= survive {
                break;
            }
            throughput /= survive;
        }
        let d = cosine_direction(n, rng);
        let Some((t, q)) = bvh.closest(x, d, p as u32) else {
            break;
        };
        let q = q as usize;
        // Front faces only: a back face and the light (counted by the direct term) end the path.
        if scene.polygons[q].normal.dot(d) >= 0.0 || q == light {
            break;
        }
        x += d * t;
        p = q;
        throughput *= scene.material(&scene.polygons[q]).kd;
    }
    total
}

/// The RGB mean, the radiance the comparisons use.
fn lum(v: Vec3) -> f32 {
    (v.x + v.y + v.z) / 3.0
}

/// The centres of polygon `p`'s patches: (atlas texel index, world position).
pub fn patch_centres(layout: &PatchLayout, p: usize) -> Vec<(usize, Vec3)> {
    let lm = &layout.lightmaps[p];
    let mut out = Vec::new();
    for t in 0..lm.h {
        for s in 0..lm.w {
            let at = (lm.y + t) as usize * layout.atlas_width as usize + (lm.x + s) as usize;
            if layout.owner[at] == p as u32 + 1 {
                out.push((at, lm.world(s as f32 + 0.5, t as f32 + 0.5)));
            }
        }
    }
    out
}

/// The mean radiance (RGB) of polygon `p` over all its patch centres, and the relative standard
/// error of its RGB mean: [`BATCHES`] independent batches of `paths / BATCHES` paths per centre.
fn polygon_reference(
    scene: &Scene,
    bvh: &Bvh,
    layout: &PatchLayout,
    light: usize,
    p: usize,
    paths: usize,
) -> (Vec3, f32) {
    let centres = patch_centres(layout, p);
    if centres.is_empty() {
        return (Vec3::ZERO, 0.0);
    }
    let per_batch = paths / BATCHES;
    let batches: Vec<Vec3> = (0..BATCHES as u64)
        .into_par_iter()
        .map(|b| {
            // Seeded by polygon and batch: the same numbers on any thread count.
            let mut rng = Rng::new(1000 * p as u64 + 7919 * b + 1);
            let mut sum = Vec3::ZERO;
            for (_, x) in &centres {
                for _ in 0..per_batch {
                    sum += radiance(scene, bvh, light, p, *x, &mut rng);
                }
            }
            sum / (centres.len() * per_batch) as f32
        })
        .collect();
    let mean = batches.iter().copied().sum::<Vec3>() / BATCHES as f32;
    let m = lum(mean);
    let variance =
        batches.iter().map(|b| (lum(*b) - m).powi(2)).sum::<f32>() / (BATCHES - 1) as f32;
    (mean, (variance / BATCHES as f32).sqrt() / m)
}

/// The scene's one light, if it has exactly one and it is a parallelogram (the tracer samples it
/// uniformly as the parallelogram of its corners 0, 1 and 3).
pub fn the_light(scene: &Scene) -> Result<usize, PathTracedError> {
    let lights: Vec<usize> = (0..scene.polygons.len())
        .filter(|&p| scene.material(&scene.polygons[p]).is_emitter())
        .collect();
    let &[light] = lights.as_slice() else {
        return Err(PathTracedError::Lights(lights.len()));
    };
    let polygon = &scene.polygons[light];
    let v = &polygon.vertices;
    let parallelogram = v.len() == 4 && {
        let size = (v[2] - v[0]).length().max((v[3] - v[1]).length());
        (v[0] + v[2] - v[1] - v[3]).length() <= 1e-4 * size
    };
    if !parallelogram {
        return Err(PathTracedError::LightShape {
            polygon: light,
            object: polygon.object.clone(),
            corners: v.len(),
        });
    }
    Ok(light)
}

/// The path-traced reference of a scene's patches.
#[derive(Clone, Debug)]
pub struct Reference {
    /// The light (no reference: emission is not traced).
    pub light: usize,
    /// Paths per patch centre.
    pub paths: usize,
    /// Per polygon, the mean radiance (RGB) over its patch centres and the relative standard
    /// error of its RGB mean; zero for the light and for a polygon without patches.
    pub polygons: Vec<(Vec3, f32)>,
}

impl Reference {
    /// Trace `paths` paths at every patch centre of `layout` of every polygon but the light
    /// (in parallel, over the batches; the result does not depend on the thread count).
    pub fn new(
        scene: &Scene,
        layout: &PatchLayout,
        paths: usize,
    ) -> Result<Reference, PathTracedError> {
        let light = the_light(scene)?;
        if paths < BATCHES {
            return Err(PathTracedError::Paths(paths));
        }
        let bvh = Bvh::new(scene);
        let polygons = (0..scene.polygons.len())
            .map(|p| {
                if p == light {
                    (Vec3::ZERO, 0.0)
                } else {
                    polygon_reference(scene, &bvh, layout, light, p, paths)
                }
            })
            .collect();
        Ok(Reference {
            light,
            paths,
            polygons,
        })
    }
}

/// The region of the Cornell box polygon `p` belongs to, by its object and facing: the walls,
/// floor and ceiling, each block's top, the tall block's other faces, and the short block's front
/// (its side facing the camera, at -z: behind every whole-polygon shooter's centroid) apart from
/// its other sides. `None` for an object the box does not have.
pub fn cornell_region(scene: &Scene, p: usize) -> Option<&'static str> {
    let polygon = &scene.polygons[p];
    let front = (0..scene.polygons.len())
        .filter(|&q| scene.polygons[q].object == "short_block")
        .min_by(|&a, &b| {
            scene.polygons[a]
                .normal
                .z
                .total_cmp(&scene.polygons[b].normal.z)
        });
    Some(match (polygon.object.as_str(), polygon.normal.y > 0.9) {
        ("short_block", true) => "short block top",
        ("short_block", false) if Some(p) == front => "short block front",
        ("short_block", false) => "short block sides",
        ("tall_block", true) => "tall block top",
        ("tall_block", false) => "tall block faces",
        ("floor", _) => "floor",
        ("ceiling", _) => "ceiling",
        ("back_wall", _) => "back_wall",
        ("red_wall", _) => "red_wall",
        ("green_wall", _) => "green_wall",
        _ => return None,
    })
}

/// One polygon of a solution against the reference.
#[derive(Clone, Debug)]
pub struct RegionRow {
    /// Its Cornell region ([`cornell_region`]).
    pub region: &'static str,
    /// The polygon.
    pub polygon: usize,
    /// The solution's and the reference's mean radiance (RGB) over the polygon's patch centres.
    pub ours: Vec3,
    /// See `ours`: the path tracer's.
    pub reference: Vec3,
    /// (ours − reference) / reference, by the RGB mean, in %.
    pub difference: f64,
    /// The reference's relative standard error, in %.
    pub noise: f64,
}

/// A solution against the reference: every polygon with patches but the light, and the worst.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// One row per polygon compared.
    pub rows: Vec<RegionRow>,
    /// The largest |difference| over the rows, a fraction.
    pub worst: f32,
    /// The largest reference noise over the rows, a fraction.
    pub worst_noise: f32,
}

impl Comparison {
    /// The row of the largest |difference| (the first of equals), if there is a row.
    pub fn worst_row(&self) -> Option<&RegionRow> {
        self.rows.iter().reduce(|a, b| {
            if b.difference.abs() > a.difference.abs() {
                b
            } else {
                a
            }
        })
    }
}

/// The radiosity `atlas` (RGBA, in `layout`, the reference's) of the Cornell box `scene` against
/// `reference`, polygon by polygon: the mean of the atlas at the patch centres against the
/// reference's mean there.
pub fn compare(
    scene: &Scene,
    layout: &PatchLayout,
    reference: &Reference,
    atlas: &[f32],
) -> Result<Comparison, PathTracedError> {
    let expected = 4 * layout.atlas_width as usize * layout.atlas_height as usize;
    if atlas.len() != expected {
        return Err(PathTracedError::AtlasSize {
            got: atlas.len(),
            expected,
            width: layout.atlas_width,
            height: layout.atlas_height,
        });
    }
    if reference.polygons.len() != scene.polygons.len() {
        return Err(PathTracedError::ReferenceSize {
            got: reference.polygons.len(),
            expected: scene.polygons.len(),
        });
    }
    let (mut worst, mut worst_noise) = (0f32, 0f32);
    let mut rows = Vec::new();
    for (p, polygon) in scene.polygons.iter().enumerate() {
        if p == reference.light {
            continue;
        }
        let region = cornell_region(scene, p).ok_or_else(|| PathTracedError::NotCornell {
            polygon: p,
            object: polygon.object.clone(),
        })?;
        let centres = patch_centres(layout, p);
        if centres.is_empty() {
            continue;
        }
        let ours = centres
            .iter()
            .map(|&(at, _)| Vec3::from_slice(&atlas[at * 4..at * 4 + 3]))
            .sum::<Vec3>()
            / centres.len() as f32;
        let (expected, noise) = reference.polygons[p];
        let err = (lum(ours) - lum(expected)) / lum(expected);
        worst = worst.max(err.abs());
        worst_noise = worst_noise.max(noise);
        rows.push(RegionRow {
            region,
            polygon: p,
            ours,
            reference: expected,
            difference: 100.0 * err as f64,
            noise: 100.0 * noise as f64,
        });
    }
    Ok(Comparison {
        rows,
        worst,
        worst_noise,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patches::Resolution;
    use crate::scene::bundled;

    fn cornell() -> (Scene, PatchLayout) {
        let scene = bundled::cornell().load().unwrap();
        let layout = PatchLayout::new(&scene, Resolution::Patches(64));
        (scene, layout)
    }

    fn atlas_len(layout: &PatchLayout) -> usize {
        4 * (layout.atlas_width * layout.atlas_height) as usize
    }

    #[test]
    fn every_cornell_polygon_has_a_region_and_the_short_block_one_front() {
        let (scene, _) = cornell();
        let light = the_light(&scene).unwrap();
        let regions: Vec<_> = (0..scene.polygons.len())
            .filter(|&p| p != light)
            .map(|p| cornell_region(&scene, p).unwrap())
            .collect();
        assert_eq!(
            regions
                .iter()
                .filter(|&&r| r == "short block front")
                .count(),
            1
        );
        assert_eq!(regions.iter().filter(|&&r| r == "floor").count(), 1);
    }

    #[test]
    fn a_solution_equal_to_the_reference_differs_by_nothing_and_a_brighter_one_by_its_gain() {
        let (scene, layout) = cornell();
        let reference = Reference::new(&scene, &layout, 16).unwrap();
        assert_eq!(reference.light, the_light(&scene).unwrap());
        let mut atlas = vec![0f32; atlas_len(&layout)];
        for p in 0..scene.polygons.len() {
            for (at, _) in patch_centres(&layout, p) {
                let (mean, _) = reference.polygons[p];
                atlas[at * 4..at * 4 + 3].copy_from_slice(&mean.to_array());
            }
        }
        let same = compare(&scene, &layout, &reference, &atlas).unwrap();
        assert_eq!(same.rows.len(), scene.polygons.len() - 1);
        assert!(same.worst < 1e-5, "{}", same.worst);
        // Every receiver lit: the reference is not all zeros.
        assert!(same.rows.iter().all(|r| lum(r.reference) > 0.0));
        // The floor 10 % brighter: the worst is the floor's +10 %.
        let floor = (0..scene.polygons.len())
            .find(|&p| scene.polygons[p].object == "floor")
            .unwrap();
        for (at, _) in patch_centres(&layout, floor) {
            for c in &mut atlas[at * 4..at * 4 + 3] {
                *c *= 1.1;
            }
        }
        let brighter = compare(&scene, &layout, &reference, &atlas).unwrap();
        let worst = brighter.worst_row().unwrap();
        assert_eq!((worst.region, worst.polygon), ("floor", floor));
        assert!(
            (worst.difference - 10.0).abs() < 1e-3,
            "{}",
            worst.difference
        );
    }

    #[test]
    fn scenes_and_atlases_it_cannot_judge_are_refused() {
        let (scene, layout) = cornell();
        assert_eq!(
            Reference::new(&scene, &layout, 4).unwrap_err(),
            PathTracedError::Paths(4)
        );
        let reference = Reference::new(&scene, &layout, 8).unwrap();
        assert!(matches!(
            compare(&scene, &layout, &reference, &[0.0; 8]),
            Err(PathTracedError::AtlasSize { got: 8, .. })
        ));
        let mut two_lights = scene.clone();
        two_lights
            .polygons
            .push(two_lights.polygons[reference.light].clone());
        assert_eq!(
            the_light(&two_lights).unwrap_err(),
            PathTracedError::Lights(2)
        );
        let mut bent = scene.clone();
        bent.polygons[reference.light].vertices[2].x += 50.0;
        assert!(matches!(
            the_light(&bent),
            Err(PathTracedError::LightShape { corners: 4, .. })
        ));
        let mut renamed = scene.clone();
        let floor = (0..scene.polygons.len())
            .find(|&p| scene.polygons[p].object == "floor")
            .unwrap();
        renamed.polygons[floor].object = "mirror".into();
        assert_eq!(
            compare(
                &renamed,
                &layout,
                &reference,
                &vec![0.0; atlas_len(&layout)]
            )
            .unwrap_err(),
            PathTracedError::NotCornell {
                polygon: floor,
                object: "mirror".into()
            }
        );
    }
}
