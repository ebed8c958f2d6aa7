//! KHR_lights_punctual against closed forms: a diffuse plane of albedo ρ lit only by one punctual
//! light shows radiance L = (ρ/π) E, with E = I cos θ / d² for a point light (times the cone
//! falloff for a spot) and E = I cos θ for a directional one. With max depth 2 (direct light
//! only; a plane cannot light itself) and no environment, every path-traced sample is that
//! value at its jittered primary hit, so each pixel must be within 1% of the closed form averaged
//! over the pixel's footprint. ReSTIR PT reuses
//! paths onto the delta light through its shifts (Jacobian 1 for a reconnection onto it): its
//! image's sum must meet the same 1% bar and each pixel a bar set by its 64 frames of jitter,
//! which a wrong Jacobian, MIS weight or light pdf would miss.

use glam::Vec3;
use restir_pt::render::{Image, PathTracer, RenderSettings, Restir, RestirSettings, SceneGpu, ShiftKind};
use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};
use restir_pt::scene::{load_scene_reporting, LoadOptions, Scene};
use restir_pt::shading::lights::spot_falloff;
use serde_json::{json, Value};

use crate::common::{assert_clean, gpu, temp_file};

const ALBEDO: f32 = 0.5;
const SIDE: u32 = 32;
/// Static-camera ReSTIR PT frames averaged: each pixel sees FRAMES jittered positions, so its
/// jitter noise is up to 0.2/sqrt(12 FRAMES) = 0.72% (the tolerance is 5.5 sigma); the sum over
/// hundreds of pixels carries the 1% bar.
const FRAMES: usize = 64;
const RESTIR_PIXEL_TOLERANCE: f32 = 0.04;

fn plane_scene(name: &str, light: Value, position: Vec3, direction: Vec3) -> Scene {
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(ALBEDO)));
    let plane = MeshData::quad(Vec3::new(-4.0, 0.0, -4.0), Vec3::Z * 8.0, Vec3::X * 8.0);
    let m = b.mesh("plane", &plane, grey);
    b.instance("plane", m, 0.0, Vec3::ZERO);
    b.punctual_light(light, position, direction);
    b.camera("camera", Vec3::new(0.0, 2.5, 2.5), Vec3::ZERO, 0.9);
    let path = temp_file(name, b.finish(name, Vec3::ZERO).as_bytes());
    // An open plane: the default environment would join the light (`--env none` keeps it out).
    let options = LoadOptions {
        no_environment: true,
        ..Default::default()
    };
    let scene = load_scene_reporting(&path, &options, &mut Vec::new()).unwrap();
    assert_eq!(scene.environment, Vec3::ZERO, "the light must be the only one");
    assert_eq!(scene.lights.len(), 1);
    scene
}

/// (ρ/π) E at point x of the plane y = 0 (normal +Y).
fn closed_form(scene: &Scene, x: Vec3) -> Vec3 {
    let l = &scene.lights[0];
    let e = match l.kind {
        restir_pt::scene::PunctualKind::Directional => l.intensity * (-l.direction).y.max(0.0),
        _ => {
            let to = l.position - x;
            let d2 = to.length_squared();
            let dir = to / d2.sqrt();
            l.intensity * dir.y.max(0.0) * spot_falloff(l, -dir) / d2
        }
    };
    e * ALBEDO / std::f32::consts::PI
}

/// The plane point seen through image point (px, py), if the ray hits the plane; in scene
/// coordinates (relative to `scene.origin`, like the camera and the light), the plane being
/// y = 0 and |x|, |z| < 4 in world coordinates.
fn plane_hit(scene: &Scene, px: f32, py: f32) -> Option<Vec3> {
    let c = &scene.cameras[0];
    let origin = scene.origin.as_vec3();
    let d = c.ray_dir(px, py, SIDE, SIDE);
    let t = (-origin.y - c.position.y) / d.y;
    let x = c.position + t * d;
    let world = x + origin;
    (t > 0.0 && world.x.abs() < 4.0 && world.z.abs() < 4.0).then_some(x)
}

