// Error-bounded ray origins: every ray that leaves a surface starts at offset_ray_origin.
// Twin: crates/shading-core/src/ray_offset.rs, where the bound is derived.
#ifndef RAY_OFFSET_GLSL
#define RAY_OFFSET_GLSL

#include "interface/types.glsl"

// 2^-17 = 128 unit roundoffs of f32 per unit of |v0| + |e1| + |e2| (see crates/shading-core/src/ray_offset.rs).

// The float next to x away from zero in direction s (s > 0: up, s < 0: down); x itself when
// s == 0, x == 0 (the next float is denormal and may be flushed) or x is infinite.
float next_float_towards(float x, float s) {
    if (s == 0.0 || x == 0.0 || isinf(x)) return x;
    int bits = floatBitsToInt(x);
    return intBitsToFloat((s > 0.0) == (x > 0.0) ? bits + 1 : bits - 1);
}

// Moves p, a point computed as tri.v0 + b1 tri.e1 + b2 tri.e2, off the triangle's plane along n
// (the geometric normal facing the side the ray leaves to) by more than p's rounding error and
// the intersection test's, at any scale and position (pbrt-v4 OffsetRayOrigin).
vec3 offset_ray_origin(vec3 p, vec3 n, Triangle tri) {
    vec3 err = RAY_OFFSET_SCALE * (abs(tri.v0) + abs(tri.e1) + abs(tri.e2));
    vec3 o = p + dot(abs(n), err) * n;
    return vec3(next_float_towards(o.x, n.x), next_float_towards(o.y, n.y), next_float_towards(o.z, n.z));
}

#endif
