//! The speed switches of `solver::Tuning` leave the answer as it is: each is turned off on its
//! own, on the Cornell box (default options: shooter cells, hemicube) and the simple room (the
//! bench's options), and the lightmaps compared with the tuned ones, bit for bit or within 1e-6
//! L1 where the switch says float rounding may differ. Also: the reconstruction pass draws the
//! receivers as squares of whole 4×4 blocks over an atlas without gutters, and what it computes
//! does not depend on where the lightmaps lie in the atlas.

mod common;

use common::*;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::solver::reconstruction::{Lightmaps, ReconstructionPass};
use gpu_radiosity::solver::{
    FormFactorKind, GpuSolver, ReceiverChoice, SolveOptions, Tuning, Walk,
};

#[test]
fn squares_drawn_as_points_or_triangles_give_the_same_lightmaps() {
    let off = |t: &mut Tuning| t.squares_as_points = false;
    on_both_rooms(off, |name, mut points, mut triangles| {
        assert_eq!(step_both(name, &mut points, &mut triangles, 40), 0.0);
        assert!(
            points.backend().reconstruction.drew_points(),
            "llvmpipe draws wide points"
        );
        assert!(!triangles.backend().reconstruction.drew_points());
    });
}

#[test]
fn atlases_come_back_in_the_callers_layout() {
    // The solver packs the lightmaps without gutters; what it hands out is in the layout it was
    // given: every patch texel carries its polygon's ID + 1, every other texel is zero.
    let scene = load("simple");
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(scene.patch_size.unwrap()));
    let dense = layout.without_gutters();
    assert!(dense.atlas_width * dense.atlas_height < layout.atlas_width * layout.atlas_height);
    assert_eq!(dense.patch_count(), layout.patch_count());
    let ctx = context();
    let mut solver = GpuSolver::new(
        &ctx,
        &scene,
        &layout,
        gpu_radiosity::solver::SolveOptions::paper_faithful(0.01),
    )
    .unwrap();
    solver.step().unwrap().unwrap();
    let atlas = solver.radiosity_atlas();
    assert_eq!(atlas.len(), layout.owner.len() * 4);
    for (texel, &owner) in atlas.chunks_exact(4).zip(&layout.owner) {
        assert_eq!(texel[3], owner as f32);
    }
}

#[test]
fn skipping_needless_clipping_changes_nothing_but_float_noise() {
    // Blocks whose receivers all have the whole shooter above their plane are drawn with the
    // shader variant that does not clip it: the same contour integral, so the same lightmaps up
    // to float rounding.
    // The variant needs the receivers' flags, so both solvers pick the receivers.
    let receivers = |t: &mut Tuning| t.receivers = ReceiverChoice::InFrontUnclipped;
    let off = |t: &mut Tuning| t.receivers = ReceiverChoice::InFront;
    on_both_rooms_from(receivers, off, |name, mut split, mut clipped| {
        let (mut cheap, mut full) = (0, 0);
        for _ in 0..40 {
            let a = split.step().unwrap().unwrap();
            let b = clipped.step().unwrap().unwrap();
            assert_eq!(a.shooter, b.shooter, "{name}");
            let (c, u) = split.backend().reconstruction.squares_drawn();
            full += c;
            cheap += u;
            assert_eq!(clipped.backend().reconstruction.squares_drawn().1, 0);
        }
        assert!(
            cheap > 0 && full > 0,
            "{name}: squares {full} clipped, {cheap} not"
        );
        let (a, b) = (split.radiosity_atlas(), clipped.radiosity_atlas());
        let diff: f64 = a.iter().zip(&b).map(|(x, y)| (x - y).abs() as f64).sum();
        let total: f64 = b.iter().map(|y| y.abs() as f64).sum();
        eprintln!(
            "{name}: {full} squares clipped, {cheap} not; L1 difference {:.2e}",
            diff / total
        );
        assert!(
            diff / total < 1e-6,
            "{name}: L1 difference {}",
            diff / total
        );
        // Clipping only where needed: float rounding on the Cornell box (its cut cells' squares;
        // measured 2.1e-8), nothing at all on the simple room (whole polygons).
        if name != "cornell" {
            assert_eq!(diff, 0.0, "{name}: L1 difference");
        }
    });
}

