//! glTF vertex attributes to per-triangle [`TriangleSurface`]s: NORMAL, TANGENT (generated with
//! MikkTSpace, as glTF 2.0 section 3.7.2.1 asks, where a normal-mapped primitive has none),
//! TEXCOORD_0 and TEXCOORD_1.

use glam::{DMat3, DMat4, Vec2, Vec3, Vec4};

use restir_pt_shading_core::surface::TriangleSurface;

use super::gltf_loader::Loader;

/// A primitive's vertex attributes in scene space (`None`: the file has none, or unusable ones).
pub(super) struct PrimitiveSurface {
    normals: Option<Vec<Vec3>>,
    tangents: Option<Vec<Vec4>>,
    uv: [Option<Vec<Vec2>>; 2],
    /// MikkTSpace tangents per triangle corner (in `tris` order), where the file has none.
    corner_tangents: Option<Vec<[Vec4; 3]>>,
}

/// A vertex normal this far (1 - cos) from its face's normal makes the triangle smooth-shaded.
const FLAT_TOLERANCE: f32 = 1e-5;

impl Loader<'_> {
    /// The surface attributes of `prim` (vertices placed by `world`; `tris` its triangles), or
    /// `None` if it has no normals and no texture coordinates. Attributes of the wrong type or
    /// count are dropped with a warning (the primitive still renders, flat or untextured).
    pub(super) fn read_surface(
        &mut self,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
        world: &DMat4,
        positions: &[Vec3],
        tris: &[[u32; 3]],
    ) -> Option<PrimitiveSurface> {
        use gltf::accessor::{DataType, Dimensions};
        let buffers = self.buffers;
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let n = positions.len();
        let mut usable = |semantic: gltf::Semantic, name: &str, types: &[DataType], dims: Dimensions| -> bool {
            let Some(a) = prim.get(&semantic) else { return false };
            let ok = types.contains(&a.data_type()) && a.dimensions() == dims && a.count() == n;
            if !ok {
                self.warn(format!(
                    "mesh {}: {name} ignored: it must be {dims:?} of {types:?} with one entry per vertex ({n})",
                    mesh.index()
                ));
            }
            ok
        };
        let has_normals = usable(gltf::Semantic::Normals, "NORMAL", &[DataType::F32], Dimensions::Vec3);
        let has_tangents = usable(gltf::Semantic::Tangents, "TANGENT", &[DataType::F32], Dimensions::Vec4);
        let uv_types = [DataType::F32, DataType::U8, DataType::U16];
        let has_uv = [0, 1].map(|s| usable(gltf::Semantic::TexCoords(s), &format!("TEXCOORD_{s}"), &uv_types, Dimensions::Vec2));
        if !has_normals && !has_uv[0] && !has_uv[1] {
            return None;
        }
        let linear = DMat3::from_mat4(*world);
        // Normals transform by the inverse transpose; a singular transform has no faces anyway.
        let normal_matrix = linear.inverse().transpose().as_mat3();
        let (linear32, mirror) = (linear.as_mat3(), if linear.determinant() < 0.0 { -1.0 } else { 1.0 });
        let finite_or_zero = |v: Vec3| if v.is_finite() { v } else { Vec3::ZERO };
        let normals: Option<Vec<Vec3>> = has_normals.then(|| reader.read_normals()).flatten().map(|it| {
            it.map(|v| finite_or_zero((normal_matrix * Vec3::from(v)).normalize_or_zero()))
                .collect()
        });
        let local_normals: Option<Vec<Vec3>> = has_normals
            .then(|| reader.read_normals())
            .flatten()
            .map(|it| it.map(Vec3::from).collect());
        let place_tangent = |t: Vec4| {
            let v = finite_or_zero((linear32 * t.truncate()).normalize_or_zero());
            v.extend(if t.w < 0.0 { -mirror } else { mirror })
        };
        let tangents: Option<Vec<Vec4>> = has_tangents
            .then(|| reader.read_tangents())
            .flatten()
            .map(|it| it.map(|t| place_tangent(Vec4::from(t))).collect());
        let uv = [0, 1].map(|s| {
            has_uv[s as usize].then(|| reader.read_tex_coords(s)).flatten().map(|it| {
                it.into_f32()
                    .map(Vec2::from)
                    .map(|v| if v.is_finite() { v } else { Vec2::ZERO })
                    .collect::<Vec<_>>()
            })
        });
        let mut corner_tangents = None;
        if tangents.is_none() {
            if let Some(set) = self.normal_map_texcoord(prim) {
                if let Some(uv) = &uv[set as usize] {
                    let generated = generate_tangents(positions, local_normals.as_deref(), uv, tris);
                    corner_tangents = Some(generated.into_iter().map(|c| c.map(place_tangent)).collect());
                }
            }
        }
        Some(PrimitiveSurface {
            normals,
            tangents,
            uv,
            corner_tangents,
        })
    }

    /// The texture-coordinate set of the normal map of `prim`'s material, if it has one.
    fn normal_map_texcoord(&self, prim: &gltf::Primitive) -> Option<u32> {
        let material = prim.material();
        let normal = material.normal_texture()?;
        let set = super::gltf_texture::normal_transform(&material)
            .and_then(|t| t.3)
            .unwrap_or(normal.tex_coord());
        Some(set.min(1))
    }

    /// The attributes of triangle `k` of a primitive (vertex indices `tri`, corners in the
    /// order the triangle is stored), and whether its vertex normals differ from its face
    /// normal `face` (where none does, by 1 - cos within `FLAT_TOLERANCE`, they are left out).
    pub(super) fn triangle_surface(
        surface: &PrimitiveSurface,
        k: usize,
        corners: [u32; 3],
        order: [usize; 3],
        face: Vec3,
    ) -> (TriangleSurface, bool) {
        let mut out = TriangleSurface::flat();
        let mut smooth = false;
        for (slot, &c) in order.iter().enumerate() {
            let v = corners[c] as usize;
            if let Some(n) = &surface.normals {
                out.normal[slot] = n[v].extend(0.0).to_array();
                smooth |= n[v] != Vec3::ZERO && n[v].dot(face) < 1.0 - FLAT_TOLERANCE;
            }
            if let Some(t) = &surface.tangents {
                out.tangent[slot] = t[v].to_array();
            } else if let Some(t) = &surface.corner_tangents {
                out.tangent[slot] = t[k][c].to_array();
            }
            let uv0 = surface.uv[0].as_ref().map_or(Vec2::ZERO, |u| u[v]);
            let uv1 = surface.uv[1].as_ref().map_or(Vec2::ZERO, |u| u[v]);
            out.uv[slot] = [uv0.x, uv0.y, uv1.x, uv1.y];
        }
        // Flat vertex normals are stored as none: the face normal is used, exactly, and a scene
        // with no others compiles without shading normals (Scene::has_shading_normals).
        if !smooth {
            out.normal = TriangleSurface::flat().normal;
        }
        (out, smooth)
    }
}

