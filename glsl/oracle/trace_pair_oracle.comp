#version 460
// Oracle kernel: trace_pair against a real scene (twin: trace_pair in crates/shading-core/src/bvh.rs). Compiled with
// the scene's defines, and with SCENE_BRUTE_FORCE=1 for the brute-force form.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "interface/scene_bindings.glsl"
#include "shading_core/trace_pair.glsl"

// Per item: closest ray origin (w: tmax), direction, shadow ray origin (w: tmax), direction.
layout(std430, set = 0, binding = 5) readonly buffer Inputs { vec4 inputs[]; };
layout(std430, set = 0, binding = 6) writeonly buffer Outputs { vec4 outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    vec4 co = inputs[4u * i];
    vec4 so = inputs[4u * i + 2u];
    Hit h;
    bool occluded;
    trace_pair(PairRay(co.xyz, inputs[4u * i + 1u].xyz, co.w), PairRay(so.xyz, inputs[4u * i + 3u].xyz, so.w), h, occluded);
    outputs[2u * i] = vec4(h.t, uintBitsToFloat(h.triangle), h.bary);
    outputs[2u * i + 1u] = vec4(occluded ? 1.0 : 0.0, 0.0, 0.0, 0.0);
}
