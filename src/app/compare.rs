//! `restir-pt compare`: error against GPU time per frame for each method, at equal time budgets,
//! against a path-traced reference. Writes results.csv, error-against-time charts (SVG and PNG)
//! and an equal-time image strip with insets.

use std::cell::Cell;
use std::path::PathBuf;

use anyhow::{bail, Context as _, Result};
use glam::Vec3;

use clap::Args;

use super::args::{DeviceArgs, PathArgs, RestirArgs, SweepArgs};
use super::compare_outputs::write_outputs;
use super::method_spec::{parse_methods, MethodRenderer, MethodSpec, DEFAULT_METHODS};
use super::reference_record::check_reference;
use super::render_output::status_spinner;
use super::sweep::SweepMode;
use super::{finish_device, load_with_warnings, open_device, scene_path};
use restir_pt::image_io::read_exr;
use restir_pt::metrics::{energy_ratio, hdr_flip, mape, median, mse, rel_mse, rel_mse_trimmed, standard_error, TRIMMED_SHARE};
use restir_pt::render::{Image, RenderSettings, SceneGpu, SceneInfo, MAX_RESERVOIRS};
use restir_pt::scene::{camera_on_path, Scene};

/// `restir-pt compare`.
#[derive(Args, Debug, Clone)]
pub struct CompareArgs {
    /// glTF 2.0 scene (.gltf or .glb).
    pub scene: PathBuf,
    /// Path-traced reference EXR (see `reference`); it sets the resolution.
    #[arg(long)]
    pub reference: PathBuf,
    /// Methods: pt, restir (the ReSTIR options' settings), restir:reconnection|replay|hybrid,
    /// each ReSTIR form optionally with /gbh or /pairwise and @sK (K spatial neighbours; @s0:
    /// spatial reuse off), e.g. pt,restir,restir@s0.
    #[arg(long, value_delimiter = ',', default_value = DEFAULT_METHODS)]
    pub methods: Vec<String>,
    /// GPU ms per frame (default: ReSTIR PT's cheapest frame times 1.05, 2.1 and 4.2). Each method
    /// spends a budget on path-tracer spp or ReSTIR PT reservoirs per pixel (each with --candidates paths).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub budgets_ms: Vec<f64>,
    /// Frames per run; the error is measured on the last frame alone.
    #[arg(long, default_value_t = 16)]
    pub frames: u32,
    /// Move the camera along the scene's camera path from --camera (as `render --frames` does)
    /// instead of keeping it still; --reference must then be of the last frame's camera, which
    /// the command prints.
    #[arg(long)]
    pub camera_path: bool,
    /// Independent runs per method and budget (errors averaged, times median).
    #[arg(long, default_value_t = 1)]
    pub trials: u32,
    #[command(flatten)]
    pub path: PathArgs,
    #[command(flatten)]
    pub restir: RestirArgs,
    /// Folder for results.csv, the charts and equal_time.png.
    #[arg(long, default_value = "out/compare")]
    pub out_dir: PathBuf,
    #[command(flatten)]
    pub sweep: SweepArgs,
    #[command(flatten)]
    pub device: DeviceArgs,
}

/// One method at one budget.
pub struct CompareRow {
    pub method: String,
    pub budget_ms: f64,
    /// The cost knob chosen to fit the budget: path-tracer spp or ReSTIR PT reservoirs.
    pub knob: String,
    pub gpu_ms_per_frame: f64,
    pub rel_mse: f64,
    /// Standard error of `rel_mse`, the mean over trials (metrics::standard_error); None for
    /// one trial.
    pub rel_mse_stderr: Option<f64>,
    /// relMSE without the largest 0.1% of pixel errors (metrics::rel_mse_trimmed).
    pub rel_mse_trimmed: f64,
    pub mse: f64,
    pub energy_ratio: f64,
    pub failed_shift_rate: Option<f64>,
    pub nonfinite_pixels: usize,
    /// Mean absolute percentage error (metrics::mape), the mean over trials.
    pub mape: f64,
    /// HDR-ꟻLIP (metrics::hdr_flip), the mean over trials.
    pub hdr_flip: f64,
    /// The frame's GPU time in path-tracer samples per pixel of the same scene, size and
    /// camera, measured in the same process: `gpu_ms_per_frame` over the path tracer's ms per
    /// sample (the slope of its calibration, `Cost::Affine::per_sample`). None where the run
    /// has no `pt` method (each `--job` of a sweep runs one method).
    pub pt_samples_per_frame: Option<f64>,
}