#[test]
fn drawing_only_the_receivers_gives_the_same_lightmaps() {
    // The polygons left out can receive nothing from the shooter; their texels keep the last
    // copy's values, which are the textures'.
    let on = |t: &mut Tuning| t.receivers = ReceiverChoice::InFront;
    on_both_rooms(on, |name, mut every, mut receivers| {
        let (mut all, mut fewer) = (0, 0);
        for _ in 0..40 {
            let d = step_both(name, &mut every, &mut receivers, 1);
            assert_eq!(d, 0.0, "{name}: L1 difference {d}");
            all += every.backend().reconstruction.texels_drawn();
            fewer += receivers.backend().reconstruction.texels_drawn();
        }
        eprintln!("{name}: texels drawn {all} (every polygon), {fewer} (receivers only)");
        assert!(fewer < all, "{name}: receivers_only left nothing out");
    });
}

#[test]
fn marking_after_some_shots_only_gives_the_same_lightmaps() {
    // The fast configuration on the simple room, where a shot of four polygons lights about half
    // the patches: the marking pass runs only after the shots that lit under
    // `Tuning::marking_below` of them. The same lightmaps, bit for bit, as marking before every
    // pass and as never marking.
    let scene = load("simple");
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(scene.patch_size.unwrap()));
    let ctx = context();
    let fast = gpu_radiosity::solver::SolveOptions::whole_polygons(0.01);
    let solver = |tweak: fn(&mut Tuning)| {
        let mut options = fast.clone();
        tweak(&mut options.tuning);
        GpuSolver::new(&ctx, &scene, &layout, options).unwrap()
    };
    let mut adaptive = solver(|_| {});
    let mut always = solver(|t| t.marking_below = 100);
    let mut never = solver(|t| {
        t.marking_pass = false;
        // Needs the marking pass (`Tuning::check`); bit for bit the same without.
        t.walk = Walk::ReceiversFound;
    });
    let steps = 60;
    let d = step_both("simple, always", &mut adaptive, &mut always, steps);
    assert_eq!(d, 0.0, "marking before every pass: L1 difference {d}");
    for _ in 0..steps {
        never.step().unwrap().unwrap();
    }
    assert_eq!(adaptive.radiosity_atlas(), never.radiosity_atlas());
    assert_eq!(adaptive.unshot_atlas(), never.unshot_atlas());
    let marked = |s: &GpuSolver<'_>| s.backend().reconstruction.marked_passes();
    eprintln!(
        "passes marked: {} adaptive, {} always, {} never",
        marked(&adaptive),
        marked(&always),
        marked(&never)
    );
    // Every pass (a step of several passes when large shots cut their cells).
    assert_eq!(marked(&always), always.passes());
    assert_eq!(marked(&never), 0);
    assert!(
        (1..steps).contains(&marked(&adaptive)),
        "the adaptive rule marked {} of {steps} passes",
        marked(&adaptive)
    );
}

#[test]
fn programs_unrolled_for_quadrilaterals_give_the_same_lightmaps() {
    // Quadrilateral shooters are drawn with programs compiled for four corners (`CORNERS`):
    // the same sums in the same order as the loop over a corner count read at run time, so
    // the same lightmaps, bit for bit (measured on both rooms).
    let off = |t: &mut Tuning| t.unroll_quads = false;
    on_both_rooms(off, |name, mut unrolled, mut looped| {
        for _ in 0..40 {
            let a = unrolled.step().unwrap().unwrap();
            let b = looped.step().unwrap().unwrap();
            assert_eq!(a.shooter, b.shooter, "{name}");
        }
        assert!(
            unrolled.backend().reconstruction.quad_passes > 0,
            "{name}: no quadrilateral shooter"
        );
        assert_eq!(looped.backend().reconstruction.quad_passes, 0);
        let (a, b) = (unrolled.radiosity_atlas(), looped.radiosity_atlas());
        assert!(a.iter().any(|&v| v > 0.0), "{name}");
        assert!(
            a == b,
            "{name}: the unrolled programs computed different radiance"
        );
        assert_eq!(unrolled.unshot_atlas(), looped.unshot_atlas(), "{name}");
    });
}

