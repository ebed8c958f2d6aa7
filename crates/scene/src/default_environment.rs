//! The environment a file without one gets, decided from what it holds. glTF viewers (the Khronos
//! sample viewer, three.js, Blender's preview) light an asset with an environment unless told
//! otherwise, while a scene built around its own lights should keep its look:
//!
//! - no light at all (no emissive triangle, punctual light or environment): the default
//!   environment;
//! - lights, and the scene closed around them, so that most of what they emit stays in it (a room
//!   such as the bundled Cornell boxes): no environment, the file's lights alone;
//! - lights whose emission mostly leaves the scene (an open asset, such as a helmet whose
//!   emissive texture makes every triangle an emitter, or a sun, which shines from outside by
//!   definition): the default environment beside them.
//!
//! "Mostly leaves" is [`light_escape_fraction`] above [`OPEN_SCENE_FRACTION`]: the share of the
//! lights' emitted power whose first ray from the light leaves the scene without a hit. The
//! default environment is a uniform one of radiance [`DEFAULT_ENVIRONMENT`] (a neutral white
//! sky). `--env` replaces all of this; `--env none` turns it off.

use glam::{Vec2, Vec3};

use restir_pt_interface::gpu_types::NO_EMITTER;
use restir_pt_shading_core::bvh::{trace_closest, NO_HIT};
use restir_pt_shading_core::ray_offset::offset_ray_origin;
use restir_pt_shading_core::sampling::{build_onb, sample_cosine_hemisphere, sample_triangle, sample_uniform_sphere};

use super::{luminance, PunctualKind, PunctualLight, Scene, DEFAULT_ENVIRONMENT};

/// Rays shot from the lights to measure how much of their emission leaves the scene.
const ESCAPE_RAYS: u32 = 4096;
/// A scene is open when more than this share of its lights' power leaves it on the first ray:
/// most of it. The bundled Cornell boxes, open at the front, lose 17% to 19.5%, a lamp 1 above a
/// 2 x 2 floor 45% and a point light over a floor about half (all kept as they are), while a
/// convex emissive object loses all of it and a sun counts as leaving
/// (tests/suite/default_environment.rs).
pub const OPEN_SCENE_FRACTION: f32 = 0.6;

/// A light of the scene as the escape estimate sees it: an emissive triangle or a punctual light.
enum Source {
    Triangle(u32),
    Punctual(usize),
}

/// Emitted power (luminance-weighted) of a punctual light: 4πI for a point light, the solid
/// angle of the cone halfway between the inner and outer angles times I for a spot, and I times
/// the area of the scene's bounding disc (radius `scene_radius`) for a directional light (as
/// pbrt-v4's `DistantLight::Phi`).
fn punctual_power(light: &PunctualLight, scene_radius: f32) -> f32 {
    let i = luminance(light.intensity);
    match light.kind {
        PunctualKind::Point => 4.0 * std::f32::consts::PI * i,
        PunctualKind::Spot => {
            let cos_mid = 0.5 * (light.cos_inner + light.cos_outer);
            2.0 * std::f32::consts::PI * (1.0 - cos_mid) * i
        }
        PunctualKind::Directional => std::f32::consts::PI * scene_radius * scene_radius * i,
    }
}

