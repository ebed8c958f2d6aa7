//! The progressive GPU path tracer: accumulates glsl/pathtrace.comp over short submissions.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context as _, Result};

use super::counters::{TraversalCounters, COUNTER_COUNT};
use super::image_readback::AccumReadback;
use super::{Image, RenderSettings, SceneGpu};
use crate::error::GpuError;
use crate::shader_interface::{PathTraceBinding, IMAGE_LOCAL_SIZE};
use crate::shading::bvh::BRUTE_FORCE_MAX_TRIANGLES;
use crate::vk::{record_compute_barrier, Binding, BindingFamilyExt, Buffer, BufferUsage, Context, Kernel, KernelCompile, PassTimer};

/// Submissions are sized to about this much GPU time, which keeps GPU watchdogs far away.
const TARGET_SUBMISSION_MS_GPU: f64 = 250.0;
/// A CPU device (lavapipe) has no watchdog; longer submissions let paths regenerate within a lane.
const TARGET_SUBMISSION_MS_CPU: f64 = 1500.0;
/// How fast the adaptive chunk may grow from one submission to the next.
const MAX_CHUNK_GROWTH: u32 = 8;
/// Share of a driver's per-invocation loop budget a dispatch may plan to use; the rest absorbs
/// pixels whose paths cost more than the ones measured so far.
const LOOP_BUDGET_SHARE: f64 = 0.25;
/// Words of glsl/pathtrace.comp's Status block: max loop iterations, subgroups with a cut loop,
/// paths with a non-finite radiance or throughput, a pad word (the counters are 8-byte aligned),
/// the 64-bit profile counters and the subgroup size.
const STATUS_WORDS: u64 = 5 + 2 * COUNTER_COUNT as u64;
/// The first word of the profile counters in the Status block.
const COUNTER_WORDS_START: usize = 4;
const LOCAL_SIZE: u32 = IMAGE_LOCAL_SIZE;

/// What one [`PathTracer::render`] call did and how long it took.
pub struct RenderStats {
    /// Samples per pixel accumulated so far, over every call since the tracer was built or reset.
    pub spp: u32,
    /// Milliseconds of GPU time of this call's dispatches, by timestamp queries; where the device
    /// has none, each submission's wall time instead.
    pub gpu_ms: f64,
    /// Wall-clock milliseconds of the call, submissions and waits included.
    pub wall_ms: f64,
    /// Paths whose radiance or throughput was NaN or infinite (counted on the GPU); each one
    /// makes its pixel non-finite.
    pub nonfinite_paths: u64,
    /// True if the render stopped early on request (Ctrl-C); the image holds what was done.
    pub interrupted: bool,
    /// The kernel's profile counters, when built with them (`PathTracer::with_counters`).
    pub counters: Option<TraversalCounters>,
}

impl RenderStats {
    /// Throughput: `pixels * spp` paths over `gpu_ms` (over `wall_ms` if no GPU time was
    /// measured), in paths per second.
    pub fn paths_per_second(&self, pixels: usize) -> f64 {
        let ms = if self.gpu_ms > 0.0 { self.gpu_ms } else { self.wall_ms };
        pixels as f64 * self.spp as f64 / (ms * 1e-3)
    }
}

pub use super::image_readback::PixelSums;

/// The progressive path tracer of one uploaded scene at one resolution: accumulates paths per
/// pixel over adaptive submissions (`render`) and reads back their mean and variance (`image`).
pub struct PathTracer {
    ctx: Arc<Context>,
    kernel: Kernel,
    params: Buffer,
    accum: Buffer,
    accum_sq: Buffer,
    status: Buffer,
    /// The image and the dispatch status come back through it.
    readback: AccumReadback,
    /// The scene the kernel's descriptors point at; kept alive with the renderer.
    scene: Arc<SceneGpu>,
    timer: PassTimer,
    settings: RenderSettings,
    base_params: crate::gpu_types::FrameParams,
    /// Index of the first sample of this render in the (pixel, sample, seed) key of
    /// `path_seed`; `samples_done` counts on from it.
    first_sample: u32,
    samples_done: u32,
    counters: Option<TraversalCounters>,
}

impl PathTracer {
    /// A path tracer of the uploaded `scene` on its device, its kernel compiled. Errors:
    /// `settings` invalid for the scene (see `RenderSettings::validate`), an image too large
    /// for one binding, or a failed allocation or compile.
    pub fn new(scene: &Arc<SceneGpu>, settings: &RenderSettings) -> Result<Self> {
        Self::with_counters(scene, settings, false)
    }

