//! Alpha modes in rendered images, against closed forms. A black plane cut out by a MASK
//! texture (or made stochastically transparent by BLEND) in front of a uniform environment of
//! radiance 1 (closest-hit traversal), or between a directional light and a white Lambertian
//! wall (shadow traversal): the image mean is the light let through, the uncovered fraction
//! (MASK) or 1 - alpha (BLEND). The views are set up so that the image samples the mask's
//! periods uniformly (camera axis normal to the plane, the view spanning whole periods).

use std::sync::atomic::AtomicBool;

use glam::{Vec2, Vec3};
use restir_pt::render::{Image, PathTracer, RenderSettings, SceneGpu};
use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData, FILTER_NEAREST, WRAP_REPEAT};
use restir_pt::scene::{load_scene_from_bytes, Scene};
use restir_pt::shading::texture::{ALPHA_BLEND, ALPHA_MASK};
use serde_json::json;

use crate::common::{assert_clean, gpu};

/// Texel alphas of the 2 x 2 mask (exact in 8 bits: 204/255 and 102/255).
const MASK_ALPHAS: [f32; 4] = [0.8, 0.4, 0.4, 0.4];
/// Mask periods across the view, each way.
const PERIODS: f32 = 8.0;
/// tan(yfov / 2) of the cameras: the view is 2 * distance * 0.5 wide.
const HALF_TAN: f32 = 0.5;

/// A 2 x 2 PNG, black, with the alphas of [`MASK_ALPHAS`] (row-major from the top row).
pub fn mask_png() -> Vec<u8> {
    png_with_alphas(MASK_ALPHAS)
}

/// A 2 x 2 white PNG with `alphas` (row-major from the top row, rounded to 8 bits).
pub fn png_with_alphas(alphas: [f32; 4]) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(2, 2, |x, y| {
        image::Rgba([255, 255, 255, (alphas[(y * 2 + x) as usize] * 255.0).round() as u8])
    });
    let mut out = std::io::Cursor::new(Vec::new());
    image::DynamicImage::ImageRgba8(img)
        .write_to(&mut out, image::ImageFormat::Png)
        .unwrap();
    out.into_inner()
}

/// How the screen (the black plane) is cut out.
#[derive(Clone, Copy, Debug)]
pub enum Screen {
    /// alphaMode MASK with the mask texture and this alphaCutoff.
    Mask(f32),
    /// alphaMode BLEND with baseColorFactor alpha `a`, and the mask texture if `textured`.
    Blend { a: f32, textured: bool },
}

/// Adds the black screen: a square of side 4 * `half` in the plane z = `z`, facing +z, whose
/// texture coordinates run over PERIODS periods of the mask across x, y in [-half, half].
fn add_screen(b: &mut GltfBuilder, screen: Screen, z: f32, half: f32) {
    let material = b.material("screen", MaterialSpec::diffuse(Vec3::ZERO));
    let (alpha, textured) = match screen {
        Screen::Mask(cutoff) => {
            b.set_material_field(material, &["alphaMode"], json!("MASK"));
            b.set_material_field(material, &["alphaCutoff"], json!(cutoff));
            (1.0, true)
        }
        Screen::Blend { a, textured } => {
            b.set_material_field(material, &["alphaMode"], json!("BLEND"));
            (a, textured)
        }
    };
    b.set_material_field(
        material,
        &["pbrMetallicRoughness", "baseColorFactor"],
        json!([0.0, 0.0, 0.0, alpha]),
    );
    if textured {
        let texture = b.texture(&mask_png(), "image/png", [WRAP_REPEAT, WRAP_REPEAT], FILTER_NEAREST);
        b.set_material_field(material, &["pbrMetallicRoughness", "baseColorTexture"], json!({ "index": texture }));
    }
    let s = 2.0 * half;
    let quad = MeshData::quad(Vec3::new(-s, -s, z), Vec3::X * 2.0 * s, Vec3::Y * 2.0 * s);
    let uv: Vec<Vec2> = quad
        .positions
        .iter()
        .map(|p| Vec2::new(p.x + half, half - p.y) * (PERIODS / (2.0 * half)))
        .collect();
    let mesh = b.mesh_with_attributes("screen", &quad, None, &[&uv], material);
    b.instance("screen", mesh, 0.0, Vec3::ZERO);
}

