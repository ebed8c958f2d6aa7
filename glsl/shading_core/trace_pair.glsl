// Two rays in one traversal: a closest-hit ray (the path's next segment) and an any-hit ray (the
// shadow ray of next-event estimation), tested against each node or triangle loaded once.
// llvmpipe runs 8 lanes in lockstep, executes every branch of a loop body under a mask and loads
// divergent buffer elements one lane and one word at a time, so the cost of a traversal is its
// loop iterations times the words it loads; a pair shares both (docs/performance.md).
// Expects the scene buffers (interface/scene_bindings.glsl). Twin: trace_pair in crates/shading-core/src/bvh.rs.
#ifndef TRACE_PAIR_GLSL
#define TRACE_PAIR_GLSL

#include "shading_core/bvh.glsl"

// 1: small scenes bound as uniform buffers test every triangle in index order; no node is loaded
// and every lane runs the same iterations. 0: the BVH, traversed once for both rays.
#ifndef SCENE_BRUTE_FORCE
#define SCENE_BRUTE_FORCE 0
#endif

// A ray with tmax <= 0 is inactive: it hits nothing and costs no node visit of its own.
struct PairRay {
    vec3 origin;
    vec3 dir;
    float tmax;
};

#if SCENE_ALPHA
#include "shading_core/alpha_trace_pair.glsl"
#elif SCENE_BRUTE_FORCE
void trace_pair(PairRay closest, PairRay shadow, out Hit hit, out bool occluded) {
    hit = Hit(closest.tmax, NO_HIT, vec2(0.0));
    occluded = false;
    count_lane(COUNTER_TRAVERSALS);
    uint i = 0u;
    uint triangle_count = uint(SCENE_TRIANGLES_LENGTH);
    for (; i < triangle_count; ++i) {
        loop_tick();
        count_lane(COUNTER_TRIANGLE_TESTS);
        count_subgroup(COUNTER_TRIANGLE_ITERATIONS);
        Triangle tri = triangles[i];
        float t;
        vec2 bary;
        if (intersect_triangle(closest.origin, closest.dir, tri, hit.t, t, bary)) {
            hit = Hit(t, i, bary);
        }
        occluded = intersect_triangle(shadow.origin, shadow.dir, tri, shadow.tmax, t, bary) || occluded;
    }
    note_loop_exit(i < triangle_count);
}
#else
void trace_pair(PairRay closest, PairRay shadow, out Hit hit, out bool occluded) {
    hit = Hit(closest.tmax, NO_HIT, vec2(0.0));
    occluded = false;
    count_lane(COUNTER_TRAVERSALS);
    vec3 inv_c = safe_inverse(closest.dir);
    vec3 o_inv_c = closest.origin * inv_c;
    vec3 inv_s = safe_inverse(shadow.dir);
    vec3 o_inv_s = shadow.origin * inv_s;
    bool active_c = closest.tmax > 0.0;
    bool active_s = shadow.tmax > 0.0;
    uint end = SCENE_NODES_LENGTH;
    uint node = active_c || active_s ? 0u : end;
    while (node < end) {
        loop_tick();
        count_lane(COUNTER_NODE_VISITS);
        count_subgroup(COUNTER_NODE_ITERATIONS);
        BvhNode n = nodes[node];
        bool enter_c = active_c && intersect_aabb(o_inv_c, inv_c, n.lo, n.hi, hit.t);
        bool enter_s = active_s && !occluded && intersect_aabb(o_inv_s, inv_s, n.lo, n.hi, shadow.tmax);
        if (!enter_c && !enter_s) {
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
            Triangle tri = triangles[i];
            float t;
            vec2 bary;
            if (enter_c && intersect_triangle(closest.origin, closest.dir, tri, hit.t, t, bary)) {
                hit = Hit(t, i, bary);
            }
            occluded = (enter_s && intersect_triangle(shadow.origin, shadow.dir, tri, shadow.tmax, t, bary)) || occluded;
        }
        note_loop_exit(i < last);
        // An occluded shadow ray is done, and so is the lane if it has no closest ray.
        node = occluded && !active_c ? end : n.skip;
    }
    note_loop_exit(node < end);
}
#endif

#endif
