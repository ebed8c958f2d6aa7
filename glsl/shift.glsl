// Shift mappings of ReSTIR PT in primary sample space: random replay, reconnection and hybrid,
// with their inverses, on path records. Expects the scene bindings. Twin: src/shading/shift.rs, where
// the measure, the contribution and the Jacobians are described; docs/shift-mappings.md.
#ifndef SHIFT_GLSL
#define SHIFT_GLSL

#include "bsdf.glsl"
#include "bvh.glsl"
#include "lights.glsl"
#include "path_record.glsl"
#include "punctual.glsl"
#include "rng.glsl"

const float SHIFT_RAY_TMAX = 1e30;

struct ShiftParams {
    float roughness_threshold;
    float distance_threshold;
};

// A surface point, or (triangle == NO_HIT) a direction to the environment, or (a punctual light
// id, only as a path's last vertex) a punctual light's position, or for a directional light the
// direction towards it.
struct Vertex {
    vec3 pos;
    vec3 normal;
    uint triangle;
};

// A path x1..xk. Its vertices, lobes and weights are not members but the invocation's rows of
// the shared arrays below, so an invocation builds one path at a time: lavapipe turns every
// run-time index into a function-local array into a chain of selects over the whole array,
// and with the per-vertex arrays in Path the shift kernels took seconds longer to compile.
struct Path {
    uint seed;
    vec3 camera;
    uint count;                        // the number of vertices k
    bool nee_end;
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

struct ShiftResult {
    bool valid;
    PathRecord record;
    float jacobian;
    vec3 contribution;
#ifdef SHIFT_ORACLE
    // The vertices the shift made (see src/shading/shift.rs), which only the oracle test compares:
    // production kernels would copy them on every shift.
    uint vertex_count;
    vec3 vertices[MAX_PATH_LENGTH];
#endif
};

bool vertex_is_escaped(Vertex v) { return v.triangle == NO_HIT; }

bool vertex_is_punctual(Vertex v) { return SCENE_PUNCTUAL != 0 && is_punctual_light(v.triangle); }

uint vertex_light(Vertex v) { return v.triangle & ~PUNCTUAL_LIGHT_BIT; }

// Escaped, or on a directional light: `pos` is a direction and the vertex is infinitely far.
bool vertex_is_at_infinity(Vertex v) {
    return vertex_is_escaped(v) || (vertex_is_punctual(v) && punctual_light(vertex_light(v)).kind == PUNCTUAL_DIRECTIONAL);
}

// Punctual light `id` as a path vertex: its position, or the direction towards a directional one.
Vertex vertex_punctual(uint id) {
    PunctualLight l = punctual_light(id & ~PUNCTUAL_LIGHT_BIT);
    return Vertex(l.kind == PUNCTUAL_DIRECTIONAL ? -l.direction : l.position, vec3(0.0), id);
}

Vertex vertex_on_surface(uint triangle, vec3 pos) {
    Triangle t = triangles[triangle];
    return Vertex(pos, normalize(cross(t.e1, t.e2)), triangle);
}

Vertex vertex_escaped(vec3 dir) { return Vertex(dir, vec3(0.0), NO_HIT); }

Material material_of(Vertex v) { return materials[triangles[v.triangle].material]; }

bool vertex_is_rough(Vertex v, ShiftParams params) {
    if (vertex_is_escaped(v) || vertex_is_punctual(v)) return true;
    Material m = material_of(v);
    float w_d, w_c, w_t;
    lobe_weights(m, w_d, w_c, w_t);
    // A non-metal's specular layer is a GGX lobe too.
    if (w_d > 0.0 && m.specular > 0.0) w_c = 1.0;
    bool rough_ggx = m.roughness >= params.roughness_threshold && m.roughness * m.roughness >= DELTA_ALPHA;
    return (w_c <= 0.0 || rough_ggx) && (w_t <= 0.0 || (rough_ggx && !index_matched(m.ior)));
}

bool is_reconnectable(Vertex prev, Vertex cur, ShiftParams params) {
    bool far = vertex_is_at_infinity(cur) || length(prev.pos - cur.pos) >= params.distance_threshold;
    return !vertex_is_escaped(prev) && far && vertex_is_rough(prev, params) && vertex_is_rough(cur, params);
}

// The first r >= 2 whose pair (x_{r-1}, x_r) is reconnectable; 0 if none.
uint reconnection_index(Path path, ShiftParams params) {
    for (uint r = 2u; r <= path.count; ++r) {
        loop_tick();
        if (is_reconnectable(path_vertex(r - 2u), path_vertex(r - 1u), params)) return r;
    }
    return 0u;
}

void direction(Vertex from, Vertex to, out vec3 dir, out float dist) {
    if (vertex_is_at_infinity(to)) {
        dir = to.pos;
        dist = 1.0 / 0.0;
    } else {
        vec3 d = to.pos - from.pos;
        dist = length(d);
        dir = d / dist;
    }
}

// The shadow ray between two vertices: a segment between surface points, a ray to a punctual
// light, or a ray towards an escaped vertex's direction. One ray for every case keeps one
// traversal per call site: every call inlines a whole traversal, and llvmpipe's compile time
// grows with the copies.
void visibility_ray(Vertex from, Vertex to, out vec3 origin, out vec3 dir, out float tmax) {
    if (vertex_is_punctual(to)) {
        vec3 to_light;
        float dist;
        direction(from, to, to_light, dist);
        punctual_ray(from.pos, from.normal, from.triangle, to_light, dist, origin, dir, tmax);
    } else if (!vertex_is_escaped(to)) {
        segment_ray(from.pos, from.normal, from.triangle, to.pos, to.normal, to.triangle, origin, dir, tmax);
    } else {
        origin = offset_ray_origin(from.pos, dot(to.pos, from.normal) > 0.0 ? from.normal : -from.normal, triangles[from.triangle]);
        dir = to.pos;
        tmax = SHIFT_RAY_TMAX;
    }
}

bool visible(Vertex from, Vertex to) {
    vec3 origin, dir;
    float tmax;
    visibility_ray(from, to, origin, dir, tmax);
    return !trace_occluded(origin, dir, tmax);
}

vec3 end_emission(Vertex from, Vertex end) {
    if (vertex_is_escaped(end)) return environment_radiance(end.pos);
    if (vertex_is_punctual(end)) {
        vec3 dir, value;
        float dist;
        punctual_arrival(punctual_light(vertex_light(end)), from.pos, dir, dist, value);
        return value;
    }
    Triangle tri = triangles[end.triangle];
    if (tri.emitter == NO_EMITTER) return vec3(0.0);
    return emitted_radiance(tri, normalize(from.pos - end.pos));
}

// For a punctual light: the discrete probability of choosing it (whose ratio between two paths
// to the same light is 1, as its geometry term is).
float light_pdf(Vertex from, Vertex end) {
    if (vertex_is_punctual(end)) return punctual_pdf(vertex_light(end));
    vec3 dir;
    float dist;
    direction(from, end, dir, dist);
    return vertex_is_escaped(end) ? environment_pdf(dir) : emitter_pdf(end.triangle, dir, dist);
}

// Balance-heuristic weight of the technique that ended a path at `end` from `x` (reached from
// `before`): NEE (`nee_end`) or BSDF sampling. Both are evaluated from the vertices, so a shifted
// path gets its own weight. After a delta lobe only BSDF sampling reaches the end: weight 1.
// A punctual light is reached by NEE alone: weight 1 (BSDF sampling never ends on one).
float end_mis_weight(Vertex x, vec3 before, Vertex end, bool nee_end, bool after_delta) {
    if (vertex_is_punctual(end)) return nee_end ? 1.0 : 0.0;
    if (after_delta) return nee_end ? 0.0 : 1.0;
    vec3 dir;
    float dist;
    direction(x, end, dir, dist);
    float bsdf_pdf;
    bsdf_eval_pdf(material_of(x), x.normal, x.normal, normalize(before - x.pos), dir, bsdf_pdf);
    float light = light_pdf(x, end);
    return nee_end ? balance_heuristic(light, bsdf_pdf) : balance_heuristic(bsdf_pdf, light);
}

Vertex hit_vertex(Hit hit) {
    Triangle t = triangles[hit.triangle];
    return vertex_on_surface(hit.triangle, t.v0 + hit.bary.x * t.e1 + hit.bary.y * t.e2);
}

// The light point NEE at x_i chooses with the path's random numbers; false if none can be chosen.
// Visibility is left to the caller.
bool nee_vertex(Vertex x, uint seed, uint i, out LightSample ls, out Vertex light) {
    ls = sample_light(x.pos, rng_uniform4(seed, i, STREAM_LIGHT).xyz);
    if (!(ls.pdf > 0.0)) return false;
    if (SCENE_PUNCTUAL != 0 && is_punctual_light(ls.triangle)) {
        light = vertex_punctual(ls.triangle);
        return true;
    }
    light = ls.triangle == NO_EMITTER ? vertex_escaped(ls.dir) : vertex_on_surface(ls.triangle, x.pos + ls.dir * ls.dist);
    return true;
}

// The BSDF sample at x_i drawn with the path's random numbers and the origin of its ray; false
// if no lobe was sampled.
bool bsdf_ray(Vertex x, vec3 wo, Material m, uint seed, uint i, out BsdfSample s, out vec3 origin) {
    s = bsdf_sample(m, x.normal, x.normal, wo, rng_uniform4(seed, i, STREAM_BSDF));
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
bool bsdf_vertex(Vertex x, vec3 wo, Material m, uint seed, uint i, out BsdfSample s, out Vertex next) {
    vec3 origin;
    if (!bsdf_ray(x, wo, m, seed, i, s, origin)) return false;
    next = ray_end_vertex(trace_closest(origin, s.wi, SHIFT_RAY_TMAX), s.wi);
    return true;
}

// A path of the single vertex x1 from `camera`, to be extended with `seed`'s random numbers.
void path_begin(vec3 camera, Vertex x1, uint seed, bool nee_end, out Path path) {
    path.seed = seed;
    path.camera = camera;
    path.count = 1u;
    path.nee_end = nee_end;
    set_path_vertex(0, x1);
    path.contribution = vec3(0.0);
    path.end_weight = 0.0;
}

// The vertices, lobes and weights of a path regenerated from x1 with `seed`. Each step traces
// one ray, a shadow ray for the NEE step and a closest-hit ray otherwise, through a single
// traversal (see visibility_ray).
bool trace_vertices(vec3 camera, Vertex x1, uint seed, uint target_length, bool nee_end, out Path path) {
    path_begin(camera, x1, seed, nee_end, path);
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
        Material m = material_of(x);
        bool nee_step = i + 1u == target_length && nee_end;
        Vertex next;
        uint lobe;
        vec3 weight;
        vec3 origin, dir;
        float tmax;
        if (nee_step) {
            LightSample ls;
            if (!nee_vertex(x, seed, i, ls, next)) return false;
            float bsdf_pdf;
            lobe = LOBE_NONE;
            weight = bsdf_eval_pdf(m, x.normal, x.normal, wo, ls.dir, bsdf_pdf) / ls.pdf;
            visibility_ray(x, next, origin, dir, tmax);
        } else {
            BsdfSample s;
            if (!bsdf_ray(x, wo, m, seed, i, s, origin)) return false;
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

struct Link {
    vec3 dir;
    vec3 f_cos;
    float pdf;
    float geometry;
};

Link reconnection_link(Vertex prev, vec3 before, Vertex x_r, bool nee_at_r) {
    Link link;
    float dist;
    direction(prev, x_r, link.dir, dist);
    float bsdf_pdf;
    link.f_cos = bsdf_eval_pdf(material_of(prev), prev.normal, prev.normal, normalize(before - prev.pos), link.dir, bsdf_pdf);
    link.pdf = nee_at_r ? light_pdf(prev, x_r) : bsdf_pdf;
    // A punctual x_r is one fixed point (or direction) whichever predecessor joins it: no
    // solid-angle-to-area factor, so its part of the Jacobian is 1.
    link.geometry = vertex_is_escaped(x_r) || vertex_is_punctual(x_r) ? 1.0 : abs(dot(x_r.normal, link.dir)) / (dist * dist);
    return link;
}

float pdf_after(Vertex x_r, vec3 dir_in, Vertex next, bool next_is_nee, out vec3 f_cos) {
    vec3 dir_next;
    float dist;
    direction(x_r, next, dir_next, dist);
    float pdf;
    f_cos = bsdf_eval_pdf(material_of(x_r), x_r.normal, x_r.normal, -dir_in, dir_next, pdf);
    return next_is_nee ? light_pdf(x_r, next) : pdf;
}

Vertex record_vertex(uint triangle, vec3 pos) {
    if (SCENE_PUNCTUAL != 0 && is_punctual_light(triangle)) return vertex_punctual(triangle);
    return triangle == NO_HIT ? vertex_escaped(pos) : vertex_on_surface(triangle, pos);
}

// Joins `prev` (reached from `before`, prefix weight `prefix_weight`) to the record's x_r.
bool join_at_reconnection(PathRecord base, Vertex prev, vec3 before, Vertex x_r, vec3 prefix_weight,
                          out PathRecord record, out bool has_pdf_after, out float pdf_after_x_r) {
    uint k = record_length(base);
    uint r = record_reconnection_index(base);
    record = base;
    has_pdf_after = false;
    pdf_after_x_r = 1.0;
    if (r == 0u) return false;
    Link link = reconnection_link(prev, before, x_r, r == k && record_nee_end(base));
    if (!(link.pdf > 0.0) || max_component(link.f_cos) <= 0.0) return false;
    record.rc_pdf = link.pdf;
    record.rc_geometry = link.geometry;
    record.rc_pdf_after = 1.0;
    vec3 contribution = prefix_weight * link.f_cos / link.pdf;
    // The end's MIS weight is evaluated anew where the join changes it: at x_r when x_r ends the
    // path, at the next vertex when x_r is the last scattering vertex (its incoming direction
    // changed); otherwise the suffix holds it. One call for both keeps one copy of the BSDF
    // evaluation in the kernel.
    Vertex mis_from = prev;
    vec3 mis_before = before;
    Vertex mis_end = x_r;
    bool mis_after_delta = false;
    bool needs_mis = true;
    if (r == k) {
        mis_after_delta = (record_lobe(base, k - 1u) & LOBE_DELTA) != 0u;
        contribution *= end_emission(prev, x_r);
    } else {
        Vertex x_next = record_vertex(base.rc_next_triangle, base.rc_next);
        bool next_is_nee = r + 1u == k && record_nee_end(base);
        vec3 f_r;
        float q = pdf_after(x_r, link.dir, x_next, next_is_nee, f_r);
        if (!(q > 0.0) || max_component(f_r) <= 0.0 || (record_lobe(base, r) & LOBE_DELTA) != 0u) return false;
        if (!next_is_nee) {
            record.rc_pdf_after = q;
            has_pdf_after = true;
            pdf_after_x_r = q;
        }
        contribution = contribution * f_r / q * base.suffix;
        needs_mis = r + 1u == k;
        mis_from = x_r;
        mis_before = prev.pos;
        mis_end = x_next;
    }
    if (needs_mis) contribution *= end_mis_weight(mis_from, mis_before, mis_end, record_nee_end(base), mis_after_delta);
    if (!(max_component(contribution) > 0.0)) return false;
    record.contribution = contribution;
    return true;
}

// The record of `path` without its reconnection's join (see record_path); returns the
// reconnection index r (0: none), or MAX_PATH_LENGTH + 1 if the path is too long for a record.
uint record_fields(Path path, ShiftParams params, out PathRecord record) {
    uint k = path.count;
    uint r = reconnection_index(path, params);
    record.seed = path.seed;
    record.info = pack_info(k, r, path.nee_end);
    record.lobes = 0u;
    for (uint i = 0u; i + 1u < k; ++i) {
        loop_tick();
        record.lobes |= path_lobe(i) << (LOBE_BITS * i);
    }
    record.rc_triangle = NO_HIT;
    record.rc_pos = vec3(0.0);
    record.rc_pdf = 1.0;
    record.rc_next = vec3(0.0);
    record.rc_geometry = 1.0;
    record.suffix = vec3(1.0);
    record.rc_pdf_after = 1.0;
    record.contribution = path.contribution;
    record.rc_next_triangle = NO_HIT;
    if (k > MAX_PATH_LENGTH) return MAX_PATH_LENGTH + 1u;
    if (r == 0u) return 0u;
    Vertex x_r = path_vertex(r - 1u);
    record.rc_triangle = x_r.triangle;
    record.rc_pos = x_r.pos;
    if (r < k) {
        Vertex x_next = path_vertex(r);
        record.rc_next = x_next.pos;
        record.rc_next_triangle = x_next.triangle;
        vec3 s = end_emission(path_vertex(k - 2u), path_vertex(k - 1u));
        if (r + 1u < k) s *= path.end_weight;
        for (uint i = r; i + 1u < k; ++i) {
            loop_tick();
            s *= path_weight(i);
        }
        record.suffix = s;
    }
    return r;
}

bool record_path(Path path, ShiftParams params, out PathRecord record) {
    uint r = record_fields(path, params, record);
    if (r > MAX_PATH_LENGTH) return false;
    if (r == 0u) return true;
    Vertex x_r = path_vertex(r - 1u);
    vec3 before = r >= 3u ? path_vertex(r - 3u).pos : path.camera;
    vec3 prefix_weight = vec3(1.0);
    for (uint i = 0u; i + 2u < r; ++i) {
        loop_tick();
        prefix_weight *= path_weight(i);
    }
    PathRecord joined;
    bool has_after;
    float after;
    if (!join_at_reconnection(record, path_vertex(r - 2u), before, x_r, prefix_weight, joined, has_after, after)) return false;
    record = joined;
    return true;
}

ShiftResult shift_failed() {
    ShiftResult s;
    s.valid = false;
    s.jacobian = 0.0;
    s.contribution = vec3(0.0);
#ifdef SHIFT_ORACLE
    s.vertex_count = 0u;
#endif
    return s;
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

// Random replay on a regenerated path `y` (trace_vertices of the base's length and end type):
// valid if it carries light and samples the base's lobes.
ShiftResult finish_random_replay(ShiftParams params, PathRecord base, Path y) {
    if (!finish_path(y)) return shift_failed();
    PathRecord record;
    if (!record_path(y, params, record) || record.lobes != base.lobes) return shift_failed();
    return shift_ok(record, 1.0, y);
}

ShiftResult shift_random_replay(ShiftParams params, PathRecord base, vec3 camera, Vertex y1) {
    Path y;
    if (!trace_vertices(camera, y1, base.seed, record_length(base), record_nee_end(base), y)) return shift_failed();
    return finish_random_replay(params, base, y);
}

ShiftResult inverse_random_replay(ShiftParams params, PathRecord shifted, vec3 camera, Vertex x1) {
    return shift_random_replay(params, shifted, camera, x1);
}

// Reconnection of the regenerated prefix y_1..y_{r-1} (`prefix`) to the base's x_r.
ShiftResult finish_reconnection(ShiftParams params, PathRecord base, Path prefix, uint r) {
    for (uint i = 1u; i + 1u < r; ++i) {
        loop_tick();
        if (path_lobe(i - 1u) != record_lobe(base, i)) return shift_failed();
    }
    for (uint i = 2u; i < r; ++i) {
        loop_tick();
        if (is_reconnectable(path_vertex(i - 2u), path_vertex(i - 1u), params)) return shift_failed();
    }
    Vertex y_prev = path_vertex(r - 2u);
    Vertex x_r = record_vertex(base.rc_triangle, base.rc_pos);
    if (!is_reconnectable(y_prev, x_r, params) || !visible(y_prev, x_r)) return shift_failed();
    vec3 y_before = r >= 3u ? path_vertex(r - 3u).pos : prefix.camera;
    vec3 prefix_weight = vec3(1.0);
    for (uint i = 0u; i + 1u < prefix.count; ++i) {
        loop_tick();
        prefix_weight *= path_weight(i);
    }
    PathRecord joined;
    bool has_after;
    float after_y;
    if (!join_at_reconnection(base, y_prev, y_before, x_r, prefix_weight, joined, has_after, after_y)) return shift_failed();
    if (!(base.rc_pdf > 0.0 && base.rc_pdf_after > 0.0)) return shift_failed();
    float after_x = has_after ? base.rc_pdf_after : 1.0;
    float jacobian = (joined.rc_pdf * joined.rc_geometry) / (base.rc_pdf * base.rc_geometry) * (after_y / after_x);
    return shift_ok(joined, jacobian, prefix);
}

ShiftResult reconnect_at(ShiftParams params, PathRecord base, vec3 camera, Vertex y1, uint r) {
    Path prefix;
    if (!trace_vertices(camera, y1, base.seed, r - 1u, false, prefix)) return shift_failed();
    return finish_reconnection(params, base, prefix, r);
}

// Random replay where the base has no reconnection vertex (and the replayed path must have none
// either, or the shift would not be invertible), reconnection at the base's x_r otherwise. Both
// branches share one regeneration of the path (random replay: the whole path; reconnection: the
// prefix before x_r), so a kernel holds one copy of it; a replayed path needs no join.
ShiftResult shift_hybrid(ShiftParams params, PathRecord base, vec3 camera, Vertex y1) {
    uint r = record_reconnection_index(base);
    bool replay = r == 0u;
    Path y;
    uint length = replay ? record_length(base) : r - 1u;
    if (!trace_vertices(camera, y1, base.seed, length, replay && record_nee_end(base), y)) return shift_failed();
    if (!replay) return finish_reconnection(params, base, y, r);
    if (!finish_path(y)) return shift_failed();
    PathRecord record;
    if (record_fields(y, params, record) != 0u || record.lobes != base.lobes) return shift_failed();
    return shift_ok(record, 1.0, y);
}

ShiftResult inverse_hybrid(ShiftParams params, PathRecord shifted, vec3 camera, Vertex x1) {
    return shift_hybrid(params, shifted, camera, x1);
}

ShiftResult shift_reconnection(ShiftParams params, PathRecord base, vec3 camera, Vertex y1) {
    return record_reconnection_index(base) == 2u ? reconnect_at(params, base, camera, y1, 2u) : shift_failed();
}

ShiftResult inverse_reconnection(ShiftParams params, PathRecord shifted, vec3 camera, Vertex x1) {
    return shift_reconnection(params, shifted, camera, x1);
}

#endif
