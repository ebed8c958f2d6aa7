//! Per-triangle surface attributes (vertex normals, tangents, texture coordinates) and the
//! surface of a hit built from them. Twin of glsl/shading_core/surface.glsl: `surface_at` has a GLSL function
//! of the same name, compared in tests/suite/surface_oracle.rs.
//!
//! The attributes live in their own array, parallel to the triangles (same BVH order) and read
//! only at hits, never during traversal, so the `Triangle` records that traversal streams stay
//! small. A scene with flat faces and no textures has none, and its kernels are compiled without
//! them (`SCENE_SURFACE 0`).

use glam::{Vec2, Vec3, Vec4};

use restir_pt_interface::gpu_types::Triangle;
use restir_pt_interface::shader_interface::SURFACE_MIN_LENGTH_SQUARED;
pub use restir_pt_interface::surface_types::TriangleSurface;

use crate::sampling::build_onb;

/// [`pack_vertex_color`]'s flag bit: the vertex has a colour.
const VERTEX_COLOR_PRESENT: u32 = 1 << 31;

/// A COLOR_0 value (linear RGB, clamped to [0, 1]) as the bits of an f32 kept in a vertex
/// normal's unused w: 10 bits per channel (R in bits 0-9, G 10-19, B 20-29, rounded to
/// 1/1023), bit 31 set to say the vertex has one. Bit 30 stays clear, so the exponent is never
/// all ones: the value is never a NaN or an infinity that a copy could alter.
pub fn pack_vertex_color(c: Vec3) -> f32 {
    let q = (c.clamp(Vec3::ZERO, Vec3::ONE) * 1023.0).round();
    f32::from_bits(VERTEX_COLOR_PRESENT | q.x as u32 | (q.y as u32) << 10 | (q.z as u32) << 20)
}

/// The colour of one vertex's packed value, or None (no colour).
fn unpack_vertex_color(w: f32) -> Option<Vec3> {
    let b = w.to_bits();
    (b & VERTEX_COLOR_PRESENT != 0).then(|| Vec3::new((b & 1023) as f32, ((b >> 10) & 1023) as f32, ((b >> 20) & 1023) as f32) / 1023.0)
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
    /// Interpolated COLOR_0 (linear RGB), which multiplies the base colour; 1 where the
    /// vertices have none.
    pub color: Vec3,
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

/// The surface of triangle `tri` with attributes `attr` at barycentrics `bary` = (b1, b2) of
/// vertices v0 + e1 and v0 + e2 (as `bvh::Hit::bary`): attributes interpolated linearly
/// (b0 = 1 - b1 - b2), normal and tangent re-normalised and made orthogonal.
pub fn surface_at(tri: &Triangle, attr: &TriangleSurface, bary: Vec2) -> SurfaceHit {
    let w = Vec3::new(1.0 - bary.x - bary.y, bary.x, bary.y);
    let lerp4 = |rows: &[[f32; 4]; 3]| Vec4::from(rows[0]) * w.x + Vec4::from(rows[1]) * w.y + Vec4::from(rows[2]) * w.z;
    let n = lerp4(&attr.normal).truncate();
    let normal = if n.length_squared() > SURFACE_MIN_LENGTH_SQUARED {
        n.normalize()
    } else {
        tri.normal_area2().normalize()
    };
    let t4 = lerp4(&attr.tangent);
    let t = t4.truncate() - normal * normal.dot(t4.truncate());
    let tangent = if t.length_squared() > SURFACE_MIN_LENGTH_SQUARED {
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
        color: vertex_color(attr, w),
    }
}

/// COLOR_0 at vertex weights `w` (b0, b1, b2): the vertices' colours interpolated, as glTF
/// interpolates every vertex attribute; 1 where the first vertex has none (a primitive's
/// vertices all have one or none). Twin of GLSL `vertex_color`.
pub fn vertex_color(attr: &TriangleSurface, w: Vec3) -> Vec3 {
    let c = attr.normal.map(|n| unpack_vertex_color(n[3]));
    match c {
        [Some(a), Some(b), Some(d)] => a * w.x + b * w.y + d * w.z,
        _ => Vec3::ONE,
    }
}
