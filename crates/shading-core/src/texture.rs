//! Material textures: texels in one storage buffer with the lookup (address modes, bilinear or
//! nearest filtering, sRGB decoding) done by hand, and the material a hit sees once its textures
//! apply. Twin of glsl/shading_core/texture.glsl: `texture_lookup`, `texture_coordinates`,
//! `textured_material` and `normal_mapped` have GLSL functions of the same names, compared in
//! tests/suite/surface_oracle.rs. Why a buffer rather than sampled images: docs/textures.md.

use glam::{Vec2, Vec3, Vec4};

use restir_pt_interface::gpu_types::{Material, MATERIAL_ALPHA_EMISSION, MATERIAL_BLEND_EMISSION};
pub use restir_pt_interface::surface_types::{
    MaterialTextures, TextureHeader, TextureSlot, ALPHA_BLEND, ALPHA_MASK, ALPHA_OPAQUE, NO_TEXTURE, TEXTURE_NEAREST, TEXTURE_WRAP_CLAMP,
    TEXTURE_WRAP_MIRROR, TEXTURE_WRAP_REPEAT,
};

use crate::surface::SurfaceHit;

/// The scene's textures; all empty when no material has one.
#[derive(Debug, Clone, Default)]
pub struct SceneTextures {
    /// One per texture, indexed by [`TextureSlot::texture_index`].
    pub headers: Vec<TextureHeader>,
    /// RGBA8 texels, R in the low byte.
    pub texels: Vec<u32>,
    /// One per material when any material has a texture (or a non-opaque alpha mode).
    pub materials: Vec<MaterialTextures>,
}

impl SceneTextures {
    /// Whether the scene has no material table: no material has a texture or a non-opaque alpha
    /// mode.
    pub fn is_empty(&self) -> bool {
        self.materials.is_empty()
    }

    /// Bytes of GPU memory the textures take (texels, headers and material table).
    pub fn gpu_bytes(&self) -> usize {
        std::mem::size_of_val(self.texels.as_slice())
            + std::mem::size_of_val(self.headers.as_slice())
            + std::mem::size_of_val(self.materials.as_slice())
    }
}

/// The rows of uv' = T(offset) · R(rotation) · S(scale) · uv (KHR_texture_transform; the
/// rotation turns the UVs counter-clockwise in their own v-down space).
pub fn texture_transform_rows(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> ([f32; 3], [f32; 3]) {
    let (s, c) = rotation.sin_cos();
    ([c * scale[0], s * scale[1], offset[0]], [-s * scale[0], c * scale[1], offset[1]])
}

/// The sRGB transfer function's inverse (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Texel index `i` of a row or column of `n` under address mode `mode` (glTF samplers: REPEAT,
/// CLAMP_TO_EDGE, MIRRORED_REPEAT).
fn wrap_texel(i: i32, n: u32, mode: u32) -> u32 {
    let n = n as i32;
    let k = match mode {
        TEXTURE_WRAP_CLAMP => i.clamp(0, n - 1),
        TEXTURE_WRAP_MIRROR => {
            let m = i.rem_euclid(2 * n);
            if m >= n {
                2 * n - 1 - m
            } else {
                m
            }
        }
        _ => i.rem_euclid(n),
    };
    k as u32
}

/// A texture coordinate brought into a range where texel indices fit an i32 without changing
/// the lookup: by whole periods of 2 for repeat and mirror, clamped for clamp-to-edge; 0 if
/// not finite.
fn reduce_coordinate(u: f32, mode: u32) -> f32 {
    if !(u.abs() < 1e30) {
        return 0.0;
    }
    if mode == TEXTURE_WRAP_CLAMP {
        u.clamp(-1.0, 2.0)
    } else {
        u - 2.0 * (u * 0.5).floor()
    }
}

fn texel(textures: &SceneTextures, h: &TextureHeader, x: i32, y: i32, srgb: bool) -> Vec4 {
    let (sx, sy) = (
        wrap_texel(x, h.width, h.sampler_bits & 3),
        wrap_texel(y, h.height, (h.sampler_bits >> 2) & 3),
    );
    let word = textures.texels[(h.offset + sy * h.width + sx) as usize];
    let c = Vec4::new(
        (word & 0xff) as f32,
        ((word >> 8) & 0xff) as f32,
        ((word >> 16) & 0xff) as f32,
        (word >> 24) as f32,
    ) / 255.0;
    if srgb {
        Vec4::new(srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z), c.w)
    } else {
        c
    }
}

