#version 460
// Oracle kernel: one shift per item on records the host made, the function ORACLE_SHIFT names
// (0 to 2: shift_reconnection, shift_random_replay, shift_hybrid; 3 to 5: inverse_reconnection,
// inverse_random_replay, inverse_hybrid), each compiled alone. Twins: the functions of the same
// names in crates/shading/src/shift/.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#define SHIFT_ORACLE 1
#include "interface/scene_bindings.glsl"
#include "shading/shift.glsl"

#ifndef ORACLE_SHIFT
#error "ORACLE_SHIFT names the shift to test"
#endif

// x: unused, y: roughness threshold, z: distance threshold (float bits), w: unused.
layout(std430, set = 0, binding = 5) readonly buffer Params { uvec4 shift_params; };
layout(std430, set = 0, binding = 6) readonly buffer Records { PathRecord records[]; };
// Per item: the target domain's primary hit position (w: triangle bits; the base's x1 for an
// inverse), its camera position.
layout(std430, set = 0, binding = 7) readonly buffer Targets { vec4 targets[]; };
// Per item, 13 vec4: (valid, jacobian, vertex count, 0), the record (5 vec4), the vertices (7 vec4).
layout(std430, set = 0, binding = 8) writeonly buffer Outputs { vec4 outputs[]; };
layout(push_constant) uniform Push { uint count; };

const uint OUT_STRIDE = 13u;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    ShiftParams params = ShiftParams(uintBitsToFloat(shift_params.y), uintBitsToFloat(shift_params.z));
    vec4 target = targets[2u * i];
    Vertex v1 = vertex_on_surface(floatBitsToUint(target.w), target.xyz);
    vec3 camera = targets[2u * i + 1u].xyz;
    PathRecord record = records[i];
#if ORACLE_SHIFT == 0
    ShiftResult s = shift_reconnection(params, record, camera, v1);
#elif ORACLE_SHIFT == 1
    ShiftResult s = shift_random_replay(params, record, camera, v1);
#elif ORACLE_SHIFT == 2
    ShiftResult s = shift_hybrid(params, record, camera, v1);
#elif ORACLE_SHIFT == 3
    ShiftResult s = inverse_reconnection(params, record, camera, v1);
#elif ORACLE_SHIFT == 4
    ShiftResult s = inverse_random_replay(params, record, camera, v1);
#else
    ShiftResult s = inverse_hybrid(params, record, camera, v1);
#endif
    uint o = OUT_STRIDE * i;
    outputs[o] = vec4(s.valid ? 1.0 : 0.0, s.jacobian, float(s.vertex_count), 0.0);
    PathRecord r = s.record;
    outputs[o + 1u] = vec4(uintBitsToFloat(r.seed), uintBitsToFloat(r.info), uintBitsToFloat(r.lobes), uintBitsToFloat(r.rc_triangle));
    outputs[o + 2u] = vec4(r.rc_pos, r.rc_pdf);
    outputs[o + 3u] = vec4(r.rc_next, r.rc_geometry);
    outputs[o + 4u] = vec4(r.suffix, r.rc_pdf_after);
    outputs[o + 5u] = vec4(s.contribution, uintBitsToFloat(r.rc_next_triangle));
    for (uint v = 0u; v < MAX_PATH_LENGTH; ++v) {
        outputs[o + 6u + v] = vec4(v < s.vertex_count ? s.vertices[v] : vec3(0.0), 0.0);
    }
}
