// The reconnection of a predecessor to a record's x_r: the edge's BSDF, pdf and geometry term,
// the BSDF at x_r towards x_{r+1}, the Jacobian of the shift that makes it, and the path record
// that caches the base side's terms. Expects the scene bindings. Twin:
// crates/shading/src/shift/reconnection.rs.
#ifndef SHIFT_RECONNECTION_GLSL
#define SHIFT_RECONNECTION_GLSL

#include "shading/shift/path.glsl"

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
    vec3 ns;
    Material m = vertex_shading(prev, ns);
    float bsdf_pdf;
    link.f_cos = bsdf_eval_pdf(m, prev.normal, ns, normalize(before - prev.pos), link.dir, bsdf_pdf);
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
    vec3 ns;
    Material m = vertex_shading(x_r, ns);
    float pdf;
    f_cos = bsdf_eval_pdf(m, x_r.normal, ns, -dir_in, dir_next, pdf);
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
    record.info = pack_info(k, r, path.nee_end, path.nee_directional);
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
    if (!trace_vertices(camera, y1, base.seed, r - 1u, false, 0u, prefix)) return shift_failed();
    return finish_reconnection(params, base, prefix, r);
}

#endif
