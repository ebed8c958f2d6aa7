// Next-event estimation: emissive triangles and point and spot lights chosen by their likely
// contribution at the shading point through the light tree (shading/light_tree.glsl), uniform area
// sampling, and the environment beside them with a fixed probability; every directional light
// besides, at every vertex (sample_directional). A punctual light's sample is a delta: pdf is
// the discrete probability of choosing it (1 for a directional light), radiance is
// I·falloff/d² (or E), and MIS gives it weight 1. Expects `triangles`,
// `materials`, `emitters` and the scene parameters (interface/scene_bindings.glsl). Twin: crates/shading/src/lights.rs.
#ifndef LIGHTS_GLSL
#define LIGHTS_GLSL

#include "shading/light_tree.glsl"
#include "shading_core/sampling.glsl"
#include "shading_core/texture.glsl"
#include "interface/types.glsl"

// Specialisation like the BSDF lobes: a scene without an environment or without emissive
// triangles compiles that half of NEE out. Both default to on.
#ifndef SCENE_ENVIRONMENT
#define SCENE_ENVIRONMENT 1
#endif
#ifndef SCENE_EMITTERS
#define SCENE_EMITTERS 1
#endif
#ifndef SCENE_PUNCTUAL
#define SCENE_PUNCTUAL 1
#endif
// Whether the scene has directional lights, which NEE takes at every vertex (sample_directional).
#ifndef SCENE_DIRECTIONAL
#define SCENE_DIRECTIONAL 1
#endif
// An equirectangular environment map (crates/scene/src/environment.rs) replaces the constant environment; its
// rows start SCENE_ENV_MAP_BASE rows after the emitter rows in the emitter buffer (after the light
// tree and the punctual lights).
#ifndef SCENE_ENV_MAP
#define SCENE_ENV_MAP 0
#endif
#ifndef SCENE_ENV_MAP_BASE
#define SCENE_ENV_MAP_BASE 0u
#endif

struct LightSample {
    vec3 dir;        // unit direction from the shading point towards the light
    float dist;      // distance to the light point; +inf for the environment
    vec3 radiance;   // emitted radiance towards the shading point (0 from a back face)
    float pdf;       // solid-angle pdf including the selection probability; 0 if impossible
    uint triangle;   // the emitter triangle sampled, NO_EMITTER for the environment,
                     // PUNCTUAL_LIGHT_BIT | k for punctual light k
};

bool is_punctual_light(uint id) { return id != NO_EMITTER && (id & PUNCTUAL_LIGHT_BIT) != 0u; }

struct PunctualLight {
    vec3 position;
    uint kind;
    vec3 direction;    // unit, the way the light shines
    float cos_outer;
    vec3 intensity;    // colour x intensity: candela (point, spot) or lux (directional)
    float cos_inner;
};

PunctualLight punctual_light(uint k) {
    uint base = light_tree_end() + PUNCTUAL_ROWS * k;
    uvec4 r0 = emitter_words(base);
    uvec4 r1 = emitter_words(base + 1u);
    uvec4 r2 = emitter_words(base + 2u);
    PunctualLight l;
    l.position = uintBitsToFloat(r0.xyz);
    l.kind = r0.w;
    l.direction = uintBitsToFloat(r1.xyz);
    l.cos_outer = uintBitsToFloat(r1.w);
    l.intensity = uintBitsToFloat(r2.xyz);
    l.cos_inner = uintBitsToFloat(r2.w);
    return l;
}

// KHR_lights_punctual's smooth spot falloff for light leaving along dir_out; 1 for other kinds.
float spot_falloff(PunctualLight l, vec3 dir_out) {
    if (l.kind != PUNCTUAL_SPOT) return 1.0;
    float scale = 1.0 / max(l.cos_inner - l.cos_outer, 1e-3);
    float t = clamp((dot(l.direction, dir_out) - l.cos_outer) * scale, 0.0, 1.0);
    return t * t;
}

