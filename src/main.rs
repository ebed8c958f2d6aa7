//! Command-line parsing only; the commands live in `restir_pt::cli`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::Vec3;
use restir_pt::cli::{self, DeviceArgs, Method, RenderArgs};
use restir_pt::image_io::Exposure;
use restir_pt::render::{History, RestirSettings, ReuseMis, ShiftKind};
use restir_pt::scene::LoadOptions;

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

#[derive(Subcommand)]
enum Command {
    /// Render a glTF scene (default: scenes/cornell.gltf) to EXR and PNG with ReSTIR PT (default)
    /// or the path tracer.
    Render(RenderCmd),
    /// Print a scene's triangles, emitters, lights, materials, bounds and cameras; with
    /// --kernels, the SPIR-V size and compile time of each kernel the scene would use.
    Info(InfoCmd),
    /// Measure path-tracer throughput (M paths/s) on a scene after a warm-up; reports the median.
    Bench(BenchCmd),
    /// Path-trace a converged reference: mean EXR (--out) and variance EXR (<out>.variance.exr).
    Reference(ReferenceCmd),
    /// Add up reference shards (`reference --shard I/N`) into the mean EXR (--out) and variance
    /// EXR (<out>.variance.exr) one `reference` process of the same seed and spp writes.
    Merge(MergeCmd),
    /// Per-pass GPU times of ReSTIR PT frames: CSV, Chrome trace (Perfetto) and a stacked-bar SVG.
    Profile(ProfileCmd),
    /// Error against GPU time per frame for each method at equal time budgets, against a
    /// reference: results.csv, log-log charts (SVG, PNG) and an equal-time image strip.
    Compare(CompareCmd),
    /// Every scene and method over F frames, static and moving camera: non-finite pixels (must
    /// be 0), energy and relMSE per frame against references, flicker and failed-shift rate.
    Stability(StabilityCmd),
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Toggle {
    On,
    Off,
}

impl Toggle {
    fn on(self) -> bool {
        self == Toggle::On
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MethodOpt {
    /// Unidirectional path tracing with NEE and MIS.
    Pt,
    /// ReSTIR PT: resampled paths reused across pixels and frames through shift mappings.
    Restir,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum HistoryOpt {
    Temporal,
    Spatial,
}

impl From<History> for HistoryOpt {
    fn from(h: History) -> Self {
        match h {
            History::Temporal => HistoryOpt::Temporal,
            History::Spatial => HistoryOpt::Spatial,
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ShiftOpt {
    Reconnection,
    Replay,
    Hybrid,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MisOpt {
    /// Generalized balance heuristic with confidence weights (O(M^2) shifts).
    Gbh,
    /// Defensive pairwise MIS (O(M) shifts).
    Pairwise,
}

#[derive(Args)]
struct InfoCmd {
    scene: PathBuf,
    /// The glTF scene to describe (index into the file's scenes; default: its default scene).
    #[arg(long = "scene")]
    scene_index: Option<usize>,
    /// Also build every kernel of the path tracer and of ReSTIR PT (with the shift and MIS
    /// given) and print its SPIR-V size and compile time per stage.
    #[arg(long)]
    kernels: bool,
    #[command(flatten)]
    restir: RestirOpts,
    #[command(flatten)]
    device: DeviceOpts,
}

#[derive(Args)]
struct RestirOpts {
    /// ReSTIR PT: the shift mapping used for reuse.
    #[arg(long, value_enum, default_value_t = ShiftOpt::Hybrid)]
    shift: ShiftOpt,
    /// ReSTIR PT: the reservoirs the next frame's temporal reuse reads, those before spatial
    /// reuse (temporal) or after it (spatial).
    #[arg(long, value_enum, default_value_t = HistoryOpt::from(RestirSettings::default().history))]
    history: HistoryOpt,
    /// ReSTIR PT: resampling MIS weights.
    #[arg(long, value_enum, default_value_t = MisOpt::Gbh)]
    mis: MisOpt,
    /// ReSTIR PT: reuse the previous frame's reservoirs.
    #[arg(long, value_enum, default_value_t = Toggle::On)]
    temporal: Toggle,
    /// ReSTIR PT: spatial neighbours per round (0 turns spatial reuse off; at most 8).
    #[arg(long, default_value_t = 3)]
    spatial: u32,
    /// ReSTIR PT: spatial reuse radius in pixels.
    #[arg(long, default_value_t = 20.0)]
    radius: f32,
    /// ReSTIR PT: spatial reuse rounds (1 to 3).
    #[arg(long, default_value_t = 1)]
    rounds: u32,
    /// ReSTIR PT: the temporal input's confidence is capped at this multiple of the current M.
    #[arg(long, default_value_t = 20.0)]
    m_cap: f32,
    /// ReSTIR PT: initial paths traced per reservoir and frame.
    #[arg(long, default_value_t = 1)]
    candidates: u32,
    /// ReSTIR PT: independent reservoirs per pixel (1 to 16), each with its own paths, history
    /// and neighbours; the pixel shows their mean, which averages down the colour noise of
    /// one luminance-resampled path.
    #[arg(long, default_value_t = 1)]
    reservoirs: u32,
    /// ReSTIR PT: camera rays per pixel and frame that estimate the emission seen directly
    /// (1: only the reservoir's primary ray); each further ray costs one closest-hit trace.
    #[arg(long, default_value_t = RestirSettings::default().emission_rays)]
    emission_rays: u32,
}

impl RestirOpts {
    fn settings(&self) -> RestirSettings {
        RestirSettings {
            shift: match self.shift {
                ShiftOpt::Reconnection => ShiftKind::Reconnection,
                ShiftOpt::Replay => ShiftKind::Replay,
                ShiftOpt::Hybrid => ShiftKind::Hybrid,
            },
            mis: match self.mis {
                MisOpt::Gbh => ReuseMis::GeneralizedBalance,
                MisOpt::Pairwise => ReuseMis::Pairwise,
            },
            temporal: self.temporal.on(),
            history: match self.history {
                HistoryOpt::Temporal => History::Temporal,
                HistoryOpt::Spatial => History::Spatial,
            },
            spatial: self.spatial,
            radius: self.radius,
            rounds: self.rounds,
            m_cap: self.m_cap,
            candidates: self.candidates,
            reservoirs: self.reservoirs,
            emission_rays: self.emission_rays,
            ..Default::default()
        }
    }
}

#[derive(Args)]
struct DeviceOpts {
    /// Vulkan device to use: a name substring or an index (the chosen device is printed).
    #[arg(long, value_name = "NAME|INDEX")]
    device: Option<String>,
    /// Enable the Vulkan validation layer (always on in debug builds); any message fails the run.
    #[arg(long)]
    validate: bool,
}

#[derive(Args)]
struct RenderCmd {
    /// glTF 2.0 scene (.gltf or .glb); defaults to the bundled Cornell box.
    scene: Option<PathBuf>,
    #[arg(long, value_enum, default_value_t = MethodOpt::Restir)]
    method: MethodOpt,
    /// Path-tracer samples per pixel (default 64); only with --method pt.
    #[arg(long)]
    spp: Option<u32>,
    /// Image width; with --height alone it follows the camera's aspectRatio (default 256).
    #[arg(long)]
    width: Option<u32>,
    /// Image height; with --width alone it follows the camera's aspectRatio (default 256).
    #[arg(long)]
    height: Option<u32>,
    /// The glTF scene to render (index into the file's scenes; default: its default scene).
    #[arg(long = "scene")]
    scene_index: Option<usize>,
    /// Environment replacing the scene's (and the default one): a radiance R,G,B, or an
    /// equirectangular FILE.exr or FILE.hdr importance-sampled by luminance.
    #[arg(long, value_parser = parse_env, value_name = "R,G,B|FILE")]
    env: Option<EnvOpt>,
    /// PNG preview exposure: EV (radiance times 2^EV) or auto (log-average luminance to 0.18).
    /// The EXR is never changed.
    #[arg(long, default_value = "auto", value_parser = parse_exposure)]
    exposure: Exposure,
    /// Maximum number of path segments: 1 shows only directly visible emitters, 2 adds direct
    /// lighting, each further step adds one bounce of indirect light (ReSTIR PT: at most 7).
    #[arg(long, default_value_t = 7)]
    max_depth: u32,
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Russian roulette from the third segment on (survival = max throughput, at most 0.95).
    #[arg(long, value_enum, default_value_t = Toggle::On)]
    russian_roulette: Toggle,
    /// Index of the glTF camera to render from (scene order); with --frames, the first pose.
    #[arg(long, default_value_t = 0)]
    camera: usize,
    /// Render F frames along the scene's camera path from --camera: its cameras in order, then
    /// back and forth (0, 1, ..., n-1, n-2, ..., 0, 1, ...). The last frame goes to --out;
    /// every frame too with --out-dir.
    #[arg(long, default_value_t = 1)]
    frames: u32,
    /// Render every frame from --camera and write the average of the frames (offline mode).
    #[arg(long)]
    static_camera: bool,
    #[command(flatten)]
    restir: RestirOpts,
    /// Folder for every frame of --frames (frame_0000.exr/png, ...).
    #[arg(long)]
    out_dir: Option<PathBuf>,
    /// Linear float RGB EXR output (default: out/<scene>.exr).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Tonemapped sRGB PNG preview (default: next to the EXR).
    #[arg(long)]
    png: Option<PathBuf>,
    /// Also write the per-pixel variance of the estimate as an EXR.
    #[arg(long)]
    variance: Option<PathBuf>,
    /// Write the summary as JSON.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Write images that have NaN or infinite pixels (with a warning); without it such an
    /// image is not written and the exit code is 1.
    #[arg(long)]
    allow_nonfinite: bool,
    #[command(flatten)]
    device: DeviceOpts,
}

#[derive(Args)]
struct BenchCmd {
    scene: Option<PathBuf>,
    #[arg(long, default_value_t = 256)]
    width: u32,
    #[arg(long, default_value_t = 256)]
    height: u32,
    #[arg(long, default_value_t = 16)]
    spp: u32,
    #[arg(long, default_value_t = 8)]
    max_depth: u32,
    /// Russian roulette from the third segment on, as in `render`.
    #[arg(long, value_enum, default_value_t = Toggle::On)]
    russian_roulette: Toggle,
    /// Timed runs after one warm-up run.
    #[arg(long, default_value_t = 5)]
    runs: u32,
    /// Count rays, BVH node visits, triangle tests and SIMD lane use in the kernel (slower:
    /// a profile, not a timing).
    #[arg(long)]
    counters: bool,
    /// Write the figures as JSON to this file.
    #[arg(long)]
    report: Option<PathBuf>,
    #[command(flatten)]
    device: DeviceOpts,
}

#[derive(Args)]
struct ReferenceCmd {
    scene: PathBuf,
    #[arg(long, default_value_t = 4096)]
    spp: u32,
    #[arg(long, default_value_t = 256)]
    width: u32,
    #[arg(long, default_value_t = 256)]
    height: u32,
    #[arg(long, default_value_t = 7)]
    max_depth: u32,
    #[arg(long, default_value_t = 0)]
    camera: usize,
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Mean EXR; the variance goes next to it as <name>.variance.exr.
    #[arg(long)]
    out: PathBuf,
    /// Write a reference with NaN or infinite pixels (with a warning) instead of failing.
    #[arg(long)]
    allow_nonfinite: bool,
    /// Render only share I of N (0-based) of the --spp samples, disjoint from the other shares,
    /// and write their per-pixel sums to --out as a shard EXR for `merge`.
    #[arg(long, value_name = "I/N")]
    shard: Option<String>,
    #[command(flatten)]
    device: DeviceOpts,
}

#[derive(Args)]
struct MergeCmd {
    /// Shard EXRs written by `reference --shard I/N`.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Mean EXR; the variance goes next to it as <name>.variance.exr.
    #[arg(long)]
    out: PathBuf,
    /// Write a reference with NaN or infinite pixels (with a warning) instead of failing.
    #[arg(long)]
    allow_nonfinite: bool,
}

#[derive(Args)]
struct ProfileCmd {
    scene: Option<PathBuf>,
    /// Frames to time (a static camera unless --camera-path); kernels are compiled before them.
    #[arg(long, default_value_t = 16)]
    frames: u32,
    #[arg(long, default_value_t = 256)]
    width: u32,
    #[arg(long, default_value_t = 256)]
    height: u32,
    #[arg(long, default_value_t = 7)]
    max_depth: u32,
    #[arg(long, default_value_t = 0)]
    camera: usize,
    /// Move the camera along the scene's camera path from --camera instead of accumulating
    /// frames of an unmoved one.
    #[arg(long)]
    camera_path: bool,
    #[command(flatten)]
    restir: RestirOpts,
    /// Folder for passes.csv, trace.json and passes.svg.
    #[arg(long, default_value = "out/profile")]
    out_dir: PathBuf,
    #[command(flatten)]
    device: DeviceOpts,
}

#[derive(Args)]
struct CompareCmd {
    scene: PathBuf,
    /// Path-traced reference EXR (see `reference`); it sets the resolution.
    #[arg(long)]
    reference: PathBuf,
    /// Methods: pt, restir:reconnection, restir:replay, restir:hybrid (optionally /gbh or /pairwise).
    #[arg(long, value_delimiter = ',', default_value = "pt,restir:reconnection,restir:replay,restir:hybrid")]
    methods: Vec<String>,
    /// GPU ms per frame (default: ReSTIR PT's cheapest frame times 1.05, 2.1 and 4.2). Each method
    /// spends a budget on path-tracer spp or ReSTIR PT reservoirs per pixel (each with --candidates paths).
    #[arg(long, value_delimiter = ',')]
    budgets_ms: Vec<f64>,
    /// Frames per run; the error is measured on the last frame alone.
    #[arg(long, default_value_t = 16)]
    frames: u32,
    /// Move the camera along the scene's camera path from --camera (as `render --frames` does)
    /// instead of keeping it still; --reference must then be of the last frame's camera, which
    /// the command prints.
    #[arg(long)]
    camera_path: bool,
    /// Independent runs per method and budget (errors averaged, times median).
    #[arg(long, default_value_t = 1)]
    trials: u32,
    #[arg(long, default_value_t = 7)]
    max_depth: u32,
    #[arg(long, default_value_t = 0)]
    camera: usize,
    #[arg(long, default_value_t = 0)]
    seed: u32,
    #[command(flatten)]
    restir: RestirOpts,
    /// Folder for results.csv, the charts and equal_time.png.
    #[arg(long, default_value = "out/compare")]
    out_dir: PathBuf,
    #[command(flatten)]
    sweep: SweepOpts,
    #[command(flatten)]
    device: DeviceOpts,
}

#[derive(Args)]
struct StabilityCmd {
    /// Scenes to run (default: every bundled scene).
    #[arg(long, value_delimiter = ',')]
    scenes: Vec<PathBuf>,
    #[arg(long, value_delimiter = ',', default_value = "pt,restir:reconnection,restir:replay,restir:hybrid")]
    methods: Vec<String>,
    #[arg(long, default_value_t = 16)]
    frames: u32,
    #[arg(long, default_value_t = 64)]
    width: u32,
    #[arg(long, default_value_t = 64)]
    height: u32,
    #[arg(long, default_value_t = 7)]
    max_depth: u32,
    /// Paths per pixel of each camera pose's path-traced reference.
    #[arg(long, default_value_t = 512)]
    reference_spp: u32,
    /// Paths per pixel of one path-traced frame.
    #[arg(long, default_value_t = 4)]
    pt_spp: u32,
    #[arg(long, default_value_t = 0)]
    seed: u32,
    #[command(flatten)]
    restir: RestirOpts,
    /// Folder for stability.csv and <scene>_rel_mse.svg/png.
    #[arg(long, default_value = "out/stability")]
    out_dir: PathBuf,
    #[command(flatten)]
    sweep: SweepOpts,
    #[command(flatten)]
    device: DeviceOpts,
}

#[derive(Args)]
struct SweepOpts {
    /// Write the runs as a job list (JSON lines: each job's command and working folder) to
    /// this file and run nothing; see tools/cluster/.
    #[arg(long, value_name = "JOBS.jsonl")]
    plan: Option<PathBuf>,
    /// Run only job K (0-based) of the job list these arguments make; it writes
    /// <out-dir>/jobs/job_K.csv/.json.
    #[arg(long, value_name = "K")]
    job: Option<usize>,
    /// Merge the jobs' files in DIR (normally <out-dir>/jobs) into the usual outputs and
    /// accounting.csv.
    #[arg(long, value_name = "DIR")]
    merge: Option<PathBuf>,
}

impl SweepOpts {
    fn mode(self) -> anyhow::Result<cli::SweepMode> {
        cli::SweepMode::from_flags(self.plan, self.job, self.merge)
    }
}

/// The command line after the program name, for job lists.
fn argv() -> Vec<String> {
    std::env::args_os().skip(1).map(|a| a.to_string_lossy().into_owned()).collect()
}

impl From<DeviceOpts> for DeviceArgs {
    fn from(d: DeviceOpts) -> Self {
        DeviceArgs {
            device: d.device,
            validate: d.validate || cfg!(debug_assertions),
        }
    }
}

fn parse_exposure(s: &str) -> Result<Exposure, String> {
    if s == "auto" {
        return Ok(Exposure::Auto);
    }
    match s.parse::<f32>() {
        Ok(ev) if ev.is_finite() && ev.abs() <= 64.0 => Ok(Exposure::Ev(ev)),
        _ => Err(format!("{s:?} is neither auto nor an EV between -64 and 64")),
    }
}

/// `--env`: a constant radiance or an environment map file.
#[derive(Clone, Debug)]
enum EnvOpt {
    Constant(Vec3),
    File(PathBuf),
}

impl EnvOpt {
    fn constant(&self) -> Option<Vec3> {
        match self {
            EnvOpt::Constant(c) => Some(*c),
            EnvOpt::File(_) => None,
        }
    }

    fn file(&self) -> Option<PathBuf> {
        match self {
            EnvOpt::File(f) => Some(f.clone()),
            EnvOpt::Constant(_) => None,
        }
    }
}

fn parse_env(s: &str) -> Result<EnvOpt, String> {
    let lower = s.to_ascii_lowercase();
    if lower.ends_with(".exr") || lower.ends_with(".hdr") {
        return Ok(EnvOpt::File(PathBuf::from(s)));
    }
    parse_radiance(s).map(EnvOpt::Constant)
}

fn parse_radiance(s: &str) -> Result<Vec3, String> {
    let usage = || format!("{s:?} must be R,G,B (three finite, non-negative radiances) or FILE.exr|FILE.hdr");
    let values: Vec<f32> = s
        .split(',')
        .map(|v| v.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| usage())?;
    match values[..] {
        [r, g, b] if values.iter().all(|v| v.is_finite() && *v >= 0.0) => Ok(Vec3::new(r, g, b)),
        _ => Err(usage()),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let command = match cli.command {
        Some(c) => c,
        None => Cli::parse_from(["restir-pt", "render"])
            .command
            .expect("render parses with defaults"),
    };
    let result = match command {
        Command::Render(r) => cli::render(RenderArgs {
            method: match r.method {
                MethodOpt::Pt => Method::PathTracing,
                MethodOpt::Restir => Method::Restir(r.restir.settings()),
            },
            static_camera: r.static_camera,
            scene: r.scene,
            spp: r.spp,
            width: r.width,
            height: r.height,
            max_depth: r.max_depth,
            seed: r.seed,
            russian_roulette: r.russian_roulette.on(),
            camera: r.camera,
            frames: r.frames,
            out_dir: r.out_dir,
            out: r.out,
            png: r.png,
            variance: r.variance,
            report: r.report,
            allow_nonfinite: r.allow_nonfinite,
            load: LoadOptions {
                scene: r.scene_index,
                environment: r.env.as_ref().and_then(EnvOpt::constant),
                environment_map: r.env.as_ref().and_then(EnvOpt::file),
                max_binding_bytes: None,
            },
            exposure: r.exposure,
            device: r.device.into(),
        }),
        Command::Info(i) => {
            let kernels = i.kernels.then(|| (i.restir.settings(), i.device.into()));
            let load = LoadOptions {
                scene: i.scene_index,
                ..Default::default()
            };
            cli::info(&i.scene, &load, kernels)
        }
        Command::Reference(r) => r.shard.as_deref().map(cli::ShardSpec::parse).transpose().and_then(|shard| {
            cli::reference(cli::ReferenceArgs {
                scene: r.scene,
                spp: r.spp,
                width: r.width,
                height: r.height,
                max_depth: r.max_depth,
                camera: r.camera,
                seed: r.seed,
                out: r.out,
                allow_nonfinite: r.allow_nonfinite,
                shard,
                device: r.device.into(),
            })
        }),
        Command::Merge(m) => cli::merge(&m.shards, &m.out, m.allow_nonfinite),
        Command::Profile(p) => cli::profile(cli::ProfileArgs {
            restir: p.restir.settings(),
            scene: p.scene,
            frames: p.frames,
            width: p.width,
            height: p.height,
            max_depth: p.max_depth,
            camera: p.camera,
            camera_path: p.camera_path,
            out_dir: p.out_dir,
            device: p.device.into(),
        }),
        Command::Compare(c) => c
            .sweep
            .mode()
            .and_then(|sweep| {
                cli::compare(cli::CompareArgs {
                    restir: c.restir.settings(),
                    scene: c.scene,
                    reference: c.reference,
                    methods: c.methods,
                    budgets_ms: c.budgets_ms,
                    frames: c.frames,
                    camera_path: c.camera_path,
                    trials: c.trials,
                    max_depth: c.max_depth,
                    camera: c.camera,
                    seed: c.seed,
                    out_dir: c.out_dir,
                    sweep,
                    argv: argv(),
                    device: c.device.into(),
                })
            })
            .map(|_| ()),
        Command::Stability(s) => s
            .sweep
            .mode()
            .and_then(|sweep| {
                cli::stability(cli::StabilityArgs {
                    restir: s.restir.settings(),
                    scenes: s.scenes,
                    methods: s.methods,
                    frames: s.frames,
                    width: s.width,
                    height: s.height,
                    max_depth: s.max_depth,
                    reference_spp: s.reference_spp,
                    pt_spp: s.pt_spp,
                    seed: s.seed,
                    out_dir: Some(s.out_dir),
                    sweep,
                    argv: argv(),
                    device: s.device.into(),
                })
            })
            .map(|_| ()),
        Command::Bench(b) => cli::bench(cli::BenchArgs {
            scene: b.scene,
            width: b.width,
            height: b.height,
            spp: b.spp,
            max_depth: b.max_depth,
            runs: b.runs,
            russian_roulette: b.russian_roulette.on(),
            counters: b.counters,
            report: b.report,
            device: b.device.into(),
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
