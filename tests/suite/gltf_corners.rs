//! glTF corners viewers handle, each against an equivalent file or a closed form: a rotated normal
//! texture equals the same normal map with the rotation baked into its texels; COLOR_0 is
//! interpolated per hit (BoxVertexColors shows a gradient); an emitter's alpha weights its
//! emission and lets what lies behind show through; a missing texture file renders with the
//! factor; transmission leaves metals alone.

use std::sync::atomic::AtomicBool;

use glam::{Vec2, Vec3};
use restir_pt::render::{Image, PathTracer, RenderSettings, SceneGpu};
use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData, FILTER_LINEAR, WRAP_REPEAT};
use restir_pt::scene::{load_scene_from_bytes_with_options, LoadOptions, Scene};
use restir_pt::shading::bvh::{trace_closest, NO_HIT};
use serde_json::json;

use crate::common::{assert_clean, gpu, repo_path};

/// Texels per side of the normal map.
const SIDE: u32 = 16;

/// An asymmetric tangent-space normal map (no rotation maps it onto itself): slopes varying with
/// x along u and with y along v at different rates, `rotate_quarter` giving the same map turned
/// by 90 degrees with its vectors turned along (texel (x, y) takes texel (y, SIDE - 1 - x) of the
/// unturned map, and n' = (n.y, -n.x, n.z), exactly in the 8-bit encoding).
fn normal_map_png(rotate_quarter: bool) -> Vec<u8> {
    let encode = |x: u32, y: u32| {
        let (u, v) = (x as f32 / SIDE as f32, y as f32 / SIDE as f32);
        let n = Vec3::new(
            0.6 * (std::f32::consts::TAU * u).sin() + 0.2,
            0.4 * (2.0 * std::f32::consts::TAU * v).cos() - 0.1 * u,
            1.0,
        )
        .normalize();
        ((n * 0.5 + Vec3::splat(0.5)) * 255.0).round().as_uvec3()
    };
    let img = image::RgbaImage::from_fn(SIDE, SIDE, |x, y| {
        let c = if rotate_quarter {
            let c = encode(y, SIDE - 1 - x);
            glam::UVec3::new(c.y, 255 - c.x, c.z)
        } else {
            encode(x, y)
        };
        image::Rgba([c.x as u8, c.y as u8, c.z as u8, 255])
    });
    let mut out = std::io::Cursor::new(Vec::new());
    image::DynamicImage::ImageRgba8(img)
        .write_to(&mut out, image::ImageFormat::Png)
        .unwrap();
    out.into_inner()
}

/// A normal-mapped floor (y = 0, two texture periods) under a low sun, no environment: with
/// `transform`, the unturned map looked up through KHR_texture_transform rotation π/2; without,
/// the baked map.
fn bumpy_floor(transform: bool) -> Scene {
    let mut b = GltfBuilder::default();
    let floor = b.material("bumpy", MaterialSpec::diffuse(Vec3::splat(0.7)));
    let texture = b.texture(&normal_map_png(!transform), "image/png", [WRAP_REPEAT, WRAP_REPEAT], FILTER_LINEAR);
    let mut normal = json!({ "index": texture });
    if transform {
        normal["extensions"] = json!({ "KHR_texture_transform": { "rotation": std::f32::consts::FRAC_PI_2 } });
        b.declare_extension("KHR_texture_transform");
    }
    b.set_material_field(floor, &["normalTexture"], normal);
    let quad = MeshData::quad(Vec3::new(-1.0, 0.0, -1.0), Vec3::Z * 2.0, Vec3::X * 2.0);
    let uv = [Vec2::ZERO, Vec2::new(2.0, 0.0), Vec2::splat(2.0), Vec2::new(0.0, 2.0)];
    let m = b.mesh_with_attributes("floor", &quad, Some(&[Vec3::Y; 4]), &[&uv], floor);
    b.instance("floor", m, 0.0, Vec3::ZERO);
    b.punctual_light(
        json!({ "type": "directional", "intensity": 3.0 }),
        Vec3::Y,
        Vec3::new(0.8, -0.5, 0.3),
    );
    b.camera("above", Vec3::new(0.0, 2.0, 0.1), Vec3::ZERO, 0.9);
    let text = b.finish("bumpy floor", Vec3::ZERO);
    let options = LoadOptions {
        no_environment: true,
        ..Default::default()
    };
    load_scene_from_bytes_with_options(text.as_bytes(), None, std::path::Path::new("bumpy.gltf"), &options).unwrap()
}

