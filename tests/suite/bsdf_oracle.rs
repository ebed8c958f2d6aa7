//! GLSL glsl/shading_core/bsdf.glsl against crates/shading-core/src/bsdf.rs: bsdf_eval_pdf and bsdf_sample (through
//! bsdf_sample_frame, sample_smooth_dielectric and sample_rough_dielectric) on random materials,
//! normals, directions and uniforms, plus sample/pdf consistency of the Rust model.

use glam::{Vec3, Vec4};
use restir_pt::gpu_types::Material;
use restir_pt::oracle_types::{BsdfOracleInput, BsdfOracleOutput};
use restir_pt::shading::bsdf::*;

use crate::common::{assert_clean, assert_vec3_close, bsdf_input, close, gpu, run_bsdf_oracle, TestRng};

/// Relative agreement of values; GGX at small alpha and grazing angles amplifies ulp differences.
const TOL: f32 = 1e-3;
/// Inputs this close to a sampling decision (lobe choice, reflect/refract) or to grazing may take
/// the other branch on the GPU; they are excluded and counted.
const DECISION_MARGIN: f32 = 1e-4;

pub fn random_material(r: &mut TestRng) -> Material {
    let roughness = match (r.uniform() * 4.0) as u32 {
        0 => 0.0,
        1 => 0.005 + 0.05 * r.uniform(),
        _ => 0.05 + 0.95 * r.uniform(),
    };
    let (metallic, transmission) = match (r.uniform() * 5.0) as u32 {
        0 => (0.0, 0.0),
        1 => (1.0, 0.0),
        2 => (0.0, 1.0),
        3 => (r.uniform(), 0.0),
        _ => (r.uniform(), r.uniform()),
    };
    // The non-metal's specular layer: absent (Lambertian), the core spec's, or a
    // KHR_materials_specular strength and tint (a tint up to 25 reaches F0 = 1 in a channel).
    let (specular, specular_color) = match (r.uniform() * 3.0) as u32 {
        0 => (0.0, [0.0; 3]),
        1 => (1.0, [1.0; 3]),
        _ => (r.uniform(), [25.0 * r.uniform(), 25.0 * r.uniform(), 25.0 * r.uniform()]),
    };
    Material {
        base_color: [0.05 + 0.95 * r.uniform(), 0.05 + 0.95 * r.uniform(), 0.05 + 0.95 * r.uniform()],
        metallic,
        roughness,
        transmission,
        ior: 1.0 + 1.5 * r.uniform(),
        specular,
        specular_color,
        ..Default::default()
    }
}

/// A shading normal for geometric normal `n`: `n` itself for half the items, else tilted by up
/// to about 37°, and for one item in eight also flipped (to be turned back by
/// `shading_normal_facing`).
pub fn random_shading_normal(r: &mut TestRng, n: Vec3) -> Vec3 {
    let k = r.uniform();
    let tilted = (n + 0.6 * r.unit_vector()).normalize();
    if k < 0.5 {
        n
    } else if k < 0.875 {
        tilted
    } else {
        -tilted
    }
}

/// Whether direction `w` is within rounding of either normal's plane, where GLSL and Rust may
/// disagree on `sides_agree`.
fn near_side(ng: Vec3, ns: Vec3, w: Vec3) -> bool {
    w.dot(ng).abs() < 1e-4 || w.dot(ns).abs() < 1e-4
}

fn near_decision(m: &Material, ng: Vec3, ns: Vec3, wo: Vec3, u: Vec4) -> bool {
    let n = shading_normal_facing(ng, ns);
    let (w_d, w_c, _) = lobe_weights(m);
    let cos_o = n.dot(wo);
    let fr_smooth = fresnel_dielectric(cos_o, m.ior);
    let p_layer = w_d * specular_layer_fresnel(m, cos_o).max_element();
    (u.z - w_d).abs() < DECISION_MARGIN
        || (u.z - (w_d - p_layer)).abs() < DECISION_MARGIN
        || (u.z - (w_d + w_c)).abs() < DECISION_MARGIN
        || (u.w - fr_smooth).abs() < DECISION_MARGIN
        || cos_o.abs() < 1e-3
        || near_side(ng, n, wo)
}

