// Light selection by likely contribution: a stochastic single-path descent of the light tree
// (pbrt-v4 BVHLightSampler; Conty Estevez & Kulla 2018), built on the host (src/scene/light_tree.rs)
// and stored in the emitter buffer right after the emitter rows: a header row (directional light
// count, node count, 0, 0), then LIGHT_NODE_ROWS rows per node.
// Directional lights are chosen beside the tree (light_select). Expects `emitters` and the
// scene parameters (scene_bindings.glsl). Twin: src/shading/light_tree.rs.
#ifndef LIGHT_TREE_GLSL
#define LIGHT_TREE_GLSL

#include "loop_budget.glsl"
#include "types.glsl"

struct LightNode {
    vec3 lo;
    float intensity;   // sum of the largest radiant intensities below (luminance, W/sr)
    vec3 hi;
    float cos_theta_o; // the cone of normals around axis
    vec3 axis;
    float cos_theta_e; // how far beyond it the lights still emit
    uint child;        // a leaf's emitter row; an interior node's second child (the first follows it)
    uint flags;        // LIGHT_NODE_LEAF | LIGHT_NODE_TWO_SIDED
};

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
const uint WALK_ESTIMATE = 2u;  // descend to the more important child, summing the others

// Descends the tree from the root at p. WALK_SAMPLE and WALK_TRAIL go to a child with
// probability proportional to its importance, by u in [0, 1) or along the bit trail `trail`
// (bit d: the second child at depth d), and return in `value` the product of the branch
// probabilities: sampling a light and following its trail give the same product for the same p.
// WALK_ESTIMATE goes to the more important child and returns in `value` the importance of the
// leaf reached plus that of every child passed by: a deterministic estimate of what the tree's
// lights send to p, refined towards the one that sends most. Returns the emitter row of the leaf
// reached (NO_EMITTER where no light below can reach p: then a probability of 0).
// Twin: light_tree::light_tree_walk.
uint light_tree_walk(vec3 p, vec3 normal, uint mode, uint trail, float u, out float value) {
    value = mode == WALK_ESTIMATE ? 0.0 : 1.0;
    uint node = 0u;
    float reached = -1.0;  // the importance of `node`, once known
    uint depth = 0u;
    for (; depth <= LIGHT_TREE_MAX_DEPTH; depth++) {
        loop_tick();
        LightNode n = light_node(node);
        if ((n.flags & LIGHT_NODE_LEAF) != 0u) {
            if (mode == WALK_ESTIMATE) value += reached >= 0.0 ? reached : light_node_importance(n, p, normal);
            return n.child;
        }
        float first = light_node_importance(light_node(node + 1u), p, normal);
        float second = light_node_importance(light_node(n.child), p, normal);
        if (!(first + second > 0.0)) {
            // No light below reaches p: a dead end (the estimate keeps what it passed by).
            if (mode != WALK_ESTIMATE) value = 0.0;
            return NO_EMITTER;
        }
        float p_first = first / (first + second);
        bool take_second = mode == WALK_SAMPLE ? u >= p_first : mode == WALK_TRAIL ? (trail & 1u) != 0u : second > first;
        if (mode == WALK_ESTIMATE) value += take_second ? first : second;
        if (take_second) {
            if (mode != WALK_ESTIMATE) value *= 1.0 - p_first;
            u = min((u - p_first) / (1.0 - p_first), 0.99999994);
            node = n.child;
        } else {
            if (mode != WALK_ESTIMATE) value *= p_first;
            u = min(u / p_first, 0.99999994);
            node = node + 1u;
        }
        reached = take_second ? second : first;
        trail >>= 1u;
    }
    // The tree is at most LIGHT_TREE_MAX_DEPTH deep: only the driver's loop budget ends here.
    note_loop_exit(depth <= LIGHT_TREE_MAX_DEPTH);
    value = 0.0;
    return NO_EMITTER;
}

// Probability of choosing the environment rather than another light.
float env_select_prob() { return scene_env.w; }

// A unit direction from its octahedral encoding (two 16-bit fixed-point coordinates).
// Twin: light_tree::octahedral_decode.
vec3 octahedral_decode(uint bits) {
    vec2 f = vec2(float(bits & 0xffffu), float(bits >> 16u)) * (2.0 / 65535.0) - 1.0;
    vec3 v = vec3(f, 1.0 - abs(f.x) - abs(f.y));
    float t = max(-v.z, 0.0);
    v.x += v.x >= 0.0 ? -t : t;
    v.y += v.y >= 0.0 ? -t : t;
    return normalize(v);
}

