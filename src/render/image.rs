//! A linear RGB float image with per-pixel variance of the mean.

use glam::Vec3;

/// A rendered image: `width * height` pixels, row-major from the top left, linear RGB radiance.
#[derive(Debug, Clone)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The pixel estimates (the mean of their samples).
    pub mean: Vec<Vec3>,
    /// Variance of the pixel estimate (the sample variance divided by the sample count).
    pub variance: Vec<Vec3>,
}

impl Image {
    /// From per-pixel sums of L (rgb) and counts (w), and sums of L^2. A pixel no sample reached
    /// is NaN, never a plausible-looking 0.
    pub fn from_sums(width: u32, height: u32, sums: &[[f32; 4]], sums_sq: &[[f32; 4]]) -> Image {
        let mut mean = Vec::with_capacity(sums.len());
        let mut variance = Vec::with_capacity(sums.len());
        for (s, q) in sums.iter().zip(sums_sq) {
            if s[3] <= 0.0 {
                mean.push(Vec3::NAN);
                variance.push(Vec3::NAN);
                continue;
            }
            let n = s[3];
            let m = Vec3::new(s[0], s[1], s[2]) / n;
            let m2 = Vec3::new(q[0], q[1], q[2]) / n;
            let sample_var = if n > 1.0 {
                (m2 - m * m).max(Vec3::ZERO) * (n / (n - 1.0))
            } else {
                Vec3::ZERO
            };
            mean.push(m);
            variance.push(sample_var / n);
        }
        Image {
            width,
            height,
            mean,
            variance,
        }
    }

    /// Pixels whose mean has a NaN or infinite channel (a correct render has none).
    pub fn non_finite_count(&self) -> usize {
        self.mean.iter().filter(|p| !p.is_finite()).count()
    }

    /// The mean over all pixels (NaN if any pixel is).
    pub fn average(&self) -> Vec3 {
        self.mean.iter().fold(Vec3::ZERO, |a, &p| a + p) / self.mean.len() as f32
    }
}
