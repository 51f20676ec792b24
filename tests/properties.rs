//! Property tests for the path from polygons to the lightmap atlas (issue 6): random planar
//! polygons (convex, star-shaped, orthogonal "skyline" ones with reflex and collinear vertices),
//! in random 3D orientations, at random scales from 1e-3 to 1e4, grouped into random scenes and
//! cut into patches at random resolutions. Every check is relative to the polygon's own size, so
//! the same property must hold at every scale.
//!
//! The polygons are built in f64 in their own 2D frame, then rotated, scaled and moved into the
//! world; the checks map world points back to that frame, so they never trust the code under test
//! for the geometry they check it against.
//!
//! `PROPTEST_CASES=N` scales every property's case count by N / 256 (the defaults, ~2,000 scenes
//! for the layout properties, take ~3 s in release mode on 2 cores); the seed is fixed unless
//! `PROPTEST_RNG_SEED` is set. Tests marked `#[ignore]` record findings awaiting a fix in src/.

use glam::{DQuat, DVec2, DVec3, Vec3};
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::{triangulate, Polygon, Scene};
use proptest::prelude::*;

mod common;
use common::{load_text, scene_of, LAMP_MTL};
use proptest::test_runner::{Config, RngSeed};

// ---------------------------------------------------------------------------------------------
// Generators
// ---------------------------------------------------------------------------------------------

/// A simple polygon in its own plane, counter-clockwise, of size about 1 (f64, exact reference).
#[derive(Clone, Debug)]
struct Shape {
    points: Vec<DVec2>,
}

/// Angles around a full turn whose consecutive gaps are all below half a turn, so that the
/// star-shaped polygon through them is simple and contains the origin.
fn turn_angles(weights: &[f64], start: f64) -> Vec<f64> {
    let total: f64 = weights.iter().sum();
    let mut angle = start;
    weights
        .iter()
        .map(|w| {
            let a = angle;
            angle += std::f64::consts::TAU * w / total;
            a
        })
        .collect()
}

/// Convex: points on an ellipse (aspect down to 1:50) at increasing angles.
fn convex() -> impl Strategy<Value = Shape> {
    (
        prop::collection::vec(1.0..1.9f64, 3..12),
        0.02..1.0f64,
        0.0..std::f64::consts::TAU,
    )
        .prop_map(|(weights, aspect, start)| Shape {
            points: turn_angles(&weights, start)
                .into_iter()
                .map(|a| DVec2::new(a.cos(), aspect * a.sin()))
                .collect(),
        })
}

/// Star-shaped around the origin, usually non-convex (random radii).
fn star() -> impl Strategy<Value = Shape> {
    (
        prop::collection::vec((1.0..1.9f64, 0.1..1.0f64), 3..16),
        0.0..std::f64::consts::TAU,
    )
        .prop_map(|(wr, start)| {
            let weights: Vec<f64> = wr.iter().map(|w| w.0).collect();
            Shape {
                points: turn_angles(&weights, start)
                    .into_iter()
                    .zip(&wr)
                    .map(|(a, &(_, r))| DVec2::new(r * a.cos(), r * a.sin()))
                    .collect(),
            }
        })
}

/// Orthogonal "skyline": columns of random widths and heights standing on the x axis. Equal
/// neighbouring heights give collinear vertices; thin deep notches give reflex vertices whose ears
/// are hard to find.
fn skyline() -> impl Strategy<Value = Shape> {
    prop::collection::vec((0.05..1.0f64, 1u8..5), 1..8).prop_map(|columns| {
        let total: f64 = columns.iter().map(|c| c.0).sum();
        let mut xs = vec![0.0];
        for c in &columns {
            xs.push(xs.last().unwrap() + c.0 / total);
        }
        *xs.last_mut().unwrap() = 1.0;
        let mut points = vec![DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0)];
        for i in (0..columns.len()).rev() {
            let h = columns[i].1 as f64 * 0.25;
            for p in [DVec2::new(xs[i + 1], h), DVec2::new(xs[i], h)] {
                if points.last() != Some(&p) {
                    points.push(p);
                }
            }
        }
        // The walk ends at (0, h0) above the start: no duplicate to drop there.
        Shape { points }
    })
}

