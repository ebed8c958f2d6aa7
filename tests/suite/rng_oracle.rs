//! GLSL glsl/shading_core/rng.glsl against crates/shading-core/src/rng.rs: pcg4d, path_seed and rng_uniform4 must agree bit for bit.

use glam::UVec4;
use restir_pt::oracle_types::RngOracleOutput;
use restir_pt::shading::rng::{path_seed, pcg4d, rng_uniform4};

use crate::common::{assert_clean, gpu, run_oracle, TestRng};

#[test]
fn rng_pcg4d_path_seed_rng_uniform4_glsl_matches_rust_bit_exact() {
    let ctx = gpu();
    let mut r = TestRng(7);
    let n = 1 << 14;
    let mut keys: Vec<UVec4> = (0..n)
        .map(|_| UVec4::new(r.next_u64() as u32, r.next_u64() as u32, r.next_u64() as u32, r.next_u64() as u32))
        .collect();
    // Edge keys: zeros and all-ones exercise the wrap-around arithmetic.
    keys[0] = UVec4::ZERO;
    keys[1] = UVec4::MAX;
    let out: Vec<RngOracleOutput> = run_oracle(
        &ctx,
        "oracle/rng_oracle.comp",
        &[],
        &[("Inputs", bytemuck::cast_slice(&keys))],
        n * std::mem::size_of::<RngOracleOutput>() / 4,
        n as u32,
    );
    for (k, g) in keys.iter().zip(&out) {
        assert_eq!(UVec4::from_array(g.pcg4d), pcg4d(*k), "pcg4d({k})");
        assert_eq!(g.path_seed, path_seed(k.x, k.y, k.z), "path_seed({k})");
        let u = rng_uniform4(k.x, k.y, k.z);
        assert_eq!(g.uniforms.map(f32::to_bits), u.to_array().map(f32::to_bits), "rng_uniform4({k})");
    }
    assert_clean(&ctx);
}

#[test]
fn rng_uniform4_is_in_unit_interval_and_uniform() {
    // 2^20 draws, 64 bins: chi-square at the 1% level.
    let bins = 64;
    let mut counts = vec![0u64; bins];
    let draws = 1u32 << 18;
    for i in 0..draws {
        let u = rng_uniform4(path_seed(i, 3, 11), 2, 1);
        for x in u.to_array() {
            assert!((0.0..1.0).contains(&x), "{x} outside [0, 1)");
            counts[(x * bins as f32) as usize] += 1;
        }
    }
    let expected = (draws as f64 * 4.0) / bins as f64;
    let chi2: f64 = counts.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum();
    let critical = crate::fixtures::statistics::chi_square_critical_1pct(bins - 1);
    assert!(chi2 < critical, "chi2 {chi2:.1} >= {critical:.1}");
}
