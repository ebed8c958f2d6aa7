// The material model (docs/materials.md): a linear blend of a Lambertian lobe under a GGX
// specular layer (the glTF non-metal), a GGX conductor and a GGX (or smooth) dielectric. All
// directions point away from the surface. BSDFs evaluate in the shading frame (normal ns); the
// geometric normal ng (as wound) decides sides (docs/materials.md, "Shading normals").
// Twin: crates/shading-core/src/bsdf.rs.
#ifndef BSDF_GLSL
#define BSDF_GLSL

#include "shading_core/sampling.glsl"
#include "interface/types.glsl"

// Kernels are specialised to the lobes a scene uses (lavapipe executes both sides of a divergent
// branch, so unused lobes would cost time); each defaults to on, as in the oracle kernels.
#ifndef BSDF_DIFFUSE
#define BSDF_DIFFUSE 1
#endif
#ifndef BSDF_CONDUCTOR
#define BSDF_CONDUCTOR 1
#endif
#ifndef BSDF_DIELECTRIC
#define BSDF_DIELECTRIC 1
#endif
#ifndef BSDF_SPECULAR
#define BSDF_SPECULAR 1
#endif

// DELTA_ALPHA, INDEX_MATCHED_TOLERANCE and the LOBE_* bits come from the generated header
// (crates/interface/src/shader_interface.rs and path_record.rs say why they are what they are).

bool index_matched(float eta) { return abs(eta - 1.0) <= INDEX_MATCHED_TOLERANCE; }

struct BsdfSample {
    vec3 wi;
    vec3 weight;   // f * |cos| / pdf
    float pdf;     // solid-angle pdf of the whole mixture, or the discrete probability for delta lobes
    uint lobe;     // LOBE_* bits; LOBE_NONE when sampling failed
};

float ggx_alpha(float roughness) { return roughness * roughness; }

// sin^2 comes from x^2 + y^2 rather than 1 - z^2: near the lobe peak of a narrow GGX the latter
// cancels catastrophically in f32.
float ggx_d(vec3 h, float alpha) {
    float a2 = alpha * alpha;
    float d = (h.x * h.x + h.y * h.y) + h.z * h.z * a2;
    return a2 / (PI * d * d);
}

float smith_lambda(vec3 w, float alpha) {
    float c2 = w.z * w.z;
    if (c2 <= 0.0) return 0.0;
    float t2 = (w.x * w.x + w.y * w.y) / c2;
    return 0.5 * (-1.0 + sqrt(1.0 + alpha * alpha * t2));
}

float smith_g1(vec3 w, float alpha) { return 1.0 / (1.0 + smith_lambda(w, alpha)); }

float smith_g2(vec3 wo, vec3 wi, float alpha) {
    return 1.0 / (1.0 + smith_lambda(wo, alpha) + smith_lambda(wi, alpha));
}

// Density of visible normal h seen from wo: G1(wo) max(0, wo.h) D(h) / |wo.z|.
float ggx_vndf_pdf(vec3 wo, vec3 h, float alpha) {
    return smith_g1(wo, alpha) * max(0.0, dot(wo, h)) * ggx_d(h, alpha) / abs(wo.z);
}

vec3 fresnel_schlick(vec3 f0, float cos_theta) {
    float m = clamp(1.0 - cos_theta, 0.0, 1.0);
    float m5 = (m * m) * (m * m) * m;
    return f0 + (1.0 - f0) * m5;
}

// Unpolarised Fresnel reflectance; cos_i < 0 means the ray arrives from inside (eta inverted).
float fresnel_dielectric(float cos_i, float eta) {
    if (cos_i < 0.0) { eta = 1.0 / eta; cos_i = -cos_i; }
    float sin2_t = max(0.0, 1.0 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0) return 1.0;
    float cos_t = sqrt(1.0 - sin2_t);
    float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (r_par * r_par + r_perp * r_perp);
}

// Refraction of w about normal m (both local); returns false on total internal reflection.
// etap receives the relative IOR actually used (eta or 1/eta).
bool refract_dir(vec3 w, vec3 m, float eta, out vec3 wt, out float etap) {
    float cos_i = dot(m, w);
    if (cos_i < 0.0) { eta = 1.0 / eta; cos_i = -cos_i; m = -m; }
    float sin2_t = max(0.0, 1.0 - cos_i * cos_i) / (eta * eta);
    etap = eta;
    wt = vec3(0.0);
    if (sin2_t >= 1.0) return false;
    float cos_t = sqrt(1.0 - sin2_t);
    wt = -w / eta + (cos_i / eta - cos_t) * m;
    return true;
}

