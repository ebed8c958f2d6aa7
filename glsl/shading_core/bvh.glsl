// Ray-triangle intersection and stack traversal of the flattened BVH. Expects the scene buffers
// `triangles` and `nodes` (interface/scene_bindings.glsl). Twin: crates/shading-core/src/bvh.rs.
#ifndef BVH_GLSL
#define BVH_GLSL

#include "interface/counters.glsl"
#include "interface/loop_budget.glsl"
#include "shading_core/ray_offset.glsl"
#include "interface/types.glsl"

#ifndef SCENE_ALPHA
#define SCENE_ALPHA 0
#endif

struct Hit {
    float t;
    uint triangle;   // NO_HIT on a miss
    vec2 bary;       // (b1, b2) of vertices v0 + e1 and v0 + e2
};

// Möller-Trumbore; hits with t in (0, tmax) count, from either side.
bool intersect_triangle(vec3 o, vec3 d, Triangle tri, float tmax, out float t, out vec2 bary) {
    vec3 p = cross(d, tri.e2);
    float det = dot(tri.e1, p);
    t = 0.0;
    bary = vec2(0.0);
    if (det == 0.0) return false;
    float inv_det = 1.0 / det;
    vec3 s = o - tri.v0;
    float b1 = dot(s, p) * inv_det;
    if (b1 < 0.0 || b1 > 1.0) return false;
    vec3 q = cross(s, tri.e1);
    float b2 = dot(d, q) * inv_det;
    if (b2 < 0.0 || b1 + b2 > 1.0) return false;
    t = dot(tri.e2, q) * inv_det;
    bary = vec2(b1, b2);
    return t > 0.0 && t < tmax;
}

// Slab test: does the ray enter the box before tmax? o_inv_d = o * inv_d turns each plane
// distance into one fused multiply-add.
bool intersect_aabb(vec3 o_inv_d, vec3 inv_d, vec3 lo, vec3 hi, float tmax) {
    vec3 t0 = lo * inv_d - o_inv_d;
    vec3 t1 = hi * inv_d - o_inv_d;
    vec3 tn = min(t0, t1);
    vec3 tf = max(t0, t1);
    float enter = max(max(tn.x, tn.y), max(tn.z, 0.0));
    float leave = min(min(tf.x, tf.y), min(tf.z, tmax));
    return enter <= leave;
}

vec3 safe_inverse(vec3 d) {
    const float big = 1e30;
    return vec3(d.x != 0.0 ? 1.0 / d.x : big, d.y != 0.0 ? 1.0 / d.y : big, d.z != 0.0 ? 1.0 / d.z : big);
}

#if SCENE_ALPHA
#include "shading_core/alpha_trace.glsl"
#else
// Closest hit when any_hit is false; the first hit found otherwise (shadow rays). With
// SCENE_ALPHA, hits that alpha_keeps rejects do not count (shading_core/alpha_trace.glsl). Stackless: the
// uniform control flow suits SIMD CPUs (lavapipe) and keeps register pressure low on GPUs.
Hit bvh_traverse(vec3 o, vec3 d, float tmax, bool any_hit) {
    Hit hit;
    hit.t = tmax;
    hit.triangle = NO_HIT;
    hit.bary = vec2(0.0);
    vec3 inv_d = safe_inverse(d);
    vec3 o_inv_d = o * inv_d;
    uint end = SCENE_NODES_LENGTH;
    uint node = 0u;
    count_lane(COUNTER_TRAVERSALS);
    while (node < end) {
        loop_tick();
        count_lane(COUNTER_NODE_VISITS);
        count_subgroup(COUNTER_NODE_ITERATIONS);
        BvhNode n = nodes[node];
        if (!intersect_aabb(o_inv_d, inv_d, n.lo, n.hi, hit.t)) {
            node = n.skip;
            continue;
        }
        if (n.leaf == 0u) {
            node += 1u;
            continue;
        }
        uint first = n.leaf >> LEAF_COUNT_BITS;
        uint last = first + (n.leaf & LEAF_COUNT_MASK);
        uint i = first;
        for (; i < last; ++i) {
            loop_tick();
            count_lane(COUNTER_TRIANGLE_TESTS);
            count_subgroup(COUNTER_TRIANGLE_ITERATIONS);
            float t;
            vec2 bary;
            if (intersect_triangle(o, d, triangles[i], hit.t, t, bary)) {
                hit.t = t;
                hit.triangle = i;
                hit.bary = bary;
                if (any_hit) return hit;
            }
        }
        note_loop_exit(i < last);
        node = n.skip;
    }
    note_loop_exit(node < end);
    return hit;
}

#endif

Hit trace_closest(vec3 o, vec3 d, float tmax) { return bvh_traverse(o, d, tmax, false); }
bool trace_occluded(vec3 o, vec3 d, float tmax) { return bvh_traverse(o, d, tmax, true).triangle != NO_HIT; }

// Segment tests stop this fraction short of their (offset) end point.

// The shadow ray of the segment between surface points p (normal np, on triangle index tp) and q
// (normal nq, on triangle index tq). Both ends are offset off their surfaces, each towards the
// other, and the ray runs between the offset points: offsetting one end only moves a grazing far
// hit by more than any epsilon.
void segment_ray(vec3 p, vec3 np, uint tp, vec3 q, vec3 nq, uint tq, out vec3 origin, out vec3 dir, out float tmax) {
    vec3 d = q - p;
    origin = offset_ray_origin(p, dot(d, np) > 0.0 ? np : -np, triangles[tp]);
    vec3 target = offset_ray_origin(q, dot(d, nq) < 0.0 ? nq : -nq, triangles[tq]);
    dir = target - origin;
    tmax = 1.0 - SEGMENT_EPSILON;
}

#endif
