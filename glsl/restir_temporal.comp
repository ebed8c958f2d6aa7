#version 460
// ReSTIR PT pass 2: temporal reuse. The pixel's primary hit is reprojected into the previous
// frame's camera (an unmoved camera keeps the pixel); that pixel's final reservoir is shifted
// into this pixel's domain and resampled with this pixel's initial reservoir, its confidence
// capped at m_cap times the current M. Compiled twice: with CANONICAL_DOMAIN_ONLY for an
// unmoved camera, without shifts (restir_reuse.glsl), and as is for a moving one.
#extension GL_GOOGLE_include_directive : require

#include "shader_interface.glsl"

layout(local_size_x = IMAGE_LOCAL_SIZE, local_size_y = IMAGE_LOCAL_SIZE) in;

#include "restir_reuse.glsl"

// The previous frame's pixel that saw `pos`, if any.
bool reproject(vec3 pos, out uint pixel) {
    vec3 d = pos - temporal.prev_cam_position.xyz;
    float z = dot(d, temporal.prev_cam_forward.xyz);
    if (!(z > 0.0)) return false;
    float x = dot(d, temporal.prev_cam_right.xyz) / (z * temporal.prev_cam_position.w * temporal.prev_cam_right.w);
    float y = dot(d, temporal.prev_cam_up.xyz) / (z * temporal.prev_cam_position.w);
    vec2 image = vec2((x + 1.0) * 0.5 * float(width), (1.0 - y) * 0.5 * float(height));
    if (!(image.x >= 0.0 && image.y >= 0.0 && image.x < float(width) && image.y < float(height))) return false;
    pixel = uint(image.y) * width + uint(image.x);
    return true;
}

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    bool inside = p.x < width && p.y < height;
    uint layer = gl_GlobalInvocationID.z;
    uint pixel = p.y * width + p.x;
    uint index = reservoir_index(pixel, layer);
    if (inside) {
        Reservoir canonical = load_reservoir(in_slot, index);
        Reservoir result = canonical;
        Surface surface = load_surface(surface_slot, pixel);
        // An unmoved camera sees the pixel's own domain again, whatever its jittered hits: the
        // history is taken as it is (reprojecting this frame's hit could round into a neighbour
        // at the pixel's edge, and an edge pixel's two hits may lie on different surfaces).
#ifdef CANONICAL_DOMAIN_ONLY
        // The host compiles this variant for frames whose camera did not move.
        bool unmoved = true;
#else
        bool unmoved = same_pose(previous_camera(), frame_camera());
#endif
        uint prev_pixel = pixel;
        bool reusable = unmoved;
        if (!unmoved && surface.triangle != NO_HIT && reproject(surface.pos, prev_pixel)) {
            reusable = similar_surfaces(surface, load_surface(1u - surface_slot, prev_pixel));
        }
        if (temporal.valid != 0u && reusable) {
            inputs[0] = ReuseInput(in_slot, index, Domain(p, false));
            confidences[0] = canonical.M;
            uint prev_index = reservoir_index(prev_pixel, layer);
            float confidence = min(load_reservoir(prev_slot, prev_index).M, temporal.m_cap * canonical.M);
            inputs[1] = ReuseInput(prev_slot, prev_index, Domain(uvec2(prev_pixel % width, prev_pixel / width), true));
            confidences[1] = confidence;
            vec3 expected;
            result = resample_inputs(2u, path_seed(index, frame_index, render_seed ^ pass_seed), expected);
            expectation[index] = vec4(expected, 0.0);
        }
        store_reservoir(out_slot, index, result);
    }
    report_pass_stats();
}
