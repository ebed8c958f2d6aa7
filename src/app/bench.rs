//! `restir-pt bench`: path-tracer throughput after a warm-up, median of several runs, with the
//! time of every stage of the process and the CPU time the driver's threads spent.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use serde::Serialize;

use clap::Args;

use super::args::{DeviceArgs, SceneArgs, SizeArgs, Toggle};
use super::{finish_device, load_with_options, open_device};
use restir_pt::metrics::median;
use restir_pt::render::{PathTracer, RenderSettings, SceneGpu, SceneInfo, TraversalCounters};

/// `restir-pt bench`.
#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub size: SizeArgs,
    /// Samples per pixel of each run.
    #[arg(long, default_value_t = 16)]
    pub spp: u32,
    /// Maximum number of path segments, as in `render`.
    #[arg(long, default_value_t = RenderSettings::DEFAULT_MAX_DEPTH)]
    pub max_depth: u32,
    /// Russian roulette from the third segment on, as in `render`.
    #[arg(long, value_enum, default_value_t = Toggle::On)]
    pub russian_roulette: Toggle,
    /// Timed runs after one warm-up run.
    #[arg(long, default_value_t = 5)]
    pub runs: u32,
    /// Count rays, BVH node visits, triangle tests and SIMD lane use in the kernel (slower:
    /// a profile, not a timing).
    #[arg(long)]
    pub counters: bool,
    /// Write the figures as JSON to this file.
    #[arg(long)]
    pub report: Option<PathBuf>,
    #[command(flatten)]
    pub device: DeviceArgs,
}

/// Seconds of CPU time (user + system) this process has used so far, all threads together.
pub fn process_cpu_seconds() -> f64 {
    let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage writes a complete rusage into the buffer it is given.
    let usage = unsafe {
        if libc::getrusage(libc::RUSAGE_SELF, usage.as_mut_ptr()) != 0 {
            return 0.0;
        }
        usage.assume_init()
    };
    let secs = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    secs(usage.ru_utime) + secs(usage.ru_stime)
}

/// Wall and CPU seconds of one stage of the process.
#[derive(Serialize, Clone, Copy)]
struct StageTime {
    wall_s: f64,
    cpu_s: f64,
}

struct Stopwatch {
    wall: Instant,
    cpu: f64,
}

impl Stopwatch {
    fn start() -> Self {
        Self {
            wall: Instant::now(),
            cpu: process_cpu_seconds(),
        }
    }
    fn lap(&mut self) -> StageTime {
        let next = Self::start();
        let t = StageTime {
            wall_s: (next.wall - self.wall).as_secs_f64(),
            cpu_s: next.cpu - self.cpu,
        };
        *self = next;
        t
    }
}

#[derive(Serialize)]
struct BenchReport {
    device: String,
    scene: String,
    triangles: usize,
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
    /// Paths per second of CPU time (all driver threads): the throughput a contended machine
    /// still measures faithfully.
    median_paths_per_cpu_second: f64,
    /// Scene loading with the BVH build, device creation, kernel compilation with the warm-up
    /// render, the timed renders, and the whole process up to the report.
    stage_load: StageTime,
    stage_device: StageTime,
    stage_warm_up: StageTime,
    stage_timed_runs: StageTime,
    whole_process: StageTime,
    counters: Option<TraversalCounters>,
}

pub fn bench(args: BenchArgs) -> Result<()> {
    let mut whole = Stopwatch::start();
    // CPU time before bench() (argument parsing, loader start-up) belongs to the process too.
    whole.cpu = 0.0;
    let mut lap = Stopwatch::start();
    let path = args.scene.path()?;
    let scene = load_with_options(&path, &args.scene.load_options(None))?;
    let settings = RenderSettings {
        width: args.size.width,
        height: args.size.height,
        spp: args.spp,
        max_depth: args.max_depth,
        russian_roulette: args.russian_roulette.on(),
        ..Default::default()
    };
    settings.validate(&SceneInfo::of(&scene))?;
    let stage_load = lap.lap();
    if args.runs == 0 {
        bail!("--runs must be at least 1");
    }
    let runs = args.runs;
    let ctx = open_device(&args.device)?;
    let stage_device = lap.lap();
    let scene_gpu = SceneGpu::upload(&ctx, &scene)?;
    let mut tracer = PathTracer::with_counters(&scene_gpu, &settings, args.counters)?;
    let Runs {
        rates,
        gpu_ms,
        cpu_rates,
        counters,
        stage_warm_up,
    } = timed_runs(&mut tracer, &settings, runs, &mut lap)?;
    let stage_timed_runs = lap.lap();
    drop(tracer);
    drop(scene_gpu);
    finish_device(&ctx)?;
    let report = BenchReport {
        device: ctx.info.name.clone(),
        scene: path.display().to_string(),
        triangles: scene.triangles.len(),
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
        median_paths_per_cpu_second: median(&cpu_rates),
        stage_load,
        stage_device,
        stage_warm_up,
        stage_timed_runs,
        whole_process: whole.lap(),
        counters,
    };
    print_report(&report);
    if let Some(r) = &args.report {
        std::fs::write(r, serde_json::to_string_pretty(&report)?).with_context(|| format!("{}: cannot write the report", r.display()))?;
    }
    Ok(())
}

