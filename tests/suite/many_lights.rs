//! Light selection by contribution (the light tree, glsl/shading/light_tree.glsl) on the GPU:
//! - a small lamp keeps its noise when a far light joins it: per-pixel standard deviation over
//!   the lamp-lit ground with and without a point light 10^6 units away or a sun over a large
//!   ground, ratio at most 2 (choosing by power made it 72);
//! - the path tracer is unbiased on a scene of many lights: a ground lit by 48 emissive panels,
//!   12 point lights, a spot and a sun against the closed-form irradiance (Lambert's polygon
//!   formula, I cos θ / d², E cos θ with the panels' sun shadows), pixel by pixel.

use glam::{Vec2, Vec3};
use restir_pt::render::{Image, PathTracer, RenderSettings, SceneGpu};
use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};
use restir_pt::scene::{load_scene_from_bytes_with_options, LoadOptions, Scene};
use restir_pt::shading::lights::spot_falloff;
use serde_json::{json, Value};

use crate::common::{assert_clean, gpu};
use crate::fixtures::unbiasedness::luminance;

const ALBEDO: f32 = 0.5;

/// A ground of half-size `ground` (scene units) under a 0.2 x 0.2 panel 0.5 above the origin
/// facing down, a lamp of radiance `lamp` (0: an unlit black panel), with `extra` lights beside
/// it (JSON, position, direction).
fn lamp_scene(name: &str, ground: f32, lamp: f32, extra: &[(Value, Vec3, Vec3)]) -> Scene {
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(ALBEDO)));
    let lamp = b.material("lamp", MaterialSpec::emitter(Vec3::splat(lamp)));
    let plane = MeshData::quad(Vec3::new(-ground, 0.0, -ground), Vec3::Z * 2.0 * ground, Vec3::X * 2.0 * ground);
    let m = b.mesh("ground", &plane, grey);
    b.instance("ground", m, 0.0, Vec3::ZERO);
    let panel = MeshData::quad(Vec3::new(-0.1, 0.5, -0.1), Vec3::X * 0.2, Vec3::Z * 0.2);
    let m = b.mesh("lamp", &panel, lamp);
    b.instance("lamp", m, 0.0, Vec3::ZERO);
    for (light, position, direction) in extra {
        b.punctual_light(light.clone(), *position, *direction);
    }
    b.camera("camera", Vec3::new(0.0, 2.0, 1.2), Vec3::ZERO, 0.7);
    without_default_sky(name, &b.finish(name, Vec3::ZERO))
}

/// The scene of glTF `text` lit by its lights alone: a sun would otherwise bring the viewer's
/// default sky (crates/scene/src/default_environment.rs), whose noise is not the lamps'.
fn without_default_sky(name: &str, text: &str) -> Scene {
    let options = LoadOptions {
        no_environment: true,
        ..Default::default()
    };
    load_scene_from_bytes_with_options(text.as_bytes(), None, std::path::Path::new(name), &options).unwrap()
}

fn path_traced(scene: &Scene, side: u32, spp: u32, max_depth: u32) -> Image {
    let ctx = gpu();
    let settings = RenderSettings {
        width: side,
        height: side,
        spp,
        max_depth,
        seed: 11,
        ..Default::default()
    };
    let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, scene).unwrap(), &settings).unwrap();
    tracer.render(&|_| {}, &std::sync::atomic::AtomicBool::new(false)).unwrap();
    let image = tracer.image().unwrap();
    drop(tracer);
    assert_clean(&ctx);
    image
}

/// The root mean square of the per-pixel standard deviations (luminance) over `pixels`.
fn rms_std(image: &Image, pixels: &[usize]) -> f64 {
    (pixels.iter().map(|&i| luminance(image.variance[i]).max(0.0)).sum::<f64>() / pixels.len() as f64).sqrt()
}