/// Texture `texture` at `uv` (u right, v down from the image's top row, texel centres at
/// half-integers / size): bilinear (or nearest, by its sampler) over texels decoded to linear
/// first when `srgb` (as a GPU's sRGB formats filter). RGBA in [0, 1].
pub fn texture_lookup(textures: &SceneTextures, texture: u32, uv: Vec2, srgb: bool) -> Vec4 {
    let h = &textures.headers[texture as usize];
    let u = reduce_coordinate(uv.x, h.sampler_bits & 3) * h.width as f32;
    let v = reduce_coordinate(uv.y, (h.sampler_bits >> 2) & 3) * h.height as f32;
    if h.sampler_bits & TEXTURE_NEAREST != 0 {
        return texel(textures, h, u.floor() as i32, v.floor() as i32, srgb);
    }
    let (x, y) = (u - 0.5, v - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i32, y0 as i32);
    let top = texel(textures, h, x0, y0, srgb).lerp(texel(textures, h, x0 + 1, y0, srgb), fx);
    let bottom = texel(textures, h, x0, y0 + 1, srgb).lerp(texel(textures, h, x0 + 1, y0 + 1, srgb), fx);
    top.lerp(bottom, fy)
}

/// The lookup coordinates of `slot` at surface `s`: its coordinate set, transformed.
pub fn texture_coordinates(slot: &TextureSlot, s: &SurfaceHit) -> Vec2 {
    let uv = if slot.texcoord == 1 { s.uv1 } else { s.uv0 }.extend(1.0);
    Vec2::new(Vec3::from(slot.u_row).dot(uv), Vec3::from(slot.v_row).dot(uv))
}

/// `m` with its textures `t` applied at surface `s` (glTF 2.0 section 3.9: the texture values
/// multiply the factors).
pub fn textured_material(m: &Material, t: &MaterialTextures, textures: &SceneTextures, s: &SurfaceHit) -> Material {
    let mut out = *m;
    if t.base_color.texture_index != NO_TEXTURE {
        let c = texture_lookup(textures, t.base_color.texture_index, texture_coordinates(&t.base_color, s), true);
        out.base_color = (Vec3::from(m.base_color) * c.truncate()).into();
    }
    if t.metal_rough.texture_index != NO_TEXTURE {
        let c = texture_lookup(textures, t.metal_rough.texture_index, texture_coordinates(&t.metal_rough, s), false);
        out.metallic = m.metallic * c.z;
        out.roughness = m.roughness * c.y;
    }
    if t.emissive.texture_index != NO_TEXTURE {
        let c = texture_lookup(textures, t.emissive.texture_index, texture_coordinates(&t.emissive, s), true);
        out.emission = (Vec3::from(m.emission) * c.truncate()).into();
    }
    if m.flags & MATERIAL_ALPHA_EMISSION != 0 {
        out.emission = (Vec3::from(out.emission) * emission_coverage(m, t, textures, s)).into();
    }
    out
}

/// The share of an alpha-tested emitter's emission at `s` (`MATERIAL_ALPHA_EMISSION`): 0 where
/// its alpha is below the cutoff traversal uses (no surface there), else 1, or the alpha itself
/// for a BLEND emitter (`MATERIAL_BLEND_EMISSION`). Twin of GLSL `emission_coverage`.
pub fn emission_coverage(m: &Material, t: &MaterialTextures, textures: &SceneTextures, s: &SurfaceHit) -> f32 {
    let a = material_alpha(t, textures, s);
    if !(a >= t.alpha_cutoff) {
        0.0
    } else if m.flags & MATERIAL_BLEND_EMISSION != 0 {
        a
    } else {
        1.0
    }
}

