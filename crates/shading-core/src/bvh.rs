//! The stackless BVH traversal twin of glsl/shading_core/bvh.glsl, the oracle for GPU hits, over the
//! depth-first nodes with skip links that `restir_pt_scene::bvh` builds.

use glam::{Vec2, Vec3};

use restir_pt_interface::gpu_types::{BvhNode, Triangle};

use crate::alpha::AlphaScene;
use crate::ray_offset::offset_ray_origin;

pub use restir_pt_interface::gpu_types::NO_HIT;

/// A ray's hit (twin of GLSL `Hit`, glsl/shading_core/bvh.glsl).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit: distance along the ray in units of |d| (scene units for a unit d).
    pub t: f32,
    /// Index of the triangle hit (in the scene's BVH leaf order), or [`NO_HIT`].
    pub triangle: u32,
    /// Barycentrics (b1, b2) of the hit on the triangle, weights of vertices 1 and 2.
    pub bary: Vec2,
}

/// Möller-Trumbore; hits with t in (0, tmax) count, from either side. Returns (t, (b1, b2)).
pub fn intersect_triangle(o: Vec3, d: Vec3, tri: &Triangle, tmax: f32) -> Option<(f32, Vec2)> {
    let (v0, e1, e2) = (Vec3::from(tri.v0), Vec3::from(tri.e1), Vec3::from(tri.e2));
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = o - v0;
    let b1 = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let q = s.cross(e1);
    let b2 = d.dot(q) * inv_det;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv_det;
    (t > 0.0 && t < tmax).then_some((t, Vec2::new(b1, b2)))
}

/// Whether the ray o + t d with t in [0, tmax] meets the box [lo, hi] (slab test, Kay and Kajiya
/// 1986), given `inv_d` = [`safe_inverse`]`(d)` and `o_inv_d` = o · inv_d precomputed per ray.
/// Twin of GLSL `intersect_aabb`.
pub fn intersect_aabb(o_inv_d: Vec3, inv_d: Vec3, lo: Vec3, hi: Vec3, tmax: f32) -> bool {
    let t0 = lo * inv_d - o_inv_d;
    let t1 = hi * inv_d - o_inv_d;
    let (tn, tf) = (t0.min(t1), t0.max(t1));
    let enter = tn.x.max(tn.y).max(tn.z.max(0.0));
    let leave = tf.x.min(tf.y).min(tf.z.min(tmax));
    enter <= leave
}

/// Componentwise 1/d, with 1e30 for a zero component so that the slab test stays finite.
/// Twin of GLSL `safe_inverse`.
pub fn safe_inverse(d: Vec3) -> Vec3 {
    let inv = |x: f32| if x != 0.0 { 1.0 / x } else { 1e30 };
    Vec3::new(inv(d.x), inv(d.y), inv(d.z))
}

/// Twin of GLSL `bvh_traverse`: closest hit, or the first hit found when `any_hit`. With
/// `alpha` (the kernels' `SCENE_ALPHA`), hits that `alpha_keeps` rejects do not count
/// ([`crate::alpha_trace::bvh_traverse`]).
pub fn bvh_traverse(
    nodes: &[BvhNode],
    triangles: &[Triangle],
    alpha: Option<&AlphaScene>,
    o: Vec3,
    d: Vec3,
    tmax: f32,
    any_hit: bool,
) -> Hit {
    if let Some(alpha) = alpha {
        return crate::alpha_trace::bvh_traverse(nodes, triangles, alpha, o, d, tmax, any_hit);
    }
    let mut hit = Hit {
        t: tmax,
        triangle: NO_HIT,
        bary: Vec2::ZERO,
    };
    let inv_d = safe_inverse(d);
    let o_inv_d = o * inv_d;
    let mut node = 0usize;
    while node < nodes.len() {
        let n = &nodes[node];
        if !intersect_aabb(o_inv_d, inv_d, Vec3::from(n.lo), Vec3::from(n.hi), hit.t) {
            node = n.skip as usize;
            continue;
        }
        let (first, count) = n.leaf_range();
        if count == 0 {
            node += 1;
            continue;
        }
        for i in first..first + count {
            if let Some((t, bary)) = intersect_triangle(o, d, &triangles[i as usize], hit.t) {
                hit = Hit { t, triangle: i, bary };
                if any_hit {
                    return hit;
                }
            }
        }
        node = n.skip as usize;
    }
    hit
}

/// The closest hit of the ray (o, d) before tmax, every surface opaque (`bvh_traverse` with
/// `restir_pt_scene::Scene::alpha` honours alpha modes).
pub fn trace_closest(nodes: &[BvhNode], triangles: &[Triangle], o: Vec3, d: Vec3, tmax: f32) -> Hit {
    bvh_traverse(nodes, triangles, None, o, d, tmax, false)
}

/// Whether anything blocks the ray (o, d) before tmax, every surface opaque.
pub fn trace_occluded(nodes: &[BvhNode], triangles: &[Triangle], o: Vec3, d: Vec3, tmax: f32) -> bool {
    bvh_traverse(nodes, triangles, None, o, d, tmax, true).triangle != NO_HIT
}

pub use restir_pt_interface::shader_interface::SEGMENT_EPSILON;

