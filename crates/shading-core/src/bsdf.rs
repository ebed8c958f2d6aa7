//! The material model, twin of glsl/shading_core/bsdf.glsl: a linear blend of a Lambertian lobe under a GGX
//! specular layer (the glTF non-metal), a GGX conductor and a GGX (or smooth) dielectric
//! (docs/materials.md). Directions point away from the surface.

use glam::{Vec3, Vec4};
use std::f32::consts::PI;

use restir_pt_interface::gpu_types::Material;
pub use restir_pt_interface::path_record::{LOBE_CONDUCTOR, LOBE_DELTA, LOBE_DIELECTRIC, LOBE_DIFFUSE, LOBE_NONE, LOBE_TRANSMISSION};
pub use restir_pt_interface::shader_interface::{DELTA_ALPHA, INDEX_MATCHED_TOLERANCE};

use crate::sampling::{build_onb, pdf_cosine_hemisphere, sample_cosine_hemisphere, sample_ggx_vndf, to_local, to_world, INV_PI};

/// Twin of GLSL `index_matched`: whether relative IOR `eta` is within rounding of 1.
pub fn index_matched(eta: f32) -> bool {
    (eta - 1.0).abs() <= INDEX_MATCHED_TOLERANCE
}

/// A direction sampled from the BSDF (twin of GLSL `BsdfSample`, glsl/shading_core/bsdf.glsl). A failed
/// sample has zero `weight`, zero `pdf` and [`LOBE_NONE`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// The incident (light) direction, unit, world space, pointing away from the surface.
    pub wi: Vec3,
    /// f · |cos θi| / pdf, linear RGB: the path throughput factor of this bounce.
    pub weight: Vec3,
    /// Solid-angle density of `wi` summed over the non-delta lobes (1/sr), or for a delta lobe
    /// the discrete probability of that choice.
    pub pdf: f32,
    /// The `LOBE_*` bits of the lobe that produced `wi`.
    pub lobe: u32,
}

impl BsdfSample {
    const FAILED: BsdfSample = BsdfSample {
        wi: Vec3::ZERO,
        weight: Vec3::ZERO,
        pdf: 0.0,
        lobe: LOBE_NONE,
    };
}

/// GGX alpha from perceptual roughness, alpha = roughness² (glTF metallic-roughness, Burley 2012).
/// Twin of GLSL `ggx_alpha`.
pub fn ggx_alpha(roughness: f32) -> f32 {
    roughness * roughness
}

/// The isotropic GGX (Trowbridge-Reitz) normal distribution D(h) for a unit half-vector `h` in the
/// local frame (+z the normal), in 1/sr (pbrt-v4 `TrowbridgeReitzDistribution::D`). Twin of GLSL
/// `ggx_d`.
///
/// sin^2 comes from x^2 + y^2 rather than 1 - z^2: near the lobe peak of a narrow GGX the
/// latter cancels catastrophically in f32.
pub fn ggx_d(h: Vec3, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = (h.x * h.x + h.y * h.y) + h.z * h.z * a2;
    a2 / (PI * d * d)
}

/// Smith's auxiliary function Λ(w) for GGX (pbrt-v4 `TrowbridgeReitzDistribution::Lambda`),
/// `w` unit in the local frame; 0 at normal incidence, and returned as 0 for w.z = 0. Twin of GLSL
/// `smith_lambda`.
pub fn smith_lambda(w: Vec3, alpha: f32) -> f32 {
    let c2 = w.z * w.z;
    if c2 <= 0.0 {
        return 0.0;
    }
    let t2 = (w.x * w.x + w.y * w.y) / c2;
    0.5 * (-1.0 + (1.0 + alpha * alpha * t2).sqrt())
}

/// Smith's masking function G1(w) = 1 / (1 + Λ(w)), unitless in [0, 1]. Twin of GLSL `smith_g1`.
pub fn smith_g1(w: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + smith_lambda(w, alpha))
}

