//! `restir-pt render`: ReSTIR PT frames or progressive path tracing to EXR/PNG, with a one-line
//! summary per frame.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::{bail, Context as _, Result};
use serde::Serialize;

use super::{finish_device, load_with_options, open_device, scene_path, DeviceArgs};
use crate::image_io::{exposure_ev, write_exr, write_png_exposed, Exposure};
use crate::render::{FrameStats, PathTracer, RenderSettings, Restir, RestirSettings, PASS_NAMES};
use crate::scene::{camera_on_path, LoadOptions, Scene};

/// The rendering method: the path tracer, or ReSTIR PT with its settings.
#[derive(Debug, Clone)]
pub enum Method {
    PathTracing,
    Restir(RestirSettings),
}

pub struct RenderArgs {
    pub scene: Option<PathBuf>,
    pub method: Method,
    /// Paths per pixel of the path tracer (default 64); ReSTIR PT renders frames instead.
    pub spp: Option<u32>,
    /// Every frame from --camera, averaged (ReSTIR PT's offline mode).
    pub static_camera: bool,
    /// Image sides; a missing one follows the camera's aspect ratio (`Camera::image_size`).
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub max_depth: u32,
    pub seed: u32,
    pub russian_roulette: bool,
    pub camera: usize,
    pub frames: u32,
    pub out_dir: Option<PathBuf>,
    pub out: Option<PathBuf>,
    pub png: Option<PathBuf>,
    pub variance: Option<PathBuf>,
    pub report: Option<PathBuf>,
    /// Write images with non-finite pixels (with a warning) instead of failing.
    pub allow_nonfinite: bool,
    /// What to load besides the file: `--scene N`, `--env`.
    pub load: LoadOptions,
    /// Exposure of the PNG previews.
    pub exposure: Exposure,
    pub device: DeviceArgs,
}

#[derive(Serialize)]
pub struct RenderReport {
    pub device: String,
    pub scene: String,
    pub method: String,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub gpu_ms: f64,
    pub wall_ms: f64,
    pub paths_per_second: f64,
    /// Start-up milliseconds spent compiling the kernels (outside every frame's time).
    pub compile_ms: f64,
    /// NaN or infinite pixels of the image written (or refused) for this frame.
    pub nonfinite_pixels: usize,
    /// Path weights found NaN or infinite: the path tracer's paths with a non-finite radiance or
    /// throughput over the whole render; ReSTIR PT's candidate and shift weights of this frame.
    pub nonfinite_weights: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub restir: Option<RestirFrameReport>,
}

/// A spinner that names the kernel being compiled; compiling takes seconds on llvmpipe.
pub(super) fn compile_progress() -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(indicatif::ProgressStyle::with_template("{spinner} compiling {msg}  {elapsed}").expect("static template is valid"));
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// The start-up line: how long compiling the kernels took.
pub(super) fn print_compile_summary(kernels: &[crate::vk::KernelCompile]) {
    let total: f64 = kernels.iter().map(|k| k.total_ms()).sum();
    eprintln!("start-up: {} kernel(s) compiled in {total:.0} ms", kernels.len());
}

impl RenderReport {
    pub fn summary_line(&self) -> String {
        format!(
            "{} | {} | {}x{} | {} spp | depth {} | GPU {:.1} ms | wall {:.1} ms | {:.3} M paths/s | non-finite pixels {}, weights {}",
            self.device,
            self.method,
            self.width,
            self.height,
            self.spp,
            self.max_depth,
            self.gpu_ms,
            self.wall_ms,
            self.paths_per_second * 1e-6,
            self.nonfinite_pixels,
            self.nonfinite_weights
        )
    }
}

/// Refuses an image with non-finite pixels unless --allow-nonfinite: the report (if asked for)
/// is written first so that the counts are kept, then the error names the frame and the counts.
/// With --allow-nonfinite it warns and lets the image be written.
fn guard_nonfinite(args: &RenderArgs, frame: u32, report: &RenderReport) -> Result<()> {
    if report.nonfinite_pixels == 0 {
        return Ok(());
    }
    let what = format!(
        "frame {frame}: {} non-finite pixels ({} non-finite path weights)",
        report.nonfinite_pixels, report.nonfinite_weights
    );
    if args.allow_nonfinite {
        eprintln!("warning: {what}; writing the image anyway (--allow-nonfinite)");
        return Ok(());
    }
    if let Some(r) = &args.report {
        std::fs::write(r, serde_json::to_string_pretty(report)?).with_context(|| format!("{}: cannot write the report", r.display()))?;
    }
    bail!("{what}; no image written (--allow-nonfinite writes it anyway)")
}

