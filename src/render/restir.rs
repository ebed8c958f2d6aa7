//! The ReSTIR PT renderer: per frame, initial candidates, temporal reuse, spatial rounds and
//! shading (glsl/restir_*.comp) in one submission, with reservoirs in storage buffers. Which
//! passes run is planned in frame_plan.rs.

use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context as _, Result};

use super::frame_plan::{pass_table, plan_frame, FramePlan, FrameState, PassKernel, PASS_NAMES};
use super::reservoir_layers::ReservoirLayers;
use super::{Image, RenderSettings, RestirSettings, SceneGpu};
use crate::error::GpuError;
use crate::gpu_types::{FrameParams, RestirStats, ReuseParams, Surface};
use crate::scene::Scene;
use crate::shading::shift::ShiftParams;
use crate::vk::{record_compute_barrier, Binding, Buffer, BufferUsage, Context, Kernel, KernelCompile, PassTimer};

const LOCAL_SIZE: u32 = 8;

/// Shared memory of one workgroup of the ReSTIR kernels: the path being built by each of its
/// LOCAL_SIZE² invocations (glsl/shift.glsl, `path_vertices`, `path_lobes`, `path_weights`),
/// per vertex a 32-byte vertex, a lobe and a 16-byte weight row.
const SHARED_BYTES: u32 = LOCAL_SIZE * LOCAL_SIZE * crate::shading::path_record::MAX_PATH_LENGTH as u32 * (32 + 4 + 16);

/// GPU milliseconds per pass of one frame (indexed like PASS_NAMES); None without timestamps.
#[derive(Debug, Clone)]
pub struct FrameStats {
    pub pass_ms: Option<[f64; 4]>,
    pub wall_ms: f64,
    pub counters: RestirStats,
}

impl FrameStats {
    pub fn gpu_ms(&self) -> Option<f64> {
        self.pass_ms.map(|p| p.iter().sum())
    }

    /// Failed shifts over attempted shifts (0 if none was attempted).
    pub fn failed_shift_rate(&self) -> f64 {
        let c = &self.counters;
        if c.shifts_attempted == 0 {
            0.0
        } else {
            c.shifts_failed as f64 / c.shifts_attempted as f64
        }
    }
}

pub struct Restir {
    ctx: Arc<Context>,
    /// The frame's kernels, indexed by `PassKernel as usize`.
    kernels: Vec<Kernel>,
    params: Buffer,
    reuse: Buffer,
    /// Each pixel's surface (glsl/restir_bindings.glsl), this frame's and the previous one's,
    /// shared by the pixel's reservoirs.
    surfaces: [Buffer; 2],
    layers: ReservoirLayers,
    accum: Buffer,
    accum_sq: Buffer,
    stats: Buffer,
    scene_gpu: SceneGpu,
    timer: PassTimer,
    settings: RenderSettings,
    restir: RestirSettings,
    shift_params: ShiftParams,
    frame_index: u32,
    /// The previous frame's final reservoir slot and camera, if temporal reuse may read them.
    history: Option<(u32, FrameParams)>,
    surface_slot: u32,
}

/// The GLSL file and extra `#define`s of each kernel.
fn kernel_source(kernel: PassKernel) -> (&'static str, &'static [(&'static str, &'static str)]) {
    match kernel {
        PassKernel::Initial => ("restir_initial.comp", &[]),
        PassKernel::Temporal => ("restir_temporal.comp", &[]),
        PassKernel::TemporalUnmoved => ("restir_temporal.comp", &[("CANONICAL_DOMAIN_ONLY", "1")]),
        PassKernel::Spatial => ("restir_spatial.comp", &[]),
        PassKernel::Shade => ("restir_shade.comp", &[]),
    }
}

impl Restir {
    /// Uploads `scene`, builds every kernel a run can use and compiles them (see `warm_up`);
    /// the time that took is in `compile_reports`.
    pub fn new(ctx: &Arc<Context>, scene: &Scene, settings: &RenderSettings, restir: &RestirSettings) -> Result<Self> {
        Self::with_progress(ctx, scene, settings, restir, &|_| {})
    }

