//! restir-pt-scene, the renderable scene: triangles in BVH order, materials, emitters,
//! environment and cameras; the glTF loader that makes one, the BVH and light-tree builds, the
//! environment maps (with the EXR reader they need) and the bundled scenes.
//!
//! It may use restir-pt-interface (the records a scene is made of) and restir-pt-shading-core
//! (the twins loading runs: the default environment traces rays from the lights, and a hit's
//! surface, material and alpha test below are those twins'); nothing of the Vulkan layer, the
//! scene-wide shading twins or the renderer (docs/layout.md). What a device allows a
//! scene is decided by the renderer (`restir_pt::render::scene_array_limit`) and handed to the
//! loader as an [`ArrayLimit`].

// Every public item carries a doc comment (units, spaces, layouts, errors, sources): a new
// undocumented one fails the build, clippy and rustdoc alike.
#![deny(missing_docs)]
// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bundled_scenes;
pub mod bvh;
mod camera;
pub mod default_environment;
pub mod environment;
mod gltf_budget;
mod gltf_json;
mod gltf_loader;
mod gltf_material;
mod gltf_mesh;
mod gltf_surface;
mod gltf_texture;
pub mod gltf_writer;
mod hit_surface;
pub mod light_tree;
pub mod many_lights_scene;
mod punctual;

pub use camera::{camera_on_path, Camera, DEFAULT_CAMERA_NAME, DEFAULT_IMAGE_SIDE, DEFAULT_VIEW_DIRECTION, DEFAULT_YFOV};
pub use gltf_json::check_gltf_start;
pub use gltf_loader::{
    load_scene, load_scene_from_bytes, load_scene_from_bytes_with_options, load_scene_reporting, ArrayLimit, LoadOptions,
    DEFAULT_ENVIRONMENT,
};
pub use gltf_material::spec_gloss_to_metal_rough;
pub use gltf_mesh::triangle_indices;
pub use punctual::{PunctualKind, PunctualLight};

use glam::{DVec3, Vec3};
use std::path::PathBuf;

use restir_pt_interface::gpu_types::{BvhNode, Emitter, LightNode, Material, Triangle, NO_EMITTER, PUNCTUAL_LIGHT_BIT};
use restir_pt_shading_core::surface::TriangleSurface;
use restir_pt_shading_core::texture::{SceneTextures, ALPHA_OPAQUE};

use crate::bvh::Bvh;
use crate::environment::EnvironmentMap;
use crate::light_tree::{LightBounds, LightTree};

/// Relative luminance of linear Rec. 709 / sRGB primaries (ITU-R BT.709 weights). Light power,
/// the light tree and environment sampling weigh by it here; `restir_pt::metrics` re-exports it.
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Probability that NEE samples the environment when the scene also has other lights.
const ENV_SELECT_PROB_WITH_EMITTERS: f32 = 0.5;

