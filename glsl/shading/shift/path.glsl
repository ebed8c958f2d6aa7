// Paths regenerated in primary sample space from a primary hit and a seed (random replay's
// map, and the replayed prefix of the hybrid shift).
// Expects the scene bindings. Twin: crates/shading/src/shift/path.rs.
#ifndef SHIFT_PATH_GLSL
#define SHIFT_PATH_GLSL

#include "shading_core/path_record.glsl"
#include "shading_core/rng.glsl"
#include "shading/shift/result.glsl"
#include "shading/shift/vertex.glsl"

// A path x1..xk. Its vertices, lobes and weights are not members but the invocation's rows of
// the shared arrays below, so an invocation builds one path at a time: lavapipe turns every
// run-time index into a function-local array into a chain of selects over the whole array,
// and with the per-vertex arrays in Path the shift kernels took seconds longer to compile.
struct Path {
    uint seed;
    vec3 camera;
    uint count;                        // the number of vertices k
    bool nee_end;
    uint nee_directional;              // NEE's technique at the end: 0 the drawn light, k + 1 directional light k
    vec3 contribution;
    float end_weight;                  // end_mis_weight of the technique that made x_k
};

const uint PATH_INVOCATIONS = gl_WorkGroupSize.x * gl_WorkGroupSize.y * gl_WorkGroupSize.z;
shared Vertex path_vertices[PATH_INVOCATIONS * MAX_PATH_LENGTH];  // x1..xk
shared uint path_lobes[PATH_INVOCATIONS * MAX_PATH_LENGTH];       // the lobe sampled at x_i is [i - 1]
shared vec3 path_weights[PATH_INVOCATIONS * MAX_PATH_LENGTH];     // f_s |cos| / p at x_i is [i - 1]

uint path_row(uint i) { return gl_LocalInvocationIndex * MAX_PATH_LENGTH + i; }
Vertex path_vertex(uint i) { return path_vertices[path_row(i)]; }
uint path_lobe(uint i) { return path_lobes[path_row(i)]; }
vec3 path_weight(uint i) { return path_weights[path_row(i)]; }
void set_path_vertex(uint i, Vertex v) { path_vertices[path_row(i)] = v; }
void set_path_lobe(uint i, uint lobe) { path_lobes[path_row(i)] = lobe; }
void set_path_weight(uint i, vec3 w) { path_weights[path_row(i)] = w; }

// The first r >= 2 whose pair (x_{r-1}, x_r) is reconnectable; 0 if none.
uint reconnection_index(Path path, ShiftParams params) {
    for (uint r = 2u; r <= path.count; ++r) {
        loop_tick();
        if (is_reconnectable(path_vertex(r - 2u), path_vertex(r - 1u), params)) return r;
    }
    return 0u;
}

// The light point NEE at x_i takes with technique `directional`: directional light
// `directional` - 1, or for 0 the light it draws with the path's random numbers; false if none
// can be chosen. Visibility is left to the caller.
bool nee_vertex(Vertex x, uint seed, uint i, uint directional, out LightSample ls, out Vertex light) {
    ls = directional > 0u ? sample_directional(directional - 1u) : sample_light(x.pos, x.normal, rng_uniform4(seed, i, STREAM_LIGHT).xyz);
    if (!(ls.pdf > 0.0)) return false;
    if (SCENE_PUNCTUAL != 0 && is_punctual_light(ls.triangle)) {
        light = vertex_punctual(ls.triangle);
        return true;
    }
    light = ls.triangle == NO_EMITTER ? vertex_escaped(ls.dir) : vertex_on_surface(ls.triangle, x.pos + ls.dir * ls.dist);
    return true;
}

// The BSDF sample at x_i (material m, shading normal ns: vertex_shading) drawn with the path's
// random numbers and the origin of its ray, offset along the geometric normal; false if no lobe
// was sampled.
bool bsdf_ray(Vertex x, vec3 wo, Material m, vec3 ns, uint seed, uint i, out BsdfSample s, out vec3 origin) {
    s = bsdf_sample(m, x.normal, ns, wo, rng_uniform4(seed, i, STREAM_BSDF));
    if (s.lobe == LOBE_NONE) return false;
    origin = offset_ray_origin(x.pos, dot(s.wi, x.normal) > 0.0 ? x.normal : -x.normal, triangles[x.triangle]);
    return true;
}

// The vertex a ray in direction `dir` reaches: its hit, or the environment.
Vertex ray_end_vertex(Hit hit, vec3 dir) {
    return hit.triangle == NO_HIT ? vertex_escaped(dir) : hit_vertex(hit);
}

