// bvh_traverse for scenes with alpha-tested materials (SCENE_ALPHA), included by shading_core/bvh.glsl: the
// loop records candidate hits and the alpha tests run after it (shading_core/alpha_pass.glsl). Twin:
// bvh_traverse and bvh_alpha_pass in crates/shading-core/src/alpha_trace.rs.
#ifndef ALPHA_TRACE_GLSL
#define ALPHA_TRACE_GLSL

#include "shading_core/alpha_pass.glsl"

// One pass of the ray (o, d) over the BVH: boxes are culled at the nearest opaque hit so far, so
// that every alpha-tested hit before it is met; with any_hit the pass ends at an opaque hit.
void bvh_alpha_pass(vec3 o, vec3 d, bool any_hit, inout AlphaPass p) {
    vec3 inv_d = safe_inverse(d);
    vec3 o_inv_d = o * inv_d;
    uint end = SCENE_NODES_LENGTH;
    uint node = 0u;
    while (node < end) {
        loop_tick();
        count_lane(COUNTER_NODE_VISITS);
        count_subgroup(COUNTER_NODE_ITERATIONS);
        BvhNode n = nodes[node];
        if (!intersect_aabb(o_inv_d, inv_d, n.lo, n.hi, p.opaque.t)) {
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
            if (intersect_triangle(o, d, tri, p.opaque.t, t, bary)) {
                alpha_pass_record(p, i, tri.alpha_tested, t, bary);
            }
        }
        note_loop_exit(i < last);
        node = any_hit && p.opaque.triangle != NO_HIT ? end : n.skip;
    }
    note_loop_exit(node < end);
}

// Closest kept hit when any_hit is false; some kept hit otherwise (shadow rays). Hits that
// alpha_keeps rejects do not count.
Hit bvh_traverse(vec3 o, vec3 d, float tmax, bool any_hit) {
    count_lane(COUNTER_TRAVERSALS);
    AlphaPass p = alpha_pass_new(tmax);
    Hit hit;
    bool done = false;
    while (!done) {
        loop_tick();
        alpha_pass_begin(p, tmax);
        bvh_alpha_pass(o, d, any_hit, p);
        done = alpha_pass_resolve(p, o, d, any_hit, hit);
    }
    note_loop_exit(!done);
    return hit;
}

#endif
