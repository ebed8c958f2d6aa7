//! The uploaded scene: its buffers (bindings 1-4 of glsl/interface/scene_bindings.glsl), the `#define`s
//! that specialise scene kernels to what the scene contains, and the host data renderers read.
//! Renderers are built from an `Arc<SceneGpu>` and share it, so one upload serves every method.
//!
//! Three layouts, chosen by size: uniform buffers (CPU devices, small scenes), storage buffers,
//! and, when the triangles, BVH nodes, emitters, surface attributes or texels exceed one
//! binding's range (`DeviceInfo::scene_binding_limit`), those five arrays in buffers reached by
//! device address, with their bindings (1, 2 and 4 of set 0; the attributes' and texels' of
//! set 1) holding each one's address and length (`SCENE_ADDRESSED`).

use std::sync::Arc;

use anyhow::{Context as _, Result};
use ash::vk::PhysicalDeviceType;

use crate::error::GpuError;
use crate::gpu_types::{Emitter, Material, Triangle, LIGHT_NODE_ROWS, PUNCTUAL_ROWS};
use crate::scene::{ArrayLimit, Scene};
use crate::shader_interface::SceneBinding;
use crate::shading::bsdf::{has_specular_layer, lobe_weights};
use crate::shading::texture::NO_TEXTURE;
use crate::vk::{Binding, BindingFamilyExt, BindingSlot, BoundBuffer, Buffer, BufferUsage, CompiledKernel, Context, Kernel};

use super::surface_gpu::SurfaceGpu;
use super::SceneInfo;

/// A scene on one device: made by [`SceneGpu::upload`], shared by `Arc` among the renderers
/// (`PathTracer`, `Restir`) and oracle kernels that read it.
pub struct SceneGpu {
    ctx: Arc<Context>,
    /// The host data of the scene these buffers hold.
    info: SceneInfo,
    /// `Triangle` records (glsl/interface/types.glsl), one per scene triangle (one placeholder if none).
    pub triangles: Buffer,
    /// The BVH's `BvhNode` records, root first.
    pub nodes: Buffer,
    /// `Material` records, indexed by a triangle's material (one default if none).
    pub materials: Buffer,
    /// `Emitter` rows: the lights (`Scene::emitters`), the light tree
    /// (`Scene::light_tree_rows`), `PUNCTUAL_ROWS` per punctual light and the environment
    /// map's sampling rows.
    pub emitters: Buffer,
    /// Scene arrays are bound as uniform buffers (CPU devices, small scenes), else storage buffers.
    pub uniform: bool,
    /// With the addressed layout: the records bound in place of the triangles, nodes and
    /// emitters (address, then length; see `address_record`).
    addresses: Option<[Buffer; 3]>,
    /// Surface attributes and textures (descriptor set 1), if the scene has any.
    pub surface: Option<SurfaceGpu>,
    defines: Vec<(&'static str, String)>,
}

/// The 16 bytes of a binding that points at an addressed array: its device address (a
/// GL_EXT_buffer_reference, 8 bytes at offset 0 under std430) and its element count.
pub(super) fn address_record(ctx: &Arc<Context>, name: &str, array: &Buffer, length: usize) -> Result<Buffer, GpuError> {
    let address = array.device_address();
    let record = [address as u32, (address >> 32) as u32, length as u32, 0];
    let buffer = Buffer::new(ctx, name, std::mem::size_of_val(&record) as u64, BufferUsage::Params)?;
    buffer.write(&record)?;
    Ok(buffer)
}

impl SceneGpu {
    /// Uploads `scene`'s triangles, BVH nodes, materials, emitters (with the punctual lights'
    /// and environment map's rows) and surface attributes and textures to `ctx`'s device.
    /// Errors: a buffer the device cannot allocate or bind (out of memory, over a binding's
    /// range), named with the scene's file and the array.
    pub fn upload(ctx: &Arc<Context>, scene: &Scene) -> Result<Arc<Self>> {
        let source = scene.source.display();
        let upload = |name: &str, r: Result<Buffer, GpuError>| r.with_context(|| format!("{source}: uploading {name}"));
        let env_rows = scene.environment_map.as_ref().map(|m| m.gpu_rows()).unwrap_or_default();
        let emitter_rows: Vec<Emitter> = scene
            .emitters
            .iter()
            .copied()
            .chain(scene.light_tree_rows())
            .chain(scene.punctual_rows())
            .chain(env_rows)
            .collect();
        let arrays = [
            std::mem::size_of_val(scene.triangles.as_slice()),
            std::mem::size_of_val(scene.nodes.as_slice()),
            std::mem::size_of_val(scene.materials.as_slice()),
            std::mem::size_of_val(emitter_rows.as_slice()),
        ];
        // Materials, texture headers and the material texture table stay bound: a binding
        // holds millions of them.
        let [tri_bytes, node_bytes, _, emitter_bytes] = arrays;
        let surface_bytes = [
            std::mem::size_of_val(scene.surfaces.as_slice()),
            std::mem::size_of_val(scene.textures.texels.as_slice()),
        ];
        let addressed = ctx.info.buffer_device_address
            && [tri_bytes, node_bytes, emitter_bytes]
                .iter()
                .chain(&surface_bytes)
                .any(|&bytes| bytes as u64 > ctx.info.scene_binding_limit);
        // Divergent uniform-buffer indexing serialises on GPUs; on llvmpipe it beats storage loads.
        let uniform = !addressed
            && ctx.info.device_type == PhysicalDeviceType::CPU
            && arrays.iter().all(|&bytes| bytes as u64 <= ctx.info.max_uniform_buffer_range);
        let big = if addressed { BufferUsage::Addressed } else { BufferUsage::Storage };
        let placeholder = [Triangle::default()];
        let no_material = [Material::default()];
        // Vulkan has no empty buffers; a scene of points and lines alone has no triangles,
        // and its BVH's one empty leaf never reads this placeholder.
        let triangles = if scene.triangles.is_empty() {
            &placeholder[..]
        } else {
            &scene.triangles
        };
        let triangles = upload("triangles", Buffer::with_data(ctx, "triangles", triangles, big))?;
        let nodes = upload("BVH nodes", Buffer::with_data(ctx, "BVH nodes", &scene.nodes, big))?;
        let emitters = upload("emitters", Buffer::with_data(ctx, "emitters", &emitter_rows, big))?;
        let addresses = if addressed {
            let record = |name: &str, array: &Buffer, length: usize| upload(name, address_record(ctx, name, array, length));
            Some([
                record("triangle addresses", &triangles, scene.triangles.len())?,
                record("BVH node addresses", &nodes, scene.nodes.len())?,
                record("emitter addresses", &emitters, emitter_rows.len())?,
            ])
        } else {
            None
        };
        let mut defines = scene_defines(scene, uniform);
        if addressed {
            defines.push(("SCENE_ADDRESSED", "1".to_string()));
        }
        Ok(Arc::new(Self {
            ctx: ctx.clone(),
            info: SceneInfo::of(scene),
            triangles,
            nodes,
            materials: upload(
                "materials",
                Buffer::from_slice(
                    ctx,
                    "materials",
                    if scene.materials.is_empty() {
                        &no_material
                    } else {
                        &scene.materials
                    },
                ),
            )?,
            emitters,
            uniform,
            addresses,
            surface: SurfaceGpu::upload(ctx, scene, addressed)?,
            defines,
        }))
    }

