// ReSTIR reservoirs: a path record, its unbiased contribution weight W and its confidence M.
// Stored as two 48-byte halves in separate bindings, so that a 1920x1080 frame needs 99.5 MB
// per binding, under lavapipe's 128 MiB limit (one 96-byte array would need 199 MB).
// Twins: ReservoirHead and ReservoirTail in crates/interface/src/gpu_types.rs (layout test).
#ifndef RESERVOIR_GLSL
#define RESERVOIR_GLSL

#include "shading_core/path_record.glsl"

struct Reservoir {
    PathRecord record;
    float W;
    float M;
};

// The target function p̂: luminance of the path contribution. Every channel has a positive
// weight, so p̂ > 0 wherever f is non-zero, as unbiased resampling requires.
float target_function(vec3 contribution) {
    return dot(contribution, vec3(0.2126, 0.7152, 0.0722));
}

Reservoir reservoir_empty() {
    PathRecord r = PathRecord(0u, 0u, 0u, 0xffffffffu, vec3(0.0), 0.0, vec3(0.0), 0.0, vec3(0.0), 0.0, vec3(0.0), 0xffffffffu);
    return Reservoir(r, 0.0, 0.0);
}

ReservoirHead reservoir_head(Reservoir r) {
    PathRecord p = r.record;
    return ReservoirHead(p.seed, p.info, p.lobes, p.rc_triangle, p.rc_pos, p.rc_pdf, p.rc_next, p.rc_geometry);
}

ReservoirTail reservoir_tail(Reservoir r) {
    PathRecord p = r.record;
    return ReservoirTail(p.suffix, p.rc_pdf_after, p.contribution, p.rc_next_triangle, r.W, r.M, 0u, 0u);
}

Reservoir reservoir_join(ReservoirHead h, ReservoirTail t) {
    PathRecord p = PathRecord(h.seed, h.info, h.lobes, h.rc_triangle, h.rc_pos, h.rc_pdf, h.rc_next, h.rc_geometry, t.suffix,
                              t.rc_pdf_after, t.contribution, t.rc_next_triangle);
    return Reservoir(p, t.weight, t.confidence);
}

// Resampling weights must be finite: a non-finite one is counted and dropped, never offered.
bool is_finite(float x) {
    return !isnan(x) && !isinf(x);
}

// Streaming weighted selection: after add() of candidates with weights w_i, `chosen` is candidate
// i with probability w_i / sum w and W = sum w / p̂(chosen).
// `expected` is the expectation of f(Y) W_Y over the choice, sum w_i f(y_i) / p̂(y_i): the
// pixel is shaded with it, which removes the choice's noise (chiefly colour noise, as p̂ is
// luminance) without bias. Twins: gris::Resampler, resampler_begin, resampler_offer and
// resampler_finish in crates/shading-core/src/gris.rs (`expected`: gris::resampled_expectation).
struct Resampler {
    PathRecord chosen;
    float chosen_target;
    float weight_sum;
    float confidence;
    vec3 expected;
    bool chosen_lost;   // the chosen candidate could not be recorded: the result is empty
};

Resampler resampler_begin() {
    return Resampler(reservoir_empty().record, 0.0, 0.0, 0.0, vec3(0.0), false);
}

// Adds a candidate of contribution f and target p̂ = `target` with weight `w` (finite, positive);
// true if it becomes the chosen one, which the caller then stores in `chosen`. `u` is uniform
// in [0, 1).
bool resampler_offer(inout Resampler s, vec3 contribution, float target, float w, float u) {
    s.weight_sum += w;
    s.expected += (w / target) * contribution;
    if (u * s.weight_sum >= w) return false;
    s.chosen_target = target;
    s.chosen_lost = false;
    return true;
}

void resampler_add(inout Resampler s, PathRecord y, float target, float w, float u) {
    if (resampler_offer(s, y.contribution, target, w, u)) s.chosen = y;
}

Reservoir resampler_finish(Resampler s) {
    float W = s.weight_sum > 0.0 && !s.chosen_lost ? s.weight_sum / s.chosen_target : 0.0;
    return Reservoir(s.chosen, W, s.confidence);
}

#endif
