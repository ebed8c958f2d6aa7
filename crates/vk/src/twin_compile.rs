//! Compiling kernels on a second device so that the driver's disk cache serves the first.
//!
//! llvmpipe compiles a kernel with LLVM at its first dispatch, on the queue's one thread, and
//! stores the machine code in Mesa's disk cache under a key of the shader's NIR and its variant
//! key (Mesa's `lp_cs_get_ir_cache_key`). A renderer that warms up N kernels one after another
//! therefore keeps one core busy for N compiles. A second device of the same driver, made by
//! another instance on another thread, compiles the same SPIR-V into the same cache entries:
//! while it warms up half of the kernels, the first device warms up the other half, and then
//! finds the twin's half in the cache. The twin only fills a cache: every kernel is still
//! created and dispatched on the renderer's own device, so images cannot differ.

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::shader::CompiledKernel;
use super::{Binding, BindingSlot, Buffer, BufferUsage, Context, ContextOptions, Kernel};

/// When a renderer may compile on a twin device (`set_twin_compile`, [`TWIN_COMPILE_ENV`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum TwinCompile {
    /// Never.
    Off,
    /// Unless every kernel's SPIR-V came from restir-pt's SPIR-V cache: this machine then
    /// compiled them before and the driver's cache most likely holds them, so a twin would
    /// only add its device (0.25 s on a warm start of cornell-glossy). The default.
    WhenCold,
    /// Whenever the device allows it (tests, measurements).
    Always,
}

/// The process-wide `TwinCompile`, as its `u8`.
static TWIN_COMPILE: AtomicU8 = AtomicU8::new(TwinCompile::WhenCold as u8);

/// The environment variable that sets [`TwinCompile`]: `0` Off, `1` Always, unset WhenCold.
pub const TWIN_COMPILE_ENV: &str = "RESTIR_PT_TWIN_COMPILE";

/// Sets when renderers of this process compile on a twin device; [`TWIN_COMPILE_ENV`], where
/// set, overrides it.
pub fn set_twin_compile(mode: TwinCompile) {
    TWIN_COMPILE.store(mode as u8, Ordering::Relaxed);
}

/// The mode in force: [`TWIN_COMPILE_ENV`] if set to `0` or `1`, else `set_twin_compile`'s.
fn twin_compile_mode() -> TwinCompile {
    match std::env::var(TWIN_COMPILE_ENV).as_deref() {
        Ok("0") => TwinCompile::Off,
        Ok("1") => TwinCompile::Always,
        _ => match TWIN_COMPILE.load(Ordering::Relaxed) {
            0 => TwinCompile::Off,
            1 => TwinCompile::WhenCold,
            _ => TwinCompile::Always,
        },
    }
}

/// One kernel for [`warm_up_on_twin`]: its GLSL file name, SPIR-V, bindings of every set and
/// the push-constant bytes its warm-up dispatch passes.
pub struct TwinKernel<'a> {
    /// The GLSL file name, for errors.
    pub name: &'a str,
    /// The SPIR-V exactly as the renderer's device gets it (another module is another cache key).
    pub compiled: &'a CompiledKernel,
    /// The kernel's bindings, as the renderer's device gets them.
    pub layout: &'a [BindingSlot],
    /// The push-constant block of the warm-up dispatch.
    pub push: &'a [u8],
}

/// Whether warming kernels up on a twin of `ctx`'s device can shorten a start-up whose
/// kernels' SPIR-V all came from restir-pt's cache (`spirv_cached`) or not: the mode allows it
/// ([`TwinCompile`]), the device compiles at first dispatch into a disk cache (a CPU device:
/// lavapipe), Mesa's disk cache is not switched off, the machine has a second core, and no
/// validation layer is in the process (Debian 12's layer races between devices made on two
/// threads; see [`ContextOptions::validation`]).
pub fn twin_compile_pays(ctx: &Context, spirv_cached: bool) -> bool {
    let env_on = |name: &str| std::env::var(name).is_ok_and(|v| matches!(v.to_lowercase().as_str(), "1" | "true" | "yes"));
    let layers_from_env = ["VK_INSTANCE_LAYERS", "VK_LOADER_LAYERS_ENABLE"]
        .iter()
        .any(|name| std::env::var(name).is_ok_and(|v| !v.is_empty()));
    let allowed = match twin_compile_mode() {
        TwinCompile::Off => false,
        TwinCompile::WhenCold => !spirv_cached,
        TwinCompile::Always => true,
    };
    allowed
        && ctx.info.device_type == vk::PhysicalDeviceType::CPU
        && !ctx.validated()
        && !layers_from_env
        && !env_on("MESA_SHADER_CACHE_DISABLE")
        && !env_on("MESA_GLSL_CACHE_DISABLE")
        && std::thread::available_parallelism().is_ok_and(|n| n.get() >= 2)
}

/// Makes a twin of `ctx`'s device (same driver and device name, no validation), creates each
/// of `kernels` there with zero-filled buffers at every binding and dispatches it once, which
/// makes a compile-at-dispatch driver compile it into its disk cache. The caller's push block
/// and the zeroed parameters must make that dispatch write nothing of consequence: the buffers
/// are dropped with the twin. Returns when the twin is destroyed, which flushes the cache.
///
/// # Errors
/// A failed device creation, allocation, pipeline or dispatch on the twin. The renderer's own
/// device is not touched, so a caller may ignore the error and compile as if no twin ran.
pub fn warm_up_on_twin(ctx: &Context, kernels: &[TwinKernel]) -> Result<()> {
    let twin = Arc::new(Context::new(&ContextOptions {
        device: Some(ctx.info.name.clone()),
        validation: false,
        ..Default::default()
    })?);
    for k in kernels {
        // 64 KiB of zeros per binding (a uniform one at most maxUniformBufferRange), so that a
        // dispatch reading its parameter block reads an image of zero pixels.
        let buffers = k
            .layout
            .iter()
            .map(|slot| {
                let bytes = match slot.kind {
                    Binding::Uniform => twin.info.max_uniform_buffer_range.min(1 << 16),
                    Binding::Storage => 1 << 16,
                };
                let buffer = Buffer::new(&twin, slot.block, bytes, BufferUsage::Storage)?;
                buffer.fill(0)?;
                Ok(buffer)
            })
            .collect::<Result<Vec<_>>>()?;
        let mut kernel = Kernel::with_spirv(&twin, k.name, k.compiled, k.layout, k.push.len() as u32)?;
        let bound: Vec<_> = k.layout.iter().zip(&buffers).map(|(slot, b)| slot.to(b)).collect();
        kernel.bind(&bound)?;
        kernel.warm_up(k.push)?;
    }
    Ok(())
}
