//! A compute pipeline with descriptor sets of buffers (set 0, and set 1 for the scene's surface
//! attributes and textures), bound by name, and an optional push-constant block.

use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context as _, Result};
use ash::vk;
use restir_pt_interface::shader_interface::BindingFamily;

use super::reflect::check_bindings;
use super::shader::{compile_timed, process_cpu_ms, CompiledKernel};
use super::{Buffer, Context};
use crate::error::{vk_error, GpuError};

/// The descriptor kind of a buffer binding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Binding {
    /// A uniform buffer (std140 in GLSL, at most maxUniformBufferRange bytes).
    Uniform,
    /// A storage buffer (std430 in GLSL, at most maxStorageBufferRange bytes).
    Storage,
}

/// One binding of a kernel: its descriptor set and number, the GLSL block declared there and
/// its descriptor kind. crates/interface/src/shader_interface.rs declares those of the renderers'
/// kernels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BindingSlot {
    /// Descriptor set number.
    pub set: u32,
    /// Binding number within the set.
    pub binding: u32,
    /// The GLSL block's type name declared at this binding (checked against the SPIR-V).
    pub block: &'static str,
    /// Uniform or storage buffer.
    pub kind: Binding,
}

impl BindingSlot {
    /// A storage-buffer binding of set 0.
    pub fn storage(binding: u32, block: &'static str) -> Self {
        Self {
            set: 0,
            binding,
            block,
            kind: Binding::Storage,
        }
    }

    /// `buffer` bound to this binding.
    pub fn to(self, buffer: &Buffer) -> BoundBuffer<'_> {
        BoundBuffer { slot: self, buffer }
    }
}

/// The Vulkan side of a binding family of restir-pt-interface: its bindings as [`BindingSlot`]s
/// and buffers bound to them. Implemented for every [`BindingFamily`], so that `use` of this
/// trait gives `SceneBinding::Triangles.slot(kind)` and `RestirBinding::Accum.to(&buffer)`.
pub trait BindingFamilyExt: BindingFamily {
    /// This binding with descriptor kind `kind`, for a kernel's layout.
    fn slot(self, kind: Binding) -> BindingSlot {
        BindingSlot {
            set: Self::SET,
            binding: self.binding(),
            block: self.block(),
            kind,
        }
    }

    /// `buffer` bound to this binding as a storage buffer.
    fn to(self, buffer: &Buffer) -> BoundBuffer<'_> {
        self.slot(Binding::Storage).to(buffer)
    }

    /// This binding moved to set `set` at `first` + its number, for oracle kernels that bind
    /// everything in one set (the surface family, `SURFACE_SET` and `SURFACE_BINDING` in the
    /// GLSL).
    fn slot_at(self, set: u32, first: u32, kind: Binding) -> BindingSlot {
        BindingSlot {
            set,
            binding: first + self.binding(),
            block: self.block(),
            kind,
        }
    }
}

impl<F: BindingFamily> BindingFamilyExt for F {}

/// A buffer for the binding `slot` (checked against the kernel's layout by `Kernel::bind`).
#[derive(Clone, Copy)]
pub struct BoundBuffer<'a> {
    /// The binding it goes to.
    pub slot: BindingSlot,
    /// The buffer bound there, whole.
    pub buffer: &'a Buffer,
}

impl Binding {
    fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            Binding::Uniform => vk::DescriptorType::UNIFORM_BUFFER,
            Binding::Storage => vk::DescriptorType::STORAGE_BUFFER,
        }
    }
}

/// What building one kernel cost, in wall-clock milliseconds per stage, and in CPU milliseconds
/// (which other processes on the machine do not inflate).
/// Drivers may compile at pipeline creation or at the first dispatch (llvmpipe JIT-compiles
/// there), so both count.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KernelCompile {
    /// The GLSL file and its variant, e.g. "restir_temporal.comp (unmoved camera)".
    pub name: String,
    /// Size of the SPIR-V module in bytes.
    pub spirv_bytes: usize,
    /// GLSL to SPIR-V (shaderc; 0 when the process had compiled the same source before).
    pub glsl_ms: f64,
    /// vkCreateComputePipelines.
    pub pipeline_ms: f64,
    /// The first dispatch of one workgroup (see `Kernel::warm_up`), 0 before it.
    pub first_dispatch_ms: f64,
    /// CPU milliseconds of the GLSL to SPIR-V stage on the thread that compiled it.
    pub glsl_cpu_ms: f64,
    /// CPU milliseconds of the process in vkCreateComputePipelines: the driver's alone when
    /// nothing else runs in the process (`set_compile_threads(0)`), else with the GLSL
    /// compiles of other kernels on worker threads meanwhile.
    pub pipeline_cpu_ms: f64,
    /// CPU milliseconds of the process in the first dispatch (lavapipe compiles on its queue
    /// thread, not the caller's), counted as `pipeline_cpu_ms` is.
    pub first_dispatch_cpu_ms: f64,
}