/// A method's frame cost, measured after its kernels are compiled.
pub(super) enum Cost {
    /// Path tracing: GPU ms per frame of its own and per sample per pixel. A frame's fixed cost
    /// (about 7 ms, cornell-glossy at 64x64 on llvmpipe) is not small beside a sample (about
    /// 6 ms): a cost of 8 spp over 8 gave 2 spp a 21 ms budget and they took 30 ms.
    Affine { fixed: f64, per_sample: f64 },
    /// ReSTIR PT: GPU ms per frame with 1, 2, ... reservoirs per pixel, each measured: a
    /// straight line through 1 and 4 reservoirs once gave 2 reservoirs where 3 fitted, their
    /// cost not being linear (cornell-glossy, 64x64: 14.5 ms for one, 67 ms for four).
    PerReservoirs(Vec<f64>),
}

impl Cost {
    /// What was measured, for the calibration line.
    fn describe(&self) -> String {
        match self {
            Cost::Affine { fixed, per_sample } => format!("{fixed:.1} ms per frame + {per_sample:.2} ms per spp"),
            Cost::PerReservoirs(ms) => format!("{:.1} ms per frame with 1 reservoir per pixel", ms[0]),
        }
    }

    /// The knob value that fits `budget_ms`, or None if even the cheapest frame does not.
    fn fit(&self, budget_ms: f64) -> Option<u32> {
        match self {
            Cost::Affine { fixed, per_sample } => Some((((budget_ms - fixed) / per_sample).floor().max(1.0)) as u32),
            Cost::PerReservoirs(ms) => ms.iter().rposition(|&t| t <= budget_ms).map(|i| i as u32 + 1),
        }
    }
}

/// Frames per cost measurement, whose median is taken: on a shared machine single frames of
/// one setting vary by half (cornell-glossy, 64x64: 14.4 to 21.5 ms), and a cost read from
/// three frames once filled half a budget.
const CALIBRATION_FRAMES: u32 = 8;

pub(super) struct Run<'a> {
    /// Cameras of the scene, for the camera path.
    pub camera_count: usize,
    pub settings: &'a RenderSettings,
    pub camera_path: bool,
    /// Samples per pixel of the reference, from its record.
    pub reference_spp: Option<u32>,
    /// GPU ms of every frame rendered so far (calibration included), for the job's accounting.
    pub gpu_ms: Cell<f64>,
    /// The path tracer's GPU ms per sample per pixel, once a `pt` method is calibrated.
    pub pt_ms_per_sample: Cell<Option<f64>>,
}

/// What `Run::sequence` measured.
struct Sequence {
    gpu_ms_per_frame: f64,
    failed_shift_rate: Option<f64>,
    last_frame: Image,
}

impl<'a> Run<'a> {
    pub(super) fn new(camera_count: usize, settings: &'a RenderSettings, camera_path: bool, reference_spp: Option<u32>) -> Self {
        Run {
            camera_count,
            settings,
            camera_path,
            reference_spp,
            gpu_ms: Cell::new(0.0),
            pt_ms_per_sample: Cell::new(None),
        }
    }

    /// The camera of frame `frame`.
    pub(super) fn camera(&self, frame: u32) -> usize {
        if self.camera_path {
            camera_on_path(self.settings.camera, frame, self.camera_count)
        } else {
            self.settings.camera
        }
    }

