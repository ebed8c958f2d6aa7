//! Writes glTF 2.0 files with the buffer embedded as a base64 data URI, so that each bundled
//! scene is one self-contained, byte-for-byte reproducible text file.

use glam::{Quat, Vec3};
use serde_json::{json, Value};

mod textures;

pub use textures::{textured_sphere, FILTER_LINEAR, FILTER_NEAREST, WRAP_CLAMP_TO_EDGE, WRAP_MIRRORED_REPEAT, WRAP_REPEAT};

/// A glTF metallic-roughness material to write (the fields map to [`restir_pt_interface::gpu_types::Material`]'s).
#[derive(Debug, Clone, Copy)]
pub struct MaterialSpec {
    /// baseColorFactor (linear RGB; alpha is written as 1).
    pub base_color: Vec3,
    /// metallicFactor in [0, 1].
    pub metallic: f32,
    /// roughnessFactor (perceptual roughness) in [0, 1].
    pub roughness: f32,
    /// Emitted radiance (linear RGB, W/(m² sr)); written as emissiveFactor scaled to at most 1
    /// and `KHR_materials_emissive_strength` for the rest.
    pub emission: Vec3,
    /// `KHR_materials_transmission` transmissionFactor in [0, 1]; written when non-zero.
    pub transmission: f32,
    /// `KHR_materials_ior`; written (with the transmission) only when `transmission` > 0.
    pub ior: f32,
    /// glTF `doubleSided`.
    pub double_sided: bool,
    /// `KHR_materials_specular` specularFactor of the non-metal part (glTF's default is 1);
    /// written only where it differs from 1 on a material with a non-metal part.
    pub specular: f32,
}

impl MaterialSpec {
    /// A Lambertian surface: a non-metal without the specular layer (specularFactor 0).
    pub fn diffuse(c: Vec3) -> Self {
        Self {
            base_color: c,
            metallic: 0.0,
            roughness: 1.0,
            emission: Vec3::ZERO,
            transmission: 0.0,
            ior: 1.5,
            double_sided: false,
            specular: 0.0,
        }
    }
    /// A GGX conductor (metallic 1) of F0 `c` and perceptual `roughness`.
    pub fn conductor(c: Vec3, roughness: f32) -> Self {
        Self {
            metallic: 1.0,
            roughness,
            ..Self::diffuse(c)
        }
    }
    /// A clear dielectric (transmission 1, white) of index `ior`; roughness below about 0.032 is
    /// a smooth interface.
    pub fn glass(ior: f32, roughness: f32) -> Self {
        Self {
            transmission: 1.0,
            ior,
            roughness,
            ..Self::diffuse(Vec3::ONE)
        }
    }
    /// A glTF non-metal as the core spec defines it: a Lambertian base under a GGX specular layer
    /// of F0 0.04 (docs/materials.md).
    pub fn plastic(c: Vec3, roughness: f32) -> Self {
        Self {
            roughness,
            specular: 1.0,
            ..Self::diffuse(c)
        }
    }
    /// A black, one-sided area light emitting `radiance` (linear RGB, W/(m² sr)) from its front.
    pub fn emitter(radiance: Vec3) -> Self {
        Self {
            emission: radiance,
            ..Self::diffuse(Vec3::ZERO)
        }
    }
}

/// A triangle mesh in object space; triangles wound counter-clockwise seen from the front.
#[derive(Debug, Clone, Default)]
pub struct MeshData {
    /// Vertex positions, object space.
    pub positions: Vec<Vec3>,
    /// Three indices into `positions` per triangle.
    pub indices: Vec<u32>,
}

impl MeshData {
    /// A quad with corners c, c+a, c+a+b, c+b; its front faces along a x b.
    pub fn quad(c: Vec3, a: Vec3, b: Vec3) -> MeshData {
        MeshData {
            positions: vec![c, c + a, c + a + b, c + b],
            indices: vec![0, 1, 2, 0, 2, 3],
        }
    }

