// The vertices of ReSTIR PT's paths and what the shifts evaluate between two of them: the
// reconnection test, visibility, the emission and light pdf at the end, and the end's MIS weight.
// Expects the scene bindings. Twin: crates/shading/src/shift/vertex.rs.
#ifndef SHIFT_VERTEX_GLSL
#define SHIFT_VERTEX_GLSL

#include "shading_core/bsdf.glsl"
#include "shading_core/bvh.glsl"
#include "shading/lights.glsl"
#include "shading/punctual.glsl"
#include "scene/hit_surface.glsl"

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
    vec3 normal;      // the geometric normal (as wound); vertex_shading gives the shading normal
    uint triangle;
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

Material material_of(Vertex v) { return material_at(v.triangle, triangle_bary(triangles[v.triangle], v.pos)); }

// The material at surface vertex v and its shading normal ns: the path tracer's hit_shading
// (the interpolated vertex normal with the material's normal map applied; v.normal in a scene
// without shading normals). BSDFs evaluate in the frame of ns, as the path tracer's do, so that
// candidates, shifts and the path tracer share one target function; v.normal, the geometric
// normal, keeps deciding sides, ray offsets and the measure (docs/shift-mappings.md, "Shading
// frame").
Material vertex_shading(Vertex v, out vec3 ns) {
    Material m;
    hit_shading(v.triangle, triangle_bary(triangles[v.triangle], v.pos), v.normal, m, ns);
    return m;
}

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
    return emitted_radiance(end.triangle, triangle_bary(tri, end.pos), normalize(from.pos - end.pos));
}

// The pdf that NEE at `from` picks `end` (solid angle); for a punctual light the discrete
// probability of choosing it (whose ratio between two paths to the same light is 1, as its
// geometry term is). One light_select_pmf for every kind keeps one copy of the tree walk.
float light_pdf(Vertex from, Vertex end) {
    vec3 dir;
    float dist;
    direction(from, end, dir, dist);
    if (vertex_is_escaped(end)) return environment_pdf(dir);
    bool punctual = vertex_is_punctual(end);
    uint row = punctual ? punctual_emitter_row(vertex_light(end)) : triangles[end.triangle].emitter;
    if (row == NO_EMITTER) return 0.0;
    float pmf = light_select_pmf(from.pos, from.normal, row);
    return punctual ? pmf : emitter_area_pdf(pmf, end.triangle, dir, dist);
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
    vec3 ns;
    Material m = vertex_shading(x, ns);
    float bsdf_pdf;
    bsdf_eval_pdf(m, x.normal, ns, normalize(before - x.pos), dir, bsdf_pdf);
    float light = light_pdf(x, end);
    return nee_end ? balance_heuristic(light, bsdf_pdf) : balance_heuristic(bsdf_pdf, light);
}

Vertex hit_vertex(Hit hit) {
    Triangle t = triangles[hit.triangle];
    return vertex_on_surface(hit.triangle, t.v0 + hit.bary.x * t.e1 + hit.bary.y * t.e2);
}
#endif
