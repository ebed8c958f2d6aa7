//! ReSTIR PT on the GPU: unbiasedness of every shift and MIS against a path-traced reference,
//! bit-identical images per seed, and the shared structs' layout.
//!
//! Unbiasedness: on 64x64 images with a moving camera (cameras 0, 1, 2: initial candidates,
//! temporal reuse with reprojection and spatial reuse), the mean of independent renders (fresh
//! seeds, cleared history; 32 on cornell, more on the harder scenes) is compared with a
//! 4096-spp path-traced reference of camera 2: total energy within 1%, and per 8x8 block a
//! two-sided Welch t-test at the 1% level. A configuration fails if its energy is off or more
//! blocks fail than chance allows at 1% (at most 3 of 64; see max_failing_blocks), or, on
//! scenes with a path-tracer control, than the unbiased path tracer fails with as many renders;
//! the pass rate is printed against the 99% bar.

use std::sync::atomic::AtomicBool;

use restir_pt::metrics::{mse, rel_mse};
use restir_pt::render::{History, Image, PassKernel, PathTracer, RenderSettings, Restir, RestirSettings, ReuseMis, ShiftKind};
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

/// One independent ReSTIR chain of FRAMES frames with `seed`, along cameras 0..FRAMES or, with
/// `static_camera`, from the last of them throughout; the last frame's image.
fn render_chain(renderer: &mut Restir, scene: &Scene, seed: u32, static_camera: bool) -> (Image, f64) {
    renderer.reset(seed).unwrap();
    let mut failed = 0.0;
    for frame in 0..FRAMES {
        let camera = if static_camera { FRAMES - 1 } else { frame };
        let stats = renderer.frame(scene, camera, false).unwrap();
        assert_eq!(stats.counters.nonfinite_pixels, 0, "non-finite pixels");
        failed = stats.failed_shift_rate();
    }
    (renderer.image().unwrap(), failed)
}

/// Independent renders of one configuration, summarised per 8x8 block for Welch's t-test
/// against the reference.
struct RenderSet {
    /// Per block: the sum of the renders' block means and of their squares.
    sums: Vec<(f64, f64)>,
    /// Per render: its energy over the reference's.
    energies: Vec<f64>,
}

impl RenderSet {
    fn new(blocks: usize) -> Self {
        Self {
            sums: vec![(0.0, 0.0); blocks],
            energies: vec![],
        }
    }

    fn add(&mut self, image: &Image, reference: &[(f64, f64)]) {
        let image_blocks = blocks(image);
        let ref_energy: f64 = reference.iter().map(|b| b.0).sum();
        self.energies.push(image_blocks.iter().map(|b| b.0).sum::<f64>() / ref_energy);
        for (s, b) in self.sums.iter_mut().zip(image_blocks) {
            s.0 += b.0;
            s.1 += b.0 * b.0;
        }
    }

    /// The mean energy ratio and its standard error between renders.
    fn energy(&self) -> (f64, f64) {
        let n = self.energies.len() as f64;
        let mean = self.energies.iter().sum::<f64>() / n;
        let var = self.energies.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (mean, (var / n).sqrt())
    }

    /// Welch's t of every block that fails the two-sided test at ALPHA.
    fn failing_blocks(&self, reference: &[(f64, f64)]) -> Vec<f64> {
        let n = self.energies.len() as f64;
        let mut failing = vec![];
        for (s, r) in self.sums.iter().zip(reference) {
            let mean = s.0 / n;
            let var_of_mean = ((s.1 / n - mean * mean) * n / (n - 1.0)).max(0.0) / n;
            let se2 = var_of_mean + r.1;
            if se2 <= 0.0 {
                continue;
            }
            let dof = se2 * se2 / (var_of_mean * var_of_mean / (n - 1.0) + r.1 * r.1 / (REFERENCE_SPP as f64 - 1.0));
            let t = (mean - r.0) / se2.sqrt();
            if student_t_two_sided(t.abs(), dof) < ALPHA {
                failing.push(t);
            }
        }
        failing
    }
}

/// How one scene's unbiasedness is judged.
struct Unbiasedness {
    scene: &'static str,
    renders: u32,
    /// Initial paths per reservoir and frame.
    candidates: u32,
    /// Reservoirs per pixel.
    reservoirs: u32,
    /// Whether the unbiased path tracer (`candidates` spp, as many renders) is put through the same block
    /// test, and a configuration may fail as many blocks as it does: on scenes whose light
    /// arrives through rare, large samples, block means of a few dozen renders are skewed
    /// (most fall below the true mean), and Welch's t-test then fails more blocks than its
    /// level says even for an exact renderer.
    path_tracer_control: bool,
    /// Whether every frame is seen from the same camera, so that temporal reuse stays within
    /// one pixel's domain instead of shifting between frames.
    static_camera: bool,
    configurations: &'static [(ShiftKind, ReuseMis)],
    /// The settings not named above.
    base: RestirSettings,
}