// Direction from p towards light l, distance (+inf for directional) and I·falloff/d² or E.
void punctual_arrival(PunctualLight l, vec3 p, out vec3 dir, out float dist, out vec3 value) {
    if (l.kind == PUNCTUAL_DIRECTIONAL) {
        dir = -l.direction;
        dist = 1.0 / 0.0;
        value = l.intensity;
        return;
    }
    vec3 to_light = l.position - p;
    float d2 = dot(to_light, to_light);
    dir = vec3(0.0, 0.0, 1.0);
    dist = 0.0;
    value = vec3(0.0);
    if (!(d2 > 0.0)) return;
    dist = sqrt(d2);
    dir = to_light / dist;
    value = l.intensity * (spot_falloff(l, -dir) / d2);
}

// Emitted radiance of triangle index `triangle` at barycentrics bary towards direction
// `to_viewer` (front face only unless double-sided), its emissive texture applied.
vec3 emitted_radiance(uint triangle, vec2 bary, vec3 to_viewer) {
    Triangle tri = triangles[triangle];
    Material m = material_at(triangle, bary);
    float facing = dot(cross(tri.e1, tri.e2), to_viewer);
    bool lit = facing > 0.0 || ((m.flags & MATERIAL_DOUBLE_SIDED) != 0u && facing < 0.0);
    return lit ? m.emission : vec3(0.0);
}

// The solid-angle pdf of the point at distance `dist` along `dir` on emitter triangle `tri_index`
// chosen with probability `pmf` and sampled uniformly by area.
float emitter_area_pdf(float pmf, uint tri_index, vec3 dir, float dist) {
    Triangle tri = triangles[tri_index];
    vec3 ng = cross(tri.e1, tri.e2);
    float area2 = length(ng);
    float cos_l = abs(dot(ng, dir)) / area2;
    if (cos_l <= 0.0) return 0.0;
    float p_area = pmf * 2.0 / area2;
    return p_area * dist * dist / cos_l;
}

// Solid-angle pdf that NEE at p (geometric normal n) would have sampled direction `dir` hitting
// emitter triangle `tri_index` at distance `dist` (used for MIS when BSDF sampling hits an emitter).
float emitter_pdf(vec3 p, vec3 n, uint tri_index, vec3 dir, float dist) {
    uint row = triangles[tri_index].emitter;
    return row == NO_EMITTER ? 0.0 : emitter_area_pdf(light_select_pmf(p, n, row), tri_index, dir, dist);
}

// Mitsuba 3's mapping in the map's frame: u = atan2(d.x, -d.z) / 2pi wrapped to [0, 1) (the
// centre column looks along +Z, the edges along -Z), v = acos(d.y) / pi (top +Y).
vec2 equirect_uv(vec3 d) {
    float u = atan(d.x, -d.z) / (2.0 * PI);
    return vec2(u < 0.0 ? u + 1.0 : u, acos(clamp(d.y, -1.0, 1.0)) / PI);
}

vec3 equirect_dir(vec2 uv) {
    float phi = uv.x * 2.0 * PI;
    float theta = uv.y * PI;
    float s = sin(theta);
    return vec3(s * sin(phi), cos(theta), -s * cos(phi));
}

#if SCENE_ENV_MAP
// Header (width, cos, sin, height) of the rotation about +Y (--env-rotation), one row-CDF value
// per row, then per texel (r, g, b, row CDF).
Emitter env_row(uint k) { return emitters[emitter_count + SCENE_ENV_MAP_BASE + k]; }
uvec2 env_size() { Emitter h = env_row(0u); return uvec2(h.triangle, h.leaf); }
vec2 env_rotation() { Emitter h = env_row(0u); return vec2(uintBitsToFloat(h.trail), h.intensity); }