#[test]
fn bsdf_eval_pdf_and_bsdf_sample_glsl_matches_rust() {
    // GLSL bsdf_eval_pdf and bsdf_sample against their Rust twins (check_bsdf_item).
    let ctx = gpu();
    let mut r = TestRng(99);
    let n_items = 1 << 14;
    let mut materials = Vec::with_capacity(n_items);
    let mut inputs = Vec::with_capacity(n_items);
    for _ in 0..n_items {
        materials.push(random_material(&mut r));
        let ng = r.unit_vector();
        inputs.push(bsdf_input(
            ng,
            random_shading_normal(&mut r, ng),
            r.unit_vector(),
            r.unit_vector(),
            Vec4::new(r.uniform(), r.uniform(), r.uniform(), r.uniform()),
        ));
    }
    let out = run_bsdf_oracle(&ctx, &materials, &inputs);
    let mut excluded = 0;
    let mut sampled = 0;
    for i in 0..n_items {
        match check_bsdf_item(&materials[i], &inputs[i], &out[i], i) {
            None => excluded += 1,
            Some(true) => sampled += 1,
            Some(false) => {}
        }
    }
    eprintln!(
        "bsdf oracle: {n_items} items, {sampled} successful samples compared, {excluded} within {DECISION_MARGIN} of a decision excluded"
    );
    assert!(excluded < n_items / 50, "too many excluded items: {excluded}");
    assert!(sampled > n_items / 2, "too few successful samples: {sampled}");
    assert_clean(&ctx);
}

/// bsdf_eval_pdf and bsdf_sample of item `i` (GLSL outputs `g`) against their Rust twins. None
/// when the item sits within rounding of a decision and is excluded, else whether a sample was
/// drawn and compared.
fn check_bsdf_item(m: &Material, input: &BsdfOracleInput, g: &BsdfOracleOutput, i: usize) -> Option<bool> {
    let (ng, ns, wo, wi, u) = (
        Vec3::from_array(input.geometric_normal),
        Vec3::from_array(input.shading_normal),
        Vec3::from_array(input.wo),
        Vec3::from_array(input.wi),
        Vec4::from_array(input.u),
    );
    if near_side(ng, ns, wi) || near_decision(m, ng, ns, wo, u) {
        return None;
    }
    let (f, pdf) = bsdf_eval_pdf(m, ng, ns, wo, wi);
    assert_vec3_close(format_args!("bsdf_eval_pdf f item {i} for {m:?}"), Vec3::from_array(g.f), f, TOL);
    assert!(close(g.pdf, pdf, TOL), "bsdf_eval_pdf pdf item {i}: GLSL {} vs Rust {pdf}", g.pdf);
    let s = bsdf_sample(m, ng, ns, wo, u);
    if s.lobe != LOBE_NONE && near_side(ng, ns, s.wi) {
        return None;
    }
    let lobe = g.sample_lobe;
    assert_eq!(lobe, s.lobe, "bsdf_sample lobe item {i} for {m:?}");
    if s.lobe == LOBE_NONE {
        return Some(false);
    }
    assert_vec3_close(
        format_args!("bsdf_sample wi item {i} for {m:?}"),
        Vec3::from_array(g.sample_wi),
        s.wi,
        TOL,
    );
    assert!(
        close(g.sample_pdf, s.pdf, TOL),
        "bsdf_sample pdf item {i}: GLSL {} vs Rust {}",
        g.sample_pdf,
        s.pdf
    );
    assert_vec3_close(
        format_args!("bsdf_sample weight item {i} for {m:?}"),
        Vec3::from_array(g.sample_weight),
        s.weight,
        TOL,
    );
    Some(true)
}

