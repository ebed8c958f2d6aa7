//! What the host keeps of an uploaded scene: the data that frame parameters, validation and
//! the reuse parameters read, taken from the same `Scene` as the GPU buffers.

use std::path::PathBuf;

use glam::Vec3;

use crate::scene::{Camera, Scene};
use crate::shading::shift::ShiftParams;

/// The host side of a [`SceneGpu`](super::SceneGpu): the scene's source, cameras, environment,
/// emitter and triangle counts and shift thresholds. Built by [`SceneInfo::of`]; a renderer
/// reads it only through its `SceneGpu`, so it always describes the uploaded buffers.
#[derive(Debug, Clone)]
pub struct SceneInfo {
    /// The file the scene was loaded from (named in errors).
    pub source: PathBuf,
    /// The scene's cameras, in scene coordinates; a render's `camera` indexes them.
    pub cameras: Vec<Camera>,
    /// Constant environment radiance (linear RGB, W/(m² sr)); unused with an environment map.
    pub environment: Vec3,
    /// Probability that light sampling picks the environment (0 when it emits nothing).
    pub env_select_prob: f32,
    /// Emissive triangles (the first rows of the emitter buffer).
    pub emitter_count: u32,
    /// Triangles of the scene (0 for a scene of points and lines alone).
    pub triangle_count: usize,
    /// The shift mappings' reconnection thresholds for this scene's size.
    pub shift_params: ShiftParams,
}

impl SceneInfo {
    /// Copies what the renderers need of `scene` (its cameras are cloned; the arrays stay).
    pub fn of(scene: &Scene) -> Self {
        Self {
            source: scene.source.clone(),
            cameras: scene.cameras.clone(),
            environment: scene.environment,
            env_select_prob: scene.env_select_prob,
            emitter_count: scene.emitters.len() as u32,
            triangle_count: scene.triangles.len(),
            shift_params: ShiftParams::for_scene(scene),
        }
    }
}
