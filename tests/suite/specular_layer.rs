//! The non-metal's GGX specular layer (docs/materials.md): the layer never gains energy (a
//! furnace of glsl/oracle/bsdf_oracle.comp and crates/shading-core/src/bsdf.rs over roughness, IOR, specular factor,
//! specular colour and angle), its sampling follows its pdf (chi-square at the 1% level), the
//! loader reads `KHR_materials_specular` and `KHR_materials_ior` into it, and roughness changes
//! a non-metal's BSDF and image (it changed nothing before the layer existed).

use std::f64::consts::PI;

use glam::{Vec3, Vec4};
use restir_pt::gpu_types::Material;
use restir_pt::shading::bsdf::{bsdf_eval_pdf, bsdf_sample, specular_layer_fresnel, DELTA_ALPHA, LOBE_NONE};

use crate::common::{assert_clean, bsdf_input, gpu, run_bsdf_oracle, TestRng};
use crate::fixtures::statistics::chi_square_critical_1pct;

fn plastic(roughness: f32, ior: f32, specular: f32, specular_color: Vec3) -> Material {
    Material {
        base_color: [1.0; 3],
        roughness,
        ior,
        specular,
        specular_color: specular_color.into(),
        ..Default::default()
    }
}

const ROUGHNESSES: [f32; 6] = [0.0, 0.02, 0.1, 0.3, 0.6, 1.0];
const COSINES: [f32; 5] = [1.0, 0.7, 0.4, 0.15, 0.05];
const SAMPLES: usize = 1024;

/// Every material of the furnace: white base, every roughness, with the core spec's layer
/// (IOR 1.5, 1, 2.4) and with `KHR_materials_specular` strengths and tints.
fn furnace_materials() -> Vec<Material> {
    let mut out = Vec::new();
    for &roughness in &ROUGHNESSES {
        for (ior, specular, colour) in [
            (1.5, 1.0, Vec3::ONE),
            (1.0, 1.0, Vec3::ONE),
            (2.4, 1.0, Vec3::ONE),
            (1.5, 0.5, Vec3::new(1.0, 0.5, 0.25)),
            (1.5, 1.0, Vec3::new(40.0, 10.0, 1.0)),
        ] {
            out.push(plastic(roughness, ior, specular, colour));
        }
    }
    out
}

/// The smallest directional albedo (white base, white tint) of the single-scattering layer at
/// `roughness` over this sweep, less about 2 standard errors of the estimate: only the light the
/// GGX layer shadows or sends below the surface is lost, and delta layers lose nothing.
fn energy_floor(roughness: f32) -> f32 {
    match roughness {
        r if r * r < DELTA_ALPHA => 1.0 - 1e-5,
        r if r <= 0.1 => 0.96,
        r if r <= 0.3 => 0.91,
        r if r <= 0.6 => 0.90,
        _ => 0.83,
    }
}