fn render(scene: &Scene, side: u32, spp: u32) -> Image {
    let ctx = gpu();
    let settings = RenderSettings {
        width: side,
        height: side,
        spp,
        max_depth: 2,
        seed: 7,
        russian_roulette: false,
        camera: 0,
    };
    let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, scene).unwrap(), &settings).unwrap();
    tracer.render(&|_| {}, &AtomicBool::new(false)).unwrap();
    let image = tracer.image().unwrap();
    drop(tracer);
    assert_clean(&ctx);
    image
}

/// A rotated normal texture (KHR_texture_transform rotation π/2) shades as the same map with the
/// rotation baked into its texels: the shading normals of 4096 points agree within 1e-4 (without
/// turning the tangent frame they are 90 degrees apart), and the path-traced images (32², 16 spp,
/// the same seed) agree pixel for pixel within 1e-3 relative.
#[test]
fn gltf_corners_rotated_normal_texture_equals_the_rotation_baked_in() {
    let (turned, baked) = (bumpy_floor(true), bumpy_floor(false));
    let mut worst = 0.0f32;
    let mut tilted = 0;
    for k in 0..4096u32 {
        let p = Vec2::new((k % 64) as f32 + 0.37, (k / 64) as f32 + 0.61) / 64.0 * 1.8 - Vec2::splat(0.9);
        let normal_at = |s: &Scene| {
            let o = Vec3::new(p.x, 1.0, p.y) - s.origin.as_vec3();
            let hit = trace_closest(&s.nodes, &s.triangles, o, -Vec3::Y, 1e30);
            assert_ne!(hit.triangle, NO_HIT);
            s.shading_normal(hit.triangle, hit.bary)
        };
        let (a, b) = (normal_at(&turned), normal_at(&baked));
        worst = worst.max((a - b).length());
        tilted += (a.y < 0.999) as u32;
    }
    eprintln!("rotated normal texture: shading normals within {worst:e} of the baked map's; {tilted} of 4096 tilted");
    assert!(tilted > 2000, "the map must tilt most normals: {tilted}");
    assert!(worst < 1e-4, "shading normals differ by {worst}");
    let (a, b) = (render(&turned, 32, 16), render(&baked, 32, 16));
    assert_eq!(a.non_finite_count() + b.non_finite_count(), 0);
    let mut pixel_worst = 0.0f32;
    for (x, y) in a.mean.iter().zip(&b.mean) {
        let err = ((*x - *y).abs() / y.max(Vec3::splat(1e-3))).max_element();
        pixel_worst = pixel_worst.max(err);
    }
    eprintln!("rotated normal texture: images within {pixel_worst:e} per pixel");
    assert!(pixel_worst < 1e-3, "images differ by {pixel_worst}");
}

