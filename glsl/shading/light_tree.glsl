// Light selection by likely contribution: a stochastic single-path descent of the light tree
// (pbrt-v4 BVHLightSampler; Conty Estevez & Kulla 2018), built on the host (crates/scene/src/light_tree.rs)
// and stored in the emitter buffer right after the emitter rows: a header row (directional light
// count, node count, 0, 0), then LIGHT_NODE_ROWS rows per node.
// Directional lights are not in the tree: NEE takes each of them (light_select_pmf). Expects `emitters` and the
// scene parameters (interface/scene_bindings.glsl). Twin: crates/shading/src/light_tree.rs.
#ifndef LIGHT_TREE_GLSL
#define LIGHT_TREE_GLSL

#include "interface/loop_budget.glsl"
#include "interface/types.glsl"

uvec4 emitter_words(uint row) {
    Emitter e = emitters[row];
    return uvec4(e.triangle, e.trail, floatBitsToUint(e.intensity), e.leaf);
}

uint light_tree_row(uint r) { return emitter_count + r; }

LightNode light_node(uint i) {
    uint base = light_tree_row(1u + LIGHT_NODE_ROWS * i);
    uvec4 a = emitter_words(base);
    uvec4 b = emitter_words(base + 1u);
    uvec4 c = emitter_words(base + 2u);
    uvec4 d = emitter_words(base + 3u);
    LightNode n;
    n.lo = uintBitsToFloat(a.xyz);
    n.intensity = uintBitsToFloat(a.w);
    n.hi = uintBitsToFloat(b.xyz);
    n.cos_theta_o = uintBitsToFloat(b.w);
    n.axis = uintBitsToFloat(c.xyz);
    n.cos_theta_e = uintBitsToFloat(c.w);
    n.child = d.x;
    n.flags = d.y;
    return n;
}

// The directional lights: the last rows before emitter_count.
uint directional_count() { return emitters[light_tree_row(0u)].triangle; }

// The first row after the tree: the punctual lights' parameters.
uint light_tree_end() { return light_tree_row(1u + LIGHT_NODE_ROWS * emitters[light_tree_row(0u)].trail); }

// pbrt-v4 LightBounds::Importance: intensity · cos θ' · |cos θ_i'| / d² at p with normal `normal`
// (unit), θ' the smallest angle between the node's emission cone and the direction to p over the
// node's bounding sphere, θ_i' the smallest angle between ±normal and the directions to that
// sphere (|cos|: a surface may transmit), d clamped to the sphere's radius; 0 where no light
// below can reach p. Twin: light_tree::light_node_importance.
float light_node_importance(LightNode n, vec3 p, vec3 normal) {
    vec3 half_diag = 0.5 * (n.hi - n.lo);
    float r2 = dot(half_diag, half_diag);
    vec3 from_centre = p - 0.5 * (n.lo + n.hi);
    float d2 = dot(from_centre, from_centre);
    float d2_clamped = max(d2, r2);
    if (!(d2_clamped > 0.0)) return 0.0;
    float cos_w = d2 > 0.0 ? clamp(dot(n.axis, from_centre) / sqrt(d2), -1.0, 1.0) : 1.0;
    if ((n.flags & LIGHT_NODE_TWO_SIDED) != 0u) cos_w = abs(cos_w);
    float sin_w = sqrt(max(1.0 - cos_w * cos_w, 0.0));
    float sin_o = sqrt(max(1.0 - n.cos_theta_o * n.cos_theta_o, 0.0));
    // θ_x = max(0, θ_w - θ_o), then θ' = max(0, θ_x - θ_b) with θ_b the bounding sphere's
    // half-angle seen from p (π inside it).
    float cos_x = 1.0;
    float sin_x = 0.0;
    if (cos_w < n.cos_theta_o) {
        cos_x = cos_w * n.cos_theta_o + sin_w * sin_o;
        sin_x = sin_w * n.cos_theta_o - cos_w * sin_o;
    }
    float cos_p = 1.0;
    float cos_i = 1.0;
    if (d2 > r2) {
        float sin_b2 = r2 / d2;
        float cos_b = sqrt(max(1.0 - sin_b2, 0.0));
        float sin_b = sqrt(sin_b2);
        if (cos_x < cos_b) cos_p = cos_x * cos_b + sin_x * sin_b;
        float cos_n = min(abs(dot(normal, from_centre)) / sqrt(d2), 1.0);
        if (cos_n < cos_b) cos_i = cos_n * cos_b + sqrt(max(1.0 - cos_n * cos_n, 0.0)) * sin_b;
    }
    if (cos_p < n.cos_theta_e) return 0.0;
    return n.intensity * max(cos_p, 0.0) * cos_i / d2_clamped;
}