pub(super) fn progress_bar(total: u32) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(total as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} spp  {elapsed} (eta {eta})").expect("static template is valid"),
    );
    bar
}

/// Installs a Ctrl-C handler once; later renders share the flag.
pub(super) fn interrupt_flag() -> Arc<AtomicBool> {
    static FLAG: std::sync::OnceLock<Arc<AtomicBool>> = std::sync::OnceLock::new();
    FLAG.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        let handler_flag = flag.clone();
        // Without a handler Ctrl-C still ends the process; only the partial image is lost.
        if let Err(e) = ctrlc::set_handler(move || handler_flag.store(true, Ordering::Relaxed)) {
            eprintln!("warning: Ctrl-C will not save a partial image: {e}");
        }
        flag
    })
    .clone()
}

pub(super) fn create_parent(file: &Path) -> Result<()> {
    match file.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create the output folder", dir.display())),
        None => Ok(()),
    }
}

/// The scene camera of frame `frame`: --camera for a static camera, else the scene's camera
/// path from --camera (`camera_on_path`).
fn frame_camera(args: &RenderArgs, frame: u32, cameras: usize) -> usize {
    if args.static_camera {
        args.camera
    } else {
        camera_on_path(args.camera, frame, cameras)
    }
}

pub fn render(args: RenderArgs) -> Result<()> {
    let path = scene_path(args.scene.as_deref());
    if args.frames == 0 {
        bail!("--frames must be at least 1");
    }
    if matches!(args.method, Method::Restir(_)) && args.spp.is_some() {
        bail!("--spp sets the path tracer's samples; ReSTIR PT renders --frames frames of --candidates paths per pixel");
    }
    // The device first: its per-array limit lets the loader refuse an oversized scene from its
    // accessor counts, before reading vertices or building the BVH.
    let ctx = open_device(&args.device)?;
    let load = LoadOptions {
        array_limit: Some(ctx.scene_array_limit()),
        ..args.load.clone()
    };
    let scene = load_with_options(&path, &load)?;
    if !args.static_camera && args.frames > 1 && scene.cameras.len() < 2 {
        eprintln!(
            "warning: {}: the scene has one camera, so the camera cannot move; every frame is seen from it",
            path.display()
        );
    }
    let camera = scene.cameras.get(args.camera).unwrap_or(&scene.cameras[0]);
    let (width, height) = camera.image_size(args.width, args.height);
    let settings = RenderSettings {
        width,
        height,
        spp: args.spp.unwrap_or(64),
        max_depth: args.max_depth,
        seed: args.seed,
        russian_roulette: args.russian_roulette,
        camera: args.camera,
    };
    settings.validate(&scene)?;
    if let Method::Restir(restir) = &args.method {
        restir.validate(settings.max_depth)?;
    }
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from("out").join(format!("{stem}.exr")));
    let png = args.png.clone().unwrap_or_else(|| out.with_extension("png"));
    for file in [Some(&out), Some(&png), args.variance.as_ref(), args.report.as_ref()]
        .into_iter()
        .flatten()
    {
        create_parent(file)?;
    }
    if let Some(dir) = &args.out_dir {
        std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create the output folder", dir.display()))?;
    }

    let outputs = Outputs {
        out: &out,
        png: &png,
        variance: args.variance.as_deref(),
        out_dir: args.out_dir.as_deref(),
        exposure: args.exposure,
    };
    let report = match &args.method {
        Method::PathTracing => render_path_traced(&ctx, &scene, &path, &args, &settings, &outputs)?,
        Method::Restir(restir) => render_restir(&ctx, &scene, &path, &args, &settings, restir, &outputs)?,
    };
    finish_device(&ctx)?;
    if let (Some(r), Some(report)) = (&args.report, &report) {
        std::fs::write(r, serde_json::to_string_pretty(report)?).with_context(|| format!("{}: cannot write the report", r.display()))?;
    }
    eprintln!("wrote {} and {}", out.display(), png.display());
    Ok(())
}