/// BoxVertexColors as published: COLOR_0 is interpolated per hit, not averaged per triangle. The
/// material is not split into per-colour variants; on every triangle the base colour at a hit
/// is the barycentric blend of the vertices' (to 1e-5); most triangles' vertices differ (the
/// gradient); and the path-traced image (32², 64 spp, the default environment) follows the
/// interpolated albedo's chromaticity (mean error under 0.05), at under a third of its error
/// against the per-triangle mean's.
#[test]
fn gltf_corners_vertex_colours_are_interpolated_per_hit() {
    let path = repo_path("../shared/assets/BoxVertexColors/BoxVertexColors.gltf");
    if !path.exists() {
        eprintln!("note: ../shared/assets absent; skipped");
        return;
    }
    let scene = restir_pt::scene::load_scene(&path).unwrap();
    assert_eq!(scene.materials.len(), 1, "{:?}", scene.material_names);
    let mut varying = 0;
    for t in 0..scene.triangles.len() as u32 {
        let corner = [Vec2::ZERO, Vec2::X, Vec2::Y].map(|b| Vec3::from(scene.material_at(t, b).base_color));
        for b in [Vec2::new(0.2, 0.3), Vec2::new(0.6, 0.1), Vec2::new(0.1, 0.85)] {
            let expected = corner[0] * (1.0 - b.x - b.y) + corner[1] * b.x + corner[2] * b.y;
            let got = Vec3::from(scene.material_at(t, b).base_color);
            assert!(
                (got - expected).abs().max_element() < 1e-5,
                "triangle {t} at {b}: {got} vs {expected}"
            );
        }
        varying += ((corner[0] - corner[1]).abs().max_element() > 0.05 || (corner[0] - corner[2]).abs().max_element() > 0.05) as u32;
    }
    assert!(varying * 2 > scene.triangles.len() as u32, "{varying} triangles vary");
    let side = 32;
    let image = render(&scene, side, 64);
    assert_eq!(image.non_finite_count(), 0);
    let chroma = |c: Vec3| c / c.element_sum().max(1e-6);
    let cam = &scene.cameras[0];
    let (mut err_interp, mut err_mean, mut n) = (0.0f32, 0.0f32, 0);
    for y in 0..side {
        for x in 0..side {
            let d = cam.ray_dir(x as f32 + 0.5, y as f32 + 0.5, side, side);
            let hit = trace_closest(&scene.nodes, &scene.triangles, cam.position, d, 1e30);
            if hit.triangle == NO_HIT {
                continue;
            }
            let t = hit.triangle;
            let interp = Vec3::from(scene.material_at(t, hit.bary).base_color);
            let mean = [Vec2::ZERO, Vec2::X, Vec2::Y]
                .map(|b| Vec3::from(scene.material_at(t, b).base_color))
                .iter()
                .sum::<Vec3>()
                / 3.0;
            let got = chroma(image.mean[(y * side + x) as usize]);
            err_interp += (got - chroma(interp)).abs().max_element();
            err_mean += (got - chroma(mean)).abs().max_element();
            n += 1;
        }
    }
    let (err_interp, err_mean) = (err_interp / n as f32, err_mean / n as f32);
    eprintln!("BoxVertexColors: {n} pixels, chromaticity off the interpolated albedo by {err_interp:.4}, off the per-triangle mean by {err_mean:.4}");
    assert!(n > 100);
    // The material's white specular layer (metallic 0.1) pales every pixel a little: measured
    // 0.035 off the albedo's chromaticity, 0.138 off the per-triangle mean's.
    assert!(err_interp < 0.05, "{err_interp}");
    assert!(err_mean > 3.0 * err_interp, "{err_mean} vs {err_interp}");
}

