#version 460
// Oracle kernel: RNG outputs for given keys (twin: crates/shading-core/src/rng.rs). Bit-exact comparison.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "shading_core/rng.glsl"

// Per item: the key k.
layout(std430, set = 0, binding = 0) readonly buffer Inputs { uvec4 inputs[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Outputs { RngOracleOutput outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    uvec4 k = inputs[i];
    outputs[i] = RngOracleOutput(pcg4d(k), path_seed(k.x, k.y, k.z), 0u, 0u, 0u, rng_uniform4(k.x, k.y, k.z));
}