    /// Like `new`; with `counters` the kernel also counts rays, node visits, triangle tests and
    /// SIMD loop iterations (glsl/interface/counters.glsl), which `render` returns in its stats.
    pub fn with_counters(scene: &Arc<SceneGpu>, settings: &RenderSettings, counters: bool) -> Result<Self> {
        let ctx = scene.ctx();
        settings.validate(scene.info())?;
        let pixels = settings.pixel_count() as u64;
        ctx.check_binding_size("the accumulation image", pixels * 16)?;
        let scene_gpu = scene;
        let params = Buffer::new(
            ctx,
            "frame parameters",
            std::mem::size_of::<crate::gpu_types::FrameParams>() as u64,
            BufferUsage::Params,
        )?;
        let accum = Buffer::new(ctx, "accumulation", pixels * 16, BufferUsage::Storage)?;
        let accum_sq = Buffer::new(ctx, "accumulation of squares", pixels * 16, BufferUsage::Storage)?;
        let status = Buffer::new(ctx, "dispatch status", STATUS_WORDS * 4, BufferUsage::Storage)?;
        let mut bindings = scene_gpu.bindings();
        bindings.extend(PathTraceBinding::ALL.iter().map(|b| b.slot(Binding::Storage)));
        let mut defines = scene_gpu.defines();
        if scene_gpu.uniform && scene.info().triangle_count <= BRUTE_FORCE_MAX_TRIANGLES {
            defines.push(("SCENE_BRUTE_FORCE", "1"));
        }
        if counters {
            defines.push(("TRAVERSAL_COUNTERS", "1"));
        }
        let mut kernel = scene_gpu.kernel("pathtrace.comp", &defines, bindings, 0)?;
        let mut buffers = scene_gpu.buffers(&params);
        buffers.extend([
            PathTraceBinding::Accum.to(&accum),
            PathTraceBinding::AccumSq.to(&accum_sq),
            PathTraceBinding::Status.to(&status),
        ]);
        kernel.bind(&buffers)?;
        // One dispatch over zero pixels compiles the kernel now (llvmpipe compiles at the first
        // dispatch), so that no sample's GPU time includes it.
        let empty = crate::gpu_types::FrameParams::default();
        params.write(std::slice::from_ref(&empty))?;
        kernel.warm_up(&[]).context("compiling pathtrace.comp")?;
        accum.fill(0)?;
        accum_sq.fill(0)?;
        Ok(Self {
            ctx: ctx.clone(),
            kernel,
            params,
            accum,
            accum_sq,
            status,
            readback: AccumReadback::new(ctx, settings.width, settings.height, STATUS_WORDS * 4)?,
            timer: PassTimer::new(ctx, 1)?,
            base_params: settings.frame_params(scene.info()),
            settings: settings.clone(),
            scene: scene.clone(),
            first_sample: 0,
            samples_done: 0,
            counters: counters.then(TraversalCounters::default),
        })
    }

    /// Starts over with `settings` (another camera, seed, spp or depth) and cleared sums, keeping
    /// the compiled kernel; the resolution must stay the same.
    pub fn restart(&mut self, settings: &RenderSettings) -> Result<()> {
        settings.validate(self.scene.info())?;
        let camera = self.scene.info().cameras[settings.camera].clone();
        self.restart_from(settings, &camera)
    }

    /// [`PathTracer::restart`] seen from `camera`, a pose in scene coordinates (as the scene's
    /// cameras) that need not be one of the scene's; `settings.camera` is not used. Errors: as
    /// `restart`, and a pose whose position or axes are not finite.
    pub fn restart_from(&mut self, settings: &RenderSettings, camera: &crate::scene::Camera) -> Result<()> {
        settings.validate_numbers()?;
        camera.check_pose()?;
        if (settings.width, settings.height) != (self.settings.width, self.settings.height) {
            anyhow::bail!(
                "restart cannot change the resolution ({}x{} to {}x{})",
                self.settings.width,
                self.settings.height,
                settings.width,
                settings.height
            );
        }
        self.accum.fill(0)?;
        self.accum_sq.fill(0)?;
        self.base_params = settings.frame_params_from(self.scene.info(), camera);
        self.settings = settings.clone();
        self.first_sample = 0;
        self.samples_done = 0;
        if let Some(c) = self.counters.as_mut() {
            *c = TraversalCounters::default();
        }
        Ok(())
    }

    /// Makes this render's samples the ones numbered `first`, `first + 1`, ... (up to
    /// `first + spp`) of the same seed, so that renders of disjoint ranges are disjoint shares of
    /// one render; `restart` goes back to 0. Call before the first dispatch.
    pub fn start_at_sample(&mut self, first: u32) {
        self.first_sample = first;
    }

    /// Raises the render's target by `spp` paths per pixel and keeps the sums: the next `render`
    /// continues the same sample sequence, so that its image averages all samples so far (the
    /// image of one render of the total spp, up to float rounding of the sums).
    pub fn add_samples(&mut self, spp: u32) {
        self.settings.spp = self.settings.spp.saturating_add(spp);
    }

    /// The paths per pixel `render` runs up to.
    pub fn target_spp(&self) -> u32 {
        self.settings.spp
    }