fn shape() -> impl Strategy<Value = Shape> {
    prop_oneof![convex(), star(), skyline()]
}

/// A rotation: arbitrary, or one of the 24 axis-aligned ones (faces of real scenes are mostly
/// axis-aligned, which puts exact zeros in the normals).
fn rotation() -> impl Strategy<Value = DQuat> {
    prop_oneof![
        (
            -std::f64::consts::PI..std::f64::consts::PI,
            -std::f64::consts::PI..std::f64::consts::PI,
            -std::f64::consts::PI..std::f64::consts::PI
        )
            .prop_map(|(a, b, c)| DQuat::from_euler(glam::EulerRot::ZYX, a, b, c)),
        (0u8..4, 0u8..4, 0u8..4).prop_map(|(a, b, c)| {
            let q = std::f64::consts::FRAC_PI_2;
            DQuat::from_euler(
                glam::EulerRot::ZYX,
                a as f64 * q,
                b as f64 * q,
                c as f64 * q,
            )
        }),
    ]
}

/// Scale of a whole scene: log-uniform in [1e-3, 1e4].
fn scale() -> impl Strategy<Value = f64> {
    (-3.0..4.0f64).prop_map(|e| 10f64.powf(e))
}

/// One polygon placed in a scene: shape, orientation, size relative to the scene (0.1 to 1) and
/// position (within 1.5 scene units of the origin along each axis).
#[derive(Clone, Debug)]
struct Placed {
    shape: Shape,
    rotation: DQuat,
    size: f64,
    offset: DVec3,
}

fn placed() -> impl Strategy<Value = Placed> {
    (
        shape(),
        rotation(),
        0.1..1.0f64,
        (-1.5..1.5f64, -1.5..1.5f64, -1.5..1.5f64),
    )
        .prop_map(|(shape, rotation, size, (x, y, z))| Placed {
            shape,
            rotation,
            size,
            offset: DVec3::new(x, y, z),
        })
}

impl Placed {
    /// World position of a point of the shape's plane (local z = distance from the plane).
    fn to_world(&self, p: DVec2, scale: f64) -> Vec3 {
        let local = DVec3::new(p.x, p.y, 0.0) * self.size;
        ((self.rotation * local + self.offset) * scale).as_vec3()
    }

    /// The shape's frame coordinates of a world point: (x, y) in the plane, z off it.
    fn to_local(&self, w: Vec3, scale: f64) -> DVec3 {
        self.rotation.inverse() * (w.as_dvec3() / scale - self.offset) / self.size
    }

    fn polygon(&self, scale: f64) -> Polygon {
        let vertices = self
            .shape
            .points
            .iter()
            .map(|&p| self.to_world(p, scale))
            .collect();
        Polygon::new(vertices, 0, "p".into()).expect("generated polygons have an area")
    }

    fn world_area(&self, scale: f64) -> f64 {
        shoelace(&self.shape.points) * (self.size * scale).powi(2)
    }
}

#[derive(Clone, Debug)]
struct SceneSpec {
    polygons: Vec<Placed>,
    scale: f64,
}

fn scene_spec() -> impl Strategy<Value = SceneSpec> {
    (prop::collection::vec(placed(), 1..7), scale())
        .prop_map(|(polygons, scale)| SceneSpec { polygons, scale })
}

impl SceneSpec {
    fn scene(&self) -> Scene {
        scene_of(
            self.polygons
                .iter()
                .map(|p| p.polygon(self.scale))
                .collect(),
        )
    }
}

/// `PatchLayout::try_new` (the path user input takes); a refusal fails the case with its message.
fn layout_of(scene: &Scene, resolution: Resolution) -> Result<PatchLayout, TestCaseError> {
    PatchLayout::try_new(scene, resolution)
        .map_err(|e| TestCaseError::fail(format!("try_new refused ({resolution:?}): {e}")))
}

