//! The ReSTIR PT renderer: per frame, initial candidates, temporal reuse, spatial rounds and
//! shading (glsl/restir_*.comp) in one submission, with reservoirs in storage buffers. Which
//! passes run is planned in frame_plan.rs (a pure function), recorded in restir/record.rs.

use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context as _, Result};

use self::buffers::RestirBuffers;
use self::params::same_pose;
use super::frame_plan::{plan_frame, FramePlan, FrameState};
use super::image_readback::AccumReadback;
use super::reservoir_layers::ReservoirLayers;
use super::restir_passes::{PassDeclaration, PassKernel, PassTimes, PASS_COUNT};
use super::{Image, RenderSettings, RestirSettings, SceneGpu};
use crate::error::GpuError;
use crate::gpu_types::{FrameParams, RestirStats, ReuseParams};
use crate::scene::Camera;
use crate::shader_interface::IMAGE_LOCAL_SIZE;
use crate::shading::shift::ShiftParams;
use crate::vk::{
    compile_kernels_in_parallel, process_cpu_ms, twin_compile_pays, warm_up_on_twin, Binding, BindingFamilyExt, BindingSlot,
    CompiledKernel, Context, Kernel, KernelCompile, PassTimer, TwinKernel,
};

mod buffers;
mod params;
mod record;

const LOCAL_SIZE: u32 = IMAGE_LOCAL_SIZE;

/// The push block of every dispatch: the index of its pass-table entry (`ReuseParams::passes`).
const PUSH_BYTES: u32 = std::mem::size_of::<u32>() as u32;

/// The push block of a warm-up dispatch, which writes nothing.
const WARM_UP_PUSH: [u8; PUSH_BYTES as usize] = [0; PUSH_BYTES as usize];

/// Kernels `compiled` split in two sets of about equal SPIR-V size (llvmpipe's compile time
/// grows with it), the largest kernel in the first: indices into `compiled`, each set in
/// ascending order.
fn halves_by_size(compiled: &[CompiledKernel]) -> (Vec<usize>, Vec<usize>) {
    let mut order: Vec<usize> = (0..compiled.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(compiled[i].spirv.len()));
    let (mut halves, mut sizes) = ((Vec::new(), Vec::new()), (0, 0));
    for i in order {
        if sizes.0 <= sizes.1 {
            halves.0.push(i);
            sizes.0 += compiled[i].spirv.len();
        } else {
            halves.1.push(i);
            sizes.1 += compiled[i].spirv.len();
        }
    }
    halves.0.sort_unstable();
    halves.1.sort_unstable();
    halves
}

/// Shared memory of one workgroup of the ReSTIR kernels: the path being built by each of its
/// LOCAL_SIZE² invocations (glsl/shading/shift/path.glsl, `path_vertices`, `path_lobes`, `path_weights`),
/// per vertex a 32-byte vertex, a lobe and a 16-byte weight row.
const SHARED_BYTES: u32 = LOCAL_SIZE * LOCAL_SIZE * crate::shading::path_record::MAX_PATH_LENGTH as u32 * (32 + 4 + 16);

/// The set-0 layout of `pass`'s kernel: the scene's bindings, then the ReSTIR buffers its row
/// reads or writes.
fn pass_layout(scene: &SceneGpu, pass: &PassDeclaration) -> Vec<BindingSlot> {
    let mut layout = scene.bindings();
    layout.extend(pass.bindings().into_iter().map(|b| b.slot(Binding::Storage)));
    layout
}

/// What one ReSTIR PT frame ([`Restir::frame`]) took, and its counters.
#[derive(Debug, Clone)]
pub struct FrameStats {
    /// GPU milliseconds per pass, indexed like [`PASS_NAMES`](super::PASS_NAMES) (initial,
    /// temporal, spatial, shade; about 0 for a pass the frame did not run); `None` where the
    /// device has no timestamp queries.
    pub pass_ms: Option<PassTimes>,
    /// Wall-clock milliseconds of the frame, parameter upload and counter readback included.
    pub wall_ms: f64,
    /// The kernels' counters for this frame (shifts, dropped candidates, non-finite values).
    pub counters: RestirStats,
}

impl FrameStats {
    /// Sum of `pass_ms`: the frame's GPU time in milliseconds, if measured.
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

    /// Traversals per attempted shift in the temporal and spatial passes (each shift traces
    /// at least its primary ray, so at least 1); None if no shift was attempted.
    pub fn traversals_per_shift(&self) -> Option<f64> {
        let c = &self.counters;
        (c.shifts_attempted > 0).then(|| c.reuse_traversals as f64 / c.shifts_attempted as f64)
    }

