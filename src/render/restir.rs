//! The ReSTIR PT renderer: per frame, initial candidates, temporal reuse, spatial rounds and
//! shading (glsl/restir_*.comp) in one submission, with reservoirs in storage buffers.

use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context as _, Result};

use super::{Image, RenderSettings, RestirSettings, SceneGpu};
use crate::error::GpuError;
use crate::gpu_types::{FrameParams, ReservoirHead, ReservoirTail, RestirPass, RestirStats, ReuseParams, Surface};
use crate::scene::Scene;
use crate::shift::ShiftParams;
use crate::vk::{record_compute_barrier, Binding, Buffer, BufferUsage, Context, Kernel, PassTimer};

const LOCAL_SIZE: u32 = 8;
const RESERVOIR_SLOTS: usize = 3;

/// The passes of a frame, in order; their GPU times are reported under these names.
pub const PASS_NAMES: [&str; 4] = ["initial", "temporal", "spatial", "shade"];

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
    initial: Kernel,
    temporal: Kernel,
    spatial: Kernel,
    shade: Kernel,
    params: Buffer,
    reuse: Buffer,
    _surfaces: [Buffer; 2],
    _heads: [Buffer; RESERVOIR_SLOTS],
    _tails: [Buffer; RESERVOIR_SLOTS],
    _direct: Buffer,
    _expectation: Buffer,
    accum: Buffer,
    accum_sq: Buffer,
    stats: Buffer,
    _scene_gpu: SceneGpu,
    timer: PassTimer,
    settings: RenderSettings,
    restir: RestirSettings,
    shift_params: ShiftParams,
    frame_index: u32,
    /// The previous frame's final reservoir slot and camera, if temporal reuse may read them.
    history: Option<(u32, FrameParams)>,
    surface_slot: u32,
}

