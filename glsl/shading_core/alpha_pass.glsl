// Alpha tests out of the triangle loops (glsl/shading_core/bvh.glsl, glsl/shading_core/trace_pair.glsl with SCENE_ALPHA):
// llvmpipe runs every branch of a loop body under a mask, so a test inside the loop would cost its
// texture lookup on every iteration where any lane meets a triangle. A traversal pass instead
// records, per ray, the nearest hit on a triangle without alpha testing and the nearest
// alpha-tested hit before it; alpha_keeps then runs once, after the loop. Only when that hit is
// rejected and the pass met more than one alpha-tested hit before the opaque one does the ray go
// through another pass, counting only hits past the rejected one in (t, triangle index) order,
// the order in which both traversals visit triangles (the BVH's leaves index them in depth-first
// order). The hit found is the one a test inside the loop finds: the first of the nearest kept
// hits. Twin: AlphaPass in crates/shading-core/src/alpha_pass.rs.
#ifndef ALPHA_PASS_GLSL
#define ALPHA_PASS_GLSL

#include "shading_core/alpha.glsl"

struct AlphaPass {
    Hit opaque;        // nearest hit on a triangle without alpha testing; t = tmax, NO_HIT if none
    Hit tested;        // nearest alpha-tested hit met before `opaque` was as near as it is now
    uint count;        // alpha-tested hits met before the then-nearest opaque hit (>= those before it)
    float bound_t;     // hits at or before (bound_t, bound_triangle) in (t, index) order do not count
    uint bound_triangle;
};

// A ray's pass state before its first pass: every hit with t > 0 counts.
AlphaPass alpha_pass_new(float tmax) {
    Hit none = Hit(tmax, NO_HIT, vec2(0.0));
    return AlphaPass(none, none, 0u, 0.0, NO_HIT);
}

// Starts a pass up to tmax, keeping the bound.
void alpha_pass_begin(inout AlphaPass p, float tmax) {
    p.opaque = Hit(tmax, NO_HIT, vec2(0.0));
    p.tested = p.opaque;
    p.count = 0u;
}

// Records the hit of triangle index i at distance t (< p.opaque.t, as intersect_triangle with
// tmax p.opaque.t returns it) and barycentrics bary. `alpha_tested` is the triangle's flag.
// Straight-line code: an early return here costs llvmpipe 13% of an alpha-tested scene's time.
void alpha_pass_record(inout AlphaPass p, uint i, uint alpha_tested, float t, vec2 bary) {
    bool counts = t > p.bound_t || (t == p.bound_t && i > p.bound_triangle);
    bool opaque = alpha_tested == 0u;
    if (counts && opaque) p.opaque = Hit(t, i, bary);
    if (counts && !opaque) p.count += 1u;
    if (counts && !opaque && t < p.tested.t) p.tested = Hit(t, i, bary);
}

// After a pass of the ray (o, d): true with its hit when done, false (the bound moved past the
// rejected hit) when it needs another pass. With any_hit, any opaque hit is the answer.
bool alpha_pass_resolve(inout AlphaPass p, vec3 o, vec3 d, bool any_hit, out Hit hit) {
    hit = p.opaque;
    if (any_hit && p.opaque.triangle != NO_HIT) return true;
    // Equal t: the alpha-tested hit was met first, or the opaque one would have excluded it.
    if (p.tested.triangle == NO_HIT || p.tested.t > p.opaque.t) return true;
    if (alpha_keeps(p.tested.triangle, p.tested.bary, o, d)) {
        hit = p.tested;
        return true;
    }
    if (p.count == 1u) return true;
    p.bound_t = p.tested.t;
    p.bound_triangle = p.tested.triangle;
    return false;
}

#endif