    /// `new`, telling `progress` the name of each kernel before the driver compiles it.
    pub fn with_progress(
        ctx: &Arc<Context>,
        scene: &Scene,
        settings: &RenderSettings,
        restir: &RestirSettings,
        progress: &dyn Fn(&str),
    ) -> Result<Self> {
        settings.validate(scene)?;
        restir.validate(settings.max_depth)?;
        if ctx.info.max_compute_shared_memory < SHARED_BYTES {
            anyhow::bail!(
                "{}: ReSTIR PT's kernels need {SHARED_BYTES} bytes of shared memory per workgroup, the device offers {}",
                ctx.info.name,
                ctx.info.max_compute_shared_memory
            );
        }
        let pixels = settings.pixel_count() as u64;
        ctx.check_binding_size("the accumulation image", pixels * 16)?;
        let surface_bytes = pixels * std::mem::size_of::<Surface>() as u64;
        ctx.check_binding_size("the surfaces", surface_bytes)?;
        let layers = ReservoirLayers::new(ctx, pixels, restir.reservoirs)?;
        let scene_gpu = SceneGpu::upload(ctx, scene)?;
        let storage = |name: &str, bytes: u64| Buffer::new(ctx, name, bytes, BufferUsage::Storage);
        let params_buffer = |name: &str, bytes: usize| Buffer::new(ctx, name, bytes as u64, BufferUsage::Params);
        let params = params_buffer("frame parameters", std::mem::size_of::<FrameParams>())?;
        let reuse = params_buffer("reuse parameters", std::mem::size_of::<ReuseParams>())?;
        let surfaces = [storage("surfaces 0", surface_bytes)?, storage("surfaces 1", surface_bytes)?];
        let accum = storage("accumulation", pixels * 16)?;
        let accum_sq = storage("accumulation of squares", pixels * 16)?;
        let stats = storage("ReSTIR statistics", std::mem::size_of::<RestirStats>() as u64)?;

        let mut bindings = scene_gpu.bindings();
        bindings.extend([Binding::Storage; 14]);
        let mut defines = scene_gpu.defines();
        defines.extend(restir.defines());
        let mut kernels = Vec::with_capacity(PassKernel::ALL.len());
        for kernel in PassKernel::ALL {
            let (file, extra) = kernel_source(kernel);
            let all: Vec<_> = defines.iter().chain(extra).copied().collect();
            let mut k = scene_gpu.kernel(ctx, file, &all, bindings.clone(), 4)?;
            if kernel == PassKernel::TemporalUnmoved {
                k.set_variant("(unmoved camera)");
            }
            kernels.push(k);
        }
        accum.fill(0)?;
        accum_sq.fill(0)?;
        let mut restir = Self {
            ctx: ctx.clone(),
            kernels,
            params,
            reuse,
            surfaces,
            layers,
            accum,
            accum_sq,
            stats,
            scene_gpu,
            timer: PassTimer::new(ctx, PASS_NAMES.len() as u32)?,
            settings: settings.clone(),
            restir: restir.clone(),
            shift_params: ShiftParams::for_scene(scene),
            frame_index: 0,
            history: None,
            surface_slot: 0,
        };
        restir.bind_buffers();
        restir.warm_up(progress)?;
        Ok(restir)
    }

    /// Dispatches every kernel once over an image of zero pixels, which writes nothing: llvmpipe
    /// compiles a kernel at its first dispatch, and that compile belongs to start-up, not to a
    /// frame's GPU time.
    fn warm_up(&mut self, progress: &dyn Fn(&str)) -> Result<()> {
        let empty = FrameParams {
            width: 0,
            height: 0,
            ..Default::default()
        };
        self.params.write(std::slice::from_ref(&empty))?;
        self.reuse.write(std::slice::from_ref(&ReuseParams::default()))?;
        for kernel in &mut self.kernels {
            progress(&kernel.compile_report().name);
            kernel
                .warm_up(&0u32.to_ne_bytes())
                .with_context(|| format!("compiling {}", kernel.name))?;
        }
        Ok(())
    }

