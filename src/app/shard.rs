//! `restir-pt merge`: reference shards (`reference --shard I/N`, see
//! `restir_pt::reference_shard`) added up into the mean and variance EXRs that one `reference`
//! process of the same seed and total spp writes.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

use super::reference::variance_path;
use restir_pt::image_io::write_exr;
use restir_pt::reference_shard::merge_shards;
use restir_pt::render::Image;

/// `restir-pt merge`: shards to the mean EXR at `out` and the variance EXR next to it.
/// `restir-pt merge`.
#[derive(clap::Args, Debug, Clone)]
pub struct MergeArgs {
    /// Shard EXRs written by `reference --shard I/N`.
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Mean EXR; the variance goes next to it as NAME.variance.exr.
    #[arg(long)]
    pub out: PathBuf,
    /// Write a reference with NaN or infinite pixels (with a warning) instead of failing.
    #[arg(long)]
    pub allow_nonfinite: bool,
}

pub fn merge(args: MergeArgs) -> Result<()> {
    let (out, allow_nonfinite) = (args.out.as_path(), args.allow_nonfinite);
    super::render_output::check_extension("--out", out, "exr", "OpenEXR")?;
    let (merged, missing) = merge_shards(&args.shards)?;
    let meta = &merged.meta;
    if !missing.is_empty() {
        eprintln!(
            "warning: shards {missing:?} of {} are missing: the reference has {} of {} spp",
            meta.shards, meta.spp, meta.total_spp
        );
    } else if meta.spp != meta.total_spp {
        eprintln!(
            "warning: the shards hold {} of {} spp (was a shard interrupted?)",
            meta.spp, meta.total_spp
        );
    }
    let image = Image::from_sums(meta.width, meta.height, &merged.sums, &merged.sums_sq);
    let nonfinite = image.non_finite_count();
    if nonfinite > 0 {
        if !allow_nonfinite {
            bail!(
                "{}: {nonfinite} non-finite pixels after merging; no reference written (--allow-nonfinite writes it anyway)",
                meta.scene
            );
        }
        eprintln!("warning: {nonfinite} non-finite pixels; writing the reference anyway (--allow-nonfinite)");
    }
    super::render_output::create_parent(out)?;
    let variance = variance_path(out);
    write_exr(out, image.width, image.height, &image.mean)?;
    write_exr(&variance, image.width, image.height, &image.variance)?;
    let record = super::reference_record::ReferenceRecord {
        scene: super::reference_record::scene_name(Path::new(&meta.scene)),
        camera: meta.camera,
        width: meta.width,
        height: meta.height,
        spp: meta.spp,
    };
    super::reference_record::write_record(out, &record)?;
    println!(
        "merged {} shards of {} | {}x{} | {} spp",
        args.shards.len(),
        meta.scene,
        meta.width,
        meta.height,
        meta.spp
    );
    eprintln!("wrote {} and {}", out.display(), variance.display());
    Ok(())
}
