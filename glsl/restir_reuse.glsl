// GRIS across pixels and frames (docs/restir.md): the domains of ReSTIR PT's reservoirs (a pixel
// seen from a frame's camera) and the shifts between them, the bridge on which the reuse loop
// (shading/resample_inputs.glsl) runs: input_reservoir, input_domain, same_domain and shift_path.
// SHIFT_MODE and MIS_MODE select the shift and the MIS at compile time.
#ifndef RESTIR_REUSE_GLSL
#define RESTIR_REUSE_GLSL

// Every traversal of a reuse kernel belongs to a shift; counting them gives rays per shift.
#define COUNT_TRAVERSALS 1

#include "interface/restir_bindings.glsl"
#include "scene/camera.glsl"
#include "shading_core/gris.glsl"
#include "shading/shift.glsl"

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
// confidence weight c is `confidences` (shading_core/gris.glsl) at the same index. The reservoir stays in its
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
    return CameraPose(temporal.prev_cam_position, temporal.prev_cam_right, temporal.prev_cam_up, temporal.prev_cam_forward);
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

Domain input_domain(uint i) {
    return inputs[i].domain;
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
    return s;
}

// The reuse loop, on the bridge above.
#include "shading/resample_inputs.glsl"

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