    /// What building and compiling each kernel cost (one entry per kernel).
    pub fn compile_reports(&self) -> Vec<KernelCompile> {
        self.kernels.iter().map(|k| k.compile_report().clone()).collect()
    }

    /// Milliseconds of start-up spent compiling kernels, over all kernels.
    pub fn compile_ms(&self) -> f64 {
        self.kernels.iter().map(|k| k.compile_report().total_ms()).sum()
    }

    /// Points every kernel's descriptors at the current buffers.
    fn bind_buffers(&self) {
        let layers = &self.layers;
        let mut buffers = self.scene_gpu.buffers(&self.params);
        buffers.push(&self.reuse);
        buffers.extend(self.surfaces.iter());
        for (h, t) in layers.heads.iter().zip(&layers.tails) {
            buffers.extend([h, t]);
        }
        buffers.extend([&layers.direct, &self.accum, &self.accum_sq, &self.stats, &layers.expectation]);
        for kernel in &self.kernels {
            kernel.bind(&buffers);
        }
    }

    /// Forgets the temporal history and the accumulated average; the next frame starts a new,
    /// independent chain with seed `seed`.
    pub fn reset(&mut self, seed: u32) -> Result<()> {
        self.accum.fill(0)?;
        self.accum_sq.fill(0)?;
        self.history = None;
        self.frame_index = 0;
        self.settings.seed = seed;
        Ok(())
    }

    /// Changes the reservoirs per pixel of the next frames (a frame-cost knob; the kernels stay
    /// compiled, the per-reservoir buffers are made anew). The history is forgotten.
    pub fn set_reservoirs(&mut self, reservoirs: u32) -> Result<()> {
        let restir = RestirSettings {
            reservoirs,
            ..self.restir.clone()
        };
        restir.validate(self.settings.max_depth)?;
        if reservoirs != self.restir.reservoirs {
            self.layers = ReservoirLayers::new(&self.ctx, self.settings.pixel_count() as u64, reservoirs)?;
            self.bind_buffers();
            self.history = None;
        }
        self.restir = restir;
        Ok(())
    }

    /// The reuse parameters of a frame seen from `frame` after `prev`, with its pass table.
    fn reuse_params(&self, prev: &FrameParams, frame: &FrameParams, plan: &FramePlan, accumulate: bool) -> ReuseParams {
        let temporal_valid = self.restir.temporal && self.history.is_some();
        ReuseParams {
            prev_cam_position: prev.cam_position,
            prev_cam_right: prev.cam_right,
            prev_cam_up: prev.cam_up,
            prev_cam_forward: prev.cam_forward,
            roughness_threshold: self.shift_params.roughness_threshold,
            distance_threshold: self.shift_params.distance_threshold,
            m_cap: self.restir.m_cap,
            radius: self.restir.radius,
            normal_threshold: self.restir.normal_threshold,
            depth_threshold: self.restir.depth_threshold,
            frame_index: self.frame_index,
            candidates: self.restir.candidates,
            neighbours: self.restir.spatial,
            temporal_valid: temporal_valid as u32,
            emission_rays: self.restir.emission_rays,
            reservoirs: self.restir.reservoirs,
            // Frames being accumulated are averaged already; a running mean inside them would
            // only weigh the early frames' rays more.
            emission_history: (temporal_valid && same_pose(prev, frame) && !accumulate) as u32,
            passes: pass_table(plan),
        }
    }