    /// `frames` frames from one seed: the median GPU ms per frame (from the second frame on,
    /// once ReSTIR has a history), the failed-shift rate, and the last frame.
    fn sequence(&self, renderer: &mut MethodRenderer, frames: u32, seed: u32) -> Result<Sequence> {
        let settings = RenderSettings {
            seed,
            ..self.settings.clone()
        };
        renderer.reset(&settings)?;
        let (mut times, mut failed, mut last) = (vec![], vec![], None);
        for f in 0..frames {
            let (outcome, image) = renderer.frame(&settings, self.camera(f), f)?;
            self.gpu_ms.set(self.gpu_ms.get() + outcome.gpu_ms);
            if f > 0 || frames == 1 {
                times.push(outcome.gpu_ms);
            }
            failed.extend(outcome.failed_shift_rate);
            last = Some(image);
        }
        Ok(Sequence {
            gpu_ms_per_frame: median(&times),
            failed_shift_rate: (!failed.is_empty()).then(|| failed.iter().sum::<f64>() / failed.len() as f64),
            last_frame: last.expect("at least one frame"),
        })
    }

    /// Measures a method's frame cost: the path tracer's per sample, ReSTIR PT's with one
    /// reservoir. The first run compiles the kernels (llvmpipe compiles at the first dispatch)
    /// and is not counted.
    pub(super) fn calibrate(&self, renderer: &mut MethodRenderer) -> Result<Cost> {
        match renderer {
            MethodRenderer::PathTracing(..) => {
                renderer.set_cost_knob(1)?;
                self.sequence(renderer, 1, 0)?;
                let one = self.sequence(renderer, CALIBRATION_FRAMES, 0)?.gpu_ms_per_frame;
                const SAMPLES: u32 = 8;
                renderer.set_cost_knob(SAMPLES)?;
                let more = self.sequence(renderer, CALIBRATION_FRAMES, 0)?.gpu_ms_per_frame;
                let per_sample = ((more - one) / (SAMPLES - 1) as f64).max(0.1 * more / SAMPLES as f64);
                self.pt_ms_per_sample.set(Some(per_sample));
                Ok(Cost::Affine {
                    fixed: (one - per_sample).max(0.0),
                    per_sample,
                })
            }
            MethodRenderer::Restir(_) => {
                renderer.set_cost_knob(1)?;
                self.sequence(renderer, CALIBRATION_FRAMES, 0)?;
                Ok(Cost::PerReservoirs(vec![
                    self.sequence(renderer, CALIBRATION_FRAMES, 0)?.gpu_ms_per_frame,
                ]))
            }
        }
    }

    /// The cost model is measured before the runs, and a shared machine's speed drifts (the path
    /// tracer's 10 spp, fitted to 65 ms, once took 84 ms; 2 reservoirs fitted to 40 ms took 27):
    /// short runs move `knob` in proportion to the budget over their time, down while they
    /// overrun `budget_ms`, up while one more unit would fit, never back to a knob that overran.
    /// Returns the knob, set.
    fn fit_to_budget(&self, renderer: &mut MethodRenderer, mut knob: u32, budget_ms: f64, frames: u32) -> Result<u32> {
        let check_frames = CALIBRATION_FRAMES.min(frames.max(2));
        let mut overran = renderer.max_cost_knob() + 1;
        knob = knob.min(renderer.max_cost_knob());
        loop {
            renderer.set_cost_knob(knob)?;
            let ms = self.sequence(renderer, check_frames, 0)?.gpu_ms_per_frame;
            let scaled = (knob as f64 * budget_ms / ms).floor() as u32;
            if ms > budget_ms {
                overran = knob;
                if knob == 1 {
                    return Ok(knob);
                }
                knob = scaled.clamp(1, knob - 1);
            } else if knob + 1 < overran && ms * (knob + 1) as f64 / knob as f64 <= budget_ms {
                knob = scaled.clamp(knob + 1, overran - 1);
            } else {
                return Ok(knob);
            }
        }
    }