struct Outputs<'a> {
    out: &'a Path,
    png: &'a Path,
    variance: Option<&'a Path>,
    out_dir: Option<&'a Path>,
    exposure: Exposure,
}

impl Outputs<'_> {
    fn write_frame(&self, frame: u32, image: &crate::render::Image) -> Result<()> {
        if let Some(dir) = self.out_dir {
            let name = format!("frame_{frame:04}");
            write_exr(&dir.join(format!("{name}.exr")), image.width, image.height, &image.mean)?;
            write_png_exposed(&dir.join(format!("{name}.png")), image, exposure_ev(self.exposure, image))?;
        }
        Ok(())
    }

    fn write_final(&self, image: &crate::render::Image) -> Result<()> {
        write_exr(self.out, image.width, image.height, &image.mean)?;
        let ev = exposure_ev(self.exposure, image);
        if self.exposure == Exposure::Auto {
            eprintln!("PNG preview: exposure {ev:+.2} EV (automatic; --exposure EV sets it)");
        }
        write_png_exposed(self.png, image, ev)?;
        if let Some(v) = self.variance {
            write_exr(v, image.width, image.height, &image.variance)?;
        }
        Ok(())
    }
}

/// "frame F | camera C | " for runs of several frames (the camera a frame's reference needs).
fn frame_prefix(args: &RenderArgs, frame: u32, cameras: usize) -> String {
    if args.frames > 1 {
        format!("frame {frame} | camera {} | ", frame_camera(args, frame, cameras))
    } else {
        String::new()
    }
}

fn render_path_traced(
    ctx: &Arc<crate::vk::Context>,
    scene: &Scene,
    path: &Path,
    args: &RenderArgs,
    settings: &RenderSettings,
    outputs: &Outputs,
) -> Result<Option<RenderReport>> {
    let interrupt = interrupt_flag();
    let spinner = compile_progress();
    spinner.set_message("pathtrace.comp");
    let mut tracer = PathTracer::new(ctx, scene, settings)?;
    spinner.finish_and_clear();
    let compile = tracer.compile_report().clone();
    print_compile_summary(std::slice::from_ref(&compile));
    for frame in 0..args.frames {
        if frame > 0 {
            let camera = frame_camera(args, frame, scene.cameras.len());
            tracer.restart(
                scene,
                &RenderSettings {
                    camera,
                    ..settings.clone()
                },
            )?;
        }
        let bar = progress_bar(settings.spp);
        let stats = tracer.render(&|done| bar.set_position(done as u64), &interrupt)?;
        bar.finish_and_clear();
        let image = tracer.image()?;
        let frame_report = RenderReport {
            device: ctx.info.name.clone(),
            scene: path.display().to_string(),
            method: "pt".into(),
            width: settings.width,
            height: settings.height,
            spp: stats.spp,
            max_depth: settings.max_depth,
            gpu_ms: stats.gpu_ms,
            wall_ms: stats.wall_ms,
            paths_per_second: stats.paths_per_second(settings.pixel_count()),
            compile_ms: compile.total_ms(),
            nonfinite_pixels: image.non_finite_count(),
            nonfinite_weights: stats.nonfinite_paths,
            restir: None,
        };
        println!("{}{}", frame_prefix(args, frame, scene.cameras.len()), frame_report.summary_line());
        guard_nonfinite(args, frame, &frame_report)?;
        outputs.write_frame(frame, &image)?;
        if stats.interrupted {
            eprintln!("interrupted: writing the {} spp of frame {frame} accumulated so far", stats.spp);
        }
        if frame + 1 == args.frames || stats.interrupted {
            outputs.write_final(&image)?;
            return Ok(Some(frame_report));
        }
    }
    Ok(None)
}

/// What a ReSTIR PT frame reports beyond the common summary.
#[derive(Serialize, Clone)]
pub struct RestirFrameReport {
    pub frames: u32,
    pub pass_ms: Vec<(String, f64)>,
    pub shifts_attempted: u32,
    pub shifts_failed: u32,
    pub failed_shift_rate: f64,
    pub nonfinite_weights: u32,
    pub nonfinite_pixels: u32,
    pub candidates_dropped: u32,
}