/// A sun of `lux` whose light falls at about 70 degrees, shading part of the lamp-lit ground
/// with the lamp's panel.
fn sun(lux: f32) -> (Value, Vec3, Vec3) {
    (
        json!({ "type": "directional", "intensity": lux }),
        Vec3::ZERO,
        Vec3::new(0.3, -1.0, 0.2),
    )
}

#[test]
fn many_lights_a_far_light_leaves_a_lamp_within_2x_of_its_noise_alone() {
    const SIDE: u32 = 48;
    const SPP: u32 = 64;
    let alone = lamp_scene("lamp-alone.gltf", 5.0, 20.0, &[]);
    let alone_image = path_traced(&alone, SIDE, SPP, 3);
    // The lamp-lit region: pixels at least a quarter as bright as the brightest.
    let peak = alone_image.mean.iter().map(|&v| luminance(v)).fold(0.0, f64::max);
    let lit: Vec<usize> = (0..alone_image.mean.len())
        .filter(|&i| luminance(alone_image.mean[i]) > 0.25 * peak)
        .collect();
    assert!(lit.len() > 100, "only {} lamp-lit pixels", lit.len());
    let base = rms_std(&alone_image, &lit);
    // The sun's noise is not the lamp's: where the panel's hard shadow edge crosses a pixel, the
    // pixel's value varies with the sample's position in it, however the lights are sampled.
    // Those pixels are the ones with variance under the sun and the unlit panel alone (above
    // 1% of the sun's peak: f32 sums leave 0.016% elsewhere; a half-covered edge pixel has 6%).
    let shadow = path_traced(&lamp_scene("sun-alone.gltf", 200.0, 0.0, &[sun(1.0)]), SIDE, SPP, 3);
    let sun_peak = shadow.mean.iter().map(|&v| luminance(v)).fold(0.0, f64::max);
    let off_edge: Vec<usize> = lit
        .iter()
        .copied()
        .filter(|&i| luminance(shadow.variance[i]).max(0.0).sqrt() <= 1e-2 * sun_peak)
        .collect();
    assert!(
        off_edge.len() > lit.len() / 2 && off_edge.len() < lit.len(),
        "{} of {} lamp-lit pixels off the sun's shadow edge",
        off_edge.len(),
        lit.len()
    );
    let base_off_edge = rms_std(&alone_image, &off_edge);
    // A point light 10^6 units away whose power is 10^11 times the lamp's (its irradiance here
    // 0.05); suns from 0.1 lux to 100 lux (the lamp's peak irradiance is about 3) over a
    // 400 x 400 ground; a far light and a sun together.
    let far = (
        json!({ "type": "point", "intensity": 5.0e10 }),
        Vec3::new(3.0e5, 9.5e5, 0.0),
        -Vec3::Y,
    );
    let mut cases = vec![(
        "a far point light".to_string(),
        lamp_scene("lamp-far.gltf", 5.0, 20.0, std::slice::from_ref(&far)),
    )];
    for lux in [0.1, 0.5, 2.0, 10.0, 100.0] {
        cases.push((format!("a {lux} lux sun"), lamp_scene("lamp-sun.gltf", 200.0, 20.0, &[sun(lux)])));
    }
    for lux in [2.0, 100.0] {
        cases.push((
            format!("a far point light and a {lux} lux sun"),
            lamp_scene("lamp-both.gltf", 200.0, 20.0, &[far.clone(), sun(lux)]),
        ));
    }
    for (what, scene) in cases {
        let image = path_traced(&scene, SIDE, SPP, 3);
        let ratio = rms_std(&image, &off_edge) / base_off_edge;
        let with_edge = rms_std(&image, &lit) / base;
        eprintln!(
            "lamp beside {what}: per-pixel standard deviation {ratio:.3} x the lamp's alone over {} pixels \
             ({with_edge:.3} x with the {} on the sun's shadow edge)",
            off_edge.len(),
            lit.len() - off_edge.len()
        );
        assert!(ratio <= 2.0, "lamp beside {what}: {ratio:.2} x its noise alone");
    }
}