    /// Measures ReSTIR PT frames with more reservoirs until one costs over `max_budget_ms` or
    /// the most reservoirs are measured. Returns the frame ms of the most reservoirs when even
    /// they fit: larger budgets then run with the most and leave time unspent.
    pub(super) fn extend(&self, renderer: &mut MethodRenderer, cost: &mut Cost, max_budget_ms: f64) -> Result<Option<f64>> {
        let Cost::PerReservoirs(ms) = cost else {
            return Ok(None);
        };
        while ms.last().is_some_and(|&t| t <= max_budget_ms) && ms.len() < MAX_RESERVOIRS as usize {
            renderer.set_cost_knob(ms.len() as u32 + 1)?;
            ms.push(self.sequence(renderer, CALIBRATION_FRAMES, 0)?.gpu_ms_per_frame);
        }
        Ok(ms
            .last()
            .copied()
            .filter(|&t| t <= max_budget_ms && ms.len() == MAX_RESERVOIRS as usize))
    }
}

/// The notice that a method's reservoirs per pixel are capped below a budget.
pub(super) fn reservoir_cap_note(label: &str, most_ms: f64) -> String {
    format!(
        "note: {label}: {MAX_RESERVOIRS} reservoirs per pixel (the most) take {most_ms:.1} ms per frame; budgets above that run with {MAX_RESERVOIRS} and leave time unspent"
    )
}

/// What every mode of `compare` reads and checks before it opens a device.
pub(super) struct Setup {
    pub path: PathBuf,
    pub scene: Scene,
    pub width: u32,
    pub height: u32,
    pub reference: Vec<Vec3>,
    pub methods: Vec<MethodSpec>,
    pub settings: RenderSettings,
    /// Samples per pixel of the reference, from its record.
    pub reference_spp: Option<u32>,
}

impl Setup {
    pub(super) fn run(&self, camera_path: bool) -> Run<'_> {
        Run::new(self.scene.cameras.len(), &self.settings, camera_path, self.reference_spp)
    }
}

fn setup(args: &CompareArgs) -> Result<Setup> {
    if args.frames == 0 || args.trials == 0 {
        bail!("--frames and --trials must be at least 1");
    }
    if let Some(b) = args.budgets_ms.iter().find(|b| !(**b > 0.0) || !b.is_finite()) {
        bail!("--budgets-ms {b}: a budget must be a positive number of milliseconds");
    }
    let path = scene_path(Some(&args.scene))?;
    let scene = load_with_warnings(&path)?;
    let (width, height, reference) = read_exr(&args.reference)?;
    if let Some(i) = reference.iter().position(|p| !p.is_finite()) {
        bail!(
            "{}: the reference has a non-finite pixel ({}, {})",
            args.reference.display(),
            i as u32 % width,
            i as u32 / width
        );
    }
    let methods = parse_methods(&args.methods, &args.restir.settings())?;
    let settings = RenderSettings {
        width,
        height,
        spp: 1,
        max_depth: args.path.max_depth,
        seed: args.path.seed,
        camera: args.path.camera,
        russian_roulette: args.path.russian_roulette.on(),
    };
    settings.validate(&SceneInfo::of(&scene))?;
    for m in &methods {
        if let MethodSpec::Restir(r) = m {
            r.validate(settings.max_depth).with_context(|| format!("--methods {}", m.label()))?;
        }
    }
    // The error is measured on the last frame, seen from this camera.
    let last_camera = if args.camera_path {
        camera_on_path(args.path.camera, args.frames - 1, scene.cameras.len())
    } else {
        args.path.camera
    };
    let reference_spp = check_reference(&args.reference, &path, last_camera, (width, height))?.map(|r| r.spp);
    std::fs::create_dir_all(&args.out_dir).with_context(|| format!("{}: cannot create the output folder", args.out_dir.display()))?;
    Ok(Setup {
        path,
        scene,
        width,
        height,
        reference,
        methods,
        settings,
        reference_spp,
    })
}

