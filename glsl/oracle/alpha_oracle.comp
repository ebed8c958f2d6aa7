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

// Per item: (origin, shadow tmax), (direction, -), (triangle bits, b1, b2, -).
layout(std430, set = 0, binding = 9) readonly buffer Inputs { vec4 inputs[]; };
layout(std430, set = 0, binding = 10) writeonly buffer Outputs { vec4 outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    vec4 o = inputs[3u * i];
    vec3 d = inputs[3u * i + 1u].xyz;
    vec4 a = inputs[3u * i + 2u];
    uint tri = floatBitsToUint(a.x);
    Hit h = bvh_traverse(o.xyz, d, 1e30, false);
    bool any = bvh_traverse(o.xyz, d, o.w, true).triangle != NO_HIT;
    Hit ph;
    bool pair_occluded;
    trace_pair(PairRay(o.xyz, d, 1e30), PairRay(o.xyz, d, o.w), ph, pair_occluded);
    uint material = triangles[tri].material;
    float alpha = material_alpha(material, surface_at(tri, a.yz));
    outputs[4u * i] = vec4(h.t, uintBitsToFloat(h.triangle), h.bary);
    outputs[4u * i + 1u] = vec4(any ? 1.0 : 0.0, pair_occluded ? 1.0 : 0.0, alpha_hash(o.xyz, d, tri), alpha);
    outputs[4u * i + 2u] = vec4(ph.t, uintBitsToFloat(ph.triangle), ph.bary);
    outputs[4u * i + 3u] = vec4(alpha_keeps(tri, a.yz, o.xyz, d) ? 1.0 : 0.0, 0.0, 0.0, 0.0);
}
