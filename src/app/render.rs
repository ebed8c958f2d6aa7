//! `restir-pt render`: ReSTIR PT frames or progressive path tracing to EXR/PNG, with a one-line
//! summary per frame; its options and how long a run lasts (render_loop.rs runs the frames).

use std::io::Read as _;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context as _, Result};
use clap::{Args, ValueEnum};

use super::args::{parse_exposure, DeviceArgs, PathArgs, RestirArgs, SceneArgs};
use super::render_loop::{render_path_traced, render_restir, Job};
use super::render_output::{check_extension, create_parent, Outputs};
use super::{finish_device, load_with_options, open_device};
use restir_pt::image_io::Exposure;
use restir_pt::render::{scene_array_limit, RenderSettings, RestirSettings, SceneGpu, SceneInfo};
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
    /// Path-tracer samples per pixel (default 64; with --time, 4 per step); only with --method pt.
    /// With --static-camera and --frames F, each frame adds this many and the image holds all F
    /// times as many.
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
    /// Render exactly F frames along the scene's camera path from --camera: its cameras in
    /// order, then back and forth (0, 1, ..., n-1, n-2, ..., 0, 1, ...). The last frame goes to
    /// --out; every frame too with --out-dir. `--frames 1` is one frame. Without --frames,
    /// ReSTIR PT renders to a time budget (--time) and the path tracer one frame of --spp.
    #[arg(long, conflicts_with = "time")]
    pub frames: Option<u32>,
    /// Render frames of an unmoved camera (--camera) and write their average, until their GPU
    /// time reaches SECONDS (default for ReSTIR PT without --frames: 8). The path tracer adds
    /// --spp (default 4) per step.
    #[arg(long, value_name = "SECONDS")]
    pub time: Option<f64>,
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

/// How much of a scene file is read before the device opens, to tell glTF from other files.
const GLTF_START_BYTES: u64 = 4096;

/// GPU seconds of frames that ReSTIR PT renders and averages without --frames or --time.
pub const DEFAULT_TIME_S: f64 = 8.0;
/// ReSTIR PT's M-cap when `render` averages a still camera's frames to a time budget. The
/// temporal history makes successive frames correlated, so a path found once (a caustic the
/// shifts cannot reuse) stays in about M-cap frames of the average instead of one; the
/// average's variance grows with that correlation while one frame's shrinks with the history.
/// For the average a short history wins: 16 frames of the still camera at 256² (8 s of GPU
/// time), relMSE against 1024-spp references, 3 to 4 seeds: cornell-glossy 0.071 (M-cap 20),
/// 0.037 (5), 0.028 (2); cornell 0.0076 (20), 0.0056 (2) (docs/lab-notebook.md, 2026-12-05).
pub const STILL_AVERAGE_M_CAP: f32 = 2.0;

/// Path-tracer samples per pixel per step of a time budget, when --spp is not given.
const BUDGET_STEP_SPP: u32 = 4;

/// How long a render runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RunLength {
    /// Exactly this many frames (`--frames`).
    Frames(u32),
    /// Frames of an unmoved camera, averaged, until their GPU time reaches this many
    /// milliseconds (`--time`): the frame that reaches it is the last.
    GpuMs(f64),
}

impl RenderArgs {
    /// How long the run lasts: `--frames`, else `--time`, else ReSTIR PT's default time budget
    /// or the path tracer's one frame.
    pub fn run_length(&self) -> RunLength {
        match (self.frames, self.time) {
            (Some(frames), _) => RunLength::Frames(frames),
            (None, Some(seconds)) => RunLength::GpuMs(seconds * 1e3),
            (None, None) if self.method == MethodArg::Restir => RunLength::GpuMs(DEFAULT_TIME_S * 1e3),
            (None, None) => RunLength::Frames(1),
        }
    }

    /// Whether every frame is seen from --camera: with --static-camera and under a time budget.
    pub fn is_static(&self) -> bool {
        self.static_camera || matches!(self.run_length(), RunLength::GpuMs(_))
    }

    /// Every flag at its default: what `restir-pt` without a command renders.
    pub fn parse_defaults() -> Result<Self> {
        super::parse_args(&[])
    }

    /// ReSTIR PT's settings, or None for the path tracer. A still camera averaged to a time
    /// budget gets [`STILL_AVERAGE_M_CAP`] unless --m-cap is given.
    fn restir_settings(&self) -> Option<RestirSettings> {
        (self.method == MethodArg::Restir).then(|| {
            let mut restir = self.restir.settings();
            if self.restir.m_cap.is_none() && matches!(self.run_length(), RunLength::GpuMs(_)) {
                restir.m_cap = STILL_AVERAGE_M_CAP;
            }
            restir
        })
    }

