//! The thin Vulkan layer: instance/device selection, buffers, compute kernels and timing.

mod buffer;
mod context;
mod device_setup;
mod kernel;
mod reflect;
mod shader;
mod spirv_cache;
mod timer;

pub use buffer::{Buffer, BufferUsage};
pub use context::{Context, ContextOptions, DeviceInfo, ValidationLog, DEFAULT_FENCE_TIMEOUT};
pub use kernel::{record_compute_barrier, record_host_read_barrier, Binding, BindingSlot, BoundBuffer, Kernel, KernelCompile};
pub use reflect::{check_bindings, reflect_bindings, ReflectedBinding};
pub use shader::{compile_kernel, compile_kernel_cached_in, glsl_source};
pub use spirv_cache::{cache_dir as spirv_cache_dir, SPIRV_CACHE_ENV};
pub use timer::PassTimer;