/// A scene ready to upload: what [`load_scene`] returns and the renderers draw. Positions are
/// in scene coordinates (world minus [`Scene::origin`], metres as the file has them).
pub struct Scene {
    /// The file it was loaded from (or a description for scenes built in code).
    pub source: PathBuf,
    /// Triangles in BVH leaf order, each with its material and emitter index.
    pub triangles: Vec<Triangle>,
    /// Vertex attributes of `triangles` (same order), or empty: a scene of flat faces without
    /// textures has none (see crates/shading-core/src/surface.rs).
    pub surfaces: Vec<TriangleSurface>,
    /// The materials' textures (empty: none).
    pub textures: SceneTextures,
    /// The BVH over `triangles`, in depth-first order with skip links (crates/scene/src/bvh.rs).
    pub nodes: Vec<BvhNode>,
    /// Materials by index (`Triangle::material`).
    pub materials: Vec<Material>,
    /// The materials' names from the file, parallel to `materials` (for messages and reports).
    pub material_names: Vec<String>,
    /// The lights NEE chooses from: emissive triangles, then point and spot lights (the light
    /// tree's leaves, each with its bit trail), then directional lights.
    pub emitters: Vec<Emitter>,
    /// The light tree over the emitters before the directional ones (crates/scene/src/light_tree.rs);
    /// empty when there are none.
    pub light_nodes: Vec<LightNode>,
    /// Directional lights: the last rows of `emitters`, outside the light tree: NEE takes each
    /// of them at every vertex (`shading::lights::sample_directional`).
    pub directional_count: u32,
    /// Per punctual light (index into `lights`): its row in `emitters`.
    pub punctual_emitter_rows: Vec<u32>,
    /// Total emitted power of the emissive triangles (W, luminance-weighted, front faces).
    pub emitter_power: f32,
    /// Constant environment radiance (unused when `environment_map` is set).
    pub environment: Vec3,
    /// An equirectangular environment map (`--env FILE`), replacing the constant.
    pub environment_map: Option<EnvironmentMap>,
    /// Probability that next-event estimation samples the environment rather than another light
    /// (0 without environment light, 1 without other lights).
    pub env_select_prob: f32,
    /// The file's cameras, or one default camera framing the scene; never empty.
    pub cameras: Vec<Camera>,
    /// `KHR_lights_punctual` lights in scene coordinates (like the triangles: relative to
    /// [`Scene::origin`]).
    pub lights: Vec<PunctualLight>,
    /// Bounds of the triangles in scene coordinates.
    pub bounds: (Vec3, Vec3),
    /// World position of the scene coordinates' origin. Loaded scenes are re-centred in f64
    /// before rounding to f32, so precision near the camera does not depend on where the scene
    /// sits in the world: on their first camera (camera-relative coordinates), or, in a scene
    /// without one, on the centre of its vertices' world bounds, which the default camera looks
    /// at. 0 for scenes built directly.
    pub origin: DVec3,
    /// Things the loader dropped or ignored; each line names the file.
    pub warnings: Vec<String>,
    /// Wall time of the BVH build and emitter table (ms).
    pub build_ms: f64,
}

/// Input to [`Scene::build`]: triangles as loaded, each tagged with its material.
/// Fields mean what the [`Scene`] fields of the same names mean; `triangles` in any order.
pub struct SceneParts {
    /// See [`Scene::source`].
    pub source: PathBuf,
    /// The triangles in scene coordinates, in any order.
    pub triangles: Vec<Triangle>,
    /// Vertex attributes parallel to `triangles`, or empty.
    pub surfaces: Vec<TriangleSurface>,
    /// See [`Scene::textures`].
    pub textures: SceneTextures,
    /// See [`Scene::materials`].
    pub materials: Vec<Material>,
    /// See [`Scene::material_names`].
    pub material_names: Vec<String>,
    /// See [`Scene::environment`].
    pub environment: Vec3,
    /// See [`Scene::environment_map`].
    pub environment_map: Option<EnvironmentMap>,
    /// See [`Scene::cameras`].
    pub cameras: Vec<Camera>,
    /// See [`Scene::lights`].
    pub lights: Vec<PunctualLight>,
    /// See [`Scene::warnings`].
    pub warnings: Vec<String>,
}

/// Sets each triangle's emitter index (into the triangle emitters, in order; `NO_EMITTER` if it
/// emits nothing) and `alpha_tested` flag; returns the emitting triangles' indices, light bounds
/// and total power (luminance × area × π per emitting side, in scene units).
fn tag_triangles(triangles: &mut [Triangle], materials: &[Material], textures: &SceneTextures) -> (Vec<u32>, Vec<LightBounds>, f32) {
    let mut emitter_tris = Vec::new();
    let mut bounds = Vec::new();
    let mut total = 0.0;
    for (i, tri) in triangles.iter_mut().enumerate() {
        let m = &materials[tri.material as usize];
        let sides = if m.is_double_sided() { 2.0 } else { 1.0 };
        let power = luminance(Vec3::from(m.emission)) * tri.area() * std::f32::consts::PI * sides;
        tri.emitter = NO_EMITTER;
        let mode = textures.materials.get(tri.material as usize).map_or(ALPHA_OPAQUE, |t| t.alpha_mode);
        tri.alpha_tested = (mode != ALPHA_OPAQUE) as u32;
        if power > 0.0 {
            tri.emitter = emitter_tris.len() as u32;
            emitter_tris.push(i as u32);
            bounds.push(LightBounds::triangle(
                tri.vertices(),
                luminance(Vec3::from(m.emission)),
                m.is_double_sided(),
            ));
            total += power;
        }
    }
    (emitter_tris, bounds, total)
}