/// The height-correlated masking-shadowing G2 = 1 / (1 + Λ(wo) + Λ(wi)) (Heitz 2014; pbrt-v4
/// `TrowbridgeReitzDistribution::G`). Twin of GLSL `smith_g2`.
pub fn smith_g2(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + smith_lambda(wo, alpha) + smith_lambda(wi, alpha))
}

/// Density of half-vector `h` under visible-normal sampling from `wo` (Heitz 2018):
/// G1(wo) max(0, wo·h) D(h) / |wo.z|, in 1/sr of h, local frame. Twin of GLSL `ggx_vndf_pdf`.
pub fn ggx_vndf_pdf(wo: Vec3, h: Vec3, alpha: f32) -> f32 {
    smith_g1(wo, alpha) * wo.dot(h).max(0.0) * ggx_d(h, alpha) / wo.z.abs()
}

/// Schlick's Fresnel approximation F0 + (1 - F0)(1 - cos θ)⁵ per RGB channel; `cos_theta` is
/// clamped to [0, 1]. Twin of GLSL `fresnel_schlick`.
pub fn fresnel_schlick(f0: Vec3, cos_theta: f32) -> Vec3 {
    let m = (1.0 - cos_theta).clamp(0.0, 1.0);
    let m5 = (m * m) * (m * m) * m;
    f0 + (Vec3::ONE - f0) * m5
}

/// Unpolarised Fresnel reflectance of a dielectric interface (pbrt-v4 `FrDielectric`): `cos_i`
/// is the cosine to the normal on the outside (negative: the ray arrives from inside, and `eta`
/// is inverted), `eta` = IOR inside / IOR outside. 1 under total internal reflection. Twin of
/// GLSL `fresnel_dielectric`.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let (eta, cos_i) = if cos_i < 0.0 { (1.0 / eta, -cos_i) } else { (eta, cos_i) };
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_par * r_par + r_perp * r_perp)
}

/// Refraction of w about m; `None` on total internal reflection, else (direction, etap used).
pub fn refract_dir(w: Vec3, m: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = m.dot(w);
    let (mut eta, mut m) = (eta, m);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        m = -m;
    }
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-w / eta + (cos_i / eta - cos_t) * m, eta))
}

/// The split by metallic and transmission factors: (non-metal (diffuse base and its specular
/// layer), conductor, dielectric), summing to 1. `KHR_materials_transmission` replaces only the
/// non-metal part (the extension: metals are not transmissive), so the split is
/// mix(mix(base, dielectric, t), conductor, metallic). Twin of GLSL `lobe_weights`.
pub fn lobe_weights(m: &Material) -> (f32, f32, f32) {
    let t = m.transmission.clamp(0.0, 1.0);
    let k = m.metallic.clamp(0.0, 1.0);
    ((1.0 - t) * (1.0 - k), k, t * (1.0 - k))
}

/// Whether the material's non-metal part has a specular layer (`specular_layer_fresnel` is not
/// identically zero).
pub fn has_specular_layer(m: &Material) -> bool {
    lobe_weights(m).0 > 0.0 && m.specular > 0.0
}

/// The non-metal's specular-layer Fresnel `weight * fr` (RGB) at |cos_o| from the shading normal:
/// `KHR_materials_specular`'s `fresnel_mix` with `f0 = min(((ior - 1) / (ior + 1))² specularColor, 1)`
/// and Schlick's approximation, taken at the shading normal instead of at wo·h so that the layer
/// never gains energy (docs/materials.md). Twin of GLSL `specular_layer_fresnel`.
pub fn specular_layer_fresnel(m: &Material, cos_o: f32) -> Vec3 {
    if !(m.specular > 0.0) {
        return Vec3::ZERO;
    }
    let r = (m.ior - 1.0) / (m.ior + 1.0);
    let f0 = (r * r * Vec3::from(m.specular_color)).min(Vec3::ONE);
    m.specular * fresnel_schlick(f0, cos_o.abs())
}

