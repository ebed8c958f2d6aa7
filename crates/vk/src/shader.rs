//! GLSL to SPIR-V with shaderc (glslang), resolving `#include` against the embedded glsl/ tree.

use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{mpsc, Mutex, OnceLock};
use std::time::Instant;

use anyhow::{anyhow, Result};

use super::spirv_cache;

/// Every file under glsl/ (but glsl/generated/), keyed by its path relative to glsl/, and the
/// header that crates/vk/build.rs generated from crates/interface/ under its include name
/// (`shader_interface.glsl`).
pub static GLSL_SOURCES: &[(&str, &str)] = include!(concat!(env!("OUT_DIR"), "/glsl_sources.rs"));

/// The text of glsl/`name`, or of the generated header when `name` is its include name.
pub fn glsl_source(name: &str) -> Option<&'static str> {
    GLSL_SOURCES.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// Joins `path` onto `dir` and folds "." and ".." segments, as the include table has no folders.
fn normalize_path(dir: &str, path: &str) -> String {
    let mut parts: Vec<&str> = Vec::new();
    for segment in dir.split('/').chain(path.split('/')) {
        match segment {
            "" | "." => {}
            ".." => {
                parts.pop();
            }
            s => parts.push(s),
        }
    }
    parts.join("/")
}

fn resolve_include(requested: &str, kind: shaderc::IncludeType, requester: &str) -> Option<(String, &'static str)> {
    let relative = match (kind, requester.rsplit_once('/')) {
        (shaderc::IncludeType::Relative, Some((dir, _))) => normalize_path(dir, requested),
        _ => normalize_path("", requested),
    };
    // Includes written relative to a subfolder may still name a top-level file.
    [relative, requested.to_string()]
        .into_iter()
        .find_map(|name| glsl_source(&name).map(|s| (name, s)))
}

type CacheKey = (String, Vec<(String, String)>);

/// Compiles the compute kernel `name` (a path under glsl/) with the given `#define`s.
/// Results are kept for the process (tests build the same kernels many times) and on disk
/// across processes (`spirv_cache`).
pub fn compile_kernel(name: &str, defines: &[(&str, &str)]) -> Result<Vec<u32>> {
    Ok(compile_kernel_noting_cache(name, defines)?.0)
}

/// `compile_kernel`, and whether the SPIR-V came from a cache (the process's or the disk's)
/// rather than from shaderc.
fn compile_kernel_noting_cache(name: &str, defines: &[(&str, &str)]) -> Result<(Vec<u32>, bool)> {
    static CACHE: OnceLock<Mutex<HashMap<CacheKey, Vec<u32>>>> = OnceLock::new();
    let key = (
        name.to_string(),
        defines.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect::<Vec<_>>(),
    );
    let cache = CACHE.get_or_init(Default::default);
    if let Some(spirv) = cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
        return Ok((spirv, true));
    }
    let (spirv, from_disk) = match spirv_cache::cache_dir() {
        Some(dir) => compile_kernel_cached_in(name, defines, &dir)?,
        None => (compile_glsl(name, defines)?, false),
    };
    if let Ok(mut c) = cache.lock() {
        c.insert(key, spirv.clone());
    }
    Ok((spirv, from_disk))
}

/// One kernel's SPIR-V from [`compile_kernels_in_parallel`], with what compiling it cost.
pub struct CompiledKernel {
    /// The SPIR-V words.
    pub spirv: Vec<u32>,
    /// Wall-clock milliseconds of `compile_kernel` on its thread (0-ish from a cache).
    pub wall_ms: f64,
    /// CPU milliseconds its thread spent in `compile_kernel`, which other processes do not
    /// inflate as they do the wall-clock time.
    pub cpu_ms: f64,
    /// Whether the SPIR-V came from restir-pt's SPIR-V cache (this process's or the disk's):
    /// then this machine has most likely compiled the kernel before, and the driver's own
    /// cache holds it too.
    pub from_cache: bool,
}

/// The CPU time of the calling thread, in milliseconds (0 where the clock is unavailable).
pub fn thread_cpu_ms() -> f64 {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes one timespec through a valid pointer.
    if unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) } != 0 {
        return 0.0;
    }
    t.tv_sec as f64 * 1e3 + t.tv_nsec as f64 * 1e-6
}

/// The CPU time of the whole process, in milliseconds (0 where the clock is unavailable).
pub fn process_cpu_ms() -> f64 {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes one timespec through a valid pointer.
    if unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) } != 0 {
        return 0.0;
    }
    t.tv_sec as f64 * 1e3 + t.tv_nsec as f64 * 1e-6
}

/// Worker threads of `compile_kernels_in_parallel`; `usize::MAX` stands for one per core.
static COMPILE_THREADS: AtomicUsize = AtomicUsize::new(usize::MAX);

/// Sets how many worker threads `compile_kernels_in_parallel` compiles GLSL on: 0 compiles
/// each kernel on the calling thread just before it is consumed, so that nothing else runs in
/// the process while the driver compiles and each stage's process CPU time is its own (what
/// `restir-pt info --kernels` reports).
pub fn set_compile_threads(threads: usize) {
    COMPILE_THREADS.store(threads, Ordering::Relaxed);
}