#[test]
fn bsdf_sample_pdf_and_weight_are_consistent_with_bsdf_eval_pdf() {
    const SINGULAR_PDF: f32 = 1e5;
    let mut r = TestRng(3);
    let (mut checked, mut singular) = (0, 0);
    for _ in 0..50_000 {
        let m = random_material(&mut r);
        let (n, wo) = (r.unit_vector(), r.unit_vector());
        let ns = random_shading_normal(&mut r, n);
        let s = bsdf_sample(&m, n, ns, wo, Vec4::new(r.uniform(), r.uniform(), r.uniform(), r.uniform()));
        assert!(s.weight.is_finite() && s.pdf.is_finite(), "non-finite sample for {m:?}");
        if s.lobe == LOBE_NONE || s.lobe & LOBE_DELTA != 0 {
            continue;
        }
        // Re-evaluating in world space round-trips wi through the shading frame, an ulp-level
        // change that peaked densities amplify: the tolerance grows with the pdf (1e-3 for
        // pdf <= 1e3, 1e-2 at 1e4), and near the grazing-refraction singularity (pdf > 1e5) the
        // samples are counted, not compared. Formula errors are O(1) and fail regardless.
        if s.pdf > SINGULAR_PDF {
            singular += 1;
            continue;
        }
        let tol = 1e-3 * (1.0 + s.pdf / 1e3);
        let (f, pdf) = bsdf_eval_pdf(&m, n, ns, wo, s.wi);
        assert!(close(s.pdf, pdf, tol), "sampled pdf {} vs evaluated {pdf} for {m:?}", s.pdf);
        assert!(
            (s.weight - f / pdf).abs().max_element() <= tol * (1.0 + s.weight.max_element()),
            "weight != f/pdf for {m:?}"
        );
        checked += 1;
    }
    assert!(checked > 20_000, "only {checked} non-delta samples");
    // Narrow lobes (alpha 1e-3..3e-3, a quarter of the random materials) peak near 3e5.
    assert!(singular < checked / 20, "{singular} samples with pdf > {SINGULAR_PDF}");
}

/// The pdf integrates to the probability that sampling succeeds on a non-delta lobe: estimated
/// by sampling (fraction of successes) and by integrating the pdf over the sphere (Monte Carlo
/// with uniform directions); the two agree within 4 standard errors.
#[test]
fn bsdf_pdf_integrates_to_sampling_success_rate() {
    let mut r = TestRng(17);
    let materials = [
        Material {
            base_color: [0.8; 3],
            roughness: 1.0,
            ior: 1.5,
            ..Default::default()
        },
        Material {
            base_color: [0.9; 3],
            metallic: 1.0,
            roughness: 0.3,
            ior: 1.5,
            ..Default::default()
        },
        Material {
            base_color: [1.0; 3],
            transmission: 1.0,
            roughness: 0.4,
            ior: 1.5,
            ..Default::default()
        },
        Material {
            base_color: [0.7; 3],
            metallic: 0.5,
            transmission: 0.3,
            roughness: 0.6,
            ior: 1.33,
            ..Default::default()
        },
    ];
    let n = Vec3::Z;
    // With a tilted shading normal, directions on different sides of the two normals carry
    // nothing: the rejected samples and the zero pdf there must match.
    let tilted = Vec3::new(0.45, 0.0, 0.9).normalize();
    for m in &materials {
        for (ns, wo) in [
            (n, Vec3::new(0.3, 0.1, 0.9).normalize()),
            (n, Vec3::new(0.8, 0.0, -0.3).normalize()),
            (tilted, Vec3::new(0.3, 0.1, 0.9).normalize()),
            (tilted, Vec3::new(-0.3, 0.2, 0.6).normalize()),
            (tilted, Vec3::new(0.8, 0.0, -0.3).normalize()),
        ] {
            let trials = 200_000;
            let successes = (0..trials)
                .filter(|_| bsdf_sample(m, n, ns, wo, Vec4::new(r.uniform(), r.uniform(), r.uniform(), r.uniform())).lobe != LOBE_NONE)
                .count() as f64
                / trials as f64;
            let samples: Vec<f64> = (0..trials)
                .map(|_| {
                    let wi = r.unit_vector();
                    bsdf_eval_pdf(m, n, ns, wo, wi).1 as f64 * 4.0 * std::f64::consts::PI
                })
                .collect();
            let mean = samples.iter().sum::<f64>() / trials as f64;
            let var = samples.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (trials as f64 - 1.0);
            let se = (var / trials as f64 + successes * (1.0 - successes) / trials as f64).sqrt();
            assert!(
                (mean - successes).abs() < 4.0 * se + 1e-3,
                "{m:?}, ns {ns}, wo {wo}: integral {mean:.4} vs success rate {successes:.4} (se {se:.4})"
            );
        }
    }
}
