//! Shading normals in the BSDF (docs/materials.md, "Shading normals"): a plane whose shading
//! normal is tilted by a known angle shades as the tilted plane in closed form, through the GLSL
//! bsdf_eval_pdf (glsl/oracle/bsdf_oracle.comp) and its Rust twin, and directions on different
//! sides of the geometric and the shading normal carry nothing (Mitsuba's strict normals).

use std::f32::consts::PI;

use glam::{Vec3, Vec4};
use restir_pt::gpu_types::Material;
use restir_pt::shading::bsdf::{bsdf_eval_pdf, sides_agree};

use crate::common::{assert_clean, bsdf_input, gpu, run_bsdf_oracle, TestRng};

/// The tilt the shading normal encodes: 25° about the x axis from the geometric normal +z.
fn tilted_normal() -> Vec3 {
    let t = 25f32.to_radians();
    Vec3::new(0.0, -t.sin(), t.cos())
}

/// A Lambertian plane (ρ = 0.7) with geometric normal +z and the tilted shading normal, lit from
/// random directions and seen from random directions: f·cos equals the closed-form shading of
/// the tilted plane, ρ/π · max(0, wi·n_tilted), within 1% (GLSL and Rust), where both
/// directions are on the same side of both normals, and is zero elsewhere. A layered non-metal
/// equals the same material on a plane whose geometric normal is the tilted one.
#[test]
fn shading_normal_tilted_plane_matches_closed_form_glsl_and_rust() {
    let ctx = gpu();
    let ns = tilted_normal();
    let lambert = Material {
        base_color: [0.7; 3],
        roughness: 1.0,
        ior: 1.5,
        ..Default::default()
    };
    let plastic = Material {
        base_color: [0.7; 3],
        roughness: 0.4,
        ior: 1.5,
        specular: 1.0,
        specular_color: [1.0; 3],
        ..Default::default()
    };
    let mut r = TestRng(2525);
    let (mut materials, mut inputs) = (Vec::new(), Vec::new());
    for i in 0..4096 {
        materials.push(if i % 2 == 0 { lambert } else { plastic });
        inputs.push(bsdf_input(
            Vec3::Z,
            ns,
            r.unit_vector(),
            r.unit_vector(),
            Vec4::new(r.uniform(), r.uniform(), r.uniform(), r.uniform()),
        ));
    }
    let out = run_bsdf_oracle(&ctx, &materials, &inputs);
    let (mut lit, mut rejected) = (0, 0);
    for (i, m) in materials.iter().enumerate() {
        let (wo, wi) = (Vec3::from_array(inputs[i].wo), Vec3::from_array(inputs[i].wi));
        let near_plane = [Vec3::Z, ns].iter().any(|n| wo.dot(*n).abs() < 1e-3 || wi.dot(*n).abs() < 1e-3);
        if near_plane {
            continue;
        }
        let gpu_f = Vec3::from_array(out[i].f);
        let (cpu_f, _) = bsdf_eval_pdf(m, Vec3::Z, ns, wo, wi);
        let agree = sides_agree(Vec3::Z, ns, wo) && sides_agree(Vec3::Z, ns, wi);
        let expected = if !agree {
            Vec3::ZERO
        } else if i % 2 == 0 {
            // Reflection on wo's side only; the tilted plane's cosine.
            let same = wo.dot(ns) * wi.dot(ns) > 0.0;
            if same {
                Vec3::splat(0.7 / PI * wi.dot(ns).abs())
            } else {
                Vec3::ZERO
            }
        } else {
            bsdf_eval_pdf(m, ns, ns, wo, wi).0
        };
        for (who, f) in [("GLSL", gpu_f), ("Rust", cpu_f)] {
            let err = (f - expected).abs().max_element();
            assert!(
                err <= 0.01 * expected.max_element() + 1e-6,
                "{who}, item {i} ({}): f·cos {f} vs the tilted plane's {expected}",
                if i % 2 == 0 { "Lambertian" } else { "layered" }
            );
        }
        if !agree {
            rejected += 1;
        } else if expected.max_element() > 0.0 {
            lit += 1;
        }
    }
    eprintln!("tilted shading normal: {lit} lit pairs equal the tilted plane, {rejected} pairs on disagreeing sides are zero");
    assert!(lit > 500 && rejected > 500, "too few cases: {lit} lit, {rejected} rejected");
    assert_clean(&ctx);
}
