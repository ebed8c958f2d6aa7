//! `restir-pt stability`: every scene and method over F frames with a static and a moving camera:
//! non-finite pixels, energy and relMSE against a path-traced reference per frame, temporal
//! flicker and the failed-shift rate. Writes stability.csv and an error-over-frames chart per
//! scene, and fails if any pixel was not finite.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use glam::Vec3;

use clap::Args;

use super::args::{argv, DeviceArgs, RestirArgs, SweepArgs};
use super::method_spec::{parse_methods, MethodRenderer, MethodSpec, DEFAULT_METHODS};
use super::sweep::{
    job_file, parse_optional, read_job_reports, read_job_rows, start_job, write_accounting, write_job_report, write_plan, JobReport,
    SweepMode, COMMIT,
};
use super::{bundled_file, finish_device, load_with_warnings, open_device};
use crate::app::charts::{write_line_chart, LineChart, Series};
use restir_pt::metrics::{energy_ratio, flicker, mean, rel_mse};
use restir_pt::render::{PathTracer, RenderSettings, SceneGpu, SceneInfo};
use restir_pt::scene::{camera_on_path, Scene};

/// `restir-pt stability`.
#[derive(Args, Debug, Clone)]
pub struct StabilityArgs {
    /// Scenes to run (default: every bundled scene).
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<PathBuf>,
    /// Methods, as in `compare`.
    #[arg(long, value_delimiter = ',', default_value = DEFAULT_METHODS)]
    pub methods: Vec<String>,
    /// Frames per run (at least 2: flicker compares consecutive frames).
    #[arg(long, default_value_t = 16)]
    pub frames: u32,
    /// Image width in pixels.
    #[arg(long, default_value_t = 64)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 64)]
    pub height: u32,
    /// Maximum number of path segments, as in `render`.
    #[arg(long, default_value_t = RenderSettings::DEFAULT_MAX_DEPTH)]
    pub max_depth: u32,
    /// Paths per pixel of each camera pose's path-traced reference.
    #[arg(long, default_value_t = 512)]
    pub reference_spp: u32,
    /// Paths per pixel of one path-traced frame.
    #[arg(long, default_value_t = 4)]
    pub pt_spp: u32,
    /// Seed of the random numbers, as in `render`.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    #[command(flatten)]
    pub restir: RestirArgs,
    /// Folder for stability.csv and SCENE_rel_mse.svg/png.
    #[arg(long, default_value = "out/stability")]
    pub out_dir: PathBuf,
    #[command(flatten)]
    pub sweep: SweepArgs,
    #[command(flatten)]
    pub device: DeviceArgs,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraMotion {
    Static,
    /// Back and forth along the scene's camera path, one pose per frame.
    Moving,
}

impl CameraMotion {
    pub fn name(self) -> &'static str {
        match self {
            CameraMotion::Static => "static",
            CameraMotion::Moving => "moving",
        }
    }

    /// The scene camera of frame `frame` among `cameras` poses.
    fn camera(self, frame: u32, cameras: usize) -> usize {
        match self {
            CameraMotion::Static => 0,
            CameraMotion::Moving => camera_on_path(0, frame, cameras),
        }
    }
}

/// One frame of one method on one scene.
#[derive(Debug, Clone)]
pub struct StabilityRow {
    pub scene: String,
    pub method: String,
    pub motion: CameraMotion,
    pub frame: u32,
    pub nonfinite_pixels: usize,
    pub energy_ratio: f64,
    pub rel_mse: f64,
    /// Static camera only, from the second frame on.
    pub flicker: Option<f64>,
    pub failed_shift_rate: Option<f64>,
}

/// Path-traced references of a scene's camera poses, made on first use.
struct References {
    tracer: PathTracer,
    settings: RenderSettings,
    images: HashMap<usize, Vec<Vec3>>,
    /// GPU ms of the references rendered.
    gpu_ms: f64,
}

impl References {
    fn get(&mut self, camera: usize) -> Result<&[Vec3]> {
        if !self.images.contains_key(&camera) {
            let settings = RenderSettings {
                camera,
                ..self.settings.clone()
            };
            self.tracer.restart(&settings)?;
            self.gpu_ms += self.tracer.render(&|_| {}, &AtomicBool::new(false))?.gpu_ms;
            self.images.insert(camera, self.tracer.image()?.mean);
        }
        Ok(&self.images[&camera])
    }
}

