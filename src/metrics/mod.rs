//! Image error metrics against a reference: relMSE (also trimmed), MAPE, MSE, energy,
//! frame-to-frame flicker, and LDR- and HDR-ꟻLIP.

use glam::Vec3;

mod flip;
pub use flip::{hdr_flip, hdr_flip_exposures, hdr_flip_map, ldr_flip_map, PIXELS_PER_DEGREE};

/// Guards relMSE's denominator where the reference is black (the usual 1e-2 of the literature).
pub const REL_MSE_EPSILON: f32 = 1e-2;

pub use crate::scene::luminance;

fn check_sizes(image: &[Vec3], reference: &[Vec3]) {
    assert_eq!(image.len(), reference.len(), "an image and its reference differ in size");
}

/// One pixel's (x - r)^2 / (r^2 + 1e-2), summed over its channels.
pub fn rel_squared_error(x: Vec3, r: Vec3) -> f64 {
    let d = x - r;
    (d * d / (r * r + Vec3::splat(REL_MSE_EPSILON))).element_sum() as f64
}

/// Mean over pixels and channels of (x - r)^2 / (r^2 + 1e-2), accumulated in f64.
pub fn rel_mse(image: &[Vec3], reference: &[Vec3]) -> f64 {
    check_sizes(image, reference);
    let sum: f64 = image.iter().zip(reference).map(|(x, r)| rel_squared_error(*x, *r)).sum();
    sum / (3 * image.len().max(1)) as f64
}

/// Guards MAPE's denominator where the reference is black: the same 1e-2 as relMSE's, in the
/// reference's radiance units, so that a black reference pixel does not divide by zero and
/// the two metrics treat dark pixels alike.
pub const MAPE_EPSILON: f32 = 1e-2;

/// Mean absolute percentage error as the ReSTIR papers report it (Lin et al. 2022, GRIS):
/// the mean over pixels and channels of |x - r| / (r + [`MAPE_EPSILON`]), accumulated in f64;
/// 0.1 reads as 10%. Unlike relMSE it weighs an error linearly, so a few fireflies count less.
pub fn mape(image: &[Vec3], reference: &[Vec3]) -> f64 {
    check_sizes(image, reference);
    let sum: f64 = image
        .iter()
        .zip(reference)
        .map(|(x, r)| ((*x - *r).abs() / (*r + Vec3::splat(MAPE_EPSILON))).element_sum() as f64)
        .sum();
    sum / (3 * image.len().max(1)) as f64
}

/// The share of pixels `rel_mse_trimmed` leaves out: 0.1%, as papers on path guiding do, so
/// that a handful of fireflies does not decide a single frame's error.
pub const TRIMMED_SHARE: f64 = 1e-3;

/// relMSE without the largest `share` of per-pixel errors (floor(share × pixels) pixels),
/// averaged over the pixels kept.
pub fn rel_mse_trimmed(image: &[Vec3], reference: &[Vec3], share: f64) -> f64 {
    check_sizes(image, reference);
    let mut errors: Vec<f64> = image.iter().zip(reference).map(|(x, r)| rel_squared_error(*x, *r)).collect();
    errors.sort_by(f64::total_cmp);
    let kept = errors.len() - (share * errors.len() as f64).floor() as usize;
    errors[..kept].iter().sum::<f64>() / (3 * kept.max(1)) as f64
}

/// Mean over pixels and channels of (x - r)^2.
pub fn mse(image: &[Vec3], reference: &[Vec3]) -> f64 {
    check_sizes(image, reference);
    let sum: f64 = image.iter().zip(reference).map(|(x, r)| (*x - *r).length_squared() as f64).sum();
    sum / (3 * image.len().max(1)) as f64
}

fn mean_luminance(image: &[Vec3]) -> f64 {
    image.iter().map(|&c| luminance(c) as f64).sum::<f64>() / image.len().max(1) as f64
}

/// The image's mean luminance over the reference's.
pub fn energy_ratio(image: &[Vec3], reference: &[Vec3]) -> f64 {
    check_sizes(image, reference);
    mean_luminance(image) / mean_luminance(reference)
}

/// Temporal flicker: the mean absolute luminance change between two consecutive frames of a
/// static camera, relative to the reference's mean luminance.
pub fn flicker(previous: &[Vec3], current: &[Vec3], reference: &[Vec3]) -> f64 {
    check_sizes(previous, current);
    let change: f64 = previous
        .iter()
        .zip(current)
        .map(|(a, b)| (luminance(*a) - luminance(*b)).abs() as f64)
        .sum::<f64>()
        / current.len().max(1) as f64;
    change / mean_luminance(reference)
}

/// The arithmetic mean; NaN for no values.
pub fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        sum / n as f64
    }
}

/// The standard error of the mean of `values`: the sample standard deviation (n − 1 in the
/// denominator) over √n. None for fewer than two values, which give no estimate of spread.
pub fn standard_error(values: &[f64]) -> Option<f64> {
    let n = values.len();
    if n < 2 {
        return None;
    }
    let m = mean(values.iter().copied());
    let var = values.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1) as f64;
    Some((var / n as f64).sqrt())
}

/// The median (the mean of the two middle values for an even count).
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The q-quantile (0..=1) of `values` by the nearest-rank method.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    let rank = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len());
    v[rank - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mape_is_the_mean_absolute_error_over_reference_plus_epsilon() {
        let reference = [Vec3::new(1.0, 0.5, 0.0), Vec3::splat(2.0)];
        assert_eq!(mape(&reference, &reference), 0.0);
        let image = [Vec3::new(1.1, 0.25, 0.02), Vec3::splat(3.0)];
        // By hand: 0.1/1.01, 0.25/0.51, 0.02/0.01 and three times 1/2.01, over 6 channels.
        let expected = (0.1 / 1.01 + 0.25 / 0.51 + 0.02 / 0.01 + 3.0 / 2.01) / 6.0;
        assert!((mape(&image, &reference) - expected).abs() < 1e-6, "{}", mape(&image, &reference));
        // Linear in the error: twice the error, twice the MAPE.
        let doubled: Vec<Vec3> = image.iter().zip(&reference).map(|(x, r)| *r + 2.0 * (*x - *r)).collect();
        assert!((mape(&doubled, &reference) - 2.0 * expected).abs() < 1e-5);
    }
}
