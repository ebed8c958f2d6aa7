//! glTF 2.0 (.gltf and .glb) to [`Scene`]. The data is checked, not only the JSON: every problem
//! is an error or a warning that names the file.

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use glam::{DMat4, DVec3, Vec3};

pub use super::gltf_budget::ArrayLimit;
use restir_pt_interface::gpu_types::{Material, Triangle};
use restir_pt_shading_core::surface::TriangleSurface;
use restir_pt_shading_core::texture::SceneTextures;

use super::default_environment::{light_open_scene, unlit_scene_line};
use super::gltf_json::{check_external_buffers, read_raw, Instancing};
use super::{Camera, PunctualLight, Scene, SceneParts};
use crate::environment::EnvironmentMap;

/// Deeper hierarchies are rejected: glTF forbids cycles, and no sane scene nests this deep.
pub(super) const MAX_NODE_DEPTH: usize = 256;
/// Node instances visited; guards against exponential instancing blow-ups.
pub(super) const MAX_NODE_INSTANCES: usize = 1 << 20;
pub(super) const MAX_TRIANGLES: usize = 1 << 26;

pub(super) struct Loader<'a> {
    pub(super) path: &'a Path,
    /// The folder external images resolve against (none: only embedded images).
    pub(super) base: Option<&'a Path>,
    pub(super) doc: &'a gltf::Document,
    pub(super) buffers: &'a [gltf::buffer::Data],
    pub(super) instancing: &'a HashMap<usize, Instancing>,
    pub(super) triangles: Vec<Triangle>,
    /// Vertex attributes parallel to `triangles`, from the first triangle that has any (earlier
    /// ones are flat); empty while none has.
    pub(super) surfaces: Vec<TriangleSurface>,
    pub(super) materials: Vec<Material>,
    pub(super) material_names: Vec<String>,
    /// The glTF material each of `materials` comes from (none: the default material).
    pub(super) material_sources: Vec<Option<usize>>,
    /// Whether each material is `KHR_materials_unlit` (its emission is its base colour).
    pub(super) unlit: Vec<bool>,
    /// Index of the glTF default material in `materials`, added on first use.
    pub(super) default_material: Option<u32>,
    pub(super) cameras: Vec<Camera>,
    /// Punctual lights; their positions are set relative to `origin` once the walk is done.
    pub(super) lights: Vec<PunctualLight>,
    /// World positions (f64) of `lights`, one per light.
    pub(super) light_positions: Vec<DVec3>,
    /// Mesh instances with their world transforms (f64), added once the origin is known.
    instances: Vec<(gltf::Mesh<'a>, DMat4)>,
    /// World position of the scene coordinates' origin (see `walk_nodes`).
    pub(super) origin: DVec3,
    pub(super) warnings: Vec<String>,
    pub(super) counts: MeshCounts,
}

/// Things counted over the whole file and reported once each.
#[derive(Default)]
pub(super) struct MeshCounts {
    pub degenerate: usize,
    pub degenerate_emitters: usize,
    pub points_or_lines: usize,
    /// Some primitive has COLOR_0 (kept per vertex in the surface attributes).
    pub vertex_colours: bool,
    /// Some vertex normal differs from its face's normal.
    pub smooth: bool,
    pub instances: usize,
    /// World-space bounds of the skipped points and lines (frame a scene made only of them).
    pub skipped_bounds: Option<(Vec3, Vec3)>,
}

pub(super) fn problem(path: &Path, msg: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("{}: {msg}", path.display())
}

/// What to take from a file besides its own content.
#[derive(Debug, Clone, Default)]
pub struct LoadOptions {
    /// The glTF scene to load (index into `scenes`); none: the file's default scene, else the first.
    pub scene: Option<usize>,
    /// An environment that replaces the file's and the default one (black included).
    pub environment: Option<Vec3>,
    /// An equirectangular environment map (.exr or .hdr) that replaces the file's environment.
    pub environment_map: Option<PathBuf>,
    /// The map's rotation about +Y in degrees (`--env-rotation`; see
    /// [`crate::environment`] for the convention).
    pub env_rotation: f32,
    /// No environment at all (`--env none`): neither the file's nor the default one
    /// (crate::default_environment).
    pub no_environment: bool,
    /// The most bytes the device lets one scene array take: a file whose accessor counts
    /// promise more triangles than that fails before its vertices are read.
    pub array_limit: Option<ArrayLimit>,
}