/// Every shift with both resampling MIS weights.
const EVERY_CONFIGURATION: &[(ShiftKind, ReuseMis)] = &[
    (ShiftKind::Reconnection, ReuseMis::GeneralizedBalance),
    (ShiftKind::Reconnection, ReuseMis::Pairwise),
    (ShiftKind::Replay, ReuseMis::GeneralizedBalance),
    (ShiftKind::Replay, ReuseMis::Pairwise),
    (ShiftKind::Hybrid, ReuseMis::GeneralizedBalance),
    (ShiftKind::Hybrid, ReuseMis::Pairwise),
];

fn check_unbiased(test: Unbiasedness) {
    let name = if test.static_camera {
        format!("{} (static camera)", test.scene)
    } else {
        test.scene.to_string()
    };
    let ctx = gpu();
    let scene = load_scene(&repo_path(&format!("scenes/{}.gltf", test.scene))).unwrap();
    let reference = blocks(&reference(&ctx, &scene));
    let mut max_failing = max_failing_blocks(reference.len());
    if test.path_tracer_control {
        let mut control = RenderSet::new(reference.len());
        for seed in 0..test.renders {
            let mut pt = PathTracer::new(
                &ctx,
                &scene,
                &RenderSettings {
                    seed: 5000 + seed,
                    ..settings(test.candidates)
                },
            )
            .unwrap();
            pt.render(&|_| {}, &AtomicBool::new(false)).unwrap();
            control.add(&pt.image().unwrap(), &reference);
        }
        let failing = control.failing_blocks(&reference);
        let (energy, energy_se) = control.energy();
        println!(
            "{name} control, path tracer at {} spp: energy ratio {energy:.4} (standard error {energy_se:.4}), failing blocks {} (t: {failing:.2?})",
            test.candidates,
            failing.len()
        );
        max_failing = max_failing.max(failing.len());
    }
    let mut failures = vec![];
    for &(shift, mis) in test.configurations {
        let restir = RestirSettings {
            shift,
            mis,
            candidates: test.candidates,
            reservoirs: test.reservoirs,
            ..test.base.clone()
        };
        let mut renderer = Restir::new(&ctx, &scene, &settings(1), &restir).unwrap();
        let mut set = RenderSet::new(reference.len());
        let mut failed_rate = 0.0;
        for seed in 0..test.renders {
            let (image, failed) = render_chain(&mut renderer, &scene, 1000 + seed, test.static_camera);
            failed_rate += failed / test.renders as f64;
            set.add(&image, &reference);
        }
        let failing = set.failing_blocks(&reference);
        let passed = reference.len() - failing.len();
        let (energy, energy_se) = set.energy();
        println!(
            "{name} {}: energy ratio {energy:.4} (standard error {energy_se:.4}), blocks passing {passed}/{} ({:.1}%; failing t: {failing:.2?}; allowed {max_failing}), failed shifts {:.1}%",
            restir.label(),
            reference.len(),
            100.0 * passed as f64 / reference.len() as f64,
            100.0 * failed_rate
        );
        if (energy - 1.0).abs() > 0.01 || failing.len() > max_failing {
            failures.push(format!(
                "{} (energy {energy:.4}, blocks {passed}/{})",
                restir.label(),
                reference.len()
            ));
        }
    }
    assert_clean(&ctx);
    assert!(failures.is_empty(), "{name}: biased against the path tracer: {failures:?}");
}

#[test]
fn restir_unbiased_cornell() {
    check_unbiased(Unbiasedness {
        scene: "cornell",
        renders: RENDERS,
        candidates: 1,
        reservoirs: 1,
        path_tracer_control: false,
        static_camera: false,
        configurations: EVERY_CONFIGURATION,
        base: RestirSettings::default(),
    });
}