#[test]
fn programs_with_the_solves_choices_compiled_in_give_the_same_lightmaps() {
    // `compile_choices` turns the shader's branches on the form factor, the visibility kind and
    // the robust test into constants: the branch taken does the same arithmetic, so the same
    // lightmaps, bit for bit; for the rooms' choices and for the paper's (point factor,
    // hemispherical projection, nearest ID), which the tuned passes then compile in too.
    let off = |t: &mut Tuning| t.compile_choices = false;
    on_both_rooms(off, |name, mut compiled, mut read| {
        let d = step_both(name, &mut compiled, &mut read, 40);
        assert_eq!(
            d, 0.0,
            "{name}: the compiled-in choices changed the lightmaps"
        );
    });
    let scene = load("simple");
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(scene.patch_size.unwrap()));
    let ctx = context();
    let options = SolveOptions {
        tuning: Tuning::llvmpipe(),
        ..SolveOptions::paper()
    };
    let mut read = options.clone();
    off(&mut read.tuning);
    let mut a = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
    let mut b = GpuSolver::new(&ctx, &scene, &layout, read).unwrap();
    let d = step_both("simple, the paper's choices", &mut a, &mut b, 20);
    assert_eq!(
        d, 0.0,
        "the paper's choices compiled in changed the lightmaps"
    );
}

#[test]
fn programs_with_choices_compiled_in_refuse_other_choices() {
    // A pass set up for the hemicube must not quietly look the hemisphere up in its item buffer.
    let scene = load("simple");
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(scene.patch_size.unwrap()))
        .without_gutters();
    let ctx = context();
    let options = gpu_radiosity::solver::SolveOptions::paper_faithful(0.01);
    let solver = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
    let shooters = solver.shooters_of(solver.next_polygon().unwrap());
    let visibility = &solver.backend().visibility;
    let lightmaps =
        Lightmaps::new(&ctx, layout.atlas_width as i32, layout.atlas_height as i32).unwrap();
    let mut pass = ReconstructionPass::new(&ctx, &scene, &layout, &options).unwrap();
    let run = |pass: &mut ReconstructionPass, options: &SolveOptions| {
        pass.run(&ctx, visibility, &lightmaps, &shooters[..1], options)
    };
    run(&mut pass, &options).expect("the options it was set up with");
    let other = SolveOptions {
        form_factor: FormFactorKind::Point,
        ..options.clone()
    };
    let refused = run(&mut pass, &other).expect_err("another form factor");
    assert!(
        refused.to_string().contains("compiled for"),
        "unclear refusal: {refused}"
    );
    // Without the switch the programs read the choices from uniforms and serve any.
    let mut loose = options.clone();
    loose.tuning.compile_choices = false;
    let mut pass = ReconstructionPass::new(&ctx, &scene, &layout, &loose).unwrap();
    let other = SolveOptions {
        tuning: loose.tuning,
        ..other
    };
    run(&mut pass, &other).expect("uniforms serve any form factor");
}

#[test]
fn the_papers_passes_and_the_tuned_ones_give_the_same_lightmaps() {
    // With every switch of `Tuning::none` off, each reconstruction pass draws every patch and
    // tests visibility in the one shader, and each view of the visibility pass draws the whole
    // scene, as the paper does: the same answer as the tuned passes, up to float rounding (the
    // variant that does not clip sums the same terms in another order).
    on_both_rooms(
        |t| *t = Tuning::none(),
        |name, mut tuned, mut paper| {
            let d = step_both(name, &mut tuned, &mut paper, 20);
            assert!(d < 1e-6, "{name}: L1 difference {d}");
        },
    );
}

#[test]
fn the_gpu_profile_gives_the_llvmpipe_engines_lightmaps_but_for_edge_pixels() {
    // Forced on llvmpipe, `Tuning::gpu` draws every item buffer whole and shades every receiver:
    // against the llvmpipe engine (the default here), whose switches change only depth ties,
    // edge pixels (the walk) and float rounding (the guard band, plates), the answer moves as
    // little as with the walk alone (`writing_the_item_buffers_from_the_walk_...`).
    for (name, options) in [
        ("cornell", SolveOptions::default_with(1e-3)),
        ("simple", SolveOptions::paper_faithful(0.01)),
    ] {
        let scene = load(name);
        let resolution =
            (scene.patch_size).map_or(Resolution::Patches(4096), Resolution::PatchSize);
        let layout = PatchLayout::new(&scene, resolution);
        let ctx = context();
        let solver = |tuning| {
            let options = SolveOptions {
                tuning,
                ..options.clone()
            };
            GpuSolver::new(&ctx, &scene, &layout, options).unwrap()
        };
        let (mut engine, mut gpu) = (solver(Tuning::llvmpipe()), solver(Tuning::gpu()));
        if name == "cornell" {
            let d = step_both(name, &mut engine, &mut gpu, 40);
            assert!(d < 1e-5, "{name}: L1 difference {d}");
            assert!(!gpu.backend().reconstruction.drew_points());
            continue;
        }
        // The simple room's shots part within 40 steps, as with the walk alone.
        for _ in 0..40 {
            engine.step().unwrap().unwrap();
            gpu.step().unwrap().unwrap();
        }
        let (a, b) = (engine.unshot_fraction(), gpu.unshot_fraction());
        assert!(
            (a - b).abs() < 0.02 * a,
            "{name}: unshot {a} engine, {b} gpu"
        );
        // The GPU profile culls nothing and marks nothing.
        assert_eq!(gpu.backend().visibility.missed(), 0);
        assert_eq!(gpu.backend().reconstruction.marked_passes(), 0);
    }
}

