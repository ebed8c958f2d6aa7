//! Next-event estimation: the twin of glsl/shading/lights.glsl. Lights are chosen by their likely
//! contribution at the shading point (the light tree, crates/shading/src/light_tree.rs); point and spot
//! lights (KHR_lights_punctual) are chosen beside emissive triangles, and directional lights are
//! not chosen but taken at every vertex ([`sample_directional`]). A sample of a punctual light
//! is a delta: its `pdf` is the discrete probability of choosing the light (1 for a directional
//! one), its `radiance` the irradiance-like I·falloff/d² (or E), and MIS gives it weight 1.

use glam::{Vec2, Vec3};

use restir_pt_interface::gpu_types::{NO_EMITTER, PUNCTUAL_LIGHT_BIT};
use restir_pt_scene::{PunctualKind, PunctualLight, Scene};

use crate::light_tree::{directional_row, light_select, light_select_pmf};
use crate::sampling::{sample_triangle, sample_uniform_sphere, UNIFORM_SPHERE_PDF};

/// A next-event-estimation sample from a shading point (twin of GLSL `LightSample`,
/// glsl/shading/lights.glsl). A failed sample has zero `pdf` and `radiance`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point towards the light, world space.
    pub dir: Vec3,
    /// Distance to the sampled point in scene units; infinite for the environment and
    /// directional lights.
    pub dist: f32,
    /// Radiance arriving along `dir` (linear RGB, W/(m² sr)); for a punctual light the
    /// irradiance-like I·falloff/d² or E that multiplies f_s |cos|.
    pub radiance: Vec3,
    /// Solid-angle density of `dir` (1/sr), selection probability included; for a punctual
    /// light the discrete probability of choosing it.
    pub pdf: f32,
    /// The emitter triangle sampled, NO_EMITTER for the environment, PUNCTUAL_LIGHT_BIT | k for
    /// punctual light k.
    pub triangle: u32,
}

/// Whether a light or vertex id names a punctual light (twin of GLSL `is_punctual_light`).
pub fn is_punctual_light(id: u32) -> bool {
    id != NO_EMITTER && id & PUNCTUAL_LIGHT_BIT != 0
}

/// The spot cone's smooth falloff for light leaving along `dir_out` (unit): the square of
/// clamp((cos θ - cos outer) / (cos inner - cos outer), 0, 1), KHR_lights_punctual's recommended
/// formula; 1 for point and directional lights. Twin of GLSL `spot_falloff`.
pub fn spot_falloff(light: &PunctualLight, dir_out: Vec3) -> f32 {
    if light.kind != PunctualKind::Spot {
        return 1.0;
    }
    let scale = 1.0 / (light.cos_inner - light.cos_outer).max(1e-3);
    let t = ((light.direction.dot(dir_out) - light.cos_outer) * scale).clamp(0.0, 1.0);
    t * t
}

/// What punctual light `light` sends to point `p`: the unit direction from p towards it, the
/// distance (infinite for a directional light) and I·falloff/d² (point, spot) or E
/// (directional), the factor that multiplies f_s |cos| at p. Twin of GLSL `punctual_arrival`.
pub fn punctual_arrival(light: &PunctualLight, p: Vec3) -> (Vec3, f32, Vec3) {
    if light.kind == PunctualKind::Directional {
        return (-light.direction, f32::INFINITY, light.intensity);
    }
    let to_light = light.position - p;
    let d2 = to_light.dot(to_light);
    if !(d2 > 0.0) {
        return (Vec3::Z, 0.0, Vec3::ZERO);
    }
    let dist = d2.sqrt();
    let dir = to_light / dist;
    (dir, dist, light.intensity * (spot_falloff(light, -dir) / d2))
}

/// Whether anything blocks the way from surface point `x` (normal `n`, on triangle index `tri`)
/// to a punctual light along the unit `dir` at distance `dist` (infinite: a directional light);
/// only x is offset, the light being a point in the air. Twin of GLSL `punctual_occluded` (glsl/shading/punctual.glsl).
pub fn punctual_occluded(scene: &Scene, x: Vec3, n: Vec3, tri: u32, dir: Vec3, dist: f32) -> bool {
    use restir_pt_shading_core::bvh::{trace_occluded, SEGMENT_EPSILON};
    let origin = crate::ray_offset::offset_ray_origin(x, if dir.dot(n) > 0.0 { n } else { -n }, &scene.triangles[tri as usize]);
    if dist.is_infinite() {
        return trace_occluded(&scene.nodes, &scene.triangles, origin, dir, 1e30);
    }
    trace_occluded(
        &scene.nodes,
        &scene.triangles,
        origin,
        x + dir * dist - origin,
        1.0 - SEGMENT_EPSILON,
    )
}

/// The emitter row of punctual light `k`. Twin of GLSL `punctual_emitter_row`.
pub fn punctual_emitter_row(scene: &Scene, k: u32) -> u32 {
    scene.punctual_emitter_rows[k as usize]
}

/// Emitted radiance of triangle index `triangle` at barycentrics `bary` towards `to_viewer`
/// (front face only unless double-sided), its emissive texture applied.
pub fn emitted_radiance(scene: &Scene, triangle: u32, bary: glam::Vec2, to_viewer: Vec3) -> Vec3 {
    let tri = &scene.triangles[triangle as usize];
    let m = &scene.material_at(triangle, bary);
    let facing = tri.normal_area2().dot(to_viewer);
    let lit = facing > 0.0 || (m.is_double_sided() && facing < 0.0);
    if lit {
        Vec3::from(m.emission)
    } else {
        Vec3::ZERO
    }
}