// A static camera keeps each pixel's domain from frame to frame: temporal reuse takes the
// previous reservoir unshifted (same_domain in glsl/restir_reuse.glsl), and only spatial reuse
// shifts. Two configurations keep the test's time down; the identity is the same for all. Two
// reservoirs per pixel check that each keeps to its own layer's history and neighbours.
#[test]
fn restir_unbiased_cornell_static_camera() {
    check_unbiased(Unbiasedness {
        scene: "cornell",
        renders: RENDERS,
        candidates: 1,
        reservoirs: 2,
        path_tracer_control: false,
        static_camera: true,
        configurations: &[
            (ShiftKind::Reconnection, ReuseMis::GeneralizedBalance),
            (ShiftKind::Hybrid, ReuseMis::Pairwise),
        ],
        base: RestirSettings::default(),
    });
}

// The next frame's history is the reservoir before spatial reuse (ReSTIR GI's separate temporal
// and spatial reservoirs) under a moving camera, with two spatial rounds, so that the second
// round writes the previous frame's slot after the temporal pass has read it (frame_plan).
#[test]
fn restir_unbiased_cornell_temporal_history() {
    check_unbiased(Unbiasedness {
        scene: "cornell",
        renders: RENDERS,
        candidates: 1,
        reservoirs: 1,
        path_tracer_control: false,
        static_camera: false,
        configurations: &[
            (ShiftKind::Hybrid, ReuseMis::GeneralizedBalance),
            (ShiftKind::Reconnection, ReuseMis::Pairwise),
        ],
        base: RestirSettings {
            history: History::Temporal,
            rounds: 2,
            ..Default::default()
        },
    });
}

// The glossy spheres (roughness 0.05 and 0.1) reflect the small light through rare, large
// samples. With 32 renders the unbiased path tracer itself fails 6 to 10 of 64 blocks (1 to 4
// spp, all too dark), 5 with 128 and 2 with 512; hence the path-tracer control. ReSTIR PT's
// renders are heavier-tailed still: with 128 renders and inputs chosen from centre surfaces,
// two configurations failed 4 blocks each, every t negative (docs/lab-notebook.md); hence 384.
#[test]
#[ignore = "minutes; run with --ignored (docs/restir.md)"]
fn restir_unbiased_cornell_glossy() {
    check_unbiased(Unbiasedness {
        scene: "cornell-glossy",
        renders: 384,
        candidates: 1,
        reservoirs: 1,
        path_tracer_control: true,
        static_camera: false,
        configurations: EVERY_CONFIGURATION,
        base: RestirSettings::default(),
    });
}