/// Each sample's weight f·cos/pdf is a ratio of sums whose terms each have a ratio at most 1
/// (ρ ≤ 1, and F·G2 / (max F·G1) ≤ 1), so no single sample may exceed 1 in any channel beyond
/// rounding; the mean over the sampled directions is the directional albedo.
#[test]
fn specular_layer_furnace_never_gains_energy_glsl_and_rust() {
    let ctx = gpu();
    let mut r = TestRng(1919);
    let (mut materials, mut inputs, mut cases) = (Vec::new(), Vec::new(), Vec::new());
    for m in furnace_materials() {
        for &c in &COSINES {
            let wo = Vec3::new((1.0 - c * c).sqrt(), 0.0, c);
            cases.push((m, wo));
            for _ in 0..SAMPLES {
                materials.push(m);
                let u = Vec4::new(r.uniform(), r.uniform(), r.uniform(), r.uniform());
                inputs.push(bsdf_input(Vec3::Z, Vec3::Z, wo, Vec3::Z, u));
            }
        }
    }
    let out = run_bsdf_oracle(&ctx, &materials, &inputs);
    let mut lowest = vec![(f32::MAX, String::new()); ROUGHNESSES.len()];
    for (c, (m, wo)) in cases.iter().enumerate() {
        let what = format!(
            "roughness {}, IOR {}, specular {} × {:?}, cos_o {}",
            m.roughness, m.ior, m.specular, m.specular_color, wo.z
        );
        let (mut gpu_sum, mut cpu_sum) = (Vec3::ZERO, Vec3::ZERO);
        for k in c * SAMPLES..(c + 1) * SAMPLES {
            let gpu_w = Vec3::from_array(out[k].sample_weight);
            let s = bsdf_sample(m, Vec3::Z, Vec3::Z, *wo, Vec4::from_array(inputs[k].u));
            for (who, w) in [("GLSL", gpu_w), ("Rust", s.weight)] {
                assert!(
                    w.is_finite() && w.min_element() >= 0.0 && w.max_element() <= 1.0 + 1e-4,
                    "{who}, {what}: a sample has weight {w}"
                );
            }
            gpu_sum += gpu_w;
            cpu_sum += s.weight;
        }
        let (gpu_mean, cpu_mean) = (gpu_sum / SAMPLES as f32, cpu_sum / SAMPLES as f32);
        // Same uniforms: the twins differ only where rounding flips a decision.
        assert!(
            (gpu_mean - cpu_mean).abs().max_element() <= 5e-3,
            "{what}: GLSL albedo {gpu_mean} vs Rust {cpu_mean}"
        );
        if Vec3::from(m.specular_color) == Vec3::ONE && m.specular == 1.0 {
            let i = ROUGHNESSES.iter().position(|&r| r == m.roughness).unwrap();
            if cpu_mean.min_element() < lowest[i].0 {
                lowest[i] = (cpu_mean.min_element(), what);
            }
        }
    }
    for (albedo, what) in &lowest {
        eprintln!("specular-layer furnace: lowest white albedo {albedo:.4} at {what}");
    }
    for (&roughness, (albedo, what)) in ROUGHNESSES.iter().zip(&lowest) {
        let floor = energy_floor(roughness);
        assert!(*albedo >= floor, "{what}: albedo {albedo} below the floor {floor}");
    }
    assert_clean(&ctx);
}

/// bsdf_sample on layered non-metals against bsdf_eval_pdf's density: bins uniform in θ (5°) and
/// φ over the sphere's upper half, plus one bin for failed samples (a GGX reflection below the
/// surface), expected counts from the pdf by an 8 × 8 midpoint rule per bin.
#[test]
fn specular_layer_sampling_chi_square() {
    const N: usize = 1_000_000;
    let (nt, np, sub) = (18usize, 24usize, 8usize);
    let cases = [
        (plastic(0.5, 1.5, 1.0, Vec3::splat(10.0)), 1.0f32),
        (plastic(0.3, 1.5, 1.0, Vec3::new(20.0, 10.0, 5.0)), 0.35),
        (plastic(0.8, 1.5, 0.7, Vec3::ONE), 0.9),
    ];
    for (m, theta_o) in cases {
        let wo = Vec3::new(theta_o.sin(), 0.0, theta_o.cos());
        let bin = |w: Vec3| {
            let theta = (w.z as f64).clamp(-1.0, 1.0).acos();
            let phi = ((w.y as f64).atan2(w.x as f64) + 2.0 * PI) % (2.0 * PI);
            let i = ((theta / (PI / 2.0) * nt as f64) as usize).min(nt - 1);
            i * np + ((phi / (2.0 * PI) * np as f64) as usize).min(np - 1)
        };
        let mut observed = vec![0.0f64; nt * np + 1];
        let mut r = TestRng(77);
        for _ in 0..N {
            let s = bsdf_sample(
                &m,
                Vec3::Z,
                Vec3::Z,
                wo,
                Vec4::new(r.uniform(), r.uniform(), r.uniform(), r.uniform()),
            );
            if s.lobe == LOBE_NONE {
                observed[nt * np] += 1.0;
            } else {
                assert!(s.wi.z > 0.0, "a layered non-metal sampled below the surface: {s:?}");
                observed[bin(s.wi)] += 1.0;
            }
        }
        let mut expected: Vec<f64> = (0..nt * np)
            .map(|k| {
                let (i, j) = (k / np, k % np);
                let (dt, dp) = (PI / 2.0 / nt as f64, 2.0 * PI / np as f64);
                let mut sum = 0.0;
                for a in 0..sub {
                    for b in 0..sub {
                        let theta = dt * (i as f64 + (a as f64 + 0.5) / sub as f64);
                        let phi = dp * (j as f64 + (b as f64 + 0.5) / sub as f64);
                        let w = Vec3::new(
                            (theta.sin() * phi.cos()) as f32,
                            (theta.sin() * phi.sin()) as f32,
                            theta.cos() as f32,
                        );
                        sum += bsdf_eval_pdf(&m, Vec3::Z, Vec3::Z, wo, w).1 as f64 * theta.sin();
                    }
                }
                N as f64 * sum * dt * dp / (sub * sub) as f64
            })
            .collect();
        let success: f64 = expected.iter().sum::<f64>() / N as f64;
        assert!(success <= 1.0 + 1e-3, "{m:?}: the pdf integrates to {success}");
        expected.push(N as f64 * (1.0 - success).max(0.0));
        let (mut chi2, mut bins) = (0.0, 0usize);
        for (&o, &e) in observed.iter().zip(&expected) {
            if e >= 5.0 {
                chi2 += (o - e).powi(2) / e;
                bins += 1;
            }
        }
        let critical = chi_square_critical_1pct(bins - 1);
        assert!(
            chi2 < critical,
            "{m:?}, theta_o {theta_o}: chi2 {chi2:.1} >= {critical:.1} ({} dof)",
            bins - 1
        );
    }
}

