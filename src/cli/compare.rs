//! `restir-pt compare`: error against GPU time per frame for each method, at equal time budgets,
//! against a path-traced reference. Writes results.csv, error-against-time charts (SVG and PNG)
//! and an equal-time image strip with insets.

use std::cell::Cell;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};
use glam::Vec3;

use super::method_spec::{parse_methods, MethodRenderer, MethodSpec};
use super::sweep::SweepMode;
use super::{finish_device, load_with_warnings, open_device, scene_path, DeviceArgs};
use crate::charts::{write_image_strip, write_line_chart, Inset, LineChart, Series, StripPanel};
use crate::image_io::read_exr;
use crate::metrics::{energy_ratio, median, mse, rel_mse, rel_mse_trimmed, rel_squared_error, TRIMMED_SHARE};
use crate::render::{Image, RenderSettings, RestirSettings, MAX_RESERVOIRS};
use crate::scene::{camera_on_path, Scene};

pub struct CompareArgs {
    pub scene: PathBuf,
    pub reference: PathBuf,
    pub methods: Vec<String>,
    /// GPU ms per frame; empty: ReSTIR PT's one-reservoir frame cost times 1, 2 and 4.
    pub budgets_ms: Vec<f64>,
    /// Frames per run; the error is the last frame's.
    pub frames: u32,
    /// The camera moves along the scene's camera path (`camera_on_path`) instead of staying at
    /// `camera`; the reference is then of the last frame's camera.
    pub camera_path: bool,
    /// Independent runs per method and budget; errors are averaged, times are medians.
    pub trials: u32,
    pub max_depth: u32,
    pub camera: usize,
    pub seed: u32,
    pub restir: RestirSettings,
    pub out_dir: PathBuf,
    /// One process for everything, or a job list, one job of it, or the merge of its jobs.
    pub sweep: SweepMode,
    /// The command line after `restir-pt` (for the job list's commands).
    pub argv: Vec<String>,
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
    /// relMSE without the largest 0.1% of pixel errors (metrics::rel_mse_trimmed).
    pub rel_mse_trimmed: f64,
    pub mse: f64,
    pub energy_ratio: f64,
    pub failed_shift_rate: Option<f64>,
    pub nonfinite_pixels: usize,
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
    pub scene: &'a Scene,
    pub settings: &'a RenderSettings,
    pub camera_path: bool,
    /// GPU ms of every frame rendered so far (calibration included), for the job's accounting.
    pub gpu_ms: Cell<f64>,
}

/// What `Run::sequence` measured.
struct Sequence {
    gpu_ms_per_frame: f64,
    failed_shift_rate: Option<f64>,
    last_frame: Image,
}

impl Run<'_> {
    /// The camera of frame `frame`.
    pub(super) fn camera(&self, frame: u32) -> usize {
        if self.camera_path {
            camera_on_path(self.settings.camera, frame, self.scene.cameras.len())
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
        renderer.reset(self.scene, &settings)?;
        let (mut times, mut failed, mut last) = (vec![], vec![], None);
        for f in 0..frames {
            let (outcome, image) = renderer.frame(self.scene, &settings, self.camera(f), f)?;
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
    /// the most reservoirs are measured.
    pub(super) fn extend(&self, renderer: &mut MethodRenderer, cost: &mut Cost, max_budget_ms: f64) -> Result<()> {
        if let Cost::PerReservoirs(ms) = cost {
            while ms.last().is_some_and(|&t| t <= max_budget_ms) && ms.len() < MAX_RESERVOIRS as usize {
                renderer.set_cost_knob(ms.len() as u32 + 1)?;
                ms.push(self.sequence(renderer, CALIBRATION_FRAMES, 0)?.gpu_ms_per_frame);
            }
        }
        Ok(())
    }
}

/// The inset window: the square (a quarter of the image's width) where `image` is furthest
/// from the reference.
fn worst_window(image: &[Vec3], reference: &[Vec3], width: u32, height: u32) -> Inset {
    let size = (width.min(height) / 4).max(4).min(width.min(height));
    let error = |x: u32, y: u32| {
        let i = (y * width + x) as usize;
        rel_squared_error(image[i], reference[i])
    };
    let mut best = (f64::NEG_INFINITY, Inset { x: 0, y: 0, size });
    let step = (size / 2).max(1);
    for y in (0..=height - size).step_by(step as usize) {
        for x in (0..=width - size).step_by(step as usize) {
            let e: f64 = (y..y + size)
                .flat_map(|yy| (x..x + size).map(move |xx| (xx, yy)))
                .map(|(xx, yy)| error(xx, yy))
                .filter(|e| e.is_finite())
                .sum();
            if e > best.0 {
                best = (e, Inset { x, y, size });
            }
        }
    }
    best.1
}

pub(super) fn write_csv(path: &Path, rows: &[CompareRow]) -> Result<()> {
    let mut csv = String::from(
        "method,budget_ms,knob,gpu_ms_per_frame,rel_mse,rel_mse_trimmed,mse,energy_ratio,failed_shift_rate,nonfinite_pixels\n",
    );
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{:.3},{},{:.4},{:.6e},{:.6e},{:.6e},{:.5},{},{}",
            r.method,
            r.budget_ms,
            r.knob,
            r.gpu_ms_per_frame,
            r.rel_mse,
            r.rel_mse_trimmed,
            r.mse,
            r.energy_ratio,
            r.failed_shift_rate.map(|f| format!("{f:.5}")).unwrap_or_default(),
            r.nonfinite_pixels
        );
    }
    std::fs::write(path, csv).with_context(|| format!("{}: cannot write", path.display()))
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
}