    /// Share of SIMD lanes doing a shift while their subgroup runs the shift code (in 0..=1):
    /// shifts attempted over (subgroup runs of the shift code × lanes per subgroup). The rest
    /// idle under the mask, their pixel having no input to shift at that step; None if no shift
    /// ran.
    pub fn shift_lane_use(&self) -> Option<f64> {
        let c = &self.counters;
        let slots = c.shift_subgroup_runs as f64 * c.subgroup_size as f64;
        (slots > 0.0).then(|| c.shifts_attempted as f64 / slots)
    }
}

/// ReSTIR PT on one uploaded scene at one resolution: one `frame` per camera pose, with the
/// temporal history and the running average of a static camera kept between frames.
pub struct Restir {
    ctx: Arc<Context>,
    /// The frame's kernels, indexed by `PassKernel as usize`; None until built.
    kernels: Vec<Option<Kernel>>,
    /// Wall-clock and process CPU milliseconds spent building kernels (`compile_ms`).
    compile_ms: f64,
    compile_cpu_ms: f64,
    /// Kernels a twin device compiled into the driver's cache first (`build`).
    twin_warmed: usize,
    buffers: RestirBuffers,
    /// The image and the per-frame counters come back through it.
    readback: AccumReadback,
    scene_gpu: Arc<SceneGpu>,
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
    /// A ReSTIR PT renderer of the uploaded `scene` on its device: builds every kernel a run
    /// can use and compiles them (see `build`); the time that took is in `compile_reports`.
    /// Errors: settings invalid for the scene, too little shared memory, a failed allocation or
    /// compile.
    pub fn new(scene: &Arc<SceneGpu>, settings: &RenderSettings, restir: &RestirSettings) -> Result<Self> {
        Self::with_kernels(scene, settings, restir, &PassKernel::ALL, &|_| {})
    }

    /// `new`, telling `progress` the name of each kernel before the driver compiles it.
    pub fn with_progress(
        scene: &Arc<SceneGpu>,
        settings: &RenderSettings,
        restir: &RestirSettings,
        progress: &dyn Fn(&str),
    ) -> Result<Self> {
        Self::with_kernels(scene, settings, restir, &PassKernel::ALL, progress)
    }

    /// A renderer that builds only `kernels` at start-up (those a run will dispatch:
    /// [`RestirSettings::kernels_for_cameras`]), compiling their GLSL on worker threads while
    /// the driver compiles the ones ready (see `build`). A frame that needs a kernel left out
    /// builds it before it is recorded, outside the frame's GPU time; the images are the same
    /// either way. `progress` hears each kernel's name before the driver compiles it.
    pub fn with_kernels(
        scene: &Arc<SceneGpu>,
        settings: &RenderSettings,
        restir: &RestirSettings,
        kernels: &[PassKernel],
        progress: &dyn Fn(&str),
    ) -> Result<Self> {
        let ctx = scene.ctx();
        settings.validate(scene.info())?;
        restir.validate(settings.max_depth)?;
        if ctx.info.max_compute_shared_memory < SHARED_BYTES {
            anyhow::bail!(
                "{}: ReSTIR PT's kernels need {SHARED_BYTES} bytes of shared memory per workgroup, the device offers {}",
                ctx.info.name,
                ctx.info.max_compute_shared_memory
            );
        }
        let buffers = RestirBuffers::new(ctx, settings.pixel_count() as u64, restir.reservoirs)?;
        let stats_bytes = std::mem::size_of::<RestirStats>() as u64;
        let mut renderer = Self {
            ctx: ctx.clone(),
            kernels: PassKernel::ALL.iter().map(|_| None).collect(),
            compile_ms: 0.0,
            compile_cpu_ms: 0.0,
            twin_warmed: 0,
            buffers,
            readback: AccumReadback::new(ctx, settings.width, settings.height, stats_bytes)?,
            scene_gpu: scene.clone(),
            timer: PassTimer::new(ctx, PASS_COUNT as u32)?,
            settings: settings.clone(),
            restir: restir.clone(),
            shift_params: scene.info().shift_params,
            frame_index: 0,
            history: None,
            surface_slot: 0,
        };
        renderer.build(kernels, progress)?;
        Ok(renderer)
    }

