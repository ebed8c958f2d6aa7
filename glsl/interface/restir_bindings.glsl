// The bindings every ReSTIR PT kernel shares (set 0, after the scene's 0-4, numbered by
// RestirBinding in crates/interface/src/shader_interface.rs, which also sets RESTIR_MAX_PASSES), with loads and
// stores by slot. Twins: ReuseParams, Surface, ReservoirHead/Tail, RestirStats and RestirPass
// in crates/interface/src/gpu_types.rs. Each pass reads its slots from the frame's pass table, picked by a push
// constant, so that one descriptor set serves every pass: reservoir slots 0-2 rotate between
// initial candidates, reuse rounds and the previous frame's result; surface slots 0-1 alternate
// between frames. Parameters live in storage buffers and the push constant is only an index:
// lavapipe compiles a kernel again for each new value of a uniform or push constant that steers
// its control flow (crates/vk/src/buffer.rs), and the slots steer every load and store below.
#ifndef RESTIR_BINDINGS_GLSL
#define RESTIR_BINDINGS_GLSL

#include "interface/scene_bindings.glsl"
#include "shading_core/reservoir.glsl"
#include "interface/loop_budget.glsl"
#include "interface/counters.glsl"

layout(std430, set = 0, binding = RESTIR_BINDING_REUSE_PARAMS) readonly buffer ReuseParams { REUSE_PARAMS_FIELDS };

layout(std430, set = 0, binding = RESTIR_BINDING_SURFACES0) buffer Surfaces0 { Surface surfaces0[]; };
layout(std430, set = 0, binding = RESTIR_BINDING_SURFACES1) buffer Surfaces1 { Surface surfaces1[]; };
layout(std430, set = 0, binding = RESTIR_BINDING_RESERVOIR_HEADS0) buffer ReservoirHeads0 { ReservoirHead heads0[]; };
layout(std430, set = 0, binding = RESTIR_BINDING_RESERVOIR_TAILS0) buffer ReservoirTails0 { ReservoirTail tails0[]; };
layout(std430, set = 0, binding = RESTIR_BINDING_RESERVOIR_HEADS1) buffer ReservoirHeads1 { ReservoirHead heads1[]; };
layout(std430, set = 0, binding = RESTIR_BINDING_RESERVOIR_TAILS1) buffer ReservoirTails1 { ReservoirTail tails1[]; };
layout(std430, set = 0, binding = RESTIR_BINDING_RESERVOIR_HEADS2) buffer ReservoirHeads2 { ReservoirHead heads2[]; };
layout(std430, set = 0, binding = RESTIR_BINDING_RESERVOIR_TAILS2) buffer ReservoirTails2 { ReservoirTail tails2[]; };
layout(std430, set = 0, binding = RESTIR_BINDING_DIRECT) buffer Direct { vec4 direct[]; };     // rgb: emission seen directly, w: frames averaged
layout(std430, set = 0, binding = RESTIR_BINDING_ACCUM) buffer Accum { vec4 accum[]; };       // rgb: sum of frames, w: count
layout(std430, set = 0, binding = RESTIR_BINDING_ACCUM_SQ) buffer AccumSq { vec4 accum_sq[]; };  // rgb: sum of squares
layout(std430, set = 0, binding = RESTIR_BINDING_RESTIR_STATS) buffer RestirStats { RESTIR_STATS_FIELDS };
// rgb: the expectation of f(Y) W_Y over the last resampling's choice (see Resampler), written by
// whichever pass last resampled the pixel.
layout(std430, set = 0, binding = RESTIR_BINDING_EXPECTATION) buffer Expectation { vec4 expectation[]; };

layout(push_constant) uniform PassIndex {
    uint pass_index;     // this dispatch's entry of `passes`
};

#define in_slot (passes[pass_index].in_slot)
#define out_slot (passes[pass_index].out_slot)
#define prev_slot (passes[pass_index].prev_slot)
#define surface_slot (passes[pass_index].surface_slot)
#define pass_seed (passes[pass_index].pass_seed)

// A pixel keeps `reservoirs` independent reservoirs, each with its own paths, history and
// neighbours, and the pixel's estimate is their mean. Each reservoir's path is one colour
// drawn in proportion to luminance, and that colour noise stays however many candidates one
// reservoir resamples; independent reservoirs average it down. Reservoir `layer` of every pixel
// forms one width x height layer of the per-reservoir buffers (reservoirs, emission,
// expectation); layer 0 alone is the one-reservoir layout.
uint reservoir_index(uint pixel, uint layer) {
    return layer * width * height + pixel;
}

// if/else rather than ?:, which glslang's optimiser mistypes for structs read from buffers.
Surface load_surface(uint slot, uint pixel) {
    if (slot == 0u) return surfaces0[pixel];
    return surfaces1[pixel];
}

void store_surface(uint slot, uint pixel, Surface s) {
    if (slot == 0u) surfaces0[pixel] = s;
    else surfaces1[pixel] = s;
}

Reservoir load_reservoir(uint slot, uint pixel) {
    if (slot == 0u) return reservoir_join(heads0[pixel], tails0[pixel]);
    if (slot == 1u) return reservoir_join(heads1[pixel], tails1[pixel]);
    return reservoir_join(heads2[pixel], tails2[pixel]);
}

void store_reservoir(uint slot, uint pixel, Reservoir r) {
    ReservoirHead h = reservoir_head(r);
    ReservoirTail t = reservoir_tail(r);
    if (slot == 0u) {
        heads0[pixel] = h;
        tails0[pixel] = t;
    } else if (slot == 1u) {
        heads1[pixel] = h;
        tails1[pixel] = t;
    } else {
        heads2[pixel] = h;
        tails2[pixel] = t;
    }
}

// Per-invocation counts, summed per subgroup into Stats by report_pass_stats().
uint local_shifts_attempted = 0u;
uint local_shifts_failed = 0u;
uint local_nonfinite_weights = 0u;
uint local_candidates_dropped = 0u;
uint local_nonfinite_pixels = 0u;
uint local_shift_runs = 0u;   // counted by one lane of the subgroup (see shift_path)

// Call once at the end of main(), from uniform control flow.
void report_pass_stats() {
    uint iterations = subgroup_loop_iterations();
    bool cut = subgroup_loop_budget_cut();
    uint attempted = subgroupAdd(local_shifts_attempted);
    uint failed = subgroupAdd(local_shifts_failed);
    uint nonfinite = subgroupAdd(local_nonfinite_weights);
    uint dropped = subgroupAdd(local_candidates_dropped);
    uint pixels = subgroupAdd(local_nonfinite_pixels);
    uint shift_runs = subgroupAdd(local_shift_runs);
#if COUNT_TRAVERSALS
    uint traversals = subgroupAdd(traversals_started);
#else
    uint traversals = 0u;
#endif
    if (subgroupElect()) {
        atomicMax(max_loop_iterations, iterations);
        if (cut) atomicAdd(loop_budget_cut_groups, 1u);
        if (attempted > 0u) atomicAdd(shifts_attempted, attempted);
        if (failed > 0u) atomicAdd(shifts_failed, failed);
        if (nonfinite > 0u) atomicAdd(nonfinite_weights, nonfinite);
        if (dropped > 0u) atomicAdd(candidates_dropped, dropped);
        if (pixels > 0u) atomicAdd(nonfinite_pixels, pixels);
        if (traversals > 0u) atomicAdd(reuse_traversals, traversals);
        if (shift_runs > 0u) {
            atomicAdd(shift_subgroup_runs, shift_runs);
            atomicMax(subgroup_size, gl_SubgroupSize);
        }
    }
}

#endif