impl RestirFrameReport {
    fn from_stats(frames: u32, stats: &FrameStats) -> Self {
        let c = &stats.counters;
        RestirFrameReport {
            frames,
            pass_ms: match stats.pass_ms {
                Some(ms) => PASS_NAMES.iter().zip(ms).map(|(n, t)| (n.to_string(), t)).collect(),
                None => vec![],
            },
            shifts_attempted: c.shifts_attempted,
            shifts_failed: c.shifts_failed,
            failed_shift_rate: stats.failed_shift_rate(),
            nonfinite_weights: c.nonfinite_weights,
            nonfinite_pixels: c.nonfinite_pixels,
            candidates_dropped: c.candidates_dropped,
        }
    }

    fn summary(&self) -> String {
        let passes: Vec<String> = self.pass_ms.iter().map(|(n, t)| format!("{n} {t:.1}")).collect();
        format!(
            "passes ms: {} | failed shifts {}/{} ({:.1}%) | non-finite weights {} | non-finite pixels {}",
            if passes.is_empty() { "n/a".to_string() } else { passes.join(", ") },
            self.shifts_failed,
            self.shifts_attempted,
            100.0 * self.failed_shift_rate,
            self.nonfinite_weights,
            self.nonfinite_pixels
        )
    }
}

fn render_restir(
    ctx: &Arc<crate::vk::Context>,
    scene: &Scene,
    path: &Path,
    args: &RenderArgs,
    settings: &RenderSettings,
    restir: &RestirSettings,
    outputs: &Outputs,
) -> Result<Option<RenderReport>> {
    let interrupt = interrupt_flag();
    let spinner = compile_progress();
    let mut renderer = Restir::with_progress(ctx, scene, settings, restir, &|name| spinner.set_message(name.to_string()))?;
    spinner.finish_and_clear();
    let compile_reports = renderer.compile_reports();
    print_compile_summary(&compile_reports);
    let mut gpu_ms = 0.0;
    let mut report = None;
    // Whether an estimate accumulated since the last restart was non-finite (counted on the
    // GPU): only then can the image hold non-finite pixels.
    let mut nonfinite_seen = false;
    for frame in 0..args.frames {
        let stats = renderer.frame(scene, frame_camera(args, frame, scene.cameras.len()), args.static_camera)?;
        let interrupted = interrupt.load(Ordering::Relaxed);
        let last = frame + 1 == args.frames || interrupted;
        nonfinite_seen = (nonfinite_seen && args.static_camera) || stats.counters.nonfinite_pixels > 0;
        // The image is read back only when it is written or has non-finite pixels to count.
        let image = (last || outputs.out_dir.is_some() || nonfinite_seen)
            .then(|| renderer.image())
            .transpose()?;
        let frame_ms = stats.gpu_ms().unwrap_or(stats.wall_ms);
        gpu_ms += frame_ms;
        let detail = RestirFrameReport::from_stats(frame + 1, &stats);
        let frame_report = RenderReport {
            device: ctx.info.name.clone(),
            scene: path.display().to_string(),
            method: restir.label(),
            width: settings.width,
            height: settings.height,
            spp: restir.candidates * restir.reservoirs,
            max_depth: settings.max_depth,
            gpu_ms: frame_ms,
            wall_ms: stats.wall_ms,
            paths_per_second: settings.pixel_count() as f64 * (restir.candidates * restir.reservoirs) as f64 / (frame_ms * 1e-3),
            compile_ms: compile_reports.iter().map(|k| k.total_ms()).sum(),
            nonfinite_pixels: image.as_ref().map_or(0, |i| i.non_finite_count()),
            nonfinite_weights: detail.nonfinite_weights as u64,
            restir: Some(detail.clone()),
        };
        println!(
            "{}{} | {}",
            frame_prefix(args, frame, scene.cameras.len()),
            frame_report.summary_line(),
            detail.summary()
        );
        guard_nonfinite(args, frame, &frame_report)?;
        let Some(image) = image else { continue };
        outputs.write_frame(frame, &image)?;
        if interrupted {
            eprintln!("interrupted: writing frame {frame}");
        }
        if last {
            outputs.write_final(&image)?;
            report = Some(frame_report);
            break;
        }
    }
    if args.frames > 1 {
        eprintln!("{} frames, {gpu_ms:.1} ms of GPU time in all", args.frames);
    }
    Ok(report)
}
