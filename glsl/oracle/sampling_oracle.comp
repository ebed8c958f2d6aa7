#version 460
// Oracle kernel: the warps of shading_core/sampling.glsl on given uniforms (twin: crates/shading-core/src/sampling.rs).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "shading_core/sampling.glsl"

#include "shader_interface.glsl"

layout(std430, set = 0, binding = 0) readonly buffer Inputs { SamplingOracleInput inputs[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Outputs { SamplingOracleOutput outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    vec4 u = inputs[i].u;
    vec4 p = vec4(inputs[i].direction, inputs[i].alpha);
    vec3 t, b;
    build_onb(normalize(p.xyz), t, b);
    SamplingOracleOutput o;
    o.cosine_hemisphere = sample_cosine_hemisphere(u.xy);
    o.cosine_pdf = pdf_cosine_hemisphere(u.z * 2.0 - 1.0);
    o.uniform_sphere = sample_uniform_sphere(u.xy);
    o.power_heuristic = power_heuristic(u.z, u.w);
    o.triangle = sample_triangle(u.xy);
    o.concentric_disk = sample_concentric_disk(u.zw);
    vec3 wo = normalize(vec3(p.x, p.y, abs(p.z) + 1e-3));
    o.ggx_vndf = sample_ggx_vndf(wo, p.w, u.xy);
    o.onb_tangent = t;
    o.onb_bitangent = b;
    o.round_trip = to_world(to_local(u.xyz, t, b, normalize(p.xyz)), t, b, normalize(p.xyz));
    o.pad0 = 0.0;
    o.pad1 = 0.0;
    o.pad2 = 0.0;
    o.pad3 = 0.0;
    outputs[i] = o;
}
