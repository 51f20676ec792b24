//! Solve the bundled Cornell box through the library and write `cornell.png`:
//! `cargo run --release --example solve_cornell [OUT.png]`.

use gpu_radiosity::display::output::write_png;
use gpu_radiosity::gl::{BackendChoice, GlContext};
use gpu_radiosity::pipeline::{self, Mode, SolverKind};

fn main() -> anyhow::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "cornell.png".into());
    let (scene, _) = pipeline::load_scene(None)?; // the built-in Cornell box
    let layout = pipeline::lay_out(&scene, None, None)?; // about 4,096 patches
    let ctx = GlContext::headless(BackendChoice::Auto)?; // EGL or OSMesa, no display needed
    let solution = pipeline::solve(
        &ctx,
        &scene,
        &layout,
        SolverKind::Gpu,
        Mode::Accurate.options(),
        0,
        |shot| eprint!("\rshot {} unshot {:.4}", shot.shot, shot.unshot_fraction),
    )?;
    eprintln!();
    let (atlas, _) = solution.display_atlas(&scene, &layout, false);
    let camera = scene.camera_or_default();
    let image = pipeline::render(&ctx, &scene, &layout, &atlas, &camera, (512, 512))?;
    write_png(out.as_ref(), &image, 1.0)?;
    eprintln!("{} shots, wrote {out}", solution.shots);
    Ok(())
}
