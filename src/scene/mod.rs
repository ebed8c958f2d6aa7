//! The renderable scene: triangles in BVH order, materials, emitters, environment and cameras.

mod camera;
mod gltf_loader;

pub use camera::{camera_on_path, Camera};
pub use gltf_loader::{load_scene, load_scene_from_bytes};

use glam::{DVec3, Vec3};
use std::path::PathBuf;

use crate::bvh::Bvh;
use crate::gpu_types::{BvhNode, Emitter, Material, Triangle, NO_EMITTER};
use crate::lights::build_alias_table;

/// Probability that NEE samples the environment when the scene also has emissive triangles.
const ENV_SELECT_PROB_WITH_EMITTERS: f32 = 0.5;

pub struct Scene {
    pub source: PathBuf,
    pub triangles: Vec<Triangle>,
    pub nodes: Vec<BvhNode>,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    pub emitters: Vec<Emitter>,
    /// Total emitted power of the emissive triangles (W, luminance-weighted, front faces).
    pub emitter_power: f32,
    pub environment: Vec3,
    pub env_select_prob: f32,
    pub cameras: Vec<Camera>,
    /// Bounds of the triangles in scene coordinates.
    pub bounds: (Vec3, Vec3),
    /// World position of the scene coordinates' origin. Loaded scenes are re-centred on their
    /// first camera in f64 before rounding to f32 (camera-relative coordinates), so precision
    /// near the camera does not depend on where the scene sits in the world; 0 for scenes built
    /// directly.
    pub origin: DVec3,
    /// Things the loader dropped or ignored; each line names the file.
    pub warnings: Vec<String>,
}

pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Input to [`Scene::build`]: triangles as loaded, each tagged with its material.
pub struct SceneParts {
    pub source: PathBuf,
    pub triangles: Vec<Triangle>,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    pub environment: Vec3,
    pub cameras: Vec<Camera>,
    pub warnings: Vec<String>,
}

impl Scene {
    /// Builds the BVH (reordering triangles) and the emitter table. Triangles must be
    /// non-degenerate and finite; the loader guarantees it.
    pub fn build(parts: SceneParts) -> Scene {
        let bvh = Bvh::build(&parts.triangles);
        let mut triangles: Vec<Triangle> = bvh.order.iter().map(|&i| parts.triangles[i as usize]).collect();
        let mut emitter_tris = Vec::new();
        let mut powers = Vec::new();
        for (i, tri) in triangles.iter_mut().enumerate() {
            let m = &parts.materials[tri.material as usize];
            let sides = if m.is_double_sided() { 2.0 } else { 1.0 };
            let power = luminance(Vec3::from(m.emission)) * tri.area() * std::f32::consts::PI * sides;
            tri.emitter = NO_EMITTER;
            if power > 0.0 {
                tri.emitter = emitter_tris.len() as u32;
                emitter_tris.push(i as u32);
                powers.push(power);
            }
        }
        let emitters = if emitter_tris.is_empty() {
            Vec::new()
        } else {
            build_alias_table(&emitter_tris, &powers)
        };
        let has_env = luminance(parts.environment) > 0.0;
        let env_select_prob = match (has_env, emitters.is_empty()) {
            (false, _) => 0.0,
            (true, true) => 1.0,
            (true, false) => ENV_SELECT_PROB_WITH_EMITTERS,
        };
        let root = bvh.nodes[0];
        Scene {
            source: parts.source,
            triangles,
            nodes: bvh.nodes,
            materials: parts.materials,
            material_names: parts.material_names,
            emitters,
            emitter_power: powers.iter().fold(0.0, |a, p| a + p),
            environment: parts.environment,
            env_select_prob,
            cameras: parts.cameras,
            bounds: (Vec3::from(root.lo), Vec3::from(root.hi)),
            origin: DVec3::ZERO,
            warnings: parts.warnings,
        }
    }

    pub fn extent(&self) -> f32 {
        (self.bounds.1 - self.bounds.0).max_element()
    }
}
