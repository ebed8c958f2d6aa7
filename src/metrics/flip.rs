//! ꟻLIP (Andersson et al., "FLIP: A Difference Evaluator for Alternating Images", HPG 2020) and
//! HDR-ꟻLIP (Andersson et al., "Visualizing Errors in Rendered High Dynamic Range Images",
//! Eurographics 2021 short papers), the image metrics the ReSTIR papers chart beside relMSE.
//!
//! The LDR metric is NVIDIA's implementation through the `nv-flip` crate; HDR-ꟻLIP is its
//! definition around it: both images exposed at a range of exposures chosen from the
//! reference, each pair tone-mapped and compared with LDR-ꟻLIP, and the per-pixel maximum over
//! exposures kept.

use glam::Vec3;

use super::luminance;
use crate::image_io::srgb_encode;

/// The viewing condition of ꟻLIP's default: a 0.7 m wide 4K monitor seen from 0.7 m, 67 pixels
/// per degree of visual angle.
pub const PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// The ACES filmic curve (Narkowicz's fit, with ꟻLIP's 0.6 pre-exposure folded in) as the
/// rational function (a x² + b x + c) / (d x² + e x + f), HDR-ꟻLIP's default tone mapper.
const ACES: [f32; 6] = [0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0, 0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14];

/// The tone-mapped value HDR-ꟻLIP's exposure range is built around: the brightest reference
/// pixel maps to it at the first exposure, the median one at the last.
const EXPOSURE_TARGET: f32 = 0.85;

fn aces(x: f32) -> f32 {
    let [a, b, c, d, e, f] = ACES;
    ((a * x * x + b * x + c) / (d * x * x + e * x + f)).clamp(0.0, 1.0)
}

/// The radiance that ACES maps to [`EXPOSURE_TARGET`]: the larger root of
/// (a - t d) x² + (b - t e) x + (c - t f) = 0.
fn aces_inverse_of_target() -> f32 {
    let [a, b, c, d, e, f] = ACES;
    let t = EXPOSURE_TARGET;
    let (qa, qb, qc) = (a - t * d, b - t * e, c - t * f);
    let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
    let (r0, r1) = ((-qb - disc) / (2.0 * qa), (-qb + disc) / (2.0 * qa));
    r0.max(r1)
}

/// HDR-ꟻLIP's exposures (in stops, applied as 2^e) for a reference: from the one that brings
/// its brightest luminance to the tone mapper's 0.85 to the one that brings its median there,
/// at least two, about one stop apart. A reference with a black median uses its darkest
/// non-black luminance instead (the published range would be infinite); a black reference
/// gets the single exposure 0.
pub fn hdr_flip_exposures(reference: &[Vec3]) -> Vec<f32> {
    let mut lum: Vec<f32> = reference
        .iter()
        .map(|&p| luminance(p.max(Vec3::ZERO)))
        .filter(|l| l.is_finite())
        .collect();
    lum.sort_by(f32::total_cmp);
    let Some(&max) = lum.last().filter(|&&m| m > 0.0) else {
        return vec![0.0];
    };
    let mid = lum.len() / 2;
    let median = if lum.len().is_multiple_of(2) {
        0.5 * (lum[mid - 1] + lum[mid])
    } else {
        lum[mid]
    };
    let low = if median > 0.0 {
        median
    } else {
        lum.iter().copied().find(|&l| l > 0.0).unwrap_or(max)
    };
    let x = aces_inverse_of_target();
    let (start, stop) = ((x / max).log2(), (x / low).log2());
    let count = ((stop - start).ceil() as usize).max(2);
    let step = (stop - start) / (count - 1) as f32;
    (0..count).map(|i| start + i as f32 * step).collect()
}

/// 8-bit sRGB of `pixels` exposed by 2^`ev` and tone-mapped per channel by `tone_map`.
fn ldr_bytes(pixels: &[Vec3], ev: f32, tone_map: fn(f32) -> f32) -> Vec<u8> {
    let scale = ev.exp2();
    pixels
        .iter()
        .map(|&p| (p.max(Vec3::ZERO) * scale).to_array())
        .flat_map(|c| c.map(|v| srgb_encode(tone_map(if v.is_finite() { v } else { 0.0 }))))
        .collect()
}

/// LDR-ꟻLIP's per-pixel error map, row-major (`width` × `height`, values in [0, 1]), of two
/// images after exposing them by 2^`ev` and clamping to [0, 1] (no tone curve), sRGB-encoded
/// to 8 bits, seen at `pixels_per_degree` (default [`PIXELS_PER_DEGREE`]). Non-finite pixels
/// count as black. Panics if a size differs from width × height.
pub fn ldr_flip_map(image: &[Vec3], reference: &[Vec3], width: u32, height: u32, ev: f32, pixels_per_degree: f32) -> Vec<f32> {
    flip_map(image, reference, (width, height), ev, |v| v, pixels_per_degree)
}

