//! Host twins of the records in glsl/types.glsl; `#[repr(C)]` so that a test can check offsets.

use bytemuck::{Pod, Zeroable};

pub const MATERIAL_DOUBLE_SIDED: u32 = 1;
pub const NO_EMITTER: u32 = u32::MAX;

#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct Material {
    pub base_color: [f32; 3],
    pub metallic: f32,
    pub emission: [f32; 3],
    pub roughness: f32,
    pub transmission: f32,
    pub ior: f32,
    pub flags: u32,
    /// `KHR_materials_specular` specularFactor: the strength of the non-metal specular layer
    /// (docs/materials.md); 0 makes the non-metal part purely Lambertian.
    pub specular: f32,
    /// `KHR_materials_specular` specularColorFactor (linear RGB), scaling the layer's F0.
    pub specular_color: [f32; 3],
    pub pad: u32,
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct Triangle {
    pub v0: [f32; 3],
    pub material: u32,
    pub e1: [f32; 3],
    pub emitter: u32,
    pub e2: [f32; 3],
    /// 1 if the triangle's material is alpha-tested (`alphaMode` MASK or BLEND), else 0: set by
    /// [`crate::scene::Scene::build`], so that traversal reaches the material and its texture
    /// only for such triangles (glsl/alpha.glsl, [`crate::shading::alpha::alpha_keeps`]).
    pub alpha_tested: u32,
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    pub lo: [f32; 3],
    pub skip: u32,
    pub hi: [f32; 3],
    pub leaf: u32,
}

pub const LEAF_COUNT_BITS: u32 = 4;
pub const LEAF_COUNT_MASK: u32 = 15;

impl BvhNode {
    /// (first triangle, count) of a leaf; count 0 for interior nodes.
    pub fn leaf_range(&self) -> (u32, u32) {
        (self.leaf >> LEAF_COUNT_BITS, self.leaf & LEAF_COUNT_MASK)
    }
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct Emitter {
    pub triangle: u32,
    pub select_pdf: f32,
    pub alias_prob: f32,
    pub alias: u32,
}

/// Set in `Emitter::triangle` (and in path vertices' triangle ids) for a punctual light: the low
/// bits are the light's index in `Scene::lights`. Triangle indices stay below 2^26.
pub const PUNCTUAL_LIGHT_BIT: u32 = 1 << 31;

/// Rows of the emitter buffer per punctual light, after the alias table (glsl/types.glsl):
/// (position, kind), (direction, cos outer), (intensity, cos inner), (select pdf, 0, 0, 0).
pub const PUNCTUAL_ROWS: usize = 4;

/// The emitter-buffer rows of punctual lights (`select_pdfs[k]`: light k's probability in the
/// alias table), reinterpreting each 16-byte row as four 32-bit words.
pub fn punctual_rows(lights: &[crate::scene::PunctualLight], select_pdfs: &[f32]) -> Vec<Emitter> {
    let row = |a: [f32; 3], w: u32| Emitter {
        triangle: a[0].to_bits(),
        select_pdf: a[1],
        alias_prob: a[2],
        alias: w,
    };
    lights
        .iter()
        .zip(select_pdfs)
        .flat_map(|(l, &pdf)| {
            [
                row(l.position.into(), l.kind as u32),
                row(l.direction.into(), l.cos_outer.to_bits()),
                row(l.intensity.into(), l.cos_inner.to_bits()),
                row([pdf, 0.0, 0.0], 0),
            ]
        })
        .collect()
}

impl Material {
    pub fn is_double_sided(&self) -> bool {
        self.flags & MATERIAL_DOUBLE_SIDED != 0
    }
}

impl Triangle {
    pub fn vertices(&self) -> [glam::Vec3; 3] {
        let v0 = glam::Vec3::from(self.v0);
        [v0, v0 + glam::Vec3::from(self.e1), v0 + glam::Vec3::from(self.e2)]
    }

    /// Unnormalised geometric normal; its winding (counter-clockwise) defines the front face.
    pub fn normal_area2(&self) -> glam::Vec3 {
        glam::Vec3::from(self.e1).cross(glam::Vec3::from(self.e2))
    }

