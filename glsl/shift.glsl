// Shift mappings of ReSTIR PT in primary sample space: random replay, reconnection and hybrid,
// with their inverses, on path records. Expects the scene bindings. Twin: src/shift.rs, where
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

struct Path {
    uint seed;
    vec3 camera;
    uint count;                        // the number of vertices k
    bool nee_end;
    Vertex vertices[MAX_PATH_LENGTH];  // x1..xk
    uint lobes[MAX_PATH_LENGTH];       // the lobe sampled at x_i is lobes[i - 1]
    vec3 weights[MAX_PATH_LENGTH];     // f_s |cos| / p at x_i is weights[i - 1]
    vec3 contribution;
    float end_weight;                  // end_mis_weight of the technique that made x_k
};

struct ShiftResult {
    bool valid;
    PathRecord record;
    float jacobian;
    vec3 contribution;
    uint vertex_count;                 // the vertices the shift made (see src/shift.rs)
    vec3 vertices[MAX_PATH_LENGTH];
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
    bool rough_ggx = m.roughness >= params.roughness_threshold && m.roughness * m.roughness >= DELTA_ALPHA;
    return (w_c <= 0.0 || rough_ggx) && (w_t <= 0.0 || rough_ggx);
}

bool is_reconnectable(Vertex prev, Vertex cur, ShiftParams params) {
    bool far = vertex_is_at_infinity(cur) || length(prev.pos - cur.pos) >= params.distance_threshold;
    return !vertex_is_escaped(prev) && far && vertex_is_rough(prev, params) && vertex_is_rough(cur, params);
}