impl KernelCompile {
    /// The sum of the three stages, in milliseconds.
    pub fn total_ms(&self) -> f64 {
        self.glsl_ms + self.pipeline_ms + self.first_dispatch_ms
    }

    /// The sum of the three stages' CPU time, in milliseconds.
    pub fn total_cpu_ms(&self) -> f64 {
        self.glsl_cpu_ms + self.pipeline_cpu_ms + self.first_dispatch_cpu_ms
    }
}

/// A compute pipeline built from one GLSL file with its descriptor sets and their buffers. It
/// holds its [`Context`]; pipeline, layouts and pool are destroyed on drop.
pub struct Kernel {
    /// The GLSL file name under glsl/, e.g. "pathtrace.comp" (named in errors and reports).
    pub name: String,
    compile: KernelCompile,
    /// The bindings of every set.
    bindings: Vec<BindingSlot>,
    push_bytes: u32,
    pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
    /// One layout and one descriptor set per set number up to the highest the bindings use (a
    /// set without bindings still gets its empty layout, so that later sets keep their numbers).
    set_layouts: Vec<vk::DescriptorSetLayout>,
    pool: vk::DescriptorPool,
    sets: Vec<vk::DescriptorSet>,
    module: vk::ShaderModule,
    ctx: Arc<Context>,
}

impl Kernel {
    /// Builds the kernel glsl/`name` with the bindings `layout` (of any sets). Fails when the
    /// compiled shader declares a binding that `layout` lacks or names differently.
    pub fn new(ctx: &Arc<Context>, name: &str, defines: &[(&str, &str)], layout: &[BindingSlot], push_bytes: u32) -> Result<Self> {
        let compiled = compile_timed(name, defines)?;
        Self::with_spirv(ctx, name, &compiled, layout, push_bytes)
    }

    /// Builds the kernel glsl/`name` from its SPIR-V, compiled elsewhere (e.g. by
    /// `compile_kernels_in_parallel`), whose cost goes to the GLSL stage of its report. Fails as
    /// `new` does when the layout does not match the shader's bindings.
    pub fn with_spirv(ctx: &Arc<Context>, name: &str, compiled: &CompiledKernel, layout: &[BindingSlot], push_bytes: u32) -> Result<Self> {
        let spirv = &compiled.spirv;
        check_bindings(name, spirv, layout).map_err(anyhow::Error::msg)?;
        let (start, cpu) = (Instant::now(), process_cpu_ms());
        let mut kernel =
            Self::from_spirv(ctx, name, spirv, layout, push_bytes).with_context(|| format!("creating the compute pipeline {name}"))?;
        kernel.compile = KernelCompile {
            name: name.to_string(),
            spirv_bytes: spirv.len() * 4,
            glsl_ms: compiled.wall_ms,
            pipeline_ms: start.elapsed().as_secs_f64() * 1e3,
            first_dispatch_ms: 0.0,
            glsl_cpu_ms: compiled.cpu_ms,
            pipeline_cpu_ms: process_cpu_ms() - cpu,
            first_dispatch_cpu_ms: 0.0,
        };
        Ok(kernel)
    }

    /// What building this kernel cost so far.
    pub fn compile_report(&self) -> &KernelCompile {
        &self.compile
    }

    /// Names the kernel's variant in its compile report, e.g. "(unmoved camera)".
    pub fn set_variant(&mut self, variant: &str) {
        self.compile.name = format!("{} {variant}", self.name);
    }