// The split by metallic and transmission factors: the non-metal (diffuse base and its specular
// layer), the conductor and the dielectric. KHR_materials_transmission replaces only the
// non-metal part (metals are not transmissive): mix(mix(base, dielectric, t), conductor, k).
void lobe_weights(Material m, out float w_diffuse, out float w_conductor, out float w_dielectric) {
    float t = clamp(m.transmission, 0.0, 1.0);
    float k = clamp(m.metallic, 0.0, 1.0);
    w_diffuse = (1.0 - t) * (1.0 - k);
    w_conductor = k;
    w_dielectric = t * (1.0 - k);
}

float max_component3(vec3 v) { return max(v.x, max(v.y, v.z)); }

// The non-metal's specular-layer Fresnel weight * fr: KHR_materials_specular's fresnel_mix
// (f0 = min(((ior - 1) / (ior + 1))^2 * specularColor, 1), Schlick) taken at the shading normal,
// |cos_o|, rather than at wo.h, so that the layer never gains energy (docs/materials.md).
vec3 specular_layer_fresnel(Material m, float cos_o) {
    if (BSDF_SPECULAR == 0 || !(m.specular > 0.0)) return vec3(0.0);
    float r = (m.ior - 1.0) / (m.ior + 1.0);
    vec3 f0 = min(r * r * m.specular_color, vec3(1.0));
    return m.specular * fresnel_schlick(f0, abs(cos_o));
}

// Rough dielectric f*|cos_i| and pdf (local frame; n = +z is the outside).
void dielectric_eval_pdf(vec3 wo, vec3 wi, float alpha, float eta, out float f_cos, out float pdf) {
    f_cos = 0.0;
    pdf = 0.0;
    float cos_o = wo.z, cos_i = wi.z;
    if (cos_o == 0.0 || cos_i == 0.0) return;
    bool reflect = cos_o * cos_i > 0.0;
    float etap = reflect ? 1.0 : (cos_o > 0.0 ? eta : 1.0 / eta);
    vec3 wm = wi * etap + wo;
    if (dot(wm, wm) == 0.0) return;
    wm = normalize(wm);
    if (wm.z < 0.0) wm = -wm;
    // Microfacets facing away from either direction carry nothing.
    if (dot(wm, wi) * cos_i < 0.0 || dot(wm, wo) * cos_o < 0.0) return;
    float fr = fresnel_dielectric(dot(wo, wm), eta);
    float d = ggx_d(wm, alpha);
    float g = smith_g2(wo, wi, alpha);
    vec3 wo_up = wo * sign(cos_o);
    float vis = smith_g1(wo_up, alpha) * abs(dot(wo, wm)) * d / abs(cos_o);
    if (reflect) {
        f_cos = d * g * fr / (4.0 * abs(cos_o));
        pdf = vis / (4.0 * abs(dot(wo, wm))) * fr;
    } else {
        float denom = dot(wi, wm) + dot(wo, wm) / etap;
        denom *= denom;
        if (!(denom > 0.0)) return;
        f_cos = d * (1.0 - fr) * g * abs(dot(wi, wm) * dot(wo, wm) / (cos_o * denom)) / (etap * etap);
        pdf = vis * abs(dot(wi, wm)) / denom * (1.0 - fr);
    }
}

