//! glTF mesh primitives to world-space triangles: every triangle mode (lists, strips, fans),
//! COLOR_0 and `EXT_mesh_gpu_instancing`.

use std::collections::HashMap;

use anyhow::{bail, Result};
use glam::{DMat4, DQuat, DVec3, Vec3};

use restir_pt_interface::gpu_types::{Triangle, NO_EMITTER};
use restir_pt_shading_core::surface::{pack_vertex_color, TriangleSurface};

use super::gltf_json::Instancing;
use super::gltf_loader::{problem, Loader, MAX_TRIANGLES};

/// Vertex-index triples of the triangles a primitive of `mode` draws from `indices`, in the
/// winding glTF 2.0 defines (section 3.7.2.1): strips alternate the order of their first two
/// vertices so that every triangle keeps the first one's orientation; fans pivot on vertex 0.
/// Triangles that repeat a vertex (the restarts of stitched strips) are left out; other modes
/// (points, lines) give `None`.
pub fn triangle_indices(mode: gltf::mesh::Mode, indices: &[u32]) -> Option<Vec<[u32; 3]>> {
    use gltf::mesh::Mode;
    let n = indices.len();
    let tris: Vec<[u32; 3]> = match mode {
        Mode::Triangles => indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|i| {
                let odd = i % 2;
                [indices[i], indices[i + 1 + odd], indices[i + 2 - odd]]
            })
            .collect(),
        Mode::TriangleFan => (1..n.saturating_sub(1)).map(|i| [indices[i], indices[i + 1], indices[0]]).collect(),
        _ => return None,
    };
    let restart = !matches!(mode, Mode::Triangles);
    Some(
        tris.into_iter()
            .filter(|t| !restart || (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]))
            .collect(),
    )
}