impl Setup {
    pub(super) fn run(&self, camera_path: bool) -> Run<'_> {
        Run {
            scene: &self.scene,
            settings: &self.settings,
            camera_path,
            gpu_ms: Cell::new(0.0),
        }
    }
}

fn setup(args: &CompareArgs) -> Result<Setup> {
    if args.frames == 0 || args.trials == 0 {
        bail!("--frames and --trials must be at least 1");
    }
    if let Some(b) = args.budgets_ms.iter().find(|b| !(**b > 0.0) || !b.is_finite()) {
        bail!("--budgets-ms {b}: a budget must be a positive number of milliseconds");
    }
    let path = scene_path(Some(&args.scene));
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
    let methods = parse_methods(&args.methods, &args.restir)?;
    let settings = RenderSettings {
        width,
        height,
        spp: 1,
        max_depth: args.max_depth,
        seed: args.seed,
        camera: args.camera,
        ..Default::default()
    };
    settings.validate(&scene)?;
    for m in &methods {
        if let MethodSpec::Restir(r) = m {
            r.validate(settings.max_depth)?;
        }
    }
    std::fs::create_dir_all(&args.out_dir).with_context(|| format!("{}: cannot create the output folder", args.out_dir.display()))?;
    Ok(Setup {
        path,
        scene,
        width,
        height,
        reference,
        methods,
        settings,
    })
}

