//! Textured scenes made by the generator (crates/scene/src/gltf_writer/textures.rs): the textured furnace,
//! and the loader's reading of samplers, texture coordinate sets and KHR_texture_transform.

use std::sync::atomic::AtomicBool;

use glam::{Vec2, Vec3};
use restir_pt::render::{PathTracer, RenderSettings, SceneGpu};
use restir_pt::scene::gltf_writer::{textured_sphere, GltfBuilder, MaterialSpec, FILTER_LINEAR, WRAP_CLAMP_TO_EDGE, WRAP_REPEAT};
use restir_pt::scene::{load_scene_from_bytes, Scene};
use restir_pt::shading::bvh::{trace_closest, NO_HIT};
use serde_json::json;

use crate::common::{assert_clean, gpu};

/// A PNG of `w` x `h` whose sRGB texels vary smoothly (red with x, blue with y) and in blocks
/// (green checker), all channels within [40, 240] so that the albedo stays within (0, 1).
pub fn test_png(w: u32, h: u32) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(w, h, |x, y| {
        let r = 40 + (200 * x / w.max(2)) as u8;
        let b = 40 + (200 * y / h.max(2)) as u8;
        let g = if (x / 4 + y / 4) % 2 == 0 { 220 } else { 60 };
        image::Rgba([r, g, b, 255])
    });
    let mut out = std::io::Cursor::new(Vec::new());
    image::DynamicImage::ImageRgba8(img)
        .write_to(&mut out, image::ImageFormat::Png)
        .unwrap();
    out.into_inner()
}

/// A diffuse sphere (base colour factor white) textured by [`test_png`] inside a uniform
/// environment of radiance 1; camera 0 sees only the sphere.
pub fn textured_furnace_gltf() -> String {
    let mut b = GltfBuilder::default();
    let material = b.material("textured albedo", MaterialSpec::diffuse(Vec3::ONE));
    let texture = b.texture(&test_png(64, 32), "image/png", [WRAP_REPEAT, WRAP_CLAMP_TO_EDGE], FILTER_LINEAR);
    b.set_material_field(material, &["pbrMetallicRoughness", "baseColorTexture"], json!({ "index": texture }));
    let (mesh, normals, uv) = textured_sphere(Vec3::ZERO, 1.0, 48, 96);
    let m = b.mesh_with_attributes("sphere", &mesh, Some(&normals), &[&uv], material);
    b.instance("sphere", m, 0.0, Vec3::ZERO);
    b.camera("filled by the sphere", Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 0.3);
    b.finish("textured furnace", Vec3::ONE)
}

/// Per pixel, the mean and the variance of the mean of the base colour seen through the pixel
/// (`n` x `n` stratified points): what a convex diffuse object in a uniform environment of
/// radiance 1 shows, since its radiance is its albedo.
fn albedo_as_seen(scene: &Scene, width: u32, height: u32, n: u32) -> Vec<(Vec3, Vec3)> {
    let cam = &scene.cameras[0];
    let mut out = Vec::new();
    for py in 0..height {
        for px in 0..width {
            let (mut sum, mut sum_sq) = (Vec3::ZERO, Vec3::ZERO);
            for k in 0..n * n {
                let (sx, sy) = ((k % n) as f32 + 0.5, (k / n) as f32 + 0.5);
                let d = cam.ray_dir(px as f32 + sx / n as f32, py as f32 + sy / n as f32, width, height);
                let hit = trace_closest(&scene.nodes, &scene.triangles, cam.position, d, 1e30);
                assert_ne!(hit.triangle, NO_HIT, "pixel ({px}, {py}) misses the sphere");
                let a = Vec3::from(scene.material_at(hit.triangle, hit.bary).base_color);
                sum += a;
                sum_sq += a * a;
            }
            let m = (n * n) as f32;
            let mean = sum / m;
            out.push((mean, (sum_sq / m - mean * mean).max(Vec3::ZERO) / m));
        }
    }
    out
}

/// The textured furnace: the path-traced image equals the texture's albedo as seen (its mean
/// within 1% per channel; every pixel within 4.5 standard errors of the GPU estimate and the
/// reference's footprint average together).
#[test]
fn textured_furnace_image_equals_the_albedo_as_seen() {
    let ctx = gpu();
    let text = textured_furnace_gltf();
    let scene = load_scene_from_bytes(text.as_bytes(), None, std::path::Path::new("textured furnace.gltf")).unwrap();
    assert_eq!(scene.textures.headers.len(), 1);
    assert_eq!(scene.environment, Vec3::ONE);
    let (width, height) = (32, 32);
    let settings = RenderSettings {
        width,
        height,
        spp: 512,
        max_depth: 8,
        seed: 3,
        russian_roulette: false,
        camera: 0,
    };
    let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, &scene).unwrap(), &settings).unwrap();
    tracer.render(&|_| {}, &AtomicBool::new(false)).unwrap();
    let image = tracer.image().unwrap();
    drop(tracer);
    assert_eq!(image.non_finite_count(), 0);
    let reference = albedo_as_seen(&scene, width, height, 16);
    let ref_mean = reference.iter().fold(Vec3::ZERO, |a, (m, _)| a + *m) / reference.len() as f32;
    let mean = image.average();
    for c in 0..3 {
        assert!(
            (mean[c] - ref_mean[c]).abs() <= 0.01 * ref_mean[c],
            "image mean {mean} vs the albedo as seen {ref_mean}"
        );
    }
    let mut worst = 0.0f32;
    for (i, ((m, v), (r, rv))) in image.mean.iter().zip(&image.variance).zip(&reference).enumerate() {
        for c in 0..3 {
            let z = (m[c] - r[c]).abs() / (v[c] + rv[c]).sqrt().max(1e-6);
            worst = worst.max(z);
            assert!(
                z <= 4.5,
                "pixel {i} channel {c}: {} vs albedo as seen {} ({z:.2} standard errors)",
                m[c],
                r[c]
            );
        }
    }
    eprintln!("textured furnace: mean {mean} vs {ref_mean}, worst pixel {worst:.2} standard errors");
    assert_clean(&ctx);
}