/// Runs every method at every budget; returns the rows and writes the CSV, charts and strip.
/// With `args.sweep` other than `All`, writes the job list, runs one job, or merges the jobs'
/// results instead (compare_sweep.rs).
pub fn compare(args: CompareArgs) -> Result<Vec<CompareRow>> {
    let mode = args.sweep.mode()?;
    let setup = setup(&args)?;
    match &mode {
        SweepMode::All => compare_all(&args, &setup),
        mode => super::compare_sweep::compare_sweep(&args, &setup, mode),
    }
}

/// Prints which camera the last frame sees when the camera moves.
pub(super) fn note_camera_path(args: &CompareArgs, run: &Run) {
    if args.camera_path {
        eprintln!(
            "camera path: frame {} sees camera {}; {} must be a reference of that camera",
            args.frames - 1,
            run.camera(args.frames - 1),
            args.reference.display()
        );
    }
}

fn compare_all(args: &CompareArgs, setup: &Setup) -> Result<Vec<CompareRow>> {
    let ctx = open_device(&args.device)?;
    let run = setup.run(args.camera_path);
    note_camera_path(args, &run);
    let progress = status_spinner();
    let scene = SceneGpu::upload(&ctx, &setup.scene)?;
    let mut renderers = vec![];
    for m in &setup.methods {
        progress.set_message(format!("compiling and calibrating {}", m.label()));
        let mut renderer = MethodRenderer::new(&scene, &setup.settings, m)?;
        let cost = run.calibrate(&mut renderer)?;
        progress.suspend(|| eprintln!("{}: {}", m.label(), cost.describe()));
        renderers.push((m.label(), renderer, cost));
    }
    let budgets = default_budgets(args, &renderers);
    let max_budget = budgets.iter().copied().fold(0.0, f64::max);
    for (label, renderer, cost) in &mut renderers {
        progress.set_message(format!("calibrating {label} with more reservoirs"));
        if let Some(most_ms) = run.extend(renderer, cost, max_budget)? {
            progress.suspend(|| eprintln!("{}", reservoir_cap_note(label, most_ms)));
        }
    }
    progress.finish_and_clear();

    let mut rows = vec![];
    let mut images: Vec<(String, f64, Image)> = vec![];
    for (label, renderer, cost) in &mut renderers {
        for &budget in &budgets {
            if let Some((row, image)) = measure(&run, renderer, cost, label, budget, &setup.reference, args)? {
                images.push((label.clone(), budget, image));
                rows.push(row);
            }
        }
    }
    drop(renderers);
    finish_device(&ctx)?;
    write_outputs(args, setup, &budgets, &rows, &images, &ctx.info.name)?;
    Ok(rows)
}

/// --budgets-ms, or ReSTIR PT's cheapest frame (of all ReSTIR methods) times 1.05, 2.1 and 4.2
/// (10, 20 and 40 ms without a ReSTIR method).
fn default_budgets(args: &CompareArgs, renderers: &[(String, MethodRenderer, Cost)]) -> Vec<f64> {
    if args.budgets_ms.is_empty() {
        let cheapest_restir = renderers
            .iter()
            .filter_map(|(_, _, c)| match c {
                Cost::PerReservoirs(ms) => Some(ms[0]),
                Cost::Affine { .. } => None,
            })
            .fold(f64::INFINITY, f64::min);
        let unit = if cheapest_restir.is_finite() {
            cheapest_restir * 1.05
        } else {
            10.0
        };
        vec![unit, 2.0 * unit, 4.0 * unit]
    } else {
        args.budgets_ms.clone()
    }
}

/// A reference needs several times the samples of the frames measured against it, or its own
/// noise becomes a large part of their measured error.
const REFERENCE_SPP_FACTOR: u32 = 4;

fn warn_noisy_reference(renderer: &MethodRenderer, knob: u32, reference_spp: Option<u32>, label: &str, budget: f64) {
    if let (MethodRenderer::PathTracing(..), Some(reference)) = (renderer, reference_spp) {
        if knob.saturating_mul(REFERENCE_SPP_FACTOR) > reference {
            eprintln!(
                "warning: {label} at {budget:.1} ms renders {knob} spp per frame against a reference of {reference} spp: the reference's own noise is a large part of the measured error (render it with at least {REFERENCE_SPP_FACTOR}x the spp)"
            );
        }
    }
}