    /// The device the buffers live on.
    pub fn ctx(&self) -> &Arc<Context> {
        &self.ctx
    }

    /// The host data of the uploaded scene (cameras, environment, counts).
    pub fn info(&self) -> &SceneInfo {
        &self.info
    }

    /// Whether the triangles, nodes, emitters, surface attributes and texels are reached by
    /// device address.
    pub fn addressed(&self) -> bool {
        self.addresses.is_some()
    }

    /// The buffers of bindings 0-4, with `params` as the frame parameters. In the addressed
    /// layout bindings 1, 2 and 4 hold the arrays' addresses.
    pub fn buffers<'a>(&'a self, params: &'a Buffer) -> Vec<BoundBuffer<'a>> {
        let scene = if self.uniform { Binding::Uniform } else { Binding::Storage };
        let [triangles, nodes, emitters] = match &self.addresses {
            Some([t, n, e]) => [t, n, e],
            None => [&self.triangles, &self.nodes, &self.emitters],
        };
        vec![
            SceneBinding::FrameParams.to(params),
            SceneBinding::Triangles.slot(scene).to(triangles),
            SceneBinding::Nodes.slot(scene).to(nodes),
            SceneBinding::Materials.slot(scene).to(&self.materials),
            SceneBinding::Emitters.slot(scene).to(emitters),
        ]
    }

    /// The layout of bindings 0-4: the frame parameters in a storage buffer, the scene arrays
    /// in uniform or storage buffers (`uniform`).
    pub fn bindings(&self) -> Vec<BindingSlot> {
        let scene = if self.uniform { Binding::Uniform } else { Binding::Storage };
        SceneBinding::ALL
            .iter()
            .map(|&b| b.slot(if b == SceneBinding::FrameParams { Binding::Storage } else { scene }))
            .collect()
    }

    /// The layout of a scene kernel whose set 0 is `set0`: set 1 (`SurfaceBinding`) holds the
    /// surface attributes and textures when the scene has them.
    pub fn layout(&self, mut set0: Vec<BindingSlot>) -> Vec<BindingSlot> {
        if let Some(s) = &self.surface {
            set0.extend(s.bindings());
        }
        set0
    }

    /// Builds scene kernel glsl/`name` with set 0 `set0` (bound by the caller) and binds set 1.
    pub fn kernel(&self, name: &str, defines: &[(&str, &str)], set0: Vec<BindingSlot>, push_bytes: u32) -> Result<Kernel> {
        let kernel = Kernel::new(&self.ctx, name, defines, &self.layout(set0), push_bytes)?;
        self.bind_surface(kernel)
    }

