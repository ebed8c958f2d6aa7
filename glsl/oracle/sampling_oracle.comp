#version 460
// Oracle kernel: the warps of shading_core/sampling.glsl on given uniforms (twin: crates/shading-core/src/sampling.rs).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "shading_core/sampling.glsl"

// Per item: u (xy used), params (xyz: direction or normal, w: alpha).
layout(std430, set = 0, binding = 0) readonly buffer Inputs { vec4 inputs[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Outputs { vec4 outputs[]; };
layout(push_constant) uniform Push { uint count; };

const uint OUTPUTS_PER_ITEM = 7u;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    vec4 u = inputs[2u * i];
    vec4 p = inputs[2u * i + 1u];
    uint o = OUTPUTS_PER_ITEM * i;
    vec3 t, b;
    build_onb(normalize(p.xyz), t, b);
    outputs[o] = vec4(sample_cosine_hemisphere(u.xy), pdf_cosine_hemisphere(u.z * 2.0 - 1.0));
    outputs[o + 1u] = vec4(sample_uniform_sphere(u.xy), power_heuristic(u.z, u.w));
    outputs[o + 2u] = vec4(sample_triangle(u.xy), sample_concentric_disk(u.zw));
    vec3 wo = normalize(vec3(p.x, p.y, abs(p.z) + 1e-3));
    outputs[o + 3u] = vec4(sample_ggx_vndf(wo, p.w, u.xy), 0.0);
    outputs[o + 4u] = vec4(t, 0.0);
    outputs[o + 5u] = vec4(b, 0.0);
    outputs[o + 6u] = vec4(to_world(to_local(u.xyz, t, b, normalize(p.xyz)), t, b, normalize(p.xyz)), 0.0);
}
