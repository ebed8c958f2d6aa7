// Unidirectional path tracing with NEE and BSDF sampling combined by the power heuristic (NEE:
// one light drawn, plus every directional light, add_directional_lights), written
// as a per-segment state machine: a kernel steps every lane once per iteration and restarts lanes
// whose path ended, so SIMD lanes (lavapipe runs 8 in lockstep) stay busy however long paths are.
// Each step traces one pair of rays in one traversal (shading_core/trace_pair.glsl): the next segment and the
// shadow ray of the vertex before it, whose NEE contribution waits in the state until then.
// max_depth counts path segments: 1 shows emitters seen directly, 2 adds direct lighting.
#ifndef PATH_TRACER_GLSL
#define PATH_TRACER_GLSL

#include "shading_core/bsdf.glsl"
#include "shading_core/bvh.glsl"
#include "scene/camera.glsl"
#include "shading/lights.glsl"
#include "shading/punctual.glsl"
#include "shading_core/rng.glsl"
#include "scene/hit_surface.glsl"
#include "shading_core/trace_pair.glsl"

const float RAY_TMAX = 1e30;


// The ray that tells whether the light sample is hidden from the shading point x (geometric
// normal ng, on triangle index tri): towards a punctual light, the environment, or the segment
// to the sampled emitter point.
PairRay shadow_ray(vec3 x, vec3 ng, uint tri, LightSample ls) {
    PairRay r;
    if (SCENE_PUNCTUAL != 0 && is_punctual_light(ls.triangle)) {
        punctual_ray(x, ng, tri, ls.dir, ls.dist, r.origin, r.dir, r.tmax);
        return r;
    }
    if (ls.triangle == NO_EMITTER) return PairRay(offset_ray_origin(x, dot(ls.dir, ng) > 0.0 ? ng : -ng, triangles[tri]), ls.dir, RAY_TMAX);
    Triangle light = triangles[ls.triangle];
    segment_ray(x, ng, tri, x + ls.dir * ls.dist, normalize(cross(light.e1, light.e2)), ls.triangle, r.origin, r.dir, r.tmax);
    return r;
}

struct PathState {
    vec3 origin;
    vec3 dir;
    vec3 beta;        // throughput of the prefix
    vec3 radiance;    // radiance gathered so far
    vec3 prev_pos;    // the last scattering vertex and its geometric normal, whose
    vec3 prev_normal; // light-selection pmf MIS needs
    float prev_pdf;   // solid-angle pdf of the last BSDF sample (for MIS at emitter hits)
    bool prev_delta;  // the last scattering was a delta lobe (or the camera): no MIS
    uint depth;       // segments traced so far
    uint seed;
    bool extend;      // the next segment (origin, dir) is still to be traced
    PairRay shadow;   // the pending shadow ray; tmax 0 when there is none
    vec3 nee;         // radiance the pending shadow ray adds if it reaches the light
};

PathState path_begin(uvec2 pixel, uint seed) {
    PathState s;
    vec4 uc = rng_uniform4(seed, 0u, STREAM_CAMERA);
    s.origin = cam_position.xyz;
    s.dir = camera_ray_dir(float(pixel.x) + uc.x, float(pixel.y) + uc.y);
    s.beta = vec3(1.0);
    s.radiance = vec3(0.0);
    s.prev_pos = s.origin;
    s.prev_normal = vec3(0.0, 1.0, 0.0);
    s.prev_pdf = 0.0;
    s.prev_delta = true;
    s.depth = 0u;
    s.seed = seed;
    s.extend = true;
    s.shadow = PairRay(vec3(0.0), vec3(0.0, 0.0, 1.0), 0.0);
    s.nee = vec3(0.0);
    return s;
}

// Adds to s.radiance what every directional light sends through the vertex x (geometric normal
// ng, on triangle index tri; material m, shading normal ns, towards wo): NEE takes each of them
// beside the light sample_light draws (shading/light_tree.glsl), one shadow ray each, traced at once.
void add_directional_lights(inout PathState s, vec3 x, vec3 ng, uint tri, Material m, vec3 ns, vec3 wo) {
#if SCENE_PUNCTUAL && SCENE_DIRECTIONAL
    uint n_dir = directional_count();
    for (uint k = 0u; k < n_dir; k++) {
        loop_tick();
        LightSample ls = sample_directional(k);
        float bsdf_pdf;
        vec3 f = bsdf_eval_pdf(m, ng, ns, wo, ls.dir, bsdf_pdf);
        if (!(max_component(f * ls.radiance) > 0.0)) continue;
        Hit unused;
        bool occluded;
        trace_pair(PairRay(x, ls.dir, 0.0), shadow_ray(x, ng, tri, ls), unused, occluded);
        if (!occluded) s.radiance += s.beta * f * ls.radiance;
    }
#endif
}

