//! Equirectangular environment maps (`--env FILE.exr|FILE.hdr`), importance-sampled by luminance:
//! a texel is chosen with probability proportional to its luminance times sin θ (its solid
//! angle), then a direction uniformly in its (u, v) rectangle (pbrt-v4's piecewise-constant 2D
//! distribution, "Sampling Light Sources"). Twin of the environment half of glsl/shading/lights.glsl.
//!
//! Mapping (Mitsuba 3's `envmap` with an identity `to_world`): in the map's own frame
//! u = atan2(d.x, -d.z) / 2π wrapped to [0, 1) across the image, so its left and right edges look
//! along -Z (glTF's forward), u = 1/4 along +X and the centre column along +Z; v = acos(d.y) / π
//! down it (the top row is +Y). Mitsuba 3 is the renderer this project checks its images against
//! (docs/independent-check.md), so an HDRI lights a scene from the same side in both. The map's
//! frame is the scene's turned by `rotation` about +Y (`--env-rotation`, right-handed: 90° turns
//! the map's +Z towards the scene's +X), as Mitsuba's `to_world = rotate([0, 1, 0], angle)`. The
//! radiance of a direction is its texel's (no filtering), so the pdf and the radiance are
//! constant per texel together; the rotation keeps solid angles, so it changes neither.

use std::f32::consts::PI;
use std::path::Path;

use anyhow::{anyhow, bail, Result};
use glam::{Vec2, Vec3};

use restir_pt_interface::gpu_types::Emitter;

use crate::luminance;

/// An equirectangular map with its sampling tables.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentMap {
    /// Width in texels (longitude: u from 0 to 1 covers 2π).
    pub width: u32,
    /// Height in texels (latitude: v from 0, +Y, to 1, -Y).
    pub height: u32,
    /// Radiance, row-major from the top row (+Y).
    pub texels: Vec<Vec3>,
    /// Marginal CDF over rows: `row_cdf[i]` is the probability of rows 0..=i (the last is 1).
    pub row_cdf: Vec<f32>,
    /// Conditional CDF within each row: `texel_cdf[i * width + j]` is the probability of texels
    /// 0..=j given row i.
    pub texel_cdf: Vec<f32>,
    /// (cos, sin) of the map's rotation about +Y, the map's frame to the scene's
    /// ([`Self::with_rotation`]; (1, 0) unrotated).
    pub rotation: Vec2,
}

/// The (u, v) in [0, 1]² of direction `d` (unit, the map's own frame). Twin of GLSL `equirect_uv`.
pub fn equirect_uv(d: Vec3) -> Vec2 {
    let u = d.x.atan2(-d.z) / (2.0 * PI);
    Vec2::new(if u < 0.0 { u + 1.0 } else { u }, d.y.clamp(-1.0, 1.0).acos() / PI)
}

/// The unit direction (the map's own frame) of (u, v). Twin of GLSL `equirect_dir`.
pub fn equirect_dir(uv: Vec2) -> Vec3 {
    let phi = uv.x * 2.0 * PI;
    let theta = uv.y * PI;
    let s = theta.sin();
    Vec3::new(s * phi.sin(), theta.cos(), -s * phi.cos())
}

/// Direction `d` turned about +Y by the angle whose cosine and sine are `cs`: the map's frame to
/// the scene's with (cos, sin) of the rotation, the scene's to the map's with (cos, -sin).
/// Twin of GLSL `env_rotate`.
pub fn env_rotate(d: Vec3, cs: Vec2) -> Vec3 {
    Vec3::new(cs.x * d.x + cs.y * d.z, d.y, cs.x * d.z - cs.y * d.x)
}

