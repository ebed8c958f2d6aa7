//! glTF 2.0 (.gltf and .glb) to [`Scene`]. The data is checked, not only the JSON: every problem
//! is an error or a warning that names the file.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use glam::{DMat4, DVec3, Vec3};

use super::{Camera, Scene, SceneParts};
use crate::gpu_types::{Material, Triangle, MATERIAL_DOUBLE_SIDED, NO_EMITTER};

/// Deeper hierarchies are rejected: glTF forbids cycles, and no sane scene nests this deep.
const MAX_NODE_DEPTH: usize = 256;
/// Node instances visited; guards against exponential instancing blow-ups.
const MAX_NODE_INSTANCES: usize = 1 << 20;
const MAX_TRIANGLES: usize = 1 << 26;

struct Loader<'a> {
    path: &'a Path,
    doc: &'a gltf::Document,
    buffers: &'a [gltf::buffer::Data],
    triangles: Vec<Triangle>,
    materials: Vec<Material>,
    material_names: Vec<String>,
    /// Index of the glTF default material in `materials`, added on first use.
    default_material: Option<u32>,
    cameras: Vec<Camera>,
    /// Mesh instances with their world transforms, added once the origin is known.
    instances: Vec<(gltf::Mesh<'a>, DMat4)>,
    /// World position of the scene's coordinate origin: the first camera (see `walk_nodes`).
    origin: DVec3,
    warnings: Vec<String>,
    degenerate: usize,
    degenerate_emitters: usize,
}

fn problem(path: &Path, msg: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("{}: {msg}", path.display())
}

/// Loads a glTF or GLB file. Errors are one line naming the file and the problem.
pub fn load_scene(path: &Path) -> Result<Scene> {
    let bytes = std::fs::read(path).map_err(|e| problem(path, format!("cannot read the file: {e}")))?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_else(|| PathBuf::from("."));
    load_scene_from_bytes(&bytes, Some(&base), path)
}

/// Loads glTF or GLB bytes; external buffers resolve against `base` (none: only embedded data).
/// `path` names the input in messages.
pub fn load_scene_from_bytes(bytes: &[u8], base: Option<&Path>, path: &Path) -> Result<Scene> {
    let gltf = parse_gltf(bytes, path)?;
    let buffers = gltf::import_buffers(&gltf.document, base, gltf.blob.clone())
        .map_err(|e| problem(path, format!("cannot load buffer data: {e}")))?;
    for (i, (data, buffer)) in buffers.iter().zip(gltf.document.buffers()).enumerate() {
        if data.len() < buffer.length() {
            bail!(problem(
                path,
                format!("buffer {i} holds {} bytes but declares {}", data.len(), buffer.length())
            ));
        }
    }
    let mut loader = Loader {
        path,
        doc: &gltf.document,
        buffers: &buffers,
        triangles: Vec::new(),
        materials: Vec::new(),
        material_names: Vec::new(),
        default_material: None,
        cameras: Vec::new(),
        instances: Vec::new(),
        origin: DVec3::ZERO,
        warnings: Vec::new(),
        degenerate: 0,
        degenerate_emitters: 0,
    };
    loader.load_materials()?;
    let scene = gltf.document.default_scene().or_else(|| gltf.document.scenes().next());
    let scene = scene.ok_or_else(|| problem(path, "the file has no scene"))?;
    loader.walk_nodes(&scene)?;
    let environment = scene_environment(path, &scene, &gltf.document)?;
    loader.finish(environment)
}

fn invalid_gltf(path: &Path, e: gltf::Error) -> anyhow::Error {
    let e = e.to_string();
    // The gltf crate prefixes validation errors itself; JSON errors need the context.
    problem(
        path,
        if e.starts_with("invalid glTF") {
            e
        } else {
            format!("invalid glTF: {e}")
        },
    )
}

/// GLB files start with this magic, then a version and the total length (12 bytes).
const GLB_MAGIC: &[u8; 4] = b"glTF";
const GLB_HEADER_BYTES: usize = 12;

