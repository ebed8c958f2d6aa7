//! GLSL to SPIR-V with shaderc (glslang), resolving `#include` against the embedded glsl/ tree.

use std::collections::HashMap;
use std::path::Path;
use std::sync::{Mutex, OnceLock};

use anyhow::{anyhow, Result};

use super::spirv_cache;
use crate::shader_interface::{glsl_header, GLSL_HEADER_NAME};

/// Every file under glsl/, keyed by its path relative to glsl/.
pub static GLSL_SOURCES: &[(&str, &str)] = include!(concat!(env!("OUT_DIR"), "/glsl_sources.rs"));

/// The text of glsl/`name`, or of the header generated from src/shader_interface.rs when
/// `name` is its include name.
pub fn glsl_source(name: &str) -> Option<&'static str> {
    if name == GLSL_HEADER_NAME {
        return Some(glsl_header());
    }
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
    static CACHE: OnceLock<Mutex<HashMap<CacheKey, Vec<u32>>>> = OnceLock::new();
    let key = (
        name.to_string(),
        defines.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect::<Vec<_>>(),
    );
    let cache = CACHE.get_or_init(Default::default);
    if let Some(spirv) = cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
        return Ok(spirv);
    }
    let spirv = match spirv_cache::cache_dir() {
        Some(dir) => compile_kernel_cached_in(name, defines, &dir)?.0,
        None => compile_glsl(name, defines)?,
    };
    if let Ok(mut c) = cache.lock() {
        c.insert(key, spirv.clone());
    }
    Ok(spirv)
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

/// GLSL to SPIR-V with shaderc: Vulkan 1.2, SPIR-V 1.5, optimised, with debug information
/// (names for the validation layer's messages and for `reflect`).
fn compile_glsl(name: &str, defines: &[(&str, &str)]) -> Result<Vec<u32>> {
    let source = glsl_source(name).ok_or_else(|| anyhow!("no GLSL kernel named {name} under glsl/"))?;
    let compiler = shaderc::Compiler::new().map_err(|e| anyhow!("cannot initialise shaderc: {e}"))?;
    let mut options = shaderc::CompileOptions::new().map_err(|e| anyhow!("cannot create shaderc options: {e}"))?;
    options.set_target_env(shaderc::TargetEnv::Vulkan, shaderc::EnvVersion::Vulkan1_2 as u32);
    options.set_target_spirv(shaderc::SpirvVersion::V1_5);
    options.set_optimization_level(shaderc::OptimizationLevel::Performance);
    options.set_generate_debug_info();
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
