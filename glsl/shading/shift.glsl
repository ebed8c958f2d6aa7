// Shift mappings of ReSTIR PT in primary sample space: random replay, reconnection and hybrid,
// with their inverses, on path records. Built from path vertices (shading/shift/vertex.glsl), regenerated
// paths (shading/shift/path.glsl) and the reconnection with its Jacobian (shading/shift/reconnection.glsl).
// Expects the scene bindings. Twin: crates/shading/src/shift/, where the measure, the contribution and
// the Jacobians are described; docs/shift-mappings.md.
#ifndef SHIFT_GLSL
#define SHIFT_GLSL

#include "shading/shift/reconnection.glsl"

// Random replay on a regenerated path `y` (trace_vertices of the base's length and end type):
// valid if it carries light and samples the base's lobes.
ShiftResult finish_random_replay(ShiftParams params, PathRecord base, Path y) {
    if (!finish_path(y)) return shift_failed();
    PathRecord record;
    if (!record_path(y, params, record) || record.lobes != base.lobes) return shift_failed();
    return shift_ok(record, 1.0, y);
}

ShiftResult shift_random_replay(ShiftParams params, PathRecord base, vec3 camera, Vertex y1) {
    Path y;
    if (!trace_vertices(camera, y1, base.seed, record_length(base), record_nee_end(base), record_nee_directional(base), y)) return shift_failed();
    return finish_random_replay(params, base, y);
}

ShiftResult inverse_random_replay(ShiftParams params, PathRecord shifted, vec3 camera, Vertex x1) {
    return shift_random_replay(params, shifted, camera, x1);
}

// Random replay where the base has no reconnection vertex (and the replayed path must have none
// either, or the shift would not be invertible), reconnection at the base's x_r otherwise. Both
// branches share one regeneration of the path (random replay: the whole path; reconnection: the
// prefix before x_r), so a kernel holds one copy of it; a replayed path needs no join.
ShiftResult shift_hybrid(ShiftParams params, PathRecord base, vec3 camera, Vertex y1) {
    uint r = record_reconnection_index(base);
    bool replay = r == 0u;
    Path y;
    uint length = replay ? record_length(base) : r - 1u;
    if (!trace_vertices(camera, y1, base.seed, length, replay && record_nee_end(base), replay ? record_nee_directional(base) : 0u, y)) return shift_failed();
    if (!replay) return finish_reconnection(params, base, y, r);
    if (!finish_path(y)) return shift_failed();
    PathRecord record;
    if (record_fields(y, params, record) != 0u || record.lobes != base.lobes) return shift_failed();
    return shift_ok(record, 1.0, y);
}

ShiftResult inverse_hybrid(ShiftParams params, PathRecord shifted, vec3 camera, Vertex x1) {
    return shift_hybrid(params, shifted, camera, x1);
}

ShiftResult shift_reconnection(ShiftParams params, PathRecord base, vec3 camera, Vertex y1) {
    return record_reconnection_index(base) == 2u ? reconnect_at(params, base, camera, y1, 2u) : shift_failed();
}

ShiftResult inverse_reconnection(ShiftParams params, PathRecord shifted, vec3 camera, Vertex x1) {
    return shift_reconnection(params, shifted, camera, x1);
}

#endif