    /// Builds those of `wanted` not built yet: their GLSL compiled on worker threads
    /// (`compile_kernels_in_parallel`), each pipeline created, bound and dispatched once over
    /// an image of zero pixels (which writes nothing) on this thread as soon as its SPIR-V is
    /// ready. llvmpipe compiles a kernel at its first dispatch, and that compile belongs to
    /// start-up, not to a frame's GPU time. Where a twin device pays (`twin_compile_pays`),
    /// about half of the kernels, by SPIR-V size, are first compiled on a twin device on
    /// another thread while this thread builds the other half, and then found in the driver's
    /// disk cache (crates/vk/src/twin_compile.rs).
    fn build(&mut self, wanted: &[PassKernel], progress: &dyn Fn(&str)) -> Result<()> {
        let (start, cpu) = (Instant::now(), process_cpu_ms());
        let mut todo: Vec<PassKernel> = Vec::new();
        for &k in wanted {
            if self.kernels[k as usize].is_none() && !todo.contains(&k) {
                todo.push(k);
            }
        }
        if todo.is_empty() {
            return Ok(());
        }
        let empty = FrameParams {
            width: 0,
            height: 0,
            ..Default::default()
        };
        self.buffers.params.write(std::slice::from_ref(&empty))?;
        self.buffers.reuse.write(std::slice::from_ref(&ReuseParams::default()))?;
        let scene_gpu = self.scene_gpu.clone();
        let mut defines = scene_gpu.defines();
        defines.extend(self.restir.defines());
        let jobs: Vec<(&str, Vec<(&str, &str)>)> = todo
            .iter()
            .map(|k| {
                let (file, extra) = k.source();
                (file, defines.iter().chain(extra).copied().collect())
            })
            .collect();
        let mut built = 0;
        let mut build_one = |this: &mut Self, i: usize, compiled: &CompiledKernel| -> Result<()> {
            built += 1;
            let pass = todo[i].declaration();
            let mut k = scene_gpu.kernel_with_spirv(jobs[i].0, compiled, pass_layout(&scene_gpu, pass), PUSH_BYTES)?;
            if let Some(variant) = pass.variant {
                k.set_variant(variant);
            }
            progress(&format!("{} ({built}/{})", k.compile_report().name, todo.len()));
            k.bind(&this.buffers.pass_table(&scene_gpu, pass))?;
            k.warm_up(&WARM_UP_PUSH).with_context(|| format!("compiling {}", k.name))?;
            this.kernels[todo[i] as usize] = Some(k);
            Ok(())
        };
        if todo.len() < 2 || !twin_compile_pays(&self.ctx, false) {
            compile_kernels_in_parallel(&jobs, |i, compiled| build_one(self, i, &compiled))?;
        } else {
            let mut compiled = Vec::new();
            compile_kernels_in_parallel(&jobs, |_, c| {
                compiled.push(c);
                Ok(())
            })?;
            let (mine, theirs) = if twin_compile_pays(&self.ctx, compiled.iter().all(|c| c.from_cache)) {
                halves_by_size(&compiled)
            } else {
                ((0..compiled.len()).collect(), Vec::new())
            };
            let layouts: Vec<_> = theirs
                .iter()
                .map(|&i| scene_gpu.layout(pass_layout(&scene_gpu, todo[i].declaration())))
                .collect();
            let twin_kernels: Vec<TwinKernel> = theirs
                .iter()
                .zip(&layouts)
                .map(|(&i, layout)| TwinKernel {
                    name: jobs[i].0,
                    compiled: &compiled[i],
                    layout,
                    push: &WARM_UP_PUSH,
                })
                .collect();
            let ctx = self.ctx.clone();
            let mut this_twin_warmed = 0;
            std::thread::scope(|scope| -> Result<()> {
                let twin = (!twin_kernels.is_empty()).then(|| scope.spawn(move || warm_up_on_twin(&ctx, &twin_kernels)));
                for &i in &mine {
                    build_one(self, i, &compiled[i])?;
                }
                // A twin that failed only leaves its kernels to be compiled here.
                if matches!(twin.map(|t| t.join()), Some(Ok(Ok(())))) {
                    this_twin_warmed += theirs.len();
                }
                theirs.iter().try_for_each(|&i| build_one(self, i, &compiled[i]))
            })?;
            self.twin_warmed += this_twin_warmed;
        }
        self.compile_ms += start.elapsed().as_secs_f64() * 1e3;
        self.compile_cpu_ms += process_cpu_ms() - cpu;
        Ok(())
    }

    /// The kernels built so far, in frame order.
    fn built(&self) -> impl Iterator<Item = &Kernel> {
        self.kernels.iter().flatten()
    }

    /// What building and compiling each kernel cost (one entry per kernel built so far).
    pub fn compile_reports(&self) -> Vec<KernelCompile> {
        self.built().map(|k| k.compile_report().clone()).collect()
    }

    /// Wall-clock milliseconds spent building kernels, start-up and any kernel a frame needed
    /// later. Below the sum of the reports' stages where GLSL compiled on other threads.
    pub fn compile_ms(&self) -> f64 {
        self.compile_ms
    }

    /// How many of the kernels built so far a twin device compiled first, into the driver's
    /// disk cache, while this device compiled the others (crates/vk/src/twin_compile.rs); 0 where no
    /// twin paid or it failed.
    pub fn twin_warmed_kernels(&self) -> usize {
        self.twin_warmed
    }

    /// CPU milliseconds of the whole process while it built kernels (every thread: GLSL
    /// workers, the driver's), which other processes on the machine do not inflate.
    pub fn compile_cpu_ms(&self) -> f64 {
        self.compile_cpu_ms
    }