    /// Dispatches one workgroup with `push` and waits, so that a driver that compiles at the
    /// first dispatch (llvmpipe) does so now rather than inside a timed frame; the time goes to
    /// `compile_report().first_dispatch_ms`. The caller makes the dispatch harmless, e.g. with
    /// an image size of zero in the bound parameters.
    pub fn warm_up(&mut self, push: &[u8]) -> Result<(), GpuError> {
        let (start, cpu) = (Instant::now(), process_cpu_ms());
        self.run_1d(1, 1, push)?;
        self.compile.first_dispatch_ms = start.elapsed().as_secs_f64() * 1e3;
        self.compile.first_dispatch_cpu_ms = process_cpu_ms() - cpu;
        Ok(())
    }

    fn from_spirv(ctx: &Arc<Context>, name: &str, spirv: &[u32], bindings: &[BindingSlot], push_bytes: u32) -> Result<Self, GpuError> {
        let device = &ctx.device;
        // Each handle is owned by `kernel` as soon as it exists, so an early return frees it.
        let mut kernel = Kernel {
            name: name.to_string(),
            compile: KernelCompile::default(),
            bindings: bindings.to_vec(),
            push_bytes,
            pipeline: vk::Pipeline::null(),
            layout: vk::PipelineLayout::null(),
            set_layouts: Vec::new(),
            pool: vk::DescriptorPool::null(),
            sets: Vec::new(),
            module: vk::ShaderModule::null(),
            ctx: ctx.clone(),
        };
        let module_info = vk::ShaderModuleCreateInfo::default().code(spirv);
        kernel.module = unsafe { device.create_shader_module(&module_info, None) }.map_err(vk_error("creating a shader module"))?;
        let set_count = bindings.iter().map(|b| b.set + 1).max().unwrap_or(1);
        for set in 0..set_count {
            let layout_bindings: Vec<_> = bindings
                .iter()
                .filter(|b| b.set == set)
                .map(|b| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(b.binding)
                        .descriptor_type(b.kind.descriptor_type())
                        .descriptor_count(1)
                        .stage_flags(vk::ShaderStageFlags::COMPUTE)
                })
                .collect();
            let set_layout_info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings);
            let set_layout = unsafe { device.create_descriptor_set_layout(&set_layout_info, None) }
                .map_err(vk_error("creating a descriptor set layout"))?;
            kernel.set_layouts.push(set_layout);
        }
        let set_layouts = kernel.set_layouts.clone();
        let ranges = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::COMPUTE)
            .size(push_bytes)];
        let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
        if push_bytes > 0 {
            layout_info = layout_info.push_constant_ranges(&ranges);
        }
        kernel.layout = unsafe { device.create_pipeline_layout(&layout_info, None) }.map_err(vk_error("creating a pipeline layout"))?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(kernel.module)
            .name(c"main");
        let pipeline_info = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(kernel.layout)];
        kernel.pipeline = unsafe { device.create_compute_pipelines(vk::PipelineCache::null(), &pipeline_info, None) }
            .map_err(|(_, e)| vk_error("creating a compute pipeline")(e))?[0];
        ctx.count_pipeline();

        let mut sizes = Vec::new();
        for kind in [Binding::Uniform, Binding::Storage] {
            let count = bindings.iter().filter(|b| b.kind == kind).count() as u32;
            if count > 0 {
                sizes.push(vk::DescriptorPoolSize::default().ty(kind.descriptor_type()).descriptor_count(count));
            }
        }
        let pool_info = vk::DescriptorPoolCreateInfo::default().max_sets(set_count).pool_sizes(&sizes);
        kernel.pool = unsafe { device.create_descriptor_pool(&pool_info, None) }.map_err(vk_error("creating a descriptor pool"))?;
        let alloc_info = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(kernel.pool)
            .set_layouts(&set_layouts);
        kernel.sets = unsafe { device.allocate_descriptor_sets(&alloc_info) }.map_err(vk_error("allocating descriptor sets"))?;
        Ok(kernel)
    }

    /// Points each binding of the layout at its buffer in `buffers`, matched by set and number
    /// and checked by block name and kind; every binding of each set that `buffers` touches
    /// must be given exactly once (sets are bound separately: a scene's set 1 once at build,
    /// set 0 by the renderer). The caller keeps the buffers alive while dispatching.
    pub fn bind(&self, buffers: &[BoundBuffer]) -> Result<()> {
        let same = |a: &BindingSlot, b: &BindingSlot| a.set == b.set && a.binding == b.binding;
        for (i, bound) in buffers.iter().enumerate() {
            let slot = bound.slot;
            if !self.bindings.contains(&slot) {
                anyhow::bail!(
                    "kernel {}: its layout has no binding {} {} ({:?}) in set {}",
                    self.name,
                    slot.binding,
                    slot.block,
                    slot.kind,
                    slot.set
                );
            }
            if buffers[..i].iter().any(|b| same(&b.slot, &slot)) {
                anyhow::bail!(
                    "kernel {}: binding {} ({}) of set {} given twice",
                    self.name,
                    slot.binding,
                    slot.block,
                    slot.set
                );
            }
        }
        if let Some(missing) = self
            .bindings
            .iter()
            .filter(|s| buffers.iter().any(|b| b.slot.set == s.set))
            .find(|s| !buffers.iter().any(|b| same(&b.slot, s)))
        {
            anyhow::bail!(
                "kernel {}: no buffer for binding {} ({}) of set {}",
                self.name,
                missing.binding,
                missing.block,
                missing.set
            );
        }
        let infos: Vec<[vk::DescriptorBufferInfo; 1]> = buffers
            .iter()
            .map(|b| {
                [vk::DescriptorBufferInfo::default()
                    .buffer(b.buffer.handle)
                    .offset(0)
                    .range(vk::WHOLE_SIZE)]
            })
            .collect();
        let writes: Vec<_> = infos
            .iter()
            .zip(buffers)
            .map(|(info, bound)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(self.sets[bound.slot.set as usize])
                    .dst_binding(bound.slot.binding)
                    .descriptor_type(bound.slot.kind.descriptor_type())
                    .buffer_info(info)
            })
            .collect();
        unsafe { self.ctx.device.update_descriptor_sets(&writes, &[]) };
        Ok(())
    }

    /// Records a dispatch of `groups` workgroups with `push` as the push-constant block.
    pub fn record_dispatch(&self, cmd: vk::CommandBuffer, groups: [u32; 3], push: &[u8]) {
        assert_eq!(
            push.len() as u32,
            self.push_bytes,
            "kernel {} takes {} push-constant bytes",
            self.name,
            self.push_bytes
        );
        let device = &self.ctx.device;
        unsafe {
            device.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            device.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.layout, 0, &self.sets, &[]);
            if !push.is_empty() {
                device.cmd_push_constants(cmd, self.layout, vk::ShaderStageFlags::COMPUTE, 0, push);
            }
            device.cmd_dispatch(cmd, groups[0], groups[1], groups[2]);
        }
    }

    /// Dispatches once over `count` invocations in 1D groups of `local_size` and waits.
    pub fn run_1d(&self, count: u32, local_size: u32, push: &[u8]) -> Result<(), GpuError> {
        self.ctx
            .submit_and_wait(|cmd| self.record_dispatch(cmd, [count.div_ceil(local_size), 1, 1], push))
    }
}

