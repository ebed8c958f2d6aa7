//! `restir-pt render`: ReSTIR PT frames or progressive path tracing to EXR/PNG, with a one-line
//! summary per frame.

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::sync::Arc;

use anyhow::{anyhow, bail, Context as _, Result};
use clap::{Args, ValueEnum};

use super::args::{parse_exposure, DeviceArgs, PathArgs, RestirArgs, SceneArgs, Toggle};
use super::render_output::{
    check_extension, compile_progress, create_parent, guard_nonfinite, interrupt_flag, print_compile_summary, progress_bar, Outputs,
    RenderReport, RestirFrameReport,
};
use super::{finish_device, load_with_options, open_device};
use restir_pt::image_io::Exposure;
use restir_pt::render::{PathTracer, RenderSettings, Restir, RestirSettings, SceneGpu, SceneInfo};
use restir_pt::scene::{camera_on_path, Scene};

/// The rendering method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Unidirectional path tracing with NEE and MIS.
    Pt,
    /// ReSTIR PT: resampled paths reused across pixels and frames through shift mappings.
    Restir,
}

/// `restir-pt render`.
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[arg(long, value_enum, default_value_t = MethodArg::Restir)]
    pub method: MethodArg,
    /// Path-tracer samples per pixel (default 64); only with --method pt. With --static-camera
    /// and --frames F, each frame adds this many and the image holds all F times as many.
    #[arg(long)]
    pub spp: Option<u32>,
    /// Image width; with --height alone it follows the camera's aspectRatio (default 256).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height; with --width alone it follows the camera's aspectRatio (default 256).
    #[arg(long)]
    pub height: Option<u32>,
    /// PNG preview exposure: EV (radiance times 2^EV) or auto (log-average luminance to 0.18,
    /// so that an evenly lit scene shows mid-grey whatever its radiance). The EXR is never
    /// changed.
    #[arg(long, default_value = "auto", value_parser = parse_exposure, allow_hyphen_values = true)]
    pub exposure: Exposure,
    #[command(flatten)]
    pub path: PathArgs,
    /// Russian roulette from the third segment on (survival = max throughput, at most 0.95);
    /// path tracer only, default on (ReSTIR PT does not use it: it traces every path to
    /// --max-depth).
    #[arg(long, value_enum)]
    pub russian_roulette: Option<Toggle>,
    /// Render F frames along the scene's camera path from --camera: its cameras in order, then
    /// back and forth (0, 1, ..., n-1, n-2, ..., 0, 1, ...). The last frame goes to --out;
    /// every frame too with --out-dir.
    #[arg(long, default_value_t = 1)]
    pub frames: u32,
    /// Render every frame from --camera and write the average of the frames (offline mode).
    #[arg(long)]
    pub static_camera: bool,
    #[command(flatten)]
    pub restir: RestirArgs,
    /// Folder for every frame of --frames (frame_0000.exr/png, ...).
    #[arg(long)]
    pub out_dir: Option<PathBuf>,
    /// Linear float RGB EXR output (default: out/SCENE.exr).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Tonemapped sRGB PNG preview (default: next to the EXR).
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Also write the per-pixel variance of the estimate as an EXR.
    #[arg(long)]
    pub variance: Option<PathBuf>,
    /// Write the summary as JSON, with every frame's GPU time and their median.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write images that have NaN or infinite pixels (with a warning); without it such an
    /// image is not written and the exit code is 1.
    #[arg(long)]
    pub allow_nonfinite: bool,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl RenderArgs {
    /// Every flag at its default: what `restir-pt` without a command renders.
    pub fn parse_defaults() -> Result<Self> {
        super::parse_args(&[])
    }

    /// ReSTIR PT's settings, or None for the path tracer.
    fn restir_settings(&self) -> Option<RestirSettings> {
        (self.method == MethodArg::Restir).then(|| self.restir.settings())
    }

    /// Warns about flags the method ignores (one line per method, naming them).
    fn warn_ignored_flags(&self) {
        match self.method {
            MethodArg::Restir => {
                if self.spp.is_some() {
                    eprintln!("warning: --spp is ignored by ReSTIR PT, which renders --frames frames of --candidates paths per pixel (--method pt uses it)");
                }
                if self.russian_roulette == Some(Toggle::On) {
                    eprintln!("warning: --russian-roulette on is ignored by ReSTIR PT, which traces every path to --max-depth (--method pt uses it)");
                }
            }
            MethodArg::Pt => {
                let ignored = self.restir.changed_flags();
                if !ignored.is_empty() {
                    eprintln!("warning: --method pt ignores the ReSTIR PT options {}", ignored.join(", "));
                }
            }
        }
    }

    /// The render's settings on `scene`, validated.
    fn settings(&self, scene: &Scene) -> Result<RenderSettings> {
        let camera = scene.cameras.get(self.path.camera).unwrap_or(&scene.cameras[0]);
        let (width, height) = camera.image_size(self.width, self.height);
        let settings = self.settings_of_size(width, height);
        settings.validate(&SceneInfo::of(scene))?;
        if let Some(restir) = self.restir_settings() {
            restir.validate(settings.max_depth)?;
        }
        Ok(settings)
    }

    /// What [`RenderArgs::settings`] checks without the scene, and that the scene file can be
    /// opened, so that bad input fails before the device opens (a second or more on lavapipe).
    /// The image size is checked here when both sides are given; a side the camera completes
    /// waits for the scene.
    fn check_before_device(&self, scene_path: &Path) -> Result<()> {
        std::fs::File::open(scene_path).map_err(|e| anyhow!("{}: cannot read the file: {e}", scene_path.display()))?;
        let (width, height) = match (self.width, self.height) {
            (Some(w), Some(h)) => (w, h),
            // A valid stand-in: only spp and depth are checked.
            _ => (1, 1),
        };
        self.settings_of_size(width, height).validate_numbers()?;
        if let Some(restir) = self.restir_settings() {
            restir.validate(self.path.max_depth)?;
        }
        self.check_output_names()
    }

    /// The EXR (--out) and its PNG preview (--png, default --out with a .png extension) must be
    /// two files: with `--out image.png` the preview would overwrite the linear image.
    /// Each file is named for its format (--out and --variance OpenEXR, --png PNG).
    fn check_output_names(&self) -> Result<()> {
        if let Some(out) = &self.out {
            let png = self.png.clone().unwrap_or_else(|| out.with_extension("png"));
            if &png == out {
                if self.png.is_some() {
                    bail!("--png {}: the same file as --out; give the preview another name", png.display());
                }
                bail!(
                    "--out {}: the image is written as OpenEXR and its PNG preview would overwrite it; give --out an .exr name (the preview goes beside it) or --png another file",
                    out.display()
                );
            }
            check_extension("--out", out, "exr", "OpenEXR")?;
        }
        if let Some(png) = &self.png {
            check_extension("--png", png, "png", "PNG")?;
        }
        if let Some(variance) = &self.variance {
            check_extension("--variance", variance, "exr", "OpenEXR")?;
        }
        Ok(())
    }

    /// The settings of an image of `width` x `height`, unchecked.
    fn settings_of_size(&self, width: u32, height: u32) -> RenderSettings {
        RenderSettings {
            width,
            height,
            // ReSTIR PT ignores --spp (warn_ignored_flags says so), so its value is not checked.
            spp: self
                .spp
                .filter(|_| self.method == MethodArg::Pt)
                .unwrap_or(RenderSettings::DEFAULT_SPP),
            max_depth: self.path.max_depth,
            seed: self.path.seed,
            russian_roulette: self.russian_roulette.is_none_or(Toggle::on),
            camera: self.path.camera,
        }
    }

    /// The scene camera of frame `frame`: --camera for a static camera, else the scene's camera
    /// path from --camera (`camera_on_path`).
    fn frame_camera(&self, frame: u32, cameras: usize) -> usize {
        if self.static_camera {
            self.path.camera
        } else {
            camera_on_path(self.path.camera, frame, cameras)
        }
    }

    /// "frame F | camera C | " for runs of several frames (the camera a frame's reference needs).
    fn frame_prefix(&self, frame: u32, cameras: usize) -> String {
        if self.frames > 1 {
            format!("frame {frame} | camera {} | ", self.frame_camera(frame, cameras))
        } else {
            String::new()
        }
    }
}