/// How finely to cut: a patch target, or a patch size relative to the scene's scale (1 to 200
/// patches across a polygon of size 1). Both keep the atlas small enough for a quick check.
#[derive(Clone, Copy, Debug)]
enum Res {
    Patches(u32),
    PerUnit(f64),
}

fn resolution() -> impl Strategy<Value = Res> {
    prop_oneof![
        (1u32..3000).prop_map(Res::Patches),
        (-0.3..2.3f64).prop_map(|e| Res::PerUnit(10f64.powf(e))),
    ]
}

impl Res {
    fn at(self, scale: f64) -> Resolution {
        match self {
            Res::Patches(n) => Resolution::Patches(n),
            Res::PerUnit(k) => Resolution::PatchSize((scale / k) as f32),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Reference geometry (f64)
// ---------------------------------------------------------------------------------------------

fn shoelace(points: &[DVec2]) -> f64 {
    let n = points.len();
    0.5 * (0..n)
        .map(|i| points[i].perp_dot(points[(i + 1) % n]))
        .sum::<f64>()
}

fn point_in_polygon(points: &[DVec2], p: DVec2) -> bool {
    let n = points.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (points[i], points[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

fn distance_to_outline(points: &[DVec2], p: DVec2) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % n]);
            let ab = b - a;
            let t = ((p - a).dot(ab) / ab.length_squared().max(1e-300)).clamp(0.0, 1.0);
            (a + ab * t - p).length()
        })
        .fold(f64::INFINITY, f64::min)
}

impl Placed {
    /// Tolerance for "on the plane / inside the polygon / same area", in units of the polygon's
    /// own size. f32 coordinates carry ~6e-8 relative error, but `Polygon::new` takes Newell's
    /// normal from cross products of absolute positions, whose error grows with the square of
    /// (distance from the origin / polygon size) = r, divided by the polygon's area: measured
    /// up to 3.2e-4 at r = 14 for an area of 0.065 size² (see
    /// `polygon_far_from_the_origin_keeps_its_normal` for where that goes wrong). The generators
    /// keep r below ~27; this allows 5e-7·r²/area on top of 2e-5.
    fn tol(&self) -> f64 {
        let r = 1.0 + self.offset.length() / self.size;
        2e-5 + 5e-7 * r * r / shoelace(&self.shape.points)
    }
}

// ---------------------------------------------------------------------------------------------
// The checks, shared by the properties
// ---------------------------------------------------------------------------------------------

/// (a) Every lightmap rectangle plus its one-texel gutter lies inside the atlas, and no two of
/// them overlap.
fn check_packing(layout: &PatchLayout) -> Result<(), TestCaseError> {
    let (w, h) = (layout.atlas_width as u64, layout.atlas_height as u64);
    prop_assert!(w * h <= 64 << 20, "atlas {w}x{h} too large for the test");
    prop_assert_eq!(layout.owner.len() as u64, w * h);
    let mut used = vec![u32::MAX; (w * h) as usize];
    for (i, lm) in layout.lightmaps.iter().enumerate() {
        prop_assert!(lm.w >= 1 && lm.h >= 1, "lightmap {i} is empty");
        prop_assert!(
            lm.x >= 1
                && lm.y >= 1
                && (lm.x + lm.w + 1) as u64 <= w
                && (lm.y + lm.h + 1) as u64 <= h,
            "lightmap {i} ({},{} {}x{}) with its gutter leaves the {w}x{h} atlas",
            lm.x,
            lm.y,
            lm.w,
            lm.h
        );
        for y in lm.y - 1..lm.y + lm.h + 1 {
            for x in lm.x - 1..lm.x + lm.w + 1 {
                let at = (y as u64 * w + x as u64) as usize;
                prop_assert!(
                    used[at] == u32::MAX,
                    "lightmaps {} and {i} overlap at texel ({x}, {y}) (gutters included)",
                    used[at]
                );
                used[at] = i as u32;
            }
        }
    }
    Ok(())
}

/// (b) Every patch texel lies in its own polygon's lightmap rectangle, and its centre maps to a
/// point on the polygon's plane and inside the polygon. (c) The patch counts add up. Also: the
/// lightmap covers the whole polygon, and no texel is larger than the patch size.
fn check_patches(
    layout: &PatchLayout,
    placed: &[Placed],
    scale: f64,
    scene: &Scene,
) -> Result<(), TestCaseError> {
    let w = layout.atlas_width as usize;
    let mut counted = vec![0u32; layout.lightmaps.len()];
    for (at, &owner) in layout.owner.iter().enumerate() {
        if owner == 0 {
            continue;
        }
        let i = owner as usize - 1;
        prop_assert!(i < layout.lightmaps.len(), "owner {owner} out of range");
        counted[i] += 1;
        let (x, y) = ((at % w) as u32, (at / w) as u32);
        let lm = &layout.lightmaps[i];
        prop_assert!(
            (lm.x..lm.x + lm.w).contains(&x) && (lm.y..lm.y + lm.h).contains(&y),
            "patch texel ({x}, {y}) of polygon {i} outside its lightmap ({},{} {}x{})",
            lm.x,
            lm.y,
            lm.w,
            lm.h
        );
        let centre = lm.world((x - lm.x) as f32 + 0.5, (y - lm.y) as f32 + 0.5);
        let local = placed[i].to_local(centre, scale);
        prop_assert!(
            local.z.abs() <= placed[i].tol(),
            "centre of patch ({x}, {y}) is {} polygon sizes off polygon {i}'s plane",
            local.z
        );
        let flat = local.truncate();
        let points = &placed[i].shape.points;
        prop_assert!(
            point_in_polygon(points, flat) || distance_to_outline(points, flat) <= placed[i].tol(),
            "centre of patch ({x}, {y}) maps to {flat:?}, outside polygon {i} by {}",
            distance_to_outline(points, flat)
        );
    }
    prop_assert_eq!(&counted, &layout.patches_per_polygon);
    let total = layout.patch_count();
    prop_assert_eq!(
        total,
        layout.owner.iter().filter(|&&o| o != 0).count() as u64
    );
    prop_assert_eq!(total, layout.patch_count());

    for (i, (lm, polygon)) in layout.lightmaps.iter().zip(&scene.polygons).enumerate() {
        let slack = placed[i].tol() * (lm.w.max(lm.h) as f64);
        for &v in &polygon.vertices {
            let t = lm.texel_of(v).as_dvec2();
            prop_assert!(
                t.x >= -slack
                    && t.y >= -slack
                    && t.x <= lm.w as f64 + slack
                    && t.y <= lm.h as f64 + slack,
                "vertex {v} of polygon {i} is outside its lightmap (texel {t:?}, {}x{})",
                lm.w,
                lm.h
            );
        }
        let texel = (lm.axis_u.length() / lm.w as f32).max(lm.axis_v.length() / lm.h as f32);
        prop_assert!(
            texel <= layout.patch_size * (1.0 + 1e-5),
            "polygon {i}'s texels are {texel}, larger than the patch size {}",
            layout.patch_size
        );
    }
    Ok(())
}

/// The layout's patches, one colour per polygon; everything else a sentinel.
fn patch_colours(layout: &PatchLayout) -> Vec<f32> {
    layout
        .owner
        .iter()
        .enumerate()
        .flat_map(|(at, &o)| {
            if o == 0 {
                [-1.0; 4]
            } else {
                [o as f32, (at % 97) as f32, 1.0, 0.25]
            }
        })
        .collect()
}

/// (e), part one: dilation never changes a patch texel, and whatever it writes is the mean of
/// the same polygon's patches (channel 0 holds the polygon's id). Returns the dilated atlas.
fn check_dilate_keeps_patches(layout: &PatchLayout) -> Result<Vec<f32>, TestCaseError> {
    let before = patch_colours(layout);
    let mut after = before.clone();
    layout.dilate(&mut after);
    let w = layout.atlas_width as usize;
    for (at, &o) in layout.owner.iter().enumerate() {
        let (b, a) = (&before[at * 4..at * 4 + 4], &after[at * 4..at * 4 + 4]);
        if o != 0 {
            prop_assert!(
                a == b,
                "dilate changed patch texel ({}, {}) of polygon {}: {b:?} -> {a:?}",
                at % w,
                at / w,
                o - 1
            );
        } else if a[0] != -1.0 {
            // A written texel must lie in some lightmap or gutter whose polygon it copies.
            let (x, y) = ((at % w) as i64, (at / w) as i64);
            let id = a[0] as usize;
            prop_assert!(
                a[0] == id as f32 && id >= 1 && id <= layout.lightmaps.len(),
                "texel ({x}, {y}) got {a:?}, not one polygon's patches"
            );
            let lm = &layout.lightmaps[id - 1];
            prop_assert!(
                x >= lm.x as i64 - 1
                    && x <= (lm.x + lm.w) as i64
                    && y >= lm.y as i64 - 1
                    && y <= (lm.y + lm.h) as i64,
                "texel ({x}, {y}) got polygon {}'s colour outside its lightmap and gutter",
                id - 1
            );
        }
    }
    Ok(after)
}

/// Texels of lightmap `lm`'s one-texel gutter ring.
fn gutter(lm: &gpu_radiosity::patches::Lightmap) -> Vec<(u32, u32)> {
    let (x0, y0, x1, y1) = (lm.x - 1, lm.y - 1, lm.x + lm.w, lm.y + lm.h);
    let mut ring = Vec::new();
    for x in x0..=x1 {
        ring.push((x, y0));
        ring.push((x, y1));
    }
    for y in y0 + 1..y1 {
        ring.push((x0, y));
        ring.push((x1, y));
    }
    ring
}

/// (e), part two, as the layout documents it: every gutter texel within three texels (8-connected
/// rounds) of one of the polygon's patches is filled with that polygon's colour.
fn check_dilate_fills_near_gutter(
    layout: &PatchLayout,
    after: &[f32],
) -> Result<(), TestCaseError> {
    let w = layout.atlas_width as usize;
    for (i, lm) in layout.lightmaps.iter().enumerate() {
        for (x, y) in gutter(lm) {
            let near = (y.saturating_sub(3)..=y + 3).any(|py| {
                (x.saturating_sub(3)..=x + 3).any(|px| {
                    (lm.x..lm.x + lm.w).contains(&px)
                        && (lm.y..lm.y + lm.h).contains(&py)
                        && layout.owner[py as usize * w + px as usize] == i as u32 + 1
                })
            });
            if near {
                let v = after[(y as usize * w + x as usize) * 4];
                prop_assert!(
                    v == (i + 1) as f32,
                    "gutter texel ({x}, {y}) of polygon {i}, near its patches, holds {v}"
                );
            }
        }
    }
    Ok(())
}

/// (e), part three, as issue 6 states it: every gutter texel of a lightmap with at least one
/// patch is filled.
fn check_dilate_fills_whole_gutter(
    layout: &PatchLayout,
    after: &[f32],
) -> Result<(), TestCaseError> {
    let w = layout.atlas_width as usize;
    for (i, lm) in layout.lightmaps.iter().enumerate() {
        if layout.patches_per_polygon[i] == 0 {
            continue;
        }
        for (x, y) in gutter(lm) {
            let v = after[(y as usize * w + x as usize) * 4];
            prop_assert!(
                v == (i + 1) as f32,
                "gutter texel ({x}, {y}) of polygon {i} ({}x{}, {} patches) holds {v}",
                lm.w,
                lm.h,
                layout.patches_per_polygon[i]
            );
        }
    }
    Ok(())
}

/// (d) `triangulate` gives n - 2 triangles, all counter-clockwise (up to rounding), whose areas
/// sum to the polygon's area: with unsigned areas, so that flipped or overlapping triangles show.
fn check_triangulation(polygon: &Polygon, exact_area: f64, tol: f64) -> Result<(), TestCaseError> {
    let n = polygon.vertices.len();
    let triangles = triangulate(&polygon.vertices, polygon.normal);
    prop_assert_eq!(triangles.len(), n - 2);
    let normal = polygon.normal.as_dvec3();
    let v: Vec<DVec3> = polygon.vertices.iter().map(|v| v.as_dvec3()).collect();
    let mut unsigned = 0.0;
    for t in &triangles {
        prop_assert!(t.iter().all(|&k| k < n) && t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
        let a = 0.5 * (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).dot(normal);
        unsigned += a.abs();
    }
    prop_assert!(
        (unsigned - exact_area).abs() <= tol * exact_area,
        "{} triangles cover {unsigned} (unsigned), the polygon's area is {exact_area}",
        triangles.len()
    );
    prop_assert!(
        ((polygon.area as f64) - exact_area).abs() <= tol * exact_area,
        "Polygon::area {} against {exact_area}",
        polygon.area
    );
    Ok(())
}

/// `cases` at the default budget; `PROPTEST_CASES=N` scales every property by N / 256. The seed
/// is fixed, so CI runs the same cases every time; `PROPTEST_RNG_SEED=N` explores others.
fn config(cases: u32) -> Config {
    let budget = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
        .map(|c| c.max(1))
        .unwrap_or(256);
    let base = Config::default();
    Config {
        cases: ((cases as u64 * budget / 256).max(1)).min(u32::MAX as u64) as u32,
        rng_seed: if std::env::var_os("PROPTEST_RNG_SEED").is_some() {
            base.rng_seed
        } else {
            RngSeed::Fixed(0x5ca1e)
        },
        // Persisted failures would land in the tree; a failure prints its minimal input instead.
        failure_persistence: None,
        ..base
    }
}

// ---------------------------------------------------------------------------------------------
// The properties
// ---------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(config(2048))]

    /// (a), (b), (c) and (e, as documented) on random scenes at random resolutions.
    #[test]
    fn layout_invariants(spec in scene_spec(), res in resolution()) {
        let scene = spec.scene();
        let layout = layout_of(&scene, res.at(spec.scale))?;
        check_packing(&layout)?;
        check_patches(&layout, &spec.polygons, spec.scale, &scene)?;
        let after = check_dilate_keeps_patches(&layout)?;
        check_dilate_fills_near_gutter(&layout, &after)?;
    }

    /// (d) on single polygons of every kind, orientation and scale.
    #[test]
    fn triangulation_covers_the_polygon(p in placed(), s in scale()) {
        let polygon = p.polygon(s);
        check_triangulation(&polygon, p.world_area(s), p.tol())?;
    }

    /// (d) with collinear vertices inserted (T-junctions, as meshes exported from modellers
    /// have): midpoints of random edges.
    #[test]
    fn triangulation_with_collinear_vertices(
        p in placed(),
        s in scale(),
        splits in prop::collection::vec((any::<prop::sample::Index>(), 0.1..0.9f64), 1..4),
    ) {
        let mut p = p;
        for (edge, t) in splits {
            let n = p.shape.points.len();
            let i = edge.index(n);
            let (a, b) = (p.shape.points[i], p.shape.points[(i + 1) % n]);
            p.shape.points.insert(i + 1, a.lerp(b, t));
        }
        let polygon = p.polygon(s);
        check_triangulation(&polygon, p.world_area(s), p.tol())?;
    }

    /// Results do not depend on the scale: the same scene at scale 1 and at a random scale from
    /// 1e-3 to 1e4 gets the same lightmap sizes, atlas and patches, for a patch target and for a
    /// proportional patch size.
    #[test]
    fn layout_does_not_depend_on_scale(spec in scene_spec(), res in resolution()) {
        let unit = SceneSpec { scale: 1.0, ..spec.clone() };
        let a = layout_of(&unit.scene(), res.at(1.0))?;
        let b = layout_of(&spec.scene(), res.at(spec.scale))?;
        // `fit_lightmap` keeps the first edge whose rectangle is 0.1 % smaller than the best so
        // far; when two orientations are within rounding of that margin, the choice flips with
        // the scale (seen: 0.7688 x 0.9430 against 0.9653 x 0.7503). Harmless, but then sizes
        // cannot be compared: such cases only check what does not depend on the orientation.
        let flipped = a.lightmaps.iter().zip(&b.lightmaps).any(|(la, lb)| {
            la.axis_u.normalize().dot(lb.axis_u.normalize()).abs() < 0.9999
        });
        if flipped {
            prop_assert_eq!(a.lightmaps.len(), b.lightmaps.len());
            return Ok(());
        }
        let sizes = |l: &PatchLayout| -> Vec<(u32, u32)> {
            l.lightmaps.iter().map(|m| (m.w, m.h)).collect()
        };
        // Rounding (a texel count that is an exact integer at one scale and a hair above at
        // another) may move a lightmap by one texel; anything more is a dependence on scale.
        for (i, (sa, sb)) in sizes(&a).iter().zip(sizes(&b).iter()).enumerate() {
            prop_assert!(
                sa.0.abs_diff(sb.0) <= 1 && sa.1.abs_diff(sb.1) <= 1,
                "polygon {i}: lightmap {sa:?} at scale 1, {sb:?} at scale {}", spec.scale
            );
        }
        // So the patch counts may differ by at most a row and a column per lightmap. (With a
        // patch target, `size_for_count` returns a patch size exactly at a jump of
        // ceil(side / size), so a polygon whose sides are in an integer ratio, e.g. a 4:1
        // rectangle, flips between w and w + 1 with the rounding of its coordinates.)
        let slack: u64 = sizes(&a)
            .iter()
            .zip(sizes(&b).iter())
            .map(|(sa, sb)| (sa.0.max(sb.0) + sa.1.max(sb.1) + 1) as u64)
            .sum();
        let (na, nb) = (a.patch_count(), b.patch_count());
        prop_assert!(
            na.abs_diff(nb) <= slack,
            "{na} patches at scale 1, {nb} at scale {}", spec.scale
        );
        let rel = (b.patch_size as f64 / spec.scale) / a.patch_size as f64;
        prop_assert!((rel - 1.0).abs() < 1e-3, "patch size ratio {rel}");
    }
}

proptest! {
    #![proptest_config(config(256))]

    /// (e) as issue 6 states it: dilation fills *every* gutter texel of a lightmap that has a
    /// patch. Fails today for lightmaps larger than ~6 texels whose polygon leaves a corner of its
    /// bounding rectangle empty (any triangle): `dilate` runs three rounds, so gutter texels more
    /// than three texels from a patch stay unfilled. Those texels are never sampled by the
    /// display's bilinear filter, so this is kept as a record of the gap, not a live check.
    #[test]

    fn dilate_fills_every_gutter_texel(spec in scene_spec(), res in resolution()) {
        let scene = spec.scene();
        let layout = layout_of(&scene, res.at(spec.scale))?;
        let after = check_dilate_keeps_patches(&layout)?;
        check_dilate_fills_whole_gutter(&layout, &after)?;
    }

    /// (d) with a repeated vertex (a zero-length edge, as `f 1 2 2 3` or two `v` lines at the
    /// same place give): still n - 2 triangles covering the polygon exactly. Fails today: the
    /// repeated point lies on the corner of every ear next to it, the ear test wants all other
    /// vertices strictly outside, so no ear is found and the fan fallback clips a reflex vertex
    /// (see `triangulate_with_a_repeated_vertex_regression` below).
    #[test]

    fn triangulation_with_a_repeated_vertex(
        p in placed(),
        s in scale(),
        at in any::<prop::sample::Index>(),
    ) {
        let mut p = p;
        let i = at.index(p.shape.points.len());
        let v = p.shape.points[i];
        p.shape.points.insert(i, v);
        let polygon = p.polygon(s);
        check_triangulation(&polygon, p.world_area(s), p.tol())?;
    }
}

// ---------------------------------------------------------------------------------------------
// Loading from bytes: the same invariants through `load_obj`
// ---------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(config(256))]