/// Compiles `name` with `defines`, timed on the calling thread.
pub(super) fn compile_timed(name: &str, defines: &[(&str, &str)]) -> Result<CompiledKernel> {
    let (start, cpu) = (Instant::now(), thread_cpu_ms());
    let (spirv, from_cache) = compile_kernel_noting_cache(name, defines)?;
    Ok(CompiledKernel {
        spirv,
        wall_ms: start.elapsed().as_secs_f64() * 1e3,
        cpu_ms: thread_cpu_ms() - cpu,
        from_cache,
    })
}

/// Compiles the kernels `jobs` (a path under glsl/ and its defines, as `compile_kernel` takes
/// them) on worker threads, one per core, taking them in order, and hands each result to
/// `consume` on the calling thread in the order of `jobs` as soon as it is ready. shaderc
/// compiles on one core; so the calling thread can build the driver's pipeline of kernel i
/// (llvmpipe: another single-threaded compile) while the workers compile kernels i+1 onwards.
/// Stops at the first error of `consume` or of a compile.
pub fn compile_kernels_in_parallel(
    jobs: &[(&str, Vec<(&str, &str)>)],
    mut consume: impl FnMut(usize, CompiledKernel) -> Result<()>,
) -> Result<()> {
    let workers = match COMPILE_THREADS.load(Ordering::Relaxed) {
        usize::MAX => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    };
    if workers == 0 {
        return jobs
            .iter()
            .enumerate()
            .try_for_each(|(i, (name, defines))| consume(i, compile_timed(name, defines)?));
    }
    let workers = workers.min(jobs.len());
    let next = AtomicUsize::new(0);
    let stop = std::sync::atomic::AtomicBool::new(false);
    let (senders, receivers): (Vec<_>, Vec<_>) = jobs.iter().map(|_| mpsc::channel::<Result<CompiledKernel>>()).unzip();
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= jobs.len() || stop.load(Ordering::Relaxed) {
                    break;
                }
                let (name, defines) = &jobs[i];
                let result = compile_timed(name, defines);
                // The receiver is gone only when the caller has stopped.
                let _ = senders[i].send(result);
            });
        }
        let result = receivers.iter().enumerate().try_for_each(|(i, receiver)| {
            let compiled = receiver
                .recv()
                .map_err(|_| anyhow!("the compile thread of {} stopped", jobs[i].0))??;
            consume(i, compiled)
        });
        stop.store(true, Ordering::Relaxed);
        result
    })
}

/// `compile_kernel` through the on-disk cache in `dir` alone: the SPIR-V, and whether it came
/// from the cache.
pub fn compile_kernel_cached_in(name: &str, defines: &[(&str, &str)], dir: &Path) -> Result<(Vec<u32>, bool)> {
    let key = spirv_cache::cache_key(name, defines);
    if let Some(spirv) = spirv_cache::load(dir, &key) {
        return Ok((spirv, true));
    }
    let spirv = compile_glsl(name, defines)?;
    spirv_cache::store(dir, &key, &spirv);
    Ok((spirv, false))
}

/// GLSL to SPIR-V with shaderc: Vulkan 1.2, SPIR-V 1.5, unoptimised, with glslang's names (for
/// the validation layer's messages and for `reflect`) and no line information.
///
/// spirv-opt is left out because the driver optimises again: lavapipe lowers SPIR-V to NIR and
/// runs NIR's and LLVM's optimisers on it. The unoptimised SPIR-V gave bit-identical images on
/// the untextured scenes tried and images within 5e-7 relative on a textured one (Avocado),
/// while shaderc's `Performance` level spent 1 to 3 s of CPU per ReSTIR kernel, half of a cold
/// start-up (docs/performance.md, "Start-up"). Unoptimised, glslang keeps its `OpName`s
/// without `-g`, which would only add line records.
fn compile_glsl(name: &str, defines: &[(&str, &str)]) -> Result<Vec<u32>> {
    let source = glsl_source(name).ok_or_else(|| anyhow!("no GLSL kernel named {name} under glsl/"))?;
    compile_glsl_source(name, source, defines)
}

/// Compiles the compute kernel text `source`, named `name` in messages and as the includer of
/// its `#include`s (which resolve against the embedded glsl/ tree and the generated header as a
/// file's under glsl/ do), with the options of every kernel; not cached. For kernels written by
/// a program, such as the layout test's, which declares every generated record.
pub fn compile_glsl_source(name: &str, source: &str, defines: &[(&str, &str)]) -> Result<Vec<u32>> {
    let compiler = shaderc::Compiler::new().map_err(|e| anyhow!("cannot initialise shaderc: {e}"))?;
    let mut options = shaderc::CompileOptions::new().map_err(|e| anyhow!("cannot create shaderc options: {e}"))?;
    options.set_target_env(shaderc::TargetEnv::Vulkan, shaderc::EnvVersion::Vulkan1_2 as u32);
    options.set_target_spirv(shaderc::SpirvVersion::V1_5);
    options.set_optimization_level(shaderc::OptimizationLevel::Zero);
    for (k, v) in defines {
        options.add_macro_definition(k, Some(v));
    }
    options.set_include_callback(|requested, kind, requester, _depth| {
        resolve_include(requested, kind, requester)
            .map(|(resolved_name, content)| shaderc::ResolvedInclude {
                resolved_name,
                content: content.to_string(),
            })
            .ok_or_else(|| format!("{requester}: cannot find include {requested:?} under glsl/"))
    });
    let artifact = compiler
        .compile_into_spirv(source, shaderc::ShaderKind::Compute, name, "main", Some(&options))
        .map_err(|e| anyhow!("GLSL compilation of {name} failed:\n{e}"))?;
    Ok(artifact.as_binary().to_vec())
}