    /// Renders one frame from the scene's camera `camera`. With `accumulate` the frame is added
    /// to the running average (a static camera's offline mode); otherwise the average restarts.
    pub fn frame(&mut self, scene: &Scene, camera: usize, accumulate: bool) -> Result<FrameStats> {
        let start = Instant::now();
        let settings = RenderSettings {
            camera,
            ..self.settings.clone()
        };
        settings.validate(scene)?;
        let frame_params = settings.frame_params(scene);
        let prev = self.history.map(|(_, p)| p).unwrap_or(frame_params);
        let plan = plan_frame(&FrameState {
            history_slot: self.history.map(|(s, _)| s),
            temporal: self.restir.temporal,
            unmoved: same_pose(&prev, &frame_params),
            surface_slot: self.surface_slot,
            spatial_rounds: self.restir.spatial_rounds(),
        });
        self.params.write(std::slice::from_ref(&frame_params))?;
        let reuse = self.reuse_params(&prev, &frame_params, &plan, accumulate);
        self.reuse.write(std::slice::from_ref(&reuse))?;
        self.ctx
            .submit_and_wait(|cmd| self.record_frame(cmd, &plan, accumulate))
            .context("ReSTIR PT frame")?;
        let counters = self.stats.read::<RestirStats>(1)?[0];
        if counters.loop_budget_cut_groups > 0 {
            return Err(GpuError::LoopLimit {
                limit: self.ctx.info.loop_iteration_limit.unwrap_or(0),
                counted: counters.max_loop_iterations,
                groups: counters.loop_budget_cut_groups,
            }
            .into());
        }
        let pass_ms = self.timer.read_ms(PASS_NAMES.len() as u32)?.map(|t| [t[0], t[1], t[2], t[3]]);
        self.history = Some((plan.final_slot, frame_params));
        self.surface_slot = 1 - self.surface_slot;
        self.frame_index += 1;
        Ok(FrameStats {
            pass_ms,
            wall_ms: start.elapsed().as_secs_f64() * 1e3,
            counters,
        })
    }

    /// Records a frame's dispatches; each pass's push constant is its index in the pass table.
    /// Every pass but shading runs once per reservoir (the z dimension); shading averages a
    /// pixel's reservoirs.
    fn record_frame(&self, cmd: ash::vk::CommandBuffer, plan: &FramePlan, accumulate: bool) {
        self.stats.record_fill(cmd, 0);
        if !accumulate {
            self.accum.record_fill(cmd, 0);
            self.accum_sq.record_fill(cmd, 0);
        }
        record_compute_barrier(&self.ctx.device, cmd);
        self.timer.record_reset(cmd);
        let mut open: Option<usize> = None;
        for (index, pass) in plan.passes.iter().enumerate() {
            let slot = pass.kernel.timer_slot();
            if open != Some(slot) {
                if let Some(s) = open {
                    self.timer.record_end(cmd, s as u32);
                }
                self.timer.record_begin(cmd, slot as u32);
                open = Some(slot);
            }
            let layers = if pass.kernel == PassKernel::Shade {
                1
            } else {
                self.restir.reservoirs
            };
            let groups = [
                self.settings.width.div_ceil(LOCAL_SIZE),
                self.settings.height.div_ceil(LOCAL_SIZE),
                layers,
            ];
            self.kernels[pass.kernel as usize].record_dispatch(cmd, groups, &(index as u32).to_ne_bytes());
            record_compute_barrier(&self.ctx.device, cmd);
        }
        if let Some(s) = open {
            self.timer.record_end(cmd, s as u32);
        }
        // Passes that did not run this frame get an empty interval.
        for slot in 0..PASS_NAMES.len() {
            if !plan.passes.iter().any(|p| p.kernel.timer_slot() == slot) {
                self.timer.record_begin(cmd, slot as u32);
                self.timer.record_end(cmd, slot as u32);
            }
        }
    }

    /// The average of the frames accumulated since the last restart.
    pub fn image(&self) -> Result<Image> {
        Ok(Image::read_accumulation(&self.settings, &self.accum, &self.accum_sq)?)
    }
}

/// Whether two frames share a camera pose, compared as glsl/restir_reuse.glsl's same_pose does.
fn same_pose(a: &FrameParams, b: &FrameParams) -> bool {
    a.cam_position == b.cam_position && a.cam_right == b.cam_right && a.cam_up == b.cam_up && a.cam_forward == b.cam_forward
}