/// Where the images go: --out (default out/SCENE.exr), --png next to it.
struct OutputPaths {
    out: PathBuf,
    png: PathBuf,
}

fn output_paths(args: &RenderArgs, scene_path: &Path) -> Result<OutputPaths> {
    let stem = scene_path
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
    Ok(OutputPaths { out, png })
}

/// What both methods' frame loops need.
struct Job<'a> {
    /// The uploaded scene both renderers are built from.
    scene: &'a Arc<SceneGpu>,
    scene_path: &'a Path,
    args: &'a RenderArgs,
    settings: &'a RenderSettings,
    outputs: Outputs<'a>,
}

impl Job<'_> {
    /// Whether the run ends with `frame` (the last frame, or Ctrl-C).
    fn is_last(&self, frame: u32, interrupted: bool) -> bool {
        frame + 1 == self.args.frames || interrupted
    }

    /// Whether `frame`'s image is written: the last frame's, and every frame's with --out-dir.
    fn writes_image(&self, frame: u32, interrupted: bool) -> bool {
        self.args.out_dir.is_some() || self.is_last(frame, interrupted)
    }

    /// Prints the frame's line, refuses or warns about non-finite pixels and writes the frame's
    /// image if it was read back (`writes_image`). Returns whether the run ends here.
    fn finish_frame(
        &self,
        frame: u32,
        report: &RenderReport,
        line: &str,
        image: Option<&restir_pt::render::Image>,
        interrupted: bool,
    ) -> Result<bool> {
        println!("{}{line}", self.args.frame_prefix(frame, self.scene.info().cameras.len()));
        guard_nonfinite(self.args.allow_nonfinite, self.args.report.as_deref(), frame, report)?;
        let last = self.is_last(frame, interrupted);
        if let Some(image) = image {
            self.outputs.write_frame(frame, image)?;
            if last {
                self.outputs.write_final(image)?;
            }
        }
        Ok(last)
    }

    fn report(&self, method: String, spp: u32, frame_ms: f64, wall_ms: f64, compile_ms: f64) -> RenderReport {
        RenderReport {
            device: self.scene.ctx().info.name.clone(),
            scene: self.scene_path.display().to_string(),
            method,
            width: self.settings.width,
            height: self.settings.height,
            spp,
            max_depth: self.settings.max_depth,
            gpu_ms: frame_ms,
            frame_gpu_ms: vec![frame_ms],
            median_gpu_ms: frame_ms,
            wall_ms,
            paths_per_second: 0.0,
            compile_ms,
            nonfinite_pixels: 0,
            nonfinite_weights: 0,
            restir: None,
        }
    }
}