/// The screen at z = 0 seen from z = 2 (the view spans x, y in [-1, 1]) against a uniform
/// environment of radiance 1.
pub fn screen_in_front_of_the_sky(screen: Screen) -> Scene {
    let mut b = GltfBuilder::default();
    add_screen(&mut b, screen, 0.0, 1.0);
    b.camera("facing the screen", Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, 2.0 * HALF_TAN.atan());
    let text = b.finish("screen in front of the sky", Vec3::ONE);
    load_scene_from_bytes(text.as_bytes(), None, std::path::Path::new("screen.gltf")).unwrap()
}

/// A white Lambertian wall at z = 0 seen from z = 1 (the view spans x, y in [-0.5, 0.5]), lit
/// by a directional light of irradiance π along -z through the screen at z = 2, behind the
/// camera; no environment. The wall's radiance is 1 where the light reaches it.
pub fn screen_shadowing_a_wall(screen: Screen) -> Scene {
    let mut b = GltfBuilder::default();
    add_screen(&mut b, screen, 2.0, 0.5);
    let wall = b.material("wall", MaterialSpec::diffuse(Vec3::ONE));
    let w = b.mesh(
        "wall",
        &MeshData::quad(Vec3::new(-2.0, -2.0, 0.0), Vec3::X * 4.0, Vec3::Y * 4.0),
        wall,
    );
    b.instance("wall", w, 0.0, Vec3::ZERO);
    b.punctual_light(
        json!({ "type": "directional", "intensity": std::f32::consts::PI }),
        Vec3::new(0.0, 0.0, 5.0),
        -Vec3::Z,
    );
    b.camera("facing the wall", Vec3::new(0.0, 0.0, 1.0), Vec3::ZERO, 2.0 * HALF_TAN.atan());
    let text = b.finish("screen shadowing a wall", Vec3::ZERO);
    // A sun over an open wall gets the default environment unless told otherwise (--env none).
    let options = restir_pt::scene::LoadOptions {
        no_environment: true,
        ..Default::default()
    };
    let scene =
        restir_pt::scene::load_scene_from_bytes_with_options(text.as_bytes(), None, std::path::Path::new("shadow.gltf"), &options).unwrap();
    assert_eq!(scene.environment, Vec3::ZERO, "the wall must be lit by the light alone");
    scene
}

/// Path-traces camera 0 at 64 x 64 with `spp` samples per pixel.
pub fn render(scene: &Scene, spp: u32, seed: u32) -> Image {
    let ctx = gpu();
    let settings = RenderSettings {
        width: 64,
        height: 64,
        spp,
        max_depth: 4,
        seed,
        russian_roulette: false,
        camera: 0,
    };
    let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, scene).unwrap(), &settings).unwrap();
    tracer.render(&|_| {}, &AtomicBool::new(false)).unwrap();
    let image = tracer.image().unwrap();
    drop(tracer);
    assert_eq!(image.non_finite_count(), 0);
    assert_clean(&ctx);
    image
}

/// The image's mean over pixels and channels, and the standard error of that mean (from the
/// per-pixel variances of the estimate).
pub fn mean_and_error(image: &Image) -> (f64, f64) {
    let n = image.mean.len() as f64;
    let mean = image.mean.iter().map(|p| p.element_sum() as f64 / 3.0).sum::<f64>() / n;
    let var = image.variance.iter().map(|v| v.element_sum() as f64 / 3.0).sum::<f64>() / (n * n);
    (mean, var.sqrt())
}

/// MASK: the light let through equals the uncovered fraction within 1%, for cutoffs that cover
/// one texel of four (0.5: 0.75 passes), all (0.3: none passes) and none (0.9: all passes), in
/// front of the sky (closest hits) and between a light and a wall (shadow rays).
#[test]
fn alpha_mask_lets_through_the_uncovered_fraction() {
    for (cutoff, expected) in [(0.5, 0.75), (0.3, 0.0), (0.9, 1.0)] {
        for (what, scene) in [
            ("sky", screen_in_front_of_the_sky(Screen::Mask(cutoff))),
            ("shadow", screen_shadowing_a_wall(Screen::Mask(cutoff))),
        ] {
            let (mean, error) = mean_and_error(&render(&scene, 16, 1));
            println!("MASK cutoff {cutoff} ({what}): {mean:.5} (standard error {error:.5}) vs {expected}");
            assert!(
                (mean - expected).abs() <= 0.01 * expected.max(0.01),
                "MASK cutoff {cutoff} ({what}): {mean} lets through, the uncovered fraction is {expected}"
            );
        }
    }
}