fn flip_map(image: &[Vec3], reference: &[Vec3], (width, height): (u32, u32), ev: f32, tone_map: fn(f32) -> f32, ppd: f32) -> Vec<f32> {
    let pixels = (width * height) as usize;
    assert!(
        image.len() == pixels && reference.len() == pixels,
        "an image and its reference differ in size"
    );
    nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(width, height, &ldr_bytes(reference, ev, tone_map)),
        nv_flip::FlipImageRgb8::with_data(width, height, &ldr_bytes(image, ev, tone_map)),
        ppd,
    )
    .to_vec()
}

/// HDR-ꟻLIP's per-pixel error map (row-major, values in [0, 1]): the maximum over
/// [`hdr_flip_exposures`] of LDR-ꟻLIP between the ACES-tone-mapped exposures of the two linear
/// RGB images. The 8-bit sRGB step before LDR-ꟻLIP is `nv-flip`'s input format; the
/// published tool compares in float, so values can differ from it in the third decimal.
/// Panics if a size differs from width × height.
pub fn hdr_flip_map(image: &[Vec3], reference: &[Vec3], width: u32, height: u32) -> Vec<f32> {
    let mut worst = vec![0.0f32; (width * height) as usize];
    for ev in hdr_flip_exposures(reference) {
        for (w, e) in worst
            .iter_mut()
            .zip(flip_map(image, reference, (width, height), ev, aces, PIXELS_PER_DEGREE))
        {
            *w = w.max(e);
        }
    }
    worst
}

/// The mean of [`hdr_flip_map`]: 0 for equal images, towards 1 as they differ.
pub fn hdr_flip(image: &[Vec3], reference: &[Vec3], width: u32, height: u32) -> f64 {
    let map = hdr_flip_map(image, reference, width, height);
    map.iter().map(|&e| e as f64).sum::<f64>() / map.len().max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient(w: u32, h: u32, scale: f32) -> Vec<Vec3> {
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
                Vec3::new(x, y, 0.5) * scale * (1.0 + 30.0 * x * x)
            })
            .collect()
    }

    #[test]
    fn aces_maps_the_target_radiance_to_the_target() {
        assert!((aces(aces_inverse_of_target()) - EXPOSURE_TARGET).abs() < 1e-5);
    }

    #[test]
    fn exposures_span_brightest_to_median_at_least_two() {
        let r = gradient(32, 32, 1.0);
        let ev = hdr_flip_exposures(&r);
        let mut lum: Vec<f32> = r.iter().map(|&p| luminance(p)).collect();
        lum.sort_by(f32::total_cmp);
        let x = aces_inverse_of_target();
        assert!(ev.len() >= 2);
        assert!((ev[0] - (x / lum[1023]).log2()).abs() < 1e-5);
        assert!((ev[ev.len() - 1] - (x / (0.5 * (lum[511] + lum[512]))).log2()).abs() < 1e-4);
        assert_eq!(hdr_flip_exposures(&[Vec3::ZERO; 4]), vec![0.0]);
    }

    #[test]
    fn hdr_flip_is_zero_for_equal_images_and_grows_with_the_error() {
        let (w, h) = (48, 40);
        let r = gradient(w, h, 1.0);
        assert_eq!(hdr_flip(&r, &r, w, h), 0.0);
        let small: Vec<Vec3> = r.iter().map(|&p| p * 1.1).collect();
        let large: Vec<Vec3> = r.iter().map(|&p| p * 2.0).collect();
        let (a, b) = (hdr_flip(&small, &r, w, h), hdr_flip(&large, &r, w, h));
        assert!(a > 0.0 && b > 2.0 * a && b < 1.0, "10% {a}, 100% {b}");
        // A firefly is seen at the exposure where it is not saturated.
        let mut firefly = r.clone();
        firefly[100] = Vec3::splat(50.0);
        assert!(hdr_flip_map(&firefly, &r, w, h)[100] > 0.5);
    }

    #[test]
    fn hdr_flip_does_not_depend_on_the_radiance_scale() {
        let (w, h) = (32, 32);
        let r = gradient(w, h, 1.0);
        let x: Vec<Vec3> = r.iter().enumerate().map(|(i, &p)| if i % 7 == 0 { p * 3.0 } else { p }).collect();
        // HDR-ꟻLIP depends on radiance only through exposure: scaling both images by 2^k
        // shifts every exposure by -k and leaves the error unchanged.
        let scaled = |v: &[Vec3]| v.iter().map(|&p| p * 8.0).collect::<Vec<_>>();
        let (a, b) = (hdr_flip(&x, &r, w, h), hdr_flip(&scaled(&x), &scaled(&r), w, h));
        assert!(a > 0.0 && (a - b).abs() < 1e-3 * a, "{a} vs {b}");
        assert!(ldr_flip_map(&x, &r, w, h, 0.0, PIXELS_PER_DEGREE).iter().any(|&e| e > 0.0));
    }
}
