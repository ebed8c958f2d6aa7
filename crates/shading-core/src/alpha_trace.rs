//! Traversal of scenes with alpha-tested materials, the twins of glsl/shading_core/alpha_trace.glsl
//! (`bvh_traverse`, `bvh_alpha_pass`) and glsl/shading_core/alpha_trace_pair.glsl (`trace_pair`,
//! `trace_pair_alpha_pass`): the loops record candidate hits and the alpha tests run after them
//! ([`crate::alpha_pass`]). [`crate::bvh::bvh_traverse`] and
//! [`crate::bvh::trace_pair`] call these when given an [`AlphaScene`].

use glam::Vec3;

use restir_pt_interface::gpu_types::{BvhNode, Triangle};

use crate::alpha::AlphaScene;
use crate::alpha_pass::{alpha_pass_begin, alpha_pass_new, alpha_pass_record, alpha_pass_resolve, AlphaPass};
use crate::bvh::{intersect_aabb, intersect_triangle, safe_inverse, Hit, PairRay, NO_HIT};

/// One pass of the ray (o, d) over the BVH, boxes culled at the nearest opaque hit so far (so
/// every alpha-tested hit before it is met); with `any_hit` the pass ends at an opaque hit.
pub fn bvh_alpha_pass(nodes: &[BvhNode], triangles: &[Triangle], o: Vec3, d: Vec3, any_hit: bool, p: &mut AlphaPass) {
    let inv_d = safe_inverse(d);
    let o_inv_d = o * inv_d;
    let mut node = 0usize;
    while node < nodes.len() {
        let n = &nodes[node];
        if !intersect_aabb(o_inv_d, inv_d, Vec3::from(n.lo), Vec3::from(n.hi), p.opaque.t) {
            node = n.skip as usize;
            continue;
        }
        let (first, count) = n.leaf_range();
        if count == 0 {
            node += 1;
            continue;
        }
        for i in first..first + count {
            let tri = &triangles[i as usize];
            if let Some((t, bary)) = intersect_triangle(o, d, tri, p.opaque.t) {
                alpha_pass_record(p, i, tri.alpha_tested, t, bary);
            }
        }
        node = if any_hit && p.opaque.triangle != NO_HIT {
            nodes.len()
        } else {
            n.skip as usize
        };
    }
}

/// Twin of GLSL `bvh_traverse` with `SCENE_ALPHA`: the closest kept hit, or with `any_hit` some
/// kept hit (shadow rays); hits that `alpha_keeps` rejects do not count.
#[allow(clippy::too_many_arguments)]
pub fn bvh_traverse(nodes: &[BvhNode], triangles: &[Triangle], alpha: &AlphaScene, o: Vec3, d: Vec3, tmax: f32, any_hit: bool) -> Hit {
    let mut p = alpha_pass_new(tmax);
    loop {
        alpha_pass_begin(&mut p, tmax);
        bvh_alpha_pass(nodes, triangles, o, d, any_hit, &mut p);
        if let Some(hit) = alpha_pass_resolve(&mut p, alpha, triangles, o, d, any_hit) {
            return hit;
        }
    }
}

/// Tests triangle index `i` for the closest ray (if `enter_c`) and the shadow ray (if `enter_s`).
#[allow(clippy::too_many_arguments)]
fn alpha_pair_test(
    triangles: &[Triangle],
    i: u32,
    closest: &PairRay,
    shadow: &PairRay,
    enter_c: bool,
    enter_s: bool,
    c: &mut AlphaPass,
    s: &mut AlphaPass,
) {
    let tri = &triangles[i as usize];
    if enter_c {
        if let Some((t, bary)) = intersect_triangle(closest.origin, closest.dir, tri, c.opaque.t) {
            alpha_pass_record(c, i, tri.alpha_tested, t, bary);
        }
    }
    if enter_s {
        if let Some((t, bary)) = intersect_triangle(shadow.origin, shadow.dir, tri, s.opaque.t) {
            alpha_pass_record(s, i, tri.alpha_tested, t, bary);
        }
    }
}

/// One pass for the rays `open` (closest, shadow): over every triangle in index order with
/// `brute_force`, else over the BVH, culling each ray at its nearest opaque hit so far; the
/// shadow ray stops at an opaque hit.
#[allow(clippy::too_many_arguments)]
pub fn trace_pair_alpha_pass(
    nodes: &[BvhNode],
    triangles: &[Triangle],
    brute_force: bool,
    closest: &PairRay,
    shadow: &PairRay,
    open: (bool, bool),
    c: &mut AlphaPass,
    s: &mut AlphaPass,
) {
    let (open_c, open_s) = open;
    if brute_force {
        for i in 0..triangles.len() as u32 {
            let enter_s = open_s && s.opaque.triangle == NO_HIT;
            alpha_pair_test(triangles, i, closest, shadow, open_c, enter_s, c, s);
        }
        return;
    }
    let (inv_c, inv_s) = (safe_inverse(closest.dir), safe_inverse(shadow.dir));
    let (o_inv_c, o_inv_s) = (closest.origin * inv_c, shadow.origin * inv_s);
    let mut node = 0usize;
    while node < nodes.len() {
        let n = &nodes[node];
        let (lo, hi) = (Vec3::from(n.lo), Vec3::from(n.hi));
        let blocked = s.opaque.triangle != NO_HIT;
        let enter_c = open_c && intersect_aabb(o_inv_c, inv_c, lo, hi, c.opaque.t);
        let enter_s = open_s && !blocked && intersect_aabb(o_inv_s, inv_s, lo, hi, s.opaque.t);
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
            let enter_s_now = enter_s && s.opaque.triangle == NO_HIT;
            alpha_pair_test(triangles, i, closest, shadow, enter_c, enter_s_now, c, s);
        }
        node = if s.opaque.triangle != NO_HIT && !open_c {
            nodes.len()
        } else {
            n.skip as usize
        };
    }
}

/// Twin of GLSL `trace_pair` with `SCENE_ALPHA`: the closest kept hit of `closest` and whether
/// a kept hit blocks `shadow`, in passes over both rays until each is resolved.
pub fn trace_pair(
    nodes: &[BvhNode],
    triangles: &[Triangle],
    alpha: &AlphaScene,
    brute_force: bool,
    closest: PairRay,
    shadow: PairRay,
) -> (Hit, bool) {
    let mut c = alpha_pass_new(closest.tmax);
    let mut s = alpha_pass_new(shadow.tmax);
    let mut hit = c.opaque;
    let mut occluded = false;
    let (mut open_c, mut open_s) = (closest.tmax > 0.0, shadow.tmax > 0.0);
    while open_c || open_s {
        if open_c {
            alpha_pass_begin(&mut c, closest.tmax);
        }
        if open_s {
            alpha_pass_begin(&mut s, shadow.tmax);
        }
        trace_pair_alpha_pass(nodes, triangles, brute_force, &closest, &shadow, (open_c, open_s), &mut c, &mut s);
        if open_c {
            if let Some(h) = alpha_pass_resolve(&mut c, alpha, triangles, closest.origin, closest.dir, false) {
                hit = h;
                open_c = false;
            }
        }
        if open_s {
            if let Some(h) = alpha_pass_resolve(&mut s, alpha, triangles, shadow.origin, shadow.dir, true) {
                occluded = h.triangle != NO_HIT;
                open_s = false;
            }
        }
    }
    (hit, occluded)
}