#[test]
fn every_profile_solves_the_cornell_box_to_the_same_lightmaps() {
    // Whole default solves of the Cornell box (to its stopping rule) with each profile forced on
    // llvmpipe: the radiance atlases within PROFILE_TOLERANCE (relative L1) of the llvmpipe
    // engine's, which `auto` runs here.
    const PROFILE_TOLERANCE: f64 = 2e-3;
    let scene = load("cornell");
    let layout = PatchLayout::new(&scene, Resolution::Patches(4096));
    let ctx = context();
    let solve = |tuning| {
        let options = SolveOptions {
            tuning,
            ..SolveOptions::accurate()
        };
        let mut s = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
        s.solve(|_| {}).unwrap();
        (s.radiosity_atlas(), s.shots())
    };
    let (engine, shots) = solve(Tuning::llvmpipe());
    let total: f64 = engine.iter().map(|x| x.abs() as f64).sum();
    for (name, tuning) in [("gpu", Tuning::gpu()), ("paper", Tuning::none())] {
        let (other, other_shots) = solve(tuning);
        let diff: f64 = (engine.iter().zip(&other))
            .map(|(a, b)| (a - b).abs() as f64)
            .sum();
        eprintln!(
            "{name}: relative L1 {:.2e}, shots {other_shots} against {shots}",
            diff / total
        );
        assert!(
            diff / total < PROFILE_TOLERANCE,
            "{name}: relative L1 {}",
            diff / total
        );
    }
}

#[test]
fn the_guard_band_changes_nothing_but_float_noise() {
    // Without it each hemicube face is drawn in a viewport of its own size, and the triangles
    // crossing its edges are clipped: the same pixels, but for float rounding of the clipped
    // and the widened vertices.
    let off = |t: &mut Tuning| t.guard_band = 1;
    on_both_rooms(off, |name, mut guarded, mut clipped| {
        let d = step_both(name, &mut guarded, &mut clipped, 40);
        assert!(d < 1e-6, "{name}: L1 difference {d}");
    });
}

#[test]
fn drawing_every_polygon_in_every_view_gives_the_same_lightmaps() {
    // Culled by bounding spheres or not: what culling leaves out is clipped away whole.
    let off = |t: &mut Tuning| t.cull_views = false;
    on_both_rooms(off, |name, mut culled, mut whole| {
        assert_eq!(step_both(name, &mut culled, &mut whole, 40), 0.0, "{name}");
    });
}

#[test]
fn drawing_the_unclipped_triangles_first_changes_nothing_but_depth_ties() {
    let off = |t: &mut Tuning| t.split_unclipped = false;
    on_both_rooms(off, |name, mut split, mut one| {
        let d = step_both(name, &mut split, &mut one, 40);
        assert!(d < 1e-6, "{name}: L1 difference {d}");
    });
}

#[test]
fn whole_side_faces_give_the_same_lightmaps() {
    // The lower halves of the hemicube's side faces look below the shooter's horizon, where
    // the reconstruction pass never looks.
    let off = |t: &mut Tuning| t.half_side_faces = false;
    on_both_rooms(off, |name, mut half, mut whole| {
        assert_eq!(step_both(name, &mut half, &mut whole, 40), 0.0, "{name}");
    });
}

#[test]
fn plates_change_nothing_but_float_noise() {
    let off = |t: &mut Tuning| t.plates = false;
    on_both_rooms(off, |name, mut plates, mut polygons| {
        let merged = |s: &GpuSolver| {
            (0..s.ledger().patches().len())
                .filter(|&p| s.backend().visibility.shown_as(p) != p)
                .count()
        };
        if name == "simple" {
            assert!(merged(&plates) > 150, "{name}: {} merged", merged(&plates));
        }
        assert_eq!(merged(&polygons), 0, "{name}");
        let d = step_both(name, &mut plates, &mut polygons, 40);
        assert!(d < 1e-6, "{name}: L1 difference {d}");
    });
}

