//! `restir-pt reference`: a converged path-traced mean and its variance, in short submissions.

use std::path::PathBuf;

use anyhow::{bail, Result};

use super::reference_record::{scene_name, write_record, ReferenceRecord};
use super::render::{interrupt_flag, progress_bar};
use super::shard::{write_shard, ShardMeta, ShardSpec, ShardSums};
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
    /// Render only this share of the `spp` samples and write their sums to `out` (a shard EXR,
    /// see `shard.rs`) instead of the mean and variance.
    pub shard: Option<ShardSpec>,
    pub device: DeviceArgs,
}

/// The variance image's path: `ref.exr` -> `ref.variance.exr`.
pub fn variance_path(out: &std::path::Path) -> PathBuf {
    out.with_extension("variance.exr")
}

pub fn reference(args: ReferenceArgs) -> Result<()> {
    let path = scene_path(Some(&args.scene));
    let scene = load_with_warnings(&path)?;
    let samples = args.shard.map(|s| s.samples(args.spp)).unwrap_or(0..args.spp);
    if samples.is_empty() {
        bail!(
            "--spp {} cannot be cut into {} shards: each needs at least 1 sample",
            args.spp,
            args.shard.map_or(1, |s| s.count)
        );
    }
    let settings = RenderSettings {
        width: args.width,
        height: args.height,
        spp: samples.len() as u32,
        max_depth: args.max_depth,
        seed: args.seed,
        camera: args.camera,
        ..Default::default()
    };
    settings.validate(&scene)?;
    super::render::create_parent(&args.out)?;
    let ctx = open_device(&args.device)?;
    let mut tracer = PathTracer::new(&ctx, &scene, &settings)?;
    tracer.start_at_sample(samples.start);
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
    if let Some(shard) = args.shard {
        let (sums, sums_sq) = tracer.sums()?;
        let meta = ShardMeta {
            scene: path.display().to_string(),
            width: settings.width,
            height: settings.height,
            max_depth: settings.max_depth,
            camera: settings.camera,
            seed: settings.seed,
            total_spp: args.spp,
            shard: shard.index,
            shards: shard.count,
            first_sample: samples.start,
            spp: stats.spp,
        };
        write_shard(&args.out, &ShardSums { meta, sums, sums_sq })?;
    } else {
        write_exr(&args.out, image.width, image.height, &image.mean)?;
        write_exr(&variance, image.width, image.height, &image.variance)?;
        let record = ReferenceRecord {
            scene: scene_name(&path),
            camera: settings.camera,
            width: image.width,
            height: image.height,
            spp: stats.spp,
        };
        write_record(&args.out, &record)?;
    }
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
    match args.shard {
        Some(s) => eprintln!(
            "wrote shard {}/{} (samples {}..{} of {}) to {}",
            s.index,
            s.count,
            samples.start,
            samples.end,
            args.spp,
            args.out.display()
        ),
        None => eprintln!("wrote {} and {}", args.out.display(), variance.display()),
    }
    Ok(())
}
