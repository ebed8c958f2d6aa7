//! `restir-pt reference`: a converged path-traced mean and its variance, in short submissions.

use std::ops::Range;
use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Args;

use super::args::{DeviceArgs, PathArgs, SizeArgs};
use super::reference_record::{scene_name, write_record, ReferenceRecord};
use super::render_output::{check_extension, create_parent, interrupt_flag, progress_bar};
use super::{finish_device, load_with_warnings, open_device, scene_path};
use restir_pt::image_io::write_exr;
use restir_pt::reference_shard::{write_shard, ShardMeta, ShardSpec, ShardSums};
use restir_pt::render::{Image, PathTracer, RenderSettings, RenderStats, SceneGpu, SceneInfo};

/// `restir-pt reference`.
#[derive(Args, Debug, Clone)]
pub struct ReferenceArgs {
    /// glTF 2.0 scene (.gltf or .glb).
    pub scene: PathBuf,
    /// Samples per pixel of the whole reference (of all shards together with --shard).
    #[arg(long, default_value_t = 4096)]
    pub spp: u32,
    #[command(flatten)]
    pub size: SizeArgs,
    #[command(flatten)]
    pub path: PathArgs,
    /// Mean EXR; the variance goes next to it as NAME.variance.exr.
    #[arg(long)]
    pub out: PathBuf,
    /// Write a reference with NaN or infinite pixels (with a warning) instead of failing.
    #[arg(long)]
    pub allow_nonfinite: bool,
    /// Render only share I of N (0-based) of the --spp samples, disjoint from the other shares,
    /// and write their per-pixel sums to --out as a shard EXR for `merge`.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    #[command(flatten)]
    pub device: DeviceArgs,
}

/// The variance image's path: `ref.exr` -> `ref.variance.exr`.
pub fn variance_path(out: &std::path::Path) -> PathBuf {
    out.with_extension("variance.exr")
}

pub fn reference(args: ReferenceArgs) -> Result<()> {
    let shard = args.shard.as_deref().map(ShardSpec::parse).transpose()?;
    check_extension("--out", &args.out, "exr", "OpenEXR")?;
    if args.spp == 0 {
        bail!("--spp must be at least 1");
    }
    let path = scene_path(Some(&args.scene))?;
    let scene = load_with_warnings(&path)?;
    let samples = shard.map(|s| s.samples(args.spp)).unwrap_or(0..args.spp);
    if samples.is_empty() {
        bail!(
            "--spp {} cannot be cut into {} shards: each needs at least 1 sample",
            args.spp,
            shard.map_or(1, |s| s.count)
        );
    }
    let settings = RenderSettings {
        width: args.size.width,
        height: args.size.height,
        spp: samples.len() as u32,
        max_depth: args.path.max_depth,
        seed: args.path.seed,
        camera: args.path.camera,
        russian_roulette: args.path.russian_roulette.on(),
    };
    settings.validate(&SceneInfo::of(&scene))?;
    create_parent(&args.out)?;
    let ctx = open_device(&args.device)?;
    let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, &scene)?, &settings)?;
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
    let written = Written {
        path: &path,
        settings: &settings,
        stats: &stats,
        samples,
        shard,
    };
    written.write(&args, &tracer, &image)?;
    drop(tracer);
    finish_device(&ctx)?;
    written.print(&args);
    Ok(())
}

/// What a reference run rendered, to be written as a reference or a shard.
struct Written<'a> {
    path: &'a Path,
    settings: &'a RenderSettings,
    stats: &'a RenderStats,
    samples: Range<u32>,
    shard: Option<ShardSpec>,
}

impl Written<'_> {
    /// The shard's sums, or the mean, variance and record of a whole reference.
    fn write(&self, args: &ReferenceArgs, tracer: &PathTracer, image: &Image) -> Result<()> {
        let (path, settings, stats) = (self.path, self.settings, self.stats);
        if let Some(shard) = self.shard {
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
                first_sample: self.samples.start,
                spp: stats.spp,
            };
            write_shard(&args.out, &ShardSums { meta, sums, sums_sq })
        } else {
            write_exr(&args.out, image.width, image.height, &image.mean)?;
            write_exr(&variance_path(&args.out), image.width, image.height, &image.variance)?;
            let record = ReferenceRecord {
                scene: scene_name(path),
                camera: settings.camera,
                width: image.width,
                height: image.height,
                spp: stats.spp,
            };
            write_record(&args.out, &record)
        }
    }

    /// The summary line and what was written where.
    fn print(&self, args: &ReferenceArgs) {
        let (settings, stats) = (self.settings, self.stats);
        println!(
            "reference {} | {}x{} | {} spp | depth {} | GPU {:.1} ms{}",
            self.path.display(),
            settings.width,
            settings.height,
            stats.spp,
            settings.max_depth,
            stats.gpu_ms,
            if stats.interrupted { " | interrupted" } else { "" }
        );
        match self.shard {
            Some(s) => eprintln!(
                "wrote shard {}/{} (samples {}..{} of {}) to {}",
                s.index,
                s.count,
                self.samples.start,
                self.samples.end,
                args.spp,
                args.out.display()
            ),
            None => eprintln!("wrote {} and {}", args.out.display(), variance_path(&args.out).display()),
        }
    }
}