/// The closed form averaged over the pixel's footprint (a 16x16 grid), as the camera's uniform
/// sub-pixel jitter averages it, and its relative range there (max - min) / mean.
fn pixel_mean(scene: &Scene, x: u32, y: u32) -> (Vec3, f32) {
    const N: u32 = 16;
    let (mut sum, mut lo, mut hi) = (Vec3::ZERO, f32::INFINITY, 0.0f32);
    for j in 0..N {
        for i in 0..N {
            let (px, py) = (x as f32 + (i as f32 + 0.5) / N as f32, y as f32 + (j as f32 + 0.5) / N as f32);
            let v = closed_form(scene, plane_hit(scene, px, py).expect("the footprint is on the plane"));
            sum += v;
            lo = lo.min(v.x);
            hi = hi.max(v.x);
        }
    }
    let mean = sum / (N * N) as f32;
    (mean, (hi - lo) / mean.x)
}

/// Compares every pixel whose footprint lies on the plane, whose expected radiance is not tiny
/// and varies by at most 20% across the footprint (where the jitter's noise stays well below
/// the tolerance: the sample standard deviation is then under 0.2/sqrt(12) of the value):
/// each pixel within `pixel_tol`, their sum within 1%. Returns (pixels, worst error, sum error).
fn compare(scene: &Scene, image: &Image, what: &str, pixel_tol: f32) -> (usize, f32, f32) {
    let peak = (0..SIDE * SIDE)
        .filter_map(|i| plane_hit(scene, (i % SIDE) as f32 + 0.5, (i / SIDE) as f32 + 0.5))
        .map(|x| closed_form(scene, x).x)
        .fold(0.0, f32::max);
    let (mut n, mut worst, mut sum_got, mut sum_expected) = (0, 0.0f32, 0.0f64, 0.0f64);
    for y in 0..SIDE {
        for x in 0..SIDE {
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
            if corners
                .iter()
                .any(|&(dx, dy)| plane_hit(scene, x as f32 + dx, y as f32 + dy).is_none())
            {
                continue;
            }
            let (expected, range) = pixel_mean(scene, x, y);
            if expected.x < 0.05 * peak || range > 0.2 {
                continue;
            }
            let got = image.mean[(y * SIDE + x) as usize];
            let err = ((got - expected).abs() / expected).max_element();
            worst = worst.max(err);
            n += 1;
            sum_got += got.element_sum() as f64;
            sum_expected += expected.element_sum() as f64;
            assert!(
                err < pixel_tol,
                "{what}: pixel ({x}, {y}) = {got}, closed form {expected} ({:.2}% off)",
                100.0 * err
            );
        }
    }
    assert!(n > 150, "{what}: only {n} pixels compared");
    let sum_err = (sum_got / sum_expected - 1.0).abs() as f32;
    assert!(
        sum_err < 0.01,
        "{what}: the compared pixels sum to {sum_got}, the closed form to {sum_expected}"
    );
    (n, worst, sum_err)
}

fn settings(spp: u32) -> RenderSettings {
    RenderSettings {
        width: SIDE,
        height: SIDE,
        spp,
        max_depth: 2,
        seed: 3,
        ..Default::default()
    }
}

fn path_traced(scene: &Scene, spp: u32) -> Image {
    let ctx = gpu();
    let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, scene).unwrap(), &settings(spp)).unwrap();
    tracer.render(&|_| {}, &std::sync::atomic::AtomicBool::new(false)).unwrap();
    let image = tracer.image().unwrap();
    drop(tracer);
    assert_clean(&ctx);
    image
}

#[test]
fn punctual_point_spot_and_directional_lights_match_the_closed_form_irradiance() {
    let cases = [
        (
            "point.gltf",
            json!({ "type": "point", "color": [1.0, 0.8, 0.6], "intensity": 2.0 }),
            Vec3::new(0.3, 1.0, -0.2),
        ),
        (
            "spot.gltf",
            json!({ "type": "spot", "intensity": 3.0, "spot": { "innerConeAngle": 0.6, "outerConeAngle": 1.2 } }),
            Vec3::new(-0.2, 1.2, 0.1),
        ),
        ("directional.gltf", json!({ "type": "directional", "intensity": 1.5 }), Vec3::ZERO),
    ];
    for (name, light, position) in cases {
        let scene = plane_scene(name, light, position, Vec3::new(0.3, -1.0, 0.2));
        let (n, worst, sum) = compare(&scene, &path_traced(&scene, 1024), name, 0.01);
        eprintln!(
            "{name}, path tracer: {n} pixels, worst {:.3}%, sum {:.3}%",
            100.0 * worst,
            100.0 * sum
        );
    }
}