/// The many-light scene of the closed-form test: panels, point lights, a spot, a sun.
struct ManyLights {
    scene: Scene,
    /// Each panel's lower corner (its side is PANEL), at height HEIGHT.
    panels: Vec<Vec2>,
}

const PANEL: f32 = 0.12;
const HEIGHT: f32 = 0.6;
const PANEL_RADIANCE: f32 = 30.0;

fn many_light_scene() -> ManyLights {
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(ALBEDO)));
    let lamp = b.material("lamp", MaterialSpec::emitter(Vec3::splat(PANEL_RADIANCE)));
    let plane = MeshData::quad(Vec3::new(-4.0, 0.0, -4.0), Vec3::Z * 8.0, Vec3::X * 8.0);
    let m = b.mesh("ground", &plane, grey);
    b.instance("ground", m, 0.0, Vec3::ZERO);
    let (mut mesh, mut panels) = (MeshData::default(), vec![]);
    for i in 0..64 {
        let (gx, gz) = ((i % 8) as f32, (i / 8) as f32);
        let c = Vec2::new(-3.5 + gx + 0.3 * (gz * 1.7).sin(), -3.5 + gz + 0.3 * (gx * 2.3).cos());
        if i % 4 == 1 {
            let light = json!({ "type": "point", "intensity": 0.2 + 0.05 * (i % 3) as f32 });
            b.punctual_light(light, Vec3::new(c.x, HEIGHT, c.y), -Vec3::Y);
        } else {
            panels.push(c - Vec2::splat(0.5 * PANEL));
            let corner = Vec3::new(c.x - 0.5 * PANEL, HEIGHT, c.y - 0.5 * PANEL);
            mesh = mesh.merged(&MeshData::quad(corner, Vec3::X * PANEL, Vec3::Z * PANEL));
        }
    }
    let m = b.mesh("panels", &mesh, lamp);
    b.instance("panels", m, 0.0, Vec3::ZERO);
    b.punctual_light(
        json!({ "type": "spot", "intensity": 1.5, "spot": { "innerConeAngle": 0.3, "outerConeAngle": 0.7 } }),
        Vec3::new(0.4, HEIGHT - 0.1, 0.3),
        Vec3::new(0.2, -1.0, 0.1),
    );
    b.punctual_light(
        json!({ "type": "directional", "intensity": 0.4 }),
        Vec3::ZERO,
        Vec3::new(0.5, -1.0, 0.3),
    );
    b.camera("camera", Vec3::new(0.0, 4.5, 2.5), Vec3::new(0.0, 0.0, -0.3), 0.9);
    let scene = without_default_sky("many-lights-test.gltf", &b.finish("many lights", Vec3::ZERO));
    ManyLights { scene, panels }
}

/// Whether the segment from ground point `x` along `dir` (up) crosses a panel's plane inside
/// a panel (world coordinates).
fn panel_blocks(panels: &[Vec2], x: Vec3, dir: Vec3) -> bool {
    let t = (HEIGHT - x.y) / dir.y;
    let q = x + t * dir;
    panels
        .iter()
        .any(|c| q.x > c.x && q.x < c.x + PANEL && q.z > c.y && q.z < c.y + PANEL)
}

/// Irradiance at ground point `x` (world, normal +Y) from a panel of radiance L with lower
/// corner `c` (Lambert's formula: L/2 Σ Θ_i n·Γ̂_i over the polygon's edges).
fn panel_irradiance(c: Vec2, x: Vec3) -> f32 {
    let corners = [(0.0, 0.0), (PANEL, 0.0), (PANEL, PANEL), (0.0, PANEL)].map(|(dx, dz)| Vec3::new(c.x + dx, HEIGHT, c.y + dz) - x);
    let mut sum = 0.0;
    for k in 0..4 {
        let (a, b) = (corners[k].normalize(), corners[(k + 1) % 4].normalize());
        let gamma = a.cross(b);
        sum += a.dot(b).clamp(-1.0, 1.0).acos() * gamma.normalize().y;
    }
    0.5 * PANEL_RADIANCE * sum.abs()
}