/// The solid-angle density (1/sr) of the point at distance `dist` along unit `dir` on emitter
/// triangle `tri_index` when the triangle is chosen with probability `pmf` and sampled
/// uniformly by area: pmf / area · dist² / |cos θ_light|; 0 seen edge-on. Twin of GLSL
/// `emitter_area_pdf`.
pub fn emitter_area_pdf(scene: &Scene, pmf: f32, tri_index: u32, dir: Vec3, dist: f32) -> f32 {
    let ng = scene.triangles[tri_index as usize].normal_area2();
    let area2 = ng.length();
    let cos_l = ng.dot(dir).abs() / area2;
    if cos_l <= 0.0 {
        return 0.0;
    }
    let p_area = pmf * 2.0 / area2;
    p_area * dist * dist / cos_l
}

/// Solid-angle density (1/sr) with which [`sample_light`] at `p` (geometric normal `n`) picks
/// the point at distance `dist` along unit `dir` on emissive triangle `tri_index` (see
/// [`emitter_area_pdf`] and [`light_select_pmf`]); 0 for a triangle that does not emit. Twin
/// of GLSL `emitter_pdf`.
pub fn emitter_pdf(scene: &Scene, p: Vec3, n: Vec3, tri_index: u32, dir: Vec3, dist: f32) -> f32 {
    let row = scene.triangles[tri_index as usize].emitter;
    if row == NO_EMITTER {
        0.0
    } else {
        emitter_area_pdf(scene, light_select_pmf(scene, p, n, row), tri_index, dir, dist)
    }
}

/// Solid-angle pdf that NEE samples the environment in direction `dir` (unit): uniform over the
/// sphere for a constant environment, the map's luminance density for a map. Twin of GLSL
/// `environment_pdf`.
pub fn environment_pdf(scene: &Scene, dir: Vec3) -> f32 {
    scene.env_select_prob
        * match &scene.environment_map {
            Some(map) => map.pdf(dir),
            None => UNIFORM_SPHERE_PDF,
        }
}

/// Environment radiance arriving from direction `dir` (unit). Twin of GLSL
/// `environment_radiance`.
pub fn environment_radiance(scene: &Scene, dir: Vec3) -> Vec3 {
    match &scene.environment_map {
        Some(map) => map.radiance(dir),
        None => scene.environment,
    }
}

/// A light sample from `p` (geometric normal `n`, unit, which weighs the lights): u.x selects
/// the environment or a light (by [`light_select`]), u.yz the point or direction. Twin of GLSL
/// `sample_light`.
pub fn sample_light(scene: &Scene, p: Vec3, n: Vec3, u: Vec3) -> LightSample {
    let none = LightSample {
        dir: Vec3::Z,
        dist: 0.0,
        radiance: Vec3::ZERO,
        pdf: 0.0,
        triangle: NO_EMITTER,
    };
    let p_env = scene.env_select_prob;
    if u.x < p_env {
        let dir = match &scene.environment_map {
            Some(map) => map.sample_environment(Vec2::new(u.y, u.z)),
            None => sample_uniform_sphere(Vec2::new(u.y, u.z)),
        };
        return LightSample {
            dir,
            dist: f32::INFINITY,
            radiance: environment_radiance(scene, dir),
            pdf: environment_pdf(scene, dir),
            triangle: NO_EMITTER,
        };
    }
    if scene.emitters.len() as u32 == scene.directional_count {
        return none;
    }
    let u_select = (u.x - p_env) / (1.0 - p_env);
    let (row, pmf) = light_select(scene, p, n, u_select.min(0.99999994));
    if row == NO_EMITTER {
        return none;
    }
    let e = scene.emitters[row as usize];
    if is_punctual_light(e.triangle) {
        let k = e.triangle & !PUNCTUAL_LIGHT_BIT;
        let (dir, dist, radiance) = punctual_arrival(&scene.lights[k as usize], p);
        if !(dist > 0.0) {
            return none;
        }
        return LightSample {
            dir,
            dist,
            radiance,
            pdf: pmf,
            triangle: e.triangle,
        };
    }
    let tri = &scene.triangles[e.triangle as usize];
    let b = sample_triangle(Vec2::new(u.y, u.z));
    let q = Vec3::from(tri.v0) + b.x * Vec3::from(tri.e1) + b.y * Vec3::from(tri.e2);
    let to_light = q - p;
    let d2 = to_light.dot(to_light);
    if d2 <= 0.0 {
        return none;
    }
    let dist = d2.sqrt();
    let dir = to_light / dist;
    LightSample {
        dir,
        dist,
        radiance: emitted_radiance(scene, e.triangle, b, -dir),
        pdf: emitter_area_pdf(scene, pmf, e.triangle, dir, dist),
        triangle: e.triangle,
    }
}

/// The sample of directional light `k` (`k` < `scene.directional_count`) that NEE adds at every
/// vertex beside [`sample_light`]'s: towards the light, at infinity, its irradiance E, with
/// probability 1. Twin of GLSL `sample_directional`.
pub fn sample_directional(scene: &Scene, k: u32) -> LightSample {
    let id = scene.emitters[directional_row(scene, k) as usize].triangle;
    let (dir, dist, radiance) = punctual_arrival(&scene.lights[(id & !PUNCTUAL_LIGHT_BIT) as usize], Vec3::ZERO);
    LightSample {
        dir,
        dist,
        radiance,
        pdf: 1.0,
        triangle: id,
    }
}
