// What every shift returns (shading/shift/path.glsl, shading/shift/reconnection.glsl, shading/shift.glsl) and what the
// reuse loop (shading/resample_inputs.glsl) consumes; apart from the shifts, so that an oracle kernel of
// the loop can return its own. Twin: ShiftResult in crates/shading/src/shift/path.rs.
#ifndef SHIFT_RESULT_GLSL
#define SHIFT_RESULT_GLSL

#include "shading_core/path_record.glsl"

struct ShiftResult {
    bool valid;
    PathRecord record;
    float jacobian;
    vec3 contribution;
#ifdef SHIFT_ORACLE
    // The vertices the shift made (see crates/shading/src/shift/path.rs), which only the oracle test compares:
    // production kernels would copy them on every shift.
    uint vertex_count;
    vec3 vertices[MAX_PATH_LENGTH];
#endif
};

ShiftResult shift_failed() {
    ShiftResult s;
    s.valid = false;
    s.jacobian = 0.0;
    s.contribution = vec3(0.0);
#ifdef SHIFT_ORACLE
    s.vertex_count = 0u;
#endif
    return s;
}

#endif