    /// An axis-aligned box with outward-facing fronts.
    pub fn cuboid(lo: Vec3, hi: Vec3) -> MeshData {
        let d = hi - lo;
        let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
        let faces = [
            MeshData::quad(lo, y, x),
            MeshData::quad(lo + z, x, y),
            MeshData::quad(lo, z, y),
            MeshData::quad(lo + x, y, z),
            MeshData::quad(lo, x, z),
            MeshData::quad(lo + y, z, x),
        ];
        faces.iter().fold(MeshData::default(), |acc, f| acc.merged(f))
    }

    /// A UV sphere with outward-facing fronts.
    pub fn sphere(center: Vec3, radius: f32, rings: u32, segments: u32) -> MeshData {
        let mut positions = Vec::new();
        for r in 0..=rings {
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            for s in 0..segments {
                let phi = 2.0 * std::f32::consts::PI * s as f32 / segments as f32;
                let dir = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
                positions.push(center + radius * dir);
            }
        }
        let mut indices = Vec::new();
        for r in 0..rings {
            for s in 0..segments {
                let (a, b) = (r * segments + s, r * segments + (s + 1) % segments);
                let (c, d) = (a + segments, b + segments);
                if r > 0 {
                    indices.extend([a, b, c]);
                }
                if r + 1 < rings {
                    indices.extend([b, d, c]);
                }
            }
        }
        MeshData { positions, indices }
    }

    /// The same surface with the other face in front (e.g. a box seen from inside).
    pub fn flipped(&self) -> MeshData {
        let mut out = self.clone();
        out.indices.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
        out
    }

    /// One mesh holding both: `other`'s vertices appended, its indices shifted to match.
    pub fn merged(&self, other: &MeshData) -> MeshData {
        let base = self.positions.len() as u32;
        let mut out = self.clone();
        out.positions.extend(&other.positions);
        out.indices.extend(other.indices.iter().map(|i| i + base));
        out
    }
}

/// Assembles a glTF 2.0 document (one embedded buffer, materials, meshes, nodes, cameras, lights,
/// textures) item by item; [`GltfBuilder::finish`] returns its JSON text. Indices returned by the
/// adding methods are glTF array indices, for use in later calls.
#[derive(Default)]
pub struct GltfBuilder {
    buffer: Vec<u8>,
    buffer_views: Vec<Value>,
    accessors: Vec<Value>,
    materials: Vec<Value>,
    meshes: Vec<Value>,
    cameras: Vec<Value>,
    nodes: Vec<Value>,
    roots: Vec<usize>,
    extensions_used: Vec<&'static str>,
    required: Vec<&'static str>,
    lights: Vec<Value>,
    images: Vec<Value>,
    samplers: Vec<Value>,
    textures: Vec<Value>,
}

/// glTF's primitive mode for triangle lists (the default).
pub const MODE_TRIANGLES: u32 = 4;

fn round6(x: f32) -> f64 {
    // Six decimals keep the JSON short and stable across platforms.
    (x as f64 * 1e6).round() / 1e6
}

fn vec_json(v: Vec3) -> Value {
    json!([round6(v.x), round6(v.y), round6(v.z)])
}

impl GltfBuilder {
    fn use_extension(&mut self, name: &'static str) {
        if !self.extensions_used.contains(&name) {
            self.extensions_used.push(name);
        }
    }