#[test]
fn leaving_out_the_far_faces_of_solids_changes_nothing_but_float_noise() {
    let off = |t: &mut Tuning| t.cull_solids = false;
    on_both_rooms(off, |name, mut culled, mut whole| {
        let d = step_both(name, &mut culled, &mut whole, 40);
        assert!(d < 1e-6, "{name}: L1 difference {d}");
    });
}

#[test]
fn leaving_out_hidden_polygons_gives_the_same_lightmaps() {
    // Polygons hidden behind nearer ones at every pixel centre they could cover
    // (`engine::occlusion`); tests/item_buffer.rs checks the item buffers pixel by pixel.
    let off = |t: &mut Tuning| t.walk = Walk::Off;
    on_both_rooms(off, |name, mut culled, mut whole| {
        let d = step_both(name, &mut culled, &mut whole, 40);
        println!("{name}: L1 difference {d}");
        assert_eq!(d, 0.0, "{name}");
    });
}

#[test]
fn leaving_out_polygons_between_pixel_centres_changes_no_pixel() {
    let off = |t: &mut Tuning| t.cull_between_samples = false;
    on_both_rooms(off, |name, mut culled, mut whole| {
        assert_eq!(step_both(name, &mut culled, &mut whole, 40), 0.0, "{name}");
    });
    // The fast configuration's small item buffers (16² to 128² per face), where the simple
    // room's door handles, picture frames and skirting fall between the centres: the same
    // pixels in every shooter's item buffer, step after step.
    let scene = load("simple");
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(scene.patch_size.unwrap()));
    let ctx = context();
    let mut fast = gpu_radiosity::solver::SolveOptions::whole_polygons(0.01);
    // Drawn: with the walk writing the item buffers no view is drawn to leave polygons out of.
    fast.tuning = fast.tuning.drawing();
    let fast_slots = fast.shooters_per_pass as usize;
    let mut whole_options = fast.clone();
    off(&mut whole_options.tuning);
    let mut culled = GpuSolver::new(&ctx, &scene, &layout, fast).unwrap();
    let mut whole = GpuSolver::new(&ctx, &scene, &layout, whole_options).unwrap();
    // To the stopping rule: ~110 steps of eight shots.
    for step in 0.. {
        let before = culled.shots();
        let Some(x) = culled.step().unwrap() else {
            assert!(whole.step().unwrap().is_none(), "step {step}");
            assert!(step > 100, "converged after {step} steps");
            break;
        };
        let y = whole.step().unwrap().unwrap();
        assert_eq!(x.shooter, y.shooter, "step {step}");
        // Whole polygons shoot, one item buffer each; the slots this step left idle (the first
        // steps, when the lights alone have power) hold nothing of it.
        let drawn = (culled.shots() - before) as usize;
        assert!(
            (1..=fast_slots).contains(&drawn),
            "step {step}: {drawn} shots"
        );
        for slot in 0..drawn {
            let ids = |s: &GpuSolver| s.backend().visibility.read_slot_ids(slot);
            assert!(
                ids(&culled) == ids(&whole),
                "step {step}: item buffer {slot} differs"
            );
        }
    }
    assert_eq!(culled.radiosity_atlas(), whole.radiosity_atlas());
    let missed = culled.backend().visibility.missed();
    assert!(missed > 1000, "{missed} polygon views left out");
    assert_eq!(whole.backend().visibility.missed(), 0);
}

#[test]
fn writing_the_item_buffers_from_the_walk_changes_nothing_but_edge_pixels() {
    // The walk records the nearest polygon at each pixel centre; the GPU draws the views. The
    // pixels that differ lie on edges (tests/item_buffer.rs counts them), and move the answer
    // no more than the other depth-tie switches.
    let on = |t: &mut Tuning| t.walk = Walk::ItemBuffersWritten;
    on_both_rooms(on, |name, mut drawn, mut walked| {
        if name == "cornell" {
            let d = step_both(name, &mut drawn, &mut walked, 40);
            println!("{name}: L1 difference {d}");
            assert!(d < 1e-5, "{name}: L1 difference {d}");
            return;
        }
        // The simple room's shots part within 40 steps (edge pixels tip the order of nearly
        // equal shooters); what they leave unshot stays alike.
        for _ in 0..40 {
            drawn.step().unwrap().unwrap();
            walked.step().unwrap().unwrap();
        }
        let (a, b) = (drawn.unshot_fraction(), walked.unshot_fraction());
        println!("{name}: unshot {a} drawn, {b} walked");
        assert!(
            (a - b).abs() < 0.02 * a,
            "{name}: unshot {a} drawn, {b} walked"
        );
    });
}