    /// A random scene written as OBJ text (printed with full f32 precision) loads back to the
    /// same polygons, and its layout keeps every invariant.
    #[test]
    fn obj_round_trip_keeps_the_invariants(spec in scene_spec(), n in 1u32..3000) {
        let scene = spec.scene();
        let mut obj = String::from("mtllib m.mtl\nusemtl lamp\n");
        let mut next = 1;
        for p in &scene.polygons {
            for v in &p.vertices {
                obj += &format!("v {:?} {:?} {:?}\n", v.x, v.y, v.z);
            }
            obj += "f";
            for k in 0..p.vertices.len() {
                obj += &format!(" {}", next + k);
            }
            obj += "\n";
            next += p.vertices.len();
        }
        let (_dir, loaded) = load_text(&obj, LAMP_MTL);
        let loaded = loaded.map_err(|e| TestCaseError::fail(format!("{e}\n{obj}")))?;
        prop_assert_eq!(loaded.polygons.len(), scene.polygons.len());
        for (a, b) in loaded.polygons.iter().zip(&scene.polygons) {
            prop_assert_eq!(&a.vertices, &b.vertices);
        }
        let layout = layout_of(&loaded, Resolution::Patches(n))?;
        check_packing(&layout)?;
        check_patches(&layout, &spec.polygons, spec.scale, &loaded)?;
    }
}