    /// Warns about flags the method ignores (one line per method, naming them).
    fn warn_ignored_flags(&self) {
        match self.method {
            MethodArg::Restir => {
                if self.spp.is_some() {
                    eprintln!("warning: --spp is ignored by ReSTIR PT, which renders frames (--time or --frames) of --candidates paths per pixel (--method pt uses it)");
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
    /// read and starts as glTF does, so that bad input fails before the device opens (a second or more on lavapipe).
    /// The image size is checked here when both sides are given; a side the camera completes
    /// waits for the scene.
    fn check_before_device(&self, scene_path: &Path) -> Result<()> {
        let cannot_read = |e: std::io::Error| anyhow!("{}: cannot read the file: {e}", scene_path.display());
        let file = std::fs::File::open(scene_path).map_err(cannot_read)?;
        let file_bytes = file.metadata().map_err(cannot_read)?.len();
        let mut start = Vec::with_capacity(GLTF_START_BYTES as usize);
        file.take(GLTF_START_BYTES).read_to_end(&mut start).map_err(cannot_read)?;
        restir_pt::scene::check_gltf_start(&start, file_bytes, scene_path)?;
        let (width, height) = match (self.width, self.height) {
            (Some(w), Some(h)) => (w, h),
            // A side the camera completes is checked with the scene; a given one of 0 already.
            (w, h) => {
                for (flag, side) in [("--width", w), ("--height", h)] {
                    if side == Some(0) {
                        bail!("{flag} 0: the image must be at least 1 pixel on each side");
                    }
                }
                // A valid stand-in: only spp and depth are checked.
                (1, 1)
            }
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
                .unwrap_or(match self.run_length() {
                    RunLength::GpuMs(_) => BUDGET_STEP_SPP,
                    RunLength::Frames(_) => RenderSettings::DEFAULT_SPP,
                }),
            max_depth: self.path.max_depth,
            seed: self.path.seed,
            russian_roulette: self.path.russian_roulette.on(),
            camera: self.path.camera,
        }
    }

    /// The scene camera of frame `frame`: --camera for a static camera, else the scene's camera
    /// path from --camera (`camera_on_path`).
    pub fn frame_camera(&self, frame: u32, cameras: usize) -> usize {
        if self.is_static() {
            self.path.camera
        } else {
            camera_on_path(self.path.camera, frame, cameras)
        }
    }

    /// "frame F | camera C | " for runs of several frames (the camera a frame's reference needs).
    pub fn frame_prefix(&self, frame: u32, cameras: usize) -> String {
        if self.run_length() != RunLength::Frames(1) {
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

pub fn render(args: RenderArgs) -> Result<()> {
    if args.frames == Some(0) {
        bail!("--frames must be at least 1");
    }
    if let Some(seconds) = args.time.filter(|s| !(s.is_finite() && *s > 0.0)) {
        bail!("--time {seconds}: give a positive number of seconds");
    }
    args.warn_ignored_flags();
    let path = args.scene.path()?;
    args.check_before_device(&path)?;
    // The device first: its per-array limit lets the loader refuse an oversized scene from its
    // accessor counts, before reading vertices or building the BVH.
    let ctx = open_device(&args.device)?;
    let scene = load_with_options(&path, &args.scene.load_options(Some(scene_array_limit(&ctx))))?;
    if let Some(line) = scene.surface_summary() {
        eprintln!("{line}");
    }
    if !args.is_static() && args.frames.is_some_and(|f| f > 1) && scene.cameras.len() < 2 {
        let which = if scene.cameras[0].name == restir_pt::scene::DEFAULT_CAMERA_NAME {
            "no camera, so the default camera framing it"
        } else {
            "one camera, so the camera"
        };
        eprintln!(
            "warning: {}: the scene has {which} cannot move; every frame is seen from it",
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
        run: args.run_length(),
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

#[cfg(test)]
mod tests {
    use super::super::args::Toggle;
    use super::*;

    #[test]
    fn render_without_arguments_takes_the_library_defaults() {
        let args = RenderArgs::parse_defaults().unwrap();
        assert_eq!((args.method, args.frames, args.static_camera), (MethodArg::Restir, None, false));
        assert_eq!(args.run_length(), RunLength::GpuMs(DEFAULT_TIME_S * 1e3));
        assert!(args.is_static());
        assert_eq!(args.path.max_depth, RenderSettings::DEFAULT_MAX_DEPTH);
        let still = RestirSettings {
            m_cap: STILL_AVERAGE_M_CAP,
            ..RestirSettings::default()
        };
        assert_eq!(args.restir_settings(), Some(still));
        let frames: RenderArgs = super::super::parse_args(&["--frames", "3", "--static-camera"]).unwrap();
        assert_eq!(frames.restir_settings(), Some(RestirSettings::default()));
        let given: RenderArgs = super::super::parse_args(&["--m-cap", "20"]).unwrap();
        assert_eq!(given.restir_settings(), Some(RestirSettings::default()));
        assert_eq!(args.path.russian_roulette, Toggle::On);
        let pt: RenderArgs = super::super::parse_args(&["--method", "pt", "--russian-roulette", "off", "--exposure", "-1.5"]).unwrap();
        assert_eq!((pt.restir_settings(), pt.path.russian_roulette), (None, Toggle::Off));
        assert_eq!(pt.exposure, Exposure::Ev(-1.5));
        assert_eq!((pt.run_length(), pt.is_static()), (RunLength::Frames(1), false));
        assert_eq!(pt.settings_of_size(8, 8).spp, RenderSettings::DEFAULT_SPP);
    }

    #[test]
    fn frames_and_time_choose_the_run_length() {
        let one: RenderArgs = super::super::parse_args(&["--frames", "1"]).unwrap();
        assert_eq!((one.run_length(), one.is_static()), (RunLength::Frames(1), false));
        let moving: RenderArgs = super::super::parse_args(&["--frames", "16"]).unwrap();
        assert_eq!((moving.run_length(), moving.frame_camera(3, 8)), (RunLength::Frames(16), 3));
        let timed: RenderArgs = super::super::parse_args(&["--time", "2.5", "--camera", "2"]).unwrap();
        assert_eq!((timed.run_length(), timed.frame_camera(3, 8)), (RunLength::GpuMs(2500.0), 2));
        let pt: RenderArgs = super::super::parse_args(&["--method", "pt", "--time", "1"]).unwrap();
        assert_eq!(
            (pt.run_length(), pt.settings_of_size(8, 8).spp),
            (RunLength::GpuMs(1000.0), BUDGET_STEP_SPP)
        );
        assert!(super::super::parse_args::<RenderArgs>(&["--frames", "2", "--time", "1"]).is_err());
    }
}