fn scene_name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// The bundled scenes, in their documented order.
pub fn bundled_scene_paths() -> Vec<PathBuf> {
    restir_pt::scene::bundled_scenes::BUNDLED_SCENES
        .iter()
        .map(|s| bundled_file(&Path::new("scenes").join(s.file_name)))
        .collect()
}

/// The scenes, methods and settings every mode checks before it opens a device.
struct Setup {
    methods: Vec<MethodSpec>,
    scenes: Vec<(String, Scene)>,
    base: RenderSettings,
}

impl Setup {
    /// Path-traced references of `scene`'s poses, rendered on first use.
    fn references(&self, args: &StabilityArgs, scene: &Arc<SceneGpu>) -> Result<References> {
        let settings = RenderSettings {
            spp: args.reference_spp,
            seed: args.seed ^ 0x5eed_0f5e,
            ..self.base.clone()
        };
        Ok(References {
            tracer: PathTracer::new(scene, &settings)?,
            settings,
            images: HashMap::new(),
            gpu_ms: 0.0,
        })
    }

    /// The jobs: every method on every scene, scene-major.
    fn labels(&self) -> Vec<String> {
        self.scenes
            .iter()
            .flat_map(|(name, _)| self.methods.iter().map(move |m| format!("{name} {}", m.label())))
            .collect()
    }
}

fn setup(args: &StabilityArgs) -> Result<Setup> {
    if args.frames < 2 {
        bail!("--frames must be at least 2 (flicker compares consecutive frames)");
    }
    if args.reference_spp == 0 || args.pt_spp == 0 {
        bail!("--reference-spp and --pt-spp must be at least 1");
    }
    let methods = parse_methods(&args.methods, &args.restir.settings())?;
    let paths = if args.scenes.is_empty() {
        bundled_scene_paths()
    } else {
        args.scenes.clone()
    };
    let base = RenderSettings {
        width: args.width,
        height: args.height,
        max_depth: args.max_depth,
        seed: args.seed,
        ..Default::default()
    };
    let mut scenes = vec![];
    for path in &paths {
        let scene = load_with_warnings(path)?;
        base.validate(&SceneInfo::of(&scene)).with_context(|| path.display().to_string())?;
        scenes.push((scene_name(path), scene));
    }
    for m in &methods {
        if let MethodSpec::Restir(r) = m {
            r.validate(args.max_depth)?;
        }
    }
    let dir = &args.out_dir;
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create the output folder", dir.display()))?;
    Ok(Setup { methods, scenes, base })
}

pub fn stability(args: StabilityArgs) -> Result<Vec<StabilityRow>> {
    let mode = args.sweep.mode()?;
    let setup = setup(&args)?;
    let dir = &args.out_dir;
    let rows = match &mode {
        SweepMode::Plan(plan) => {
            write_plan(plan, &argv(), &setup.labels(), dir)?;
            return Ok(vec![]);
        }
        SweepMode::Job(k) => return run_job(&args, &setup, *k, dir),
        SweepMode::Merge(jobs) => merge(&setup, jobs, dir)?,
        SweepMode::All => run_all(&args, &setup)?,
    };
    write_results(&args, &setup, &rows)?;
    Ok(rows)
}

/// Every method on every scene in this process.
fn run_all(args: &StabilityArgs, setup: &Setup) -> Result<Vec<StabilityRow>> {
    let ctx = open_device(&args.device)?;
    let mut rows = vec![];
    for (name, scene) in &setup.scenes {
        let scene = SceneGpu::upload(&ctx, scene)?;
        let mut references = setup.references(args, &scene)?;
        for method in &setup.methods {
            rows.extend(run_method(args, setup, name, &scene, method, &mut references)?.0);
        }
    }
    finish_device(&ctx)?;
    Ok(rows)
}