// The first r >= 2 whose pair (x_{r-1}, x_r) is reconnectable; 0 if none.
uint reconnection_index(Path path, ShiftParams params) {
    for (uint r = 2u; r <= path.count; ++r) {
        loop_tick();
        if (is_reconnectable(path.vertices[r - 2u], path.vertices[r - 1u], params)) return r;
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

bool visible(Vertex from, Vertex to) {
    if (vertex_is_punctual(to)) {
        vec3 dir;
        float dist;
        direction(from, to, dir, dist);
        return !punctual_occluded(from.pos, from.normal, dir, dist);
    }
    if (!vertex_is_escaped(to)) return !segment_occluded(from.pos, from.normal, to.pos, to.normal);
    vec3 origin = offset_ray_origin(from.pos, dot(to.pos, from.normal) > 0.0 ? from.normal : -from.normal);
    return !trace_occluded(origin, to.pos, SHIFT_RAY_TMAX);
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
    bsdf_eval_pdf(material_of(x), x.normal, normalize(before - x.pos), dir, bsdf_pdf);
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

// The vertex BSDF sampling at x_i reaches with the path's random numbers; false if no lobe was
// sampled. Initial candidates and path regeneration share it, so that both build the same paths.
bool bsdf_vertex(Vertex x, vec3 wo, Material m, uint seed, uint i, out BsdfSample s, out Vertex next) {
    s = bsdf_sample(m, x.normal, wo, rng_uniform4(seed, i, STREAM_BSDF));
    if (s.lobe == LOBE_NONE) return false;
    vec3 side = dot(s.wi, x.normal) > 0.0 ? x.normal : -x.normal;
    Hit hit = trace_closest(offset_ray_origin(x.pos, side), s.wi, SHIFT_RAY_TMAX);
    next = hit.triangle == NO_HIT ? vertex_escaped(s.wi) : hit_vertex(hit);
    return true;
}

// A path of the single vertex x1 from `camera`, to be extended with `seed`'s random numbers.
void path_begin(vec3 camera, Vertex x1, uint seed, bool nee_end, out Path path) {
    path.seed = seed;
    path.camera = camera;
    path.count = 1u;
    path.nee_end = nee_end;
    path.vertices[0] = x1;
    path.contribution = vec3(0.0);
    path.end_weight = 0.0;
}

// The vertices, lobes and weights of a path regenerated from x1 with `seed`.
bool trace_vertices(vec3 camera, Vertex x1, uint seed, uint target_length, bool nee_end, out Path path) {
    path_begin(camera, x1, seed, nee_end, path);
    vec3 prev_pos = camera;
    while (path.count < target_length) {
        loop_tick();
        uint i = path.count;
        Vertex x = path.vertices[i - 1u];
        if (vertex_is_escaped(x)) return false;
        vec3 wo = normalize(prev_pos - x.pos);
        Material m = material_of(x);
        Vertex next;
        uint lobe;
        vec3 weight;
        if (i + 1u == target_length && nee_end) {
            LightSample ls;
            if (!nee_vertex(x, seed, i, ls, next) || !visible(x, next)) return false;
            float bsdf_pdf;
            vec3 f_cos = bsdf_eval_pdf(m, x.normal, wo, ls.dir, bsdf_pdf);
            lobe = LOBE_NONE;
            weight = f_cos / ls.pdf;
        } else {
            BsdfSample s;
            if (!bsdf_vertex(x, wo, m, seed, i, s, next)) return false;
            lobe = s.lobe;
            weight = s.weight;
        }
        path.lobes[i - 1u] = lobe;
        path.weights[i - 1u] = weight;
        path.vertices[i] = next;
        path.count += 1u;
        prev_pos = x.pos;
    }
    return true;
}

bool generate_path(vec3 camera, Vertex x1, uint seed, uint target_length, bool nee_end, out Path path) {
    if (!trace_vertices(camera, x1, seed, target_length, nee_end, path)) return false;
    uint k = path.count;
    vec3 c = vec3(0.0);
    if (k >= 2u) {
        vec3 before = k >= 3u ? path.vertices[k - 3u].pos : camera;
        bool after_delta = (path.lobes[k - 2u] & LOBE_DELTA) != 0u;
        path.end_weight = end_mis_weight(path.vertices[k - 2u], before, path.vertices[k - 1u], nee_end, after_delta);
        c = end_emission(path.vertices[k - 2u], path.vertices[k - 1u]) * path.end_weight;
    }
    for (uint i = 0u; i + 1u < k; ++i) {
        loop_tick();
        c *= path.weights[i];
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
    link.f_cos = bsdf_eval_pdf(material_of(prev), prev.normal, normalize(before - prev.pos), link.dir, bsdf_pdf);
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
    f_cos = bsdf_eval_pdf(material_of(x_r), x_r.normal, -dir_in, dir_next, pdf);
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
    vec3 weight = prefix_weight * link.f_cos / link.pdf;
    vec3 contribution;
    if (r == k) {
        bool after_delta = (record_lobe(base, k - 1u) & LOBE_DELTA) != 0u;
        contribution = weight * end_emission(prev, x_r) * end_mis_weight(prev, before, x_r, record_nee_end(base), after_delta);
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
        contribution = weight * f_r / q * base.suffix;
        // The suffix holds the end's MIS weight unless x_r is the last scattering vertex, whose
        // incoming direction the join changes.
        if (r + 1u == k) contribution *= end_mis_weight(x_r, prev.pos, x_next, record_nee_end(base), false);
    }
    if (!(max_component(contribution) > 0.0)) return false;
    record.contribution = contribution;
    return true;
}

bool record_path(Path path, ShiftParams params, out PathRecord record) {
    uint k = path.count;
    uint r = reconnection_index(path, params);
    record.seed = path.seed;
    record.info = pack_info(k, r, path.nee_end);
    record.lobes = 0u;
    for (uint i = 0u; i + 1u < k; ++i) {
        loop_tick();
        record.lobes |= path.lobes[i] << (LOBE_BITS * i);
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
    if (k > MAX_PATH_LENGTH) return false;
    if (r == 0u) return true;
    Vertex x_r = path.vertices[r - 1u];
    record.rc_triangle = x_r.triangle;
    record.rc_pos = x_r.pos;
    if (r < k) {
        Vertex x_next = path.vertices[r];
        record.rc_next = x_next.pos;
        record.rc_next_triangle = x_next.triangle;
        vec3 s = end_emission(path.vertices[k - 2u], path.vertices[k - 1u]);
        if (r + 1u < k) s *= path.end_weight;
        for (uint i = r; i + 1u < k; ++i) {
            loop_tick();
            s *= path.weights[i];
        }
        record.suffix = s;
    }
    vec3 before = r >= 3u ? path.vertices[r - 3u].pos : path.camera;
    vec3 prefix_weight = vec3(1.0);
    for (uint i = 0u; i + 2u < r; ++i) {
        loop_tick();
        prefix_weight *= path.weights[i];
    }
    PathRecord joined;
    bool has_after;
    float after;
    if (!join_at_reconnection(record, path.vertices[r - 2u], before, x_r, prefix_weight, joined, has_after, after)) return false;
    record = joined;
    return true;
}

ShiftResult shift_failed() {
    ShiftResult s;
    s.valid = false;
    s.jacobian = 0.0;
    s.contribution = vec3(0.0);
    s.vertex_count = 0u;
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
    s.vertex_count = made.count;
    for (uint i = 0u; i < made.count; ++i) {
        loop_tick();
        s.vertices[i] = made.vertices[i].pos;
    }
    return s;
}

ShiftResult shift_random_replay(ShiftParams params, PathRecord base, vec3 camera, Vertex y1) {
    Path y;
    if (!generate_path(camera, y1, base.seed, record_length(base), record_nee_end(base), y)) return shift_failed();
    PathRecord record;
    if (!record_path(y, params, record) || record.lobes != base.lobes) return shift_failed();
    return shift_ok(record, 1.0, y);
}

ShiftResult inverse_random_replay(ShiftParams params, PathRecord shifted, vec3 camera, Vertex x1) {
    return shift_random_replay(params, shifted, camera, x1);
}

ShiftResult reconnect_at(ShiftParams params, PathRecord base, vec3 camera, Vertex y1, uint r) {
    Path prefix;
    if (!trace_vertices(camera, y1, base.seed, r - 1u, false, prefix)) return shift_failed();
    for (uint i = 1u; i + 1u < r; ++i) {
        loop_tick();
        if (prefix.lobes[i - 1u] != record_lobe(base, i)) return shift_failed();
    }
    for (uint i = 2u; i < r; ++i) {
        loop_tick();
        if (is_reconnectable(prefix.vertices[i - 2u], prefix.vertices[i - 1u], params)) return shift_failed();
    }
    Vertex y_prev = prefix.vertices[r - 2u];
    Vertex x_r = record_vertex(base.rc_triangle, base.rc_pos);
    if (!is_reconnectable(y_prev, x_r, params) || !visible(y_prev, x_r)) return shift_failed();
    vec3 y_before = r >= 3u ? prefix.vertices[r - 3u].pos : camera;
    vec3 prefix_weight = vec3(1.0);
    for (uint i = 0u; i + 1u < prefix.count; ++i) {
        loop_tick();
        prefix_weight *= prefix.weights[i];
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

ShiftResult shift_hybrid(ShiftParams params, PathRecord base, vec3 camera, Vertex y1) {
    uint r = record_reconnection_index(base);
    if (r == 0u) {
        ShiftResult replay = shift_random_replay(params, base, camera, y1);
        return replay.valid && record_reconnection_index(replay.record) == 0u ? replay : shift_failed();
    }
    return reconnect_at(params, base, camera, y1, r);
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