pub fn render(args: RenderArgs) -> Result<()> {
    if args.frames == 0 {
        bail!("--frames must be at least 1");
    }
    args.warn_ignored_flags();
    let path = args.scene.path();
    args.check_before_device(&path)?;
    // The device first: its per-array limit lets the loader refuse an oversized scene from its
    // accessor counts, before reading vertices or building the BVH.
    let ctx = open_device(&args.device)?;
    let scene = load_with_options(&path, &args.scene.load_options(Some(ctx.scene_array_limit())))?;
    if let Some(line) = scene.surface_summary() {
        eprintln!("{line}");
    }
    if !args.static_camera && args.frames > 1 && scene.cameras.len() < 2 {
        eprintln!(
            "warning: {}: the scene has one camera, so the camera cannot move; every frame is seen from it",
            path.display()
        );
    }
    let settings = args.settings(&scene)?;
    let paths = output_paths(&args, &path)?;
    let scene_gpu = SceneGpu::upload(&ctx, &scene)?;
    let job = Job {
        scene: &scene_gpu,
        scene_path: &path,
        args: &args,
        settings: &settings,
        outputs: Outputs {
            out: &paths.out,
            png: &paths.png,
            variance: args.variance.as_deref(),
            out_dir: args.out_dir.as_deref(),
            exposure: args.exposure,
        },
    };
    let report = match args.restir_settings() {
        None => render_path_traced(&job)?,
        Some(restir) => render_restir(&job, &restir)?,
    };
    finish_device(&ctx)?;
    if let Some(r) = &args.report {
        report.write(r)?;
    }
    let written: Vec<String> = [Some(&paths.out), Some(&paths.png), args.variance.as_ref(), args.report.as_ref()]
        .into_iter()
        .flatten()
        .map(|p| p.display().to_string())
        .collect();
    eprintln!("wrote {}", written.join(", "));
    Ok(())
}