// What directional light `row` sends to a surface of normal `normal`, for choosing: E |cos θ|,
// the cosine floored at 1e-3 so that no light is ever left out (shading normals may tilt).
// Twin: light_tree::directional_weight.
float directional_weight(uint row, vec3 normal) {
    Emitter e = emitters[row];
    return e.intensity * max(abs(dot(normal, octahedral_decode(e.trail))), 1e-3);
}

// The directional lights' summed weights at a surface of normal `normal`.
float directional_total(vec3 normal) {
    float total = 0.0;
    for (uint i = emitter_count - directional_count(); i < emitter_count; i++) {
        loop_tick();
        total += directional_weight(i, normal);
    }
    return total;
}

// The probability of choosing the tree rather than a directional light at p (the environment's
// share aside): the tree's WALK_ESTIMATE against the directional lights' weights, so that a lamp
// where it outshines the sun is chosen as if the sun were not there, and the sun where it
// outshines the lamps. Directional lights are then chosen in proportion to their weights.
float tree_share(float estimate, float total) { return estimate > 0.0 ? estimate / (estimate + total) : 0.0; }

// Both functions below return (or take) an emitter row and its probability at p with normal
// `normal`, the environment's share removed (1 - env_select_prob()). One walk call in a loop of
// two passes keeps one copy of the walk in each.

// The probability that light sampling at p chooses the light of emitter row `row` (discrete).
// Twin: light_tree::light_select_pmf.
float light_select_pmf(vec3 p, vec3 normal, uint row) {
    uint n_dir = directional_count();
    bool has_tree = emitter_count > n_dir;
    bool in_tree = row < emitter_count - n_dir;
    float total = n_dir > 0u ? directional_total(normal) : 0.0;
    float share = has_tree ? 1.0 : 0.0;
    float walk = 1.0;
    // Pass 0 (beside directional lights only) weighs the tree; pass 1 follows the light's trail.
    for (uint pass = has_tree && n_dir > 0u ? 0u : 1u; pass < 2u; pass++) {
        if (pass == 1u && !in_tree) break;
        float value;
        light_tree_walk(p, normal, pass == 0u ? WALK_ESTIMATE : WALK_TRAIL, emitters[row].trail, 0.0, value);
        if (pass == 0u) share = tree_share(value, total);
        else walk = value;
    }
    float pmf = in_tree ? share * walk : (1.0 - share) * (directional_weight(row, normal) / total);
    return pmf * (1.0 - env_select_prob());
}

// The emitter row that light sampling at p draws with u in [0, 1) (NO_EMITTER when no light can
// reach p) and, in pmf, its probability as light_select_pmf gives it. Twin: light_tree::light_select.
uint light_select(vec3 p, vec3 normal, float u, out float pmf) {
    uint n_dir = directional_count();
    bool has_tree = emitter_count > n_dir;
    float total = n_dir > 0u ? directional_total(normal) : 0.0;
    float share = has_tree ? 1.0 : 0.0;
    uint row = NO_EMITTER;
    pmf = 0.0;
    // Pass 0 (beside directional lights only) weighs the tree; pass 1 draws from it.
    for (uint pass = has_tree && n_dir > 0u ? 0u : 1u; pass < 2u; pass++) {
        if (pass == 1u && !(u < share)) break;
        float value;
        uint r = light_tree_walk(p, normal, pass == 0u ? WALK_ESTIMATE : WALK_SAMPLE, 0u, min(u / share, 0.99999994), value);
        if (pass == 0u) {
            share = tree_share(value, total);
        } else {
            row = r;
            pmf = share * value;
        }
    }
    if (!(u < share) && n_dir > 0u) {
        // A directional light by weight: the first whose running sum passes the target.
        float target = (u - share) / (1.0 - share) * total;
        float sum = 0.0;
        row = emitter_count - 1u;
        for (uint i = emitter_count - n_dir; i < emitter_count; i++) {
            loop_tick();
            sum += directional_weight(i, normal);
            if (target < sum) {
                row = i;
                break;
            }
        }
        pmf = (1.0 - share) * (directional_weight(row, normal) / total);
    }
    pmf *= 1.0 - env_select_prob();
    return row;
}

#endif