/// A rough non-metal's BSDF and image depend on its roughness; with `specularFactor` 0 (pure
/// Lambertian, the model before the layer) neither does: the BSDF bit for bit, the image within
/// a relative 1e-5 per pixel (two renders once differed by one ulp on a loaded machine; the
/// highlight's dependence on roughness is a factor of 3 and more).
#[test]
fn specular_layer_roughness_changes_the_bsdf_and_the_image() {
    let wo = Vec3::new(0.6, 0.0, 0.8);
    let mirror = Vec3::new(-0.6, 0.0, 0.8);
    let f = |roughness: f32, specular: f32| {
        bsdf_eval_pdf(&plastic(roughness, 1.5, specular, Vec3::ONE), Vec3::Z, Vec3::Z, wo, mirror)
            .0
            .x
    };
    assert!(
        f(0.2, 1.0) > 10.0 * f(0.8, 1.0),
        "roughness 0.2: {}, 0.8: {}",
        f(0.2, 1.0),
        f(0.8, 1.0)
    );
    assert_eq!(f(0.2, 0.0), f(0.8, 0.0), "a Lambertian non-metal ignores roughness");

    let ctx = gpu();
    let peak = |roughness: f32, specular: f32| {
        let image = render_highlight(&ctx, roughness, specular);
        assert_eq!(image.non_finite_count(), 0);
        let luminance: Vec<f32> = image.mean.iter().map(|p| p.x + p.y + p.z).collect();
        (luminance.iter().copied().fold(0.0f32, f32::max), luminance)
    };
    let (sharp, _) = peak(0.15, 1.0);
    let (broad, _) = peak(0.9, 1.0);
    assert!(sharp > 3.0 * broad, "highlight peak at roughness 0.15: {sharp}, at 0.9: {broad}");
    let (_, lambert_a) = peak(0.15, 0.0);
    let (_, lambert_b) = peak(0.9, 0.0);
    let worst = lambert_a
        .iter()
        .zip(&lambert_b)
        .map(|(a, b)| (a - b).abs() / a.abs().max(b.abs()).max(1e-6))
        .fold(0.0f32, f32::max);
    assert!(
        worst <= 1e-5,
        "a Lambertian plane's image must not depend on roughness: worst relative difference {worst}"
    );
    assert_clean(&ctx);
}