/// One method on one scene, static then moving camera. Returns the rows, their GPU ms and the
/// renderer's kernel compile ms.
fn run_method(
    args: &StabilityArgs,
    setup: &Setup,
    name: &str,
    scene: &Arc<SceneGpu>,
    method: &MethodSpec,
    references: &mut References,
) -> Result<(Vec<StabilityRow>, f64, f64)> {
    let settings = RenderSettings {
        spp: args.pt_spp,
        ..setup.base.clone()
    };
    let mut renderer = MethodRenderer::new(scene, &settings, method)?;
    let (mut rows, mut gpu_ms) = (vec![], 0.0);
    for motion in [CameraMotion::Static, CameraMotion::Moving] {
        renderer.reset(&settings)?;
        let mut previous: Option<Vec<Vec3>> = None;
        for frame in 0..args.frames {
            let camera = motion.camera(frame, scene.info().cameras.len());
            let (outcome, image) = renderer.frame(&settings, camera, frame)?;
            gpu_ms += outcome.gpu_ms;
            let reference = references.get(camera)?;
            rows.push(StabilityRow {
                scene: name.to_string(),
                method: method.label(),
                motion,
                frame,
                nonfinite_pixels: image.non_finite_count(),
                energy_ratio: energy_ratio(&image.mean, reference),
                rel_mse: rel_mse(&image.mean, reference),
                flicker: match (motion, &previous) {
                    (CameraMotion::Static, Some(p)) => Some(flicker(p, &image.mean, reference)),
                    _ => None,
                },
                failed_shift_rate: outcome.failed_shift_rate,
            });
            previous = Some(image.mean);
        }
    }
    Ok((rows, gpu_ms, renderer.compile_ms()))
}

/// Job K: method K % methods on scene K / methods, into `<out_dir>/jobs/job_K.csv/.json`.
fn run_job(args: &StabilityArgs, setup: &Setup, k: usize, out_dir: &Path) -> Result<Vec<StabilityRow>> {
    let labels = setup.labels();
    let dir = start_job(k, labels.len(), out_dir)?;
    let start = Instant::now();
    let (name, scene) = &setup.scenes[k / setup.methods.len()];
    let method = &setup.methods[k % setup.methods.len()];
    let ctx = open_device(&args.device)?;
    let scene = SceneGpu::upload(&ctx, scene)?;
    let mut references = setup.references(args, &scene)?;
    let (rows, gpu_ms, compile_ms) = run_method(args, setup, name, &scene, method, &mut references)?;
    let report = JobReport {
        job: k,
        jobs: labels.len(),
        label: labels[k].clone(),
        device: ctx.info.name.clone(),
        commit: COMMIT.to_string(),
        wall_ms: 0.0,
        gpu_ms: gpu_ms + references.gpu_ms,
        compile_ms: compile_ms + references.tracer.compile_report().total_ms(),
    };
    drop(references);
    finish_device(&ctx)?;
    write_csv(&job_file(&dir, k, "csv"), &rows)?;
    write_job_report(
        &dir,
        &JobReport {
            wall_ms: start.elapsed().as_secs_f64() * 1e3,
            ..report
        },
    )?;
    Ok(rows)
}

fn merge(setup: &Setup, jobs_dir: &Path, out_dir: &Path) -> Result<Vec<StabilityRow>> {
    let jobs = setup.labels().len();
    let reports = read_job_reports(jobs_dir, jobs)?;
    let rows = read_job_rows(jobs_dir, jobs, HEADER)?
        .into_iter()
        .map(|(_, path, fields)| parse_row(&fields).with_context(|| format!("{}: a row that is not {HEADER}", path.display())))
        .collect::<Result<Vec<_>>>()?;
    write_accounting(out_dir, &reports)?;
    Ok(rows)
}

/// Summaries, charts and stability.csv of all rows; fails if any pixel was not finite.
fn write_results(args: &StabilityArgs, setup: &Setup, rows: &[StabilityRow]) -> Result<()> {
    for (name, _) in &setup.scenes {
        let scene_rows: Vec<StabilityRow> = rows.iter().filter(|r| r.scene == *name).cloned().collect();
        print_summary(&scene_rows, &setup.methods);
        write_chart(&args.out_dir, name, &scene_rows, &setup.methods)?;
    }
    let dir = &args.out_dir;
    write_csv(&dir.join("stability.csv"), rows)?;
    eprintln!("wrote stability.csv and SCENE_rel_mse.svg/png in {}", dir.display());
    let nonfinite: usize = rows.iter().map(|r| r.nonfinite_pixels).sum();
    if nonfinite > 0 {
        bail!("{nonfinite} non-finite pixels over all frames (see the summary above)");
    }
    Ok(())
}

