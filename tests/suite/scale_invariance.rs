//! One small room rendered at scales 1e-5 to 1e5 and translated up to 1e5, by its vertices and by
//! a node transform: each image must match the unscaled render of the same seed (mean within 1%,
//! 99% of 8x8 blocks within 4 standard errors of the difference). The room's coordinates are
//! multiples of 1/64, which f32 holds exactly even at 1e5 (spacing 1/128), so the translated
//! vertices lose nothing and any difference is the renderer's.

use glam::{DVec3, Vec3};
use restir_pt::render::{Image, PathTracer, RenderSettings, Restir, RestirSettings, SceneGpu};
use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};
use restir_pt::scene::{load_scene_from_bytes, Scene};
use serde_json::{json, Value};

use crate::common::{assert_clean, gpu};

const EYE: Vec3 = Vec3::new(0.0, 0.0, 3.875);

/// How the room is moved: by its vertices (and the camera's position) or by a root node.
#[derive(Clone, Copy, Debug)]
enum Placement {
    Vertices,
    Node,
}

/// The room's glTF with every point p at `scale * p + offset`.
fn room(scale: f64, offset: DVec3, placement: Placement) -> String {
    let (s, t) = match placement {
        Placement::Vertices => (scale, offset),
        Placement::Node => (1.0, DVec3::ZERO),
    };
    let moved = |m: MeshData| MeshData {
        positions: m.positions.iter().map(|p| (s * p.as_dvec3() + t).as_vec3()).collect(),
        indices: m.indices,
    };
    let mut b = GltfBuilder::default();
    let white = b.material("white", MaterialSpec::diffuse(Vec3::splat(0.75)));
    let red = b.material("red", MaterialSpec::diffuse(Vec3::new(0.7, 0.1, 0.1)));
    let green = b.material("green", MaterialSpec::diffuse(Vec3::new(0.1, 0.6, 0.1)));
    let lamp = b.material("lamp", MaterialSpec::emitter(Vec3::splat(12.0)));
    let (x2, y2, z2, c) = (Vec3::X * 2.0, Vec3::Y * 2.0, Vec3::Z * 2.0, Vec3::splat(-1.0));
    let meshes = [
        (MeshData::quad(c, z2, x2), white),
        (MeshData::quad(Vec3::new(-1.0, 1.0, -1.0), x2, z2), white),
        (MeshData::quad(c, x2, y2), white),
        (MeshData::quad(c, y2, z2), red),
        (MeshData::quad(Vec3::new(1.0, -1.0, -1.0), z2, y2), green),
        (MeshData::cuboid(Vec3::new(-0.625, -1.0, -0.5), Vec3::new(-0.125, 0.25, 0.0)), white),
        (MeshData::cuboid(Vec3::new(0.25, -1.0, 0.0), Vec3::new(0.75, -0.5, 0.5)), white),
        (
            MeshData::quad(Vec3::new(-0.25, 0.984375, -0.25), Vec3::X * 0.5, Vec3::Z * 0.5),
            lamp,
        ),
    ];
    for (i, (mesh, material)) in meshes.into_iter().enumerate() {
        let m = b.mesh(&format!("part {i}"), &moved(mesh), material);
        b.instance(&format!("part {i}"), m, 0.0, Vec3::ZERO);
    }
    b.camera("camera", EYE, Vec3::ZERO, 0.686);
    let mut doc: Value = serde_json::from_str(&b.finish("room", Vec3::ZERO)).unwrap();
    let nodes = doc["nodes"].as_array_mut().unwrap();
    // The builder writes six decimals; the camera needs every digit at 1e-5.
    let eye = s * EYE.as_dvec3() + t;
    for node in nodes.iter_mut().filter(|n| n.get("camera").is_some()) {
        node["translation"] = json!([eye.x, eye.y, eye.z]);
    }
    if let Placement::Node = placement {
        let children: Vec<usize> = (0..nodes.len()).collect();
        nodes.push(json!({ "children": children, "scale": [scale, scale, scale], "translation": [offset.x, offset.y, offset.z] }));
        doc["scenes"][0]["nodes"] = json!([children.len()]);
    }
    serde_json::to_string(&doc).unwrap()
}

fn load(scale: f64, offset: DVec3, placement: Placement) -> Scene {
    let text = room(scale, offset, placement);
    load_scene_from_bytes(text.as_bytes(), None, std::path::Path::new("room.gltf")).unwrap()
}

const SETTINGS: RenderSettings = RenderSettings {
    width: 64,
    height: 64,
    spp: 32,
    max_depth: 6,
    seed: 3,
    russian_roulette: true,
    camera: 0,
};

