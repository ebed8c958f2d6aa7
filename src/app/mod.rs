//! The commands behind the CLI. Each command's options are declared once, as the clap struct
//! its function takes (`RenderArgs` for `render`, ...); options several commands share are
//! groups in args.rs. main.rs only parses and dispatches.

mod args;
mod bench;
mod charts;
mod compare;
mod compare_outputs;
mod compare_sweep;
mod info;
mod method_spec;
mod profile;
mod reference;
pub(crate) mod reference_record;
mod render;
mod render_loop;
mod render_output;
mod shard;
mod stability;
mod sweep;

pub use args::parse_args;
pub use bench::{bench, BenchArgs};
pub use compare::{compare, CompareArgs};
pub use info::{info, InfoArgs};
pub use profile::{profile, ProfileArgs};
pub use reference::{reference, ReferenceArgs};
pub use render::{render, RenderArgs};
pub use shard::{merge, MergeArgs};
pub use stability::{stability, StabilityArgs};

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::Result;

use restir_pt::scene::{collapse_warnings, load_scene_reporting, LoadOptions, Scene};
use restir_pt::vk::{Context, ContextOptions};

use args::DeviceArgs;

/// The bundled scene a command renders when it is given none.
pub const DEFAULT_SCENE: &str = "scenes/cornell.gltf";

/// The text of `DEFAULT_SCENE` (its buffers are data URIs), built into the binary: `cargo
/// install` copies the binary alone, and a command without a scene works from any folder.
const DEFAULT_SCENE_GLTF: &str = include_str!("../../scenes/cornell.gltf");

/// The scene to load: the given path, or the built-in Cornell box (`default_scene_file`).
pub fn scene_path(scene: Option<&Path>) -> Result<PathBuf> {
    match scene {
        Some(p) => Ok(p.to_path_buf()),
        None => default_scene_file(),
    }
}

/// Writes the built-in Cornell box to `$XDG_CACHE_HOME/restir-pt/scenes/DIGEST/cornell.gltf`
/// (`~/.cache` without XDG_CACHE_HOME, the temporary folder without either) unless it is
/// there already, and returns that path; DIGEST names the content, so a file is never stale.
/// The file keeps the name `cornell.gltf`, which names the outputs (out/cornell.exr).
fn default_scene_file() -> Result<PathBuf> {
    use sha2::{Digest, Sha256};
    let digest: String = Sha256::digest(DEFAULT_SCENE_GLTF.as_bytes())[..8]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty()).map(PathBuf::from);
    let cache = var("XDG_CACHE_HOME").or_else(|| var("HOME").map(|h| h.join(".cache")));
    let name = Path::new(DEFAULT_SCENE).file_name().unwrap_or_default();
    let mut errors = Vec::new();
    for base in cache.into_iter().chain([std::env::temp_dir()]) {
        let dir = base.join("restir-pt").join("scenes").join(&digest);
        let file = dir.join(name);
        match write_once(&dir, &file) {
            Ok(()) => {
                eprintln!(
                    "scene: the built-in Cornell box ({DEFAULT_SCENE}, written to {}); give a glTF file to render another",
                    file.display()
                );
                return Ok(file);
            }
            Err(e) => errors.push(format!("{}: {e}", file.display())),
        }
    }
    anyhow::bail!("cannot write the built-in scene: {}", errors.join("; "))
}

/// Writes `DEFAULT_SCENE_GLTF` to `file` in `dir` unless it holds it already, through a file
/// of this process renamed into place, so that processes starting together never read half.
fn write_once(dir: &Path, file: &Path) -> std::io::Result<()> {
    if std::fs::read(file).is_ok_and(|text| text == DEFAULT_SCENE_GLTF.as_bytes()) {
        return Ok(());
    }
    std::fs::create_dir_all(dir)?;
    let temp = dir.join(format!("{}.tmp", std::process::id()));
    std::fs::write(&temp, DEFAULT_SCENE_GLTF)?;
    std::fs::rename(&temp, file)
}

/// A file shipped with the crate (`relative` to its root): from the working folder if it has
/// one, else next to the crate.
pub fn bundled_file(relative: &Path) -> PathBuf {
    if relative.exists() {
        relative.to_path_buf()
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
    }
}

/// Loads a scene and prints the loader's warnings to stderr.
pub fn load_with_warnings(path: &Path) -> Result<Scene> {
    load_with_options(path, &LoadOptions::default())
}

/// Loads a scene with `options` and prints the loader's warnings to stderr, identical ones
/// collapsed with their count; they are printed also when the load then fails.
pub fn load_with_options(path: &Path, options: &LoadOptions) -> Result<Scene> {
    let mut warnings = Vec::new();
    let result = load_scene_reporting(path, options, &mut warnings);
    for w in collapse_warnings(&warnings) {
        eprintln!("warning: {w}");
    }
    result
}

pub fn open_device(args: &DeviceArgs) -> Result<Arc<Context>> {
    let ctx = Context::new(&ContextOptions {
        device: args.device.clone(),
        validation: args.validation(),
        ..Default::default()
    })?;
    eprintln!("device: {} ({:?})", ctx.info.name, ctx.info.device_type);
    Ok(Arc::new(ctx))
}

/// Fails the command if the validation layer reported anything.
pub fn finish_device(ctx: &Context) -> Result<()> {
    ctx.check_validation()?;
    Ok(())
}
