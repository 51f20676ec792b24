//! How full the GPU solver's atlas is, counted in the 4×4 blocks llvmpipe shades whole: the
//! reconstruction pass draws every block that holds a patch, and a texel of such a block costs
//! the same whether it is a patch or not (docs/perf-log.md, 2026-12-06, tenth session).
//!
//! `cargo run --release --example atlas_fill -- SCENE.obj [PATCHES]` (PATCHES as `--patches`;
//! default: `radiosity solve`'s budget for the scene). Prints the patches, the drawn blocks'
//! other texels (inside a lightmap rectangle but outside its polygon's outline, or between
//! rectangles) and the lightmaps that leave the most texels empty.

use gpu_radiosity::pipeline;
use std::path::Path;

/// Texels per side of the blocks llvmpipe shades at a time (`engine::cover::BLOCK`).
const BLOCK: usize = 4;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or_else(|| anyhow::anyhow!("usage: atlas_fill SCENE.obj [PATCHES]"))?;
    let patches: Option<u32> = args.next().map(|n| n.parse()).transpose()?;
    let (scene, _) = pipeline::load_scene(Some(Path::new(&path)))?;
    // The solver's own atlas: the caller's lightmaps packed edge to edge (`GpuSolver::new`).
    let layout = pipeline::lay_out(&scene, None, patches)?.without_gutters();
    let (w, h) = (layout.atlas_width as usize, layout.atlas_height as usize);
    let mut in_rectangle = vec![false; w * h];
    for l in &layout.lightmaps {
        for y in l.y as usize..(l.y + l.h) as usize {
            in_rectangle[y * w + l.x as usize..y * w + (l.x + l.w) as usize].fill(true);
        }
    }
    let wide = w.div_ceil(BLOCK);
    let block = |i: usize| (i / w / BLOCK) * wide + (i % w) / BLOCK;
    let mut held = vec![0u32; wide * h.div_ceil(BLOCK)];
    for (i, &owner) in layout.owner.iter().enumerate() {
        held[block(i)] += (owner != 0) as u32;
    }
    let drawn = held.iter().filter(|&&n| n > 0).count();
    let (mut patch, mut outside_outline, mut between) = (0usize, 0usize, 0usize);
    for (i, &owner) in layout.owner.iter().enumerate() {
        if held[block(i)] == 0 {
            continue;
        }
        match (owner != 0, in_rectangle[i]) {
            (true, _) => patch += 1,
            (false, true) => outside_outline += 1,
            (false, false) => between += 1,
        }
    }
    let texels = drawn * BLOCK * BLOCK;
    let share = |n: usize| 100.0 * n as f64 / texels as f64;
    println!(
        "{path}: {} polygons, atlas {w}x{h}, {drawn} blocks hold patches ({texels} texels)",
        scene.polygons.len()
    );
    println!(
        "  patches                          {patch:>9} ({:.1} %)",
        share(patch)
    );
    println!(
        "  in a rectangle, off the outline  {outside_outline:>9} ({:.1} %)",
        share(outside_outline)
    );
    println!(
        "  between rectangles               {between:>9} ({:.1} %)",
        share(between)
    );
    let mut emptiest: Vec<(u32, usize)> = (layout.lightmaps.iter().enumerate())
        .map(|(p, l)| (l.w * l.h - layout.patches_per_polygon[p], p))
        .collect();
    emptiest.sort_unstable_by(|a, b| b.cmp(a));
    println!("  lightmaps with the most empty texels (polygon: w x h, patches):");
    for &(empty, p) in emptiest.iter().take(8).filter(|e| e.0 > 0) {
        let l = &layout.lightmaps[p];
        let n = layout.patches_per_polygon[p];
        println!("    {p}: {} x {}, {n} patches, {empty} empty", l.w, l.h);
    }
    Ok(())
}