/// (ρ/π) E at ground point x (world coordinates; the scene's lights are relative to its origin).
fn closed_form(m: &ManyLights, x: Vec3) -> f32 {
    let origin = m.scene.origin.as_vec3();
    let mut e: f32 = m.panels.iter().map(|&c| panel_irradiance(c, x)).sum();
    for l in &m.scene.lights {
        let lum = luminance(l.intensity) as f32;
        e += match l.kind {
            restir_pt::scene::PunctualKind::Directional => {
                if panel_blocks(&m.panels, x, -l.direction) {
                    0.0
                } else {
                    lum * (-l.direction).y.max(0.0)
                }
            }
            _ => {
                let to = l.position + origin - x;
                let d2 = to.length_squared();
                let dir = to / d2.sqrt();
                lum * dir.y.max(0.0) * spot_falloff(l, -dir) / d2
            }
        };
    }
    e * ALBEDO / std::f32::consts::PI
}

#[test]
fn many_lights_path_tracer_matches_the_closed_form_irradiance() {
    const SIDE: u32 = 32;
    const SUB: u32 = 8;
    let m = many_light_scene();
    assert_eq!((m.scene.lights.len(), m.panels.len()), (18, 48));
    let image = path_traced(&m.scene, SIDE, 512, 2);
    let camera = &m.scene.cameras[0];
    let origin = m.scene.origin.as_vec3();
    // The ground point (world) seen through image point (px, py), unless a panel hides it.
    let ground = |px: f32, py: f32| {
        let d = camera.ray_dir(px, py, SIDE, SIDE);
        let eye = camera.position + origin;
        let t = -eye.y / d.y;
        let x = eye + t * d;
        let hidden = panel_blocks(&m.panels, x, -d);
        (t > 0.0 && x.x.abs() < 4.0 && x.z.abs() < 4.0 && !hidden).then_some(x)
    };
    let (mut n, mut beyond, mut sum_got, mut sum_expected, mut var_sum) = (0, 0, 0.0f64, 0.0f64, 0.0f64);
    for y in 0..SIDE {
        for x in 0..SIDE {
            // The closed form over the pixel's footprint, as the camera's jitter averages it.
            let points: Option<Vec<Vec3>> = (0..SUB * SUB)
                .map(|k| {
                    ground(
                        x as f32 + ((k % SUB) as f32 + 0.5) / SUB as f32,
                        y as f32 + ((k / SUB) as f32 + 0.5) / SUB as f32,
                    )
                })
                .collect();
            let Some(points) = points else { continue };
            let expected = points.iter().map(|&p| closed_form(&m, p) as f64).sum::<f64>() / points.len() as f64;
            let i = (y * SIDE + x) as usize;
            let (got, var) = (luminance(image.mean[i]), luminance(image.variance[i]).max(0.0));
            let z = (got - expected) / var.sqrt().max(1e-9);
            beyond += (z.abs() > 4.0) as usize;
            n += 1;
            sum_got += got;
            sum_expected += expected;
            var_sum += var;
        }
    }
    let z_sum = (sum_got - sum_expected) / var_sum.sqrt();
    eprintln!(
        "many lights, path tracer at 512 spp: {n} ground pixels, {beyond} beyond 4 standard errors, sum {:.4} of the closed form (z = {z_sum:.2})",
        sum_got / sum_expected
    );
    assert!(n > 600, "only {n} ground pixels");
    assert!(beyond <= 2, "{beyond} of {n} pixels beyond 4 standard errors of the closed form");
    assert!(
        z_sum.abs() < 4.0 && (sum_got / sum_expected - 1.0).abs() < 0.01,
        "sum off the closed form: z = {z_sum:.2}"
    );
}