/// The emitter rows of the scene's lights (see [`Scene::emitters`]), the light tree over all
/// but the directional ones, and each punctual light's row.
fn light_table(mut ids: Vec<u32>, mut bounds: Vec<LightBounds>, lights: &[PunctualLight]) -> (Vec<Emitter>, LightTree, Vec<u32>) {
    let mut rows = vec![0u32; lights.len()];
    let directional = |l: &PunctualLight| l.kind == PunctualKind::Directional;
    for (k, light) in lights.iter().enumerate().filter(|(_, l)| !directional(l)) {
        rows[k] = ids.len() as u32;
        ids.push(PUNCTUAL_LIGHT_BIT | k as u32);
        bounds.push(LightBounds::punctual(
            light.position,
            light.direction,
            luminance(light.intensity),
            light.cos_outer,
        ));
    }
    let tree = LightTree::build(&bounds);
    let mut emitters: Vec<Emitter> = ids
        .iter()
        .enumerate()
        .map(|(i, &id)| Emitter {
            triangle: id,
            trail: tree.trails[i],
            intensity: bounds[i].intensity,
            leaf: tree.leaves[i],
        })
        .collect();
    for (k, light) in lights.iter().enumerate().filter(|(_, l)| directional(l)) {
        rows[k] = emitters.len() as u32;
        emitters.push(Emitter {
            triangle: PUNCTUAL_LIGHT_BIT | k as u32,
            trail: 0,
            intensity: luminance(light.intensity),
            leaf: NO_EMITTER,
        });
    }
    (emitters, tree, rows)
}

/// The probability that NEE samples the environment rather than a light of the light tree:
/// directional lights are not drawn (NEE takes each of them beside the drawn light), so beside
/// them alone the environment takes every draw.
fn env_select_prob(has_env: bool, tree_empty: bool) -> f32 {
    match (has_env, tree_empty) {
        (false, _) => 0.0,
        (true, true) => 1.0,
        (true, false) => ENV_SELECT_PROB_WITH_EMITTERS,
    }
}

impl Scene {
    /// Builds the BVH (reordering triangles) and the emitter table. Triangles must be
    /// non-degenerate and finite; the loader guarantees it.
    pub fn build(parts: SceneParts) -> Scene {
        let start = std::time::Instant::now();
        let bvh = Bvh::build(&parts.triangles);
        let mut triangles = parts.triangles;
        // The surface attributes are per triangle and must follow the triangles' BVH order;
        // scenes without attributes keep an empty array (no SCENE_SURFACE).
        let mut surfaces = parts.surfaces;
        if !surfaces.is_empty() {
            permute_in_place(&mut surfaces, bvh.order.clone());
        }
        permute_in_place(&mut triangles, bvh.order);
        let (emitter_tris, bounds, triangle_power) = tag_triangles(&mut triangles, &parts.materials, &parts.textures);
        let (emitters, tree, punctual_emitter_rows) = light_table(emitter_tris, bounds, &parts.lights);
        let has_env = luminance(parts.environment) > 0.0 || parts.environment_map.is_some();
        let env_select_prob = env_select_prob(has_env, tree.trails.is_empty());
        let root = bvh.nodes[0];
        let triangles_empty = triangles.is_empty();
        Scene {
            source: parts.source,
            triangles,
            surfaces,
            textures: parts.textures,
            nodes: bvh.nodes,
            materials: parts.materials,
            material_names: parts.material_names,
            directional_count: (emitters.len() - tree.trails.len()) as u32,
            emitters,
            light_nodes: tree.nodes,
            punctual_emitter_rows,
            emitter_power: triangle_power,
            environment: if parts.environment_map.is_some() {
                Vec3::ZERO
            } else {
                parts.environment
            },
            environment_map: parts.environment_map,
            env_select_prob,
            cameras: parts.cameras,
            lights: parts.lights,
            // A scene of points and lines alone has no triangles (and an empty root box).
            bounds: if triangles_empty {
                (Vec3::ZERO, Vec3::ZERO)
            } else {
                (Vec3::from(root.lo), Vec3::from(root.hi))
            },
            origin: DVec3::ZERO,
            warnings: parts.warnings,
            build_ms: start.elapsed().as_secs_f64() * 1e3,
        }
    }

