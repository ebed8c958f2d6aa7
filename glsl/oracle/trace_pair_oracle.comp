#version 460
// Oracle kernel: trace_pair against a real scene (twin: trace_pair in crates/shading-core/src/bvh.rs). Compiled with
// the scene's defines, and with SCENE_BRUTE_FORCE=1 for the brute-force form.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "interface/scene_bindings.glsl"
#include "shading_core/trace_pair.glsl"

layout(std430, set = 0, binding = 5) readonly buffer Inputs { TracePairOracleInput inputs[]; };
layout(std430, set = 0, binding = 6) writeonly buffer Outputs { TracePairOracleOutput outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    OracleRay c = inputs[i].closest;
    OracleRay s = inputs[i].shadow;
    Hit h;
    bool occluded;
    trace_pair(PairRay(c.origin, c.dir, c.tmax), PairRay(s.origin, s.dir, s.tmax), h, occluded);
    outputs[i] = TracePairOracleOutput(OracleHit(h.t, h.triangle, h.bary), occluded ? 1u : 0u, 0u, 0u, 0u);
}
