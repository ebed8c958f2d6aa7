//! Error-bounded ray origins, twin of glsl/shading_core/ray_offset.glsl: every ray that leaves a surface (path
//! continuation, shadow ray, NEE, shift visibility) starts at [`offset_ray_origin`].
//!
//! A surface point is computed as `p = v0 + b1 e1 + b2 e2` in f32. Its rounding error is at most
//! γ₃ (|v0| + |b1 e1| + |b2 e2|) per component (γₙ = nu / (1 − nu), u = 2⁻²⁴; Pharr, Jakob and
//! Humphreys, *Physically Based Rendering* 4th ed., sec. 6.8), which is below
//! γ₃ (|v0| + |e1| + |e2|) since the barycentrics lie in [0, 1]. The Möller–Trumbore test of a
//! ray from an origin o at height h above the same plane computes the sign of
//! (o − v0) · (e1 × e2) with an error of a few u |o − v0| |e1| |e2|, against a value of
//! h |e1| |e2| sin θ (θ the triangle's smallest angle); |o − v0| is below |e1| + |e2| + h. The
//! origin is therefore moved by
//!
//! `h = 2⁻¹⁷ · (|v0| + |e1| + |e2|) · |n|` along n,
//!
//! 128 unit roundoffs, which covers the interpolation (3u) and the intersection test for
//! triangles whose smallest angle is above about 3°, then rounded one float further away from
//! the plane so that the offset survives rounding. The bound scales with the coordinates and the
//! triangle's size, never with a fixed floor, so a scene behaves the same at any scale; far from
//! the origin f32 coordinates themselves lose the geometry, which is why the loader re-centres
//! scenes on their first camera (crates/scene/src/gltf_loader.rs).

use glam::Vec3;

use restir_pt_interface::gpu_types::Triangle;

pub use restir_pt_interface::shader_interface::RAY_OFFSET_SCALE;

/// The float next to `x` in direction `s` (s > 0: up, s < 0: down); `x` itself when s == 0,
/// x == 0 (the next float is denormal, which GPUs may flush) or x is infinite.
pub fn next_float_towards(x: f32, s: f32) -> f32 {
    if s == 0.0 || x == 0.0 || x.is_infinite() {
        return x;
    }
    let bits = x.to_bits() as i32;
    f32::from_bits(if (s > 0.0) == (x > 0.0) { bits + 1 } else { bits - 1 } as u32)
}

/// Twin of GLSL `offset_ray_origin`: moves `p`, a point of `tri` computed from barycentrics, off
/// the triangle's plane along the unit normal `n` (facing the side the ray leaves to) by more than
/// the rounding error of `p` and of the intersection test, at any scale and position.
pub fn offset_ray_origin(p: Vec3, n: Vec3, tri: &Triangle) -> Vec3 {
    let err = RAY_OFFSET_SCALE * (Vec3::from(tri.v0).abs() + Vec3::from(tri.e1).abs() + Vec3::from(tri.e2).abs());
    let o = p + n.abs().dot(err) * n;
    Vec3::new(
        next_float_towards(o.x, n.x),
        next_float_towards(o.y, n.y),
        next_float_towards(o.z, n.z),
    )
}
