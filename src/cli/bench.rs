//! `restir-pt bench`: path-tracer throughput after a warm-up, median of several runs.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use anyhow::{Context as _, Result};
use serde::Serialize;

use super::{finish_device, load_with_warnings, open_device, scene_path, DeviceArgs};
use crate::metrics::median;
use crate::render::{PathTracer, RenderSettings};

pub struct BenchArgs {
    pub scene: Option<PathBuf>,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub runs: u32,
    pub russian_roulette: bool,
    pub report: Option<PathBuf>,
    pub device: DeviceArgs,
}

#[derive(Serialize)]
struct BenchReport {
    device: String,
    scene: String,
    width: u32,
    height: u32,
    spp: u32,
    max_depth: u32,
    russian_roulette: bool,
    runs: u32,
    median_paths_per_second: f64,
    min_paths_per_second: f64,
    max_paths_per_second: f64,
    median_gpu_ms: f64,
}

pub fn bench(args: BenchArgs) -> Result<()> {
    let path = scene_path(args.scene.as_deref());
    let scene = load_with_warnings(&path)?;
    let settings = RenderSettings {
        width: args.width,
        height: args.height,
        spp: args.spp,
        max_depth: args.max_depth,
        russian_roulette: args.russian_roulette,
        ..Default::default()
    };
    settings.validate(&scene)?;
    let runs = args.runs.max(1);
    let ctx = open_device(&args.device)?;
    let never = AtomicBool::new(false);
    let mut rates = Vec::new();
    let mut gpu_ms = Vec::new();
    // Run 0 warms up: llvmpipe compiles the pipeline at its first dispatch.
    let mut tracer = PathTracer::new(&ctx, &scene, &settings)?;
    for run in 0..=runs {
        tracer.restart(
            &scene,
            &RenderSettings {
                seed: run,
                ..settings.clone()
            },
        )?;
        let stats = tracer.render(&|_| {}, &never)?;
        if run > 0 {
            let rate = stats.paths_per_second(settings.pixel_count());
            eprintln!("run {run}: {:.1} ms GPU, {:.3} M paths/s", stats.gpu_ms, rate * 1e-6);
            rates.push(rate);
            gpu_ms.push(stats.gpu_ms);
        }
    }
    drop(tracer);
    finish_device(&ctx)?;
    let report = BenchReport {
        device: ctx.info.name.clone(),
        scene: path.display().to_string(),
        width: settings.width,
        height: settings.height,
        spp: settings.spp,
        max_depth: settings.max_depth,
        russian_roulette: settings.russian_roulette,
        runs,
        median_paths_per_second: median(&rates),
        min_paths_per_second: rates.iter().copied().fold(f64::INFINITY, f64::min),
        max_paths_per_second: rates.iter().copied().fold(0.0, f64::max),
        median_gpu_ms: median(&gpu_ms),
    };
    println!(
        "{} | {} {}x{} | {} spp | depth {} | median of {} runs: {:.3} M paths/s (min {:.3}, max {:.3})",
        report.device,
        report.scene,
        report.width,
        report.height,
        report.spp,
        report.max_depth,
        runs,
        report.median_paths_per_second * 1e-6,
        report.min_paths_per_second * 1e-6,
        report.max_paths_per_second * 1e-6
    );
    if let Some(r) = &args.report {
        std::fs::write(r, serde_json::to_string_pretty(&report)?).with_context(|| format!("{}: cannot write the report", r.display()))?;
    }
    Ok(())
}
