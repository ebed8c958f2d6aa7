//! The frame loops of `restir-pt render`: exact frame counts (`--frames`), or frames of an
//! unmoved camera accumulated until their GPU time reaches a budget (`--time`, the default of
//! ReSTIR PT), with a progress bar.

use std::path::Path;
use std::sync::atomic::Ordering;
use std::sync::Arc;

use anyhow::Result;

use super::render::{RenderArgs, RunLength};
use super::render_output::{
    budget_bar, compile_progress, guard_nonfinite, interrupt_flag, print_compile_summary, progress_bar, Outputs, RenderReport,
    RestirFrameReport,
};
use restir_pt::render::{Image, PathTracer, RenderSettings, Restir, RestirSettings, SceneGpu};

/// What both methods' frame loops need.
pub(super) struct Job<'a> {
    /// The uploaded scene both renderers are built from.
    pub scene: &'a Arc<SceneGpu>,
    pub scene_path: &'a Path,
    pub args: &'a RenderArgs,
    pub settings: &'a RenderSettings,
    pub outputs: Outputs<'a>,
    pub run: RunLength,
}

impl Job<'_> {
    /// Whether the run ends with `frame`, after `gpu_ms` of frames in all: the last of
    /// `--frames`, the frame that reaches the time budget, or Ctrl-C.
    fn is_last(&self, frame: u32, gpu_ms: f64, interrupted: bool) -> bool {
        interrupted
            || match self.run {
                RunLength::Frames(n) => frame + 1 >= n,
                RunLength::GpuMs(budget) => gpu_ms >= budget,
            }
    }

    /// Whether a frame's image is written: the last frame's, and every frame's with --out-dir.
    fn writes_image(&self, last: bool) -> bool {
        self.args.out_dir.is_some() || last
    }

    /// The camera of each frame of the run, as far as it is known before it starts: every
    /// frame's for `--frames`, two frames of the unmoved camera for a time budget.
    fn frame_cameras(&self) -> Vec<usize> {
        let count = match self.run {
            RunLength::Frames(n) => n,
            RunLength::GpuMs(_) => 2,
        };
        let cameras = self.scene.info().cameras.len();
        (0..count).map(|f| self.args.frame_camera(f, cameras)).collect()
    }

    /// Prints the frame's line (every frame's with --frames, the last one's under a time
    /// budget), refuses or warns about non-finite pixels and writes the frame's image if it was
    /// read back (`writes_image`).
    fn finish_frame(&self, frame: u32, report: &RenderReport, line: &str, image: Option<&Image>, last: bool) -> Result<()> {
        if last || matches!(self.run, RunLength::Frames(_)) {
            println!("{}{line}", self.args.frame_prefix(frame, self.scene.info().cameras.len()));
        }
        guard_nonfinite(self.args.allow_nonfinite, self.args.report.as_deref(), frame, report)?;
        if let Some(image) = image {
            self.outputs.write_frame(frame, image)?;
            if last {
                self.outputs.write_final(image)?;
            }
        }
        Ok(())
    }

    pub fn report(&self, method: String, spp: u32, frame_ms: f64, wall_ms: f64, compile_ms: f64) -> RenderReport {
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
            time_budget_ms: match self.run {
                RunLength::GpuMs(ms) => Some(ms),
                RunLength::Frames(_) => None,
            },
            nonfinite_pixels: 0,
            nonfinite_weights: 0,
            restir: None,
        }
    }

    /// The closing line of a run of several frames.
    fn print_totals(&self, frame_ms: &[f64], median_ms: f64) {
        if frame_ms.len() > 1 {
            let total: f64 = frame_ms.iter().sum();
            let budget = match self.run {
                RunLength::GpuMs(ms) => format!(" (budget {:.1} s, --time)", ms * 1e-3),
                RunLength::Frames(_) => String::new(),
            };
            eprintln!(
                "{} frames, {total:.1} ms of GPU time in all{budget} (median {median_ms:.1} ms per frame)",
                frame_ms.len()
            );
        }
    }
}

