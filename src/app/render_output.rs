//! What `render` prints and writes: the per-frame summary line, the JSON report, the images and
//! the guard that refuses non-finite images.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::{bail, Context as _, Result};
use serde::Serialize;

use restir_pt::image_io::{exposure_ev, write_exr, write_png_exposed, Exposure};
use restir_pt::metrics::median;
use restir_pt::render::{FrameStats, Image, PASS_NAMES};

/// The JSON report of `render --report` and the numbers of its summary lines.
#[derive(Serialize)]
pub struct RenderReport {
    pub device: String,
    pub scene: String,
    pub method: String,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    /// GPU ms of the last frame (the path tracer: of its samples in that frame).
    pub gpu_ms: f64,
    /// GPU ms of every frame rendered, in order (one entry for a single frame).
    pub frame_gpu_ms: Vec<f64>,
    /// The median of `frame_gpu_ms`.
    pub median_gpu_ms: f64,
    pub wall_ms: f64,
    pub paths_per_second: f64,
    /// Start-up milliseconds spent compiling the kernels, wall-clock (outside every frame's time).
    pub compile_ms: f64,
    /// The GPU time budget of the frames (`--time`, the default of ReSTIR PT), if the run had
    /// one rather than a frame count.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_budget_ms: Option<f64>,
    /// NaN or infinite pixels of the image written (or refused) for this frame.
    pub nonfinite_pixels: usize,
    /// Path weights found NaN or infinite: the path tracer's paths with a non-finite radiance or
    /// throughput over the whole render; ReSTIR PT's candidate and shift weights of this frame.
    pub nonfinite_weights: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub restir: Option<RestirFrameReport>,
}

impl RenderReport {
    /// One line: device, method, size, spp, depth, times, throughput and the non-finite counts.
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

    /// Records the GPU time of every frame so far (this one last).
    pub fn set_frame_times(&mut self, frame_gpu_ms: &[f64]) {
        self.frame_gpu_ms = frame_gpu_ms.to_vec();
        self.median_gpu_ms = median(frame_gpu_ms);
    }

    /// Writes the report as pretty JSON.
    pub fn write(&self, path: &Path) -> Result<()> {
        std::fs::write(path, serde_json::to_string_pretty(self)?).with_context(|| format!("{}: cannot write the report", path.display()))
    }
}

/// What a ReSTIR PT frame reports beyond the common summary.
#[derive(Serialize, Clone)]
pub struct RestirFrameReport {
    pub frames: u32,
    pub pass_ms: Vec<(String, f64)>,
    pub shifts_attempted: u32,
    pub shifts_failed: u32,
    pub failed_shift_rate: f64,
    /// Traversals per attempted shift (FrameStats::traversals_per_shift).
    pub traversals_per_shift: Option<f64>,
    /// Share of SIMD lanes busy while the shift code runs (FrameStats::shift_lane_use).
    pub shift_lane_use: Option<f64>,
    pub nonfinite_weights: u32,
    pub nonfinite_pixels: u32,
    pub candidates_dropped: u32,
}

impl RestirFrameReport {
    pub fn from_stats(frames: u32, stats: &FrameStats) -> Self {
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
            traversals_per_shift: stats.traversals_per_shift(),
            shift_lane_use: stats.shift_lane_use(),
            nonfinite_weights: c.nonfinite_weights,
            nonfinite_pixels: c.nonfinite_pixels,
            candidates_dropped: c.candidates_dropped,
        }
    }

    /// Pass times and failed shifts; the non-finite counts are the common summary's.
    pub fn summary(&self) -> String {
        let passes: Vec<String> = self.pass_ms.iter().map(|(n, t)| format!("{n} {t:.1}")).collect();
        let shifts = match (self.traversals_per_shift, self.shift_lane_use) {
            (Some(rays), Some(lanes)) => format!(", {rays:.2} traversals per shift, lanes busy in shifts {:.0}%", 100.0 * lanes),
            _ => String::new(),
        };
        format!(
            "passes ms: {} | failed shifts {}/{} ({:.1}%){shifts}",
            if passes.is_empty() { "n/a".to_string() } else { passes.join(", ") },
            self.shifts_failed,
            self.shifts_attempted,
            100.0 * self.failed_shift_rate,
        )
    }
}

/// Refuses an image with non-finite pixels unless `allow`: the report (if asked for) is written
/// first so that the counts are kept, then the error names the frame and the counts. With
/// `allow` it warns and lets the image be written.
pub fn guard_nonfinite(allow: bool, report_path: Option<&Path>, frame: u32, report: &RenderReport) -> Result<()> {
    if report.nonfinite_pixels == 0 {
        return Ok(());
    }
    let what = format!(
        "frame {frame}: {} non-finite pixels ({} non-finite path weights)",
        report.nonfinite_pixels, report.nonfinite_weights
    );
    if allow {
        eprintln!("warning: {what}; writing the image anyway (--allow-nonfinite)");
        return Ok(());
    }
    if let Some(r) = report_path {
        report.write(r)?;
    }
    bail!("{what}; no image written (--allow-nonfinite writes it anyway)")
}

