//! `restir-pt reference`: a converged path-traced mean and its variance, in short submissions.

use std::path::PathBuf;

use anyhow::{bail, Result};

use super::render::{interrupt_flag, progress_bar};
use super::{finish_device, load_with_warnings, open_device, scene_path, DeviceArgs};
use crate::image_io::write_exr;
use crate::render::{PathTracer, RenderSettings};

pub struct ReferenceArgs {
    pub scene: PathBuf,
    pub spp: u32,
    pub width: u32,
    pub height: u32,
    pub max_depth: u32,
    pub camera: usize,
    pub seed: u32,
    pub out: PathBuf,
    /// Write a reference with non-finite pixels (with a warning) instead of failing.
    pub allow_nonfinite: bool,
    pub device: DeviceArgs,
}

/// The variance image's path: `ref.exr` -> `ref.variance.exr`.
pub fn variance_path(out: &std::path::Path) -> PathBuf {
    out.with_extension("variance.exr")
}

pub fn reference(args: ReferenceArgs) -> Result<()> {
    let path = scene_path(Some(&args.scene));
    let scene = load_with_warnings(&path)?;
    let settings = RenderSettings {
        width: args.width,
        height: args.height,
        spp: args.spp,
        max_depth: args.max_depth,
        seed: args.seed,
        camera: args.camera,
        ..Default::default()
    };
    settings.validate(&scene)?;
    super::render::create_parent(&args.out)?;
    let ctx = open_device(&args.device)?;
    let mut tracer = PathTracer::new(&ctx, &scene, &settings)?;
    let bar = progress_bar(settings.spp);
    let stats = tracer.render(&|done| bar.set_position(done as u64), &interrupt_flag())?;
    bar.finish_and_clear();
    let image = tracer.image()?;
    let nonfinite = image.non_finite_count();
    if nonfinite > 0 {
        let what = format!("{nonfinite} non-finite pixels ({} non-finite path weights)", stats.nonfinite_paths);
        if !args.allow_nonfinite {
            bail!(
                "{}: {what}; no reference written (--allow-nonfinite writes it anyway)",
                path.display()
            );
        }
        eprintln!("warning: {what}; writing the reference anyway (--allow-nonfinite)");
    }
    let variance = variance_path(&args.out);
    write_exr(&args.out, image.width, image.height, &image.mean)?;
    write_exr(&variance, image.width, image.height, &image.variance)?;
    drop(tracer);
    finish_device(&ctx)?;
    println!(
        "reference {} | {}x{} | {} spp | depth {} | GPU {:.1} ms{}",
        path.display(),
        settings.width,
        settings.height,
        stats.spp,
        settings.max_depth,
        stats.gpu_ms,
        if stats.interrupted { " | interrupted" } else { "" }
    );
    eprintln!("wrote {} and {}", args.out.display(), variance.display());
    Ok(())
}
