#version 460
// ReSTIR PT pass 1: the pixel's surface (its hit through the pixel's centre), the emission seen
// directly and the initial reservoir from `initial.candidates` traced paths (shading/candidates.glsl),
// each through its own sub-pixel position.
#extension GL_GOOGLE_include_directive : require

#include "shader_interface.glsl"

layout(local_size_x = IMAGE_LOCAL_SIZE, local_size_y = IMAGE_LOCAL_SIZE) in;

#include "interface/restir_bindings.glsl"
#include "shading/candidates.glsl"
#include "scene/camera.glsl"

// The radiance a camera ray from `camera` in `dir` receives directly from what it hits (or
// escapes to): end_emission of the one-segment path.
vec3 seen_emission(vec3 camera, Hit hit, vec3 dir) {
    Vertex end = hit.triangle == NO_HIT ? vertex_escaped(dir) : hit_vertex(hit);
    return end_emission(Vertex(camera, vec3(0.0), NO_HIT), end);
}

// The pixel's mean directly seen emission over `emission_rays` jittered camera rays, the first
// being the reservoir's (`first_hit`). It is estimated apart from the reservoir's paths, which
// start at the primary hit, so more rays cut the noise of a light's edge without bias.
vec3 pixel_emission(uvec2 p, uint seed, vec3 camera, vec3 first_dir, Hit first_hit) {
    vec3 sum = seen_emission(camera, first_hit, first_dir);
    for (uint j = 1u; j < initial.emission_rays; ++j) {
        loop_tick();
        vec4 jitter = rng_uniform4(seed, j, STREAM_CAMERA);
        vec3 dir = camera_ray_dir(float(p.x) + jitter.x, float(p.y) + jitter.y);
        sum += seen_emission(camera, trace_closest(camera, dir, SHIFT_RAY_TMAX), dir);
    }
    return sum / float(initial.emission_rays);
}

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    bool inside = p.x < width && p.y < height;
    uint pixel = p.y * width + p.x;
    uint index = reservoir_index(pixel, gl_GlobalInvocationID.z);
    if (inside) {
        uint first = frame_index * initial.candidates;
        vec3 camera = cam_position.xyz;
        // The surface that picks temporal and spatial inputs is seen through the pixel's centre,
        // not through a candidate's position: inputs chosen by a candidate's own hit would make
        // the set of inputs, and so the MIS weights, depend on that candidate, and the canonical
        // sample would no longer be distributed as its weight assumes (a bias at silhouettes).
        // The pixel's reservoirs share it; the first layer traces it.
        if (gl_GlobalInvocationID.z == 0u) {
            Hit centre = trace_closest(camera, camera_ray_dir(float(p.x) + 0.5, float(p.y) + 0.5), SHIFT_RAY_TMAX);
            Surface surface = Surface(vec3(0.0), NO_HIT, camera, 0.0);
            if (centre.triangle != NO_HIT) surface = Surface(hit_vertex(centre).pos, centre.triangle, camera, centre.t);
            store_surface(surface_slot, pixel, surface);
        }
        Resampler s = resampler_begin();
        ShiftParams params = ShiftParams(roughness_threshold, distance_threshold);
        uint max_length = min(max_depth, MAX_PATH_LENGTH);
        float scale = 1.0 / float(initial.candidates);
        vec3 emission = vec3(0.0);
        // Each path has its own sub-pixel position, drawn from its seed (see Domain in
        // restir_reuse.glsl).
        for (uint c = 0u; c < initial.candidates; ++c) {
            loop_tick();
            uint seed = path_seed(index, first + c, render_seed);
            vec4 jitter = rng_uniform4(seed, 0u, STREAM_CAMERA);
            vec3 dir = camera_ray_dir(float(p.x) + jitter.x, float(p.y) + jitter.y);
            Hit hit = trace_closest(camera, dir, SHIFT_RAY_TMAX);
            if (c == 0u) emission = pixel_emission(p, seed, camera, dir, hit);
            if (hit.triangle == NO_HIT) continue;
            Vertex y1 = hit_vertex(hit);
            stream_path_candidates(s, camera, y1, seed, max_length, params, scale, (flags & FLAG_RUSSIAN_ROULETTE) != 0u);
        }
        s.confidence = float(initial.candidates);
        // Under an unmoved camera every frame estimates the same emission, so the estimate is
        // the running mean over the frames since the camera last moved (unbiased however they
        // are weighted), over at most temporal.m_cap frames, the temporal reservoir's cap.
        float frames = 1.0;
        if (initial.emission_history != 0u) {
            vec4 history = direct[index];
            frames = min(history.w + 1.0, max(temporal.m_cap, 1.0));
            emission = history.rgb + (emission - history.rgb) / frames;
        }
        direct[index] = vec4(emission, frames);
        expectation[index] = vec4(s.expected, 0.0);
        store_reservoir(out_slot, index, resampler_finish(s));
    }
    report_pass_stats();
}