/// The figures of the timed renders.
struct Runs {
    rates: Vec<f64>,
    gpu_ms: Vec<f64>,
    cpu_rates: Vec<f64>,
    counters: Option<TraversalCounters>,
    stage_warm_up: StageTime,
}

/// One warm-up render (llvmpipe compiles the pipeline at its first dispatch), timed by `lap`,
/// then `runs` timed renders with seeds 1..=runs.
fn timed_runs(tracer: &mut PathTracer, settings: &RenderSettings, runs: u32, lap: &mut Stopwatch) -> Result<Runs> {
    let never = AtomicBool::new(false);
    let (mut rates, mut gpu_ms, mut cpu_rates) = (Vec::new(), Vec::new(), Vec::new());
    let mut counters: Option<TraversalCounters> = None;
    let mut stage_warm_up = None;
    for run in 0..=runs {
        tracer.restart(&RenderSettings {
            seed: run,
            ..settings.clone()
        })?;
        let cpu0 = process_cpu_seconds();
        let stats = tracer.render(&|_| {}, &never)?;
        let cpu_s = process_cpu_seconds() - cpu0;
        if run == 0 {
            stage_warm_up = Some(lap.lap());
            continue;
        }
        let rate = stats.paths_per_second(settings.pixel_count());
        let paths = settings.pixel_count() as f64 * stats.spp as f64;
        eprintln!(
            "run {run}: {:.1} ms GPU, {:.1} ms wall, {:.1} ms CPU, {:.3} M paths/s, {:.3} M paths per CPU second",
            stats.gpu_ms,
            stats.wall_ms,
            cpu_s * 1e3,
            rate * 1e-6,
            paths / cpu_s * 1e-6
        );
        rates.push(rate);
        gpu_ms.push(stats.gpu_ms);
        cpu_rates.push(paths / cpu_s);
        if let Some(c) = stats.counters {
            counters.get_or_insert_with(TraversalCounters::default).add(&c);
        }
    }
    Ok(Runs {
        rates,
        gpu_ms,
        cpu_rates,
        counters,
        stage_warm_up: stage_warm_up.expect("run 0 is the warm-up"),
    })
}

fn print_report(r: &BenchReport) {
    let stage = |name: &str, t: &StageTime| eprintln!("{name:<28} {:>8.2} s wall {:>8.2} s CPU", t.wall_s, t.cpu_s);
    stage("load scene + build BVH", &r.stage_load);
    stage("open device", &r.stage_device);
    stage("compile kernel + warm-up", &r.stage_warm_up);
    stage(&format!("{} timed runs", r.runs), &r.stage_timed_runs);
    stage("whole process", &r.whole_process);
    if let Some(c) = &r.counters {
        c.print(r.width as u64 * r.height as u64 * r.spp as u64 * r.runs as u64);
    }
    println!(
        "{} | {} {}x{} | {} spp | depth {} | median of {} runs: {:.3} M paths/s (min {:.3}, max {:.3}), {:.3} M paths per CPU second",
        r.device,
        r.scene,
        r.width,
        r.height,
        r.spp,
        r.max_depth,
        r.runs,
        r.median_paths_per_second * 1e-6,
        r.min_paths_per_second * 1e-6,
        r.max_paths_per_second * 1e-6,
        r.median_paths_per_cpu_second * 1e-6
    );
}