/// Path-traced frames of --spp each. A moving camera restarts the sums at every frame; a static
/// one keeps them, so that the image is the average of all frames (one render of F x spp).
pub(super) fn render_path_traced(job: &Job) -> Result<RenderReport> {
    let (args, settings) = (job.args, job.settings);
    let interrupt = interrupt_flag();
    let spinner = compile_progress();
    spinner.set_message("pathtrace.comp");
    let mut tracer = PathTracer::new(job.scene, settings)?;
    spinner.finish_and_clear();
    let compile_ms = tracer.compile_report().total_ms();
    print_compile_summary(
        std::slice::from_ref(tracer.compile_report()),
        compile_ms,
        tracer.compile_report().total_cpu_ms(),
        0,
    );
    let budget = match job.run {
        RunLength::GpuMs(ms) => Some(budget_bar(ms)),
        RunLength::Frames(_) => None,
    };
    let (mut frame_ms, mut frame) = (vec![], 0);
    loop {
        if frame > 0 && args.is_static() {
            tracer.add_samples(settings.spp);
        } else if frame > 0 {
            let camera = args.frame_camera(frame, job.scene.info().cameras.len());
            tracer.restart(&RenderSettings {
                camera,
                ..settings.clone()
            })?;
        }
        let bar = budget.is_none().then(|| progress_bar(tracer.target_spp()));
        let stats = tracer.render(&|done| bar.iter().for_each(|b| b.set_position(done as u64)), &interrupt)?;
        bar.iter().for_each(|b| b.finish_and_clear());
        frame_ms.push(stats.gpu_ms);
        let total: f64 = frame_ms.iter().sum();
        let last = job.is_last(frame, total, stats.interrupted);
        if let Some(b) = &budget {
            b.set_position(total.min(b.length().unwrap_or(0) as f64) as u64);
            b.set_message(format!("{} spp", stats.spp));
        }
        let image = tracer.image()?;
        let mut report = job.report("pt".into(), stats.spp, stats.gpu_ms, stats.wall_ms, compile_ms);
        report.set_frame_times(&frame_ms);
        // A static camera's stats count every frame's samples; the throughput is this frame's.
        let frame_spp = stats.spp.saturating_sub(if args.is_static() { frame * settings.spp } else { 0 });
        report.paths_per_second = stats.paths_per_second(settings.pixel_count()) * frame_spp as f64 / stats.spp.max(1) as f64;
        report.nonfinite_pixels = image.non_finite_count();
        report.nonfinite_weights = stats.nonfinite_paths;
        if stats.interrupted {
            eprintln!("interrupted: writing the {} spp of frame {frame} accumulated so far", stats.spp);
        }
        if last {
            budget.iter().for_each(|b| b.finish_and_clear());
        }
        job.finish_frame(frame, &report, &report.summary_line(), Some(&image), last)?;
        if last {
            job.print_totals(&frame_ms, report.median_gpu_ms);
            return Ok(report);
        }
        frame += 1;
    }
}

/// ReSTIR PT frames; a static camera averages them (`Restir::frame`'s accumulate). Only the
/// kernels the run dispatches are built.
pub(super) fn render_restir(job: &Job, restir: &RestirSettings) -> Result<RenderReport> {
    let (args, settings) = (job.args, job.settings);
    let interrupt = interrupt_flag();
    let spinner = compile_progress();
    let kernels = restir.kernels_for_cameras(&job.frame_cameras());
    let mut renderer = Restir::with_kernels(job.scene, settings, restir, &kernels, &|name| spinner.set_message(name.to_string()))?;
    spinner.finish_and_clear();
    let compile_reports = renderer.compile_reports();
    let compile_ms = renderer.compile_ms();
    print_compile_summary(
        &compile_reports,
        compile_ms,
        renderer.compile_cpu_ms(),
        renderer.twin_warmed_kernels(),
    );
    let spp = restir.candidates * restir.reservoirs;
    let budget = match job.run {
        RunLength::GpuMs(ms) => Some(budget_bar(ms)),
        RunLength::Frames(_) => None,
    };
    let (mut frame_ms, mut frame) = (vec![], 0);
    loop {
        let stats = renderer.frame(args.frame_camera(frame, job.scene.info().cameras.len()), args.is_static())?;
        let interrupted = interrupt.load(Ordering::Relaxed);
        frame_ms.push(stats.gpu_ms().unwrap_or(stats.wall_ms));
        let total: f64 = frame_ms.iter().sum();
        let last = job.is_last(frame, total, interrupted);
        if let Some(b) = &budget {
            b.set_position(total.min(b.length().unwrap_or(0) as f64) as u64);
            b.set_message(format!("{} frames", frame + 1));
        }
        let detail = RestirFrameReport::from_stats(frame + 1, &stats);
        let mut report = job.report(restir.label(), spp, frame_ms[frame as usize], stats.wall_ms, compile_ms);
        report.set_frame_times(&frame_ms);
        report.paths_per_second = settings.pixel_count() as f64 * spp as f64 / (report.gpu_ms * 1e-3);
        // The image is read back only when it is written or when the shading pass counted a
        // non-finite pixel (then the host count is the one reported and guarded).
        let image = if job.writes_image(last) || detail.nonfinite_pixels > 0 {
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
        if last {
            budget.iter().for_each(|b| b.finish_and_clear());
        }
        job.finish_frame(frame, &report, &line, image.as_ref(), last)?;
        if last {
            job.print_totals(&frame_ms, report.median_gpu_ms);
            return Ok(report);
        }
        frame += 1;
    }
}