#[test]
fn drawing_only_what_the_walk_reaches_gives_the_same_lightmaps() {
    // With the walk writing the item buffers, each pass draws only the blocks its shooters may
    // reach (`engine::seen_receivers`), and with several shooters a pass marks them shooter
    // by shooter and shades the blocks only one reaches with that one alone: bit for bit the
    // same lightmaps (tests/seen_receivers.rs checks the reach patch by patch).
    // Few-shooter programs need the receivers found (`Walk`): off with them.
    let off = |t: &mut Tuning| t.walk = Walk::ItemBuffersWritten;
    on_both_rooms_from(walk_every_side, off, |name, mut reached, mut every| {
        let (mut fewer, mut all) = (0, 0);
        for _ in 0..40 {
            let d = step_both(name, &mut reached, &mut every, 1);
            assert_eq!(d, 0.0, "{name}: L1 difference {d}");
            fewer += reached.backend().reconstruction.texels_drawn();
            all += every.backend().reconstruction.texels_drawn();
        }
        eprintln!("{name}: texels drawn {fewer} (reached), {all} (every patch)");
        assert!(fewer < all, "{name}: nothing left out");
    });
    // Lost Empire, where it pays.
    on_lost_empire(off, |mut reached, mut every| {
        let (mut fewer, mut all) = (0, 0);
        for _ in 0..60 {
            assert_eq!(step_both("Lost Empire", &mut reached, &mut every, 1), 0.0);
            fewer += reached.backend().reconstruction.texels_drawn();
            all += every.backend().reconstruction.texels_drawn();
        }
        eprintln!("Lost Empire: texels drawn {fewer} (reached), {all} (every patch)");
        assert!(fewer * 2 < all, "reached {fewer} of {all} texels");
    });
}

#[test]
fn shading_shared_blocks_with_programs_for_just_their_shooters_gives_the_same_lightmaps() {
    // With the walk's reach, the blocks that two to four shooters of a pass alone may reach are
    // shaded by a program for just those shooters (`Tuning::few_shooter_programs`): every other
    // shooter adds +0.0 there, so the sums are the same bit for bit.
    let off = |t: &mut Tuning| t.walk = Walk::ReceiversFound;
    let mut few_blocks = 0;
    on_both_rooms_from(walk_every_side, off, |name, mut few, mut all| {
        for _ in 0..40 {
            assert_eq!(step_both(name, &mut few, &mut all, 1), 0.0, "{name}");
        }
        let blocks = few.backend().reconstruction.few_shooter_blocks();
        assert_eq!(
            all.backend().reconstruction.few_shooter_blocks(),
            0,
            "{name}"
        );
        eprintln!("{name}: {blocks} blocks shaded by few-shooter programs");
        few_blocks += blocks;
    });
    assert!(few_blocks > 0, "no block of either room was");
    // Lost Empire, where it pays.
    on_lost_empire(off, |mut few, mut all| {
        for _ in 0..60 {
            assert_eq!(step_both("Lost Empire", &mut few, &mut all, 1), 0.0);
        }
        let blocks = few.backend().reconstruction.few_shooter_blocks();
        eprintln!("Lost Empire: {blocks} blocks shaded by few-shooter programs");
        assert!(
            blocks > 1000,
            "{blocks} blocks shaded by few-shooter programs"
        );
    });
}

#[test]
fn flushing_after_the_visibility_pass_changes_nothing() {
    let off = |t: &mut Tuning| t.flush_visibility = false;
    on_both_rooms(off, |name, mut flushed, mut queued| {
        assert_eq!(
            step_both(name, &mut flushed, &mut queued, 40),
            0.0,
            "{name}"
        );
    });
}

#[test]
fn float_depth_or_24_bit_depth_give_the_same_lightmaps() {
    let off = |t: &mut Tuning| t.float_depth = false;
    on_both_rooms(off, |name, mut float, mut fixed| {
        let d = step_both(name, &mut float, &mut fixed, 40);
        assert!(d < 1e-6, "{name}: L1 difference {d}");
    });
}