    /// `kernel` from SPIR-V compiled elsewhere (`compile_kernels_in_parallel`).
    pub fn kernel_with_spirv(&self, name: &str, compiled: &CompiledKernel, set0: Vec<BindingSlot>, push_bytes: u32) -> Result<Kernel> {
        let kernel = Kernel::with_spirv(&self.ctx, name, compiled, &self.layout(set0), push_bytes)?;
        self.bind_surface(kernel)
    }

    /// Binds set 1, the surface attributes and textures, if the scene has them.
    fn bind_surface(&self, kernel: Kernel) -> Result<Kernel> {
        if let Some(s) = &self.surface {
            kernel.bind(&s.bound())?;
        }
        Ok(kernel)
    }

    /// The `#define`s every scene kernel is compiled with.
    pub fn defines(&self) -> Vec<(&str, &str)> {
        self.defines.iter().map(|(k, v)| (*k, v.as_str())).collect()
    }
}

/// Specialises kernels to the BSDF lobes and light types the scene uses, and sizes the uniform
/// arrays when the scene is bound as uniform buffers.
fn scene_defines(scene: &Scene, uniform: bool) -> Vec<(&'static str, String)> {
    // A metallic-roughness texture scales metallic anywhere down to 0, which brings in the
    // non-metal lobes.
    let variants: Vec<Material> = scene
        .materials
        .iter()
        .enumerate()
        .flat_map(|(i, m)| {
            let textured = scene
                .textures
                .materials
                .get(i)
                .is_some_and(|t| t.metal_rough.texture_index != NO_TEXTURE);
            let dielectric = Material { metallic: 0.0, ..*m };
            std::iter::once(*m).chain(textured.then_some(dielectric))
        })
        .collect();
    let used = |pick: fn((f32, f32, f32)) -> f32| variants.iter().any(|m| pick(lobe_weights(m)) > 0.0);
    let flag = |on: bool| if on { "1" } else { "0" }.to_string();
    // The light tree's rows (with its header) and the punctual lights', after the emitters.
    let light_rows = PUNCTUAL_ROWS * scene.lights.len() + 1 + LIGHT_NODE_ROWS * scene.light_nodes.len();
    let mut defines = vec![
        ("BSDF_DIFFUSE", flag(used(|w| w.0))),
        ("BSDF_CONDUCTOR", flag(used(|w| w.1))),
        ("BSDF_DIELECTRIC", flag(used(|w| w.2))),
        // The layer needs a non-metal lobe, which a metallic texture can give a metal factor.
        ("BSDF_SPECULAR", flag(variants.iter().any(has_specular_layer))),
        ("SCENE_ENVIRONMENT", flag(scene.env_select_prob > 0.0)),
        ("SCENE_EMITTERS", flag(!scene.emitters.is_empty())),
        ("SCENE_PUNCTUAL", flag(!scene.lights.is_empty())),
        ("SCENE_DIRECTIONAL", flag(scene.directional_count > 0)),
        ("SCENE_ENV_MAP", flag(scene.environment_map.is_some())),
        ("SCENE_ENV_MAP_BASE", format!("{}u", light_rows)),
        ("SCENE_UNIFORM_BUFFERS", flag(uniform)),
        ("SCENE_SURFACE", flag(!scene.surfaces.is_empty())),
        ("SCENE_TEXTURES", flag(!scene.surfaces.is_empty() && !scene.textures.is_empty())),
        ("SCENE_SHADING_NORMALS", flag(scene.has_shading_normals())),
    ];
    // Only scenes that alpha-test define it: opaque scenes keep their kernels' code unchanged.
    if scene.alpha().is_some() {
        defines.push(("SCENE_ALPHA", "1".to_string()));
    }
    if uniform {
        defines.extend([
            ("SCENE_TRIANGLE_COUNT", scene.triangles.len().max(1).to_string()),
            ("SCENE_NODE_COUNT", scene.nodes.len().to_string()),
            ("SCENE_MATERIAL_COUNT", scene.materials.len().max(1).to_string()),
            (
                "SCENE_EMITTER_SLOTS",
                (scene.emitters.len()
                    + light_rows
                    + scene
                        .environment_map
                        .as_ref()
                        .map_or(0, |m| 1 + (m.height + m.width * m.height) as usize))
                .max(1)
                .to_string(),
            ),
        ]);
    }
    defines
}

/// The most bytes one scene array may take on `ctx`'s device: a buffer reached by device address
/// where the device has bufferDeviceAddress, else one storage binding. The loader's budget
/// (`scene::LoadOptions`) takes it; it lives here, where the scene meets the device, because
/// neither layer knows the other.
pub fn scene_array_limit(ctx: &Context) -> ArrayLimit {
    if ctx.info.buffer_device_address {
        ArrayLimit {
            bytes: ctx.info.max_allocation_bytes,
            name: "maxMemoryAllocationSize",
        }
    } else {
        ArrayLimit {
            bytes: ctx.info.max_storage_buffer_range,
            name: "maxStorageBufferRange",
        }
    }
}