/// Loads a glTF or GLB file. Errors are one line naming the file and the problem; warnings are
/// in `Scene::warnings`.
pub fn load_scene(path: &Path) -> Result<Scene> {
    let mut warnings = Vec::new();
    load_scene_reporting(path, &LoadOptions::default(), &mut warnings)
}

/// Loads a glTF or GLB file with `options`; every warning goes to `warnings`, also when the load
/// then fails (and, on success, to `Scene::warnings` as well).
pub fn load_scene_reporting(path: &Path, options: &LoadOptions, warnings: &mut Vec<String>) -> Result<Scene> {
    let bytes = std::fs::read(path).map_err(|e| problem(path, format!("cannot read the file: {e}")))?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_else(|| PathBuf::from("."));
    let parts = load_parts(Cow::Owned(bytes), Some(&base), path, options, warnings)?;
    build_scene(parts, warnings)
}

/// Loads glTF or GLB bytes; external buffers resolve against `base` (none: only embedded data).
/// `path` names the input in messages.
pub fn load_scene_from_bytes(bytes: &[u8], base: Option<&Path>, path: &Path) -> Result<Scene> {
    load_scene_from_bytes_with_options(bytes, base, path, &LoadOptions::default())
}

/// [`load_scene_from_bytes`] with `options`; warnings are in `Scene::warnings`.
pub fn load_scene_from_bytes_with_options(bytes: &[u8], base: Option<&Path>, path: &Path, options: &LoadOptions) -> Result<Scene> {
    let mut warnings = Vec::new();
    let parts = load_parts(Cow::Borrowed(bytes), base, path, options, &mut warnings)?;
    build_scene(parts, &mut warnings)
}

/// The scene's parts, the world position of its origin (`Scene::origin`) and whether the
/// default environment is still to be decided from the built scene (it has lights and no
/// environment was given).
type LoadedParts = (SceneParts, DVec3, bool);

fn build_scene((parts, origin, decide_environment): LoadedParts, warnings: &mut Vec<String>) -> Result<Scene> {
    let source = parts.source.clone();
    let mut scene = Scene::build(parts);
    scene.origin = origin;
    if decide_environment {
        if let Some(line) = light_open_scene(&mut scene) {
            warnings.push(format!("{}: {line}", source.display()));
        }
    }
    scene.warnings = warnings.to_vec();
    Ok(scene)
}

