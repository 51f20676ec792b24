//! `radiosity`: parse the command line, run, print one clear message on failure.

use clap::Parser;

fn main() {
    let cli = gpu_radiosity::cli::Cli::parse();
    if let Err(e) = gpu_radiosity::cli::run(cli) {
        eprintln!("error: {e:#}");
        // 2 for usage errors, as clap exits for its own; 1 for everything else.
        let usage = e.downcast_ref::<gpu_radiosity::cli::UsageError>().is_some();
        std::process::exit(if usage { 2 } else { 1 });
    }
}
