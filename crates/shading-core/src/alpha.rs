//! Alpha testing inside traversal, the twin of glsl/shading_core/alpha.glsl: glTF `alphaMode` MASK (a hit
//! whose alpha is below `alphaCutoff` is no hit) and BLEND as stochastic transparency (a hit is
//! kept with probability alpha). `alpha_hash` and `alpha_keeps` have GLSL functions of the same
//! names, compared in tests/suite/alpha_oracle.rs (docs/materials.md, "Alpha modes").

use glam::{UVec4, Vec2, Vec3};

use restir_pt_interface::gpu_types::Triangle;

use crate::rng::{pcg4d, u32_to_unit_float};
use crate::surface::{surface_at, TriangleSurface};
use crate::texture::{material_alpha, SceneTextures, ALPHA_MASK, ALPHA_OPAQUE};

/// What traversal needs to alpha-test a hit: the triangles' surface attributes (for texture
/// coordinates, same order as the triangles) and the material texture table. A scene has one
/// only when some material is not opaque (`restir_pt_scene::Scene::alpha`); kernels are then
/// compiled with `SCENE_ALPHA`.
#[derive(Clone, Copy)]
pub struct AlphaScene<'a> {
    /// Per-triangle vertex attributes, indexed like the scene's triangles.
    pub surfaces: &'a [TriangleSurface],
    /// The texture table: materials' alpha modes, cutoffs and base-colour textures.
    pub textures: &'a SceneTextures,
}

/// BLEND's uniform number in [0, 1) for triangle index `triangle` met by the ray (o, d): two
/// rounds of `pcg4d` over the bits of the origin, the direction and the triangle index. A hash
/// of the ray, not a draw from the path's sample stream, so that the same ray traced again (by a
/// shift, its inverse, or this twin) meets the same surface.
pub fn alpha_hash(o: Vec3, d: Vec3, triangle: u32) -> f32 {
    let h = pcg4d(UVec4::new(o.x.to_bits(), o.y.to_bits(), o.z.to_bits(), triangle));
    let h = pcg4d(h ^ UVec4::new(d.x.to_bits(), d.y.to_bits(), d.z.to_bits(), 0x5bd1e995));
    u32_to_unit_float(h.x)
}

/// Whether the ray (o, d) hits triangle index `triangle` (of `triangles`) at barycentrics
/// `bary`: always for an opaque material, alpha >= alphaCutoff for MASK (glTF 2.0 section 3.9.4),
/// `alpha_hash` < alpha for BLEND. Alpha is `material_alpha`: baseColorFactor's alpha times the
/// base colour texture's.
pub fn alpha_keeps(alpha: &AlphaScene, triangles: &[Triangle], triangle: u32, bary: Vec2, o: Vec3, d: Vec3) -> bool {
    let tri = &triangles[triangle as usize];
    let t = &alpha.textures.materials[tri.material as usize];
    if t.alpha_mode == ALPHA_OPAQUE {
        return true;
    }
    let s = surface_at(tri, &alpha.surfaces[triangle as usize], bary);
    let a = material_alpha(t, alpha.textures, &s);
    if t.alpha_mode == ALPHA_MASK {
        return a >= t.alpha_cutoff;
    }
    alpha_hash(o, d, triangle) < a
}
