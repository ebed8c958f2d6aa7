//! GLSL glsl/shading_core/sampling.glsl against crates/shading-core/src/sampling.rs on random uniforms and directions.

use glam::{Vec2, Vec3, Vec4};
use restir_pt::shading::sampling::*;

use crate::common::{assert_clean, assert_vec3_close, close, gpu, run_oracle, TestRng};

/// Transcendentals differ by a few ulps between llvmpipe and Rust's libm.
const TOL: f32 = 2e-5;

#[test]
fn sampling_glsl_matches_rust() {
    let ctx = gpu();
    let mut r = TestRng(21);
    let n = 1 << 14;
    let mut inputs = Vec::with_capacity(2 * n);
    for _ in 0..n {
        inputs.push(Vec4::new(r.uniform(), r.uniform(), r.uniform(), r.uniform()));
        let alpha = 10f32.powf(-3.0 + 3.0 * r.uniform());
        inputs.push(r.unit_vector().extend(alpha));
    }
    let out: Vec<Vec4> = run_oracle(
        &ctx,
        "oracle/sampling_oracle.comp",
        &[],
        &[("Inputs", bytemuck::cast_slice(&inputs))],
        n * 7 * 4,
        n as u32,
    );
    for i in 0..n {
        let (u, p) = (inputs[2 * i], inputs[2 * i + 1]);
        let o = &out[7 * i..7 * i + 7];
        let n_dir = p.truncate().normalize();
        let (t, b) = build_onb(n_dir);
        assert_vec3_close(
            format_args!("sample_cosine_hemisphere item {i}"),
            o[0].truncate(),
            sample_cosine_hemisphere(Vec2::new(u.x, u.y)),
            TOL,
        );
        assert!(
            close(o[0].w, pdf_cosine_hemisphere(u.z * 2.0 - 1.0), TOL),
            "pdf_cosine_hemisphere item {i}"
        );
        assert_vec3_close(
            format_args!("sample_uniform_sphere item {i}"),
            o[1].truncate(),
            sample_uniform_sphere(Vec2::new(u.x, u.y)),
            TOL,
        );
        assert!(close(o[1].w, power_heuristic(u.z, u.w), TOL), "power_heuristic item {i}");
        let tri = sample_triangle(Vec2::new(u.x, u.y));
        let disk = sample_concentric_disk(Vec2::new(u.z, u.w));
        assert_vec3_close(
            format_args!("sample_triangle item {i}"),
            Vec3::new(o[2].x, o[2].y, 0.0),
            tri.extend(0.0),
            TOL,
        );
        assert_vec3_close(
            format_args!("sample_concentric_disk item {i}"),
            Vec3::new(o[2].z, o[2].w, 0.0),
            disk.extend(0.0),
            TOL,
        );
        let wo = Vec3::new(p.x, p.y, p.z.abs() + 1e-3).normalize();
        assert_vec3_close(
            format_args!("sample_ggx_vndf item {i}"),
            o[3].truncate(),
            sample_ggx_vndf(wo, p.w, Vec2::new(u.x, u.y)),
            1e-4,
        );
        assert_vec3_close(format_args!("build_onb t item {i}"), o[4].truncate(), t, TOL);
        assert_vec3_close(format_args!("build_onb b item {i}"), o[5].truncate(), b, TOL);
        assert_vec3_close(format_args!("to_local/to_world item {i}"), o[6].truncate(), u.truncate(), TOL);
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