// d turned about +Y by the angle of (cos, sin) cs. Twin: environment::env_rotate.
vec3 env_rotate(vec3 d, vec2 cs) { return vec3(cs.x * d.x + cs.y * d.z, d.y, cs.x * d.z - cs.y * d.x); }

// The map's (u, v) of scene direction d, the rotation undone.
vec2 env_scene_uv(vec3 d) { vec2 cs = env_rotation(); return equirect_uv(env_rotate(d, vec2(cs.x, -cs.y))); }
float env_cdf(uvec2 size, bool rows, uint i, uint j) {
    return rows ? uintBitsToFloat(env_row(1u + j).triangle) : uintBitsToFloat(env_row(1u + size.y + i * size.x + j).leaf);
}

// The first index j < n whose CDF value exceeds u (n - 1 if none): the rows' CDF, or row i's.
// Sixteen fixed halving steps instead of a loop (n < 65536): llvmpipe budgets every loop's
// iterations per invocation, and NEE runs this for every light sample.
#define CDF_STEP(s) if (lo + s <= n && env_cdf(size, rows, i, lo + s - 1u) <= u) lo += s;
uint cdf_search(uvec2 size, bool rows, uint i, uint n, float u) {
    uint lo = 0u;
    CDF_STEP(32768u) CDF_STEP(16384u) CDF_STEP(8192u) CDF_STEP(4096u) CDF_STEP(2048u) CDF_STEP(1024u)
    CDF_STEP(512u) CDF_STEP(256u) CDF_STEP(128u) CDF_STEP(64u) CDF_STEP(32u) CDF_STEP(16u) CDF_STEP(8u)
    CDF_STEP(4u) CDF_STEP(2u) CDF_STEP(1u)
    return min(lo, n - 1u);
}
#undef CDF_STEP

uvec2 env_texel_of(uvec2 size, vec2 uv) {
    return uvec2(min(uint(uv.y * float(size.y)), size.y - 1u), min(uint(uv.x * float(size.x)), size.x - 1u));
}

// The probability of texel (i, j) from the CDFs that sampling inverts.
float env_texel_probability(uvec2 size, uint i, uint j) {
    float row = env_cdf(size, true, 0u, i) - (i > 0u ? env_cdf(size, true, 0u, i - 1u) : 0.0);
    float texel = env_cdf(size, false, i, j) - (j > 0u ? env_cdf(size, false, i, j - 1u) : 0.0);
    return row * texel;
}
#endif

// Radiance arriving from direction dir (unit). Twin: lights::environment_radiance.
vec3 environment_radiance(vec3 dir) {
#if SCENE_ENV_MAP
    uvec2 size = env_size();
    uvec2 ij = env_texel_of(size, env_scene_uv(dir));
    Emitter t = env_row(1u + size.y + ij.x * size.x + ij.y);
    return vec3(uintBitsToFloat(t.triangle), uintBitsToFloat(t.trail), t.intensity);
#else
    return scene_env.rgb;
#endif
}

// Solid-angle pdf that NEE samples the environment in direction dir (unit).
float environment_pdf(vec3 dir) {
#if SCENE_ENV_MAP
    uvec2 size = env_size();
    float sin_theta = length(dir.xz);  // not sqrt(1 - y^2): y rounds to +-1 near the poles
    if (sin_theta <= 0.0) return 0.0;
    uvec2 ij = env_texel_of(size, env_scene_uv(dir));
    float p_uv = env_texel_probability(size, ij.x, ij.y) * float(size.x * size.y);
    return env_select_prob() * p_uv / (2.0 * PI * PI * sin_theta);
#else
    return env_select_prob() * UNIFORM_SPHERE_PDF;
#endif
}