proptest! {
    #![proptest_config(config(256))]

    /// Translation must not matter any more than the f32 coordinates themselves force: a polygon
    /// of size 1 at 100 to 10,000 units from the origin (a detail of a building modelled in
    /// millimetres) should get its normal to within a few ulps of its coordinates. Fails today:
    /// `Polygon::new` sums Newell's cross products of absolute positions, whose rounding error
    /// is ~eps·r² against an area of 1; at r = 1e4 a unit square gets a normal 53° off and twice
    /// its area (`polygon_far_from_the_origin_regression`).
    #[test]

    fn polygon_far_from_the_origin_keeps_its_normal(
        shape in shape(),
        rotation in rotation(),
        r in 2.0..4.0f64,
        direction in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
    ) {
        let (x, y, z) = direction;
        let offset = DVec3::new(x, y, z).normalize_or(DVec3::X) * 10f64.powf(r);
        let p = Placed { shape, rotation, size: 1.0, offset };
        let vertices: Vec<Vec3> = p.shape.points.iter().map(|&q| p.to_world(q, 1.0)).collect();
        let area = p.world_area(1.0);
        let polygon = Polygon::new(vertices, 0, "far".into()).ok_or_else(|| {
            TestCaseError::fail(format!(
                "dropped as degenerate (area {area}) at distance {}",
                offset.length()
            ))
        })?;
        let truth = rotation * DVec3::Z;
        let angle = polygon.normal.as_dvec3().angle_between(truth);
        // The coordinates are good to ~ulp(r) = 1.2e-7·r, which moves the normal and the area by
        // about that times perimeter / area (in units of the polygon's size); allow ten times it.
        let n = p.shape.points.len();
        let perimeter: f64 = (0..n)
            .map(|i| p.shape.points[i].distance(p.shape.points[(i + 1) % n]))
            .sum();
        let allowed = 1.2e-6 * offset.length() * perimeter / area;
        prop_assert!(
            angle <= allowed,
            "normal {} is {angle:.2e} rad off at distance {}",
            polygon.normal,
            offset.length()
        );
        prop_assert!(
            ((polygon.area as f64) - area).abs() <= allowed * area,
            "area {} against {area}",
            polygon.area
        );
    }
}
