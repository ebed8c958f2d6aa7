//! The surface attributes and textures of a scene on the device: descriptor set 1 of scene
//! kernels (glsl/surface_bindings.glsl), present only when the scene has them.

use std::sync::Arc;

use anyhow::{Context as _, Result};

use crate::scene::Scene;
use crate::shader_interface::SurfaceBinding;
use crate::vk::{Binding, BindingSlot, BoundBuffer, Buffer, Context};

/// Set 1's buffers: the per-triangle attributes, then (with textures) the material texture
/// table, the texture headers and the texels.
pub struct SurfaceGpu {
    /// The set's storage buffers in binding order (glsl/surface_bindings.glsl): one without
    /// textures, four with them.
    pub buffers: Vec<Buffer>,
    /// Bytes uploaded for textures (texels, headers, material table).
    pub texture_bytes: usize,
    /// Bytes uploaded for the per-triangle attributes.
    pub attribute_bytes: usize,
}

impl SurfaceGpu {
    /// `None` for a scene without attributes (flat faces and no textures).
    pub fn upload(ctx: &Arc<Context>, scene: &Scene) -> Result<Option<Self>> {
        if scene.surfaces.is_empty() {
            return Ok(None);
        }
        let source = scene.source.display();
        let mut buffers = vec![Buffer::from_slice(ctx, "surface attributes", &scene.surfaces)
            .with_context(|| format!("{source}: uploading the surface attributes"))?];
        let attribute_bytes = std::mem::size_of_val(scene.surfaces.as_slice()) as u64;
        if attribute_bytes > ctx.info.scene_binding_limit {
            anyhow::bail!(
                "{source}: the vertex attributes take {attribute_bytes} bytes, more than one binding holds on this device ({})",
                ctx.info.scene_binding_limit
            );
        }
        let t = &scene.textures;
        let texel_bytes = std::mem::size_of_val(t.texels.as_slice()) as u64;
        if texel_bytes > ctx.info.scene_binding_limit {
            anyhow::bail!(
                "{source}: the textures take {texel_bytes} bytes, more than one binding holds on this device ({}); textures are not split across bindings",
                ctx.info.scene_binding_limit
            );
        }
        if !t.is_empty() {
            // Vulkan has no empty buffers: a scene whose only non-opaque material has no texture.
            let headers = if t.headers.is_empty() {
                vec![Default::default()]
            } else {
                t.headers.clone()
            };
            let texels = if t.texels.is_empty() { vec![0u32] } else { t.texels.clone() };
            let upload = |name: &str, r: Result<Buffer, crate::error::GpuError>| r.with_context(|| format!("{source}: uploading {name}"));
            buffers.push(upload(
                "material textures",
                Buffer::from_slice(ctx, "material textures", &t.materials),
            )?);
            buffers.push(upload("texture headers", Buffer::from_slice(ctx, "texture headers", &headers))?);
            buffers.push(upload("texels", Buffer::from_slice(ctx, "texels", &texels))?);
        }
        Ok(Some(Self {
            buffers,
            texture_bytes: t.gpu_bytes(),
            attribute_bytes: std::mem::size_of_val(scene.surfaces.as_slice()),
        }))
    }

    /// Set 1's layout: the attributes, then the three texture bindings when uploaded.
    pub fn bindings(&self) -> Vec<BindingSlot> {
        SurfaceBinding::ALL[..self.buffers.len()]
            .iter()
            .map(|b| b.slot(Binding::Storage))
            .collect()
    }

    /// Set 1's buffers, each at its `SurfaceBinding`.
    pub fn bound(&self) -> Vec<BoundBuffer<'_>> {
        SurfaceBinding::ALL
            .iter()
            .zip(&self.buffers)
            .map(|(b, buffer)| b.to(buffer))
            .collect()
    }
}