/// One method at one budget: fits its knob, runs the trials and prints the row. None if even
/// the method's cheapest frame does not fit. The image is the last trial's last frame.
pub(super) fn measure(
    run: &Run,
    renderer: &mut MethodRenderer,
    cost: &Cost,
    label: &str,
    budget: f64,
    reference: &[Vec3],
    args: &CompareArgs,
) -> Result<Option<(CompareRow, Image)>> {
    let Some(knob) = cost.fit(budget) else {
        eprintln!("{label}: skipped at {budget:.1} ms, its cheapest frame does not fit");
        return Ok(None);
    };
    let knob = run.fit_to_budget(renderer, knob, budget, args.frames)?;
    warn_noisy_reference(renderer, knob, run.reference_spp, label, budget);
    let (mut times, mut rels, mut trimmed, mut abs, mut energy, mut failed, mut nonfinite) = (vec![], vec![], 0.0, 0.0, 0.0, None, 0);
    let (mut percentage, mut flip) = (0.0, 0.0);
    let mut last = None;
    let share = 1.0 / args.trials as f64;
    for t in 0..args.trials {
        let seq = run.sequence(renderer, args.frames, args.path.seed.wrapping_add(1 + t))?;
        let image = &seq.last_frame;
        times.push(seq.gpu_ms_per_frame);
        rels.push(rel_mse(&image.mean, reference));
        trimmed += rel_mse_trimmed(&image.mean, reference, TRIMMED_SHARE) * share;
        abs += mse(&image.mean, reference) * share;
        energy += energy_ratio(&image.mean, reference) * share;
        percentage += mape(&image.mean, reference) * share;
        flip += hdr_flip(&image.mean, reference, image.width, image.height) * share;
        failed = seq.failed_shift_rate.map(|f| failed.unwrap_or(0.0) + f / args.trials as f64);
        nonfinite += seq.last_frame.non_finite_count();
        last = Some(seq.last_frame);
    }
    let row = CompareRow {
        method: label.to_string(),
        budget_ms: budget,
        knob: format!("{}={knob}", renderer.cost_knob_name()),
        gpu_ms_per_frame: median(&times),
        rel_mse: rels.iter().sum::<f64>() / rels.len() as f64,
        rel_mse_stderr: standard_error(&rels),
        rel_mse_trimmed: trimmed,
        mse: abs,
        energy_ratio: energy,
        failed_shift_rate: failed,
        nonfinite_pixels: nonfinite,
        mape: percentage,
        hdr_flip: flip,
        pt_samples_per_frame: run.pt_ms_per_sample.get().map(|per_sample| median(&times) / per_sample),
    };
    println!(
        "{:<28} budget {:>8.1} ms | {:<14} | {:>8.2} ms/frame{} | relMSE {:.4e}{} (trimmed {:.4e}) | MAPE {:.4} | HDR-FLIP {:.4} | MSE {:.4e} | energy {:.4}{}",
        row.method,
        budget,
        row.knob,
        row.gpu_ms_per_frame,
        row.pt_samples_per_frame.map(|s| format!(" ({s:.2} PT spp)")).unwrap_or_default(),
        row.rel_mse,
        row.rel_mse_stderr.map(|e| format!(" ± {e:.1e}")).unwrap_or_default(),
        row.rel_mse_trimmed,
        row.mape,
        row.hdr_flip,
        row.mse,
        row.energy_ratio,
        row.failed_shift_rate
            .map(|f| format!(" | failed shifts {:.2}%", 100.0 * f))
            .unwrap_or_default()
    );
    if row.nonfinite_pixels > 0 {
        eprintln!(
            "warning: {} at {budget} ms: {} non-finite pixels in its last frames (results.csv)",
            row.method, row.nonfinite_pixels
        );
    }
    Ok(Some((row, last.expect("at least one trial"))))
}
