// Scene records shared with the host. Twin: crates/interface/src/gpu_types.rs (a test checks every offset).
#ifndef TYPES_GLSL
#define TYPES_GLSL

#include "shader_interface.glsl"

struct Material {
    vec3 base_color;
    float metallic;
    vec3 emission;      // already multiplied by KHR_materials_emissive_strength
    float roughness;    // linear (perceptual) roughness; GGX alpha = roughness^2
    float transmission;
    float ior;
    uint flags;
    float specular;        // KHR_materials_specular specularFactor; 0: no specular layer on non-metals
    vec3 specular_color;   // KHR_materials_specular specularColorFactor (linear)
    uint pad;
};
const uint MATERIAL_DOUBLE_SIDED = 1u;
const uint MATERIAL_UNLIT = 2u;     // KHR_materials_unlit: COLOR_0 multiplies the emission
const uint MATERIAL_ALPHA_EMISSION = 4u;    // emission times coverage (texture::emission_coverage)
const uint MATERIAL_BLEND_EMISSION = 8u;    // ... the coverage being alpha (a BLEND emitter)

// Vertex 0 and two edges, so that intersection needs no subtraction.
struct Triangle {
    vec3 v0;
    uint material;
    vec3 e1;
    uint emitter;       // index into the emitter table, NO_EMITTER if not emissive
    vec3 e2;
    uint alpha_tested;  // 1 if the material's alphaMode is MASK or BLEND (shading_core/alpha.glsl), else 0
};
const uint NO_EMITTER = 0xffffffffu;

// Depth-first nodes with skip links (stackless traversal): on a box hit an interior node
// continues at the next node (its left child), a leaf tests its triangles and continues at `skip`;
// on a miss traversal continues at `skip`. skip == node count ends the traversal.
// Leaves pack (first triangle << LEAF_COUNT_BITS) | count into `leaf`; interior nodes have leaf 0.
struct BvhNode {
    vec3 lo;
    uint skip;
    vec3 hi;
    uint leaf;
};
const uint LEAF_COUNT_BITS = 4u;
const uint LEAF_COUNT_MASK = 15u;

// One light NEE can choose: emissive triangles, then point and spot lights (the light tree's
// leaves), then directional lights. After the emitter_count entries, the buffer holds the light
// tree (shading/light_tree.glsl), then PUNCTUAL_ROWS rows per punctual light, each 16-byte row read as
// four words: (position, kind), (direction, cos outer), (intensity, cos inner), (emitter row, 0,
// 0, 0); then the environment map. Twin: gpu_types::Emitter, gpu_types::punctual_rows.
struct Emitter {
    uint triangle;      // the triangle, or PUNCTUAL_LIGHT_BIT | light index
    uint trail;         // the light tree's bit trail from the root to this light's leaf
    float intensity;    // largest radiant intensity (luminance, W/sr)
    uint leaf;          // the light tree node of its leaf (NO_EMITTER: a directional light)
};
const uint PUNCTUAL_LIGHT_BIT = 0x80000000u;
const uint PUNCTUAL_POINT = 0u;
const uint PUNCTUAL_SPOT = 1u;
const uint PUNCTUAL_DIRECTIONAL = 2u;

#endif