/// BLEND as stochastic transparency: the light let through equals 1 - alpha (alpha 0.3
/// constant, and the mask texture's mean alpha 0.5) within 4 standard errors of the image mean
/// (two-sided, 99.994% for a normal estimate) and within 1%, through closest-hit and shadow
/// traversal.
#[test]
fn alpha_blend_lets_through_one_minus_alpha() {
    for (screen, expected) in [
        (Screen::Blend { a: 0.3, textured: false }, 0.7),
        (Screen::Blend { a: 1.0, textured: true }, 0.5),
    ] {
        for (what, scene) in [
            ("sky", screen_in_front_of_the_sky(screen)),
            ("shadow", screen_shadowing_a_wall(screen)),
        ] {
            let (mean, error) = mean_and_error(&render(&scene, 32, 2));
            let z = (mean - expected) / error;
            println!("{screen:?} ({what}): {mean:.5} (standard error {error:.5}, z {z:.2}) vs {expected}");
            assert!(
                z.abs() <= 4.0 && (mean - expected).abs() <= 0.01 * expected,
                "{screen:?} ({what}): {mean} lets through, 1 - alpha is {expected} ({z:.2} standard errors)"
            );
        }
    }
}

/// Odd alpha settings load with one warning line each, naming the file and the material: a
/// cutoff above 1 (nothing rendered) or below 0 (opaque), and an alpha mode on an emitter (kept
/// opaque). None of them stops the load, and no warning says that an alpha-tested MASK or BLEND
/// material is "ignored (rendered opaque)".
#[test]
fn alpha_odd_settings_are_warned_about() {
    let mut b = GltfBuilder::default();
    let specs = [("too high", "MASK", 1.5), ("negative", "MASK", -0.25), ("fine", "BLEND", 0.5)];
    for (name, mode, cutoff) in specs {
        let m = b.material(name, MaterialSpec::diffuse(Vec3::ONE));
        b.set_material_field(m, &["alphaMode"], json!(mode));
        b.set_material_field(m, &["alphaCutoff"], json!(cutoff));
        let mesh = b.mesh(name, &MeshData::quad(Vec3::ZERO, Vec3::X, Vec3::Y), m);
        b.instance(name, mesh, 0.0, Vec3::ZERO);
    }
    let lamp = b.material("lamp", MaterialSpec::emitter(Vec3::ONE));
    b.set_material_field(lamp, &["alphaMode"], json!("BLEND"));
    let mesh = b.mesh("lamp", &MeshData::quad(Vec3::Z, Vec3::X, Vec3::Y), lamp);
    b.instance("lamp", mesh, 0.0, Vec3::ZERO);
    let text = b.finish("odd alpha", Vec3::ONE);
    let scene = load_scene_from_bytes(text.as_bytes(), None, std::path::Path::new("odd-alpha.gltf")).unwrap();
    let warned = |what: &str| {
        scene
            .warnings
            .iter()
            .filter(|w| w.starts_with("odd-alpha.gltf: ") && w.contains(what))
            .count()
    };
    assert_eq!(
        warned("too high: alphaCutoff 1.5 is outside [0, 1]; no part of it is rendered"),
        1,
        "{:?}",
        scene.warnings
    );
    assert_eq!(
        warned("negative: alphaCutoff -0.25 is outside [0, 1]; it is rendered opaque"),
        1,
        "{:?}",
        scene.warnings
    );
    // An emitter keeps its alpha mode (its emission weighted by coverage, texture::emission_coverage).
    assert_eq!(warned("ignored on an emissive material"), 0, "{:?}", scene.warnings);
    assert_eq!(warned("fine"), 0, "{:?}", scene.warnings);
    assert_eq!(warned("ignored (rendered opaque)"), 0, "{:?}", scene.warnings);
    let modes: Vec<u32> = scene.textures.materials.iter().map(|t| t.alpha_mode).collect();
    assert_eq!(&modes[..4], &[ALPHA_MASK, ALPHA_MASK, ALPHA_BLEND, ALPHA_MASK]);
}
