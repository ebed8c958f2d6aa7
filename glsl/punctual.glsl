// Shadow rays towards punctual lights. Expects bvh.glsl and lights.glsl. Twin: src/lights.rs.
#ifndef PUNCTUAL_GLSL
#define PUNCTUAL_GLSL

#include "bvh.glsl"
#include "lights.glsl"

// Whether anything blocks the way from surface point x (normal n) to a punctual light along the
// unit `dir` at distance `dist` (+inf: a directional light). Only x is offset: the light is a
// point in the air, not on a surface.
bool punctual_occluded(vec3 x, vec3 n, vec3 dir, float dist) {
    vec3 origin = offset_ray_origin(x, dot(dir, n) > 0.0 ? n : -n);
    if (isinf(dist)) return trace_occluded(origin, dir, 1e30);
    return trace_occluded(origin, x + dir * dist - origin, 1.0 - SEGMENT_EPSILON);
}

#endif