// The vertex BSDF sampling at x_i reaches with the path's random numbers; false if no lobe was
// sampled. Initial candidates and path regeneration share it, so that both build the same paths.
bool bsdf_vertex(Vertex x, vec3 wo, Material m, vec3 ns, uint seed, uint i, out BsdfSample s, out Vertex next) {
    vec3 origin;
    if (!bsdf_ray(x, wo, m, ns, seed, i, s, origin)) return false;
    next = ray_end_vertex(trace_closest(origin, s.wi, SHIFT_RAY_TMAX), s.wi);
    return true;
}

// A path of the single vertex x1 from `camera`, to be extended with `seed`'s random numbers.
void path_begin(vec3 camera, Vertex x1, uint seed, bool nee_end, uint nee_directional, out Path path) {
    path.seed = seed;
    path.camera = camera;
    path.count = 1u;
    path.nee_end = nee_end;
    path.nee_directional = nee_directional;
    set_path_vertex(0, x1);
    path.contribution = vec3(0.0);
    path.end_weight = 0.0;
}

// The vertices, lobes and weights of a path regenerated from x1 with `seed`, its end made by NEE
// with technique `nee_directional` (nee_vertex) when `nee_end`. Each step traces one ray, a
// shadow ray for the NEE step and a closest-hit ray otherwise, through a single traversal (see
// visibility_ray).
bool trace_vertices(vec3 camera, Vertex x1, uint seed, uint target_length, bool nee_end, uint nee_directional, out Path path) {
    path_begin(camera, x1, seed, nee_end, nee_directional, path);
    // A path's rows in shared memory hold MAX_PATH_LENGTH vertices; writing past them would
    // overwrite another invocation's path.
    if (target_length > MAX_PATH_LENGTH) return false;
    vec3 prev_pos = camera;
    while (path.count < target_length) {
        loop_tick();
        uint i = path.count;
        Vertex x = path_vertex(i - 1u);
        if (vertex_is_escaped(x)) return false;
        vec3 wo = normalize(prev_pos - x.pos);
        vec3 ns;
        Material m = vertex_shading(x, ns);
        bool nee_step = i + 1u == target_length && nee_end;
        Vertex next;
        uint lobe;
        vec3 weight;
        vec3 origin, dir;
        float tmax;
        if (nee_step) {
            LightSample ls;
            if (!nee_vertex(x, seed, i, nee_directional, ls, next)) return false;
            float bsdf_pdf;
            lobe = LOBE_NONE;
            weight = bsdf_eval_pdf(m, x.normal, ns, wo, ls.dir, bsdf_pdf) / ls.pdf;
            visibility_ray(x, next, origin, dir, tmax);
        } else {
            BsdfSample s;
            if (!bsdf_ray(x, wo, m, ns, seed, i, s, origin)) return false;
            lobe = s.lobe;
            weight = s.weight;
            dir = s.wi;
            tmax = SHIFT_RAY_TMAX;
        }
        Hit hit = bvh_traverse(origin, dir, tmax, nee_step);
        if (nee_step) {
            if (hit.triangle != NO_HIT) return false;
        } else {
            next = ray_end_vertex(hit, dir);
        }
        set_path_lobe(i - 1u, lobe);
        set_path_weight(i - 1u, weight);
        set_path_vertex(i, next);
        path.count += 1u;
        prev_pos = x.pos;
    }
    return true;
}

// The end weight and contribution of a path whose vertices trace_vertices made; false if it
// carries no light.
bool finish_path(inout Path path) {
    uint k = path.count;
    vec3 c = vec3(0.0);
    if (k >= 2u) {
        vec3 before = k >= 3u ? path_vertex(k - 3u).pos : path.camera;
        bool after_delta = (path_lobe(k - 2u) & LOBE_DELTA) != 0u;
        path.end_weight = end_mis_weight(path_vertex(k - 2u), before, path_vertex(k - 1u), path.nee_end, after_delta);
        c = end_emission(path_vertex(k - 2u), path_vertex(k - 1u)) * path.end_weight;
    }
    for (uint i = 0u; i + 1u < k; ++i) {
        loop_tick();
        c *= path_weight(i);
    }
    path.contribution = c;
    return max_component(c) > 0.0;
}

// A non-finite or non-positive Jacobian counts as a failed shift, never as a value.
ShiftResult shift_ok(PathRecord record, float jacobian, Path made) {
    bool finite = !isinf(jacobian) && !isnan(jacobian) && !any(isinf(record.contribution)) && !any(isnan(record.contribution));
    if (!finite || !(jacobian > 0.0)) return shift_failed();
    ShiftResult s;
    s.valid = true;
    s.record = record;
    s.jacobian = jacobian;
    s.contribution = record.contribution;
#ifdef SHIFT_ORACLE
    s.vertex_count = made.count;
    for (uint i = 0u; i < made.count; ++i) {
        loop_tick();
        s.vertices[i] = path_vertex(i).pos;
    }
#endif
    return s;
}

#endif
