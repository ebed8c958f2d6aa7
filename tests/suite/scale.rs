//! Scenes past one binding's range (maxStorageBufferRange, 128 MiB on lavapipe: about 2.8 M
//! triangles) reach their triangles, BVH nodes and emitters by buffer device address
//! (SCENE_ADDRESSED in glsl/scene_bindings.glsl). A lowered `ContextOptions::scene_binding_limit`
//! sends small scenes down that path, so that whole renders compare it with the bound layout at
//! test size; one scene really past the limit renders too. The oracles of the addressed path are
//! in bvh_oracle.rs and trace_pair_oracle.rs.

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use restir_pt::render::{Image, PathTracer, RenderSettings, Restir, RestirSettings, SceneGpu};
use restir_pt::scene::bundled_scenes::{cornell_sphere, tiled_floor, TILE_TRIANGLES};
use restir_pt::scene::{load_scene_from_bytes, Scene};

use crate::common::{assert_clean, gpu, gpu_with_scene_binding_limit};

/// A binding limit far below the test scene's arrays.
const TINY_LIMIT: u64 = 4096;

fn settings() -> RenderSettings {
    RenderSettings {
        width: 24,
        height: 24,
        spp: 8,
        max_depth: 7,
        seed: 3,
        ..Default::default()
    }
}

/// The Cornell box with a 2,280-triangle sphere: past the uniform-buffer range, so bound as
/// storage buffers by default.
fn sphere_scene() -> Scene {
    load_scene_from_bytes(cornell_sphere(20, 60).as_bytes(), None, Path::new("cornell-sphere.gltf")).unwrap()
}

fn path_traced(scene: &Arc<SceneGpu>) -> Image {
    let mut tracer = PathTracer::new(scene, &settings()).unwrap();
    tracer.render(&|_| {}, &AtomicBool::new(false)).unwrap();
    tracer.image().unwrap()
}

fn restir_frames(scene: &Arc<SceneGpu>) -> Image {
    let mut restir = Restir::new(scene, &settings(), &RestirSettings::default()).unwrap();
    for _ in 0..2 {
        restir.frame(0, true).unwrap();
    }
    restir.image().unwrap()
}

fn assert_bit_identical(what: &str, bound: &Image, addressed: &Image) {
    assert_eq!(bound.mean.len(), addressed.mean.len());
    for (i, (b, a)) in bound.mean.iter().zip(&addressed.mean).enumerate() {
        assert_eq!(
            b.to_array().map(f32::to_bits),
            a.to_array().map(f32::to_bits),
            "{what}: pixel {i}: {b} vs {a}"
        );
    }
    assert!(bound.average().x > 1e-3, "{what}: the image is black");
}

/// The addressed layout only changes where loads come from: the path tracer's and ReSTIR PT's
/// images equal the storage-buffer layout's bit for bit.
#[test]
fn scale_addressed_layout_renders_the_images_of_the_bound_layout() {
    let scene = sphere_scene();
    let bound_ctx = gpu();
    let addressed_ctx = gpu_with_scene_binding_limit(Some(TINY_LIMIT));
    let bound_scene = SceneGpu::upload(&bound_ctx, &scene).unwrap();
    let addressed_scene = SceneGpu::upload(&addressed_ctx, &scene).unwrap();
    let layout = |g: &SceneGpu| (g.uniform, g.addressed());
    assert_eq!(layout(&bound_scene), (false, false), "the bound run must use storage buffers");
    assert_eq!(layout(&addressed_scene), (false, true), "the lowered limit must address the arrays");
    let bound = path_traced(&bound_scene);
    let addressed = path_traced(&addressed_scene);
    assert_bit_identical("path tracer", &bound, &addressed);
    let bound = restir_frames(&bound_scene);
    let addressed = restir_frames(&addressed_scene);
    assert_bit_identical("ReSTIR PT", &bound, &addressed);
    assert_clean(&bound_ctx);
    assert_clean(&addressed_ctx);
}

/// 4.2 M triangles (201 MB of triangles), past lavapipe's 128 MiB per binding: the scene loads,
/// takes the addressed layout and renders a finite, lit image without a validation message.
#[test]
fn scale_scene_past_one_binding_renders() {
    let ctx = gpu();
    let scene = load_scene_from_bytes(tiled_floor(11).as_bytes(), None, Path::new("floor11.gltf")).unwrap();
    assert_eq!(scene.triangles.len(), (1 << 11) * TILE_TRIANGLES);
    let bytes = std::mem::size_of_val(scene.triangles.as_slice()) as u64;
    if bytes <= ctx.info.max_storage_buffer_range {
        eprintln!("this device binds {bytes} bytes at once; nothing to test");
        return;
    }
    assert!(ctx.info.buffer_device_address, "the device lacks bufferDeviceAddress");
    let settings = RenderSettings {
        width: 8,
        height: 8,
        spp: 1,
        ..Default::default()
    };
    let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, &scene).unwrap(), &settings).unwrap();
    let stats = tracer.render(&|_| {}, &AtomicBool::new(false)).unwrap();
    let image = tracer.image().unwrap();
    drop(tracer);
    assert_eq!(stats.nonfinite_paths, 0);
    assert_eq!(image.non_finite_count(), 0);
    // A grey floor (albedo 0.6) under a white sky (radiance 1) fills the lower part of the view:
    // camera rays that miss it read exactly 1, those that hit it almost never do.
    let floor = image.mean.iter().filter(|p| **p != glam::Vec3::ONE).count();
    assert!(floor >= 16, "only {floor} of 64 pixels see the floor: traversal missed it");
    assert_clean(&ctx);
}
