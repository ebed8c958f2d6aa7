#version 460
// Oracle kernel: the initial candidates of one traced path per item (stream_path_candidates of
// shading/candidates.glsl) streamed into a fresh Resampler, from primary hits and seeds the host
// chose, with Russian roulette where the frame parameters' flags ask for it. Twin:
// stream_path_candidates in crates/shading/src/candidates.rs.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "interface/scene_bindings.glsl"

// The pass counters shading/candidates.glsl expects (interface/restir_bindings.glsl in the kernels).
uint local_nonfinite_weights = 0u;
uint local_candidates_dropped = 0u;

#include "shading/candidates.glsl"

layout(std430, set = 0, binding = 5) readonly buffer Params { CandidatesOracleParams params; };
layout(std430, set = 0, binding = 6) readonly buffer Items { CandidatesOracleInput items[]; };
layout(std430, set = 0, binding = 7) writeonly buffer Outputs { CandidatesOracleOutput outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    ShiftParams shift_params = ShiftParams(params.roughness_threshold, params.distance_threshold);
    CandidatesOracleInput item = items[i];
    Vertex y1 = vertex_on_surface(item.triangle, item.primary_hit);
    Resampler s = resampler_begin();
    bool russian_roulette = (flags & FLAG_RUSSIAN_ROULETTE) != 0u;
    stream_path_candidates(s, item.camera, y1, item.seed, params.max_path_length, shift_params, params.mis_scale,
                           russian_roulette);
    Reservoir res = resampler_finish(s);
    outputs[i] = CandidatesOracleOutput(res.record, s.expected, s.weight_sum, s.chosen_target, res.W, s.chosen_lost ? 1u : 0u,
                                        local_nonfinite_weights, local_candidates_dropped, 0u, 0u, 0u);
}
