//! ReSTIR PT on the GPU (and the path tracer's sums): bit-identical images per seed, kernels compiled at start-up only, and
//! what the emission rays, temporal reuse and reservoirs per pixel must buy; unbiasedness is in
//! restir_unbiased.rs.

use std::sync::atomic::AtomicBool;

use restir_pt::metrics::{mse, rel_mse};
use restir_pt::render::{PassKernel, PathTracer, RenderSettings, Restir, RestirSettings, SceneGpu};
use restir_pt::scene::{load_scene, Scene};

use crate::common::{assert_clean, gpu, repo_path};
use crate::fixtures::unbiasedness::{luminance, settings, FRAMES};

/// The path tracer's sums add up in sample order however the samples are split into
/// dispatches (whose sizes `render` picks from timing), so equal seeds give equal bits.
#[test]
fn path_tracer_image_is_bit_identical_whatever_the_dispatch_split() {
    let ctx = gpu();
    let scene = load_scene(&repo_path("scenes/cornell.gltf")).unwrap();
    let settings = RenderSettings {
        width: 24,
        height: 16,
        spp: 12,
        seed: 5,
        ..Default::default()
    };
    let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, &scene).unwrap(), &settings).unwrap();
    let mut split = |chunks: &[u32]| -> Vec<u32> {
        tracer.restart(&settings).unwrap();
        for &samples in chunks {
            tracer.dispatch(samples).unwrap();
        }
        let image = tracer.image().unwrap();
        image
            .mean
            .iter()
            .chain(&image.variance)
            .flat_map(|v| v.to_array())
            .map(f32::to_bits)
            .collect()
    };
    let whole = split(&[12]);
    assert_eq!(whole, split(&[1; 12]), "one sample per dispatch");
    assert_eq!(whole, split(&[5, 1, 6]), "uneven dispatches");
    assert_clean(&ctx);
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
    let mut renderer = Restir::new(&SceneGpu::upload(&ctx, &scene).unwrap(), &small, &RestirSettings::default()).unwrap();
    let mut chain = |seed: u32| -> Vec<u32> {
        renderer.reset(seed).unwrap();
        for camera in 0..FRAMES {
            renderer.frame(camera, false).unwrap();
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
    let mut renderer = Restir::new(&SceneGpu::upload(&ctx, &scene).unwrap(), &small, &RestirSettings::default()).unwrap();
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
        renderer.frame(camera, false).unwrap();
    }
    for _ in 0..2 {
        renderer.frame(3, true).unwrap();
    }
    renderer.set_reservoirs(2).unwrap();
    renderer.reset(3).unwrap();
    for camera in [0, 1, 1] {
        renderer.frame(camera, false).unwrap();
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
    let scene = SceneGpu::upload(&ctx, &scene).unwrap();
    let total_variance = |emission_rays: u32| -> f64 {
        let restir = RestirSettings {
            emission_rays,
            ..Default::default()
        };
        let mut renderer = Restir::new(&scene, &small, &restir).unwrap();
        renderer.reset(11).unwrap();
        for _ in 0..8 {
            renderer.frame(0, true).unwrap();
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
    let scene = SceneGpu::upload(&ctx, &scene).unwrap();
    let emission_only = RenderSettings { max_depth: 1, ..small };
    let reference = |camera: usize| {
        let settings = RenderSettings {
            spp: 2048,
            camera,
            ..emission_only.clone()
        };
        let mut pt = PathTracer::new(&scene, &settings).unwrap();
        pt.render(&|_| {}, &AtomicBool::new(false)).unwrap();
        pt.image().unwrap().mean
    };
    let (reference_0, reference_7) = (reference(0), reference(7));
    let restir = RestirSettings {
        emission_rays: 1,
        ..Default::default()
    };
    let mut renderer = Restir::new(&scene, &emission_only, &restir).unwrap();
    let frame = |renderer: &mut Restir, camera: usize| {
        renderer.frame(camera, false).unwrap();
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
        &SceneGpu::upload(ctx, &scene).unwrap(),
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
    Restir::new(&SceneGpu::upload(ctx, &scene).unwrap(), &small, &restir).unwrap()
}

/// The relMSE of `renderer`'s frame 16 alone of a static camera, averaged over 4 seeds; asserts
/// that no frame shifted a path.
fn static_frame_16_rel_mse(renderer: &mut Restir, reference: &[glam::Vec3]) -> f64 {
    let mut errors = vec![];
    for seed in 0..4 {
        renderer.reset(21 + seed).unwrap();
        for _ in 0..16 {
            let stats = renderer.frame(0, false).unwrap();
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