#[test]
fn punctual_point_light_restir_matches_the_closed_form_irradiance() {
    let scene = plane_scene(
        "point.gltf",
        json!({ "type": "point", "intensity": 2.0 }),
        Vec3::new(0.3, 1.0, -0.2),
        -Vec3::Y,
    );
    let ctx = gpu();
    // Hybrid shifts reconnect at r = 2 here (every path is x1 -> light): the reconnection shift's
    // case. Each shift kind costs a kernel compile of about a minute on lavapipe.
    for shift in [ShiftKind::Hybrid] {
        let restir = RestirSettings {
            shift,
            ..Default::default()
        };
        let mut renderer = Restir::new(&SceneGpu::upload(&ctx, &scene).unwrap(), &settings(1), &restir).unwrap();
        let mut attempted = 0;
        let mut failed = 0;
        for _ in 0..FRAMES {
            let stats = renderer.frame(0, true).unwrap();
            attempted += stats.counters.shifts_attempted;
            failed += stats.counters.shifts_failed;
        }
        let image = renderer.image().unwrap();
        drop(renderer);
        let (n, worst, sum) = compare(&scene, &image, &format!("ReSTIR PT {shift:?}"), RESTIR_PIXEL_TOLERANCE);
        eprintln!(
            "ReSTIR PT {shift:?}: {n} pixels, worst {:.3}%, sum {:.3}%, shifts failed {failed}/{attempted}",
            100.0 * worst,
            100.0 * sum
        );
        assert!(
            attempted > 0 && failed < attempted,
            "{shift:?}: reuse onto the point light never succeeded"
        );
    }
    assert_clean(&ctx);
}

/// Blender writes innerConeAngle = outerConeAngle for a spot of blend 0: loaded with a warning
/// as a hard-edged cone (the falloff's ramp is 1e-3 wide in cos θ, under a tenth of a degree
/// here), rendered without a non-finite pixel and matching the closed form; the pixels the cone's
/// edge crosses are the only ones between dark and lit.
#[test]
fn punctual_spot_with_equal_cone_angles_is_a_hard_edged_cone() {
    let light = json!({ "type": "spot", "intensity": 3.0, "spot": { "innerConeAngle": 0.7, "outerConeAngle": 0.7 } });
    let scene = plane_scene("hard-spot.gltf", light, Vec3::new(-0.2, 1.2, 0.1), Vec3::new(0.1, -1.0, 0.05));
    assert!(
        scene.warnings.iter().any(|w| w.contains("innerConeAngle equals outerConeAngle")),
        "{:?}",
        scene.warnings
    );
    let l = &scene.lights[0];
    assert_eq!(l.cos_inner, l.cos_outer);
    // The falloff is 0 outside, 1 a tenth of a degree inside, and finite on the edge itself.
    let at = |angle: f32| {
        let (x, _) = restir_pt::shading::sampling::build_onb(l.direction);
        spot_falloff(l, (l.direction * angle.cos() + x * angle.sin()).normalize())
    };
    assert_eq!(at(0.7 + 1e-3), 0.0);
    assert_eq!(at(0.7 - 0.1f32.to_radians()), 1.0);
    assert!(at(0.7).is_finite());
    let image = path_traced(&scene, 256);
    assert_eq!(image.non_finite_count(), 0);
    let (n, worst, sum) = compare(&scene, &image, "hard-edged spot", 0.01);
    // Pixels are either dark (outside), lit (inside) or cut by the edge: no soft ring.
    let peak = image.mean.iter().map(|m| m.x).fold(0.0, f32::max);
    let mut partial = 0;
    for y in 0..SIDE {
        for x in 0..SIDE {
            let hits = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].map(|(dx, dy)| plane_hit(&scene, x as f32 + dx, y as f32 + dy));
            if hits.iter().any(Option::is_none) {
                continue;
            }
            let (expected, _) = pixel_mean(&scene, x, y);
            let corners = hits.map(|p| closed_form(&scene, p.unwrap()).x);
            let cut = corners.contains(&0.0) && corners.iter().any(|&c| c > 0.0);
            partial += cut as u32;
            if !cut {
                let got = image.mean[(y * SIDE + x) as usize].x;
                assert!(got < 1e-6 || expected.x > 0.0, "pixel ({x}, {y}) outside the cone is lit: {got}");
                assert!(
                    expected.x == 0.0 || got > 0.05 * peak || expected.x < 0.05 * peak,
                    "pixel ({x}, {y})"
                );
            }
        }
    }
    eprintln!(
        "hard-edged spot: {n} pixels within {:.3}% (sum {:.3}%), {partial} pixels cut by the edge",
        100.0 * worst,
        100.0 * sum
    );
}