/// Where `render` writes its images.
pub struct Outputs<'a> {
    pub out: &'a Path,
    pub png: &'a Path,
    pub variance: Option<&'a Path>,
    pub out_dir: Option<&'a Path>,
    pub exposure: Exposure,
}

impl Outputs<'_> {
    /// frame_NNNN.exr/png in --out-dir, if given.
    pub fn write_frame(&self, frame: u32, image: &Image) -> Result<()> {
        if let Some(dir) = self.out_dir {
            let name = format!("frame_{frame:04}");
            write_exr(&dir.join(format!("{name}.exr")), image.width, image.height, &image.mean)?;
            write_png_exposed(&dir.join(format!("{name}.png")), image, exposure_ev(self.exposure, image))?;
        }
        Ok(())
    }

    /// The EXR, its PNG preview and the variance EXR if asked for.
    pub fn write_final(&self, image: &Image) -> Result<()> {
        write_exr(self.out, image.width, image.height, &image.mean)?;
        let ev = exposure_ev(self.exposure, image);
        if self.exposure == Exposure::Auto {
            eprintln!("PNG preview: exposure {ev:+.2} EV (automatic: log-average luminance to 0.18; --exposure EV sets it)");
        }
        write_png_exposed(self.png, image, ev)?;
        if let Some(v) = self.variance {
            write_exr(v, image.width, image.height, &image.variance)?;
        }
        Ok(())
    }
}

/// A spinner that names the kernel being compiled; compiling takes seconds on llvmpipe.
pub fn compile_progress() -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(indicatif::ProgressStyle::with_template("{spinner} compiling {msg}  {elapsed}").expect("static template is valid"));
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// A spinner with a message and the time elapsed, for long steps without a count.
pub fn status_spinner() -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(indicatif::ProgressStyle::with_template("{spinner} {msg}  {elapsed}").expect("static template is valid"));
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// The start-up line: how long compiling the kernels took, wall-clock (`wall_ms`) and in CPU
/// time of the process (`cpu_ms`, which other processes do not inflate), the GLSL stage's CPU
/// time over all kernels (on worker threads, overlapping the driver's compiles), and how many
/// kernels a twin device compiled into the driver's cache meanwhile (`twin_warmed`,
/// `Restir::twin_warmed_kernels`).
pub fn print_compile_summary(kernels: &[restir_pt::vk::KernelCompile], wall_ms: f64, cpu_ms: f64, twin_warmed: usize) {
    let glsl: f64 = kernels.iter().map(|k| k.glsl_cpu_ms).sum();
    let twin = match twin_warmed {
        0 => String::new(),
        n => format!("; {n} of them first on a twin device"),
    };
    eprintln!(
        "start-up: {} kernel(s) compiled in {wall_ms:.0} ms ({cpu_ms:.0} ms of CPU time, {glsl:.0} of it GLSL to SPIR-V{twin})",
        kernels.len()
    );
}

/// A bar of a render's GPU time budget, in milliseconds; its message counts the frames or
/// samples so far.
pub fn budget_bar(budget_ms: f64) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(budget_ms.max(1.0) as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {msg}  {elapsed} (eta {eta}; --time sets the budget)")
            .expect("static template is valid"),
    );
    bar
}

/// A bar of samples per pixel done.
pub fn progress_bar(total: u32) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(total as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} spp  {elapsed} (eta {eta})").expect("static template is valid"),
    );
    bar
}

/// Installs a Ctrl-C handler once; later renders share the flag.
pub fn interrupt_flag() -> Arc<AtomicBool> {
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

/// Refuses an output file `path` (given with `flag`) whose extension is not `ext` (compared
/// without case): the file is written as `format` whatever its name, and a misnamed file
/// misleads every program that opens it later.
pub fn check_extension(flag: &str, path: &Path, ext: &str, format: &str) -> Result<()> {
    let matches = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(ext));
    if !matches {
        anyhow::bail!("{flag} {}: the file is written as {format}; give it a .{ext} name", path.display());
    }
    Ok(())
}

/// Creates the folder `file` goes into, with a note on stderr when it did not exist (a mistyped
/// folder name would otherwise leave the image somewhere unexpected without a word).
pub fn create_parent(file: &Path) -> Result<()> {
    match file.parent().filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
        Some(dir) => {
            std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create the output folder", dir.display()))?;
            eprintln!("note: created the folder {}", dir.display());
            Ok(())
        }
        None => Ok(()),
    }
}