fn path_traced(ctx: &std::sync::Arc<restir_pt::vk::Context>, scene: &Scene) -> Image {
    let mut tracer = PathTracer::new(&SceneGpu::upload(ctx, scene).unwrap(), &SETTINGS).unwrap();
    tracer.render(&|_| {}, &std::sync::atomic::AtomicBool::new(false)).unwrap();
    tracer.image().unwrap()
}

/// Eight accumulated ReSTIR PT frames (hybrid shifts, temporal and spatial reuse), so that every
/// shift's visibility test and the regenerated paths see the moved scene.
fn restir(ctx: &std::sync::Arc<restir_pt::vk::Context>, scene: &Scene) -> Image {
    let mut renderer = Restir::new(&SceneGpu::upload(ctx, scene).unwrap(), &SETTINGS, &RestirSettings::default()).unwrap();
    for _ in 0..8 {
        renderer.frame(0, true).unwrap();
    }
    renderer.image().unwrap()
}

/// Fails unless `image` matches `reference` within 1% in mean and in 99% of 8x8 blocks (4
/// standard errors of the difference of the block means, from the per-pixel variances).
fn assert_same_within_noise(what: &str, image: &Image, reference: &Image) {
    assert_eq!(image.non_finite_count(), 0, "{what}: non-finite pixels");
    let lum = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722)) as f64;
    let (m, r) = (lum(image.average()), lum(reference.average()));
    let (w, h) = (image.width as usize, image.height as usize);
    let (mut blocks, mut within) = (0, 0);
    for by in (0..h).step_by(8) {
        for bx in (0..w).step_by(8) {
            let (mut diff, mut var) = (0.0, 0.0);
            for y in by..by + 8 {
                for x in bx..bx + 8 {
                    let i = y * w + x;
                    diff += lum(image.mean[i]) - lum(reference.mean[i]);
                    var += lum(image.variance[i]) + lum(reference.variance[i]);
                }
            }
            blocks += 1;
            within += (diff.abs() <= 4.0 * var.sqrt() + 1e-9) as usize;
        }
    }
    eprintln!(
        "{what}: mean {m:.5} vs {r:.5} ({:+.3}%), {within}/{blocks} blocks within noise",
        100.0 * (m / r - 1.0)
    );
    assert!((m / r - 1.0).abs() <= 0.01, "{what}: mean {m} vs unscaled {r}");
    assert!(
        within as f64 >= 0.99 * blocks as f64,
        "{what}: only {within} of {blocks} blocks within noise"
    );
}

#[test]
fn scale_and_translation_leave_the_path_traced_image_unchanged() {
    let ctx = gpu();
    let reference = path_traced(&ctx, &load(1.0, DVec3::ZERO, Placement::Vertices));
    let far = DVec3::new(1e5, -1e5, 1e5);
    let mut cases: Vec<(f64, DVec3, Placement)> = Vec::new();
    for placement in [Placement::Vertices, Placement::Node] {
        for scale in [1e-5, 1e-4, 1e-2, 1e2, 1e4, 1e5] {
            cases.push((scale, DVec3::ZERO, placement));
        }
        for offset in [DVec3::splat(1e3), DVec3::splat(1e4), far] {
            cases.push((1.0, offset, placement));
        }
    }
    // Only the node's f64 transform keeps a 20 µm room 100 km from the origin.
    cases.push((1e-5, far, Placement::Node));
    for (scale, offset, placement) in cases {
        let image = path_traced(&ctx, &load(scale, offset, placement));
        assert_same_within_noise(&format!("scale {scale:e}, offset {offset}, by {placement:?}"), &image, &reference);
    }
    assert_clean(&ctx);
}

#[test]
fn scale_and_translation_leave_the_restir_image_unchanged() {
    let ctx = gpu();
    let reference = restir(&ctx, &load(1.0, DVec3::ZERO, Placement::Vertices));
    let far = DVec3::new(1e5, -1e5, 1e5);
    for (scale, offset, placement) in [
        (1e-5, DVec3::ZERO, Placement::Vertices),
        (1e5, DVec3::ZERO, Placement::Node),
        (1.0, far, Placement::Vertices),
        (1e-5, far, Placement::Node),
    ] {
        let image = restir(&ctx, &load(scale, offset, placement));
        assert_same_within_noise(
            &format!("ReSTIR PT, scale {scale:e}, offset {offset}, by {placement:?}"),
            &image,
            &reference,
        );
    }
    assert_clean(&ctx);
}
