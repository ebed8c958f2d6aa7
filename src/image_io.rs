//! Image files: linear float RGB EXR (mean and variance) and a tonemapped sRGB PNG preview.

use std::path::Path;

use anyhow::{anyhow, Context as _, Result};
use glam::Vec3;

use crate::render::Image;

/// Writes `pixels` (`width * height`, row-major from the top left, linear RGB) as an RGB
/// float EXR.
///
/// # Errors
/// The file cannot be written; the message names `path`.
pub fn write_exr(path: &Path, width: u32, height: u32, pixels: &[Vec3]) -> Result<()> {
    let (w, h) = (width as usize, height as usize);
    exr::prelude::write_rgb_file(path, w, h, |x, y| {
        let p = pixels[y * w + x];
        (p.x, p.y, p.z)
    })
    .map_err(|e| anyhow!("{}: cannot write EXR: {e}", path.display()))
}

pub use crate::scene::environment::read_exr;

/// The 8-bit sRGB code of a linear value (IEC 61966-2-1 transfer function; clamped to [0, 1],
/// rounded to nearest).
pub fn srgb_encode(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let s = if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

/// The exposure of a PNG preview; the EXR is never changed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Exposure {
    /// Scale radiance by 2^EV.
    Ev(f32),
    /// [`auto_exposure_ev`] of the image.
    Auto,
}

/// Middle grey: the log-average luminance an automatic exposure maps to (Reinhard et al. 2002,
/// "Photographic Tone Reproduction for Digital Images", the key value a = 0.18).
pub const AUTO_EXPOSURE_KEY: f32 = 0.18;

/// The exposure (EV) that maps the image's log-average luminance exp(mean(ln(1e-4 + L))) over its
/// finite pixels of positive luminance to [`AUTO_EXPOSURE_KEY`] (pixels of exactly zero, such as
/// a black background, would only darken the key); 0 for an image with no such pixel.
pub fn auto_exposure_ev(pixels: &[Vec3]) -> f32 {
    let logs: Vec<f64> = pixels
        .iter()
        .filter(|p| p.is_finite())
        .map(|&p| crate::scene::luminance(p.max(Vec3::ZERO)) as f64)
        .filter(|&l| l > 0.0)
        .map(|l| (1e-4 + l).ln())
        .collect();
    if logs.is_empty() {
        return 0.0;
    }
    let key = (logs.iter().sum::<f64>() / logs.len() as f64).exp();
    if key <= 1.01e-4 {
        return 0.0;
    }
    (AUTO_EXPOSURE_KEY as f64 / key).log2() as f32
}

/// The EV that `exposure` applies to `image`.
pub fn exposure_ev(exposure: Exposure, image: &Image) -> f32 {
    match exposure {
        Exposure::Ev(ev) => ev,
        Exposure::Auto => auto_exposure_ev(&image.mean),
    }
}

/// A preview: linear radiance clamped to [0, 1] and sRGB-encoded (no exposure change).
pub fn write_png(path: &Path, image: &Image) -> Result<()> {
    write_png_exposed(path, image, 0.0)
}

/// A preview: linear radiance times 2^`ev`, clamped to [0, 1] and sRGB-encoded.
pub fn write_png_exposed(path: &Path, image: &Image, ev: f32) -> Result<()> {
    let scale = ev.exp2();
    let file = std::fs::File::create(path).with_context(|| format!("{}: cannot create PNG", path.display()))?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), image.width, image.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let data: Vec<u8> = image
        .mean
        .iter()
        .map(|&p| p * scale)
        .flat_map(|p| [srgb_encode(p.x), srgb_encode(p.y), srgb_encode(p.z)])
        .collect();
    encoder
        .write_header()
        .and_then(|mut w| w.write_image_data(&data))
        .map_err(|e| anyhow!("{}: cannot write PNG: {e}", path.display()))
}