const uint WALK_SAMPLE = 0u;    // descend by u
const uint WALK_TRAIL = 1u;     // descend along a light's bit trail

// Descends the tree from the root at p to a child with probability proportional to its
// importance, by u in [0, 1) (WALK_SAMPLE) or along the bit trail `trail` (WALK_TRAIL; bit d: the
// second child at depth d), and returns in `pmf` the product of the branch probabilities:
// sampling a light and following its trail give the same product for the same p. Returns the
// emitter row of the leaf reached (NO_EMITTER where no light below can reach p: then a
// probability of 0). Twin: light_tree::light_tree_walk.
uint light_tree_walk(vec3 p, vec3 normal, uint mode, uint trail, float u, out float pmf) {
    pmf = 1.0;
    uint node = 0u;
    uint depth = 0u;
    for (; depth <= LIGHT_TREE_MAX_DEPTH; depth++) {
        loop_tick();
        LightNode n = light_node(node);
        if ((n.flags & LIGHT_NODE_LEAF) != 0u) return n.child;
        float first = light_node_importance(light_node(node + 1u), p, normal);
        float second = light_node_importance(light_node(n.child), p, normal);
        if (!(first + second > 0.0)) {
            // No light below reaches p: a dead end.
            pmf = 0.0;
            return NO_EMITTER;
        }
        float p_first = first / (first + second);
        bool take_second = mode == WALK_SAMPLE ? u >= p_first : (trail & 1u) != 0u;
        if (take_second) {
            pmf *= 1.0 - p_first;
            u = min((u - p_first) / (1.0 - p_first), 0.99999994);
            node = n.child;
        } else {
            pmf *= p_first;
            u = min(u / p_first, 0.99999994);
            node = node + 1u;
        }
        trail >>= 1u;
    }
    // The tree is at most LIGHT_TREE_MAX_DEPTH deep: only the driver's loop budget ends here.
    note_loop_exit(depth <= LIGHT_TREE_MAX_DEPTH);
    pmf = 0.0;
    return NO_EMITTER;
}

// Probability of choosing the environment rather than another light.
float env_select_prob() { return scene_env.w; }

// The emitter row of directional light k (k < directional_count()).
uint directional_row(uint k) { return emitter_count - directional_count() + k; }

// Directional lights are not chosen: NEE estimates every one of them at every vertex
// (sample_directional in shading/lights.glsl), with probability 1, beside the one light it draws here
// from the tree. A one-sample choice between a sun and the tree's lamps gave a lamp fewer
// samples wherever the sun outshone it, and wasted the sun's where the lamp's fixture shaded it
// (docs/light-sampling.md).

// The probability that light sampling at p (normal `normal`) chooses the light of emitter row
// `row`: for a light of the tree, its walk's, the environment's share removed
// (1 - env_select_prob()); 1 for a directional light, which NEE always takes.
// Twin: light_tree::light_select_pmf.
float light_select_pmf(vec3 p, vec3 normal, uint row) {
    if (row >= emitter_count - directional_count()) return 1.0;
    float walk;
    light_tree_walk(p, normal, WALK_TRAIL, emitters[row].trail, 0.0, walk);
    return walk * (1.0 - env_select_prob());
}

// The emitter row of the tree that light sampling at p draws with u in [0, 1) (NO_EMITTER when
// the tree is empty or no light of it can reach p) and, in pmf, its probability as
// light_select_pmf gives it. Twin: light_tree::light_select.
uint light_select(vec3 p, vec3 normal, float u, out float pmf) {
    pmf = 0.0;
    if (emitter_count == directional_count()) return NO_EMITTER;
    float walk;
    uint row = light_tree_walk(p, normal, WALK_SAMPLE, 0u, u, walk);
    pmf = walk * (1.0 - env_select_prob());
    return row;
}

#endif
