//! The records of descriptor set 1 (`SurfaceBinding`): per-triangle vertex attributes and the
//! material textures, with the constants of their encodings. The functions that read them are
//! twins in `restir_pt_shading_core::surface` and `::texture` (glsl/shading_core/surface.glsl, texture.glsl).

use bytemuck::{Pod, Zeroable};

use crate::{glsl_consts, gpu_record};

glsl_consts! {
    /// The GLSL declarations of this module's constants, for the generated header.
    fn glsl_constants;
    /// [`TextureSlot::texture_index`] of a slot without a texture: the factor applies alone.
    pub const NO_TEXTURE: u32 = u32::MAX;
    /// Wrap mode (2 bits of [`TextureHeader::sampler_bits`]): glTF REPEAT, the coordinate's
    /// fractional part.
    pub const TEXTURE_WRAP_REPEAT: u32 = 0;
    /// Wrap mode: glTF CLAMP_TO_EDGE, coordinates clamped to the edge texels.
    pub const TEXTURE_WRAP_CLAMP: u32 = 1;
    /// Wrap mode: glTF MIRRORED_REPEAT, every other repetition mirrored.
    pub const TEXTURE_WRAP_MIRROR: u32 = 2;
    /// Sampler bit: nearest-texel (magnification) filtering instead of bilinear.
    pub const TEXTURE_NEAREST: u32 = 16;
    /// [`MaterialTextures::alpha_mode`]: glTF `OPAQUE`, alpha ignored.
    pub const ALPHA_OPAQUE: u32 = 0;
    /// glTF `MASK`: a hit whose alpha is below `alpha_cutoff` is no hit (`restir_pt_shading_core::alpha`).
    pub const ALPHA_MASK: u32 = 1;
    /// glTF `BLEND`, rendered as stochastic transparency: a hit is kept with probability alpha.
    pub const ALPHA_BLEND: u32 = 2;
}

gpu_record! {
    struct;
    /// The attributes of one triangle's three vertices (v0, v0 + e1, v0 + e2), in scene space
    /// (the triangles' coordinates), std430 layout of `TriangleSurface` in glsl/shading_core/surface.glsl.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct TriangleSurface {
        /// xyz: the vertex normal (unit, or zero where the file gave none or the triangle is flat:
        /// the face normal is used);
        /// w: the vertex's COLOR_0 packed by `restir_pt_shading_core::surface::pack_vertex_color` (its bits; 0.0: no colour).
        pub normal: [[f32; 4]; 3],
        /// xyz: the vertex tangent (along +u of the normal texture's coordinates); w: its handedness
        /// ±1, the bitangent being w · cross(normal, tangent) (glTF 2.0, section 3.7.2.1).
        pub tangent: [[f32; 4]; 3],
        /// xy: TEXCOORD_0, zw: TEXCOORD_1 of each vertex (0 where absent).
        pub uv: [[f32; 4]; 3],
    }
}

impl TriangleSurface {
    /// A flat triangle: no vertex normals (the face normal is used), no tangents, uv 0.
    pub fn flat() -> Self {
        Self::default()
    }
}

gpu_record! {
    struct;
    /// A texture's place in `SceneTextures::texels` (`restir_pt_shading_core::texture`) and its sampler (glsl/interface/surface_bindings.glsl).
    #[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
    pub struct TextureHeader {
        /// Width in texels.
        pub width: u32,
        /// Height in texels.
        pub height: u32,
        /// Index of the first texel; rows run from the image's top row (v = 0) down.
        pub offset: u32,
        /// Wrap S in bits 0-1, wrap T in bits 2-3 (`TEXTURE_WRAP_*`), `TEXTURE_NEAREST`.
        pub sampler_bits: u32,
    }
}

gpu_record! {
    struct;
    /// A material's use of one texture: the texture and the affine map from its coordinate set to
    /// the lookup's uv, uv' = (u_row · (u, v, 1), v_row · (u, v, 1)), which holds
    /// `KHR_texture_transform`.
    #[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
    pub struct TextureSlot {
        /// First row of the affine uv map (identity: (1, 0, 0)).
        pub u_row: [f32; 3],
        /// Index into the headers, or [`NO_TEXTURE`].
        pub texture_index: u32,
        /// Second row of the affine uv map (identity: (0, 1, 0)).
        pub v_row: [f32; 3],
        /// TEXCOORD_0 or TEXCOORD_1.
        pub texcoord: u32,
    }
}

impl Default for TextureSlot {
    fn default() -> Self {
        Self {
            u_row: [1.0, 0.0, 0.0],
            texture_index: NO_TEXTURE,
            v_row: [0.0, 1.0, 0.0],
            texcoord: 0,
        }
    }
}

gpu_record! {
    struct;
    /// The textures of one material, parallel to `Scene::materials`.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct MaterialTextures {
        /// sRGB colour and linear alpha, multiplying the base colour factor.
        pub base_color: TextureSlot,
        /// Linear; B multiplies metallic, G roughness.
        pub metal_rough: TextureSlot,
        /// sRGB, multiplying the emission.
        pub emissive: TextureSlot,
        /// Tangent-space normal, (x, y) scaled by `normal_scale`.
        pub normal: TextureSlot,
        /// glTF `normalTexture.scale`: multiplies the tangent-space normal's x and y (default 1).
        pub normal_scale: f32,
        /// glTF `alphaCutoff` (default 0.5): the alpha below which an `ALPHA_MASK` hit is discarded.
        pub alpha_cutoff: f32,
        /// `ALPHA_OPAQUE`, `ALPHA_MASK` or `ALPHA_BLEND`.
        pub alpha_mode: u32,
        /// The alpha of the base colour factor.
        pub base_alpha: f32,
    }
}
