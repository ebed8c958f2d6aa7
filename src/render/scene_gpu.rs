//! The scene's storage buffers (bindings 1-4 of glsl/scene_bindings.glsl).

use std::sync::Arc;

use anyhow::{Context as _, Result};

use crate::scene::Scene;
use crate::vk::{Buffer, Context};

pub struct SceneGpu {
    pub triangles: Buffer,
    pub nodes: Buffer,
    pub materials: Buffer,
    pub emitters: Buffer,
}

impl SceneGpu {
    pub fn upload(ctx: &Arc<Context>, scene: &Scene) -> Result<Self> {
        let source = scene.source.display();
        let upload = |name: &str, r: Result<Buffer, crate::error::GpuError>| r.with_context(|| format!("{source}: uploading {name}"));
        Ok(Self {
            triangles: upload("triangles", Buffer::from_slice(ctx, "triangles", &scene.triangles))?,
            nodes: upload("BVH nodes", Buffer::from_slice(ctx, "BVH nodes", &scene.nodes))?,
            materials: upload("materials", Buffer::from_slice(ctx, "materials", &scene.materials))?,
            emitters: upload("emitters", Buffer::from_slice(ctx, "emitters", &scene.emitters))?,
        })
    }

    /// The scene bindings 1-4 in order, after the frame parameters at binding 0.
    pub fn bindings<'a>(&'a self, params: &'a Buffer) -> Vec<&'a Buffer> {
        vec![params, &self.triangles, &self.nodes, &self.materials, &self.emitters]
    }
}