/// Makes the writes of one dispatch (and transfers) visible to the next.
pub fn record_compute_barrier(device: &ash::Device, cmd: vk::CommandBuffer) {
    let barrier = [vk::MemoryBarrier::default()
        .src_access_mask(vk::AccessFlags::SHADER_WRITE | vk::AccessFlags::TRANSFER_WRITE)
        .dst_access_mask(vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE | vk::AccessFlags::TRANSFER_READ)];
    unsafe {
        device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER,
            vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER,
            vk::DependencyFlags::empty(),
            &barrier,
            &[],
            &[],
        )
    };
}

/// Makes transfer writes visible to the host once the submission's fence has signalled.
pub fn record_host_read_barrier(device: &ash::Device, cmd: vk::CommandBuffer) {
    let barrier = [vk::MemoryBarrier::default()
        .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
        .dst_access_mask(vk::AccessFlags::HOST_READ)];
    unsafe {
        device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::TRANSFER,
            vk::PipelineStageFlags::HOST,
            vk::DependencyFlags::empty(),
            &barrier,
            &[],
            &[],
        )
    };
}

impl Drop for Kernel {
    fn drop(&mut self) {
        if self.ctx.is_hung() {
            // An unfinished submission may still use its pipeline and sets (Context::is_hung).
            return;
        }
        let device = &self.ctx.device;
        unsafe {
            device.destroy_pipeline(self.pipeline, None);
            device.destroy_pipeline_layout(self.layout, None);
            device.destroy_descriptor_pool(self.pool, None);
            for &set_layout in &self.set_layouts {
                device.destroy_descriptor_set_layout(set_layout, None);
            }
            device.destroy_shader_module(self.module, None);
        }
    }
}
