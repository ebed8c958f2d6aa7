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

// x: the longest path, y: roughness threshold, z: distance threshold, w: the candidates' MIS
// scale (float bits).
layout(std430, set = 0, binding = 5) readonly buffer Params { uvec4 params; };
// Per item: the primary hit position (w: triangle bits), the camera position (w: seed bits).
layout(std430, set = 0, binding = 6) readonly buffer Items { vec4 items[]; };
// Per item, 8 vec4: the chosen record (5 vec4, as in shift_oracle.comp), (weight sum, p̂ of the
// chosen, W, 1 if the choice was lost), (expected, 0), (non-finite weights, dropped, 0, 0).
layout(std430, set = 0, binding = 7) writeonly buffer Outputs { vec4 outputs[]; };
layout(push_constant) uniform Push { uint count; };

const uint OUT_STRIDE = 8u;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    ShiftParams shift_params = ShiftParams(uintBitsToFloat(params.y), uintBitsToFloat(params.z));
    vec4 hit = items[2u * i];
    vec4 camera = items[2u * i + 1u];
    Vertex y1 = vertex_on_surface(floatBitsToUint(hit.w), hit.xyz);
    Resampler s = resampler_begin();
    bool russian_roulette = (flags & FLAG_RUSSIAN_ROULETTE) != 0u;
    stream_path_candidates(s, camera.xyz, y1, floatBitsToUint(camera.w), params.x, shift_params, uintBitsToFloat(params.w),
                           russian_roulette);
    Reservoir res = resampler_finish(s);
    PathRecord r = res.record;
    uint o = OUT_STRIDE * i;
    outputs[o] = vec4(uintBitsToFloat(r.seed), uintBitsToFloat(r.info), uintBitsToFloat(r.lobes), uintBitsToFloat(r.rc_triangle));
    outputs[o + 1u] = vec4(r.rc_pos, r.rc_pdf);
    outputs[o + 2u] = vec4(r.rc_next, r.rc_geometry);
    outputs[o + 3u] = vec4(r.suffix, r.rc_pdf_after);
    outputs[o + 4u] = vec4(r.contribution, uintBitsToFloat(r.rc_next_triangle));
    outputs[o + 5u] = vec4(s.weight_sum, s.chosen_target, res.W, s.chosen_lost ? 1.0 : 0.0);
    outputs[o + 6u] = vec4(s.expected, 0.0);
    outputs[o + 7u] = vec4(float(local_nonfinite_weights), float(local_candidates_dropped), 0.0, 0.0);
}
