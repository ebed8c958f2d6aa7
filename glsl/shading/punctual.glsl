// Shadow rays towards punctual lights. Expects shading_core/bvh.glsl and shading/lights.glsl. Twin: crates/shading/src/lights.rs.
#ifndef PUNCTUAL_GLSL
#define PUNCTUAL_GLSL

#include "shading_core/bvh.glsl"
#include "shading/lights.glsl"

// The shadow ray from surface point x (normal n, on triangle index tri) to a punctual light along
// the unit `dir` at distance `dist` (+inf: a directional light). Only x is offset: the light is a
// point in the air, not on a surface.
void punctual_ray(vec3 x, vec3 n, uint tri, vec3 dir, float dist, out vec3 origin, out vec3 ray_dir, out float tmax) {
    origin = offset_ray_origin(x, dot(dir, n) > 0.0 ? n : -n, triangles[tri]);
    ray_dir = isinf(dist) ? dir : x + dir * dist - origin;
    tmax = isinf(dist) ? 1e30 : 1.0 - SEGMENT_EPSILON;
}

// Whether anything blocks the way from x to the punctual light (see punctual_ray).
bool punctual_occluded(vec3 x, vec3 n, uint tri, vec3 dir, float dist) {
    vec3 origin, ray_dir;
    float tmax;
    punctual_ray(x, n, tri, dir, dist, origin, ray_dir, tmax);
    return trace_occluded(origin, ray_dir, tmax);
}

#endif
