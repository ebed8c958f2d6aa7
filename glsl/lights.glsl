// Next-event estimation: emissive triangles chosen by power through an alias table, uniform area
// sampling, and a constant environment sampled uniformly over the sphere. Expects `triangles`,
// `materials`, `emitters` and the scene parameters (scene_bindings.glsl). Twin: src/lights.rs.
#ifndef LIGHTS_GLSL
#define LIGHTS_GLSL

#include "sampling.glsl"
#include "types.glsl"

// Specialisation like the BSDF lobes: a scene without an environment or without emissive
// triangles compiles that half of NEE out. Both default to on.
#ifndef SCENE_ENVIRONMENT
#define SCENE_ENVIRONMENT 1
#endif
#ifndef SCENE_EMITTERS
#define SCENE_EMITTERS 1
#endif

struct LightSample {
    vec3 dir;        // unit direction from the shading point towards the light
    float dist;      // distance to the light point; +inf for the environment
    vec3 radiance;   // emitted radiance towards the shading point (0 from a back face)
    float pdf;       // solid-angle pdf including the selection probability; 0 if impossible
    uint triangle;   // the emitter triangle sampled, NO_EMITTER for the environment
};

// Emitted radiance of a triangle towards direction `to_viewer` (front face only unless double-sided).
vec3 emitted_radiance(Triangle tri, vec3 to_viewer) {
    Material m = materials[tri.material];
    float facing = dot(cross(tri.e1, tri.e2), to_viewer);
    bool lit = facing > 0.0 || ((m.flags & MATERIAL_DOUBLE_SIDED) != 0u && facing < 0.0);
    return lit ? m.emission : vec3(0.0);
}

uint alias_select(float u, uint count) {
    float scaled = u * float(count);
    uint i = min(uint(scaled), count - 1u);
    float coin = scaled - float(i);
    return coin < emitters[i].alias_prob ? i : emitters[i].alias;
}

// Probability of choosing the environment rather than an emitter.
float env_select_prob() { return scene_env.w; }

// Solid-angle pdf that NEE would have sampled direction `dir` hitting emitter triangle `tri_index`
// at distance `dist` (used for MIS when BSDF sampling hits an emitter).
float emitter_pdf(uint tri_index, vec3 dir, float dist) {
    Triangle tri = triangles[tri_index];
    if (tri.emitter == NO_EMITTER) return 0.0;
    vec3 ng = cross(tri.e1, tri.e2);
    float area2 = length(ng);
    float cos_l = abs(dot(ng, dir)) / area2;
    if (cos_l <= 0.0) return 0.0;
    float p_area = (1.0 - env_select_prob()) * emitters[tri.emitter].select_pdf * 2.0 / area2;
    return p_area * dist * dist / cos_l;
}

float environment_pdf() { return env_select_prob() * UNIFORM_SPHERE_PDF; }

// u.x selects the light, u.yz the point or direction.
LightSample sample_light(vec3 p, vec3 u) {
    LightSample ls;
    ls.dir = vec3(0.0, 0.0, 1.0);
    ls.dist = 0.0;
    ls.radiance = vec3(0.0);
    ls.pdf = 0.0;
    ls.triangle = NO_EMITTER;
    float p_env = env_select_prob();
    if (SCENE_ENVIRONMENT != 0 && u.x < p_env) {
        ls.dir = sample_uniform_sphere(u.yz);
        ls.dist = 1.0 / 0.0;
        ls.radiance = scene_env.rgb;
        ls.pdf = environment_pdf();
        return ls;
    }
    if (SCENE_EMITTERS == 0 || emitter_count == 0u) return ls;
    float u_select = (u.x - p_env) / (1.0 - p_env);
    Emitter e = emitters[alias_select(min(u_select, 0.99999994), emitter_count)];
    Triangle tri = triangles[e.triangle];
    ls.triangle = e.triangle;
    vec2 b = sample_triangle(u.yz);
    vec3 q = tri.v0 + b.x * tri.e1 + b.y * tri.e2;
    vec3 to_light = q - p;
    float d2 = dot(to_light, to_light);
    if (d2 <= 0.0) return ls;
    ls.dist = sqrt(d2);
    ls.dir = to_light / ls.dist;
    ls.radiance = emitted_radiance(tri, -ls.dir);
    ls.pdf = emitter_pdf(e.triangle, ls.dir, ls.dist);
    return ls;
}

#endif
