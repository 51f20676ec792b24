//! Regressions found by fuzzing (`fuzz/fuzz_targets/scene_to_atlas.rs`): each a scene or an
//! input that once panicked, aborted or gave a wrong layout, kept as the smallest case that
//! showed it (split from `tests/properties.rs`, whose random scenes found some of them).

use glam::Vec3;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::{load_obj, triangulate, Polygon};

mod common;
use common::{load_text, scene_of, LAMP_MTL};

/// A chevron whose tip is given twice (`f 1 2 3 4 4`): ear clipping finds no ear, falls back to
/// a fan from vertex 1 (a reflex vertex) and returns triangles covering 10.5 instead of 7.5, the
/// outer ones outside the polygon, so the GPU would draw (and light) texels that are not patches.
#[test]

fn triangulate_with_a_repeated_vertex_regression() {
    let v: Vec<Vec3> = [(3.0, 0.0), (0.0, 0.5), (-3.0, 0.0), (0.0, 3.0), (0.0, 3.0)]
        .iter()
        .map(|&(x, y)| Vec3::new(x, y, 0.0))
        .collect();
    let polygon = Polygon::new(v.clone(), 0, "chevron".into()).unwrap();
    assert!((polygon.area - 7.5).abs() < 1e-5);
    let triangles = triangulate(&v, polygon.normal);
    // Four distinct corners: two triangles (the repeated vertex adds no corner).
    assert_eq!(triangles.len(), 2);
    let unsigned: f32 = triangles
        .iter()
        .map(|t| (0.5 * (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).z).abs())
        .sum();
    assert!((unsigned - 7.5).abs() < 1e-4, "triangles cover {unsigned}");
}

/// A unit square tilted to the normal (0, 0.6, 0.8), at (1e4, 7e3, 3e3): `Polygon::new` gives
/// the normal (0, 1, 0) and area 2.
#[test]

fn polygon_far_from_the_origin_regression() {
    let o = Vec3::new(1e4, 7e3, 3e3);
    let (u, v) = (Vec3::X, Vec3::new(0.0, 0.8, -0.6));
    let polygon = Polygon::new(vec![o, o + u, o + u + v, o + v], 0, "far".into()).unwrap();
    let angle = polygon.normal.angle_between(Vec3::new(0.0, 0.6, 0.8));
    assert!(angle < 1e-2, "normal {} is {angle} rad off", polygon.normal);
    assert!((polygon.area - 1.0).abs() < 1e-2, "area {}", polygon.area);
}

/// An MTL colour with fewer than three values (`Kd 0.5 0.5`) panicked inside tobj 4.0.5
/// (`parse_float3` unwraps `try_into()` of the values it found: tobj-4.0.5/src/lib.rs:783,
/// "called `Result::unwrap()` on an `Err` value: [0.5, 0.5]"). Found by the fuzzer
/// (fuzz/corpus/scene_to_atlas/regress-tobj-short-colour). The loader now reads MTL files
/// itself: a short `Kd` or `Ke` (which the solver uses) is an error naming the line; a short
/// `Ka` or `Ks` (which it does not use) is skipped like any value of theirs (issue 35).
#[test]
fn load_obj_short_mtl_colour_is_an_error() {
    let obj = "mtllib m.mtl\nusemtl lamp\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    for line in ["Kd 0.5 0.5", "Ke 1"] {
        let mtl = format!("newmtl lamp\nKe 1 1 1\n{line}\n");
        let result = std::panic::catch_unwind(|| load_text(obj, &mtl).1.map(|s| s.polygons.len()));
        let result =
            result.unwrap_or_else(|_| panic!("load_obj panicked on the MTL line `{line}`"));
        let e = result.expect_err("a short colour is an error");
        assert!(e.to_string().contains("m.mtl:3"), "{e}");
    }
    for line in ["Ka", "Ks 0 0"] {
        let mtl = format!("newmtl lamp\nKe 1 1 1\n{line}\n");
        let scene = load_text(obj, &mtl).1;
        assert!(scene.is_ok(), "`{line}` is skipped: {:?}", scene.err());
    }
}

/// The same panic through a gap in that check: `check_mtl` only sees an MTL that reads as UTF-8
/// (`read_to_string`; otherwise it warns and goes on), but tobj parses line by line and panics at
/// the short colour before it reaches the bytes that are not UTF-8. So `Kd 0.5 0.5` followed by a
/// line with a 0xFF byte still ends `radiosity solve` in a panic. Found by the fuzzer
/// (fuzz/corpus/scene_to_atlas/regress-tobj-short-colour-not-utf8).
#[test]
fn load_obj_short_mtl_colour_behind_invalid_utf8_regression() {
    let obj = "mtllib m.mtl\nusemtl lamp\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let mtl = b"newmtl lamp\nKe 1 1 1\nKd 0.5 0.5\n\xff\xfe\n";
    let result = std::panic::catch_unwind(|| load_text(obj, mtl).1.is_ok());
    assert!(result.is_ok(), "load_obj panicked");
}

