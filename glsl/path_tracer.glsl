// Unidirectional path tracing with NEE and BSDF sampling combined by the power heuristic.
// max_depth counts path segments: 1 shows emitters seen directly, 2 adds direct lighting.
#ifndef PATH_TRACER_GLSL
#define PATH_TRACER_GLSL

#include "bsdf.glsl"
#include "bvh.glsl"
#include "camera.glsl"
#include "lights.glsl"
#include "rng.glsl"

const float RAY_TMAX = 1e30;
// Shadow rays stop this fraction short of the light point so that the emitter does not occlude itself.
const float SHADOW_EPSILON = 1e-4;
const float RR_MAX_SURVIVAL = 0.95;
const uint RR_START_DEPTH = 3u;

float max_component(vec3 v) { return max(v.x, max(v.y, v.z)); }

vec3 trace_path(uvec2 pixel, uint seed) {
    vec4 uc = rng_uniform4(seed, 0u, STREAM_CAMERA);
    vec3 o = cam_position.xyz;
    vec3 d = camera_ray_dir(float(pixel.x) + uc.x, float(pixel.y) + uc.y);
    vec3 radiance = vec3(0.0);
    vec3 beta = vec3(1.0);
    float prev_pdf = 0.0;
    bool prev_delta = true;
    for (uint depth = 1u;; ++depth) {
        Hit hit = trace_closest(o, d, RAY_TMAX);
        if (hit.triangle == NO_HIT) {
            if (max_component(scene_env.rgb) > 0.0) {
                float w = prev_delta ? 1.0 : power_heuristic(prev_pdf, environment_pdf());
                radiance += beta * scene_env.rgb * w;
            }
            break;
        }
        Triangle tri = triangles[hit.triangle];
        Material m = materials[tri.material];
        vec3 ng = normalize(cross(tri.e1, tri.e2));
        vec3 x = tri.v0 + hit.bary.x * tri.e1 + hit.bary.y * tri.e2;
        vec3 wo = -d;
        if (tri.emitter != NO_EMITTER) {
            vec3 le = emitted_radiance(tri, wo);
            float w = prev_delta ? 1.0 : power_heuristic(prev_pdf, emitter_pdf(hit.triangle, d, hit.t));
            radiance += beta * le * w;
        }
        if (depth >= max_depth) break;

        vec4 ul = rng_uniform4(seed, depth, STREAM_LIGHT);
        LightSample ls = sample_light(x, ul.xyz);
        if (ls.pdf > 0.0 && max_component(ls.radiance) > 0.0) {
            vec3 f = bsdf_eval(m, ng, wo, ls.dir);
            if (max_component(f) > 0.0) {
                vec3 origin = offset_ray_origin(x, dot(ls.dir, ng) > 0.0 ? ng : -ng);
                float tmax = isinf(ls.dist) ? RAY_TMAX : ls.dist * (1.0 - SHADOW_EPSILON);
                if (!trace_occluded(origin, ls.dir, tmax)) {
                    float w = power_heuristic(ls.pdf, bsdf_pdf(m, ng, wo, ls.dir));
                    radiance += beta * f * ls.radiance * (w / ls.pdf);
                }
            }
        }

        BsdfSample bs = bsdf_sample(m, ng, wo, rng_uniform4(seed, depth, STREAM_BSDF));
        if (bs.lobe == LOBE_NONE) break;
        beta *= bs.weight;
        prev_pdf = bs.pdf;
        prev_delta = (bs.lobe & LOBE_DELTA) != 0u;
        if ((flags & FLAG_RUSSIAN_ROULETTE) != 0u && depth >= RR_START_DEPTH) {
            float survive = min(max_component(beta), RR_MAX_SURVIVAL);
            if (ul.w >= survive) break;
            beta /= survive;
        }
        o = offset_ray_origin(x, dot(bs.wi, ng) > 0.0 ? ng : -ng);
        d = bs.wi;
    }
    return radiance;
}

#endif