/// Rough dielectric (f * |cos_i|, pdf) in the local frame; +z is the outside.
pub fn dielectric_eval_pdf(wo: Vec3, wi: Vec3, alpha: f32, eta: f32) -> (f32, f32) {
    let (cos_o, cos_i) = (wo.z, wi.z);
    if cos_o == 0.0 || cos_i == 0.0 {
        return (0.0, 0.0);
    }
    let reflect = cos_o * cos_i > 0.0;
    let etap = if reflect {
        1.0
    } else if cos_o > 0.0 {
        eta
    } else {
        1.0 / eta
    };
    let wm = wi * etap + wo;
    if wm.dot(wm) == 0.0 {
        return (0.0, 0.0);
    }
    let mut wm = wm.normalize();
    if wm.z < 0.0 {
        wm = -wm;
    }
    if wm.dot(wi) * cos_i < 0.0 || wm.dot(wo) * cos_o < 0.0 {
        return (0.0, 0.0);
    }
    let fr = fresnel_dielectric(wo.dot(wm), eta);
    let d = ggx_d(wm, alpha);
    let g = smith_g2(wo, wi, alpha);
    let wo_up = wo * cos_o.signum();
    let vis = smith_g1(wo_up, alpha) * wo.dot(wm).abs() * d / cos_o.abs();
    if reflect {
        (d * g * fr / (4.0 * cos_o.abs()), vis / (4.0 * wo.dot(wm).abs()) * fr)
    } else {
        let denom = wi.dot(wm) + wo.dot(wm) / etap;
        let denom = denom * denom;
        if !(denom > 0.0) {
            return (0.0, 0.0);
        }
        let f_cos = d * (1.0 - fr) * g * (wi.dot(wm) * wo.dot(wm) / (cos_o * denom)).abs() / (etap * etap);
        (f_cos, vis * wi.dot(wm).abs() / denom * (1.0 - fr))
    }
}

/// Sum over the non-delta lobes of (f * |cos_i|, pdf) in the local frame.
pub fn bsdf_eval_pdf_local(m: &Material, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
    let (w_d, w_c, w_t) = lobe_weights(m);
    let alpha = ggx_alpha(m.roughness);
    let base = Vec3::from(m.base_color);
    let mut f_cos = Vec3::ZERO;
    let mut pdf = 0.0;
    let side = if wo.z < 0.0 { -1.0 } else { 1.0 };
    let flip = Vec3::new(1.0, 1.0, side);
    let (wo_s, wi_s) = (wo * flip, wi * flip);
    let same_side = wo_s.z > 0.0 && wi_s.z > 0.0;
    // The layer's tint and its share of the non-metal's selection probability.
    let layer = w_d * specular_layer_fresnel(m, wo_s.z);
    let p_layer = layer.max_element();
    if w_d > p_layer && same_side {
        f_cos += (w_d - p_layer) * base * INV_PI * wi_s.z;
        pdf += (w_d - p_layer) * pdf_cosine_hemisphere(wi_s.z);
    }
    if w_c + p_layer > 0.0 && same_side && alpha >= DELTA_ALPHA {
        let h = (wo_s + wi_s).normalize();
        let f = w_c * fresnel_schlick(base, wo_s.dot(h)) + layer;
        f_cos += f * ggx_d(h, alpha) * smith_g2(wo_s, wi_s, alpha) / (4.0 * wo_s.z);
        pdf += (w_c + p_layer) * smith_g1(wo_s, alpha) * ggx_d(h, alpha) / (4.0 * wo_s.z);
    }
    if w_t > 0.0 && alpha >= DELTA_ALPHA && !index_matched(m.ior) {
        let (fc, p) = dielectric_eval_pdf(wo, wi, alpha, m.ior);
        f_cos += w_t * base * fc;
        pdf += w_t * p;
    }
    (f_cos, pdf)
}

