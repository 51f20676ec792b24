//! `radiosity`: parse the command line, run, print one clear message on failure.

use clap::Parser;

fn main() {
    let cli = gpu_radiosity::cli::Cli::parse();
    if let Err(e) = gpu_radiosity::cli::run(cli) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
