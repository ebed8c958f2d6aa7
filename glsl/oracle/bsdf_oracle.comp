#version 460
// Oracle kernel: bsdf_eval_pdf and bsdf_sample on given materials and directions
// (twin: crates/shading-core/src/bsdf.rs).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "shading_core/bsdf.glsl"

layout(std430, set = 0, binding = 0) readonly buffer Materials { Material materials[]; };
// Per item: geometric normal, shading normal, wo, wi (xyz), u.
layout(std430, set = 0, binding = 1) readonly buffer Inputs { vec4 inputs[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Outputs { vec4 outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    Material m = materials[i];
    vec3 ng = inputs[5u * i].xyz;
    vec3 ns = inputs[5u * i + 1u].xyz;
    vec3 wo = inputs[5u * i + 2u].xyz;
    vec3 wi = inputs[5u * i + 3u].xyz;
    vec4 u = inputs[5u * i + 4u];
    float pdf;
    vec3 f = bsdf_eval_pdf(m, ng, ns, wo, wi, pdf);
    BsdfSample s = bsdf_sample(m, ng, ns, wo, u);
    outputs[3u * i] = vec4(f, pdf);
    outputs[3u * i + 1u] = vec4(s.wi, s.pdf);
    outputs[3u * i + 2u] = vec4(s.weight, uintBitsToFloat(s.lobe));
}