/// pbrt-v4's orientation (`SurfaceInteraction::SetShadingGeometry`): the shading normal `ns`
/// turned into the geometric normal `ng`'s hemisphere. Twin of GLSL `shading_normal_facing`.
pub fn shading_normal_facing(ng: Vec3, ns: Vec3) -> Vec3 {
    if ns.dot(ng) < 0.0 {
        -ns
    } else {
        ns
    }
}

/// Mitsuba's strict normals: whether direction `w` lies on the same (strict) side of the
/// geometric normal `ng` and the shading normal `ns`; a direction where they disagree carries
/// nothing. Twin of GLSL `sides_agree`.
pub fn sides_agree(ng: Vec3, ns: Vec3, w: Vec3) -> bool {
    let (a, b) = (w.dot(ng), w.dot(ns));
    (a > 0.0 && b > 0.0) || (a < 0.0 && b < 0.0)
}

/// (f * |cos_i| of the non-delta lobes, solid-angle pdf of `bsdf_sample` producing wi), with the
/// cosine against the shading normal; `ng` geometric, `ns` shading normal (unit, world space).
/// Zero where wo or wi lies on different sides of the two normals ([`sides_agree`]).
pub fn bsdf_eval_pdf(m: &Material, ng: Vec3, ns: Vec3, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
    let n = shading_normal_facing(ng, ns);
    if !sides_agree(ng, n, wo) || !sides_agree(ng, n, wi) {
        return (Vec3::ZERO, 0.0);
    }
    let (t, b) = build_onb(n);
    bsdf_eval_pdf_local(m, to_local(wo, t, b, n), to_local(wi, t, b, n))
}

/// u.xy: direction, u.z: lobe choice, u.w: reflection/transmission choice; `ng` geometric, `ns`
/// shading normal (unit, world space). A sample on different sides of the two normals fails.
pub fn bsdf_sample(m: &Material, ng: Vec3, ns: Vec3, wo_world: Vec3, u: Vec4) -> BsdfSample {
    let n = shading_normal_facing(ng, ns);
    if !sides_agree(ng, n, wo_world) {
        return BsdfSample::FAILED;
    }
    let s = bsdf_sample_frame(m, n, wo_world, u);
    if s.lobe == LOBE_NONE || !sides_agree(ng, n, s.wi) {
        return BsdfSample::FAILED;
    }
    s
}

/// The smooth dielectric's delta sample from local `wo` in `frame` (tangent, bitangent,
/// normal): reflection when `u` < the Fresnel reflectance, else refraction; `w_t` is the lobe's
/// weight. Twin of GLSL `sample_smooth_dielectric`.
pub fn sample_smooth_dielectric(m: &Material, wo: Vec3, w_t: f32, u: f32, frame: (Vec3, Vec3, Vec3)) -> BsdfSample {
    let (t, b, n) = frame;
    let base = Vec3::from(m.base_color);
    let fr = fresnel_dielectric(wo.z, m.ior);
    if u < fr {
        return BsdfSample {
            wi: to_world(Vec3::new(-wo.x, -wo.y, wo.z), t, b, n),
            weight: base,
            pdf: w_t * fr,
            lobe: LOBE_DIELECTRIC | LOBE_DELTA,
        };
    }
    let Some((wt, etap)) = refract_dir(wo, Vec3::Z, m.ior) else {
        return BsdfSample::FAILED;
    };
    BsdfSample {
        wi: to_world(wt, t, b, n),
        weight: base / (etap * etap),
        pdf: w_t * (1.0 - fr),
        lobe: LOBE_DIELECTRIC | LOBE_DELTA | LOBE_TRANSMISSION,
    }
}

