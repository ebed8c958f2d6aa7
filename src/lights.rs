//! Next-event estimation: the alias table over emitter power and the twin of glsl/lights.glsl.

use glam::{Vec2, Vec3};

use crate::gpu_types::{Emitter, Triangle, NO_EMITTER};
use crate::sampling::{sample_triangle, sample_uniform_sphere, UNIFORM_SPHERE_PDF};
use crate::scene::Scene;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    pub dir: Vec3,
    pub dist: f32,
    pub radiance: Vec3,
    pub pdf: f32,
    /// The emitter triangle sampled, NO_EMITTER for the environment.
    pub triangle: u32,
}

/// Vose's alias table over `weights` (all finite, non-negative, positive sum).
pub fn build_alias_table(triangles: &[u32], weights: &[f32]) -> Vec<Emitter> {
    let n = weights.len();
    let total: f64 = weights.iter().map(|&w| w as f64).sum();
    let mut table: Vec<Emitter> = triangles
        .iter()
        .zip(weights)
        .map(|(&t, &w)| Emitter {
            triangle: t,
            select_pdf: (w as f64 / total) as f32,
            alias_prob: 1.0,
            alias: 0,
        })
        .collect();
    let mut scaled: Vec<f64> = weights.iter().map(|&w| w as f64 * n as f64 / total).collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    while let (Some(s), Some(&l)) = (small.pop(), large.last()) {
        table[s].alias_prob = scaled[s] as f32;
        table[s].alias = l as u32;
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    for i in small.into_iter().chain(large) {
        table[i].alias_prob = 1.0;
        table[i].alias = i as u32;
    }
    table
}

pub fn emitted_radiance(scene: &Scene, tri: &Triangle, to_viewer: Vec3) -> Vec3 {
    let m = &scene.materials[tri.material as usize];
    let facing = tri.normal_area2().dot(to_viewer);
    let lit = facing > 0.0 || (m.is_double_sided() && facing < 0.0);
    if lit {
        Vec3::from(m.emission)
    } else {
        Vec3::ZERO
    }
}

pub fn alias_select(emitters: &[Emitter], u: f32, count: u32) -> u32 {
    let scaled = u * count as f32;
    let i = (scaled as u32).min(count - 1);
    let coin = scaled - i as f32;
    if coin < emitters[i as usize].alias_prob {
        i
    } else {
        emitters[i as usize].alias
    }
}

pub fn emitter_pdf(scene: &Scene, tri_index: u32, dir: Vec3, dist: f32) -> f32 {
    let tri = &scene.triangles[tri_index as usize];
    if tri.emitter == NO_EMITTER {
        return 0.0;
    }
    let ng = tri.normal_area2();
    let area2 = ng.length();
    let cos_l = ng.dot(dir).abs() / area2;
    if cos_l <= 0.0 {
        return 0.0;
    }
    let p_area = (1.0 - scene.env_select_prob) * scene.emitters[tri.emitter as usize].select_pdf * 2.0 / area2;
    p_area * dist * dist / cos_l
}

pub fn environment_pdf(scene: &Scene) -> f32 {
    scene.env_select_prob * UNIFORM_SPHERE_PDF
}

/// u.x selects the light, u.yz the point or direction.
pub fn sample_light(scene: &Scene, p: Vec3, u: Vec3) -> LightSample {
    let none = LightSample {
        dir: Vec3::Z,
        dist: 0.0,
        radiance: Vec3::ZERO,
        pdf: 0.0,
        triangle: NO_EMITTER,
    };
    let p_env = scene.env_select_prob;
    if u.x < p_env {
        return LightSample {
            dir: sample_uniform_sphere(Vec2::new(u.y, u.z)),
            dist: f32::INFINITY,
            radiance: scene.environment,
            pdf: environment_pdf(scene),
            triangle: NO_EMITTER,
        };
    }
    if scene.emitters.is_empty() {
        return none;
    }
    let u_select = (u.x - p_env) / (1.0 - p_env);
    let e = scene.emitters[alias_select(&scene.emitters, u_select.min(0.99999994), scene.emitters.len() as u32) as usize];
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
        radiance: emitted_radiance(scene, tri, -dir),
        pdf: emitter_pdf(scene, e.triangle, dir, dist),
        triangle: e.triangle,
    }
}