/// Whether anything blocks the segment between surface points p (normal np, on triangle index
/// tp) and q (normal nq, on triangle index tq): the ray of `segment_ray`, traced (the kernels
/// trace it inside `visibility_ray` of glsl/shading/shift/vertex.glsl). Both ends are offset off their
/// surfaces, each towards the other: offsetting one end only moves a grazing far hit by more
/// than any epsilon.
#[allow(clippy::too_many_arguments)]
pub fn segment_occluded(nodes: &[BvhNode], triangles: &[Triangle], p: Vec3, np: Vec3, tp: u32, q: Vec3, nq: Vec3, tq: u32) -> bool {
    let (origin, dir) = segment_ray(triangles, p, np, tp, q, nq, tq);
    trace_occluded(nodes, triangles, origin, dir, 1.0 - SEGMENT_EPSILON)
}

/// A ray of `trace_pair`; `tmax <= 0` makes it inactive (no hit, no node visit of its own).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairRay {
    /// Ray origin in scene coordinates (already offset off its surface).
    pub origin: Vec3,
    /// Ray direction in scene coordinates; hits count for t in (0, tmax) in units of |dir|.
    pub dir: Vec3,
    /// The farthest ray parameter that counts.
    pub tmax: f32,
}

/// Scenes up to this many triangles, when bound as uniform buffers, trace pairs by testing every
/// triangle (`SCENE_BRUTE_FORCE`): on llvmpipe that beats the BVH, whose node loads and nested
/// loops cost more than the triangle tests they save (docs/performance.md).
pub const BRUTE_FORCE_MAX_TRIANGLES: usize = 64;

/// Twin of GLSL `trace_pair` (glsl/shading_core/trace_pair.glsl): the closest hit of `closest` and whether
/// anything blocks `shadow`, in one traversal of the BVH (or, with `brute_force`, one pass over
/// every triangle in index order, the closest hit being the first of equal distances). The BVH
/// form tests each ray against the same triangles in the same order as `bvh_traverse`, so its
/// results equal `trace_closest` and `trace_occluded` bit for bit. With `alpha` (`SCENE_ALPHA`)
/// each ray skips the hits `alpha_keeps` rejects for it ([`crate::alpha_trace::trace_pair`]).
pub fn trace_pair(
    nodes: &[BvhNode],
    triangles: &[Triangle],
    alpha: Option<&AlphaScene>,
    brute_force: bool,
    closest: PairRay,
    shadow: PairRay,
) -> (Hit, bool) {
    if let Some(alpha) = alpha {
        return crate::alpha_trace::trace_pair(nodes, triangles, alpha, brute_force, closest, shadow);
    }
    let mut hit = Hit {
        t: closest.tmax,
        triangle: NO_HIT,
        bary: Vec2::ZERO,
    };
    let mut occluded = false;
    let test = |i: usize, enter_c: bool, enter_s: bool, hit: &mut Hit, occluded: &mut bool| {
        let tri = &triangles[i];
        if enter_c {
            if let Some((t, bary)) = intersect_triangle(closest.origin, closest.dir, tri, hit.t) {
                *hit = Hit {
                    t,
                    triangle: i as u32,
                    bary,
                };
            }
        }
        *occluded |= enter_s && intersect_triangle(shadow.origin, shadow.dir, tri, shadow.tmax).is_some();
    };
    if brute_force {
        for i in 0..triangles.len() {
            test(i, true, true, &mut hit, &mut occluded);
        }
        return (hit, occluded);
    }
    let (active_c, active_s) = (closest.tmax > 0.0, shadow.tmax > 0.0);
    let (inv_c, inv_s) = (safe_inverse(closest.dir), safe_inverse(shadow.dir));
    let (o_inv_c, o_inv_s) = (closest.origin * inv_c, shadow.origin * inv_s);
    let mut node = if active_c || active_s { 0 } else { nodes.len() };
    while node < nodes.len() {
        let n = &nodes[node];
        let (lo, hi) = (Vec3::from(n.lo), Vec3::from(n.hi));
        let enter_c = active_c && intersect_aabb(o_inv_c, inv_c, lo, hi, hit.t);
        let enter_s = active_s && !occluded && intersect_aabb(o_inv_s, inv_s, lo, hi, shadow.tmax);
        if !enter_c && !enter_s {
            node = n.skip as usize;
            continue;
        }
        let (first, count) = n.leaf_range();
        if count == 0 {
            node += 1;
            continue;
        }
        for i in first..first + count {
            test(i as usize, enter_c, enter_s, &mut hit, &mut occluded);
        }
        node = if occluded && !active_c { nodes.len() } else { n.skip as usize };
    }
    (hit, occluded)
}

/// Twin of GLSL `segment_ray`: the ray `segment_occluded` traces from p (normal np, on triangle
/// index tp) to q (normal nq, on triangle index tq), as (origin, unnormalised direction); the
/// segment ends at tmax = 1 - SEGMENT_EPSILON.
pub fn segment_ray(triangles: &[Triangle], p: Vec3, np: Vec3, tp: u32, q: Vec3, nq: Vec3, tq: u32) -> (Vec3, Vec3) {
    let d = q - p;
    let origin = offset_ray_origin(p, if d.dot(np) > 0.0 { np } else { -np }, &triangles[tp as usize]);
    let target = offset_ray_origin(q, if d.dot(nq) < 0.0 { nq } else { -nq }, &triangles[tq as usize]);
    (origin, target - origin)
}
