//! `restir-pt profile`: per-pass GPU times of ReSTIR PT frames as CSV, as a Chrome trace
//! (opens in Perfetto or chrome://tracing) and as a stacked-bar SVG, with the median and p95,
//! each also in path-tracer samples per pixel of the same scene and size, measured in the same run.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{bail, Context as _, Result};
use clap::Args;

use super::args::{DeviceArgs, PathArgs, RestirArgs, SceneArgs, SizeArgs};
use super::compare::{Cost, Run};
use super::method_spec::{MethodRenderer, MethodSpec};
use super::render_output::{compile_progress, print_compile_summary};
use super::{finish_device, load_with_options, open_device};
use restir_pt::metrics::quantile;
use restir_pt::render::{PassTimes, RenderSettings, Restir, RestirSettings, SceneGpu, SceneInfo, PASS_NAMES};
use restir_pt::scene::camera_on_path;

/// `restir-pt profile`.
#[derive(Args, Debug, Clone)]
pub struct ProfileArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Frames to time (a static camera unless --camera-path); kernels are compiled before them.
    #[arg(long, default_value_t = 16)]
    pub frames: u32,
    #[command(flatten)]
    pub size: SizeArgs,
    #[command(flatten)]
    pub path: PathArgs,
    /// Move the camera along the scene's camera path from --camera instead of accumulating
    /// frames of an unmoved one.
    #[arg(long)]
    pub camera_path: bool,
    #[command(flatten)]
    pub restir: RestirArgs,
    /// Folder for passes.csv, trace.json and passes.svg.
    #[arg(long, default_value = "out/profile")]
    pub out_dir: PathBuf,
    #[command(flatten)]
    pub device: DeviceArgs,
}

/// Colours of the timers' bars, taken in turn (seaborn's "deep" palette), so a timer added to
/// the pass table gets one.
const PASS_COLOURS: [&str; 8] = [
    "#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#937860", "#da8bc3", "#8c8c8c",
];

fn pass_colour(pass: usize) -> &'static str {
    PASS_COLOURS[pass % PASS_COLOURS.len()]
}

/// A stacked bar per frame, one colour per pass.
fn stacked_bar_svg(times: &[PassTimes], title: &str) -> String {
    let (w, h, left, bottom, top) = (720.0, 360.0, 60.0, 40.0, 40.0);
    let max = times.iter().map(|t| t.iter().sum::<f64>()).fold(0.0, f64::max).max(1e-9);
    let bar = (w - left - 20.0) / times.len() as f64;
    let scale = (h - bottom - top) / max;
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"{left}\" y=\"20\">{title}</text>\n"
    );
    for (f, t) in times.iter().enumerate() {
        let mut y = h - bottom;
        for (p, ms) in t.iter().enumerate() {
            let height = ms * scale;
            y -= height;
            let x = left + f as f64 * bar;
            let _ = writeln!(
                svg,
                "<rect x=\"{x:.1}\" y=\"{y:.1}\" width=\"{:.1}\" height=\"{height:.1}\" fill=\"{}\"><title>frame {f} {}: {ms:.2} ms</title></rect>",
                (bar * 0.8).max(1.0),
                pass_colour(p),
                PASS_NAMES[p]
            );
        }
    }
    let _ = writeln!(
        svg,
        "<line x1=\"{left}\" y1=\"{0}\" x2=\"{1}\" y2=\"{0}\" stroke=\"black\"/><text x=\"{left}\" y=\"{2}\">frames 0..{3}</text>",
        h - bottom,
        w - 20.0,
        h - 12.0,
        times.len()
    );
    let _ = writeln!(svg, "<text x=\"4\" y=\"{}\">{max:.1} ms</text>", top + 4.0);
    for (p, name) in PASS_NAMES.iter().enumerate() {
        let x = w - 360.0 + p as f64 * 85.0;
        let _ = writeln!(
            svg,
            "<rect x=\"{x}\" y=\"8\" width=\"12\" height=\"12\" fill=\"{}\"/><text x=\"{}\" y=\"19\">{name}</text>",
            pass_colour(p),
            x + 16.0
        );
    }
    svg.push_str("</svg>\n");
    svg
}

/// Chrome trace events: frames one after another, passes one after another within a frame.
fn chrome_trace(times: &[PassTimes]) -> serde_json::Value {
    let mut events = vec![];
    let mut clock_us = 0.0;
    for (f, t) in times.iter().enumerate() {
        for (p, ms) in t.iter().enumerate() {
            events.push(serde_json::json!({
                "name": PASS_NAMES[p], "cat": "gpu", "ph": "X", "pid": 1, "tid": 1,
                "ts": clock_us, "dur": ms * 1e3, "args": { "frame": f }
            }));
            clock_us += ms * 1e3;
        }
    }
    serde_json::json!({ "traceEvents": events, "displayTimeUnit": "ms" })
}

fn write(path: &Path, contents: &str) -> Result<()> {
    std::fs::write(path, contents).with_context(|| format!("{}: cannot write", path.display()))
}

