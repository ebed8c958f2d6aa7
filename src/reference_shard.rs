//! Reference shards: a converged reference split into N disjoint ranges of its samples, each
//! rendered by its own process (`restir-pt reference --shard I/N`), written as its per-pixel
//! sums and added up afterwards (`restir-pt merge`, or [`merge_shards`] and
//! [`crate::render::Image::from_sums`] from Rust) into the mean and variance one process of the
//! same seed and total spp would give.
//!
//! A shard file is an EXR with one layer of f32 channels `sum.R/G/B`, `sum.N` (samples per
//! pixel) and `sum_sq.R/G/B` (sums of squared radiance), and the render's settings as JSON in
//! the text attribute `restirPtShard`. f32 samples are stored exactly, so the merge sees the
//! sums the GPU accumulated.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context as _, Result};
use serde::{Deserialize, Serialize};

/// The EXR attribute holding a shard's `ShardMeta` as JSON.
const META_ATTRIBUTE: &str = "restirPtShard";
/// Accumulation channels in `Image::from_sums` order: rgb sums then the count, then squares.
const SUM_CHANNELS: [&str; 4] = ["sum.R", "sum.G", "sum.B", "sum.N"];
const SQ_CHANNELS: [&str; 3] = ["sum_sq.R", "sum_sq.G", "sum_sq.B"];

/// Shard `index` of `count` (written `I/N` on the command line, 0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShardSpec {
    /// This shard, `0..count`.
    pub index: u32,
    /// How many shards the reference is split into.
    pub count: u32,
}

impl ShardSpec {
    /// Parses `I/N` with 0 <= I < N.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || anyhow!("--shard '{text}': expected I/N with 0 <= I < N, e.g. 0/4");
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count): (u32, u32) = (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Self { index, count })
    }

    /// The half-open range of sample indices this shard renders out of `spp`: the samples are
    /// cut into `count` contiguous ranges whose sizes differ by at most one.
    pub fn samples(&self, spp: u32) -> std::ops::Range<u32> {
        let at = |i: u32| (i as u64 * spp as u64 / self.count as u64) as u32;
        at(self.index)..at(self.index + 1)
    }
}

/// What a shard was rendered with. Every field but `shard`, `first_sample` and `spp` must agree
/// between the shards of one merge.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardMeta {
    /// The scene file as given to `reference`.
    pub scene: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The longest path, in segments (`RenderSettings::max_depth`).
    pub max_depth: u32,
    /// Index into the scene's cameras.
    pub camera: usize,
    /// The render's random seed (`RenderSettings::seed`).
    pub seed: u32,
    /// Samples per pixel of the whole reference.
    pub total_spp: u32,
    /// This shard's index, 0-based (`ShardSpec`).
    pub shard: u32,
    /// The number of shards the reference is split into.
    pub shards: u32,
    /// This shard's first sample index: it holds samples `first_sample .. first_sample + spp`.
    pub first_sample: u32,
    /// This shard's samples per pixel.
    pub spp: u32,
}

impl ShardMeta {
    /// The fields that make two shards parts of the same reference.
    fn render_key(&self) -> ShardMeta {
        ShardMeta {
            shard: 0,
            first_sample: 0,
            spp: 0,
            ..self.clone()
        }
    }
}

/// Per-pixel accumulations, row-major: `[sum r, sum g, sum b, count]` and `[sum r^2, g^2, b^2, 0]`.
pub struct ShardSums {
    /// What the shard was rendered with.
    pub meta: ShardMeta,
    /// `width * height` pixels of radiance sums and sample counts.
    pub sums: Vec<[f32; 4]>,
    /// `width * height` pixels of sums of squared radiance (variance estimation).
    pub sums_sq: Vec<[f32; 4]>,
}

/// Writes `shard` as the shard EXR described in the module comment.
///
/// # Errors
/// The scene path in `shard.meta` is not Latin-1 (EXR text attributes are), or the file
/// cannot be written; the message names `path`.
pub fn write_shard(path: &Path, shard: &ShardSums) -> Result<()> {
    use exr::prelude::*;
    let meta = serde_json::to_string(&shard.meta)?;
    let mut channels = Vec::new();
    for (c, name) in SUM_CHANNELS.iter().enumerate() {
        let values = shard.sums.iter().map(|s| s[c]).collect();
        channels.push(AnyChannel::new(*name, FlatSamples::F32(values)));
    }
    for (c, name) in SQ_CHANNELS.iter().enumerate() {
        let values = shard.sums_sq.iter().map(|s| s[c]).collect();
        channels.push(AnyChannel::new(*name, FlatSamples::F32(values)));
    }
    let mut attributes = LayerAttributes::named("shard");
    let text = Text::new_or_none(&meta).ok_or_else(|| anyhow!("{}: the scene path is not Latin-1", path.display()))?;
    attributes.other.insert(Text::from(META_ATTRIBUTE), AttributeValue::Text(text));
    let size = (shard.meta.width as usize, shard.meta.height as usize);
    let layer = Layer::new(
        size,
        attributes,
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    exr::image::Image::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|e| anyhow!("{}: cannot write the shard EXR: {e}", path.display()))
}