// Sum over the non-delta lobes of f * |cos_i| (local frame, n = +z as wound).
void bsdf_eval_pdf_local(Material m, vec3 wo, vec3 wi, out vec3 f_cos, out float pdf) {
    float w_d, w_c, w_t;
    lobe_weights(m, w_d, w_c, w_t);
    float alpha = ggx_alpha(m.roughness);
    f_cos = vec3(0.0);
    pdf = 0.0;
    // Opaque lobes reflect on whichever side wo lies.
    float side = wo.z < 0.0 ? -1.0 : 1.0;
    vec3 wo_s = wo * vec3(1.0, 1.0, side);
    vec3 wi_s = wi * vec3(1.0, 1.0, side);
    bool same_side = wo_s.z > 0.0 && wi_s.z > 0.0;
    // The layer's tint and its share of the non-metal's selection probability.
    vec3 layer = w_d * specular_layer_fresnel(m, wo_s.z);
    float p_layer = max_component3(layer);
    if (BSDF_DIFFUSE != 0 && w_d > p_layer && same_side) {
        f_cos += (w_d - p_layer) * m.base_color * INV_PI * wi_s.z;
        pdf += (w_d - p_layer) * pdf_cosine_hemisphere(wi_s.z);
    }
    if ((BSDF_CONDUCTOR != 0 || BSDF_SPECULAR != 0) && w_c + p_layer > 0.0 && same_side && alpha >= DELTA_ALPHA) {
        vec3 h = normalize(wo_s + wi_s);
        vec3 f = w_c * fresnel_schlick(m.base_color, dot(wo_s, h)) + layer;
        f_cos += f * ggx_d(h, alpha) * smith_g2(wo_s, wi_s, alpha) / (4.0 * wo_s.z);
        pdf += (w_c + p_layer) * smith_g1(wo_s, alpha) * ggx_d(h, alpha) / (4.0 * wo_s.z);
    }
    if (BSDF_DIELECTRIC != 0 && w_t > 0.0 && alpha >= DELTA_ALPHA && !index_matched(m.ior)) {
        float fc, p;
        dielectric_eval_pdf(wo, wi, alpha, m.ior, fc, p);
        f_cos += w_t * m.base_color * fc;
        pdf += w_t * p;
    }
}

// pbrt-v4's orientation (SurfaceInteraction::SetShadingGeometry): the shading normal is turned
// into the geometric normal's hemisphere.
vec3 shading_normal_facing(vec3 ng, vec3 ns) { return dot(ns, ng) < 0.0 ? -ns : ns; }

// Mitsuba's strict normals: a direction that lies on different sides of the geometric and the
// shading normal carries nothing (no light leaks through the surface, no reflection into it).
bool sides_agree(vec3 ng, vec3 ns, vec3 w) {
    float a = dot(w, ng), b = dot(w, ns);
    return (a > 0.0 && b > 0.0) || (a < 0.0 && b < 0.0);
}

// f * |cos_i| (the cosine against the shading normal) of the non-delta lobes, and in `pdf` the
// solid-angle pdf of bsdf_sample producing wi; ng geometric, ns shading normal (unit).
vec3 bsdf_eval_pdf(Material m, vec3 ng, vec3 ns, vec3 wo, vec3 wi, out float pdf) {
    vec3 n = shading_normal_facing(ng, ns);
    pdf = 0.0;
    if (!sides_agree(ng, n, wo) || !sides_agree(ng, n, wi)) return vec3(0.0);
    vec3 t, b;
    build_onb(n, t, b);
    vec3 f_cos;
    bsdf_eval_pdf_local(m, to_local(wo, t, b, n), to_local(wi, t, b, n), f_cos, pdf);
    return f_cos;
}

BsdfSample bsdf_sample_failed() { return BsdfSample(vec3(0.0), vec3(0.0), 0.0, LOBE_NONE); }

// The smooth dielectric's delta sample from local wo in frame (t, b, n): reflection when u < the
// Fresnel reflectance, else refraction; w_t is the lobe's weight.
BsdfSample sample_smooth_dielectric(Material m, vec3 wo, float w_t, float u, vec3 t, vec3 b, vec3 n) {
    BsdfSample s = bsdf_sample_failed();
    float fr = fresnel_dielectric(wo.z, m.ior);
    if (u < fr) {
        s.wi = to_world(vec3(-wo.x, -wo.y, wo.z), t, b, n);
        s.weight = m.base_color;
        s.pdf = w_t * fr;
        s.lobe = LOBE_DIELECTRIC | LOBE_DELTA;
        return s;
    }
    vec3 wt;
    float etap;
    if (!refract_dir(wo, vec3(0.0, 0.0, 1.0), m.ior, wt, etap)) return s;
    s.wi = to_world(wt, t, b, n);
    s.weight = m.base_color / (etap * etap);
    s.pdf = w_t * (1.0 - fr);
    s.lobe = LOBE_DIELECTRIC | LOBE_DELTA | LOBE_TRANSMISSION;
    return s;
}

