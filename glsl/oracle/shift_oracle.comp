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

layout(std430, set = 0, binding = 5) readonly buffer Params { ShiftOracleParams shift_params; };
layout(std430, set = 0, binding = 6) readonly buffer Records { PathRecord records[]; };
layout(std430, set = 0, binding = 7) readonly buffer Targets { ShiftOracleTarget targets[]; };
layout(std430, set = 0, binding = 8) writeonly buffer Outputs { ShiftOracleOutput outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    ShiftParams params = ShiftParams(shift_params.roughness_threshold, shift_params.distance_threshold);
    ShiftOracleTarget target = targets[i];
    Vertex v1 = vertex_on_surface(target.triangle, target.primary_hit);
    vec3 camera = target.camera;
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
    ShiftOracleOutput o;
    o.record = s.record;
    o.contribution = s.contribution;
    o.valid = s.valid ? 1u : 0u;
    o.jacobian = s.jacobian;
    o.vertex_count = s.vertex_count;
    o.pad0 = 0u;
    o.pad1 = 0u;
    for (uint v = 0u; v < MAX_PATH_LENGTH; ++v) {
        o.vertices[v] = vec4(v < s.vertex_count ? s.vertices[v] : vec3(0.0), 0.0);
    }
    outputs[i] = o;
}
