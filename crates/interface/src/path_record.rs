//! The path sample a reservoir stores: everything the shifts need to rebuild or reconnect a path,
//! and no more (80 bytes). Its GLSL twin is generated (`gpu_record!`); the functions that read
//! it are twins in `restir_pt_shading_core::path_record` and glsl/shading_core/path_record.glsl.
//!
//! Random replay needs the seed, the length, the end type and the lobes (to check that the
//! replayed path has the same vertex types). Reconnection and hybrid also need the reconnection
//! vertex x_r and its successor x_{r+1}, the radiance x_r receives from the suffix, and the
//! base-side terms of the Jacobian, cached when the record is made.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::{glsl_consts, gpu_record};

glsl_consts! {
    /// The GLSL declarations of this module's constants, for the generated header.
    fn glsl_constants;
    /// Lobe bits of a sampled direction (`restir_pt_shading_core::bsdf::BsdfSample::lobe`, [`PathRecord::lobes`]); shared with
    /// glsl/shading_core/bsdf.glsl. No lobe: a failed sample, or a vertex whose successor NEE chose.
    pub const LOBE_NONE: u32 = 0;
    /// The Lambertian base of the non-metal part.
    pub const LOBE_DIFFUSE: u32 = 1;
    /// GGX reflection: the conductor and the non-metal specular layer.
    pub const LOBE_CONDUCTOR: u32 = 2;
    /// The dielectric interface (transmission part), reflected or refracted.
    pub const LOBE_DIELECTRIC: u32 = 4;
    /// Set with another bit when that lobe was a perfect (delta) specular: `pdf` is then a discrete
    /// probability, not a density, and the direction cannot be reached by another technique.
    pub const LOBE_DELTA: u32 = 8;
    /// Set with [`LOBE_DIELECTRIC`] when the direction crossed the surface (refraction).
    pub const LOBE_TRANSMISSION: u32 = 16;
    /// Bits of [`PathRecord::lobes`] per vertex.
    pub const LOBE_BITS: u32 = 5;
    /// [`PathRecord::info`] bits 0-3: the path's length k.
    pub const INFO_LENGTH_MASK: u32 = 0xf;
    /// [`PathRecord::info`]: the reconnection index r starts at this bit (4 bits; 0: none).
    pub const INFO_RC_SHIFT: u32 = 4;
    /// [`PathRecord::info`] bit: next-event estimation chose the path's last vertex.
    pub const INFO_NEE_END: u32 = 1 << 8;
    /// [`PathRecord::info`]: the NEE technique of the end (0: the drawn light; k + 1: directional
    /// light k) starts at this bit.
    pub const INFO_DIRECTIONAL_SHIFT: u32 = 9;
}

gpu_record! {
    struct;
    /// A reservoir's path sample (glsl/shading_core/path_record.glsl `PathRecord`, 80 bytes, std430; stored on the
    /// GPU split into [`crate::gpu_types::ReservoirHead`] and [`crate::gpu_types::ReservoirTail`]).
    /// x_0 is the camera, x_1..x_k the path's vertices, x_r the reconnection vertex; positions and
    /// directions are in scene coordinates, colours linear RGB.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct PathRecord {
        /// The path's random-number key (`restir_pt_shading_core::rng::path_seed`): random replay
        /// regenerates the path from it.
        pub seed: u32,
        /// Bits 0-3: the length k; bits 4-7: the reconnection index r (0: none); bit 8: NEE end;
        /// bits 9-31: which NEE technique made the end (0: the light NEE draws; k + 1: directional
        /// light k, which NEE takes at every vertex).
        pub info: u32,
        /// The lobe sampled at x1..x_{k-1}, 5 bits each (LOBE_NONE where NEE chose the next vertex).
        pub lobes: u32,
        /// The triangle of x_r; NO_HIT if x_r is an escaped direction.
        pub rc_triangle: u32,
        /// x_r, or its direction if escaped.
        pub rc_pos: [f32; 3],
        /// The solid-angle pdf that chose x_r from x_{r-1} (the BSDF's, or the light's for an NEE end).
        pub rc_pdf: f32,
        /// x_{r+1}, or its direction if escaped; unused when x_r ends the path.
        pub rc_next: [f32; 3],
        /// |cos_r| / |x_{r-1} - x_r|^2 at x_r (1 for an escaped x_r).
        pub rc_geometry: f32,
        /// prod_{i > r} f_s |cos| / p times the emission at the end: what x_r receives from the suffix
        /// (1 when x_r ends the path: its emission depends on the predecessor).
        pub suffix: [f32; 3],
        /// p(x_r -> x_{r+1} | x_{r-1}); 1 when x_r ends the path or NEE chose x_{r+1}.
        pub rc_pdf_after: f32,
        /// f(X).
        pub contribution: [f32; 3],
        /// The triangle of x_{r+1}; NO_HIT if escaped.
        pub rc_next_triangle: u32,
    }
}

impl PathRecord {
    /// The `info` word for a path of `length` vertices, reconnection index r (`None`: no
    /// reconnection vertex), end type and NEE technique (`nee_directional`: 0 for the drawn
    /// light, k + 1 for directional light k). Twin of GLSL `pack_info`.
    pub fn pack_info(length: usize, reconnection: Option<usize>, nee_end: bool, nee_directional: u32) -> u32 {
        length as u32
            | (reconnection.unwrap_or(0) as u32) << INFO_RC_SHIFT
            | if nee_end { INFO_NEE_END } else { 0 }
            | nee_directional << INFO_DIRECTIONAL_SHIFT
    }

    /// The `lobes` word: `lobes[i]` (a `LOBE_*` value below 2⁵) in bits 5i..5i+4, for x1 onwards.
    pub fn pack_lobes(lobes: &[u32]) -> u32 {
        lobes.iter().enumerate().fold(0, |acc, (i, &l)| acc | l << (LOBE_BITS * i as u32))
    }

    /// f(X), linear RGB.
    pub fn contribution(&self) -> Vec3 {
        Vec3::from(self.contribution)
    }
}
