//! Counter-based RNG, the bit-exact twin of glsl/shading_core/rng.glsl.

use glam::{UVec4, Vec4};

pub use restir_pt_interface::shader_interface::{STREAM_BSDF, STREAM_CAMERA, STREAM_DIRECTIONAL, STREAM_LIGHT, STREAM_RESAMPLE};

/// The 4D permuted congruential hash of Jarzynski and Olano (JCGT 2020).
pub fn pcg4d(v: UVec4) -> UVec4 {
    let mut v = v.wrapping_mul(UVec4::splat(1664525)).wrapping_add(UVec4::splat(1013904223));
    v.x = v.x.wrapping_add(v.y.wrapping_mul(v.w));
    v.y = v.y.wrapping_add(v.z.wrapping_mul(v.x));
    v.z = v.z.wrapping_add(v.x.wrapping_mul(v.y));
    v.w = v.w.wrapping_add(v.y.wrapping_mul(v.z));
    v ^= v >> 16;
    v.x = v.x.wrapping_add(v.y.wrapping_mul(v.w));
    v.y = v.y.wrapping_add(v.z.wrapping_mul(v.x));
    v.z = v.z.wrapping_add(v.x.wrapping_mul(v.y));
    v.w = v.w.wrapping_add(v.y.wrapping_mul(v.z));
    v
}

/// The key of one path: a hash of the pixel index (row-major), the pixel's sample index and the
/// render's seed. Everything random along the path derives from it, so random replay only needs
/// the key (Lin et al. 2022, random-number replay). Twin of GLSL `path_seed`.
pub fn path_seed(pixel: u32, sample_index: u32, seed: u32) -> u32 {
    pcg4d(UVec4::new(pixel, sample_index, seed, 0x9e3779b9)).x
}

/// A uniform float in [0, 1) from the top 24 bits of `x` (exactly representable, never 1).
/// Twin of GLSL `u32_to_unit_float`.
pub fn u32_to_unit_float(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16777216.0)
}

/// Four uniforms in [0, 1) for path key `seed`, path vertex `vertex` (0: the camera) and one of the
/// `STREAM_*` uses: counter-based, so any vertex's numbers can be drawn again in any order.
/// Twin of GLSL `rng_uniform4`.
pub fn rng_uniform4(seed: u32, vertex: u32, stream: u32) -> Vec4 {
    let h = pcg4d(UVec4::new(seed, vertex, stream, 0x68e31da4));
    Vec4::new(
        u32_to_unit_float(h.x),
        u32_to_unit_float(h.y),
        u32_to_unit_float(h.z),
        u32_to_unit_float(h.w),
    )
}
