//! Scenes past one binding's range (maxStorageBufferRange, 128 MiB on lavapipe: about 2.8 M
//! triangles) reach their triangles, BVH nodes and emitters by buffer device address
//! (SCENE_ADDRESSED in glsl/interface/scene_bindings.glsl). A lowered `ContextOptions::scene_binding_limit`
//! sends small scenes down that path, so that whole renders compare it with the bound layout at
//! test size; scenes really past the limit (triangles; vertex attributes) render too. The
//! vertex attributes and texels take the same path (`SurfaceGpu`). The oracles of the addressed path are
//! in bvh_oracle.rs and trace_pair_oracle.rs.

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use restir_pt::render::{Image, PathTracer, RenderSettings, Restir, RestirSettings, SceneGpu};
use restir_pt::scene::bundled_scenes::{cornell_sphere, instanced_spheres, tiled_floor, INSTANCED_SPHERE_TRIANGLES, TILE_TRIANGLES};
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
    assert_addressed_renders_as_bound(&sphere_scene(), true);
}

/// The same with vertex attributes and textures, whose arrays (`SurfaceGpu`) are addressed too:
/// the normal-mapped box (interpolated normals, tangents, texture coordinates, normal maps),
/// path traced. ReSTIR PT reads the attributes and texels through the same names of
/// glsl/interface/surface_bindings.glsl; its four textured kernels, compiled in both layouts, would add
/// minutes of llvmpipe compilation on a cold shader cache.
#[test]
fn scale_addressed_surface_attributes_and_texels_render_the_images_of_the_bound_layout() {
    let scene = crate::fixtures::normal_mapped_scene::normal_mapped_box();
    assert!(!scene.surfaces.is_empty() && !scene.textures.texels.is_empty());
    assert_addressed_renders_as_bound(&scene, false);
}

/// Renders `scene` with its arrays bound (storage buffers) and addressed (a lowered binding
/// limit) and requires the two images of the path tracer, and with `restir` of ReSTIR PT, to
/// be equal bit for bit.
fn assert_addressed_renders_as_bound(scene: &Scene, restir: bool) {
    let bound_ctx = gpu();
    let addressed_ctx = gpu_with_scene_binding_limit(Some(TINY_LIMIT));
    let bound_scene = SceneGpu::upload(&bound_ctx, scene).unwrap();
    let addressed_scene = SceneGpu::upload(&addressed_ctx, scene).unwrap();
    let surface = |g: &SceneGpu| g.surface.as_ref().map(|s| s.addressed());
    let has_surface = (!scene.surfaces.is_empty()).then_some(false);
    assert!(!bound_scene.addressed(), "the bound run must bind the arrays");
    assert_eq!(surface(&bound_scene), has_surface);
    assert!(!addressed_scene.uniform);
    assert!(addressed_scene.addressed(), "the lowered limit must address the arrays");
    assert_eq!(surface(&addressed_scene), has_surface.map(|_| true));
    let bound = path_traced(&bound_scene);
    let addressed = path_traced(&addressed_scene);
    assert_bit_identical("path tracer", &bound, &addressed);
    if restir {
        let bound = restir_frames(&bound_scene);
        let addressed = restir_frames(&addressed_scene);
        assert_bit_identical("ReSTIR PT", &bound, &addressed);
    }
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

/// 992,640 triangles with vertex normals and texture coordinates (a sphere instanced 110 times by
/// EXT_mesh_gpu_instancing): 143 MB of vertex attributes, past lavapipe's 128 MiB per binding,
/// while the triangles (48 MB) fit one. The scene takes the addressed layout, attributes
/// included, and renders a finite image in which the spheres are seen.
#[test]
fn scale_vertex_attributes_past_one_binding_render() {
    let ctx = gpu();
    let text = instanced_spheres(11, 10);
    let scene = load_scene_from_bytes(text.as_bytes(), None, Path::new("instanced-spheres.gltf")).unwrap();
    assert_eq!(scene.triangles.len(), 110 * INSTANCED_SPHERE_TRIANGLES);
    let bytes = std::mem::size_of_val(scene.surfaces.as_slice()) as u64;
    assert_eq!(bytes, 142_940_160);
    if bytes <= ctx.info.max_storage_buffer_range {
        eprintln!("this device binds {bytes} bytes at once; nothing to test");
        return;
    }
    assert!(ctx.info.buffer_device_address, "the device lacks bufferDeviceAddress");
    let settings = RenderSettings {
        width: 16,
        height: 16,
        spp: 1,
        ..Default::default()
    };
    let scene_gpu = SceneGpu::upload(&ctx, &scene).unwrap();
    assert!(scene_gpu.addressed() && scene_gpu.surface.as_ref().unwrap().addressed());
    let mut tracer = PathTracer::new(&scene_gpu, &settings).unwrap();
    let stats = tracer.render(&|_| {}, &AtomicBool::new(false)).unwrap();
    let image = tracer.image().unwrap();
    drop(tracer);
    drop(scene_gpu);
    assert_eq!(stats.nonfinite_paths, 0);
    assert_eq!(image.non_finite_count(), 0);
    // Grey spheres (albedo 0.6) under a white sky (radiance 1): rays that miss read exactly 1,
    // those that hit a sphere almost never do.
    let spheres = image.mean.iter().filter(|p| **p != glam::Vec3::ONE).count();
    assert!(spheres >= 64, "only {spheres} of 256 pixels see a sphere: traversal missed them");
    assert_clean(&ctx);
}
