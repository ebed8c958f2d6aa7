//! Per-triangle surface attributes (vertex normals, tangents, texture coordinates) and the
//! surface of a hit built from them. Twin of glsl/surface.glsl: `surface_at` has a GLSL function
//! of the same name, compared in tests/suite/surface_oracle.rs.
//!
//! The attributes live in their own array, parallel to the triangles (same BVH order) and read
//! only at hits, never during traversal, so the `Triangle` records that traversal streams stay
//! small. A scene with flat faces and no textures has none, and its kernels are compiled without
//! them (`SCENE_SURFACE 0`).

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3, Vec4};

use crate::gpu_types::Triangle;
use crate::shading::sampling::build_onb;

/// The attributes of one triangle's three vertices (v0, v0 + e1, v0 + e2), in scene space
/// (the triangles' coordinates), std430 layout of `TriangleSurface` in glsl/surface.glsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct TriangleSurface {
    /// xyz: the vertex normal (unit, or zero where the file gave none or the triangle is flat:
    /// the face normal is used);
    /// w: unused.
    pub normal: [[f32; 4]; 3],
    /// xyz: the vertex tangent (along +u of the normal texture's coordinates); w: its handedness
    /// ±1, the bitangent being w · cross(normal, tangent) (glTF 2.0, section 3.7.2.1).
    pub tangent: [[f32; 4]; 3],
    /// xy: TEXCOORD_0, zw: TEXCOORD_1 of each vertex (0 where absent).
    pub uv: [[f32; 4]; 3],
}

impl TriangleSurface {
    /// A flat triangle: no vertex normals (the face normal is used), no tangents, uv 0.
    pub fn flat() -> Self {
        Self::default()
    }
}

/// The surface at a hit: the shading frame and texture coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceHit {
    /// The interpolated vertex normal, normalised (the geometric normal where the vertices have
    /// none or they cancel). Not flipped towards the viewer.
    pub normal: Vec3,
    /// Unit tangent orthogonal to `normal` (Gram-Schmidt of the interpolated tangent; any
    /// orthogonal direction where there is none).
    pub tangent: Vec3,
    /// ±1: the bitangent is `handedness * normal.cross(tangent)`.
    pub handedness: f32,
    /// Interpolated TEXCOORD_0 (glTF convention: v = 0 is the image's top row); zero if absent.
    pub uv0: Vec2,
    /// Interpolated TEXCOORD_1; zero if absent.
    pub uv1: Vec2,
}

/// Barycentrics (b1, b2) of point `p` (on or near the triangle's plane) in `tri`: the
/// least-squares solution of p - v0 = b1 e1 + b2 e2.
pub fn triangle_bary(tri: &Triangle, p: Vec3) -> Vec2 {
    let (e1, e2) = (Vec3::from(tri.e1), Vec3::from(tri.e2));
    let d = p - Vec3::from(tri.v0);
    let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d20, d21) = (d.dot(e1), d.dot(e2));
    let inv = 1.0 / (d00 * d11 - d01 * d01);
    Vec2::new(d11 * d20 - d01 * d21, d00 * d21 - d01 * d20) * inv
}

/// Interpolated vectors shorter than this (squared) count as missing.
const MIN_LENGTH_SQUARED: f32 = 1e-12;

/// The surface of triangle `tri` with attributes `attr` at barycentrics `bary` = (b1, b2) of
/// vertices v0 + e1 and v0 + e2 (as `bvh::Hit::bary`): attributes interpolated linearly
/// (b0 = 1 - b1 - b2), normal and tangent re-normalised and made orthogonal.
pub fn surface_at(tri: &Triangle, attr: &TriangleSurface, bary: Vec2) -> SurfaceHit {
    let w = Vec3::new(1.0 - bary.x - bary.y, bary.x, bary.y);
    let lerp4 = |rows: &[[f32; 4]; 3]| Vec4::from(rows[0]) * w.x + Vec4::from(rows[1]) * w.y + Vec4::from(rows[2]) * w.z;
    let n = lerp4(&attr.normal).truncate();
    let normal = if n.length_squared() > MIN_LENGTH_SQUARED {
        n.normalize()
    } else {
        tri.normal_area2().normalize()
    };
    let t4 = lerp4(&attr.tangent);
    let t = t4.truncate() - normal * normal.dot(t4.truncate());
    let tangent = if t.length_squared() > MIN_LENGTH_SQUARED {
        t.normalize()
    } else {
        build_onb(normal).0
    };
    let uv = lerp4(&attr.uv);
    SurfaceHit {
        normal,
        tangent,
        handedness: if t4.w < 0.0 { -1.0 } else { 1.0 },
        uv0: Vec2::new(uv.x, uv.y),
        uv1: Vec2::new(uv.z, uv.w),
    }
}
