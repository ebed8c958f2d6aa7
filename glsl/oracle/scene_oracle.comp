#version 460
// Oracle kernel: BVH traversal, light sampling and camera rays against a real scene
// (twins: crates/shading-core/src/bvh.rs, crates/shading-core/src/ray_offset.rs, crates/shading/src/lights.rs, crates/scene/src/camera.rs), and shadow rays
// to punctual lights.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "interface/scene_bindings.glsl"
#include "shading_core/bvh.glsl"
#include "scene/camera.glsl"
#include "shading/lights.glsl"
#include "shading/punctual.glsl"

layout(std430, set = 0, binding = 5) readonly buffer Inputs { SceneOracleInput inputs[]; };
layout(std430, set = 0, binding = 6) writeonly buffer Outputs { SceneOracleOutput outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    vec4 o = vec4(inputs[i].ray.origin, inputs[i].ray.tmax);
    vec3 d = inputs[i].ray.dir;
    vec3 u = inputs[i].light_uniforms;
    vec2 px = inputs[i].image_point;
    Hit h = trace_closest(o.xyz, d, o.w);
    bool occluded = trace_occluded(o.xyz, d, o.w);
    // The ray direction stands in for the shading point's normal.
    LightSample ls = sample_light(o.xyz, d, u);
    uint offset_triangle = i % uint(SCENE_TRIANGLES_LENGTH);
    bool shadowed = is_punctual_light(ls.triangle) && punctual_occluded(o.xyz, d, offset_triangle, ls.dir, ls.dist);
    // The pdf of the same sample recomputed as MIS and the shifts do (light_select_pmf's walk
    // along the light's bit trail): it must equal ls.pdf.
    float pdf_again = 0.0;
    if (ls.pdf > 0.0) {
        uint row = is_punctual_light(ls.triangle) ? punctual_emitter_row(ls.triangle & ~PUNCTUAL_LIGHT_BIT) : NO_EMITTER;
        if (ls.triangle == NO_EMITTER) pdf_again = environment_pdf(ls.dir);
        else if (row != NO_EMITTER) pdf_again = light_select_pmf(o.xyz, d, row);
        else pdf_again = emitter_pdf(o.xyz, d, ls.triangle, ls.dir, ls.dist);
    }
    outputs[i] = SceneOracleOutput(OracleHit(h.t, h.triangle, h.bary), offset_ray_origin(o.xyz, d, triangles[offset_triangle]),
                                   occluded ? 1u : 0u, ls.dir, ls.dist, ls.radiance, ls.pdf, camera_ray_dir(px.x, px.y),
                                   ls.triangle, shadowed ? 1u : 0u, pdf_again, uvec2(0u));
}
