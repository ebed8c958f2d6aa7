//! GLSL glsl/shading_core/sampling.glsl against crates/shading-core/src/sampling.rs on random uniforms and directions.

use glam::{Vec2, Vec3, Vec4};
use restir_pt::oracle_types::{SamplingOracleInput, SamplingOracleOutput};
use restir_pt::shading::sampling::*;

use crate::common::{assert_clean, assert_vec3_close, close, gpu, run_oracle, TestRng};

/// Transcendentals differ by a few ulps between llvmpipe and Rust's libm.
const TOL: f32 = 2e-5;

#[test]
fn sampling_glsl_matches_rust() {
    let ctx = gpu();
    let mut r = TestRng(21);
    let n = 1 << 14;
    let inputs: Vec<SamplingOracleInput> = (0..n)
        .map(|_| {
            let u = [r.uniform(), r.uniform(), r.uniform(), r.uniform()];
            let alpha = 10f32.powf(-3.0 + 3.0 * r.uniform());
            SamplingOracleInput {
                u,
                direction: r.unit_vector().to_array(),
                alpha,
            }
        })
        .collect();
    let out: Vec<SamplingOracleOutput> = run_oracle(
        &ctx,
        "oracle/sampling_oracle.comp",
        &[],
        &[("Inputs", bytemuck::cast_slice(&inputs))],
        n * std::mem::size_of::<SamplingOracleOutput>() / 4,
        n as u32,
    );
    for (i, (input, o)) in inputs.iter().zip(&out).enumerate() {
        let (u, p) = (Vec4::from_array(input.u), Vec3::from_array(input.direction).extend(input.alpha));
        let n_dir = p.truncate().normalize();
        let (t, b) = build_onb(n_dir);
        assert_vec3_close(
            format_args!("sample_cosine_hemisphere item {i}"),
            Vec3::from_array(o.cosine_hemisphere),
            sample_cosine_hemisphere(Vec2::new(u.x, u.y)),
            TOL,
        );
        assert!(
            close(o.cosine_pdf, pdf_cosine_hemisphere(u.z * 2.0 - 1.0), TOL),
            "pdf_cosine_hemisphere item {i}"
        );
        assert_vec3_close(
            format_args!("sample_uniform_sphere item {i}"),
            Vec3::from_array(o.uniform_sphere),
            sample_uniform_sphere(Vec2::new(u.x, u.y)),
            TOL,
        );
        assert!(close(o.power_heuristic, power_heuristic(u.z, u.w), TOL), "power_heuristic item {i}");
        let tri = sample_triangle(Vec2::new(u.x, u.y));
        let disk = sample_concentric_disk(Vec2::new(u.z, u.w));
        assert_vec3_close(
            format_args!("sample_triangle item {i}"),
            Vec2::from_array(o.triangle).extend(0.0),
            tri.extend(0.0),
            TOL,
        );
        assert_vec3_close(
            format_args!("sample_concentric_disk item {i}"),
            Vec2::from_array(o.concentric_disk).extend(0.0),
            disk.extend(0.0),
            TOL,
        );
        let wo = Vec3::new(p.x, p.y, p.z.abs() + 1e-3).normalize();
        assert_vec3_close(
            format_args!("sample_ggx_vndf item {i}"),
            Vec3::from_array(o.ggx_vndf),
            sample_ggx_vndf(wo, p.w, Vec2::new(u.x, u.y)),
            1e-4,
        );
        assert_vec3_close(format_args!("build_onb t item {i}"), Vec3::from_array(o.onb_tangent), t, TOL);
        assert_vec3_close(format_args!("build_onb b item {i}"), Vec3::from_array(o.onb_bitangent), b, TOL);
        assert_vec3_close(
            format_args!("to_local/to_world item {i}"),
            Vec3::from_array(o.round_trip),
            u.truncate(),
            TOL,
        );
    }
    assert_clean(&ctx);
}

#[test]
fn build_onb_is_orthonormal_for_every_normal() {
    let mut r = TestRng(5);
    let mut normals: Vec<Vec3> = (0..10_000).map(|_| r.unit_vector()).collect();
    normals.extend([Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::Y, Vec3::new(0.0, 1e-7, -1.0).normalize()]);
    for n in normals {
        let (t, b) = build_onb(n);
        for (x, y) in [(t, b), (t, n), (b, n)] {
            assert!(x.dot(y).abs() < 1e-5, "not orthogonal for n = {n}");
        }
        assert!(
            (t.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5,
            "not unit for n = {n}"
        );
        assert!((t.cross(b) - n).length() < 1e-5, "not right-handed for n = {n}");
    }
}
