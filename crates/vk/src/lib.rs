//! restir-pt-vk, the thin Vulkan layer (ash): instance/device selection, buffers, compute
//! kernels compiled from the GLSL under glsl/ (embedded by build.rs) with their bindings checked
//! against the SPIR-V, timing, and the GPU failures a caller may tell apart ([`error`]).
//!
//! It may use restir-pt-interface (the generated GLSL header, the binding families it binds
//! buffers to) and no other layer: it knows kernels and buffers, not scenes, shading or
//! renderers (docs/layout.md). What a device allows a scene is decided where scene and
//! device meet, in the renderer (`restir_pt::render::scene_array_limit`).

// Every public item carries a doc comment (units, spaces, layouts, errors, sources): a new
// undocumented one fails the build, clippy and rustdoc alike.
#![deny(missing_docs)]
// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod error;

mod buffer;
mod context;
mod device_list;
mod device_setup;
mod kernel;
mod reflect;
mod shader;
mod spirv_cache;
mod timer;
mod twin_compile;

pub use buffer::{Buffer, BufferUsage};
pub use context::{Context, ContextOptions, DeviceInfo, ValidationLog, DEFAULT_FENCE_TIMEOUT};
pub use device_list::{list_devices, DeviceSummary};
pub use kernel::{
    record_compute_barrier, record_host_read_barrier, Binding, BindingFamilyExt, BindingSlot, BoundBuffer, Kernel, KernelCompile,
};
pub use reflect::{check_bindings, reflect_bindings, spirv_instructions, ReflectedBinding};
pub use shader::{
    compile_glsl_source, compile_kernel, compile_kernel_cached_in, compile_kernels_in_parallel, glsl_source, process_cpu_ms,
    set_compile_threads, thread_cpu_ms, CompiledKernel, GLSL_SOURCES,
};
pub use spirv_cache::{cache_dir as spirv_cache_dir, SPIRV_CACHE_ENV};
pub use timer::PassTimer;
pub use twin_compile::{set_twin_compile, twin_compile_pays, warm_up_on_twin, TwinCompile, TwinKernel, TWIN_COMPILE_ENV};