/// MikkTSpace over one primitive's triangles (object space).
struct MikkInput<'a> {
    positions: &'a [Vec3],
    normals: Option<&'a [Vec3]>,
    uv: &'a [Vec2],
    tris: &'a [[u32; 3]],
    out: Vec<[Vec4; 3]>,
}

impl mikktspace::Geometry for MikkInput<'_> {
    fn num_faces(&self) -> usize {
        self.tris.len()
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.tris[face][vert] as usize].to_array()
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        let t = self.tris[face];
        match self.normals {
            Some(n) => n[t[vert] as usize].to_array(),
            // glTF: without NORMAL, flat normals.
            None => {
                let [a, b, c] = t.map(|i| self.positions[i as usize]);
                (b - a).cross(c - a).normalize_or_zero().to_array()
            }
        }
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.uv[self.tris[face][vert] as usize].to_array()
    }
    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        // MikkTSpace's bitangent w · cross(n, t) points along +v of the coordinates it was given,
        // but glTF's v runs down the image while a normal texture's +Y (green) points up it
        // (glTF 2.0 section 3.9.3): the sign is negated, as three.js (computeMikkTSpaceTangents'
        // negateSign, "required for glTF") and Bevy do.
        self.out[face][vert] = Vec4::new(tangent[0], tangent[1], tangent[2], -tangent[3]);
    }
}

/// Per-corner MikkTSpace tangents (xyz, w handedness) of `tris`; zero where it fails.
fn generate_tangents(positions: &[Vec3], normals: Option<&[Vec3]>, uv: &[Vec2], tris: &[[u32; 3]]) -> Vec<[Vec4; 3]> {
    let mut input = MikkInput {
        positions,
        normals,
        uv,
        tris,
        out: vec![[Vec4::ZERO; 3]; tris.len()],
    };
    if !mikktspace::generate_tangents(&mut input) {
        return vec![[Vec4::ZERO; 3]; tris.len()];
    }
    input.out
}