    /// The emitter-buffer rows of the punctual lights (see `punctual::punctual_rows`).
    pub fn punctual_rows(&self) -> Vec<Emitter> {
        punctual::punctual_rows(&self.lights, &self.punctual_emitter_rows)
    }

    /// The emitter-buffer rows of the light tree (glsl/shading/light_tree.glsl): a header (directional
    /// lights, nodes, 0, 0), then [`restir_pt_interface::gpu_types::LIGHT_NODE_ROWS`] rows per node.
    pub fn light_tree_rows(&self) -> Vec<Emitter> {
        let header = Emitter::from_words([self.directional_count, self.light_nodes.len() as u32, 0, 0]);
        std::iter::once(header)
            .chain(self.light_nodes.iter().flat_map(|n| n.rows()))
            .collect()
    }

    /// Replaces the environment by the constant radiance `env` (no map), with the light
    /// selection's environment probability chosen as [`Scene::build`] chooses it.
    pub fn set_environment(&mut self, env: Vec3) {
        self.environment = env;
        self.environment_map = None;
        let tree_empty = self.emitters.len() == self.directional_count as usize;
        self.env_select_prob = env_select_prob(luminance(env) > 0.0, tree_empty);
    }

    /// The largest side of the scene's bounds (scene units).
    pub fn extent(&self) -> f32 {
        (self.bounds.1 - self.bounds.0).max_element()
    }
}

/// Reorders `items` so that position i holds what was at `order[i]` (a permutation), without a
/// second copy of the array: a scene of 8 M triangles holds 384 MB of them. Follows each cycle of
/// the permutation once, marking visited positions in `order`.
fn permute_in_place<T: Copy>(items: &mut [T], mut order: Vec<u32>) {
    const DONE: u32 = u32::MAX;
    for start in 0..items.len() {
        if order[start] == DONE {
            continue;
        }
        let first = items[start];
        let mut at = start;
        loop {
            let from = order[at] as usize;
            order[at] = DONE;
            if from == start {
                items[at] = first;
                break;
            }
            items[at] = items[from];
            at = from;
        }
    }
}

/// Identical lines collapsed into one with their count ("line (x3)"), in order of first
/// appearance.
pub fn collapse_warnings(warnings: &[String]) -> Vec<String> {
    let mut order: Vec<(&str, usize)> = Vec::new();
    for w in warnings {
        match order.iter_mut().find(|(s, _)| *s == w.as_str()) {
            Some((_, n)) => *n += 1,
            None => order.push((w.as_str(), 1)),
        }
    }
    order
        .into_iter()
        .map(|(s, n)| if n > 1 { format!("{s} (x{n})") } else { s.to_string() })
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn permute_in_place_equals_a_gather() {
        // A permutation with cycles of several lengths and fixed points (LCG shuffle).
        let n = 1000u32;
        let mut order: Vec<u32> = (0..n).collect();
        let mut state = 12345u64;
        for i in (1..n as usize).rev() {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            order.swap(i, (state >> 33) as usize % (i + 1));
        }
        let items: Vec<u64> = (0..n as u64).map(|i| i * 7 + 3).collect();
        let gathered: Vec<u64> = order.iter().map(|&i| items[i as usize]).collect();
        let mut permuted = items.clone();
        super::permute_in_place(&mut permuted, order);
        assert_eq!(permuted, gathered);
    }
}