/// `m` with the vertex colour of `s` applied: COLOR_0 multiplies the base colour (glTF 2.0
/// section 3.9.2), and the emission of a `KHR_materials_unlit` material, which is its base colour
/// ([`restir_pt_interface::gpu_types::MATERIAL_UNLIT`]). Twin of GLSL `vertex_colored`.
pub fn vertex_colored(m: &Material, s: &SurfaceHit) -> Material {
    let mut out = *m;
    out.base_color = (Vec3::from(m.base_color) * s.color).into();
    if m.flags & restir_pt_interface::gpu_types::MATERIAL_UNLIT != 0 {
        out.emission = (Vec3::from(m.emission) * s.color).into();
    }
    out
}

/// The shading normal at surface `s` with the normal map of `t` applied: the texel's
/// tangent-space normal (2 · rgb - 1, x and y times `normal_scale`) taken to scene space by the
/// tangent frame (glTF 2.0 section 3.9.3), normalised; `s.normal` without a normal map or where
/// the result degenerates.
pub fn normal_mapped(t: &MaterialTextures, textures: &SceneTextures, s: &SurfaceHit) -> Vec3 {
    if t.normal.texture_index == NO_TEXTURE {
        return s.normal;
    }
    let c = texture_lookup(textures, t.normal.texture_index, texture_coordinates(&t.normal, s), false);
    let local = (c.truncate() * 2.0 - Vec3::ONE) * Vec3::new(t.normal_scale, t.normal_scale, 1.0);
    let (tangent, handedness) = texture_tangent_frame(&t.normal, s);
    let bitangent = handedness * s.normal.cross(tangent);
    let n = tangent * local.x + bitangent * local.y + s.normal * local.z;
    if n.length_squared() > 1e-12 {
        n.normalize()
    } else {
        s.normal
    }
}

/// The tangent and handedness of the coordinates `slot` looks its texture up with, from the
/// surface's (those of its texture coordinates): KHR_texture_transform's linear part A (rows
/// `u_row`, `v_row`) turns, scales or mirrors the lookup, and a tangent-space normal is relative
/// to the texture's axes, so the frame turns with it. The tangent becomes ∂P/∂u' of the
/// transformed coordinates, A⁻¹'s first column on the frame (with the bitangent
/// `handedness · cross(n, t)` along −v, up the image): normalize((A₁₁ t + A₁₀ b) / det A); the
/// handedness flips with det A < 0. This is the frame MikkTSpace gives coordinates with the
/// transform baked in. Untouched (bit for bit) without a rotation, where A₁₀ = 0; unchanged for a
/// singular A. Twin of GLSL `texture_tangent_frame`.
pub fn texture_tangent_frame(slot: &TextureSlot, s: &SurfaceHit) -> (Vec3, f32) {
    let (a00, a01, a10, a11) = (slot.u_row[0], slot.u_row[1], slot.v_row[0], slot.v_row[1]);
    let det = a00 * a11 - a01 * a10;
    if det == 0.0 || !det.is_finite() {
        return (s.tangent, s.handedness);
    }
    let sign = if det < 0.0 { -1.0 } else { 1.0 };
    if a10 == 0.0 {
        let flip = if a11 * sign < 0.0 { -1.0 } else { 1.0 };
        return (s.tangent * flip, s.handedness * sign);
    }
    let bitangent = s.handedness * s.normal.cross(s.tangent);
    let t = (s.tangent * a11 + bitangent * a10) * sign;
    if t.length_squared() > 1e-12 {
        (t.normalize(), s.handedness * sign)
    } else {
        (s.tangent, s.handedness)
    }
}

/// The opacity at surface `s` (base colour factor alpha times the texture's alpha). Twin of
/// GLSL `material_alpha(material, s)`, which reads `t` from the material texture table.
pub fn material_alpha(t: &MaterialTextures, textures: &SceneTextures, s: &SurfaceHit) -> f32 {
    if t.base_color.texture_index == NO_TEXTURE {
        return t.base_alpha;
    }
    t.base_alpha * texture_lookup(textures, t.base_color.texture_index, texture_coordinates(&t.base_color, s), true).w
}
