#version 460
// Oracle kernel: alpha testing in traversal (glsl/shading_core/alpha.glsl inside bvh_traverse and
// trace_pair) on a scene with MASK and BLEND materials (twins: crates/shading-core/src/alpha.rs,
// crates/shading-core/src/bvh.rs, crates/shading-core/src/texture.rs). Compiled with the scene's defines, SCENE_ALPHA
// among them. Everything is bound in set 0: the scene at 0-4, the surface bindings at 5-8, then
// inputs and outputs.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#define SURFACE_SET 0
#define SURFACE_BINDING 5
#include "interface/scene_bindings.glsl"
#include "shading_core/trace_pair.glsl"

layout(std430, set = 0, binding = 9) readonly buffer Inputs { AlphaOracleInput inputs[]; };
layout(std430, set = 0, binding = 10) writeonly buffer Outputs { AlphaOracleOutput outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    vec4 o = vec4(inputs[i].origin, inputs[i].shadow_tmax);
    vec3 d = inputs[i].dir;
    vec2 bary = inputs[i].bary;
    uint tri = inputs[i].triangle;
    Hit h = bvh_traverse(o.xyz, d, 1e30, false);
    bool any = bvh_traverse(o.xyz, d, o.w, true).triangle != NO_HIT;
    Hit ph;
    bool pair_occluded;
    trace_pair(PairRay(o.xyz, d, 1e30), PairRay(o.xyz, d, o.w), ph, pair_occluded);
    uint material = triangles[tri].material;
    float alpha = material_alpha(material, surface_at(tri, bary));
    outputs[i] = AlphaOracleOutput(OracleHit(h.t, h.triangle, h.bary), any ? 1u : 0u, pair_occluded ? 1u : 0u,
                                   alpha_hash(o.xyz, d, tri), alpha, OracleHit(ph.t, ph.triangle, ph.bary),
                                   alpha_keeps(tri, bary, o.xyz, d) ? 1u : 0u, 0u, 0u, 0u);
}
