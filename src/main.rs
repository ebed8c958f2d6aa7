//! The `restir-pt` command-line application: parsing and dispatch here, the commands, their
//! options, sweeps and charts in `app/`. It uses only the library's public API.

// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod app;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "restir-pt",
    version,
    about = "A Vulkan compute ReSTIR path tracer with explicit shift mappings"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

// Negative numbers parse as values everywhere, so that `--frames -1` is refused as an invalid
// value of --frames rather than as an unknown argument.
#[derive(Subcommand)]
enum Command {
    /// Render a glTF scene (default: the built-in scenes/cornell.gltf) to EXR and PNG with ReSTIR
    /// PT (default: frames of a still camera averaged for 8 s of GPU time; --frames N for exact
    /// frame counts) or the path tracer.
    #[command(allow_negative_numbers = true)]
    Render(app::RenderArgs),
    /// Print a scene's triangles, emitters, lights, materials, bounds and cameras; with
    /// --kernels, the SPIR-V size and compile time of each kernel the scene would use.
    #[command(allow_negative_numbers = true)]
    Info(app::InfoArgs),
    /// Measure path-tracer throughput (M paths/s) on a scene after a warm-up; reports the median.
    #[command(allow_negative_numbers = true)]
    Bench(app::BenchArgs),
    /// Path-trace a converged reference: mean EXR (--out NAME.exr) and variance EXR
    /// (NAME.variance.exr).
    #[command(allow_negative_numbers = true)]
    Reference(app::ReferenceArgs),
    /// Add up reference shards (`reference --shard I/N`) into the mean EXR (--out NAME.exr) and
    /// variance EXR (NAME.variance.exr): the images one `reference` process of the same seed and
    /// spp writes, up to the order of floating-point sums.
    #[command(allow_negative_numbers = true)]
    Merge(app::MergeArgs),
    /// Per-pass GPU times of ReSTIR PT frames: CSV, Chrome trace (Perfetto) and a stacked-bar SVG.
    #[command(allow_negative_numbers = true)]
    Profile(app::ProfileArgs),
    /// Error against GPU time per frame for each method at equal time budgets, against a
    /// reference: results.csv, log-log charts (SVG, PNG) and an equal-time image strip.
    #[command(allow_negative_numbers = true)]
    Compare(app::CompareArgs),
    /// Every scene and method over F frames, static and moving camera: non-finite pixels (must
    /// be 0), energy and relMSE per frame against references, flicker and failed-shift rate.
    #[command(allow_negative_numbers = true)]
    Stability(app::StabilityArgs),
}

fn run(command: Option<Command>) -> anyhow::Result<()> {
    match command {
        // No command renders the default scene with the default settings.
        None => app::render(app::RenderArgs::parse_defaults()?),
        Some(Command::Render(args)) => app::render(args),
        Some(Command::Info(args)) => app::info(args),
        Some(Command::Bench(args)) => app::bench(args),
        Some(Command::Reference(args)) => app::reference(args),
        Some(Command::Merge(args)) => app::merge(args),
        Some(Command::Profile(args)) => app::profile(args),
        Some(Command::Compare(args)) => app::compare(args).map(drop),
        Some(Command::Stability(args)) => app::stability(args).map(drop),
    }
}

fn main() -> ExitCode {
    // A closed pipe (`restir-pt info | head -1`) ends the process quietly, as it does other
    // command-line tools, instead of making println! panic on EPIPE.
    // SAFETY: called before any thread exists; SIG_DFL is a valid disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    match run(Cli::parse().command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Our errors are one line, whatever their chain of causes; clap's keep its style.
            eprintln!("error: {}", format!("{e:#}").replace('\n', " "));
            ExitCode::FAILURE
        }
    }
}
