//! Textures, texture references and vertex attributes (NORMAL, TEXCOORD_n) for generated scenes.

use glam::{Vec2, Vec3, Vec4};
use serde_json::{json, Value};

use super::{GltfBuilder, MeshData};

/// glTF sampler wrap mode REPEAT (the OpenGL enum glTF uses).
pub const WRAP_REPEAT: u32 = 10497;
/// glTF sampler wrap mode CLAMP_TO_EDGE.
pub const WRAP_CLAMP_TO_EDGE: u32 = 33071;
/// glTF sampler wrap mode MIRRORED_REPEAT.
pub const WRAP_MIRRORED_REPEAT: u32 = 33648;
/// glTF sampler filter NEAREST.
pub const FILTER_NEAREST: u32 = 9728;
/// glTF sampler filter LINEAR.
pub const FILTER_LINEAR: u32 = 9729;

impl GltfBuilder {
    /// Embeds an encoded image (`mime`: image/png or image/jpeg) in the buffer with a sampler
    /// (`wrap` S and T, magnification filter `mag_filter`); returns the texture's index.
    pub fn texture(&mut self, encoded: &[u8], mime: &str, wrap: [u32; 2], mag_filter: u32) -> usize {
        while !self.buffer.len().is_multiple_of(4) {
            self.buffer.push(0);
        }
        self.buffer_views
            .push(json!({ "buffer": 0, "byteOffset": self.buffer.len(), "byteLength": encoded.len() }));
        self.buffer.extend_from_slice(encoded);
        self.images
            .push(json!({ "bufferView": self.buffer_views.len() - 1, "mimeType": mime }));
        self.samplers
            .push(json!({ "wrapS": wrap[0], "wrapT": wrap[1], "magFilter": mag_filter }));
        self.textures
            .push(json!({ "source": self.images.len() - 1, "sampler": self.samplers.len() - 1 }));
        self.textures.len() - 1
    }

    /// Sets a member of material `material` by its path of keys, e.g.
    /// `["pbrMetallicRoughness", "baseColorTexture"]` to `{"index": 0}`.
    pub fn set_material_field(&mut self, material: usize, path: &[&str], value: Value) {
        let mut at = &mut self.materials[material];
        for key in &path[..path.len() - 1] {
            if at.get(*key).is_none() {
                at[*key] = json!({});
            }
            at = &mut at[*key];
        }
        at[path[path.len() - 1]] = value;
    }

    /// Declares an extension used (e.g. KHR_texture_transform).
    pub fn declare_extension(&mut self, name: &'static str) {
        self.use_extension(name);
    }

    /// A mesh of one triangle-list primitive with NORMAL (if given) and TEXCOORD_0, TEXCOORD_1...
    /// (one per entry of `uv`).
    pub fn mesh_with_attributes(
        &mut self,
        name: &str,
        data: &MeshData,
        normals: Option<&[Vec3]>,
        uv: &[&[Vec2]],
        material: usize,
    ) -> usize {
        let mesh = self.mesh(name, data, material);
        if let Some(n) = normals {
            let accessor = self.vec3_accessor(n, 34962);
            self.meshes[mesh]["primitives"][0]["attributes"]["NORMAL"] = json!(accessor);
        }
        for (set, coords) in uv.iter().enumerate() {
            let floats: Vec<f32> = coords.iter().flat_map(|c| [c.x, c.y]).collect();
            let view = self.push_view(bytemuck::cast_slice(&floats), 34962);
            let accessor = self.push_accessor(json!({ "bufferView": view, "componentType": 5126, "count": coords.len(), "type": "VEC2" }));
            self.meshes[mesh]["primitives"][0]["attributes"][format!("TEXCOORD_{set}")] = json!(accessor);
        }
        mesh
    }

    /// Gives mesh `mesh`'s first primitive a TANGENT attribute: xyz the tangent (along +u of the
    /// normal texture's coordinates), w the handedness ±1 (bitangent = w · cross(normal, tangent)).
    pub fn set_tangents(&mut self, mesh: usize, tangents: &[Vec4]) {
        let floats: Vec<f32> = tangents.iter().flat_map(|t| t.to_array()).collect();
        let view = self.push_view(bytemuck::cast_slice(&floats), 34962);
        let accessor = self.push_accessor(json!({ "bufferView": view, "componentType": 5126, "count": tangents.len(), "type": "VEC4" }));
        self.meshes[mesh]["primitives"][0]["attributes"]["TANGENT"] = json!(accessor);
    }
}

/// A UV sphere with outward fronts, its unit normals and texture coordinates u = longitude / 2π
/// (from +X towards +Z), v = colatitude / π (0 at +Y); the seam column is duplicated so that u
/// runs to 1.
pub fn textured_sphere(center: Vec3, radius: f32, rings: u32, segments: u32) -> (MeshData, Vec<Vec3>, Vec<Vec2>) {
    let (mut positions, mut normals, mut uv) = (Vec::new(), Vec::new(), Vec::new());
    let columns = segments + 1;
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..columns {
            let phi = 2.0 * std::f32::consts::PI * s as f32 / segments as f32;
            let dir = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            positions.push(center + radius * dir);
            normals.push(dir);
            uv.push(Vec2::new(s as f32 / segments as f32, r as f32 / rings as f32));
        }
    }
    let mut indices = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * columns + s, r * columns + s + 1);
            let (c, d) = (a + columns, b + columns);
            if r > 0 {
                indices.extend([a, b, c]);
            }
            if r + 1 < rings {
                indices.extend([b, d, c]);
            }
        }
    }
    (MeshData { positions, indices }, normals, uv)
}
