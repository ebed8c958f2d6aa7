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
    pub pad: u32,
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

/// Binding 0 of every scene kernel (glsl/scene_bindings.glsl), std140 with only vec4-sized rows.
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