/// The share of the lights' power (emissive triangles by emission × area, punctual lights by
/// `punctual_power`) whose first ray leaves the scene without hitting anything:
/// 4096 rays, the light chosen by power, a uniform point on a triangle and a cosine-distributed
/// direction on an emitting side, a uniform direction of a point light's sphere or a spot's
/// cone. Directional lights count as leaving (they come from outside the scene). Deterministic;
/// 0 for a scene without lights, 1 for one without triangles.
pub fn light_escape_fraction(scene: &Scene) -> f32 {
    let mut sources = Vec::new();
    let mut cumulative = Vec::new();
    let mut total = 0.0f64;
    let scene_radius = 0.5 * (scene.bounds.1 - scene.bounds.0).length().max(1e-6);
    for (i, t) in scene.triangles.iter().enumerate() {
        if t.emitter == NO_EMITTER {
            continue;
        }
        let m = &scene.materials[t.material as usize];
        let sides = if m.is_double_sided() { 2.0 } else { 1.0 };
        total += (luminance(Vec3::from(m.emission)) * t.area() * sides) as f64;
        sources.push(Source::Triangle(i as u32));
        cumulative.push(total);
    }
    for (k, light) in scene.lights.iter().enumerate() {
        total += punctual_power(light, scene_radius) as f64;
        sources.push(Source::Punctual(k));
        cumulative.push(total);
    }
    if !(total > 0.0) {
        return 0.0;
    }
    if scene.triangles.is_empty() {
        return 1.0;
    }
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut escaped = 0u32;
    for i in 0..ESCAPE_RAYS {
        let pick = (i as f64 + uniform() as f64) / ESCAPE_RAYS as f64 * total;
        let k = cumulative.partition_point(|&c| c <= pick).min(sources.len() - 1);
        let u = Vec2::new(uniform(), uniform());
        let ray = match sources[k] {
            Source::Triangle(t) => {
                let tri = &scene.triangles[t as usize];
                let b = sample_triangle(Vec2::new(uniform(), uniform()));
                let p = Vec3::from(tri.v0) + b.x * Vec3::from(tri.e1) + b.y * Vec3::from(tri.e2);
                let mut n = tri.normal_area2().normalize();
                if scene.materials[tri.material as usize].is_double_sided() && uniform() < 0.5 {
                    n = -n;
                }
                let (x, y) = build_onb(n);
                let d = sample_cosine_hemisphere(u);
                Some((offset_ray_origin(p, n, tri), x * d.x + y * d.y + n * d.z))
            }
            Source::Punctual(k) => {
                let light = &scene.lights[k];
                match light.kind {
                    PunctualKind::Directional => None,
                    PunctualKind::Point => Some((light.position, sample_uniform_sphere(u))),
                    PunctualKind::Spot => {
                        let cos = 1.0 - u.x * (1.0 - light.cos_outer);
                        let sin = (1.0 - cos * cos).max(0.0).sqrt();
                        let phi = 2.0 * std::f32::consts::PI * u.y;
                        let (x, y) = build_onb(light.direction);
                        Some((
                            light.position,
                            x * (sin * phi.cos()) + y * (sin * phi.sin()) + light.direction * cos,
                        ))
                    }
                }
            }
        };
        escaped += match ray {
            None => 1,
            Some((o, d)) => (trace_closest(&scene.nodes, &scene.triangles, o, d, f32::INFINITY).triangle == NO_HIT) as u32,
        };
    }
    escaped as f32 / ESCAPE_RAYS as f32
}

/// Gives a scene that has lights but no environment the default environment when its lights'
/// emission mostly leaves it ([`light_escape_fraction`] above [`OPEN_SCENE_FRACTION`]); returns
/// the line that says so, or None for a scene closed around its lights (left unchanged).
pub(super) fn light_open_scene(scene: &mut Scene) -> Option<String> {
    if luminance(scene.environment) > 0.0 || scene.environment_map.is_some() {
        return None;
    }
    let open = light_escape_fraction(scene);
    if open <= OPEN_SCENE_FRACTION {
        return None;
    }
    scene.set_environment(DEFAULT_ENVIRONMENT);
    Some(format!(
        "the scene has lights but no environment, and {:.0}% of their emission leaves it (an open asset, not a room closed around its lights): adding a uniform environment of radiance {} as glTF viewers do (--env none: the file's lights alone)",
        100.0 * open,
        DEFAULT_ENVIRONMENT.x
    ))
}

/// The line for a scene without any light, which gets the default environment.
pub(super) fn unlit_scene_line() -> String {
    format!(
        "the scene has no light (no emissive triangle, punctual light or environment): using a uniform environment of radiance {} (--env none: none)",
        DEFAULT_ENVIRONMENT.x
    )
}
