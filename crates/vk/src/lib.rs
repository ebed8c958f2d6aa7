//! The thin Vulkan layer: instance/device selection, buffers, compute kernels and timing.

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
pub use kernel::{record_compute_barrier, record_host_read_barrier, Binding, BindingSlot, BoundBuffer, Kernel, KernelCompile};
pub use reflect::{check_bindings, reflect_bindings, ReflectedBinding};
pub use shader::{
    compile_kernel, compile_kernel_cached_in, compile_kernels_in_parallel, glsl_source, process_cpu_ms, set_compile_threads, thread_cpu_ms,
    CompiledKernel,
};
pub use spirv_cache::{cache_dir as spirv_cache_dir, SPIRV_CACHE_ENV};
pub use timer::PassTimer;
pub use twin_compile::{set_twin_compile, twin_compile_pays, warm_up_on_twin, TwinCompile, TwinKernel, TWIN_COMPILE_ENV};
