//! One uploaded scene shared by several renderers: each holds it by `Arc`, and none changes
//! what another renders (the scene's buffers are read-only to every kernel).

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use restir_pt::render::{Image, PathTracer, RenderSettings, Restir, RestirSettings, SceneGpu};
use restir_pt::scene::load_scene;

use crate::common::{assert_clean, gpu, repo_path};

fn settings() -> RenderSettings {
    RenderSettings {
        width: 16,
        height: 16,
        spp: 4,
        seed: 3,
        ..Default::default()
    }
}

fn path_traced(tracer: &mut PathTracer) -> Image {
    tracer.render(&|_| {}, &AtomicBool::new(false)).unwrap();
    tracer.image().unwrap()
}

/// Frames along cameras 0 and 1, then the last frame's image.
fn restir_frames(renderer: &mut Restir) -> Image {
    renderer.reset(5).unwrap();
    for camera in [0, 1] {
        renderer.frame(camera, false).unwrap();
    }
    renderer.image().unwrap()
}

fn assert_same_bits(what: &str, a: &Image, b: &Image) {
    let bits = |image: &Image| -> Vec<u32> { image.mean.iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect() };
    assert_eq!(bits(a), bits(b), "{what}: the shared scene's image differs from its own upload's");
    assert!(a.average().x > 0.0, "{what}: the image is black");
}

/// A path tracer and a ReSTIR PT renderer built from one upload keep it alive (strong count
/// 3, back to 1 once dropped) and render, interleaved, the bit-identical images of renderers
/// that each have an upload of their own.
#[test]
fn scene_sharing_renderers_of_one_upload_render_as_with_their_own() {
    let ctx = gpu();
    let scene = load_scene(&repo_path("scenes/cornell-glossy.gltf")).unwrap();
    let shared = SceneGpu::upload(&ctx, &scene).unwrap();
    let mut tracer = PathTracer::new(&shared, &settings()).unwrap();
    let mut restir = Restir::new(&shared, &settings(), &RestirSettings::default()).unwrap();
    assert_eq!(Arc::strong_count(&shared), 3, "each renderer holds the scene");
    let shared_restir = restir_frames(&mut restir);
    let shared_pt = path_traced(&mut tracer);
    let shared_restir_again = restir_frames(&mut restir);
    drop((tracer, restir));
    assert_eq!(Arc::strong_count(&shared), 1, "dropped renderers release the scene");

    let own_pt = path_traced(&mut PathTracer::new(&SceneGpu::upload(&ctx, &scene).unwrap(), &settings()).unwrap());
    let mut own = Restir::new(&SceneGpu::upload(&ctx, &scene).unwrap(), &settings(), &RestirSettings::default()).unwrap();
    let own_restir = restir_frames(&mut own);
    drop(own);
    assert_same_bits("path tracer", &shared_pt, &own_pt);
    assert_same_bits("ReSTIR PT", &shared_restir, &own_restir);
    assert_same_bits("ReSTIR PT after the path tracer", &shared_restir_again, &own_restir);
    assert_clean(&ctx);
}