fn parse_row(f: &[String]) -> Result<StabilityRow> {
    if f.len() != HEADER.split(',').count() {
        bail!("{} fields", f.len());
    }
    Ok(StabilityRow {
        scene: f[0].clone(),
        method: f[1].clone(),
        motion: match f[2].as_str() {
            "static" => CameraMotion::Static,
            "moving" => CameraMotion::Moving,
            other => bail!("camera '{other}'"),
        },
        frame: f[3].parse()?,
        nonfinite_pixels: f[4].parse()?,
        energy_ratio: f[5].parse()?,
        rel_mse: f[6].parse()?,
        flicker: parse_optional(&f[7])?,
        failed_shift_rate: parse_optional(&f[8])?,
    })
}

/// One line per method and camera motion.
fn print_summary(rows: &[StabilityRow], methods: &[MethodSpec]) {
    for m in methods {
        for motion in [CameraMotion::Static, CameraMotion::Moving] {
            let run: Vec<&StabilityRow> = rows.iter().filter(|r| r.method == m.label() && r.motion == motion).collect();
            let Some(last) = run.last() else { continue };
            let energies = run.iter().map(|r| r.energy_ratio);
            let (lo, hi) = energies
                .clone()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), e| (lo.min(e), hi.max(e)));
            let flicker = mean(run.iter().filter_map(|r| r.flicker));
            let failed = mean(run.iter().filter_map(|r| r.failed_shift_rate));
            println!(
                "{:<16} {:<26} {:<7} | non-finite {} | energy mean {:.4} [{lo:.3}, {hi:.3}] | relMSE last {:.4e} mean {:.4e}{}{}",
                last.scene,
                last.method,
                motion.name(),
                run.iter().map(|r| r.nonfinite_pixels).sum::<usize>(),
                mean(energies),
                last.rel_mse,
                mean(run.iter().map(|r| r.rel_mse)),
                if flicker.is_nan() {
                    String::new()
                } else {
                    format!(" | flicker {flicker:.4}")
                },
                if failed.is_nan() {
                    String::new()
                } else {
                    format!(" | failed shifts {:.2}%", 100.0 * failed)
                }
            );
        }
    }
}

fn write_chart(dir: &Path, scene: &str, rows: &[StabilityRow], methods: &[MethodSpec]) -> Result<()> {
    let mut series = vec![];
    for m in methods {
        for motion in [CameraMotion::Static, CameraMotion::Moving] {
            series.push(Series {
                name: format!("{} {}", m.label(), motion.name()),
                points: rows
                    .iter()
                    .filter(|r| r.method == m.label() && r.motion == motion)
                    .map(|r| (r.frame as f64, r.rel_mse))
                    .collect(),
            });
        }
    }
    write_line_chart(
        &dir.join(format!("{scene}_rel_mse")),
        &LineChart {
            title: &format!("{scene}: relMSE of each frame"),
            x_label: "frame",
            y_label: "relMSE",
            log_x: false,
            series: &series,
        },
    )
}

const HEADER: &str = "scene,method,camera,frame,nonfinite_pixels,energy_ratio,rel_mse,flicker,failed_shift_rate";

fn write_csv(path: &Path, rows: &[StabilityRow]) -> Result<()> {
    let mut csv = format!("{HEADER}\n");
    let optional = |v: Option<f64>| v.map(|x| format!("{x:.6}")).unwrap_or_default();
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{:.6},{:.6e},{},{}",
            r.scene,
            r.method,
            r.motion.name(),
            r.frame,
            r.nonfinite_pixels,
            r.energy_ratio,
            r.rel_mse,
            optional(r.flicker),
            optional(r.failed_shift_rate)
        );
    }
    std::fs::write(path, csv).with_context(|| format!("{}: cannot write", path.display()))
}