impl Loader<'_> {
    /// The per-instance transforms (translation · rotation · scale, in f64) of an instanced node.
    pub(super) fn instance_transforms(&mut self, node: &gltf::Node, inst: &Instancing) -> Result<Vec<DMat4>> {
        let doc = self.doc;
        let buffers = self.buffers;
        let path = self.path;
        let get = |b: gltf::Buffer| buffers.get(b.index()).map(|d| &d.0[..]);
        let read = |index: Option<usize>, what: &str, dims: gltf::accessor::Dimensions| -> Result<Option<Vec<[f32; 4]>>> {
            let Some(i) = index else { return Ok(None) };
            let bad = || {
                problem(
                    path,
                    format!(
                        "node {}: EXT_mesh_gpu_instancing {what} must be a float {dims:?} accessor within its buffer",
                        node.index()
                    ),
                )
            };
            let a = doc.accessors().nth(i).ok_or_else(bad)?;
            if a.data_type() != gltf::accessor::DataType::F32 || a.dimensions() != dims || a.count() == 0 {
                return Err(bad());
            }
            let values: Vec<[f32; 4]> = match dims {
                gltf::accessor::Dimensions::Vec4 => gltf::accessor::Iter::<[f32; 4]>::new(a, get).ok_or_else(bad)?.collect(),
                _ => gltf::accessor::Iter::<[f32; 3]>::new(a, get)
                    .ok_or_else(bad)?
                    .map(|v| [v[0], v[1], v[2], 0.0])
                    .collect(),
            };
            Ok(Some(values))
        };
        use gltf::accessor::Dimensions::{Vec3 as D3, Vec4 as D4};
        let t = read(inst.translation, "TRANSLATION", D3)?;
        let r = read(inst.rotation, "ROTATION", D4)?;
        let s = read(inst.scale, "SCALE", D3)?;
        let count = [&t, &r, &s].iter().filter_map(|v| v.as_ref().map(Vec::len)).min().unwrap_or(0);
        self.counts.instances += count;
        let at = |v: &Option<Vec<[f32; 4]>>, i: usize| v.as_ref().map(|v| v[i]);
        let d3 = |v: [f32; 4]| DVec3::new(v[0].into(), v[1].into(), v[2].into());
        let transforms: Vec<DMat4> = (0..count)
            .map(|i| {
                let tr = at(&t, i).map_or(DVec3::ZERO, d3);
                let rot = at(&r, i).map_or(DQuat::IDENTITY, |v| DQuat::from_array(v.map(f64::from)).normalize());
                let sc = at(&s, i).map_or(DVec3::ONE, d3);
                DMat4::from_scale_rotation_translation(sc, rot, tr)
            })
            .collect();
        if transforms.iter().any(|m| !m.is_finite()) {
            bail!(problem(
                path,
                format!("node {}: an EXT_mesh_gpu_instancing transform is not finite", node.index())
            ));
        }
        Ok(transforms)
    }

    /// The world bounds (f64) of the vertex positions of `instances`, or `None` if no vertex is
    /// readable. Primitives the loader will reject are skipped here: `add_mesh` reports them.
    pub(super) fn vertex_bounds(&self, instances: &[(gltf::Mesh, DMat4)]) -> Option<(DVec3, DVec3)> {
        let buffers = self.buffers;
        let mut local: HashMap<usize, Vec<DVec3>> = HashMap::new();
        let mut bounds: Option<(DVec3, DVec3)> = None;
        for (mesh, world) in instances {
            let positions = local.entry(mesh.index()).or_insert_with(|| {
                mesh.primitives()
                    .filter(|prim| self.check_accessor_types(mesh, prim).is_ok())
                    .filter_map(|prim| prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..])).read_positions())
                    .flatten()
                    .map(|p| Vec3::from(p).as_dvec3())
                    .filter(|p| p.is_finite())
                    .collect()
            });
            for p in positions.iter().map(|&p| world.transform_point3(p)) {
                let (lo, hi) = bounds.unwrap_or((p, p));
                bounds = Some((lo.min(p), hi.max(p)));
            }
        }
        bounds
    }

    /// Adds the triangles of `mesh` placed by `world` (f64), relative to `self.origin` and then
    /// rounded to f32.
    pub(super) fn add_mesh(&mut self, mesh: &gltf::Mesh, world: &DMat4) -> Result<()> {
        // A mirroring transform flips the winding, and so which face is the front.
        let flip = world.determinant() < 0.0;
        let origin = self.origin;
        for prim in mesh.primitives() {
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
            // Scene coordinates: world (f64) minus the origin, before any rounding.
            let placed: Vec<DVec3> = positions.iter().map(|p| world.transform_point3(p.as_dvec3()) - origin).collect();
            let Some(tris) = triangle_indices(prim.mode(), &indices) else {
                self.counts.points_or_lines += 1;
                let b = placed.iter().map(|p| p.as_vec3()).fold(
                    self.counts.skipped_bounds.unwrap_or((Vec3::INFINITY, Vec3::NEG_INFINITY)),
                    |(lo, hi), p| (lo.min(p), hi.max(p)),
                );
                self.counts.skipped_bounds = Some(b).filter(|(lo, hi)| lo.cmple(*hi).all());
                continue;
            };
            if prim.mode() == gltf::mesh::Mode::Triangles && !indices.len().is_multiple_of(3) {
                self.warn(format!("mesh {}: {} trailing indices ignored", mesh.index(), indices.len() % 3));
            }
            let colours: Option<Vec<Vec3>> = reader.read_colors(0).map(|c| c.into_rgb_f32().map(Vec3::from).collect());
            let colours = colours.filter(|c| c.len() == positions.len() && c.iter().all(|v| v.is_finite()));
            let material = match prim.material().index() {
                Some(i) => i as u32,
                None => self.default_material(),
            };
            let surface = self.read_surface(mesh, &prim, world, &positions, &tris);
            let order = if flip { [0, 2, 1] } else { [0, 1, 2] };
            self.counts.vertex_colours |= colours.is_some();
            for (k, tri) in tris.iter().enumerate() {
                let [a, b, c] = order.map(|o| placed[tri[o] as usize]);
                let face = (b - a).cross(c - a).normalize_or_zero().as_vec3();
                let mut attributes = surface.as_ref().map(|s| Self::triangle_surface(s, k, *tri, order, face));
                if let Some(colours) = &colours {
                    // COLOR_0 is interpolated per hit from the vertices' packed colours.
                    let (attr, _) = attributes.get_or_insert((TriangleSurface::flat(), false));
                    for (slot, &o) in order.iter().enumerate() {
                        attr.normal[slot][3] = pack_vertex_color(colours[tri[o] as usize]);
                    }
                }
                self.push_triangle(a, b, c, material, attributes)?;
            }
        }
        Ok(())
    }

    /// Adds triangle (a, b, c) in scene coordinates (f64); the edges are taken in f64 before
    /// rounding, so they keep their precision whatever the rounding of `a`.
    /// `surface`: the triangle's vertex attributes and whether they make it smooth-shaded.
    fn push_triangle(&mut self, a: DVec3, b: DVec3, c: DVec3, material: u32, surface: Option<(TriangleSurface, bool)>) -> Result<()> {
        let emissive = Vec3::from(self.materials[material as usize].emission).max_element() > 0.0;
        let (e1, e2) = ((b - a).as_vec3(), (c - a).as_vec3());
        let a = a.as_vec3();
        let area2 = e1.cross(e2).length();
        // Degenerate triangles carry no area: they cannot be hit or emit, and break normals.
        if !(area2 > 1e-12 * (e1.length_squared() + e2.length_squared()).max(f32::MIN_POSITIVE)) || !area2.is_finite() {
            self.counts.degenerate += 1;
            self.counts.degenerate_emitters += emissive as usize;
            return Ok(());
        }
        if self.triangles.len() >= MAX_TRIANGLES {
            bail!(problem(self.path, format!("more than {MAX_TRIANGLES} triangles")));
        }
        if let Some((attributes, smooth)) = surface {
            // The attribute array starts with the first triangle that has attributes.
            self.surfaces.resize(self.triangles.len(), TriangleSurface::flat());
            self.surfaces.push(attributes);
            self.counts.smooth |= smooth;
        }
        self.triangles.push(Triangle {
            v0: a.into(),
            material,
            e1: e1.into(),
            emitter: NO_EMITTER,
            e2: e2.into(),
            alpha_tested: 0,
        });
        Ok(())
    }

    /// Whether `accessor`'s `count` elements lie within its buffer view, and the view within its
    /// loaded buffer (glTF 2.0 §5.1.1 and §3.6.2.4: offset + stride × (count − 1) + element size ≤
    /// the view's byteLength). A sparse accessor without a view has nothing to check here.
    fn accessor_fits(&self, accessor: &gltf::Accessor) -> bool {
        let Some(view) = accessor.view() else { return true };
        let element = accessor.size();
        let stride = view.stride().unwrap_or(element);
        let Some(before_last) = accessor.count().checked_sub(1) else {
            return false;
        };
        let last = before_last as u64 * stride as u64 + element as u64;
        let in_view = accessor.offset() as u64 + last <= view.length() as u64;
        let buffer_len = self.buffers.get(view.buffer().index()).map_or(0, |d| d.0.len());
        in_view && (view.offset() + view.length()) as u64 <= buffer_len as u64
    }

    /// The spec's accessor counts (at least 1) and types for positions (float VEC3), indices
    /// (unsigned SCALAR) and colours; the gltf crate's readers assume them (an index accessor of
    /// floats hits `unreachable!`, a count of 0 overflows).
    fn check_accessor_types(&self, mesh: &gltf::Mesh, prim: &gltf::Primitive) -> Result<()> {
        use gltf::accessor::{DataType, Dimensions};
        // glTF requires count >= 1, and the readers compute count - 1 (an overflow at 0).
        let read = [
            ("POSITION", prim.get(&gltf::Semantic::Positions)),
            ("indices", prim.indices()),
            ("COLOR_0", prim.get(&gltf::Semantic::Colors(0))),
        ];
        for (name, accessor) in read {
            if accessor.is_some_and(|a| a.count() == 0) {
                bail!(problem(
                    self.path,
                    format!("mesh {}: the {name} accessor has count 0", mesh.index())
                ));
            }
        }
        // The gltf crate's readers return None for data that does not fit, and an index reader
        // of None reads as "no indices": an oversized accessor would draw the vertices in order.
        let used = prim.indices().map(|a| ("indices".to_string(), a)).into_iter();
        for (name, accessor) in used.chain(prim.attributes().map(|(s, a)| (s.to_string(), a))) {
            if !self.accessor_fits(&accessor) {
                bail!(problem(
                    self.path,
                    format!(
                        "mesh {}: the {name} accessor ({}, count {}) does not fit its buffer view or buffer",
                        mesh.index(),
                        accessor.index(),
                        accessor.count()
                    )
                ));
            }
        }
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
        if let Some(c) = prim.get(&gltf::Semantic::Colors(0)) {
            let ok = matches!(c.data_type(), DataType::F32 | DataType::U8 | DataType::U16)
                && matches!(c.dimensions(), Dimensions::Vec3 | Dimensions::Vec4);
            if !ok {
                bail!(problem(
                    self.path,
                    format!(
                        "mesh {}: COLOR_0 must be VEC3 or VEC4 of float, unsigned byte or unsigned short",
                        mesh.index()
                    )
                ));
            }
        }
        Ok(())
    }
}
