//! The surface attributes and textures of a scene on the device: descriptor set 1 of scene
//! kernels (glsl/interface/surface_bindings.glsl), present only when the scene has them.

use std::sync::Arc;

use anyhow::{Context as _, Result};

use crate::error::GpuError;
use crate::scene::Scene;
use crate::shader_interface::SurfaceBinding;
use crate::vk::{Binding, BindingFamilyExt, BindingSlot, BoundBuffer, Buffer, BufferUsage, Context};

use super::scene_gpu::address_record;

/// Set 1's buffers: the per-triangle attributes, then (with textures) the material texture
/// table, the texture headers and the texels.
pub struct SurfaceGpu {
    /// The set's storage buffers in binding order (glsl/interface/surface_bindings.glsl): one without
    /// textures, four with them. In the addressed layout the attributes' and texels' bindings
    /// hold an address record (`scene_gpu::address_record`) in place of the array.
    pub buffers: Vec<Buffer>,
    /// In the addressed layout, the attribute and texel arrays the records point at.
    addressed: Vec<Buffer>,
    /// Bytes uploaded for textures (texels, headers, material table).
    pub texture_bytes: usize,
    /// Bytes uploaded for the per-triangle attributes.
    pub attribute_bytes: usize,
}

impl SurfaceGpu {
    /// `None` for a scene without attributes (flat faces and no textures). With `addressed`
    /// (the scene's arrays are reached by device address, `SceneGpu::addressed`) the
    /// attributes and texels are too, so that neither is bounded by one binding's range.
    /// Errors: a buffer the device cannot allocate, or, bound, an array past one binding.
    pub fn upload(ctx: &Arc<Context>, scene: &Scene, addressed: bool) -> Result<Option<Self>> {
        if scene.surfaces.is_empty() {
            return Ok(None);
        }
        let source = scene.source.display();
        let upload = |name: &str, r: Result<Buffer, GpuError>| r.with_context(|| format!("{source}: uploading {name}"));
        let t = &scene.textures;
        // Vulkan has no empty buffers: a scene whose only non-opaque material has no texture.
        let no_texels = [0u32];
        let texels: &[u32] = if t.texels.is_empty() { &no_texels } else { &t.texels };
        let mut arrays = vec![(
            "surface attributes",
            bytemuck::cast_slice::<_, u8>(&scene.surfaces),
            scene.surfaces.len(),
        )];
        if !t.is_empty() {
            arrays.push(("texels", bytemuck::cast_slice::<_, u8>(texels), texels.len()));
        }
        let mut stored = Vec::new();
        let mut bound = Vec::new();
        for (name, bytes, length) in arrays {
            if addressed {
                let array = upload(name, Buffer::with_data(ctx, name, bytes, BufferUsage::Addressed))?;
                bound.push(upload(name, address_record(ctx, name, &array, length))?);
                stored.push(array);
            } else {
                if bytes.len() as u64 > ctx.info.scene_binding_limit {
                    anyhow::bail!(
                        "{source}: the {name} take {} bytes, more than one binding holds on this device ({}), and the device lacks bufferDeviceAddress",
                        bytes.len(),
                        ctx.info.scene_binding_limit
                    );
                }
                bound.push(upload(name, Buffer::from_slice(ctx, name, bytes))?);
            }
        }
        let mut buffers = vec![bound.remove(0)];
        if !t.is_empty() {
            let headers = if t.headers.is_empty() {
                vec![Default::default()]
            } else {
                t.headers.clone()
            };
            buffers.push(upload(
                "material textures",
                Buffer::from_slice(ctx, "material textures", &t.materials),
            )?);
            buffers.push(upload("texture headers", Buffer::from_slice(ctx, "texture headers", &headers))?);
            buffers.push(bound.remove(0));
        }
        Ok(Some(Self {
            buffers,
            addressed: stored,
            texture_bytes: t.gpu_bytes(),
            attribute_bytes: std::mem::size_of_val(scene.surfaces.as_slice()),
        }))
    }

    /// Whether the attributes and texels are reached by device address.
    pub fn addressed(&self) -> bool {
        !self.addressed.is_empty()
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
