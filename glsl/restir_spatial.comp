#version 460
// ReSTIR PT pass 3 (one round): spatial reuse from up to `neighbours` pixels drawn uniformly in
// a disk of `radius` pixels; neighbours whose primary hit differs too much are skipped.
#extension GL_GOOGLE_include_directive : require

#include "shader_interface.glsl"

layout(local_size_x = IMAGE_LOCAL_SIZE, local_size_y = IMAGE_LOCAL_SIZE) in;

#include "restir_reuse.glsl"
#include "shading_core/sampling.glsl"

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
        if (surface.triangle != NO_HIT) {
            uint seed = path_seed(index, frame_index, render_seed ^ pass_seed);
            inputs[0] = ReuseInput(in_slot, index, Domain(p, false));
            confidences[0] = canonical.M;
            uint n = 1u;
            for (uint j = 0u; j < min(spatial.neighbours, MAX_INPUTS - 1u); ++j) {
                loop_tick();
                vec4 u = rng_uniform4(seed, MAX_INPUTS + j, STREAM_RESAMPLE);
                float r = spatial.radius * sqrt(u.x);
                float phi = 2.0 * PI * u.y;
                ivec2 q = ivec2(floor(vec2(p) + 0.5 + r * vec2(cos(phi), sin(phi))));
                if (q.x < 0 || q.y < 0 || q.x >= int(width) || q.y >= int(height) || all(equal(uvec2(q), p))) continue;
                uint neighbour = uint(q.y) * width + uint(q.x);
                if (!similar_surfaces(surface, load_surface(surface_slot, neighbour))) continue;
                uint neighbour_index = reservoir_index(neighbour, layer);
                inputs[n] = ReuseInput(in_slot, neighbour_index, Domain(uvec2(q), false));
                confidences[n] = load_reservoir(in_slot, neighbour_index).M;
                n += 1u;
            }
            vec3 expected;
            result = resample_inputs(n, seed, expected);
            expectation[index] = vec4(expected, 0.0);
        }
        store_reservoir(out_slot, index, result);
    }
    report_pass_stats();
}
