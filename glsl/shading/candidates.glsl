// Initial candidates of ReSTIR PT: one traced path from the pixel's primary hit offers every
// prefix that ends on a light, by NEE at a vertex (the drawn light and every directional light,
// each a technique of its own) or by a BSDF-sampled hit. A path either
// technique can make is offered by both, each weighted by the balance heuristic
// (end_mis_weight in shading/shift/vertex.glsl): the two weighted integrands sum to the path's, and each is a
// function of the path that the shifts evaluate anew (the end type travels in the record). The
// paths are built with the steps trace_vertices() in shading/shift/path.glsl regenerates them with
// (nee_vertex, bsdf_vertex). Expects the scene bindings and the pass counters
// local_nonfinite_weights and local_candidates_dropped (interface/restir_bindings.glsl; an oracle kernel
// declares its own). Twin: crates/shading/src/candidates.rs.
#ifndef RESTIR_CANDIDATES_GLSL
#define RESTIR_CANDIDATES_GLSL

#include "shading_core/reservoir.glsl"
#include "shading/shift.glsl"

// A candidate of the path being traced, described against that path: its first `count`
// vertices, the last replaced by a NEE light vertex when `nee_end`. The path only grows, so
// the description stays valid until the path ends.
struct TracedCandidate {
    uint count;
    bool nee_end;
    uint nee_directional;
    Vertex light;
    vec3 nee_weight;
    float end_weight;
    vec3 contribution;
};

// Offers a candidate of contribution f with weight p̂(f) * `scale` (its unbiased contribution
// weight in primary sample space is 1; `scale` is the MIS weight 1/N among N traced paths);
// true if the resampler chose it.
bool offer_candidate(inout Resampler s, vec3 contribution, float scale, float u) {
    float target = target_function(contribution);
    float w = target * scale;
    if (!is_finite(w)) {
        local_nonfinite_weights += 1u;
        return false;
    }
    return w > 0.0 && resampler_offer(s, contribution, target, w, u);
}

// Records the chosen candidate `c` of the finished path `p` as the resampler's sample. Recording
// every candidate (record_path) took longer than tracing the path, so only the path's last
// choice is recorded. It recomputes the contribution from the vertices and cannot fail where the
// traced contribution was positive, except by rounding; such a loss is counted and empties the
// result.
void record_chosen(inout Resampler s, Path p, TracedCandidate c, ShiftParams params) {
    p.count = c.count;
    p.nee_end = c.nee_end;
    p.nee_directional = c.nee_directional;
    if (c.nee_end) {
        set_path_vertex(c.count - 1u, c.light);
        set_path_lobe(c.count - 2u, LOBE_NONE);
        set_path_weight(c.count - 2u, c.nee_weight);
    }
    p.end_weight = c.end_weight;
    p.contribution = c.contribution;
    PathRecord record;
    if (record_path(p, params, record)) {
        s.chosen = record;
    } else {
        local_candidates_dropped += 1u;
        s.chosen_lost = true;
    }
}

// Streams every light-ending prefix of at most `max_length` vertices of the path from y1 with
// `seed` into `s`. With `russian_roulette` the path goes on from x_i (i >= RR_START_DEPTH) with
// probability q = min(throughput / (product of the earlier q), RR_MAX_SURVIVAL), as the path
// tracer's. Only the initial sampling uses it (Lin, Kettunen and Wyman 2026, "ReSTIR PT
// Enhanced"): a later candidate's source pdf carries the product of the q, so its resampling
// weight is divided by that product, while its contribution, the target function's argument
// that the shifts and MIS weights evaluate, stays the path's own. The roulette draws
// STREAM_RESAMPLE's z at x_i, which nothing else uses.
void stream_path_candidates(inout Resampler s, vec3 camera, Vertex y1, uint seed, uint max_length, ShiftParams params,
                            float scale, bool russian_roulette) {
    Path p;
    path_begin(camera, y1, seed, false, 0u, p);
    vec3 prefix = vec3(1.0);
    vec3 prev_pos = camera;
    TracedCandidate chosen;
    bool chose = false;
    // 1 / the product of the survival probabilities so far.
    float roulette = 1.0;
    for (uint i = 1u; i < max_length; ++i) {
        loop_tick();
        Vertex x = path_vertex(i - 1u);
        if (vertex_is_escaped(x)) break;
        vec4 u = rng_uniform4(seed, i, STREAM_RESAMPLE);
        if (russian_roulette && i >= RR_START_DEPTH) {
            float survive = min(max_component(prefix) * roulette, RR_MAX_SURVIVAL);
            if (u.z >= survive) break;
            roulette /= survive;
        }
        vec3 wo = normalize(prev_pos - x.pos);
        vec3 ns;
        Material m = vertex_shading(x, ns);

        // NEE's techniques at x: the drawn light (t = 0), then every directional light (t = k + 1),
        // each a candidate of its own, in one loop so that the kernel holds one visibility test.
        uint techniques = 1u + (SCENE_PUNCTUAL != 0 && SCENE_DIRECTIONAL != 0 ? directional_count() : 0u);
        for (uint t = 0u; t < techniques; ++t) {
            loop_tick();
            LightSample ls;
            Vertex light;
            if (!nee_vertex(x, seed, i, t, ls, light)) continue;
            float bsdf_pdf;
            vec3 f_cos = bsdf_eval_pdf(m, x.normal, ns, wo, ls.dir, bsdf_pdf);
            if (!(max_component(f_cos) > 0.0) || !visible(x, light)) continue;
            vec3 weight = f_cos / ls.pdf;
            // end_mis_weight(x, prev_pos, light, true, false) from the pdfs at hand (equal
            // to rounding): evaluating the BSDF again took 5% of the pass.
            float end_weight = vertex_is_punctual(light) ? 1.0 : balance_heuristic(ls.pdf, bsdf_pdf);
            vec3 contribution = prefix * weight * end_emission(x, light) * end_weight;
            float u_offer = t == 0u ? u.x : rng_uniform4(seed, i, STREAM_DIRECTIONAL + t - 1u).x;
            if (max_component(contribution) > 0.0 && offer_candidate(s, contribution, scale * roulette, u_offer)) {
                chosen = TracedCandidate(i + 1u, true, t, light, weight, end_weight, contribution);
                chose = true;
            }
        }

        BsdfSample b;
        Vertex next;
        if (!bsdf_vertex(x, wo, m, ns, seed, i, b, next)) break;
        set_path_lobe(i - 1u, b.lobe);
        set_path_weight(i - 1u, b.weight);
        set_path_vertex(i, next);
        p.count = i + 1u;
        prefix *= b.weight;
        vec3 emitted = end_emission(x, next);
        if (max_component(emitted) > 0.0) {
            float end_weight = end_mis_weight(x, prev_pos, next, false, (b.lobe & LOBE_DELTA) != 0u);
            vec3 contribution = prefix * emitted * end_weight;
            if (max_component(contribution) > 0.0 && offer_candidate(s, contribution, scale * roulette, u.y)) {
                chosen = TracedCandidate(i + 1u, false, 0u, next, vec3(0.0), end_weight, contribution);
                chose = true;
            }
        }
        prev_pos = x.pos;
    }
    if (chose) record_chosen(s, p, chosen, params);
}

#endif