impl Restir {
    pub fn new(ctx: &Arc<Context>, scene: &Scene, settings: &RenderSettings, restir: &RestirSettings) -> Result<Self> {
        settings.validate(scene)?;
        restir.validate(settings.max_depth)?;
        let pixels = settings.pixel_count() as u64;
        let half = std::mem::size_of::<ReservoirHead>() as u64;
        ctx.check_binding_size("a reservoir half", pixels * half)?;
        ctx.check_binding_size("the surfaces", pixels * std::mem::size_of::<Surface>() as u64)?;
        ctx.check_binding_size("the accumulation image", pixels * 16)?;
        let scene_gpu = SceneGpu::upload(ctx, scene)?;
        let storage = |name: &str, bytes: u64| Buffer::new(ctx, name, bytes, BufferUsage::Storage);
        let params = Buffer::new(
            ctx,
            "frame parameters",
            std::mem::size_of::<FrameParams>() as u64,
            BufferUsage::Uniform,
        )?;
        let reuse = Buffer::new(
            ctx,
            "reuse parameters",
            std::mem::size_of::<ReuseParams>() as u64,
            BufferUsage::Uniform,
        )?;
        let surfaces = [
            storage("surfaces 0", pixels * std::mem::size_of::<Surface>() as u64)?,
            storage("surfaces 1", pixels * std::mem::size_of::<Surface>() as u64)?,
        ];
        let tail = std::mem::size_of::<ReservoirTail>() as u64;
        let heads = [
            storage("reservoir heads 0", pixels * half)?,
            storage("reservoir heads 1", pixels * half)?,
            storage("reservoir heads 2", pixels * half)?,
        ];
        let tails = [
            storage("reservoir tails 0", pixels * tail)?,
            storage("reservoir tails 1", pixels * tail)?,
            storage("reservoir tails 2", pixels * tail)?,
        ];
        let direct = storage("primary emission", pixels * 16)?;
        let accum = storage("accumulation", pixels * 16)?;
        let accum_sq = storage("accumulation of squares", pixels * 16)?;
        let stats = storage("ReSTIR statistics", std::mem::size_of::<RestirStats>() as u64)?;
        let expectation = storage("resampled expectation", pixels * 16)?;

        let mut bindings = scene_gpu.bindings();
        bindings.push(Binding::Uniform);
        bindings.extend([Binding::Storage; 13]);
        let mut buffers = scene_gpu.buffers(&params);
        buffers.push(&reuse);
        buffers.extend(surfaces.iter());
        for (h, t) in heads.iter().zip(&tails) {
            buffers.extend([h, t]);
        }
        buffers.extend([&direct, &accum, &accum_sq, &stats, &expectation]);
        let mut defines = scene_gpu.defines();
        defines.extend(restir.defines());
        let push = std::mem::size_of::<RestirPass>() as u32;
        let kernel = |name: &str| -> Result<Kernel> {
            let k = Kernel::new(ctx, name, &defines, &bindings, push)?;
            k.bind(&buffers);
            Ok(k)
        };
        let (initial, temporal, spatial, shade) = (
            kernel("restir_initial.comp")?,
            kernel("restir_temporal.comp")?,
            kernel("restir_spatial.comp")?,
            kernel("restir_shade.comp")?,
        );
        accum.fill(0)?;
        accum_sq.fill(0)?;
        Ok(Self {
            ctx: ctx.clone(),
            initial,
            temporal,
            spatial,
            shade,
            params,
            reuse,
            _surfaces: surfaces,
            _heads: heads,
            _tails: tails,
            _direct: direct,
            _expectation: expectation,
            accum,
            accum_sq,
            stats,
            _scene_gpu: scene_gpu,
            timer: PassTimer::new(ctx, PASS_NAMES.len() as u32)?,
            settings: settings.clone(),
            restir: restir.clone(),
            shift_params: ShiftParams::for_scene(scene),
            frame_index: 0,
            history: None,
            surface_slot: 0,
        })
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

    /// Changes the initial paths per pixel of the next frames (a frame-cost knob; the kernels
    /// stay compiled).
    pub fn set_candidates(&mut self, candidates: u32) -> Result<()> {
        let restir = RestirSettings {
            candidates,
            ..self.restir.clone()
        };
        restir.validate(self.settings.max_depth)?;
        self.restir = restir;
        Ok(())
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
        self.params.write(std::slice::from_ref(&frame_params))?;
        let prev = self.history.map(|(_, p)| p).unwrap_or(frame_params);
        let reuse = ReuseParams {
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
            temporal_valid: (self.restir.temporal && self.history.is_some()) as u32,
            emission_rays: self.restir.emission_rays,
            ..Default::default()
        };
        self.reuse.write(std::slice::from_ref(&reuse))?;

        // The previous frame's result stays in its slot for temporal reuse; the other two
        // slots take turns as pass inputs and outputs.
        let prev_slot = self.history.map(|(s, _)| s).unwrap_or(RESERVOIR_SLOTS as u32 - 1);
        let work: Vec<u32> = (0..RESERVOIR_SLOTS as u32).filter(|&s| s != prev_slot).collect();
        let surface_slot = self.surface_slot;
        let pass = |in_slot: u32, out_slot: u32, pass_seed: u32| RestirPass {
            in_slot,
            out_slot,
            prev_slot,
            surface_slot,
            pass_seed,
        };
        let mut passes: Vec<(&Kernel, usize, RestirPass)> = vec![(&self.initial, 0, pass(0, work[0], 0))];
        let mut current = 0;
        if reuse.temporal_valid != 0 {
            passes.push((&self.temporal, 1, pass(work[current], work[1 - current], 0x7e3a_11c5)));
            current = 1 - current;
        }
        for round in 0..self.restir.spatial_rounds() {
            passes.push((&self.spatial, 2, pass(work[current], work[1 - current], 0x5bd1_e995 ^ (round + 1))));
            current = 1 - current;
        }
        passes.push((&self.shade, 3, pass(work[current], work[current], 0)));
        let groups = [
            self.settings.width.div_ceil(LOCAL_SIZE),
            self.settings.height.div_ceil(LOCAL_SIZE),
            1,
        ];
        self.ctx
            .submit_and_wait(|cmd| {
                self.stats.record_fill(cmd, 0);
                if !accumulate {
                    self.accum.record_fill(cmd, 0);
                    self.accum_sq.record_fill(cmd, 0);
                }
                record_compute_barrier(&self.ctx.device, cmd);
                self.timer.record_reset(cmd);
                let mut open: Option<usize> = None;
                for (kernel, slot, push) in &passes {
                    if open != Some(*slot) {
                        if let Some(s) = open {
                            self.timer.record_end(cmd, s as u32);
                        }
                        self.timer.record_begin(cmd, *slot as u32);
                        open = Some(*slot);
                    }
                    kernel.record_dispatch(cmd, groups, bytemuck::bytes_of(push));
                    record_compute_barrier(&self.ctx.device, cmd);
                }
                if let Some(s) = open {
                    self.timer.record_end(cmd, s as u32);
                }
                // Passes that did not run this frame get an empty interval.
                for slot in 0..PASS_NAMES.len() {
                    if !passes.iter().any(|p| p.1 == slot) {
                        self.timer.record_begin(cmd, slot as u32);
                        self.timer.record_end(cmd, slot as u32);
                    }
                }
            })
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
        self.history = Some((work[current], frame_params));
        self.surface_slot = 1 - self.surface_slot;
        self.frame_index += 1;
        Ok(FrameStats {
            pass_ms,
            wall_ms: start.elapsed().as_secs_f64() * 1e3,
            counters,
        })
    }

    /// The average of the frames accumulated since the last restart.
    pub fn image(&self) -> Result<Image> {
        Ok(Image::read_accumulation(&self.settings, &self.accum, &self.accum_sq)?)
    }
}