    /// Adds material `m` named `name`, declaring the extensions it needs; returns its index.
    pub fn material(&mut self, name: &str, m: MaterialSpec) -> usize {
        let mut value = json!({
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [round6(m.base_color.x), round6(m.base_color.y), round6(m.base_color.z), 1.0],
                "metallicFactor": round6(m.metallic),
                "roughnessFactor": round6(m.roughness),
            },
        });
        let mut extensions = serde_json::Map::new();
        if m.emission.max_element() > 0.0 {
            // glTF clamps emissiveFactor to [0, 1]; the strength extension carries the scale.
            let strength = m.emission.max_element();
            value["emissiveFactor"] = vec_json(m.emission / strength);
            if strength != 1.0 {
                extensions.insert(
                    "KHR_materials_emissive_strength".into(),
                    json!({ "emissiveStrength": round6(strength) }),
                );
                self.use_extension("KHR_materials_emissive_strength");
            }
        }
        if m.transmission > 0.0 {
            extensions.insert(
                "KHR_materials_transmission".into(),
                json!({ "transmissionFactor": round6(m.transmission) }),
            );
            extensions.insert("KHR_materials_ior".into(), json!({ "ior": round6(m.ior) }));
            self.use_extension("KHR_materials_transmission");
            self.use_extension("KHR_materials_ior");
        }
        if m.specular != 1.0 && m.metallic < 1.0 && m.transmission < 1.0 {
            extensions.insert("KHR_materials_specular".into(), json!({ "specularFactor": round6(m.specular) }));
            self.use_extension("KHR_materials_specular");
        }
        if !extensions.is_empty() {
            value["extensions"] = Value::Object(extensions);
        }
        if m.double_sided {
            value["doubleSided"] = json!(true);
        }
        self.materials.push(value);
        self.materials.len() - 1
    }

    fn push_view(&mut self, bytes: &[u8], target: u32) -> usize {
        while !self.buffer.len().is_multiple_of(4) {
            self.buffer.push(0);
        }
        self.buffer_views
            .push(json!({ "buffer": 0, "byteOffset": self.buffer.len(), "byteLength": bytes.len(), "target": target }));
        self.buffer.extend_from_slice(bytes);
        self.buffer_views.len() - 1
    }

    /// Adds a triangle-list mesh of `data` drawn with material index `material`; returns the mesh
    /// index (place it with [`GltfBuilder::instance`]).
    pub fn mesh(&mut self, name: &str, data: &MeshData, material: usize) -> usize {
        self.mesh_primitive(name, &data.positions, &data.indices, MODE_TRIANGLES, None, material)
    }

    fn push_accessor(&mut self, accessor: Value) -> usize {
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn vec3_accessor(&mut self, values: &[Vec3], target: u32) -> usize {
        let floats: Vec<f32> = values.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
        // Bounds over the finite values only: non-finite data (loader tests) must reach the
        // loader's own checks rather than fail JSON validation.
        let finite = values.iter().filter(|p| p.is_finite());
        let lo = finite.clone().fold(Vec3::splat(f32::INFINITY), |a, &p| a.min(p));
        let hi = finite.fold(Vec3::splat(f32::NEG_INFINITY), |a, &p| a.max(p));
        let view = self.push_view(bytemuck::cast_slice(&floats), target);
        let mut accessor = json!({ "bufferView": view, "componentType": 5126, "count": values.len(), "type": "VEC3" });
        if lo.is_finite() && hi.is_finite() {
            accessor["min"] = vec_json(lo);
            accessor["max"] = vec_json(hi);
        }
        self.push_accessor(accessor)
    }

    /// A mesh of one primitive drawn in glTF primitive `mode` (4 triangles, 5 strip, 6 fan, 0-3
    /// points and lines), with optional per-vertex COLOR_0.
    pub fn mesh_primitive(
        &mut self,
        name: &str,
        positions: &[Vec3],
        indices: &[u32],
        mode: u32,
        colours: Option<&[Vec3]>,
        material: usize,
    ) -> usize {
        let pos_accessor = self.vec3_accessor(positions, 34962);
        let idx_view = self.push_view(bytemuck::cast_slice(indices), 34963);
        let idx_accessor =
            self.push_accessor(json!({ "bufferView": idx_view, "componentType": 5125, "count": indices.len(), "type": "SCALAR" }));
        let mut primitive = json!({ "attributes": { "POSITION": pos_accessor }, "indices": idx_accessor, "material": material });
        if mode != MODE_TRIANGLES {
            primitive["mode"] = json!(mode);
        }
        if let Some(c) = colours {
            primitive["attributes"]["COLOR_0"] = json!(self.vec3_accessor(c, 34962));
        }
        self.meshes.push(json!({ "name": name, "primitives": [primitive] }));
        self.meshes.len() - 1
    }

    /// Adds a root node drawing `mesh` once per translation through `EXT_mesh_gpu_instancing`
    /// (marked required).
    pub fn instanced(&mut self, name: &str, mesh: usize, translations: &[Vec3]) -> usize {
        let accessor = self.vec3_accessor(translations, 34962);
        self.use_extension("EXT_mesh_gpu_instancing");
        self.required.push("EXT_mesh_gpu_instancing");
        self.nodes.push(json!({
            "name": name,
            "mesh": mesh,
            "extensions": { "EXT_mesh_gpu_instancing": { "attributes": { "TRANSLATION": accessor } } },
        }));
        self.roots.push(self.nodes.len() - 1);
        self.nodes.len() - 1
    }

    /// Adds a `KHR_lights_punctual` light (`light` is its JSON: type, color, intensity, spot) on a
    /// root node at `position` shining along `direction`.
    pub fn punctual_light(&mut self, light: Value, position: Vec3, direction: Vec3) {
        self.use_extension("KHR_lights_punctual");
        self.lights.push(light);
        let q = Quat::from_rotation_arc(-Vec3::Z, direction.normalize());
        self.nodes.push(json!({
            "extensions": { "KHR_lights_punctual": { "light": self.lights.len() - 1 } },
            "translation": vec_json(position),
            "rotation": [round6(q.x), round6(q.y), round6(q.z), round6(q.w)],
        }));
        self.roots.push(self.nodes.len() - 1);
    }

    /// Adds a root node instancing `mesh` with a rotation about +Y (radians) and a translation.
    pub fn instance(&mut self, name: &str, mesh: usize, rotation_y: f32, translation: Vec3) -> usize {
        let mut node = json!({ "name": name, "mesh": mesh });
        if rotation_y != 0.0 {
            let q = Quat::from_rotation_y(rotation_y);
            node["rotation"] = json!([round6(q.x), round6(q.y), round6(q.z), round6(q.w)]);
        }
        if translation != Vec3::ZERO {
            node["translation"] = vec_json(translation);
        }
        self.nodes.push(node);
        self.roots.push(self.nodes.len() - 1);
        self.nodes.len() - 1
    }

    /// Adds a perspective camera at `eye` looking at `target` with +Y up.
    pub fn camera(&mut self, name: &str, eye: Vec3, target: Vec3, yfov: f32) {
        let forward = (target - eye).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        let q = Quat::from_mat3(&glam::Mat3::from_cols(right, up, -forward)).normalize();
        self.cameras
            .push(json!({ "name": name, "type": "perspective", "perspective": { "yfov": round6(yfov), "znear": 0.01 } }));
        self.nodes.push(json!({
            "name": name,
            "camera": self.cameras.len() - 1,
            "translation": vec_json(eye),
            "rotation": [round6(q.x), round6(q.y), round6(q.z), round6(q.w)],
        }));
        self.roots.push(self.nodes.len() - 1);
    }

    /// The finished document; `environment` goes to the scene's extras when non-zero.
    pub fn finish(self, scene_name: &str, environment: Vec3) -> String {
        let mut scene = json!({ "name": scene_name, "nodes": self.roots });
        if environment != Vec3::ZERO {
            scene["extras"] = json!({ "environment": vec_json(environment) });
        }
        let mut root = json!({
            "asset": { "version": "2.0", "generator": "restir-pt tools/make_scenes.rs" },
            "scene": 0,
            "scenes": [scene],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "cameras": self.cameras,
            "accessors": self.accessors,
            "bufferViews": self.buffer_views,
            "buffers": [{ "byteLength": self.buffer.len(), "uri": format!("data:application/octet-stream;base64,{}", base64_encode(&self.buffer)) }],
        });
        for (key, list) in [("images", self.images), ("samplers", self.samplers), ("textures", self.textures)] {
            if !list.is_empty() {
                root[key] = Value::Array(list);
            }
        }
        if !self.extensions_used.is_empty() {
            root["extensionsUsed"] = json!(self.extensions_used);
        }
        if !self.required.is_empty() {
            root["extensionsRequired"] = json!(self.required);
        }
        if !self.lights.is_empty() {
            root["extensions"] = json!({ "KHR_lights_punctual": { "lights": self.lights } });
        }
        let mut text = serde_json::to_string_pretty(&root).expect("JSON values always serialise");
        text.push('\n');
        text
    }
}

fn base64_encode(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}
