//! `hikari`: the command-line renderer.

mod bench_cmd;
mod merge_cmd;
mod passes;
mod plot_cmd;
mod progress_bar;
mod render_cmd;
mod view;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "hikari",
    version,
    about = "Global illumination by photon mapping: caustics, indirect light and light in fog"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an image.
    Render(render_cmd::RenderArgs),
    /// Look around a scene in a window (the GPU renderer, live).
    #[command(after_help = "Controls: left drag orbits; middle or shift + left drag pans; the wheel zooms; \
right drag turns in place and W/A/S/D/Q/E fly (the wheel sets the speed while the right button is held); \
Home resets the camera; C prints it as a [camera] table; T prints per-pass GPU times; Space pauses \
the scene's animations; F12 writes hikari-view-N.png and .exr; F1 hides the panel; Escape quits.\n\n\
Photons are traced in the background for the scene as it stands now (its animations, the panel's edits \
of lights and named objects); a frame never waits for them. While nothing moves, the window shows the \
running mean of fresh photon sets as progressive passes (shrinking radii, docs/progressive.md), so it \
converges as you look. Saving the scene file reloads it.")]
    View(view::ViewArgs),
    /// List the built-in scenes.
    Scenes,
    /// Measure the GPU renderer: the seed's chapter-6 table for surfaces.
    Bench(bench_cmd::BenchArgs),
    /// Draw error against time (what `render --reference` prints) as a chart.
    Plot(plot_cmd::PlotArgs),
    /// Add up the parts of a render split by `render --shard K/M` into its image.
    Merge(merge_cmd::MergeArgs),
}

fn main() -> ExitCode {
    // SAFETY: no other thread has started yet.
    unsafe { hikari_gpu::context::quiet_headless_device_select() };
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render_cmd::run(&args),
        Command::Bench(args) => bench_cmd::run(&args),
        Command::Plot(args) => plot_cmd::run(&args),
        Command::Merge(args) => merge_cmd::run(&args),
        Command::View(args) => view::run(args),
        Command::Scenes => {
            for name in hikari_core::scene::builtin::NAMES {
                let default = if *name == hikari_core::scene::builtin::DEFAULT { "  (default)" } else { "" };
                println!("{name}{default}");
            }
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            // Bad input (a flag or the scene file) exits with 2, as clap's
            // own parse errors do; failures while running exit with 1.
            if e.downcast_ref::<render_cmd::UsageError>().is_some() { ExitCode::from(2) } else { ExitCode::FAILURE }
        }
    }
}
