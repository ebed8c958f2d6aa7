// The reuse loop of GRIS (docs/restir.md): inputs from other domains are shifted into the
// canonical domain, weighted by resampling MIS weights (shading_core/gris.glsl) computed with inverse shifts,
// and one is chosen by the streaming resampler (shading_core/reservoir.glsl). Twin: resample_inputs in
// crates/shading/src/resample_inputs.rs, whose test runs both on the toy domains of the GRIS tests.
//
// It runs on a bridge the including file defines first, as RTXDI's resampling functions run on
// its RAB_* functions: the renderer's (restir_reuse.glsl) on pixels, frames and path shifts, the
// oracle's (oracle/reuse_oracle.comp) on analytic one-dimensional domains.
//   struct Domain                                 where a sample lives
//   Reservoir input_reservoir(uint i)             input i's reservoir
//   Domain input_domain(uint i)                   input i's domain (0: the canonical one)
//   bool same_domain(Domain a, Domain b)          whether a shift between a and b is the identity
//   ShiftResult shift_path(PathRecord x, Domain to)  x shifted into `to`, its Jacobian and f
//   uint local_shifts_failed, local_nonfinite_weights   the counters the loop adds to: shifts
//                                                 that failed or gave a non-finite weight
#ifndef RESAMPLE_INPUTS_GLSL
#define RESAMPLE_INPUTS_GLSL

#include "shading_core/gris.glsl"
#include "shading_core/reservoir.glsl"
#include "shading_core/rng.glsl"
#include "shading/shift/result.glsl"

// Resamples inputs 0..n-1 (0: the canonical pixel's own reservoir), whose confidence weights
// c_l the caller has put in `confidences` (shading_core/gris.glsl), into one reservoir of the canonical
// domain; `seed` keys the choice. `expected` receives E[f(Y) W_Y] over the choice.
//
// Step (i, l) of the n x n steps makes at most one shift: for l = 0 the shift of input i's
// sample into the canonical domain, y_i = T_i(X_i); for l >= 1 (l != i) the inverse shift of y_i
// into domain l, for p̂_{<-l}(y_i). Every shift goes through the one call below: a kernel
// inlines each call site whole, and llvmpipe's compile time grows with the copies
// (docs/lab-notebook.md, "Compile time of the reuse kernels").
Reservoir resample_inputs(uint n, uint seed, out vec3 expected) {
    Resampler s = resampler_begin();
    PathRecord y = reservoir_empty().record;
    float W = 0.0;
    float own_target = 0.0;
    float jacobian = 1.0;
    bool alive = false;
    for (uint step = 0u; step < n * n; ++step) {
        loop_tick();
        uint i = step / n;
        uint l = step % n;
        bool forward = l == 0u;
        if (forward) {
            s.confidence += confidences[i];
            // An empty reservoir offers no sample, but its domain still counts in the MIS weights.
            Reservoir res = input_reservoir(i);
            W = res.W;
            own_target = target_function(res.record.contribution);
            alive = W > 0.0;
            y = res.record;
            jacobian = 1.0;
        }
        Domain from = forward ? input_domain(i) : input_domain(0u);
        Domain to = forward ? input_domain(0u) : input_domain(l);
        bool wanted = forward || (l != i && needs_targets_from(i));
        bool shift = alive && wanted && !same_domain(from, to);
        ShiftResult shifted = shift_failed();
        if (shift) {
            shifted = shift_path(y, to);
            if (!shifted.valid) local_shifts_failed += 1u;
        }
        if (forward) {
            if (shift && shifted.valid) {
                y = shifted.record;
                jacobian = shifted.jacobian;
            }
            alive = alive && (!shift || shifted.valid);
            float p0 = target_function(y.contribution);
            targets_from[0] = p0;
            // For input i itself the inverse shift returns its own sample, whose p̂ it carries.
            if (i != 0u) targets_from[i] = own_target / jacobian;
        } else if (alive && wanted) {
            float t = target_function(y.contribution);
            if (shift) {
                t = shifted.valid ? target_function(shifted.contribution) * shifted.jacobian : 0.0;
                // A non-finite value counts as a failed shift.
                if (!is_finite(t)) {
                    local_nonfinite_weights += 1u;
                    local_shifts_failed += 1u;
                    t = 0.0;
                }
            }
            targets_from[l] = t;
        }
        if (l + 1u == n && alive) {
            float p0 = targets_from[0];
            float w = mis_weight(n, i) * p0 * W * jacobian;
            if (!is_finite(w)) {
                local_nonfinite_weights += 1u;
                if (!same_domain(input_domain(i), input_domain(0u))) local_shifts_failed += 1u;
            } else if (w > 0.0) {
                resampler_add(s, y, p0, w, rng_uniform4(seed, i, STREAM_RESAMPLE).x);
            }
        }
    }
    expected = s.expected;
    return resampler_finish(s);
}

#endif