    /// Points every kernel's descriptors at the current buffers, by binding name.
    fn bind_buffers(&self) -> Result<()> {
        for (kernel, pass) in self.kernels.iter().zip(PassKernel::ALL) {
            if let Some(k) = kernel {
                k.bind(&self.buffers.pass_table(&self.scene_gpu, pass.declaration()))?;
            }
        }
        Ok(())
    }

    /// Forgets the temporal history and the accumulated average; the next frame starts a new,
    /// independent chain with seed `seed`.
    pub fn reset(&mut self, seed: u32) -> Result<()> {
        self.buffers.accum.fill(0)?;
        self.buffers.accum_sq.fill(0)?;
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
            self.buffers.layers = ReservoirLayers::new(&self.ctx, self.settings.pixel_count() as u64, reservoirs)?;
            self.bind_buffers()?;
            self.history = None;
        }
        self.restir = restir;
        Ok(())
    }

    /// Renders one frame from the scene's camera `camera`, in one submission. With
    /// `accumulate` the frame is added to the running average (a static camera's offline
    /// mode); otherwise the average restarts.
    pub fn frame(&mut self, camera: usize, accumulate: bool) -> Result<FrameStats> {
        let settings = RenderSettings {
            camera,
            ..self.settings.clone()
        };
        settings.validate(self.scene_gpu.info())?;
        let camera = self.scene_gpu.info().cameras[camera].clone();
        self.frame_from(&camera, accumulate)
    }

    /// [`Restir::frame`] seen from `camera`, a pose in scene coordinates (as the scene's
    /// cameras) that need not be one of the scene's: a scripted camera path. A pose equal to
    /// the last frame's counts as an unmoved camera. Errors: a pose whose position or axes are
    /// not finite, or a failed submission.
    pub fn frame_from(&mut self, camera: &Camera, accumulate: bool) -> Result<FrameStats> {
        let start = Instant::now();
        camera.check_pose()?;
        let frame_params = self.settings.frame_params_from(self.scene_gpu.info(), camera);
        let plan = self.plan(&frame_params);
        let needed: Vec<PassKernel> = plan.passes.iter().map(|p| p.kernel).collect();
        self.build(&needed, &|_| {})?;
        self.write_params(&frame_params, &plan, accumulate)?;
        self.ctx
            .submit_and_wait(|cmd| self.record_frame(cmd, &plan, accumulate))
            .context("ReSTIR PT frame")?;
        let counters = self.read_counters()?;
        let pass_ms = self.timer.read_ms(PASS_COUNT as u32)?.map(|t| std::array::from_fn(|p| t[p]));
        self.history = Some((plan.final_slot, frame_params));
        self.surface_slot = 1 - self.surface_slot;
        self.frame_index += 1;
        Ok(FrameStats {
            pass_ms,
            wall_ms: start.elapsed().as_secs_f64() * 1e3,
            counters,
        })
    }

    /// The passes of a frame from `frame` after the history (see frame_plan.rs).
    fn plan(&self, frame: &FrameParams) -> FramePlan {
        let prev = self.history.map(|(_, p)| p).unwrap_or(*frame);
        plan_frame(&FrameState {
            history_slot: self.history.map(|(s, _)| s),
            temporal: self.restir.temporal,
            unmoved: same_pose(&prev, frame),
            surface_slot: self.surface_slot,
            spatial_rounds: self.restir.spatial_rounds(),
            history: self.restir.history,
        })
    }

    /// Writes the frame and reuse parameters of the planned frame.
    fn write_params(&self, frame: &FrameParams, plan: &FramePlan, accumulate: bool) -> Result<()> {
        let prev = self.history.map(|(_, p)| p).unwrap_or(*frame);
        self.buffers.params.write(std::slice::from_ref(frame))?;
        let reuse = self.reuse_params(&prev, frame, plan, accumulate);
        self.buffers.reuse.write(std::slice::from_ref(&reuse))?;
        Ok(())
    }

    /// The frame's counters; a frame whose loops ran out of the driver's budget is an error.
    fn read_counters(&self) -> Result<RestirStats> {
        let counters = self.readback.counters::<RestirStats>(1)?[0];
        if counters.loop_budget_cut_groups > 0 {
            return Err(GpuError::LoopLimit {
                limit: self.ctx.info.loop_iteration_limit.unwrap_or(0),
                counted: counters.max_loop_iterations,
                groups: counters.loop_budget_cut_groups,
            }
            .into());
        }
        Ok(counters)
    }

    /// The average of the frames accumulated since the last restart.
    pub fn image(&self) -> Result<Image> {
        Ok(self.readback.image(&self.buffers.accum, &self.buffers.accum_sq)?)
    }
}