    pub fn area(&self) -> f32 {
        0.5 * self.normal_area2().length()
    }
}

pub const FLAG_RUSSIAN_ROULETTE: u32 = 1;

/// Binding 0 of every scene kernel (glsl/scene_bindings.glsl), std430 with only vec4-sized rows.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct FrameParams {
    pub cam_position: [f32; 4],
    pub cam_right: [f32; 4],
    pub cam_up: [f32; 4],
    pub cam_forward: [f32; 4],
    pub scene_env: [f32; 4],
    pub width: u32,
    pub height: u32,
    pub sample_offset: u32,
    pub samples_per_dispatch: u32,
    pub max_depth: u32,
    pub render_seed: u32,
    pub flags: u32,
    pub emitter_count: u32,
}

pub use crate::shader_interface::RESTIR_MAX_PASSES;

/// Binding 5 of the ReSTIR kernels (glsl/restir_bindings.glsl), std430: the frame's reuse
/// parameters and its pass table.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct ReuseParams {
    pub prev_cam_position: [f32; 4],
    pub prev_cam_right: [f32; 4],
    pub prev_cam_up: [f32; 4],
    pub prev_cam_forward: [f32; 4],
    pub roughness_threshold: f32,
    pub distance_threshold: f32,
    pub m_cap: f32,
    pub radius: f32,
    pub normal_threshold: f32,
    pub depth_threshold: f32,
    pub frame_index: u32,
    pub candidates: u32,
    pub neighbours: u32,
    pub temporal_valid: u32,
    pub emission_rays: u32,
    pub reservoirs: u32,
    pub emission_history: u32,
    /// The frame's passes in dispatch order; a dispatch's push constant indexes them.
    pub passes: [RestirPass; RESTIR_MAX_PASSES],
}

/// A pixel's primary hit in one frame (glsl/restir_bindings.glsl).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct Surface {
    pub pos: [f32; 3],
    pub triangle: u32,
    pub camera: [f32; 3],
    pub depth: f32,
}

/// The first half of a stored reservoir (glsl/reservoir.glsl).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct ReservoirHead {
    pub seed: u32,
    pub info: u32,
    pub lobes: u32,
    pub rc_triangle: u32,
    pub rc_pos: [f32; 3],
    pub rc_pdf: f32,
    pub rc_next: [f32; 3],
    pub rc_geometry: f32,
}

/// The second half of a stored reservoir, with W and M (glsl/reservoir.glsl).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct ReservoirTail {
    pub suffix: [f32; 3],
    pub rc_pdf_after: f32,
    pub contribution: [f32; 3],
    pub rc_next_triangle: u32,
    /// The unbiased contribution weight W.
    pub weight: f32,
    /// The confidence weight M.
    pub confidence: f32,
    pub pad0: u32,
    pub pad1: u32,
}

/// The per-frame counters of the ReSTIR kernels (glsl/restir_bindings.glsl).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct RestirStats {
    pub max_loop_iterations: u32,
    pub loop_budget_cut_groups: u32,
    pub shifts_attempted: u32,
    pub shifts_failed: u32,
    pub nonfinite_weights: u32,
    pub candidates_dropped: u32,
    pub nonfinite_pixels: u32,
    /// Traversals (a closest-hit or shadow ray, or a pair traced together) started by the
    /// temporal and spatial kernels, every one of them inside a shift.
    pub reuse_traversals: u32,
    /// Runs of the shift code by a subgroup, counted once for all its lanes that shift.
    pub shift_subgroup_runs: u32,
    /// Lanes per subgroup (llvmpipe: one SIMD group run in lockstep); 0 if no shift ran.
    pub subgroup_size: u32,
}

/// One entry of the ReSTIR kernels' pass table (ReuseParams::passes): which slots a pass reads
/// and writes, and its random-number key.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct RestirPass {
    pub in_slot: u32,
    pub out_slot: u32,
    pub prev_slot: u32,
    pub surface_slot: u32,
    pub pass_seed: u32,
}
