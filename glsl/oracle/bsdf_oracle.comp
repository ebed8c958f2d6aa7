#version 460
// Oracle kernel: bsdf_eval_pdf and bsdf_sample on given materials and directions
// (twin: crates/shading-core/src/bsdf.rs).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "shading_core/bsdf.glsl"

layout(std430, set = 0, binding = 0) readonly buffer Materials { Material materials[]; };
layout(std430, set = 0, binding = 1) readonly buffer Inputs { BsdfOracleInput inputs[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Outputs { BsdfOracleOutput outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    Material m = materials[i];
    vec3 ng = inputs[i].geometric_normal;
    vec3 ns = inputs[i].shading_normal;
    vec3 wo = inputs[i].wo;
    vec3 wi = inputs[i].wi;
    vec4 u = inputs[i].u;
    float pdf;
    vec3 f = bsdf_eval_pdf(m, ng, ns, wo, wi, pdf);
    BsdfSample s = bsdf_sample(m, ng, ns, wo, u);
    outputs[i] = BsdfOracleOutput(f, pdf, s.wi, s.pdf, s.weight, s.lobe);
}