pub fn profile(args: ProfileArgs) -> Result<()> {
    if args.frames == 0 {
        bail!("--frames must be at least 1");
    }
    let path = args.scene.path()?;
    let scene = load_with_options(&path, &args.scene.load_options(None))?;
    let settings = RenderSettings {
        width: args.size.width,
        height: args.size.height,
        max_depth: args.path.max_depth,
        camera: args.path.camera,
        seed: args.path.seed,
        russian_roulette: args.path.russian_roulette.on(),
        ..Default::default()
    };
    settings.validate(&SceneInfo::of(&scene))?;
    let restir = args.restir.settings();
    restir.validate(settings.max_depth)?;
    std::fs::create_dir_all(&args.out_dir).with_context(|| format!("{}: cannot create the output folder", args.out_dir.display()))?;
    let ctx = open_device(&args.device)?;
    let gpu_scene = SceneGpu::upload(&ctx, &scene)?;
    let times = pass_times(&gpu_scene, &settings, &restir, &args)?;
    let pt_ms = path_tracer_ms_per_sample(&gpu_scene, &settings, args.camera_path)?;
    drop(gpu_scene);
    finish_device(&ctx)?;
    let motion = if args.camera_path { "moving camera" } else { "static camera" };
    let title = format!(
        "{} {} {}x{}, {motion}, on {}",
        path.display(),
        restir.label(),
        settings.width,
        settings.height,
        ctx.info.name
    );
    write_outputs(&args, &times, pt_ms, &title)
}

/// The path tracer's GPU ms per sample per pixel of the same scene, size and camera (path),
/// measured as `compare` calibrates it: the slope between 1- and 8-spp frames.
fn path_tracer_ms_per_sample(scene: &Arc<SceneGpu>, settings: &RenderSettings, camera_path: bool) -> Result<f64> {
    let settings = RenderSettings {
        spp: 1,
        ..settings.clone()
    };
    let run = Run::new(scene.info().cameras.len(), &settings, camera_path, None);
    let mut renderer = MethodRenderer::new(scene, &settings, &MethodSpec::PathTracing)?;
    match run.calibrate(&mut renderer)? {
        Cost::Affine { per_sample, .. } => Ok(per_sample),
        Cost::PerReservoirs(_) => bail!("the path tracer calibrated as ReSTIR PT"),
    }
}

/// Every frame's GPU ms per pass.
fn pass_times(scene: &Arc<SceneGpu>, settings: &RenderSettings, restir: &RestirSettings, args: &ProfileArgs) -> Result<Vec<PassTimes>> {
    let ctx = scene.ctx();
    if !ctx.info.timestamps_supported {
        bail!("{}: the device has no compute timestamps to profile with", ctx.info.name);
    }
    let spinner = compile_progress();
    let mut renderer = Restir::with_progress(scene, settings, restir, &|name| spinner.set_message(name.to_string()))?;
    spinner.finish_and_clear();
    print_compile_summary(
        &renderer.compile_reports(),
        renderer.compile_ms(),
        renderer.compile_cpu_ms(),
        renderer.twin_warmed_kernels(),
    );
    let mut times = vec![];
    for f in 0..args.frames {
        let stats = if args.camera_path {
            renderer.frame(camera_on_path(args.path.camera, f, scene.info().cameras.len()), false)?
        } else {
            renderer.frame(args.path.camera, true)?
        };
        let Some(ms) = stats.pass_ms else {
            bail!("{}: a frame came back without pass times", ctx.info.name);
        };
        times.push(ms);
    }
    Ok(times)
}

/// passes.csv, trace.json, passes.svg and the median/p95 table, each time also in path-tracer
/// samples per pixel (`pt_ms` GPU ms each).
fn write_outputs(args: &ProfileArgs, times: &[PassTimes], pt_ms: f64, title: &str) -> Result<()> {
    let mut csv = String::from("frame,pass,gpu_ms,pt_samples\n");
    for (f, t) in times.iter().enumerate() {
        for (p, ms) in t.iter().enumerate() {
            let _ = writeln!(csv, "{f},{},{ms:.4},{:.4}", PASS_NAMES[p], ms / pt_ms);
        }
    }
    write(&args.out_dir.join("passes.csv"), &csv)?;
    write(&args.out_dir.join("trace.json"), &serde_json::to_string(&chrome_trace(times))?)?;
    write(&args.out_dir.join("passes.svg"), &stacked_bar_svg(times, title))?;
    println!("{title}, {} frames: GPU ms per pass", args.frames);
    println!("path tracer: {pt_ms:.2} GPU ms per sample per pixel (same scene, size and camera; PT spp = ms / that)");
    println!("{:<10} {:>10} {:>10} {:>10}", "pass", "median", "p95", "PT spp");
    let row = |name: &str, v: &[f64]| {
        let median = quantile(v, 0.5);
        println!("{name:<10} {median:>10.2} {:>10.2} {:>10.2}", quantile(v, 0.95), median / pt_ms);
    };
    for (p, name) in PASS_NAMES.iter().enumerate() {
        row(name, &times.iter().map(|t| t[p]).collect::<Vec<f64>>());
    }
    row("frame", &times.iter().map(|t| t.iter().sum()).collect::<Vec<f64>>());
    eprintln!("wrote passes.csv, trace.json and passes.svg in {}", args.out_dir.display());
    Ok(())
}