/// The albedo the reference reads is the texture's: sRGB decoded, at the coordinates of the
/// sphere (u along the longitude from +X towards +Z, v down from the north pole).
#[test]
fn textured_sphere_albedo_follows_the_texture() {
    let text = textured_furnace_gltf();
    let scene = load_scene_from_bytes(text.as_bytes(), None, std::path::Path::new("textured furnace.gltf")).unwrap();
    let srgb = |byte: f32| restir_pt::shading::texture::srgb_to_linear(byte / 255.0);
    // Straight down -Z onto the sphere's +Z point: longitude 90 degrees (u = 0.25), the equator
    // (v = 0.5): texel (16, 16) of 64 x 32 and its neighbours, bilinearly.
    let eye = Vec3::new(0.0, 0.0, 3.0) - scene.origin.as_vec3();
    let hit = trace_closest(&scene.nodes, &scene.triangles, eye, -Vec3::Z, 1e30);
    let s = scene.surface_at(hit.triangle, hit.bary);
    assert!((s.uv0 - Vec2::new(0.25, 0.5)).abs().max_element() < 0.01, "uv {}", s.uv0);
    let a = Vec3::from(scene.material_at(hit.triangle, hit.bary).base_color);
    let expected_red = srgb(40.0 + (200 * 16 / 64) as f32);
    assert!((a.x - expected_red).abs() < 0.02, "red {} vs {expected_red}", a.x);
}

/// A generated quad whose base colour texture is read through TEXCOORD_1 (the transform's
/// texCoord override), with KHR_texture_transform and a nearest, mirrored/clamped sampler: the
/// loader keeps each of them, and the albedo at a point is the texel the transform leads to.
#[test]
fn texture_transform_texcoord_override_and_sampler_are_read() {
    use restir_pt::scene::gltf_writer::{MeshData, FILTER_NEAREST, WRAP_MIRRORED_REPEAT};
    use restir_pt::shading::texture::{texture_transform_rows, TEXTURE_NEAREST, TEXTURE_WRAP_CLAMP, TEXTURE_WRAP_MIRROR};
    let mut b = GltfBuilder::default();
    let material = b.material("transformed", MaterialSpec::diffuse(Vec3::ONE));
    let texture = b.texture(
        &test_png(16, 8),
        "image/png",
        [WRAP_MIRRORED_REPEAT, WRAP_CLAMP_TO_EDGE],
        FILTER_NEAREST,
    );
    let transform = json!({ "offset": [0.25, 0.5], "rotation": 0.3, "scale": [2.0, 0.5], "texCoord": 1 });
    b.set_material_field(
        material,
        &["pbrMetallicRoughness", "baseColorTexture"],
        json!({ "index": texture, "texCoord": 0, "extensions": { "KHR_texture_transform": transform } }),
    );
    b.declare_extension("KHR_texture_transform");
    let quad = MeshData::quad(Vec3::ZERO, Vec3::X, Vec3::Y);
    let uv0 = [Vec2::ZERO; 4];
    let uv1 = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)];
    let m = b.mesh_with_attributes("quad", &quad, None, &[&uv0, &uv1], material);
    b.instance("quad", m, 0.0, Vec3::ZERO);
    b.camera("front", Vec3::new(0.5, 0.5, 2.0), Vec3::new(0.5, 0.5, 0.0), 0.8);
    let text = b.finish("transform", Vec3::ONE);
    let scene = load_scene_from_bytes(text.as_bytes(), None, std::path::Path::new("transform.gltf")).unwrap();
    let h = scene.textures.headers[0];
    assert_eq!((h.width, h.height), (16, 8));
    assert_eq!(h.sampler_bits, TEXTURE_WRAP_MIRROR | (TEXTURE_WRAP_CLAMP << 2) | TEXTURE_NEAREST);
    let slot = scene.textures.materials[0].base_color;
    assert_eq!(slot.texcoord, 1);
    let (u_row, v_row) = texture_transform_rows([0.25, 0.5], 0.3, [2.0, 0.5]);
    assert_eq!((slot.u_row, slot.v_row), (u_row, v_row));
    // The point with TEXCOORD_1 (0.6, 0.3): its lookup coordinates by the rows, then the
    // mirrored-and-clamped nearest texel of test_png.
    // Scene coordinates are relative to the first camera (Scene::origin).
    let p = Vec3::new(0.6, 0.3, 0.0) - scene.origin.as_vec3();
    let hit = trace_closest(&scene.nodes, &scene.triangles, p + Vec3::Z, -Vec3::Z, 1e30);
    let uv = Vec3::new(0.6, 0.3, 1.0);
    let (u, v) = (Vec3::from(u_row).dot(uv), Vec3::from(v_row).dot(uv));
    let x = (u * 16.0).floor() as i32;
    let x = match x.rem_euclid(32) {
        m if m >= 16 => 31 - m,
        m => m,
    };
    let y = ((v * 8.0).floor() as i32).clamp(0, 7);
    let red = restir_pt::shading::texture::srgb_to_linear((40 + 200 * x / 16) as f32 / 255.0);
    let a = scene.material_at(hit.triangle, hit.bary).base_color;
    assert!((a[0] - red).abs() < 1e-5, "red {} vs texel ({x}, {y}) {red}", a[0]);
}