/// Everything but the BVH build, so that the parsed document and its decoded buffers (as large as
/// the triangles for embedded data) are freed before it. Host memory is held to one copy of each
/// large thing at a time: the file is freed once parsed, a base64 buffer once decoded.
fn load_parts(
    bytes: Cow<[u8]>,
    base: Option<&Path>,
    path: &Path,
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Result<LoadedParts> {
    let mut warn = |w: String| warnings.push(format!("{}: {w}", path.display()));
    let raw = read_raw(&bytes, path, &mut warn)?;
    drop(bytes);
    check_external_buffers(&raw.json, base, path)?;
    let document = parse_gltf(raw.json, path)?;
    let buffers = gltf::import_buffers(&document, base, raw.blob).map_err(|e| problem(path, format!("cannot load buffer data: {e}")))?;
    let document = without_buffer_uris(document);
    for (i, (data, buffer)) in buffers.iter().zip(document.buffers()).enumerate() {
        if data.len() < buffer.length() {
            bail!(problem(
                path,
                format!("buffer {i} holds {} bytes but declares {}", data.len(), buffer.length())
            ));
        }
    }
    let mut loader = Loader {
        path,
        base,
        doc: &document,
        buffers: &buffers,
        instancing: &raw.instancing,
        triangles: Vec::new(),
        surfaces: Vec::new(),
        materials: Vec::new(),
        material_names: Vec::new(),
        material_sources: Vec::new(),
        unlit: Vec::new(),
        default_material: None,
        cameras: Vec::new(),
        lights: Vec::new(),
        light_positions: Vec::new(),
        instances: Vec::new(),
        origin: DVec3::ZERO,
        warnings: Vec::new(),
        counts: MeshCounts::default(),
    };
    let result = loader.run(options);
    warnings.append(&mut loader.warnings);
    result
}

fn invalid_gltf(path: &Path, e: impl std::fmt::Display) -> anyhow::Error {
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

/// Validates the JSON into a document. A primitive whose POSITION accessor does not exist makes
/// gltf-json's validation index out of bounds (found by fuzzing), so it is checked first.
/// The document without its buffers' URIs, which are read: a data URI holds the whole buffer in
/// base64, a third larger than the decoded data.
fn without_buffer_uris(document: gltf::Document) -> gltf::Document {
    let mut root = document.into_json();
    for buffer in &mut root.buffers {
        buffer.uri = None;
    }
    // Validated when parsed; dropping URIs leaves it valid.
    gltf::Document::from_json_without_validation(root)
}

fn parse_gltf(json: serde_json::Value, path: &Path) -> Result<gltf::Document> {
    use gltf::json::{mesh::Semantic, validation::Checked};
    let root: gltf::json::Root = serde_json::from_value(json).map_err(|e| invalid_gltf(path, e))?;
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
    gltf::Document::from_json(root).map_err(|e| invalid_gltf(path, e))
}

/// The constant environment: `"environment": [r, g, b]` in the scene's extras, else in the
/// root's (exporters write either); None if neither has one.
fn scene_environment(path: &Path, scene: &gltf::Scene, doc: &gltf::Document) -> Result<Option<Vec3>> {
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
        return Ok(Some(Vec3::from_slice(&values)));
    }
    Ok(None)
}

impl<'a> Loader<'a> {
    pub(super) fn warn(&mut self, msg: impl std::fmt::Display) {
        self.warnings.push(format!("{}: {msg}", self.path.display()));
    }

    fn run(&mut self, options: &LoadOptions) -> Result<LoadedParts> {
        self.load_materials()?;
        let doc = self.doc;
        let scene = match options.scene {
            Some(i) => doc.scenes().nth(i).ok_or_else(|| {
                problem(
                    self.path,
                    format!("--scene {i} does not exist; the file has {} scene(s)", doc.scenes().count()),
                )
            })?,
            None => doc
                .default_scene()
                .or_else(|| doc.scenes().next())
                .ok_or_else(|| problem(self.path, "the file has no scene"))?,
        };
        if let Some(limit) = options.array_limit {
            self.check_array_budget(&scene, limit)?;
        }
        self.walk_nodes(&scene)?;
        // --env replaces the file's environment; the scene's extras come before the root's.
        // An environment named by --env or the file, black included, is the author's choice: no
        // default replaces it.
        let environment = match options.environment {
            Some(env) => Some(env),
            None => scene_environment(self.path, &scene, doc)?,
        };
        let map = options
            .environment_map
            .as_deref()
            .map(|p| EnvironmentMap::load(p).map(|m| m.with_rotation(options.env_rotation)))
            .transpose()?;
        if options.env_rotation != 0.0 && map.is_none() {
            self.warn("--env-rotation ignored: it turns an environment map, and there is none");
        }
        let (environment, map) = if options.no_environment {
            (Some(Vec3::ZERO), None)
        } else {
            (environment, map)
        };
        let sources = std::mem::take(&mut self.material_sources);
        // Texel offsets are 32-bit; the device's binding limit is checked at upload.
        let textures = self.load_textures(&sources, 4 * u32::MAX as u64)?;
        self.finish(environment, map, textures, options.no_environment)
    }

    /// Walks the hierarchy in f64 and re-centres the scene before rounding to f32: on its first
    /// camera, so that geometry is uploaded in camera-relative coordinates and a scene far from
    /// the world origin keeps the precision it has near the camera (as large-world engines do);
    /// a scene without a camera on the centre of its vertices' world bounds, where the default
    /// camera (`finish`) looks. `origin` holds the chosen world position, exact in f64.
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
            if visited + self.counts.instances > MAX_NODE_INSTANCES {
                bail!(problem(self.path, format!("more than {MAX_NODE_INSTANCES} node instances")));
            }
            let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
            let world = parent * local;
            if !world.is_finite() {
                bail!(problem(self.path, format!("node {} has a non-finite transform", node.index())));
            }
            if let Some(mesh) = node.mesh() {
                match self.instancing.get(&node.index()).copied() {
                    Some(inst) => {
                        for instance in self.instance_transforms(&node, &inst)? {
                            self.instances.push((mesh.clone(), world * instance));
                        }
                    }
                    None => self.instances.push((mesh, world)),
                }
            }
            if let Some(camera) = node.camera() {
                self.add_camera(&camera, &node, &world);
            }
            if let Some(light) = node.light() {
                self.add_light(&light, &node, &world)?;
            }
            let children: Vec<_> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world, depth + 1)));
        }
        if self.cameras.is_empty() {
            if let Some((lo, hi)) = self.vertex_bounds(&self.instances) {
                self.origin = 0.5 * (lo + hi);
            }
        }
        for (mesh, world) in std::mem::take(&mut self.instances) {
            self.add_mesh(&mesh, &world)?;
        }
        let origin = self.origin;
        for (light, world) in self.lights.iter_mut().zip(&self.light_positions) {
            light.position = (*world - origin).as_vec3();
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
                let mut c = Camera::from_transform(name, &relative.as_mat4(), p.yfov());
                c.aspect_ratio = p.aspect_ratio().filter(|a| a.is_finite() && *a > 0.0);
                self.cameras.push(c);
            }
            gltf::camera::Projection::Perspective(p) => {
                self.warn(format!("camera on node {} has an invalid yfov {}; ignored", node.index(), p.yfov()))
            }
            gltf::camera::Projection::Orthographic(_) => self.warn(format!("orthographic camera on node {} ignored", node.index())),
        }
    }

    /// The scene's parts; `no_environment` (`--env none`) keeps the default environment off.
    fn finish(
        &mut self,
        environment: Option<Vec3>,
        map: Option<EnvironmentMap>,
        textures: SceneTextures,
        no_environment: bool,
    ) -> Result<LoadedParts> {
        let this = self;
        let skipped_bounds = this.counts.skipped_bounds;
        // Flat faces without textures need no attributes: their kernels do without.
        let surfaces = if this.counts.smooth || this.counts.vertex_colours || !textures.is_empty() {
            let mut s = std::mem::take(&mut this.surfaces);
            if !s.is_empty() {
                s.resize(this.triangles.len(), TriangleSurface::flat());
            }
            s
        } else {
            Vec::new()
        };
        this.report_counts();
        let bounds = match skipped_bounds {
            Some(b) if this.triangles.is_empty() => {
                this.warn("the scene has no triangles, only points or lines: the image shows the environment alone");
                b
            }
            _ if this.triangles.is_empty() => bail!(problem(this.path, "the scene has no renderable triangles")),
            _ => triangle_bounds(&this.triangles),
        };
        let has_emitter = this
            .triangles
            .iter()
            .any(|t| Vec3::from(this.materials[t.material as usize].emission).max_element() > 0.0);
        let given = environment.is_some() || map.is_some();
        let mut environment = environment.unwrap_or(Vec3::ZERO);
        let unlit = !has_emitter && this.lights.is_empty();
        if no_environment && unlit {
            this.warn("the scene has no light and --env none leaves it without an environment: the image is black");
        } else if unlit && !given {
            environment = DEFAULT_ENVIRONMENT;
            this.warn(unlit_scene_line());
        }
        let decide_environment = !no_environment && !unlit && !given;
        if this.cameras.is_empty() {
            let camera = Camera::framing(bounds);
            this.warn(format!(
                "the scene has no perspective camera: using a default one at {:?} looking at the centre of the bounds from +Z and 26.6 deg above, yfov {:.0} deg, framing their bounding sphere",
                camera.position.to_array(),
                camera.yfov.to_degrees()
            ));
            this.cameras.push(camera);
        }
        let parts = SceneParts {
            source: this.path.to_path_buf(),
            triangles: std::mem::take(&mut this.triangles),
            surfaces,
            textures,
            materials: std::mem::take(&mut this.materials),
            material_names: std::mem::take(&mut this.material_names),
            environment,
            environment_map: map,
            cameras: std::mem::take(&mut this.cameras),
            lights: std::mem::take(&mut this.lights),
            warnings: Vec::new(),
        };
        Ok((parts, this.origin, decide_environment))
    }

    /// One warning per kind of thing dropped, with its count over the whole file.
    fn report_counts(&mut self) {
        let c = std::mem::take(&mut self.counts);
        if c.degenerate > 0 {
            self.warn(format!("{} degenerate (zero-area) triangle(s) dropped", c.degenerate));
        }
        if c.degenerate_emitters > 0 {
            self.warn(format!("{} zero-area emitter triangle(s) dropped", c.degenerate_emitters));
        }
        if c.points_or_lines > 0 {
            self.warn(format!(
                "{} primitive(s) of points or lines skipped (only triangles, strips and fans are rendered)",
                c.points_or_lines
            ));
        }
    }
}

/// The environment of a scene with no light at all.
pub const DEFAULT_ENVIRONMENT: Vec3 = Vec3::ONE;

fn triangle_bounds(triangles: &[Triangle]) -> (Vec3, Vec3) {
    triangles
        .iter()
        .flat_map(Triangle::vertices)
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        })
}