// The rough dielectric's direction wi from local wo (u.xy the visible normal, u.w reflection or
// refraction): its lobe bits, LOBE_NONE when the sample fails.
uint sample_rough_dielectric(vec3 wo, float alpha, float eta, vec4 u, out vec3 wi) {
    float side = wo.z < 0.0 ? -1.0 : 1.0;
    // Visible normals are sampled from wo mirrored through the origin, as the pdf assumes.
    vec3 wm = sample_ggx_vndf(wo * side, alpha, u.xy);
    float fr = fresnel_dielectric(dot(wo, wm), eta);
    // A reflection must stay on wo's side and a refraction must cross, or the pdf would be
    // evaluated for the other event.
    if (u.w < fr) {
        wi = reflect(-wo, wm);
        return wi.z * wo.z <= 0.0 ? LOBE_NONE : LOBE_DIELECTRIC;
    }
    float etap;
    if (!refract_dir(wo, wm, eta, wi, etap) || wi.z * wo.z >= 0.0) return LOBE_NONE;
    return LOBE_DIELECTRIC | LOBE_TRANSMISSION;
}

// bsdf_sample in the frame of normal n alone (no side checks).
BsdfSample bsdf_sample_frame(Material m, vec3 n, vec3 wo_world, vec4 u) {
    BsdfSample s = bsdf_sample_failed();
    vec3 t, b;
    build_onb(n, t, b);
    vec3 wo = to_local(wo_world, t, b, n);
    if (wo.z == 0.0) return s;
    float w_d, w_c, w_t;
    lobe_weights(m, w_d, w_c, w_t);
    float alpha = ggx_alpha(m.roughness);
    float side = wo.z < 0.0 ? -1.0 : 1.0;
    vec3 wo_s = wo * vec3(1.0, 1.0, side);
    vec3 layer = w_d * specular_layer_fresnel(m, wo_s.z);
    float p_layer = max_component3(layer);
    vec3 wi;
    uint lobe;
    // Lobe choice: diffuse w_d - p_layer, GGX reflection w_c + p_layer, dielectric w_t.
    if (BSDF_DIFFUSE != 0 && u.z < w_d - p_layer) {
        wi = sample_cosine_hemisphere(u.xy) * vec3(1.0, 1.0, side);
        lobe = LOBE_DIFFUSE;
    } else if ((BSDF_CONDUCTOR != 0 || BSDF_SPECULAR != 0) && u.z < w_d + w_c) {
        lobe = LOBE_CONDUCTOR;
        if (alpha < DELTA_ALPHA) {
            s.wi = to_world(vec3(-wo.x, -wo.y, wo.z), t, b, n);
            s.pdf = w_c + p_layer;
            s.weight = (w_c * fresnel_schlick(m.base_color, wo_s.z) + layer) / s.pdf;
            s.lobe = LOBE_CONDUCTOR | LOBE_DELTA;
            return s;
        }
        vec3 h = sample_ggx_vndf(wo_s, alpha, u.xy);
        vec3 wi_s = reflect(-wo_s, h);
        // Below the surface the conductor has no density; another lobe's pdf there must not
        // turn this sample into a success.
        if (wi_s.z <= 0.0) return s;
        wi = wi_s * vec3(1.0, 1.0, side);
    } else if (BSDF_DIELECTRIC != 0 && w_t > 0.0) {
        if (index_matched(m.ior)) {
            s.wi = -wo_world;
            s.weight = m.base_color;
            s.pdf = w_t;
            s.lobe = LOBE_DIELECTRIC | LOBE_DELTA | LOBE_TRANSMISSION;
            return s;
        }
        if (alpha < DELTA_ALPHA) return sample_smooth_dielectric(m, wo, w_t, u.w, t, b, n);
        lobe = sample_rough_dielectric(wo, alpha, m.ior, u, wi);
        if (lobe == LOBE_NONE) return s;
    } else {
        return s;
    }
    vec3 f_cos;
    float pdf;
    bsdf_eval_pdf_local(m, wo, wi, f_cos, pdf);
    if (!(pdf > 0.0)) return s;
    s.wi = to_world(wi, t, b, n);
    s.weight = f_cos / pdf;
    s.pdf = pdf;
    s.lobe = lobe;
    return s;
}

// u.xy: direction, u.z: lobe choice, u.w: reflection/transmission choice; ng geometric, ns
// shading normal (unit). A sample on different sides of the two normals fails.
BsdfSample bsdf_sample(Material m, vec3 ng, vec3 ns, vec3 wo_world, vec4 u) {
    vec3 n = shading_normal_facing(ng, ns);
    if (!sides_agree(ng, n, wo_world)) return bsdf_sample_failed();
    BsdfSample r = bsdf_sample_frame(m, n, wo_world, u);
    if (r.lobe == LOBE_NONE || !sides_agree(ng, n, r.wi)) return bsdf_sample_failed();
    return r;
}

#endif
