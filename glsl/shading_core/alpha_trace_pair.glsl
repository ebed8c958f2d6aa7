// trace_pair for scenes with alpha-tested materials (SCENE_ALPHA), included by shading_core/trace_pair.glsl:
// each pass traverses for both rays still open, recording candidate hits, and the alpha tests
// run after it (shading_core/alpha_pass.glsl). Twin: trace_pair and trace_pair_alpha_pass in
// crates/shading-core/src/alpha_trace.rs.
#ifndef ALPHA_TRACE_PAIR_GLSL
#define ALPHA_TRACE_PAIR_GLSL

#include "shading_core/alpha_pass.glsl"

// Tests triangle index i for the closest ray (if enter_c) and the shadow ray (if enter_s).
void alpha_pair_test(uint i, PairRay closest, PairRay shadow, bool enter_c, bool enter_s, inout AlphaPass c, inout AlphaPass s) {
    Triangle tri = triangles[i];
    float t;
    vec2 bary;
    if (enter_c && intersect_triangle(closest.origin, closest.dir, tri, c.opaque.t, t, bary)) {
        alpha_pass_record(c, i, tri.alpha_tested, t, bary);
    }
    if (enter_s && intersect_triangle(shadow.origin, shadow.dir, tri, s.opaque.t, t, bary)) {
        alpha_pass_record(s, i, tri.alpha_tested, t, bary);
    }
}

#if SCENE_BRUTE_FORCE
// One pass over every triangle in index order for the rays open_c and open_s.
void trace_pair_alpha_pass(PairRay closest, PairRay shadow, bool open_c, bool open_s, inout AlphaPass c, inout AlphaPass s) {
    uint i = 0u;
    uint triangle_count = uint(SCENE_TRIANGLES_LENGTH);
    for (; i < triangle_count; ++i) {
        loop_tick();
        count_lane(COUNTER_TRIANGLE_TESTS);
        count_subgroup(COUNTER_TRIANGLE_ITERATIONS);
        alpha_pair_test(i, closest, shadow, open_c, open_s && s.opaque.triangle == NO_HIT, c, s);
    }
    note_loop_exit(i < triangle_count);
}
#else
// One pass over the BVH for the rays open_c and open_s, culling each at its nearest opaque hit
// so far; the shadow ray stops at an opaque hit.
void trace_pair_alpha_pass(PairRay closest, PairRay shadow, bool open_c, bool open_s, inout AlphaPass c, inout AlphaPass s) {
    vec3 inv_c = safe_inverse(closest.dir);
    vec3 o_inv_c = closest.origin * inv_c;
    vec3 inv_s = safe_inverse(shadow.dir);
    vec3 o_inv_s = shadow.origin * inv_s;
    uint end = SCENE_NODES_LENGTH;
    uint node = 0u;
    while (node < end) {
        loop_tick();
        count_lane(COUNTER_NODE_VISITS);
        count_subgroup(COUNTER_NODE_ITERATIONS);
        BvhNode n = nodes[node];
        bool blocked = s.opaque.triangle != NO_HIT;
        bool enter_c = open_c && intersect_aabb(o_inv_c, inv_c, n.lo, n.hi, c.opaque.t);
        bool enter_s = open_s && !blocked && intersect_aabb(o_inv_s, inv_s, n.lo, n.hi, s.opaque.t);
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
            alpha_pair_test(i, closest, shadow, enter_c, enter_s && s.opaque.triangle == NO_HIT, c, s);
        }
        note_loop_exit(i < last);
        // A blocked shadow ray is done, and so is the pass if the closest ray is not open.
        node = s.opaque.triangle != NO_HIT && !open_c ? end : n.skip;
    }
    note_loop_exit(node < end);
}
#endif

void trace_pair(PairRay closest, PairRay shadow, out Hit hit, out bool occluded) {
    count_lane(COUNTER_TRAVERSALS);
    AlphaPass c = alpha_pass_new(closest.tmax);
    AlphaPass s = alpha_pass_new(shadow.tmax);
    hit = c.opaque;
    occluded = false;
    bool open_c = closest.tmax > 0.0;
    bool open_s = shadow.tmax > 0.0;
    while (open_c || open_s) {
        loop_tick();
        if (open_c) alpha_pass_begin(c, closest.tmax);
        if (open_s) alpha_pass_begin(s, shadow.tmax);
        trace_pair_alpha_pass(closest, shadow, open_c, open_s, c, s);
        Hit h;
        if (open_c && alpha_pass_resolve(c, closest.origin, closest.dir, false, h)) {
            hit = h;
            open_c = false;
        }
        if (open_s && alpha_pass_resolve(s, shadow.origin, shadow.dir, true, h)) {
            occluded = h.triangle != NO_HIT;
            open_s = false;
        }
    }
    note_loop_exit(open_c || open_s);
}

#endif
