// GRIS across pixels and frames (docs/restir.md): inputs from other domains are shifted into the
// canonical pixel's domain, weighted by resampling MIS weights (gris.glsl) computed with inverse
// shifts, and one is chosen by the streaming resampler (reservoir.glsl). The estimator is
// crates/shading-core/src/gris.rs's, whose toy test checks it; SHIFT_MODE and MIS_MODE select the shift and the MIS
// at compile time.
#ifndef RESTIR_REUSE_GLSL
#define RESTIR_REUSE_GLSL

// Every traversal of a reuse kernel belongs to a shift; counting them gives rays per shift.
#define COUNT_TRAVERSALS 1

#include "restir_bindings.glsl"
#include "camera.glsl"
#include "gris.glsl"
#include "shift.glsl"

#ifndef SHIFT_MODE
#define SHIFT_MODE SHIFT_HYBRID
#endif

// The domain of a reservoir: one pixel's paths seen from one frame's camera, the sub-pixel
// position included. A path carries its own position (the camera stream of its seed), so a
// shift keeps it and traces the target pixel's primary ray through it. Between two frames of a
// static camera the domain of a pixel does not change and its paths are reused unshifted; with
// the primary hit as the domain, the hit moved with every frame's jitter, and the reconnection
// Jacobians of those moves multiplied along the temporal chain.
struct Domain {
    uvec2 pixel;
    bool previous;   // seen from the previous frame's camera
};

// One input of a resampling: the reservoir at `index` of reservoir slot `slot`, of `domain`; its
// confidence weight c is `confidences` (gris.glsl) at the same index. The reservoir stays in its
// buffer until it is resampled: lavapipe turns a run-time index into a local array into selects
// over every element, so an array of whole reservoirs cost more compile and run time than the
// loads.
struct ReuseInput {
    uint slot;
    uint index;
    Domain domain;
};

// The inputs of the current resampling, 0 the canonical one. A global rather than a parameter:
// glslang's optimiser mistypes arrays of these structs passed by value.
ReuseInput inputs[MAX_INPUTS];

Reservoir input_reservoir(uint i) {
    return load_reservoir(inputs[i].slot, inputs[i].index);
}

CameraPose previous_camera() {
    return CameraPose(prev_cam_position, prev_cam_right, prev_cam_up, prev_cam_forward);
}

CameraPose domain_camera(Domain d) {
    return d.previous ? previous_camera() : frame_camera();
}

bool same_pose(CameraPose a, CameraPose b) {
    return a.position == b.position && a.right == b.right && a.up == b.up && a.forward == b.forward;
}

// A kernel compiled with CANONICAL_DOMAIN_ONLY resamples inputs of the canonical domain alone
// (temporal reuse under an unmoved camera), so the shift code drops out of it: llvmpipe spent
// about 3.5 ms per 64x64 dispatch on that code where no shift ran.
bool same_domain(Domain a, Domain b) {
#ifdef CANONICAL_DOMAIN_ONLY
    return true;
#else
    if (a.pixel != b.pixel) return false;
    return a.previous == b.previous || same_pose(previous_camera(), frame_camera());
#endif
}

// The primary vertex of `record`'s path in domain `d`: the hit of d's camera ray through the
// record's sub-pixel position; false if that ray escapes.
bool domain_primary(Domain d, PathRecord record, out vec3 camera, out Vertex y1) {
    CameraPose pose = domain_camera(d);
    vec2 offset = rng_uniform4(record.seed, 0u, STREAM_CAMERA).xy;
    camera = pose.position.xyz;
    vec3 dir = pose_ray_dir(pose, float(d.pixel.x) + offset.x, float(d.pixel.y) + offset.y);
    Hit hit = trace_closest(camera, dir, SHIFT_RAY_TMAX);
    if (hit.triangle == NO_HIT) return false;
    y1 = hit_vertex(hit);
    return true;
}

ShiftParams reuse_shift_params() {
    return ShiftParams(roughness_threshold, distance_threshold);
}

// The selected shift of `record` into domain `to`, as an inverse shift. For the MIS weights'
// p̂_{<-l}(y), T_l^{-1} carries a sample y of the canonical domain back into input l's domain
// `to`. The forward shift T_i of input i's sample x_i into the canonical domain `to` is the
// inverse of T_i^{-1}, the shift out of the canonical domain into domain i, evaluated at x_i:
// inverse_* of x_i's record with the canonical domain's primary vertex. So every shift of a
// resampling is this one call of inverse_*: a kernel inlines each call site whole, and a second
// call site for the forward shifts (shift_*) made the temporal and spatial kernels' SPIR-V 45%
// larger and their llvmpipe compile 2.5 times slower (docs/lab-notebook.md, "Compile time of
// the reuse kernels"). Within one domain the shift is the identity, which callers skip.
ShiftResult shift_path(PathRecord record, Domain to) {
    local_shifts_attempted += 1u;
    // The subgroup runs this code once for all its lanes that shift here: lanes busy in shifts
    // are shifts_attempted / (shift_subgroup_runs * subgroup_size).
    if (subgroupElect()) local_shift_runs += 1u;
    vec3 camera;
    Vertex v1;
    ShiftResult s = shift_failed();
    if (domain_primary(to, record, camera, v1)) {
#if SHIFT_MODE == SHIFT_RECONNECTION
        s = inverse_reconnection(reuse_shift_params(), record, camera, v1);
#elif SHIFT_MODE == SHIFT_REPLAY
        s = inverse_random_replay(reuse_shift_params(), record, camera, v1);
#else
        s = inverse_hybrid(reuse_shift_params(), record, camera, v1);
#endif
    }
    if (!s.valid) local_shifts_failed += 1u;
    return s;
}

// Resamples inputs[0..n-1] (0: the canonical pixel's own reservoir) into one reservoir of the
// canonical domain; `seed` keys the choice. `expected` receives E[f(Y) W_Y] over the choice.
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
        Domain from = forward ? inputs[i].domain : inputs[0].domain;
        Domain to = forward ? inputs[0].domain : inputs[l].domain;
        bool wanted = forward || (l != i && needs_targets_from(i));
        bool shift = alive && wanted && !same_domain(from, to);
        ShiftResult shifted = shift_failed();
        if (shift) shifted = shift_path(y, to);
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
                if (!same_domain(inputs[i].domain, inputs[0].domain)) local_shifts_failed += 1u;
            } else if (w > 0.0) {
                resampler_add(s, y, p0, w, rng_uniform4(seed, i, STREAM_RESAMPLE).x);
            }
        }
    }
    expected = s.expected;
    return resampler_finish(s);
}

// Whether a neighbour's primary hit is similar enough to the canonical one to be reused: both
// hit a surface, normals agree, and the neighbour's depth agrees with the canonical point's
// distance from the neighbour's camera.
bool similar_surfaces(Surface canonical, Surface other) {
    if (canonical.triangle == NO_HIT || other.triangle == NO_HIT) return false;
    vec3 n0 = vertex_on_surface(canonical.triangle, canonical.pos).normal;
    vec3 n1 = vertex_on_surface(other.triangle, other.pos).normal;
    float expected = length(canonical.pos - other.camera);
    return abs(dot(n0, n1)) >= normal_threshold && abs(other.depth - expected) <= depth_threshold * other.depth;
}

#endif