/// Reads a shard EXR written by [`write_shard`].
///
/// # Errors
/// One line naming `path`: an unreadable EXR, an EXR that is not a shard (no shard attribute
/// or channel), or a size that disagrees with its attribute.
pub fn read_shard(path: &Path) -> Result<ShardSums> {
    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| anyhow!("{}: cannot read EXR: {e}", path.display()))?;
    let layer = &image.layer_data;
    let meta = match layer.attributes.other.get(&Text::from(META_ATTRIBUTE)) {
        Some(AttributeValue::Text(t)) => t.to_string(),
        _ => bail!(
            "{}: not a reference shard (no {META_ATTRIBUTE} attribute; see reference --shard)",
            path.display()
        ),
    };
    let meta: ShardMeta =
        serde_json::from_str(&meta).with_context(|| format!("{}: unreadable {META_ATTRIBUTE} attribute", path.display()))?;
    let pixels = meta.width as usize * meta.height as usize;
    if layer.size.width() != meta.width as usize || layer.size.height() != meta.height as usize {
        bail!(
            "{}: the image is {}x{} but its attribute says {}x{}",
            path.display(),
            layer.size.width(),
            layer.size.height(),
            meta.width,
            meta.height
        );
    }
    let channel = |name: &str| -> anyhow::Result<Vec<f32>> {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name == *name)
            .ok_or_else(|| anyhow!("{}: not a reference shard (no channel {name})", path.display()))?;
        match &c.sample_data {
            FlatSamples::F32(v) if v.len() == pixels => Ok(v.clone()),
            _ => bail!("{}: channel {name} is not {pixels} f32 samples", path.display()),
        }
    };
    let (mut sums, mut sums_sq) = (vec![[0.0f32; 4]; pixels], vec![[0.0f32; 4]; pixels]);
    for (c, name) in SUM_CHANNELS.iter().enumerate() {
        for (s, v) in sums.iter_mut().zip(channel(name)?) {
            s[c] = v;
        }
    }
    for (c, name) in SQ_CHANNELS.iter().enumerate() {
        for (s, v) in sums_sq.iter_mut().zip(channel(name)?) {
            s[c] = v;
        }
    }
    Ok(ShardSums { meta, sums, sums_sq })
}

/// Adds shards of one reference (checked to share its settings and to cover disjoint sample
/// ranges) in f64 and rounds the totals to f32 once, as the GPU's accumulation holds them.
/// Returns the merged sums (`meta.spp` their samples, `meta.shards` the set's size) and the
/// indices of the set's shards not given.
///
/// # Errors
/// No path given, a file [`read_shard`] refuses, a shard of another reference (other settings)
/// or the same shard twice; the message names the file.
pub fn merge_shards(paths: &[PathBuf]) -> Result<(ShardSums, Vec<u32>)> {
    let Some(first_path) = paths.first() else {
        bail!("merge: no shard files given");
    };
    let first = read_shard(first_path)?;
    let key = first.meta.render_key();
    let pixels = first.sums.len();
    let mut sums = vec![[0.0f64; 4]; pixels];
    let mut sums_sq = vec![[0.0f64; 3]; pixels];
    let mut seen: Vec<(u32, &Path)> = vec![];
    let mut spp = 0u32;
    for path in paths {
        let shard = if path == first_path { None } else { Some(read_shard(path)?) };
        let shard = shard.as_ref().unwrap_or(&first);
        if shard.meta.render_key() != key {
            bail!(
                "{}: a shard of another reference (its settings {} differ from {}'s {})",
                path.display(),
                serde_json::to_string(&shard.meta.render_key())?,
                first_path.display(),
                serde_json::to_string(&key)?
            );
        }
        if let Some((_, other)) = seen.iter().find(|(i, _)| *i == shard.meta.shard) {
            bail!(
                "{}: shard {} is already given as {}",
                path.display(),
                shard.meta.shard,
                other.display()
            );
        }
        seen.push((shard.meta.shard, path));
        spp += shard.meta.spp;
        for (total, s) in sums.iter_mut().zip(&shard.sums) {
            for c in 0..4 {
                total[c] += s[c] as f64;
            }
        }
        for (total, s) in sums_sq.iter_mut().zip(&shard.sums_sq) {
            for c in 0..3 {
                total[c] += s[c] as f64;
            }
        }
    }
    let missing = (0..key.shards).filter(|i| !seen.iter().any(|(s, _)| s == i)).collect();
    let meta = ShardMeta {
        shard: 0,
        first_sample: 0,
        spp,
        ..first.meta
    };
    Ok((
        ShardSums {
            meta,
            sums: sums.iter().map(|s| s.map(|v| v as f32)).collect(),
            sums_sq: sums_sq.iter().map(|s| [s[0] as f32, s[1] as f32, s[2] as f32, 0.0]).collect(),
        },
        missing,
    ))
}