/// A relative texture or normal index that reaches before the first `vt`/`vn` (`f 1/-5 ...` with
/// one `vt`) becomes a usize near 2^64 in tobj 4.0.5, and `add_vertex_multi_index` computes
/// `vt * 2 + 1` (`vn * 3 + 2`) before its bounds check (tobj-4.0.5/src/lib.rs:1055 and :1096):
/// with overflow checks on (debug builds: `cargo run`, `cargo test` without `--release`, the
/// fuzzer) that panics "attempt to multiply with overflow"; release builds wrap and get an
/// out-of-bounds error. So this passes under `--release` and fails in a debug build (or with
/// `--config 'profile.release.package.tobj.overflow-checks=true'`). Found by the fuzzer
/// (fuzz/corpus/scene_to_atlas/regress-tobj-*-index-overflow).
#[test]
fn load_obj_relative_index_before_the_first_regression() {
    for face in ["f 1/-5 2/1 3/1", "f 1//-9 2//1 3//1"] {
        let obj = format!(
            "mtllib m.mtl\nusemtl lamp\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n{face}\n"
        );
        let result = std::panic::catch_unwind(|| load_text(&obj, LAMP_MTL).1.is_ok());
        assert!(result.is_ok(), "load_obj panicked on `{face}`");
    }
}

/// `check_lines` (src/scene/obj.rs) accepts a negative face index when `-i <= count`; for
/// `f -9223372036854775808 1 2` that negation overflows: "attempt to negate with overflow" in a
/// debug build (release wraps, lets the index through, and tobj rejects it). Like the test above
/// it fails only with overflow checks on. Found by the fuzzer
/// (fuzz/corpus/scene_to_atlas/regress-face-index-i64-min, regress-found-face-index-i64-min-*).
#[test]

fn load_obj_most_negative_face_index_regression() {
    let obj = "mtllib m.mtl\nusemtl lamp\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf -9223372036854775808 1 2\n";
    let result = std::panic::catch_unwind(|| load_text(obj, LAMP_MTL).1.is_ok());
    assert_eq!(
        result.ok(),
        Some(false),
        "load_obj panicked (or accepted the face)"
    );
}

/// A patch target is a target: `size_for_count` bisects in [1/4, 4] x sqrt(area / target), and
/// when the answer lies outside that bracket it returns the bracket's top whatever the count.
/// A thin L (arms 100 long, 0.01 wide: area 2, rectangle 10,000) asked for 4,096 patches gets a
/// 1,132 x 1,132 lightmap (1.28 million texels, 312 x the target); a sliver triangle 1000 x 1e-4
/// (a trim strip) gets a patch size of 0.014 where 0.25 would do, i.e. a 71,555 x 1 lightmap,
/// and `try_new` refuses the scene ("would need a 71555x1 lightmap ... more than an atlas of
/// 16384x16384 can hold"), so `radiosity solve` with the default `--patches 4096` fails on a
/// valid scene. Bow-ties and strongly non-planar faces do the same. Found by the fuzzer
/// (fuzz/corpus/scene_to_atlas/edge-thin-l, edge-sliver, regress-bracket-*).
#[test]

fn patch_target_is_kept_for_thin_shapes_regression() {
    let thin_l = [
        (0.0, 0.0),
        (100.0, 0.0),
        (100.0, 0.01),
        (0.01, 0.01),
        (0.01, 100.0),
        (0.0, 100.0),
    ];
    let sliver = [(0.0, 0.0), (1000.0, 0.0), (500.0, 0.0001)];
    for shape in [&thin_l[..], &sliver[..]] {
        let v: Vec<Vec3> = shape.iter().map(|&(x, y)| Vec3::new(x, y, 0.0)).collect();
        let scene = scene_of(vec![Polygon::new(v, 0, "thin".into()).unwrap()]);
        let layout = PatchLayout::try_new(&scene, Resolution::Patches(4096))
            .unwrap_or_else(|e| panic!("{shape:?}: {e}"));
        let texels: u64 = layout
            .lightmaps
            .iter()
            .map(|l| l.w as u64 * l.h as u64)
            .sum();
        assert!(
            texels <= 4 * 4096,
            "{shape:?}: {texels} texels ({} patches) for a target of 4096",
            layout.patch_count()
        );
    }
}

/// A patch size far too small for the scene (`--patch-size 1e-4` on the Cornell box in
/// millimetres) used to allocate the owner map of a ~2.5e7 x 2.5e7 atlas ("memory allocation of
/// 1009774616008448 bytes failed", an abort), and 1e-9 wrapped `w + 2` and indexed out of bounds
/// (found by the fuzzer: regress-giant-atlas-patch-size, regress-u32-wrap-patch-size).
/// `try_new` now refuses both before allocating.
#[test]
fn tiny_patch_size_is_refused_before_allocating() {
    let scene = load_obj(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell/cornell.obj"),
    )
    .unwrap();
    for size in [1e-4f32, 1e-9, f32::MIN_POSITIVE] {
        let result = std::panic::catch_unwind(|| {
            PatchLayout::try_new(&scene, Resolution::PatchSize(size)).map(|l| l.atlas_width)
        });
        let result = result.unwrap_or_else(|_| panic!("try_new panicked at patch size {size}"));
        assert!(result.is_err(), "patch size {size}: {result:?}");
    }
}
