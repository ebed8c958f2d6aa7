#version 460
// Oracle kernel: the resampling MIS weights (shading_core/gris.glsl, MIS_MODE as compiled) and the streaming
// resampler (shading_core/reservoir.glsl) on inputs the host recorded, one resampling per item
// (twins: crates/shading-core/src/gris.rs mis_weight, resampler_begin, resampler_offer, resampler_finish).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "shading_core/gris.glsl"
#include "shading_core/reservoir.glsl"

// Per item: the number of inputs n, their confidences c_l, and for each input i the row
// p̂_{<-l}(y_i), l = 0..n-1.
layout(std430, set = 0, binding = 0) readonly buffer Counts { uint counts[]; };
layout(std430, set = 0, binding = 1) readonly buffer Confidences { float case_confidences[]; };
layout(std430, set = 0, binding = 2) readonly buffer Targets { float case_targets[]; };
// Per item and input: the candidate the input offers.
layout(std430, set = 0, binding = 3) readonly buffer Offers { GrisOracleOffer offers[]; };
layout(std430, set = 0, binding = 4) writeonly buffer Outputs { GrisOracleOutput outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint item = gl_GlobalInvocationID.x;
    if (item >= count) return;
    uint n = counts[item];
    for (uint l = 0u; l < n; ++l) confidences[l] = case_confidences[MAX_INPUTS * item + l];
    float m[MAX_INPUTS];
    for (uint i = 0u; i < MAX_INPUTS; ++i) m[i] = 0.0;
    Resampler s = resampler_begin();
    for (uint i = 0u; i < n; ++i) {
        for (uint l = 0u; l < n; ++l) targets_from[l] = case_targets[MAX_INPUTS * (MAX_INPUTS * item + i) + l];
        m[i] = mis_weight(n, i);
        s.confidence += confidences[i];
        GrisOracleOffer a = offers[MAX_INPUTS * item + i];
        float w = a.weight;
        float u = a.u;
        if (!(w > 0.0)) continue;
        PathRecord y = reservoir_empty().record;
        y.seed = i;
        y.contribution = a.contribution;
        resampler_add(s, y, a.target, w, u);
    }
    bool chose = s.weight_sum > 0.0;
    // As record_chosen does when the chosen path cannot be recorded.
    if (chose && offers[MAX_INPUTS * item + s.chosen.seed].lost != 0u) s.chosen_lost = true;
    Reservoir r = resampler_finish(s);
    vec4 mis_weights[3] = vec4[3](vec4(m[0], m[1], m[2], m[3]), vec4(m[4], m[5], m[6], m[7]), vec4(m[8], 0.0, 0.0, 0.0));
    outputs[item] = GrisOracleOutput(mis_weights, s.expected, chose ? int(r.record.seed) : -1, r.W, r.M, 0.0, 0.0);
}
