// Initial candidates of ReSTIR PT: one traced path from the pixel's primary hit offers every
// prefix that ends on a light, by NEE at a vertex or by a BSDF-sampled hit. A path either
// technique can make is offered by both, each weighted by the balance heuristic
// (end_mis_weight in shift.glsl): the two weighted integrands sum to the path's, and each is a
// function of the path that the shifts evaluate anew (the end type travels in the record). The
// paths are built with the steps generate_path() in shift.glsl regenerates them with
// (nee_vertex, bsdf_vertex).
#ifndef RESTIR_CANDIDATES_GLSL
#define RESTIR_CANDIDATES_GLSL

#include "restir_bindings.glsl"
#include "shift.glsl"

// Offers the path `q` with weight p̂(q) * `scale` (the candidate's unbiased contribution weight
// in primary sample space is 1; `scale` is the MIS weight 1/N among N traced paths).
void offer_candidate(inout Resampler s, Path q, ShiftParams params, float scale, float u) {
    PathRecord record;
    if (!record_path(q, params, record)) {
        local_candidates_dropped += 1u;
        return;
    }
    float target = target_function(record.contribution);
    float w = target * scale;
    if (!is_finite(w)) {
        local_nonfinite_weights += 1u;
        return;
    }
    if (w > 0.0) resampler_add(s, record, target, w, u);
}

// Streams every light-ending prefix of at most `max_length` vertices of the path from y1 with
// `seed` into `s`.
void stream_path_candidates(inout Resampler s, vec3 camera, Vertex y1, uint seed, uint max_length, ShiftParams params,
                            float scale) {
    Path p;
    path_begin(camera, y1, seed, false, p);
    vec3 prefix = vec3(1.0);
    vec3 prev_pos = camera;
    for (uint i = 1u; i < max_length; ++i) {
        loop_tick();
        Vertex x = p.vertices[i - 1u];
        if (vertex_is_escaped(x)) break;
        vec3 wo = normalize(prev_pos - x.pos);
        Material m = material_of(x);
        vec4 u = rng_uniform4(seed, i, STREAM_RESAMPLE);

        LightSample ls;
        Vertex light;
        if (nee_vertex(x, seed, i, ls, light)) {
            float bsdf_pdf;
            vec3 f_cos = bsdf_eval_pdf(m, x.normal, wo, ls.dir, bsdf_pdf);
            if (max_component(f_cos) > 0.0 && visible(x, light)) {
                Path q = p;
                q.count = i + 1u;
                q.nee_end = true;
                q.vertices[i] = light;
                q.lobes[i - 1u] = LOBE_NONE;
                q.weights[i - 1u] = f_cos / ls.pdf;
                q.end_weight = end_mis_weight(x, prev_pos, light, true, false);
                q.contribution = prefix * q.weights[i - 1u] * end_emission(x, light) * q.end_weight;
                if (max_component(q.contribution) > 0.0) offer_candidate(s, q, params, scale, u.x);
            }
        }

        BsdfSample b;
        Vertex next;
        if (!bsdf_vertex(x, wo, m, seed, i, b, next)) break;
        p.lobes[i - 1u] = b.lobe;
        p.weights[i - 1u] = b.weight;
        p.vertices[i] = next;
        p.count = i + 1u;
        prefix *= b.weight;
        vec3 emitted = end_emission(x, next);
        if (max_component(emitted) > 0.0) {
            Path q = p;
            q.end_weight = end_mis_weight(x, prev_pos, next, false, (b.lobe & LOBE_DELTA) != 0u);
            q.contribution = prefix * emitted * q.end_weight;
            if (max_component(q.contribution) > 0.0) offer_candidate(s, q, params, scale, u.y);
        }
        prev_pos = x.pos;
    }
}

#endif
