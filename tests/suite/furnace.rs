//! White furnace: a diffuse sphere inside a uniform environment of radiance 1, rendered by the
//! GPU path tracer. Every pixel of camera 0 sees the convex sphere, whose radiance is exactly its
//! albedo: the image mean must be within 0.5% and no pixel may be outside 4 standard errors.
//! 32x32 pixels at 1024 spp: for unbiased pixels a 4-sigma excursion somewhere in 1024 pixels has
//! a chance of about 6%, and the per-pixel variance estimates are accurate to a few percent.
//! Seeds are fixed, so the outcome is deterministic on a given driver.

use restir_pt::render::{PathTracer, RenderSettings, SceneGpu};
use restir_pt::scene::load_scene;

use crate::common::{assert_clean, gpu, repo_path};

fn furnace(albedo: f32, russian_roulette: bool) {
    let ctx = gpu();
    let mut scene = load_scene(&repo_path("scenes/furnace.gltf")).unwrap();
    assert_eq!(scene.environment, glam::Vec3::ONE);
    for m in &mut scene.materials {
        m.base_color = [albedo; 3];
    }
    let settings = RenderSettings {
        width: 32,
        height: 32,
        spp: 1024,
        max_depth: 8,
        seed: 1,
        russian_roulette,
        camera: 0,
    };
    let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, &scene).unwrap(), &settings).unwrap();
    let stats = tracer.render(&|_| {}, &std::sync::atomic::AtomicBool::new(false)).unwrap();
    assert_eq!(stats.spp, 1024);
    let image = tracer.image().unwrap();
    drop(tracer);
    assert_eq!(image.non_finite_count(), 0);
    let mean = image.average();
    for c in 0..3 {
        assert!(
            (mean[c] - albedo).abs() <= 0.005 * albedo,
            "albedo {albedo}: image mean {mean} vs analytic {albedo}"
        );
    }
    let mut worst = 0.0f32;
    for (i, (m, v)) in image.mean.iter().zip(&image.variance).enumerate() {
        for c in 0..3 {
            let z = (m[c] - albedo).abs() / v[c].sqrt().max(1e-12);
            worst = worst.max(z);
            assert!(
                z <= 4.0,
                "albedo {albedo}: pixel {i} channel {c} = {} is {z:.2} standard errors from {albedo}",
                m[c]
            );
        }
    }
    eprintln!("furnace albedo {albedo} (RR {russian_roulette}): mean {mean}, worst pixel {worst:.2} standard errors");
    assert_clean(&ctx);
}

#[test]
fn white_furnace_albedo_1() {
    furnace(1.0, true);
}

#[test]
fn white_furnace_albedo_half_without_russian_roulette() {
    furnace(0.5, false);
}

/// llvmpipe silently leaves any loop after 65535 iterations per invocation. One dispatch of 2000
/// samples per pixel overruns it; the tracer must refuse with an error, not return a dim image.
#[test]
fn over_long_dispatch_is_an_error_not_a_wrong_image() {
    let ctx = gpu();
    if ctx.info.loop_iteration_limit.is_none() {
        eprintln!("device {} has no known loop budget; nothing to check", ctx.info.name);
        return;
    }
    let scene = load_scene(&repo_path("scenes/furnace.gltf")).unwrap();
    let settings = RenderSettings {
        width: 16,
        height: 16,
        spp: 2000,
        ..Default::default()
    };
    let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, &scene).unwrap(), &settings).unwrap();
    let err = tracer
        .dispatch(2000)
        .expect_err("2000 samples in one dispatch exceed llvmpipe's loop budget");
    let typed = err.downcast_ref::<restir_pt::error::GpuError>();
    assert!(matches!(typed, Some(restir_pt::error::GpuError::LoopLimit { .. })), "{err:#}");
    drop(tracer);
    assert_clean(&ctx);
}
