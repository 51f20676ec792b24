//! `roomgen simple|complex [--out FILE.obj]`: write one of the paper's two rooms as FILE.obj
//! and FILE.mtl, then load it back as the solver would and print its counts.

use anyhow::{bail, Context, Result};
use clap::Parser;
use gpu_radiosity::display::output::{write_atomic, Payload};
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::load_obj;
use roomgen::{generate, Room};
use std::path::{Path, PathBuf};

#[derive(Parser, Debug)]
#[command(
    name = "roomgen",
    about = "Generate one of the paper's two rooms (Table 1) as an OBJ + MTL pair and print its counts"
)]
struct Args {
    /// Which room: simple (1,602 faces, 14,445 patches) or complex (8,549 faces, 86,077
    /// patches), as in the paper's Table 1.
    #[arg(value_enum)]
    room: RoomArg,
    /// Output OBJ file; the MTL file goes next to it with the same stem. Default:
    /// scenes/ROOM/ROOM.obj.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum RoomArg {
    Simple,
    Complex,
}

impl From<RoomArg> for Room {
    fn from(r: RoomArg) -> Room {
        match r {
            RoomArg::Simple => Room::Simple,
            RoomArg::Complex => Room::Complex,
        }
    }
}

fn main() {
    if let Err(e) = run(&Args::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(args: &Args) -> Result<()> {
    let room = Room::from(args.room);
    let obj_path = args.out.clone().unwrap_or_else(|| {
        Path::new("scenes")
            .join(room.name())
            .join(format!("{}.obj", room.name()))
    });
    if obj_path.extension().and_then(|e| e.to_str()) != Some("obj") {
        bail!(
            "--out {} must name an .obj file (the .mtl file is written next to it)",
            obj_path.display()
        );
    }
    let mtl_path = obj_path.with_extension("mtl");
    let mtl_name = mtl_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .context("the output file has no name")?;
    if let Some(dir) = obj_path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the output directory {}", dir.display()))?;
    }

    let generated = generate(room, &mtl_name);
    for (path, text) in [(&mtl_path, &generated.mtl), (&obj_path, &generated.obj)] {
        write_atomic(path, Payload::Text(text.to_string()))?;
    }

    // Count what a solve would load, from the files just written.
    let scene = load_obj(&obj_path)?;
    let size = scene
        .patch_size
        .context("the generated scene has no patch size")?;
    let patches = PatchLayout::new(&scene, Resolution::PatchSize(size)).patch_count();
    println!(
        "wrote {} and {}: {} faces, {} vertices, {} lights, {} patches (patch size {size} m)",
        obj_path.display(),
        mtl_path.display(),
        scene.polygons.len(),
        scene.vertex_count,
        scene.light_count(),
        patches
    );
    println!("counts made exact by: {}", generated.tuning);
    Ok(())
}
