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

pub const DEFAULT_SCENE: &str = "scenes/cornell.gltf";

/// The scene to load: the given path, or the bundled Cornell box.
pub fn scene_path(scene: Option<&Path>) -> PathBuf {
    match scene {
        Some(p) => p.to_path_buf(),
        None => bundled_file(Path::new(DEFAULT_SCENE)),
    }
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
