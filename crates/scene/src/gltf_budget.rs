//! The triangle count a file will produce, estimated from its accessor counts before any vertex
//! is read, so that a scene past the device's per-binding limit fails at once rather than after
//! the load and the BVH build.

use anyhow::{bail, Result};

use restir_pt_interface::gpu_types::Triangle;
use restir_pt_shading_core::surface::TriangleSurface;

use super::gltf_loader::{problem, Loader, MAX_NODE_DEPTH, MAX_NODE_INSTANCES};

/// The most bytes the device lets one scene array (the surface attributes or, without them, the
/// triangles: the largest) take, and the
/// limit's Vulkan name for messages: maxStorageBufferRange when arrays are bound,
/// maxMemoryAllocationSize when they are reached by device address
/// (`restir_pt::render::scene_array_limit`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArrayLimit {
    /// The limit in bytes.
    pub bytes: u64,
    /// The Vulkan limit's name, e.g. "maxStorageBufferRange".
    pub name: &'static str,
}

/// Triangles a primitive of `mode` draws from `count` vertices or indices (before degenerate
/// ones are dropped); points and lines draw none.
fn triangles_of(mode: gltf::mesh::Mode, count: usize) -> usize {
    use gltf::mesh::Mode;
    match mode {
        Mode::Triangles => count / 3,
        Mode::TriangleStrip | Mode::TriangleFan => count.saturating_sub(2),
        _ => 0,
    }
}

fn mesh_triangles(mesh: &gltf::Mesh) -> usize {
    mesh.primitives()
        .map(|p| {
            let count = match p.indices() {
                Some(i) => i.count(),
                None => p.get(&gltf::Semantic::Positions).map_or(0, |a| a.count()),
            };
            triangles_of(p.mode(), count)
        })
        .sum()
}

impl Loader<'_> {
    /// Walks the scene's node instances (as the load will, within the same depth and instance
    /// limits) and sums the triangles of their meshes, times `EXT_mesh_gpu_instancing` counts.
    pub(super) fn estimate_triangles(&self, scene: &gltf::Scene) -> usize {
        let mut total = 0usize;
        let mut visits = 0usize;
        let mut stack: Vec<(gltf::Node, usize)> = scene.nodes().map(|n| (n, 0)).collect();
        while let Some((node, depth)) = stack.pop() {
            visits += 1;
            if depth > MAX_NODE_DEPTH || visits > MAX_NODE_INSTANCES {
                break;
            }
            if let Some(mesh) = node.mesh() {
                let copies = self.instancing.get(&node.index()).map_or(1, |inst| {
                    [inst.translation, inst.rotation, inst.scale]
                        .into_iter()
                        .flatten()
                        .filter_map(|a| self.doc.accessors().nth(a).map(|a| a.count()))
                        .min()
                        .unwrap_or(1)
                });
                total = total.saturating_add(mesh_triangles(&mesh).saturating_mul(copies));
            }
            stack.extend(node.children().map(|c| (c, depth + 1)));
        }
        total
    }

    /// Whether the file's triangles may carry vertex attributes (normals, tangents, texture
    /// coordinates, colours) or textures, so that the scene gets a [`TriangleSurface`] per
    /// triangle, its largest per-triangle array.
    fn has_surface_attributes(&self) -> bool {
        use gltf::Semantic;
        self.doc.textures().next().is_some()
            || self.doc.meshes().flat_map(|m| m.primitives()).any(|p| {
                p.attributes().any(|(s, _)| {
                    matches!(
                        s,
                        Semantic::Normals | Semantic::Tangents | Semantic::TexCoords(_) | Semantic::Colors(_)
                    )
                })
            })
    }

    /// Fails if the estimated triangles' largest per-triangle array (the [`TriangleSurface`]
    /// attributes if the file has any, else the [`Triangle`] records) would not fit one array
    /// of `limit`.
    pub(super) fn check_array_budget(&self, scene: &gltf::Scene, limit: ArrayLimit) -> Result<()> {
        let estimate = self.estimate_triangles(scene);
        let (record, array) = if self.has_surface_attributes() {
            (std::mem::size_of::<TriangleSurface>() as u64, "vertex attributes")
        } else {
            (std::mem::size_of::<Triangle>() as u64, "triangles")
        };
        let bytes = estimate as u64 * record;
        if bytes > limit.bytes {
            bail!(problem(
                self.path,
                format!(
                    "about {estimate} triangles' {array} need {bytes} bytes in one buffer, more than the device allows ({} bytes, {}; at most {} triangles)",
                    limit.bytes,
                    limit.name,
                    limit.bytes / record
                )
            ));
        }
        Ok(())
    }
}