// A direction to the environment from u in [0, 1)^2 (by luminance for a map). Twin:
// Environment::sample_environment (crates/scene/src/environment.rs) for a map.
vec3 sample_environment(vec2 u) {
#if SCENE_ENV_MAP
    uvec2 size = env_size();
    uint i = cdf_search(size, true, 0u, size.y, u.x);
    float below = i > 0u ? env_cdf(size, true, 0u, i - 1u) : 0.0;
    float fu = clamp((u.x - below) / max(env_cdf(size, true, 0u, i) - below, 1.17549435e-38), 0.0, 0.9999999);
    uint j = cdf_search(size, false, i, size.x, u.y);
    float left = j > 0u ? env_cdf(size, false, i, j - 1u) : 0.0;
    float fv = clamp((u.y - left) / max(env_cdf(size, false, i, j) - left, 1.17549435e-38), 0.0, 0.9999999);
    return env_rotate(equirect_dir(vec2((float(j) + fv) / float(size.x), (float(i) + fu) / float(size.y))), env_rotation());
#else
    return sample_uniform_sphere(u);
#endif
}

// The emitter row of punctual light k (its fourth row holds it).
uint punctual_emitter_row(uint k) { return emitters[light_tree_end() + PUNCTUAL_ROWS * k + 3u].triangle; }

// A light sample from p (geometric normal n, unit, which weighs the lights): u.x selects the
// environment or a light (light_select), u.yz the point or direction.
LightSample sample_light(vec3 p, vec3 n, vec3 u) {
    LightSample ls;
    ls.dir = vec3(0.0, 0.0, 1.0);
    ls.dist = 0.0;
    ls.radiance = vec3(0.0);
    ls.pdf = 0.0;
    ls.triangle = NO_EMITTER;
    float p_env = env_select_prob();
    if (SCENE_ENVIRONMENT != 0 && u.x < p_env) {
        ls.dir = sample_environment(u.yz);
        ls.dist = 1.0 / 0.0;
        ls.radiance = environment_radiance(ls.dir);
        ls.pdf = environment_pdf(ls.dir);
        return ls;
    }
    if (SCENE_EMITTERS == 0 || emitter_count == directional_count()) return ls;
    float u_select = (u.x - p_env) / (1.0 - p_env);
    float pmf;
    uint row = light_select(p, n, min(u_select, 0.99999994), pmf);
    if (row == NO_EMITTER) return ls;
    Emitter e = emitters[row];
#if SCENE_PUNCTUAL
    if (is_punctual_light(e.triangle)) {
        uint k = e.triangle & ~PUNCTUAL_LIGHT_BIT;
        vec3 dir, value;
        float dist;
        punctual_arrival(punctual_light(k), p, dir, dist, value);
        if (!(dist > 0.0)) return ls;
        ls.dir = dir;
        ls.dist = dist;
        ls.radiance = value;
        ls.pdf = pmf;
        ls.triangle = e.triangle;
        return ls;
    }
#endif
    Triangle tri = triangles[e.triangle];
    ls.triangle = e.triangle;
    vec2 b = sample_triangle(u.yz);
    vec3 q = tri.v0 + b.x * tri.e1 + b.y * tri.e2;
    vec3 to_light = q - p;
    float d2 = dot(to_light, to_light);
    if (d2 <= 0.0) return ls;
    ls.dist = sqrt(d2);
    ls.dir = to_light / ls.dist;
    ls.radiance = emitted_radiance(e.triangle, b, -ls.dir);
    ls.pdf = emitter_area_pdf(pmf, e.triangle, ls.dir, ls.dist);
    return ls;
}

// The sample of directional light k (k < directional_count()) that NEE adds at every vertex
// beside sample_light's: towards the light, at infinity, its irradiance E, probability 1.
// Twin: lights::sample_directional.
LightSample sample_directional(uint k) {
    uint id = emitters[directional_row(k)].triangle;
    LightSample ls;
    punctual_arrival(punctual_light(id & ~PUNCTUAL_LIGHT_BIT), vec3(0.0), ls.dir, ls.dist, ls.radiance);
    ls.pdf = 1.0;
    ls.triangle = id;
    return ls;
}

#endif