/// The llvmpipe engine with the walk writing every item buffer, at any side, with the reach it
/// finds and the few-shooter programs (`on_both_rooms_from` starts from the views drawn).
fn walk_every_side(t: &mut Tuning) {
    *t = Tuning {
        walk_up_to: 0,
        ..*t
    };
    t.walk = Walk::FewShooterPrograms;
}

/// Step both solvers `shots` times (they must pick the same shooters) and return the larger
/// relative L1 difference of their radiance and unshot atlases: 0 when bit for bit the same.
fn step_both(name: &str, a: &mut GpuSolver<'_>, b: &mut GpuSolver<'_>, shots: u32) -> f64 {
    for _ in 0..shots {
        let x = a.step().unwrap().unwrap();
        let y = b.step().unwrap().unwrap();
        assert_eq!(x.shooter, y.shooter, "{name}");
    }
    let mut worst: f64 = 0.0;
    for (x, y) in [
        (a.radiosity_atlas(), b.radiosity_atlas()),
        (a.unshot_atlas(), b.unshot_atlas()),
    ] {
        let diff: f64 = x.iter().zip(&y).map(|(p, q)| (p - q).abs() as f64).sum();
        let total: f64 = y.iter().map(|q| q.abs() as f64).sum();
        assert!(total > 0.0, "{name}");
        if x != y {
            worst = worst.max(diff / total).max(f64::MIN_POSITIVE);
        }
    }
    eprintln!("{name}: relative L1 difference {worst:.2e}");
    worst
}

/// Run `check` on two solvers made alike but for `tweak` applied to the second one's tuning,
/// for the Cornell box with its default options (shooter cells) and for the simple room with the
/// bench's.
fn on_both_rooms(
    tweak: impl Fn(&mut Tuning),
    check: impl FnMut(&str, GpuSolver<'_>, GpuSolver<'_>),
) {
    on_both_rooms_from(|_| {}, tweak, check)
}

/// Run `check` on two solvers of Lost Empire with the defaults (eight shooters a pass), the walk
/// writing every item buffer (at any side: `Tuning::walk_up_to` 0), `tweak` applied to the
/// second one's tuning.
fn on_lost_empire(tweak: fn(&mut Tuning), check: impl FnOnce(GpuSolver<'_>, GpuSolver<'_>)) {
    let Some(scene) = third_party_lit("lost-empire/lost_empire.obj", "Torch", [5.0, 4.0, 2.0])
    else {
        return;
    };
    let layout = layout(&scene, 1.1782);
    let ctx = context();
    let solver = |tweak: fn(&mut Tuning)| {
        let mut options = SolveOptions::accurate();
        options.tuning.walk_up_to = 0;
        tweak(&mut options.tuning);
        GpuSolver::new(&ctx, &scene, &layout, options).unwrap()
    };
    check(solver(|_| {}), solver(tweak));
}

/// [`on_both_rooms`] with `base` applied to both solvers' tuning first.
fn on_both_rooms_from(
    base: impl Fn(&mut Tuning),
    tweak: impl Fn(&mut Tuning),
    mut check: impl FnMut(&str, GpuSolver<'_>, GpuSolver<'_>),
) {
    for (name, options) in [
        // The default past its own stopping rule: its 40 steps must all shoot.
        (
            "cornell",
            gpu_radiosity::solver::SolveOptions::default_with(1e-3),
        ),
        (
            "simple",
            gpu_radiosity::solver::SolveOptions::paper_faithful(0.01),
        ),
    ] {
        let scene = load(name);
        let resolution = scene
            .patch_size
            .map_or(Resolution::Patches(4096), Resolution::PatchSize);
        let layout = PatchLayout::new(&scene, resolution);
        let ctx = context();
        let mut options = options;
        // The switches below change the views the GPU draws; with the walk writing the item
        // buffers (`writing_the_item_buffers_from_the_walk_...` compares the two) there would be
        // nothing drawn to change.
        options.tuning = options.tuning.drawing();
        base(&mut options.tuning);
        let mut tweaked = options.clone();
        tweak(&mut tweaked.tuning);
        let a = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
        let b = GpuSolver::new(&ctx, &scene, &layout, tweaked).unwrap();
        check(name, a, b);
    }
}