/// Path-traced frames of --spp each. A moving camera restarts the sums at every frame; a static
/// one keeps them, so that the image is the average of all frames (one render of F x spp).
fn render_path_traced(job: &Job) -> Result<RenderReport> {
    let (args, settings) = (job.args, job.settings);
    let interrupt = interrupt_flag();
    let spinner = compile_progress();
    spinner.set_message("pathtrace.comp");
    let mut tracer = PathTracer::new(job.scene, settings)?;
    spinner.finish_and_clear();
    let compile_ms = tracer.compile_report().total_ms();
    print_compile_summary(std::slice::from_ref(tracer.compile_report()));
    let (mut frame_ms, mut frame) = (vec![], 0);
    loop {
        if frame > 0 && args.static_camera {
            tracer.add_samples(settings.spp);
        } else if frame > 0 {
            let camera = args.frame_camera(frame, job.scene.info().cameras.len());
            tracer.restart(&RenderSettings {
                camera,
                ..settings.clone()
            })?;
        }
        let bar = progress_bar(tracer.target_spp());
        let stats = tracer.render(&|done| bar.set_position(done as u64), &interrupt)?;
        bar.finish_and_clear();
        let image = tracer.image()?;
        frame_ms.push(stats.gpu_ms);
        let mut report = job.report("pt".into(), stats.spp, stats.gpu_ms, stats.wall_ms, compile_ms);
        report.set_frame_times(&frame_ms);
        // A static camera's stats count every frame's samples; the throughput is this frame's.
        let frame_spp = stats.spp.saturating_sub(if args.static_camera { frame * settings.spp } else { 0 });
        report.paths_per_second = stats.paths_per_second(settings.pixel_count()) * frame_spp as f64 / stats.spp.max(1) as f64;
        report.nonfinite_pixels = image.non_finite_count();
        report.nonfinite_weights = stats.nonfinite_paths;
        if stats.interrupted {
            eprintln!("interrupted: writing the {} spp of frame {frame} accumulated so far", stats.spp);
        }
        if job.finish_frame(frame, &report, &report.summary_line(), Some(&image), stats.interrupted)? {
            return Ok(report);
        }
        frame += 1;
    }
}

/// ReSTIR PT frames; a static camera averages them (`Restir::frame`'s accumulate).
fn render_restir(job: &Job, restir: &RestirSettings) -> Result<RenderReport> {
    let (args, settings) = (job.args, job.settings);
    let interrupt = interrupt_flag();
    let spinner = compile_progress();
    let mut renderer = Restir::with_progress(job.scene, settings, restir, &|name| spinner.set_message(name.to_string()))?;
    spinner.finish_and_clear();
    let compile_reports = renderer.compile_reports();
    print_compile_summary(&compile_reports);
    let compile_ms = compile_reports.iter().map(|k| k.total_ms()).sum();
    let spp = restir.candidates * restir.reservoirs;
    let (mut frame_ms, mut frame) = (vec![], 0);
    loop {
        let stats = renderer.frame(args.frame_camera(frame, job.scene.info().cameras.len()), args.static_camera)?;
        let interrupted = interrupt.load(Ordering::Relaxed);
        frame_ms.push(stats.gpu_ms().unwrap_or(stats.wall_ms));
        let detail = RestirFrameReport::from_stats(frame + 1, &stats);
        let mut report = job.report(restir.label(), spp, frame_ms[frame as usize], stats.wall_ms, compile_ms);
        report.set_frame_times(&frame_ms);
        report.paths_per_second = settings.pixel_count() as f64 * spp as f64 / (report.gpu_ms * 1e-3);
        // The image is read back only when it is written or when the shading pass counted a
        // non-finite pixel (then the host count is the one reported and guarded).
        let image = if job.writes_image(frame, interrupted) || detail.nonfinite_pixels > 0 {
            Some(renderer.image()?)
        } else {
            None
        };
        report.nonfinite_pixels = image.as_ref().map_or(0, |image| image.non_finite_count());
        report.nonfinite_weights = detail.nonfinite_weights as u64;
        let line = format!("{} | {}", report.summary_line(), detail.summary());
        report.restir = Some(detail);
        if interrupted {
            eprintln!("interrupted: writing frame {frame}");
        }
        if job.finish_frame(frame, &report, &line, image.as_ref(), interrupted)? {
            if frame > 0 {
                let total: f64 = frame_ms.iter().sum();
                eprintln!(
                    "{} frames, {total:.1} ms of GPU time in all (median {:.1} ms per frame)",
                    frame + 1,
                    report.median_gpu_ms
                );
            }
            return Ok(report);
        }
        frame += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn render_without_arguments_takes_the_library_defaults() {
        let args = RenderArgs::parse_defaults().unwrap();
        assert_eq!((args.method, args.frames, args.static_camera), (MethodArg::Restir, 1, false));
        assert_eq!(args.path.max_depth, RenderSettings::DEFAULT_MAX_DEPTH);
        assert_eq!(args.restir_settings(), Some(RestirSettings::default()));
        assert_eq!(args.russian_roulette, None);
        let pt: RenderArgs = super::super::parse_args(&["--method", "pt", "--russian-roulette", "off", "--exposure", "-1.5"]).unwrap();
        assert_eq!((pt.restir_settings(), pt.russian_roulette), (None, Some(Toggle::Off)));
        assert_eq!(pt.exposure, Exposure::Ev(-1.5));
    }
}
