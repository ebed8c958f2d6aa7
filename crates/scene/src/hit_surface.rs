//! What a hit on the scene sees: its surface (crates/shading-core/src/surface.rs) and its material with textures
//! applied (crates/shading-core/src/texture.rs). Host counterparts of `surface_at`, `material_at` and
//! `normal_mapped` in glsl/shading_core/surface.glsl and glsl/shading_core/texture.glsl.

use glam::{Vec2, Vec3};

use restir_pt_interface::gpu_types::Material;
use restir_pt_shading_core::alpha::AlphaScene;
use restir_pt_shading_core::surface::{surface_at, SurfaceHit, TriangleSurface};
use restir_pt_shading_core::texture::{normal_mapped, textured_material, vertex_colored, ALPHA_OPAQUE, NO_TEXTURE};

use super::Scene;

impl Scene {
    /// What traversal needs to alpha-test hits (the kernels' `SCENE_ALPHA`); `None` when every
    /// material is opaque.
    pub fn alpha(&self) -> Option<AlphaScene<'_>> {
        let any = self.textures.materials.iter().any(|t| t.alpha_mode != ALPHA_OPAQUE);
        (any && !self.surfaces.is_empty()).then_some(AlphaScene {
            surfaces: &self.surfaces,
            textures: &self.textures,
        })
    }

    /// The surface of triangle `triangle` at barycentrics `bary` (flat where the scene has no
    /// attributes).
    pub fn surface_at(&self, triangle: u32, bary: Vec2) -> SurfaceHit {
        let flat = TriangleSurface::flat();
        let attr = self.surfaces.get(triangle as usize).unwrap_or(&flat);
        surface_at(&self.triangles[triangle as usize], attr, bary)
    }

    /// The material of triangle `triangle` at barycentrics `bary`, its textures and vertex
    /// colour applied. Twin of GLSL `material_at`.
    pub fn material_at(&self, triangle: u32, bary: Vec2) -> Material {
        let index = self.triangles[triangle as usize].material as usize;
        let m = &self.materials[index];
        if self.surfaces.is_empty() {
            return *m;
        }
        let s = self.surface_at(triangle, bary);
        if self.textures.is_empty() {
            return vertex_colored(m, &s);
        }
        vertex_colored(&textured_material(m, &self.textures.materials[index], &self.textures, &s), &s)
    }

    /// The shading normal of triangle `triangle` at `bary` (unit, scene space, not flipped): the
    /// interpolated vertex normal with its material's normal map applied; the geometric normal
    /// as wound where there are neither. Twin of GLSL `shading_normal` (glsl/scene/hit_surface.glsl).
    pub fn shading_normal(&self, triangle: u32, bary: Vec2) -> Vec3 {
        let s = self.surface_at(triangle, bary);
        if self.textures.is_empty() || self.surfaces.is_empty() {
            return s.normal;
        }
        let index = self.triangles[triangle as usize].material as usize;
        normal_mapped(&self.textures.materials[index], &self.textures, &s)
    }

    /// The material (textures applied) and the shading normal of triangle `triangle` at `bary`,
    /// from one surface: what the path tracer hands the BSDF with the geometric normal. Twin of
    /// GLSL `hit_shading` (glsl/scene/hit_surface.glsl).
    pub fn hit_shading(&self, triangle: u32, bary: Vec2) -> (Material, Vec3) {
        let index = self.triangles[triangle as usize].material as usize;
        let m = &self.materials[index];
        let s = self.surface_at(triangle, bary);
        if self.surfaces.is_empty() {
            return (*m, s.normal);
        }
        if self.textures.is_empty() {
            return (vertex_colored(m, &s), s.normal);
        }
        let t = &self.textures.materials[index];
        (
            vertex_colored(&textured_material(m, t, &self.textures, &s), &s),
            normal_mapped(t, &self.textures, &s),
        )
    }

    /// Whether any shading normal can differ from the geometric normal: some triangle has vertex
    /// normals, or some material a normal map. Without, kernels compile without the shading frame
    /// (`SCENE_SHADING_NORMALS 0`) and shade with the geometric normal.
    pub fn has_shading_normals(&self) -> bool {
        if self.surfaces.is_empty() {
            return false;
        }
        let normal_map = !self.textures.is_empty() && self.textures.materials.iter().any(|t| t.normal.texture_index != NO_TEXTURE);
        normal_map || self.surfaces.iter().any(|s| s.normal.iter().any(|n| n[..3] != [0.0; 3]))
    }

    /// One line on the vertex attributes and textures and the device memory they take, or
    /// `None` for a scene without them.
    pub fn surface_summary(&self) -> Option<String> {
        if self.surfaces.is_empty() {
            return None;
        }
        let mib = |bytes: usize| bytes as f64 / (1024.0 * 1024.0);
        let attributes = mib(std::mem::size_of_val(self.surfaces.as_slice()));
        let t = &self.textures;
        let sizes: Vec<String> = t.headers.iter().map(|h| format!("{}x{}", h.width, h.height)).collect();
        Some(format!(
            "surface: vertex attributes {attributes:.2} MiB; {} texture(s) [{}] {:.2} MiB (RGBA8 texels in a storage buffer, no mipmaps)",
            t.headers.len(),
            sizes.join(", "),
            mib(t.gpu_bytes())
        ))
    }
}