/// Runs every method at every budget; returns the rows and writes the CSV, charts and strip.
/// With `args.sweep` other than `All`, writes the job list, runs one job, or merges the jobs'
/// results instead (compare_sweep.rs).
pub fn compare(args: CompareArgs) -> Result<Vec<CompareRow>> {
    let setup = setup(&args)?;
    match &args.sweep {
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
    let mut renderers = vec![];
    for m in &setup.methods {
        let mut renderer = MethodRenderer::new(&ctx, &setup.scene, &setup.settings, m)?;
        let cost = run.calibrate(&mut renderer)?;
        renderers.push((m.label(), renderer, cost));
    }
    let budgets = if args.budgets_ms.is_empty() {
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
    };

    let max_budget = budgets.iter().copied().fold(0.0, f64::max);
    for (_, renderer, cost) in &mut renderers {
        run.extend(renderer, cost, max_budget)?;
    }

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
    let (mut times, mut rel, mut trimmed, mut abs, mut energy, mut failed, mut nonfinite) = (vec![], 0.0, 0.0, 0.0, 0.0, None, 0);
    let mut last = None;
    for t in 0..args.trials {
        let seq = run.sequence(renderer, args.frames, args.seed.wrapping_add(1 + t))?;
        times.push(seq.gpu_ms_per_frame);
        rel += rel_mse(&seq.last_frame.mean, reference) / args.trials as f64;
        trimmed += rel_mse_trimmed(&seq.last_frame.mean, reference, TRIMMED_SHARE) / args.trials as f64;
        abs += mse(&seq.last_frame.mean, reference) / args.trials as f64;
        energy += energy_ratio(&seq.last_frame.mean, reference) / args.trials as f64;
        failed = seq.failed_shift_rate.map(|f| failed.unwrap_or(0.0) + f / args.trials as f64);
        nonfinite += seq.last_frame.non_finite_count();
        last = Some(seq.last_frame);
    }
    let row = CompareRow {
        method: label.to_string(),
        budget_ms: budget,
        knob: format!("{}={knob}", renderer.cost_knob_name()),
        gpu_ms_per_frame: median(&times),
        rel_mse: rel,
        rel_mse_trimmed: trimmed,
        mse: abs,
        energy_ratio: energy,
        failed_shift_rate: failed,
        nonfinite_pixels: nonfinite,
    };
    println!(
        "{:<28} budget {:>8.1} ms | {:<14} | {:>8.2} ms/frame | relMSE {:.4e} (trimmed {:.4e}) | MSE {:.4e} | energy {:.4}{}",
        row.method,
        budget,
        row.knob,
        row.gpu_ms_per_frame,
        row.rel_mse,
        row.rel_mse_trimmed,
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

/// The equal-time lines, results.csv, the charts and the strip of a whole sweep; `device`
/// names the device(s) in the charts' titles.
pub(super) fn write_outputs(
    args: &CompareArgs,
    setup: &Setup,
    budgets: &[f64],
    rows: &[CompareRow],
    images: &[(String, f64, Image)],
    device: &str,
) -> Result<()> {
    for line in equal_time_lines(rows, budgets) {
        println!("{line}");
    }
    write_csv(&args.out_dir.join("results.csv"), rows)?;
    let motion = if args.camera_path { "a moving camera" } else { "a static camera" };
    let title = format!(
        "{} {}x{}, frame {} of {motion}, {device}",
        setup.path.display(),
        setup.width,
        setup.height,
        args.frames
    );
    for (metric, name, value) in [
        ("rel_mse", "relMSE", (|r: &CompareRow| r.rel_mse) as fn(&CompareRow) -> f64),
        ("mse", "MSE", |r| r.mse),
    ] {
        let series: Vec<Series> = setup
            .methods
            .iter()
            .map(|m| Series {
                name: m.label(),
                points: rows
                    .iter()
                    .filter(|r| r.method == m.label())
                    .map(|r| (r.gpu_ms_per_frame, value(r)))
                    .collect(),
            })
            .collect();
        write_line_chart(
            &args.out_dir.join(format!("{metric}_vs_time")),
            &LineChart {
                title: &title,
                x_label: "GPU ms per frame",
                y_label: name,
                log_x: true,
                series: &series,
            },
        )?;
    }
    write_strip(
        &args.out_dir.join("equal_time.png"),
        budgets,
        &setup.methods,
        images,
        &setup.reference,
        setup.width,
        setup.height,
    )?;
    eprintln!(
        "wrote results.csv, rel_mse_vs_time.svg/png, mse_vs_time.svg/png and equal_time.png in {}",
        args.out_dir.display()
    );
    Ok(())
}

/// A run whose frames took longer than this multiple of its budget is not an equal-time point:
/// the cost model fits budgets from a few calibration frames, and a method whose cost grows
/// faster than linearly with its knob can overshoot.
const OVER_BUDGET_TOLERANCE: f64 = 1.2;

/// For each budget where the path tracer and ReSTIR PT both ran within it: the path tracer's
/// relMSE over the best ReSTIR PT method's, plain and trimmed, and a line for each run left out
/// for overshooting its budget.
pub fn equal_time_lines(rows: &[CompareRow], budgets: &[f64]) -> Vec<String> {
    type Error = fn(&CompareRow) -> f64;
    let mut lines = vec![];
    for &budget in budgets {
        let within = |r: &&CompareRow| r.gpu_ms_per_frame <= OVER_BUDGET_TOLERANCE * budget;
        for r in rows.iter().filter(|r| r.budget_ms == budget && !within(r)) {
            lines.push(format!(
                "equal time {budget:.1} ms: {} left out, its frames took {:.1} ms",
                r.method, r.gpu_ms_per_frame
            ));
        }
        let lowest = |pt: bool, error: Error| {
            rows.iter()
                .filter(|r| r.budget_ms == budget && (r.method == "pt") == pt)
                .filter(within)
                .min_by(|a, b| error(a).total_cmp(&error(b)))
        };
        let plain: Error = |r| r.rel_mse;
        let trimmed: Error = |r| r.rel_mse_trimmed;
        for (name, error) in [("relMSE", plain), ("trimmed relMSE", trimmed)] {
            if let (Some(pt), Some(best)) = (lowest(true, error), lowest(false, error)) {
                lines.push(format!(
                    "equal time {budget:.1} ms, {name}: pt {:.4e} ({:.1} ms) / {} {:.4e} ({:.1} ms) = {:.2}x",
                    error(pt),
                    pt.gpu_ms_per_frame,
                    best.method,
                    error(best),
                    best.gpu_ms_per_frame,
                    error(pt) / error(best)
                ));
            }
        }
    }
    lines
}

/// The strip of the largest budget every method fit (or the largest budget run at all).
fn write_strip(
    path: &Path,
    budgets: &[f64],
    methods: &[MethodSpec],
    images: &[(String, f64, Image)],
    reference: &[Vec3],
    width: u32,
    height: u32,
) -> Result<()> {
    let complete = |b: f64| methods.iter().all(|m| images.iter().any(|(l, ib, _)| *l == m.label() && *ib == b));
    let largest_complete = budgets.iter().copied().filter(|&b| complete(b)).reduce(f64::max);
    let Some(budget) = largest_complete.or_else(|| images.iter().map(|i| i.1).reduce(f64::max)) else {
        return Ok(());
    };
    let chosen: Vec<&(String, f64, Image)> = images.iter().filter(|i| i.1 == budget).collect();
    let inset = worst_window(&chosen[0].2.mean, reference, width, height);
    let mut panels = vec![StripPanel {
        label: "reference".into(),
        pixels: reference,
    }];
    panels.extend(chosen.iter().map(|(label, _, image)| StripPanel {
        label: format!("{label} ({:.3} relMSE)", rel_mse(&image.mean, reference)),
        pixels: &image.mean,
    }));
    write_image_strip(path, width, height, &panels, inset)
}
