#version 460
// Progressive path tracing: each invocation adds samples_per_dispatch paths to its pixel's sums,
// starting the next path as soon as one ends (see path_tracer.glsl).
#extension GL_GOOGLE_include_directive : require

#include "shader_interface.glsl"

layout(local_size_x = IMAGE_LOCAL_SIZE, local_size_y = IMAGE_LOCAL_SIZE) in;

#include "interface/scene_bindings.glsl"
#include "path_tracer.glsl"

layout(std430, set = 0, binding = PATHTRACE_BINDING_ACCUM) buffer Accum { vec4 accum[]; };       // rgb: sum of L, w: count
layout(std430, set = 0, binding = PATHTRACE_BINDING_ACCUM_SQ) buffer AccumSq { vec4 accum_sq[]; };  // rgb: sum of L^2
layout(std430, set = 0, binding = PATHTRACE_BINDING_STATUS) buffer Status {
    uint max_loop_iterations;
    uint loop_budget_cut_groups;
    uint nonfinite_paths;           // paths whose radiance or throughput is NaN or infinite
    uint status_pad;                // std430 aligns the uvec2 array below to 8 bytes
    uvec2 counters[COUNTER_COUNT];  // 64-bit totals (low, high) of interface/counters.glsl
    uint subgroup_lanes;
};

// Adds a subgroup's counter total to its 64-bit sum; call from the elected lane.
void add_counter(uint counter, uint value) {
    uint before = atomicAdd(counters[counter].x, value);
    if (before + value < before) atomicAdd(counters[counter].y, 1u);
}

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    // Lanes outside the image still reach the loop-budget report below, so no early return.
    bool inside = p.x < width && p.y < height;
    uint pixel = p.y * width + p.x;
    // The sums continue from the pixel's accumulated ones, one sample at a time, so that they
    // add up in sample order whatever the split into dispatches (chunk sizes follow timing):
    // equal seeds and settings give equal images, bit for bit.
    vec4 accumulated = inside ? accum[pixel] : vec4(0.0);
    vec3 sum = accumulated.rgb;
    vec3 sum_sq = inside ? accum_sq[pixel].rgb : vec3(0.0);
    uint sample_index = 0u;
    uint nonfinite = 0u;
    PathState path = path_begin(p, path_seed(pixel, sample_offset, render_seed));
    while (inside) {
        loop_tick();
        count_lane(COUNTER_PATH_STEPS);
        count_subgroup(COUNTER_STEP_ITERATIONS);
        if (path_step(path)) continue;
        if (any(isnan(path.radiance)) || any(isinf(path.radiance)) || any(isnan(path.beta)) || any(isinf(path.beta))) nonfinite += 1u;
        sum += path.radiance;
        sum_sq += path.radiance * path.radiance;
        sample_index += 1u;
        if (sample_index == samples_per_dispatch) break;
        path = path_begin(p, path_seed(pixel, sample_offset + sample_index, render_seed));
    }
    note_loop_exit(inside && sample_index < samples_per_dispatch);
    if (inside) {
        accum[pixel] = vec4(sum, accumulated.w + float(samples_per_dispatch));
        accum_sq[pixel].rgb = sum_sq;
    }
    uint iterations = subgroup_loop_iterations();
    bool cut = subgroup_loop_budget_cut();
    uint group_nonfinite = subgroupAdd(nonfinite);
    uint counts[COUNTER_COUNT];
    for (uint c = 0u; c < COUNTER_COUNT; ++c) counts[c] = subgroup_count(c);
    if (subgroupElect()) {
        atomicMax(max_loop_iterations, iterations);
        if (cut) atomicAdd(loop_budget_cut_groups, 1u);
        if (group_nonfinite > 0u) atomicAdd(nonfinite_paths, group_nonfinite);
        if (TRAVERSAL_COUNTERS != 0) {
            for (uint c = 0u; c < COUNTER_COUNT; ++c) add_counter(c, counts[c]);
            atomicMax(subgroup_lanes, gl_SubgroupSize);
        }
    }
}
