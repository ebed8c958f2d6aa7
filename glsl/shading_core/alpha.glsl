// Alpha testing inside traversal: glTF alphaMode MASK (a hit whose alpha is below alphaCutoff is
// no hit) and BLEND as stochastic transparency (a hit is kept with probability alpha), for
// closest-hit and shadow rays alike. Only kernels of a scene with such a material define
// SCENE_ALPHA and include this file, so opaque scenes compile to the same code as without it.
// Expects the scene and surface bindings. Twin: crates/shading-core/src/alpha.rs (docs/materials.md,
// "Alpha modes").
#ifndef ALPHA_GLSL
#define ALPHA_GLSL

#include "shading_core/rng.glsl"
#include "shading_core/texture.glsl"

// BLEND's uniform number for triangle index `triangle` met by the ray (o, d): a hash of the
// ray's bits and the triangle rather than a draw from the path's sample stream, so that tracing
// the same ray again (a shift, its inverse, the Rust twin) meets the same surface.
float alpha_hash(vec3 o, vec3 d, uint triangle) {
    uvec4 h = pcg4d(uvec4(floatBitsToUint(o), triangle));
    h = pcg4d(h ^ uvec4(floatBitsToUint(d), 0x5bd1e995u));
    return u32_to_unit_float(h.x);
}

// Whether the ray (o, d) hits triangle index `triangle` at barycentrics bary, given its
// material's alpha mode: always for OPAQUE, alpha >= alphaCutoff for MASK, and
// alpha_hash < alpha for BLEND.
bool alpha_keeps(uint triangle, vec2 bary, vec3 o, vec3 d) {
    uint material = triangles[triangle].material;
    uint mode = material_textures[material].alpha_mode;
    if (mode == ALPHA_OPAQUE) return true;
    float a = material_alpha(material, surface_at(triangle, bary));
    if (mode == ALPHA_MASK) return a >= material_textures[material].alpha_cutoff;
    return alpha_hash(o, d, triangle) < a;
}

#endif