/// The first index whose CDF value exceeds `u` (the last if none).
/// Twin of GLSL `cdf_search`.
fn cdf_search(cdf: &[f32], u: f32) -> usize {
    let (mut lo, mut hi) = (0usize, cdf.len() - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if cdf[mid] > u {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

impl EnvironmentMap {
    /// Builds the sampling tables; fails if no texel has positive luminance where sin θ > 0.
    pub fn new(width: u32, height: u32, texels: Vec<Vec3>) -> Result<Self> {
        let (w, h) = (width as usize, height as usize);
        if w == 0 || h == 0 || texels.len() != w * h {
            bail!("an environment map needs width x height texels");
        }
        if texels.iter().any(|t| !t.is_finite() || t.min_element() < 0.0) {
            bail!("the environment map has negative, NaN or infinite texels");
        }
        let weight: Vec<f64> = (0..w * h)
            .map(|k| {
                let theta = PI * ((k / w) as f32 + 0.5) / h as f32;
                luminance(texels[k]) as f64 * theta.sin() as f64
            })
            .collect();
        let total: f64 = weight.iter().sum();
        if !(total > 0.0) {
            bail!("the environment map is black");
        }
        let mut row_cdf = Vec::with_capacity(h);
        let mut texel_cdf = Vec::with_capacity(w * h);
        let mut acc_rows = 0.0f64;
        for i in 0..h {
            let row = &weight[i * w..(i + 1) * w];
            let row_sum: f64 = row.iter().sum();
            let mut acc = 0.0f64;
            for &x in row {
                acc += x;
                texel_cdf.push(if row_sum > 0.0 {
                    (acc / row_sum) as f32
                } else {
                    (texel_cdf.len() % w + 1) as f32 / w as f32
                });
            }
            // Rounding must not leave the last entry below 1: a u near 1 would find no texel.
            *texel_cdf.last_mut().expect("w > 0") = 1.0;
            acc_rows += row_sum;
            row_cdf.push((acc_rows / total) as f32);
        }
        *row_cdf.last_mut().expect("h > 0") = 1.0;
        Ok(Self {
            width,
            height,
            texels,
            row_cdf,
            texel_cdf,
            rotation: Vec2::X,
        })
    }

    /// The map turned by `degrees` about +Y (right-handed: 90 turns the map's +Z, its centre
    /// column, towards the scene's +X).
    pub fn with_rotation(mut self, degrees: f32) -> Self {
        let r = degrees.to_radians();
        self.rotation = Vec2::new(r.cos(), r.sin());
        self
    }

    /// The (u, v) of scene direction `d` (unit) on this map, its rotation undone.
    fn scene_uv(&self, d: Vec3) -> Vec2 {
        equirect_uv(env_rotate(d, Vec2::new(self.rotation.x, -self.rotation.y)))
    }

    /// Reads an OpenEXR (`.exr`) or Radiance (`.hdr`) file of linear RGB radiance.
    pub fn load(path: &Path) -> Result<Self> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        let (width, height, texels) = match ext.as_deref() {
            Some("exr") => read_exr(path)?,
            Some("hdr") => {
                let img = image::ImageReader::open(path)
                    .map_err(|e| anyhow!("{}: cannot read: {e}", path.display()))?
                    .with_guessed_format()
                    .map_err(|e| anyhow!("{}: cannot read: {e}", path.display()))?
                    .decode()
                    .map_err(|e| anyhow!("{}: not a readable Radiance HDR file: {e}", path.display()))?
                    .into_rgb32f();
                let (w, h) = img.dimensions();
                (w, h, img.pixels().map(|p| Vec3::from(p.0)).collect())
            }
            _ => bail!("{}: an environment map must be .exr or .hdr", path.display()),
        };
        Self::new(width, height, texels).map_err(|e| anyhow!("{}: {e}", path.display()))
    }

    /// (row, column) of the texel holding (u, v).
    fn env_texel_of(&self, uv: Vec2) -> (usize, usize) {
        let j = ((uv.x * self.width as f32) as usize).min(self.width as usize - 1);
        let i = ((uv.y * self.height as f32) as usize).min(self.height as usize - 1);
        (i, j)
    }

    /// The probability of texel (i, j), from the CDFs that [`Self::sample_environment`] inverts.
    fn env_texel_probability(&self, i: usize, j: usize) -> f32 {
        let w = self.width as usize;
        let row = self.row_cdf[i] - if i > 0 { self.row_cdf[i - 1] } else { 0.0 };
        let k = i * w + j;
        let texel = self.texel_cdf[k] - if j > 0 { self.texel_cdf[k - 1] } else { 0.0 };
        row * texel
    }

    /// The radiance arriving from direction `d` (unit): the map's part of
    /// `lights::environment_radiance`, the twin of GLSL `environment_radiance`.
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        let (i, j) = self.env_texel_of(self.scene_uv(d));
        self.texels[i * self.width as usize + j]
    }

    /// The solid-angle density of [`Self::sample_environment`] at direction `d` (unit): the texel's
    /// probability times its (u, v) area's inverse, over the map's Jacobian 2π² sin θ.
    pub fn pdf(&self, d: Vec3) -> f32 {
        let uv = self.scene_uv(d);
        // From x and z, not 1 - y²: near the poles y rounds to ±1 while x and z keep sin θ.
        let sin_theta = (d.x * d.x + d.z * d.z).sqrt();
        if sin_theta <= 0.0 {
            return 0.0;
        }
        let (i, j) = self.env_texel_of(uv);
        let p_uv = self.env_texel_probability(i, j) * (self.width * self.height) as f32;
        p_uv / (2.0 * PI * PI * sin_theta)
    }

    /// A direction chosen by luminance with `u` in [0, 1)²: a row by the marginal CDF, a texel
    /// by the row's CDF, then a uniform point of the texel (the CDF's leftover fractions).
    pub fn sample_environment(&self, u: Vec2) -> Vec3 {
        let (w, h) = (self.width as usize, self.height as usize);
        let i = cdf_search(&self.row_cdf, u.x);
        let below = if i > 0 { self.row_cdf[i - 1] } else { 0.0 };
        let fu = ((u.x - below) / (self.row_cdf[i] - below).max(f32::MIN_POSITIVE)).clamp(0.0, 0.999_999_9);
        let row = &self.texel_cdf[i * w..(i + 1) * w];
        let j = cdf_search(row, u.y);
        let left = if j > 0 { row[j - 1] } else { 0.0 };
        let fv = ((u.y - left) / (row[j] - left).max(f32::MIN_POSITIVE)).clamp(0.0, 0.999_999_9);
        let local = equirect_dir(Vec2::new((j as f32 + fv) / w as f32, (i as f32 + fu) / h as f32));
        env_rotate(local, self.rotation)
    }

    /// The rows after the punctual lights in the emitter buffer (glsl/interface/types.glsl): a header
    /// (width, cos, sin, height) with the rotation's cosine and sine, the row CDF (one per row),
    /// then per texel (r, g, b, row CDF value).
    pub fn gpu_rows(&self) -> Vec<Emitter> {
        let header = Emitter::from_words([self.width, self.rotation.x.to_bits(), self.rotation.y.to_bits(), self.height]);
        let rows = self.row_cdf.iter().map(|&c| Emitter {
            triangle: c.to_bits(),
            ..Default::default()
        });
        let texels = self
            .texels
            .iter()
            .zip(&self.texel_cdf)
            .map(|(t, &c)| Emitter::from_words([t.x.to_bits(), t.y.to_bits(), t.z.to_bits(), c.to_bits()]));
        std::iter::once(header).chain(rows).chain(texels).collect()
    }
}

/// Reads the first RGB(A) layer of an EXR: (width, height, row-major linear RGB pixels from the
/// top left; alpha dropped).
///
/// # Errors
/// The file cannot be read or holds no RGB layer; the message names `path`.
pub fn read_exr(path: &Path) -> Result<(u32, u32, Vec<Vec3>)> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _| (resolution.width(), vec![Vec3::ZERO; resolution.width() * resolution.height()]),
        |(w, pixels): &mut (usize, Vec<Vec3>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels[pos.y() * *w + pos.x()] = Vec3::new(r, g, b)
        },
    )
    .map_err(|e| anyhow!("{}: cannot read EXR: {e}", path.display()))?;
    let size = image.layer_data.size;
    Ok((size.width() as u32, size.height() as u32, image.layer_data.channel_data.pixels.1))
}