/// The rough dielectric's (direction, lobe bits) from local `wo` (u.xy the visible normal, u.w
/// reflection or refraction); `None` when the sample fails. Twin of GLSL `sample_rough_dielectric`.
pub fn sample_rough_dielectric(wo: Vec3, alpha: f32, eta: f32, u: Vec4) -> Option<(Vec3, u32)> {
    let side = if wo.z < 0.0 { -1.0 } else { 1.0 };
    // Visible normals are sampled from wo mirrored through the origin, as the pdf assumes.
    let wm = sample_ggx_vndf(wo * side, alpha, u.truncate().truncate());
    let fr = fresnel_dielectric(wo.dot(wm), eta);
    // A reflection must stay on wo's side and a refraction must cross, or the pdf would be
    // evaluated for the other event.
    if u.w < fr {
        let wi = reflect(-wo, wm);
        return (wi.z * wo.z > 0.0).then_some((wi, LOBE_DIELECTRIC));
    }
    match refract_dir(wo, wm, eta) {
        Some((wt, _)) if wt.z * wo.z < 0.0 => Some((wt, LOBE_DIELECTRIC | LOBE_TRANSMISSION)),
        _ => None,
    }
}

/// [`bsdf_sample`] in the frame of normal `n` alone (no side checks). Twin of GLSL
/// `bsdf_sample_frame`.
pub fn bsdf_sample_frame(m: &Material, n: Vec3, wo_world: Vec3, u: Vec4) -> BsdfSample {
    let (t, b) = build_onb(n);
    let wo = to_local(wo_world, t, b, n);
    if wo.z == 0.0 {
        return BsdfSample::FAILED;
    }
    let (w_d, w_c, w_t) = lobe_weights(m);
    let alpha = ggx_alpha(m.roughness);
    let base = Vec3::from(m.base_color);
    let side = if wo.z < 0.0 { -1.0 } else { 1.0 };
    let flip = Vec3::new(1.0, 1.0, side);
    let wo_s = wo * flip;
    let layer = w_d * specular_layer_fresnel(m, wo_s.z);
    let p_layer = layer.max_element();
    // Lobe choice: diffuse w_d - p_layer, GGX reflection w_c + p_layer, dielectric w_t.
    let (wi, lobe) = if u.z < w_d - p_layer {
        (sample_cosine_hemisphere(u.truncate().truncate()) * flip, LOBE_DIFFUSE)
    } else if u.z < w_d + w_c {
        if alpha < DELTA_ALPHA {
            let pdf = w_c + p_layer;
            return BsdfSample {
                wi: to_world(Vec3::new(-wo.x, -wo.y, wo.z), t, b, n),
                weight: (w_c * fresnel_schlick(base, wo_s.z) + layer) / pdf,
                pdf,
                lobe: LOBE_CONDUCTOR | LOBE_DELTA,
            };
        }
        let h = sample_ggx_vndf(wo_s, alpha, u.truncate().truncate());
        let wi_s = reflect(-wo_s, h);
        // Below the surface the conductor has no density; another lobe's pdf there must not
        // turn this sample into a success.
        if wi_s.z <= 0.0 {
            return BsdfSample::FAILED;
        }
        (wi_s * flip, LOBE_CONDUCTOR)
    } else {
        if w_t <= 0.0 {
            return BsdfSample::FAILED;
        }
        if index_matched(m.ior) {
            return BsdfSample {
                wi: -wo_world,
                weight: base,
                pdf: w_t,
                lobe: LOBE_DIELECTRIC | LOBE_DELTA | LOBE_TRANSMISSION,
            };
        }
        if alpha < DELTA_ALPHA {
            return sample_smooth_dielectric(m, wo, w_t, u.w, (t, b, n));
        }
        match sample_rough_dielectric(wo, alpha, m.ior, u) {
            Some(sample) => sample,
            None => return BsdfSample::FAILED,
        }
    };
    let (f_cos, pdf) = bsdf_eval_pdf_local(m, wo, wi);
    if !(pdf > 0.0) {
        return BsdfSample::FAILED;
    }
    BsdfSample {
        wi: to_world(wi, t, b, n),
        weight: f_cos / pdf,
        pdf,
        lobe,
    }
}

/// GLSL's reflect(I, N) = I - 2 dot(N, I) N.
pub fn reflect(i: Vec3, n: Vec3) -> Vec3 {
    i - 2.0 * n.dot(i) * n
}