// Traces the pending shadow ray and the next segment, and scatters at the segment's end; returns
// false once the path has ended.
bool path_step(inout PathState s) {
    Hit hit;
    bool occluded;
    trace_pair(PairRay(s.origin, s.dir, s.extend ? RAY_TMAX : 0.0), s.shadow, hit, occluded);
    if (s.shadow.tmax > 0.0 && !occluded) s.radiance += s.nee;
    s.shadow.tmax = 0.0;
    if (!s.extend) return false;
    s.depth += 1u;
    if (hit.triangle == NO_HIT) {
        vec3 le = SCENE_ENVIRONMENT != 0 ? environment_radiance(s.dir) : vec3(0.0);
        if (max_component(le) > 0.0) {
            float w = s.prev_delta ? 1.0 : power_heuristic(s.prev_pdf, environment_pdf(s.dir));
            s.radiance += s.beta * le * w;
        }
        return false;
    }
    Triangle tri = triangles[hit.triangle];
    vec3 ng = normalize(cross(tri.e1, tri.e2));
    // BSDFs see the shading normal ns; emission, light pdfs and ray offsets the geometric ng.
    Material m;
    vec3 ns;
    hit_shading(hit.triangle, hit.bary, ng, m, ns);
    vec3 x = tri.v0 + hit.bary.x * tri.e1 + hit.bary.y * tri.e2;
    vec3 wo = -s.dir;
    if (SCENE_EMITTERS != 0 && tri.emitter != NO_EMITTER) {
        vec3 le = emitted_radiance(hit.triangle, hit.bary, wo);
        float w = s.prev_delta ? 1.0 : power_heuristic(s.prev_pdf, emitter_pdf(s.prev_pos, s.prev_normal, hit.triangle, s.dir, hit.t));
        s.radiance += s.beta * le * w;
    }
    if (s.depth >= max_depth) return false;

    vec4 ul = rng_uniform4(s.seed, s.depth, STREAM_LIGHT);
    LightSample ls = sample_light(x, ng, ul.xyz);
    if (ls.pdf > 0.0 && max_component(ls.radiance) > 0.0) {
        float bsdf_pdf;
        vec3 f = bsdf_eval_pdf(m, ng, ns, wo, ls.dir, bsdf_pdf);
        if (max_component(f) > 0.0) {
            s.shadow = shadow_ray(x, ng, hit.triangle, ls);
            // BSDF sampling never reaches a punctual light: NEE alone estimates it.
            float w = is_punctual_light(ls.triangle) ? 1.0 : power_heuristic(ls.pdf, bsdf_pdf);
            s.nee = s.beta * f * ls.radiance * (w / ls.pdf);
        }
    }

    add_directional_lights(s, x, ng, hit.triangle, m, ns, wo);

    // A path that ends here still traces its pending shadow ray in one more step.
    s.extend = false;
    BsdfSample bs = bsdf_sample(m, ng, ns, wo, rng_uniform4(s.seed, s.depth, STREAM_BSDF));
    if (bs.lobe == LOBE_NONE) return s.shadow.tmax > 0.0;
    s.beta *= bs.weight;
    s.prev_pos = x;
    s.prev_normal = ng;
    s.prev_pdf = bs.pdf;
    s.prev_delta = (bs.lobe & LOBE_DELTA) != 0u;
    if ((flags & FLAG_RUSSIAN_ROULETTE) != 0u && s.depth >= RR_START_DEPTH) {
        float survive = min(max_component(s.beta), RR_MAX_SURVIVAL);
        if (ul.w >= survive) return s.shadow.tmax > 0.0;
        s.beta /= survive;
    }
    s.extend = true;
    s.origin = offset_ray_origin(x, dot(bs.wi, ng) > 0.0 ? ng : -ng, tri);
    s.dir = bs.wi;
    return true;
}

#endif
