//! The progressive GPU path tracer: accumulates glsl/pathtrace.comp over short submissions.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context as _, Result};

use super::{Image, RenderSettings, SceneGpu};
use crate::scene::Scene;
use crate::vk::{Binding, Buffer, BufferUsage, Context, Kernel, PassTimer};

/// Submissions are sized to about this much GPU time, which keeps GPU watchdogs far away.
const TARGET_SUBMISSION_MS_GPU: f64 = 250.0;
/// A CPU device (lavapipe) has no watchdog; longer submissions let paths regenerate within a lane.
const TARGET_SUBMISSION_MS_CPU: f64 = 1500.0;
/// How fast the adaptive chunk may grow from one submission to the next.
const MAX_CHUNK_GROWTH: u32 = 8;
const LOCAL_SIZE: u32 = 8;

pub struct RenderStats {
    pub spp: u32,
    pub gpu_ms: f64,
    pub wall_ms: f64,
    pub submissions: u32,
    /// True if the render stopped early on request (Ctrl-C); the image holds what was done.
    pub interrupted: bool,
}

impl RenderStats {
    pub fn paths_per_second(&self, pixels: usize) -> f64 {
        let ms = if self.gpu_ms > 0.0 { self.gpu_ms } else { self.wall_ms };
        pixels as f64 * self.spp as f64 / (ms * 1e-3)
    }
}

pub struct PathTracer {
    ctx: Arc<Context>,
    kernel: Kernel,
    params: Buffer,
    accum: Buffer,
    accum_sq: Buffer,
    _scene_gpu: SceneGpu,
    timer: PassTimer,
    settings: RenderSettings,
    base_params: crate::gpu_types::FrameParams,
    samples_done: u32,
}

impl PathTracer {
    pub fn new(ctx: &Arc<Context>, scene: &Scene, settings: &RenderSettings) -> Result<Self> {
        settings.validate(scene)?;
        let pixels = settings.pixel_count() as u64;
        ctx.check_binding_size("the accumulation image", pixels * 16)?;
        let scene_gpu = SceneGpu::upload(ctx, scene)?;
        let params = Buffer::new(
            ctx,
            "frame parameters",
            std::mem::size_of::<crate::gpu_types::FrameParams>() as u64,
            BufferUsage::Uniform,
        )?;
        let accum = Buffer::new(ctx, "accumulation", pixels * 16, BufferUsage::Storage)?;
        let accum_sq = Buffer::new(ctx, "accumulation of squares", pixels * 16, BufferUsage::Storage)?;
        let mut bindings = scene_gpu.bindings();
        bindings.extend([Binding::Storage, Binding::Storage]);
        let kernel = Kernel::new(ctx, "pathtrace.comp", &scene_gpu.defines(), &bindings, 0)?;
        let mut buffers = scene_gpu.buffers(&params);
        buffers.extend([&accum, &accum_sq]);
        kernel.bind(&buffers);
        accum.fill(0)?;
        accum_sq.fill(0)?;
        Ok(Self {
            ctx: ctx.clone(),
            kernel,
            params,
            accum,
            accum_sq,
            timer: PassTimer::new(ctx, 1)?,
            base_params: settings.frame_params(scene),
            settings: settings.clone(),
            _scene_gpu: scene_gpu,
            samples_done: 0,
        })
    }

    /// Adds `samples` paths per pixel in one submission; returns its GPU time in ms (None if the
    /// device has no timestamps).
    pub fn dispatch(&mut self, samples: u32) -> Result<Option<f64>> {
        let mut params = self.base_params;
        params.sample_offset = self.samples_done;
        params.samples_per_dispatch = samples;
        self.params.write(std::slice::from_ref(&params))?;
        let groups = [
            self.settings.width.div_ceil(LOCAL_SIZE),
            self.settings.height.div_ceil(LOCAL_SIZE),
            1,
        ];
        self.ctx
            .submit_and_wait(|cmd| {
                self.timer.record_reset(cmd);
                self.timer.record_begin(cmd, 0);
                self.kernel.record_dispatch(cmd, groups, &[]);
                self.timer.record_end(cmd, 0);
            })
            .context("path tracing")?;
        self.samples_done += samples;
        Ok(self.timer.read_ms(1)?.map(|t| t[0]))
    }

    /// Renders the requested spp in adaptive chunks. `progress` receives the samples done;
    /// `cancel` stops after the current chunk.
    pub fn render(&mut self, progress: &dyn Fn(u32), cancel: &AtomicBool) -> Result<RenderStats> {
        let start = Instant::now();
        let mut gpu_ms = 0.0;
        let mut submissions = 0;
        let mut chunk = 1u32;
        let mut interrupted = false;
        let target_ms = if self.ctx.info.device_type == ash::vk::PhysicalDeviceType::CPU {
            TARGET_SUBMISSION_MS_CPU
        } else {
            TARGET_SUBMISSION_MS_GPU
        };
        while self.samples_done < self.settings.spp {
            if cancel.load(Ordering::Relaxed) {
                interrupted = true;
                break;
            }
            let samples = chunk.min(self.settings.spp - self.samples_done);
            let t0 = Instant::now();
            let ms = self.dispatch(samples)?.unwrap_or_else(|| t0.elapsed().as_secs_f64() * 1e3);
            gpu_ms += ms;
            submissions += 1;
            progress(self.samples_done);
            let per_sample = ms / samples as f64;
            chunk = ((target_ms / per_sample.max(1e-3)) as u32).clamp(1, MAX_CHUNK_GROWTH * samples);
        }
        Ok(RenderStats {
            spp: self.samples_done,
            gpu_ms,
            wall_ms: start.elapsed().as_secs_f64() * 1e3,
            submissions,
            interrupted,
        })
    }

    pub fn image(&self) -> Result<Image> {
        let n = self.settings.pixel_count();
        let sums: Vec<[f32; 4]> = self.accum.read(n)?;
        let sums_sq: Vec<[f32; 4]> = self.accum_sq.read(n)?;
        Ok(Image::from_sums(self.settings.width, self.settings.height, &sums, &sums_sq))
    }
}