/// Parses and validates glTF or GLB. Two inputs that make the gltf crate panic (found by
/// fuzzing) are checked here first: a GLB header whose length is shorter than the header itself
/// (an overflowing subtraction), and a primitive whose POSITION accessor does not exist (which
/// gltf-json's validation indexes unchecked).
fn parse_gltf(bytes: &[u8], path: &Path) -> Result<gltf::Gltf> {
    use gltf::json::{mesh::Semantic, validation::Checked};
    if bytes.starts_with(GLB_MAGIC) {
        let declared = bytes.get(8..12).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
        match declared {
            Some(length) if (GLB_HEADER_BYTES..=bytes.len()).contains(&length) => {}
            Some(length) => bail!(problem(
                path,
                format!(
                    "truncated or corrupt GLB: the header declares {length} bytes, the file has {}",
                    bytes.len()
                )
            )),
            None => bail!(problem(
                path,
                format!("truncated GLB: {} bytes, less than its 12-byte header", bytes.len())
            )),
        }
    }
    let unchecked = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| invalid_gltf(path, e))?;
    let root = unchecked.document.into_json();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for primitive in &mesh.primitives {
            if let Some(index) = primitive.attributes.get(&Checked::Valid(Semantic::Positions)) {
                if index.value() >= root.accessors.len() {
                    bail!(problem(
                        path,
                        format!(
                            "mesh {m}: POSITION names accessor {}, but there are {}",
                            index.value(),
                            root.accessors.len()
                        )
                    ));
                }
            }
        }
    }
    let document = gltf::Document::from_json(root).map_err(|e| invalid_gltf(path, e))?;
    Ok(gltf::Gltf {
        document,
        blob: unchecked.blob,
    })
}

/// The constant environment: `"environment": [r, g, b]` in the scene's extras, else in the
/// root's (exporters write either); black if neither has one.
fn scene_environment(path: &Path, scene: &gltf::Scene, doc: &gltf::Document) -> Result<Vec3> {
    let places = [("scene", scene.extras().as_ref()), ("root", doc.as_json().extras.as_ref())];
    for (place, raw) in places {
        let Some(raw) = raw else { continue };
        let extras: serde_json::Value =
            serde_json::from_str(raw.get()).map_err(|e| problem(path, format!("{place} extras are not JSON: {e}")))?;
        let Some(env) = extras.get("environment") else { continue };
        let values: Vec<f32> = env
            .as_array()
            .filter(|a| a.len() == 3)
            .and_then(|a| a.iter().map(|v| v.as_f64().map(|x| x as f32)).collect())
            .ok_or_else(|| problem(path, format!("{place} extras \"environment\" must be [r, g, b]")))?;
        if values.iter().any(|v| !v.is_finite() || *v < 0.0) {
            bail!(problem(
                path,
                format!("{place} extras \"environment\" {values:?} must be finite and non-negative")
            ));
        }
        return Ok(Vec3::from_slice(&values));
    }
    Ok(Vec3::ZERO)
}

impl<'a> Loader<'a> {
    fn warn(&mut self, msg: impl std::fmt::Display) {
        self.warnings.push(format!("{}: {msg}", self.path.display()));
    }

