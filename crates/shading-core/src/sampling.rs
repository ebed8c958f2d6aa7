//! Warping uniforms to directions and points; the twin of glsl/shading_core/sampling.glsl.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// 1/π.
pub const INV_PI: f32 = 1.0 / PI;
/// Solid-angle density of a uniform direction on the unit sphere, 1/(4π) sr⁻¹.
pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Orthonormal basis around a unit normal without branches on its sign (Duff et al., JCGT 2017).
pub fn build_onb(n: Vec3) -> (Vec3, Vec3) {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let c = n.x * n.y * a;
    (
        Vec3::new(1.0 + s * n.x * n.x * a, s * c, -s * n.x),
        Vec3::new(c, s + n.y * n.y * a, -n.y),
    )
}

/// World-space `v` in the orthonormal frame (t, b, n): (v·t, v·b, v·n), +z along `n`. Twin of
/// GLSL `to_local`.
pub fn to_local(v: Vec3, t: Vec3, b: Vec3, n: Vec3) -> Vec3 {
    Vec3::new(v.dot(t), v.dot(b), v.dot(n))
}

/// The inverse of [`to_local`]: local `v` back to world space. Twin of GLSL `to_world`.
pub fn to_world(v: Vec3, t: Vec3, b: Vec3, n: Vec3) -> Vec3 {
    v.x * t + v.y * b + v.z * n
}

/// Shirley-Chiu concentric map of `u` in [0, 1)² to the unit disk, uniform in area (pbrt-v4
/// `SampleUniformDiskConcentric`). Twin of GLSL `sample_concentric_disk`.
pub fn sample_concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, phi) = if o.x.abs() > o.y.abs() {
        (o.x, (PI / 4.0) * (o.y / o.x))
    } else {
        (o.y, PI / 2.0 - (PI / 4.0) * (o.x / o.y))
    };
    r * Vec2::new(phi.cos(), phi.sin())
}

/// A unit direction on the +z hemisphere with density cos θ / π (Malley's method, pbrt-v4
/// `SampleCosineHemisphere`), in the local frame. Twin of GLSL `sample_cosine_hemisphere`.
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = sample_concentric_disk(u);
    Vec3::new(d.x, d.y, (1.0 - d.dot(d)).max(0.0).sqrt())
}

/// Solid-angle density of [`sample_cosine_hemisphere`], max(cos θ, 0) / π in 1/sr. Twin of GLSL
/// `pdf_cosine_hemisphere`.
pub fn pdf_cosine_hemisphere(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * INV_PI
}

/// A unit direction uniform on the sphere (density [`UNIFORM_SPHERE_PDF`]); z = 1 - 2 u.x.
/// Twin of GLSL `sample_uniform_sphere`.
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Barycentrics (b1, b2) uniform over a triangle; b0 = 1 - b1 - b2.
pub fn sample_triangle(u: Vec2) -> Vec2 {
    let su = u.x.sqrt();
    Vec2::new(1.0 - su, u.y * su)
}

/// GGX visible-normal sampling by spherical caps (Dupuy and Benyoub 2023); wo.z >= 0 locally.
pub fn sample_ggx_vndf(wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    let wo_std = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    let phi = 2.0 * PI * u.x;
    let z = (1.0 - u.y) * (1.0 + wo_std.z) - wo_std.z;
    let sin_theta = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
    let h_std = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), z) + wo_std;
    Vec3::new(alpha * h_std.x, alpha * h_std.y, h_std.z.max(0.0)).normalize()
}

/// The balance-heuristic weight of the technique of pdf `a` beside one of pdf `b` (0 where `a`
/// is).
pub fn balance_heuristic(a: f32, b: f32) -> f32 {
    if a > 0.0 {
        a / (a + b)
    } else {
        0.0
    }
}

/// Veach's power heuristic (β = 2) weight a² / (a² + b²) of the technique of pdf `a` beside one of
/// pdf `b`; 0 when both are 0. Both pdfs must be in the same measure. Twin of GLSL
/// `power_heuristic`.
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 {
        a2 / (a2 + b2)
    } else {
        0.0
    }
}
