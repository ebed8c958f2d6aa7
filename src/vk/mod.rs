//! The thin Vulkan layer: instance/device selection, buffers, compute kernels and timing.

mod buffer;
mod context;
mod kernel;
mod shader;
mod timer;

pub use buffer::{Buffer, BufferUsage};
pub use context::{Context, ContextOptions, DeviceInfo, ValidationLog};
pub use kernel::{record_compute_barrier, Binding, Kernel, KernelCompile};
pub use shader::{compile_kernel, glsl_source};
pub use timer::PassTimer;