    fn load_materials(&mut self) -> Result<()> {
        let doc = self.doc;
        for m in doc.materials() {
            let name = m
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("material {}", m.index().unwrap_or(0)));
            let material = self.convert_material(&m, &name)?;
            self.materials.push(material);
            self.material_names.push(name);
        }
        Ok(())
    }

    fn convert_material(&mut self, m: &gltf::Material, name: &str) -> Result<Material> {
        let pbr = m.pbr_metallic_roughness();
        let ignored_textures = [
            ("base colour", pbr.base_color_texture().is_some()),
            ("metallic-roughness", pbr.metallic_roughness_texture().is_some()),
            ("normal", m.normal_texture().is_some()),
            ("occlusion", m.occlusion_texture().is_some()),
            ("emissive", m.emissive_texture().is_some()),
            ("transmission", m.transmission().is_some_and(|t| t.transmission_texture().is_some())),
        ];
        for (kind, present) in ignored_textures {
            if present {
                self.warn(format!(
                    "{name}: {kind} texture ignored (textures are not supported; factors are used)"
                ));
            }
        }
        if m.alpha_mode() != gltf::material::AlphaMode::Opaque {
            self.warn(format!("{name}: alpha mode {:?} ignored (rendered opaque)", m.alpha_mode()));
        }
        if m.volume().is_some() {
            self.warn(format!("{name}: KHR_materials_volume ignored (no participating media)"));
        }
        let base = pbr.base_color_factor();
        let strength = m.emissive_strength().unwrap_or(1.0);
        let emissive = m.emissive_factor();
        let transmission = m.transmission().map(|t| t.transmission_factor()).unwrap_or(0.0);
        let ior = m.ior().unwrap_or(1.5);
        let checks = [
            (
                "baseColorFactor",
                base[..3].iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v)),
            ),
            ("metallicFactor", (0.0..=1.0).contains(&pbr.metallic_factor())),
            ("roughnessFactor", (0.0..=1.0).contains(&pbr.roughness_factor())),
            ("emissiveFactor", emissive.iter().all(|v| v.is_finite() && *v >= 0.0)),
            ("emissiveStrength", strength.is_finite() && strength >= 0.0),
            ("transmissionFactor", (0.0..=1.0).contains(&transmission)),
            // Within rounding below 1 is index-matched (docs/materials.md), not an error.
            ("ior", ior.is_finite() && (ior >= 1.0 || crate::bsdf::index_matched(ior))),
        ];
        if let Some((field, _)) = checks.iter().find(|(_, ok)| !ok) {
            bail!(problem(self.path, format!("{name}: {field} is out of range or not a number")));
        }
        Ok(Material {
            base_color: [base[0], base[1], base[2]],
            metallic: pbr.metallic_factor(),
            emission: (Vec3::from(emissive) * strength).into(),
            roughness: pbr.roughness_factor(),
            transmission,
            ior,
            flags: if m.double_sided() { MATERIAL_DOUBLE_SIDED } else { 0 },
            pad: 0,
        })
    }

    fn default_material(&mut self) -> u32 {
        *self.default_material.get_or_insert_with(|| {
            // glTF's default material: white, metallic 1, roughness 1.
            self.materials.push(Material {
                base_color: [1.0; 3],
                metallic: 1.0,
                roughness: 1.0,
                ior: 1.5,
                ..Default::default()
            });
            self.material_names.push("glTF default material".to_string());
            (self.materials.len() - 1) as u32
        })
    }

    /// Walks the hierarchy in f64 and re-centres the scene on its first camera: geometry is
    /// uploaded in f32 camera-relative coordinates, so a scene far from the world origin keeps
    /// the precision it has near the camera (as large-world engines do).
    fn walk_nodes(&mut self, scene: &gltf::Scene<'a>) -> Result<()> {
        let mut stack: Vec<(gltf::Node, DMat4, usize)> = scene.nodes().map(|n| (n, DMat4::IDENTITY, 0)).collect();
        stack.reverse();
        let mut visited = 0usize;
        while let Some((node, parent, depth)) = stack.pop() {
            visited += 1;
            if depth > MAX_NODE_DEPTH {
                bail!(problem(
                    self.path,
                    format!("node hierarchy deeper than {MAX_NODE_DEPTH} levels (a cycle?)")
                ));
            }
            if visited > MAX_NODE_INSTANCES {
                bail!(problem(self.path, format!("more than {MAX_NODE_INSTANCES} node instances")));
            }
            let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
            let world = parent * local;
            if !world.is_finite() {
                bail!(problem(self.path, format!("node {} has a non-finite transform", node.index())));
            }
            if let Some(mesh) = node.mesh() {
                self.instances.push((mesh, world));
            }
            if let Some(camera) = node.camera() {
                self.add_camera(&camera, &node, &world);
            }
            let children: Vec<_> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world, depth + 1)));
        }
        for (mesh, world) in std::mem::take(&mut self.instances) {
            self.add_mesh(&mesh, &world)?;
        }
        Ok(())
    }

    fn add_camera(&mut self, camera: &gltf::Camera, node: &gltf::Node, world: &DMat4) {
        match camera.projection() {
            gltf::camera::Projection::Perspective(p) if p.yfov().is_finite() && p.yfov() > 0.0 && p.yfov() < std::f32::consts::PI => {
                let name = node
                    .name()
                    .or(camera.name())
                    .map(str::to_string)
                    .unwrap_or_else(|| format!("camera {}", self.cameras.len()));
                if self.cameras.is_empty() {
                    self.origin = world.transform_point3(DVec3::ZERO);
                }
                let mut relative = *world;
                relative.w_axis -= self.origin.extend(0.0);
                self.cameras.push(Camera::from_transform(name, &relative.as_mat4(), p.yfov()));
            }
            gltf::camera::Projection::Perspective(p) => {
                self.warn(format!("camera on node {} has an invalid yfov {}; ignored", node.index(), p.yfov()))
            }
            gltf::camera::Projection::Orthographic(_) => self.warn(format!("orthographic camera on node {} ignored", node.index())),
        }
    }

    fn add_mesh(&mut self, mesh: &gltf::Mesh, world: &DMat4) -> Result<()> {
        // A mirroring transform flips the winding, and so which face is the front.
        let flip = world.determinant() < 0.0;
        for prim in mesh.primitives() {
            if prim.mode() != gltf::mesh::Mode::Triangles {
                self.warn(format!(
                    "mesh {}: primitive mode {:?} ignored (only triangles are rendered)",
                    mesh.index(),
                    prim.mode()
                ));
                continue;
            }
            self.check_accessor_types(mesh, &prim)?;
            let buffers = self.buffers;
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let positions: Vec<Vec3> = reader
                .read_positions()
                .ok_or_else(|| {
                    problem(
                        self.path,
                        format!("mesh {}: POSITION data is missing or does not fit its buffer", mesh.index()),
                    )
                })?
                .map(Vec3::from)
                .collect();
            if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
                bail!(problem(
                    self.path,
                    format!("mesh {}: vertex {i} has a NaN or infinite position", mesh.index())
                ));
            }
            let indices: Vec<u32> = match reader.read_indices() {
                Some(idx) => idx.into_u32().collect(),
                None => (0..positions.len() as u32).collect(),
            };
            if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
                bail!(problem(
                    self.path,
                    format!("mesh {}: index {bad} is out of range ({} vertices)", mesh.index(), positions.len())
                ));
            }
            if !indices.len().is_multiple_of(3) {
                self.warn(format!("mesh {}: {} trailing indices ignored", mesh.index(), indices.len() % 3));
            }
            let material = match prim.material().index() {
                Some(i) => i as u32,
                None => self.default_material(),
            };
            let emissive = Vec3::from(self.materials[material as usize].emission).max_element() > 0.0;
            for tri in indices.chunks_exact(3) {
                let [a, b, c] = [0, 1, 2].map(|k| world.transform_point3(positions[tri[k] as usize].as_dvec3()) - self.origin);
                let (b, c) = if flip { (c, b) } else { (b, c) };
                let (e1, e2) = ((b - a).as_vec3(), (c - a).as_vec3());
                let a = a.as_vec3();
                let area2 = e1.cross(e2).length();
                // Degenerate triangles carry no area: they cannot be hit or emit, and break normals.
                if !(area2 > 1e-12 * (e1.length_squared() + e2.length_squared()).max(f32::MIN_POSITIVE)) || !area2.is_finite() {
                    self.degenerate += 1;
                    self.degenerate_emitters += emissive as usize;
                    continue;
                }
                if self.triangles.len() >= MAX_TRIANGLES {
                    bail!(problem(self.path, format!("more than {MAX_TRIANGLES} triangles")));
                }
                self.triangles.push(Triangle {
                    v0: a.into(),
                    material,
                    e1: e1.into(),
                    emitter: NO_EMITTER,
                    e2: e2.into(),
                    pad: 0,
                });
            }
        }
        Ok(())
    }

    /// The spec's accessor types for positions (float VEC3) and indices (unsigned SCALAR); the
    /// gltf crate's readers assume them (an index accessor of floats hits `unreachable!`).
    fn check_accessor_types(&self, mesh: &gltf::Mesh, prim: &gltf::Primitive) -> Result<()> {
        use gltf::accessor::{DataType, Dimensions};
        if let Some(p) = prim.get(&gltf::Semantic::Positions) {
            if p.data_type() != DataType::F32 || p.dimensions() != Dimensions::Vec3 {
                bail!(problem(
                    self.path,
                    format!(
                        "mesh {}: POSITION must be float VEC3, not {:?} {:?}",
                        mesh.index(),
                        p.data_type(),
                        p.dimensions()
                    )
                ));
            }
        }
        if let Some(i) = prim.indices() {
            let unsigned = matches!(i.data_type(), DataType::U8 | DataType::U16 | DataType::U32);
            if !unsigned || i.dimensions() != Dimensions::Scalar {
                bail!(problem(
                    self.path,
                    format!(
                        "mesh {}: indices must be unsigned SCALAR, not {:?} {:?}",
                        mesh.index(),
                        i.data_type(),
                        i.dimensions()
                    )
                ));
            }
        }
        Ok(())
    }

    fn finish(mut self, environment: Vec3) -> Result<Scene> {
        if self.degenerate > 0 {
            let n = self.degenerate;
            self.warn(format!("{n} degenerate (zero-area) triangle(s) dropped"));
        }
        if self.degenerate_emitters > 0 {
            let n = self.degenerate_emitters;
            self.warn(format!("{n} zero-area emitter triangle(s) dropped"));
        }
        if self.triangles.is_empty() {
            bail!(problem(self.path, "the scene has no renderable triangles"));
        }
        let has_emitter = self
            .triangles
            .iter()
            .any(|t| Vec3::from(self.materials[t.material as usize].emission).max_element() > 0.0);
        if !has_emitter && environment.max_element() <= 0.0 {
            bail!(problem(
                self.path,
                "the scene has no light: no emissive triangle and no environment"
            ));
        }
        if self.cameras.is_empty() {
            bail!(problem(self.path, "the scene has no perspective camera"));
        }
        let mut scene = Scene::build(SceneParts {
            source: self.path.to_path_buf(),
            triangles: self.triangles,
            materials: self.materials,
            material_names: self.material_names,
            environment,
            cameras: self.cameras,
            warnings: self.warnings,
        });
        scene.origin = self.origin;
        Ok(scene)
    }
}
