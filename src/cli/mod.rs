//! The command line: one file per subcommand.

mod info;
mod scene;
mod solve;
mod validate;

use clap::{Parser, Subcommand};

pub use solve::{run_solve, SolveArgs};

#[derive(Parser, Debug)]
#[command(
    name = "radiosity",
    version,
    about = "Progressive refinement radiosity on the GPU (OpenGL 3.0, GLSL 1.30)"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Solve a scene and write image.png, image.exr, lightmap.exr and stats.json.
    Solve(SolveArgs),
    /// Generate one of the paper's two rooms (Table 1) as an OBJ + MTL pair and print its counts.
    Scene(scene::SceneArgs),
    /// List the OpenGL backends that work here, with their renderer and limits.
    Info(info::InfoArgs),
    /// Check the solver against closed forms, the furnace and a direct solve; print the table.
    Validate(validate::ValidateArgs),
}

pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Solve(args) => run_solve(&args).map(|_| ()),
        Command::Validate(args) => validate::run_validate(&args),
        Command::Scene(args) => scene::run_scene(&args),
        Command::Info(args) => info::run_info(&args),
    }
}