    /// Adds `samples` paths per pixel in one submission. Returns its GPU time in ms (None if the
    /// device has no timestamps), the most loop iterations any subgroup ran and the number of
    /// paths with a non-finite radiance or throughput.
    pub fn dispatch(&mut self, samples: u32) -> Result<(Option<f64>, u32, u32)> {
        let mut params = self.base_params;
        params.sample_offset = self.first_sample + self.samples_done;
        params.samples_per_dispatch = samples;
        self.params.write(std::slice::from_ref(&params))?;
        let groups = [
            self.settings.width.div_ceil(LOCAL_SIZE),
            self.settings.height.div_ceil(LOCAL_SIZE),
            1,
        ];
        self.ctx
            .submit_and_wait(|cmd| {
                self.status.record_fill(cmd, 0);
                record_compute_barrier(&self.ctx.device, cmd);
                self.timer.record_reset(cmd);
                self.timer.record_begin(cmd, 0);
                self.kernel.record_dispatch(cmd, groups, &[]);
                self.timer.record_end(cmd, 0);
                record_compute_barrier(&self.ctx.device, cmd);
                self.readback.record_counters(cmd, &self.status);
            })
            .context("path tracing")?;
        let status = self.readback.counters::<u32>(STATUS_WORDS as usize)?;
        let (iterations, cut_groups, nonfinite) = (status[0], status[1], status[2]);
        if cut_groups > 0 {
            let limit = self.ctx.info.loop_iteration_limit.unwrap_or(0);
            return Err(GpuError::LoopLimit {
                limit,
                counted: iterations,
                groups: cut_groups,
            }
            .into());
        }
        self.samples_done += samples;
        if let Some(c) = self.counters.as_mut() {
            let words = &status[COUNTER_WORDS_START..];
            c.add(&TraversalCounters::from_words(words, words[2 * COUNTER_COUNT]));
        }
        Ok((self.timer.read_ms(1)?.map(|t| t[0]), iterations, nonfinite))
    }

    /// The largest chunk the driver's loop budget allows, from the last dispatch's cost.
    fn loop_budget_chunk(&self, samples: u32, iterations: u32) -> u32 {
        match self.ctx.info.loop_iteration_limit {
            Some(limit) => {
                let per_sample = iterations.max(1) as f64 / samples as f64;
                ((LOOP_BUDGET_SHARE * limit as f64 / per_sample) as u32).max(1)
            }
            None => u32::MAX,
        }
    }

    /// Renders the requested spp in adaptive chunks. `progress` receives the samples done;
    /// `cancel` stops after the current chunk.
    pub fn render(&mut self, progress: &dyn Fn(u32), cancel: &AtomicBool) -> Result<RenderStats> {
        let start = Instant::now();
        let mut gpu_ms = 0.0;
        let mut chunk = 1u32;
        let mut interrupted = false;
        let mut nonfinite_paths = 0u64;
        let target_ms = if self.ctx.info.device_type == ash::vk::PhysicalDeviceType::CPU {
            TARGET_SUBMISSION_MS_CPU
        } else {
            TARGET_SUBMISSION_MS_GPU
        };
        while self.samples_done < self.settings.spp {
            // The first chunk always runs, so that an interrupted render's image has a sample
            // in every pixel (a pixel of no samples would read 0/0).
            if self.samples_done > 0 && cancel.load(Ordering::Relaxed) {
                interrupted = true;
                break;
            }
            let samples = chunk.min(self.settings.spp - self.samples_done);
            let t0 = Instant::now();
            let (ms, iterations, nonfinite) = self.dispatch(samples)?;
            nonfinite_paths += nonfinite as u64;
            let ms = ms.unwrap_or_else(|| t0.elapsed().as_secs_f64() * 1e3);
            gpu_ms += ms;
            progress(self.samples_done);
            let per_sample = ms / samples as f64;
            chunk = ((target_ms / per_sample.max(1e-3)) as u32)
                .clamp(1, MAX_CHUNK_GROWTH * samples)
                .min(self.loop_budget_chunk(samples, iterations));
        }
        Ok(RenderStats {
            spp: self.samples_done,
            gpu_ms,
            wall_ms: start.elapsed().as_secs_f64() * 1e3,
            nonfinite_paths,
            interrupted,
            counters: self.counters,
        })
    }

    /// What building and compiling the kernel cost.
    pub fn compile_report(&self) -> &KernelCompile {
        self.kernel.compile_report()
    }

    /// The accumulation buffers as they are: per pixel `[sum r, sum g, sum b, samples]` and
    /// `[sum r^2, sum g^2, sum b^2, 0]` of the radiance of its paths, row-major.
    pub fn sums(&self) -> Result<(PixelSums, PixelSums)> {
        Ok(self.readback.sums(&self.accum, &self.accum_sq)?)
    }

    /// The mean of the samples so far, with its variance.
    pub fn image(&self) -> Result<Image> {
        Ok(self.readback.image(&self.accum, &self.accum_sq)?)
    }
}