/// A floor lit from 1 above by a quad, seen by a camera beside it. `label`: the quad is a BLEND
/// emitter whose base colour texture is transparent on its left half (alpha 0) and opaque on its
/// right (alpha 1); otherwise an opaque emitter covering just the right half. No environment.
fn lit_floor(label: bool) -> Scene {
    let mut b = GltfBuilder::default();
    let grey = b.material("floor", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let floor = MeshData::quad(Vec3::new(-2.0, 0.0, -2.0), Vec3::Z * 4.0, Vec3::X * 4.0);
    let m = b.mesh("floor", &floor, grey);
    b.instance("floor", m, 0.0, Vec3::ZERO);
    let lamp = b.material("lamp", MaterialSpec::emitter(Vec3::splat(4.0)));
    if label {
        let img = image::RgbaImage::from_fn(2, 1, |x, _| image::Rgba([255, 255, 255, if x == 0 { 0 } else { 255 }]));
        let mut png = std::io::Cursor::new(Vec::new());
        image::DynamicImage::ImageRgba8(img)
            .write_to(&mut png, image::ImageFormat::Png)
            .unwrap();
        let t = b.texture(
            &png.into_inner(),
            "image/png",
            [WRAP_REPEAT, WRAP_REPEAT],
            restir_pt::scene::gltf_writer::FILTER_NEAREST,
        );
        b.set_material_field(lamp, &["pbrMetallicRoughness", "baseColorTexture"], json!({ "index": t }));
        b.set_material_field(lamp, &["alphaMode"], json!("BLEND"));
        let quad = MeshData::quad(Vec3::new(-0.5, 1.0, -0.25), Vec3::X, Vec3::Z * 0.5);
        let uv = [Vec2::ZERO, Vec2::new(1.0, 0.0), Vec2::ONE, Vec2::new(0.0, 1.0)];
        let q = b.mesh_with_attributes("label", &quad, None, &[&uv], lamp);
        b.instance("label", q, 0.0, Vec3::ZERO);
    } else {
        let q = b.mesh(
            "lamp",
            &MeshData::quad(Vec3::new(0.0, 1.0, -0.25), Vec3::X * 0.5, Vec3::Z * 0.5),
            lamp,
        );
        b.instance("lamp", q, 0.0, Vec3::ZERO);
    }
    b.camera("beside", Vec3::new(0.0, 0.8, 2.5), Vec3::new(0.0, 0.0, 0.0), 0.8);
    let text = b.finish("lit floor", Vec3::ZERO);
    let options = LoadOptions {
        no_environment: true,
        ..Default::default()
    };
    load_scene_from_bytes_with_options(text.as_bytes(), None, std::path::Path::new("label.gltf"), &options).unwrap()
}

/// An emitter's alpha weights its emission in every estimator: a BLEND quad, transparent on its
/// left half, lights a floor as the opaque right half alone does (light samples on the
/// transparent half add nothing, BSDF rays pass it), the images' means within 2% and 90% of the
/// pixels within 4 standard errors; seen from below, the transparent half shows what lies behind.
#[test]
fn gltf_corners_emitter_alpha_weights_the_emission() {
    let (label, half) = (lit_floor(true), lit_floor(false));
    assert!(label.warnings.iter().all(|w| !w.contains("ignored")), "{:?}", label.warnings);
    let (a, b) = (render(&label, 32, 256), render(&half, 32, 256));
    assert_eq!(a.non_finite_count(), 0);
    let (ma, mb) = (a.average(), b.average());
    let mut within = 0;
    for i in 0..a.mean.len() {
        let se = (a.variance[i] + b.variance[i]).max_element().sqrt().max(1e-6);
        within += ((a.mean[i] - b.mean[i]).abs().max_element() <= 4.0 * se) as u32;
    }
    eprintln!("emissive label: floor mean {ma} vs the opaque half's {mb}; {within} of 1024 pixels within 4 SE");
    assert!(((ma - mb).abs() / mb).max_element() < 0.02, "{ma} vs {mb}");
    assert!(within > 920, "{within}");
    // Looking up through the label: its transparent texels show no emission and no surface.
    let o = Vec3::new(-0.25, 0.5, 0.0) - label.origin.as_vec3();
    let (hit_transparent, hit_opaque) = (
        restir_pt::shading::alpha_trace::bvh_traverse(&label.nodes, &label.triangles, &label.alpha().unwrap(), o, Vec3::Y, 1e30, false),
        restir_pt::shading::alpha_trace::bvh_traverse(
            &label.nodes,
            &label.triangles,
            &label.alpha().unwrap(),
            o + Vec3::X * 0.5,
            Vec3::Y,
            1e30,
            false,
        ),
    );
    assert_eq!(hit_transparent.triangle, NO_HIT);
    assert_ne!(hit_opaque.triangle, NO_HIT);
    assert_eq!(
        Vec3::from(label.material_at(hit_opaque.triangle, hit_opaque.bary).emission),
        Vec3::splat(4.0)
    );
}

/// KHR_materials_transmission changes only the dielectric part: a metal (metallic 1) with
/// transmission 1 reflects exactly as without, and half-metal half of what it transmits.
#[test]
fn gltf_corners_transmission_leaves_metals_alone() {
    use restir_pt::gpu_types::Material;
    use restir_pt::shading::bsdf::{bsdf_eval_pdf_local, lobe_weights};
    let metal = Material {
        base_color: [0.9, 0.6, 0.3],
        metallic: 1.0,
        roughness: 0.4,
        ior: 1.5,
        specular: 1.0,
        specular_color: [1.0; 3],
        ..Default::default()
    };
    let transmissive = Material {
        transmission: 1.0,
        ..metal
    };
    assert_eq!(lobe_weights(&transmissive), (0.0, 1.0, 0.0));
    assert_eq!(
        lobe_weights(&Material {
            metallic: 0.5,
            ..transmissive
        }),
        (0.0, 0.5, 0.5)
    );
    let mut r = crate::common::TestRng(3);
    for _ in 0..1000 {
        let (wo, wi) = (r.unit_vector(), r.unit_vector());
        let (wo, wi) = (Vec3::new(wo.x, wo.y, wo.z.abs()), wi);
        assert_eq!(bsdf_eval_pdf_local(&transmissive, wo, wi), bsdf_eval_pdf_local(&metal, wo, wi));
    }
}