/// A white non-metal floor under a small bright quad light, seen at the light's mirror angle.
fn render_highlight(ctx: &std::sync::Arc<restir_pt::vk::Context>, roughness: f32, specular: f32) -> restir_pt::render::Image {
    use restir_pt::render::{PathTracer, RenderSettings, SceneGpu};
    use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};
    let mut b = GltfBuilder::default();
    let floor = b.material(
        "floor",
        MaterialSpec {
            specular,
            ..MaterialSpec::plastic(Vec3::splat(0.5), roughness)
        },
    );
    let light = b.material("light", MaterialSpec::emitter(Vec3::splat(50.0)));
    let plane = b.mesh(
        "floor",
        &MeshData::quad(Vec3::new(-4.0, 0.0, 4.0), Vec3::X * 8.0, Vec3::Z * -8.0),
        floor,
    );
    b.instance("floor", plane, 0.0, Vec3::ZERO);
    let lamp = b.mesh(
        "light",
        &MeshData::quad(Vec3::new(-0.2, 2.0, -2.2), Vec3::X * 0.4, Vec3::Z * 0.4),
        light,
    );
    b.instance("light", lamp, 0.0, Vec3::ZERO);
    b.camera("camera", Vec3::new(0.0, 2.0, 2.0), Vec3::ZERO, 0.9);
    let text = b.finish("highlight", Vec3::ZERO);
    let scene = restir_pt::scene::load_scene_from_bytes(text.as_bytes(), None, std::path::Path::new("highlight.gltf")).unwrap();
    let settings = RenderSettings {
        width: 32,
        height: 32,
        spp: 64,
        max_depth: 2,
        seed: 3,
        russian_roulette: false,
        camera: 0,
    };
    let mut tracer = PathTracer::new(&SceneGpu::upload(ctx, &scene).unwrap(), &settings).unwrap();
    tracer.render(&|_| {}, &std::sync::atomic::AtomicBool::new(false)).unwrap();
    tracer.image().unwrap()
}

/// `KHR_materials_specular` (factor, colour) and `KHR_materials_ior` reach the layer's F0 as the
/// extension defines it: weight · min(((ior − 1)/(ior + 1))² · colour, 1) at normal incidence.
#[test]
fn loader_reads_khr_materials_specular_into_the_layer() {
    let gltf = r#"{"asset":{"version":"2.0"},
      "extensionsUsed":["KHR_materials_specular","KHR_materials_ior"],
      "materials":[
        {"name":"tinted","pbrMetallicRoughness":{"metallicFactor":0.0},
         "extensions":{"KHR_materials_ior":{"ior":2.0},
           "KHR_materials_specular":{"specularFactor":0.5,"specularColorFactor":[1.0,0.5,20.0]}}},
        {"name":"plain","pbrMetallicRoughness":{"metallicFactor":0.0}}],
      "buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
      "bufferViews":[{"buffer":0,"byteLength":36}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]},{"primitives":[{"attributes":{"POSITION":0},"material":1}]}],
      "nodes":[{"mesh":0},{"mesh":1,"translation":[0,0,-1]}],"scenes":[{"nodes":[0,1]}],"scene":0}"#;
    let scene = restir_pt::scene::load_scene_from_bytes(gltf.as_bytes(), None, std::path::Path::new("specular.gltf")).unwrap();
    let by_name = |n: &str| scene.materials[scene.material_names.iter().position(|m| m == n).unwrap()];
    let tinted = by_name("tinted");
    let f0 = specular_layer_fresnel(&tinted, 1.0);
    let expected = 0.5 * (Vec3::new(1.0, 0.5, 20.0) / 9.0).min(Vec3::ONE);
    assert!((f0 - expected).abs().max_element() < 1e-6, "tinted F0 {f0} vs {expected}");
    let plain = specular_layer_fresnel(&by_name("plain"), 1.0);
    assert!((plain - Vec3::splat(0.04)).abs().max_element() < 1e-6, "default F0 {plain}");
    // At grazing incidence Schlick's F reaches the weight (F90 = specularFactor).
    assert!((specular_layer_fresnel(&tinted, 0.0) - Vec3::splat(0.5)).abs().max_element() < 1e-6);
}