// Light through the door gap makes whole-image energy vary between renders by 12.5% with one
// initial path per pixel (measured over 384 renders: energy 1.0018, standard error 0.0064),
// and by 14.5% for the path tracer at 1 spp; resolving 1% would take over a thousand renders
// per configuration. Eight initial paths bring it to 7.7%, so 256 renders measure energy to
// about 0.6%.
#[test]
#[ignore = "minutes; run with --ignored (docs/restir.md)"]
fn restir_unbiased_veach_door() {
    check_unbiased(Unbiasedness {
        scene: "veach-door",
        renders: 256,
        candidates: 8,
        reservoirs: 1,
        path_tracer_control: true,
        static_camera: false,
        configurations: EVERY_CONFIGURATION,
        base: RestirSettings::default(),
    });
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

// Every kernel is built and compiled when the renderer is made (llvmpipe compiles at the first
// dispatch), and no frame creates a pipeline: not a moving camera, an unmoved one, a change of
// the reservoirs per pixel or a restart.
#[test]
fn restir_compiles_every_kernel_at_start_up_and_none_in_frames() {
    let ctx = gpu();
    let (scene, small) = cornell_32_from_camera_0();
    let mut renderer = Restir::new(&ctx, &scene, &small, &RestirSettings::default()).unwrap();
    let created = ctx.pipelines_created();
    assert_eq!(created, PassKernel::ALL.len() as u64);
    let reports = renderer.compile_reports();
    assert_eq!(reports.len(), PassKernel::ALL.len());
    for k in &reports {
        assert!(
            k.spirv_bytes > 0 && k.first_dispatch_ms > 0.0 && k.total_ms() >= k.first_dispatch_ms,
            "{k:?}"
        );
    }
    for camera in 0..4 {
        renderer.frame(&scene, camera, false).unwrap();
    }
    for _ in 0..2 {
        renderer.frame(&scene, 3, true).unwrap();
    }
    renderer.set_reservoirs(2).unwrap();
    renderer.reset(3).unwrap();
    for camera in [0, 1, 1] {
        renderer.frame(&scene, camera, false).unwrap();
    }
    assert_eq!(ctx.pipelines_created(), created, "a frame created a pipeline");
    assert_clean(&ctx);
}

/// The Cornell box at 32x32 from camera 0, for tests of one pixel's frames.
fn cornell_32_from_camera_0() -> (Scene, RenderSettings) {
    let scene = load_scene(&repo_path("scenes/cornell.gltf")).unwrap();
    let small = RenderSettings {
        width: 32,
        height: 32,
        camera: 0,
        ..settings(1)
    };
    (scene, small)
}

// The emission seen at the primary hit is estimated with its own camera rays. On the Cornell
// box nearly all of a frame's pixel variance comes from the light's edge pixels, where one
// jittered ray sees the light (radiance 17) or the ceiling; sixteen rays must cut the summed
// per-pixel variance of the frame average at least fourfold (the emission term's share drops
// sixteenfold).
#[test]
fn restir_emission_rays_cut_light_edge_variance() {
    let ctx = gpu();
    let (scene, small) = cornell_32_from_camera_0();
    let total_variance = |emission_rays: u32| -> f64 {
        let restir = RestirSettings {
            emission_rays,
            ..Default::default()
        };
        let mut renderer = Restir::new(&ctx, &scene, &small, &restir).unwrap();
        renderer.reset(11).unwrap();
        for _ in 0..8 {
            renderer.frame(&scene, 0, true).unwrap();
        }
        renderer.image().unwrap().variance.iter().map(|v| luminance(*v)).sum()
    };
    let (one, sixteen) = (total_variance(1), total_variance(16));
    println!("summed pixel variance: 1 emission ray {one:.4}, 16 rays {sixteen:.4}");
    assert!(sixteen < 0.25 * one, "16 emission rays: {sixteen} against {one} with 1");
    assert_clean(&ctx);
}

// Under an unmoved camera the emission seen directly is a running mean over the frames, and a
// moved camera restarts it. Only that emission is rendered (max depth 1, one emission ray per
// frame, so a light's edge pixels are all the error; MSE, because relMSE there is decided by
// the rare ray that sees a sliver of light over a near-black reference). Frame 16 of camera 0
// must have at most a sixth of frame 1's MSE (its mean has a sixteenth of the variance;
// measured 0.0090 against 0.125, 8 seeds; 0.102 without the mean). The next frame, from
// camera 7, must be nearer camera 7's reference than camera 0's and have at most twice frame
// 1's MSE (measured 0.160 against camera 7's reference; with camera 0's mean leaked into it,
// 0.323).
#[test]
fn restir_emission_running_mean_restarts_when_the_camera_moves() {
    let ctx = gpu();
    let (scene, small) = cornell_32_from_camera_0();
    let emission_only = RenderSettings { max_depth: 1, ..small };
    let reference = |camera: usize| {
        let settings = RenderSettings {
            spp: 2048,
            camera,
            ..emission_only.clone()
        };
        let mut pt = PathTracer::new(&ctx, &scene, &settings).unwrap();
        pt.render(&|_| {}, &AtomicBool::new(false)).unwrap();
        pt.image().unwrap().mean
    };
    let (reference_0, reference_7) = (reference(0), reference(7));
    let restir = RestirSettings {
        emission_rays: 1,
        ..Default::default()
    };
    let mut renderer = Restir::new(&ctx, &scene, &emission_only, &restir).unwrap();
    let frame = |renderer: &mut Restir, camera: usize| {
        renderer.frame(&scene, camera, false).unwrap();
        renderer.image().unwrap().mean
    };
    const SEEDS: u32 = 8;
    let share = |image: &[glam::Vec3], reference: &[glam::Vec3]| mse(image, reference) / SEEDS as f64;
    let (mut first, mut sixteenth, mut moved, mut moved_against_0) = (0.0, 0.0, 0.0, 0.0);
    for seed in 0..SEEDS {
        renderer.reset(31 + seed).unwrap();
        first += share(&frame(&mut renderer, 0), &reference_0);
        for _ in 1..15 {
            frame(&mut renderer, 0);
        }
        sixteenth += share(&frame(&mut renderer, 0), &reference_0);
        let after_move = frame(&mut renderer, 7);
        moved += share(&after_move, &reference_7);
        moved_against_0 += share(&after_move, &reference_0);
    }
    println!(
        "emission MSE (mean of {SEEDS} seeds): frame 1 {first:.4}, frame 16 {sixteenth:.4}, then moved {moved:.4} (against camera 0's reference {moved_against_0:.4})"
    );
    assert!(sixteenth < first / 6.0, "frame 16: {sixteenth} against {first} in frame 1");
    assert!(
        moved < 2.0 * first && moved < moved_against_0,
        "moved camera: {moved} against {first} in frame 1 and {moved_against_0} against camera 0's reference"
    );
    assert_clean(&ctx);
}

/// A 2048-spp path-traced reference of cornell_32_from_camera_0.
fn cornell_32_reference(ctx: &std::sync::Arc<restir_pt::vk::Context>) -> Vec<glam::Vec3> {
    let (scene, small) = cornell_32_from_camera_0();
    let mut pt = PathTracer::new(
        ctx,
        &scene,
        &RenderSettings {
            spp: 2048,
            ..small.clone()
        },
    )
    .unwrap();
    pt.render(&|_| {}, &AtomicBool::new(false)).unwrap();
    pt.image().unwrap().mean
}

/// A renderer of cornell_32_from_camera_0 without spatial reuse. 64 emission rays keep the
/// light's edge pixels, which reuse cannot help, out of comparisons of frames.
fn cornell_32_temporal_only(ctx: &std::sync::Arc<restir_pt::vk::Context>, temporal: bool) -> Restir {
    let (scene, small) = cornell_32_from_camera_0();
    let restir = RestirSettings {
        temporal,
        spatial: 0,
        emission_rays: 64,
        ..Default::default()
    };
    Restir::new(ctx, &scene, &small, &restir).unwrap()
}

/// The relMSE of `renderer`'s frame 16 alone of a static camera, averaged over 4 seeds; asserts
/// that no frame shifted a path.
fn static_frame_16_rel_mse(renderer: &mut Restir, reference: &[glam::Vec3]) -> f64 {
    let (scene, _) = cornell_32_from_camera_0();
    let mut errors = vec![];
    for seed in 0..4 {
        renderer.reset(21 + seed).unwrap();
        for _ in 0..16 {
            let stats = renderer.frame(&scene, 0, false).unwrap();
            assert_eq!(stats.counters.shifts_attempted, 0, "a static camera's temporal reuse shifted paths");
        }
        errors.push(rel_mse(&renderer.image().unwrap().mean, reference));
    }
    errors.iter().sum::<f64>() / errors.len() as f64
}

// With a static camera a pixel's domain (its paths through any sub-pixel position) stays the
// same, so temporal reuse must shift nothing, and frame after frame the reservoir must hold
// a better estimate of the whole pixel: one frame after 16 with temporal reuse must have at
// most half the relMSE of a frame without reuse (measured: 0.030 against 0.158, 4 seeds; what
// remains is mostly the colour of the one path a pixel holds). When the domain was the frame's
// jittered primary hit, every frame shifted the history to a new hit; the reconnection
// Jacobians multiplied along the chain and one frame after 16 was only 1.5 times better
// (cornell, 64x64, the rows below the light).
#[test]
fn restir_static_camera_temporal_reuse_shifts_nothing_and_accumulates() {
    let ctx = gpu();
    let reference = cornell_32_reference(&ctx);
    let (without, with) = (
        static_frame_16_rel_mse(&mut cornell_32_temporal_only(&ctx, false), &reference),
        static_frame_16_rel_mse(&mut cornell_32_temporal_only(&ctx, true), &reference),
    );
    println!("frame 16 relMSE (mean of 4 seeds): {without:.4} without temporal reuse, {with:.4} with");
    assert!(with < without / 2.0, "temporal reuse: {with} against {without} without");
    assert_clean(&ctx);
}

// One reservoir shows one path, whose colour is drawn in proportion to luminance: after 16
// frames of temporal reuse that colour is most of a frame's error, and more candidates do not
// remove it. Four independent reservoirs per pixel must cut frame 16's relMSE at least
// threefold (their mean has a quarter of the variance; measured 0.0076 against 0.0304 with one
// reservoir, 4 seeds). The renderer switches to four reservoirs in place, as `compare` does.
#[test]
fn restir_reservoirs_average_down_colour_noise() {
    let ctx = gpu();
    let reference = cornell_32_reference(&ctx);
    let mut renderer = cornell_32_temporal_only(&ctx, true);
    let one = static_frame_16_rel_mse(&mut renderer, &reference);
    renderer.set_reservoirs(4).unwrap();
    let four = static_frame_16_rel_mse(&mut renderer, &reference);
    println!("frame 16 relMSE (mean of 4 seeds), temporal reuse: {one:.4} with 1 reservoir, {four:.4} with 4");
    assert!(four < one / 3.0, "4 reservoirs: {four} against {one} with 1");
    assert_clean(&ctx);
}
