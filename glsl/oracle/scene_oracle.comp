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

// Per item: origin (w: tmax), direction, light-sample uniforms (xyz), image point (xy).
layout(std430, set = 0, binding = 5) readonly buffer Inputs { vec4 inputs[]; };
layout(std430, set = 0, binding = 6) writeonly buffer Outputs { vec4 outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    vec4 o = inputs[4u * i];
    vec3 d = inputs[4u * i + 1u].xyz;
    vec3 u = inputs[4u * i + 2u].xyz;
    vec2 px = inputs[4u * i + 3u].xy;
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
    outputs[6u * i + 5u] = vec4(shadowed ? 1.0 : 0.0, pdf_again, 0.0, 0.0);
    outputs[6u * i] = vec4(h.t, uintBitsToFloat(h.triangle), h.bary);
    outputs[6u * i + 1u] = vec4(occluded ? 1.0 : 0.0, offset_ray_origin(o.xyz, d, triangles[offset_triangle]));
    outputs[6u * i + 2u] = vec4(ls.dir, ls.dist);
    outputs[6u * i + 3u] = vec4(ls.radiance, ls.pdf);
    outputs[6u * i + 4u] = vec4(camera_ray_dir(px.x, px.y), uintBitsToFloat(ls.triangle));
}
