//! Binned-SAH BVH built on the CPU and flattened depth-first with skip links, plus the stackless
//! traversal twin of glsl/bvh.glsl used as the oracle for GPU hits.

use glam::{Vec2, Vec3};

use crate::gpu_types::{BvhNode, Triangle, LEAF_COUNT_BITS, LEAF_COUNT_MASK};
use crate::shading::alpha::AlphaScene;
use crate::shading::ray_offset::offset_ray_origin;

/// The triangle index of a miss (and of an escaped path vertex); shared with glsl/bvh.glsl.
pub const NO_HIT: u32 = u32::MAX;
const SAH_BINS: usize = 16;
const MAX_LEAF_TRIANGLES: usize = 4;
/// A leaf may hold up to this many triangles when SAH finds no cheaper split.
const MAX_SAH_LEAF_TRIANGLES: usize = 12;
/// Past this depth splits fall back to the object median, which bounds the recursion.
const SAH_MAX_DEPTH: usize = 40;
const _: () = assert!(MAX_SAH_LEAF_TRIANGLES as u32 <= LEAF_COUNT_MASK);

/// A ray's hit (twin of GLSL `Hit`, glsl/bvh.glsl).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit: distance along the ray in units of |d| (scene units for a unit d).
    pub t: f32,
    /// Index of the triangle hit (in the scene's BVH leaf order), or [`NO_HIT`].
    pub triangle: u32,
    /// Barycentrics (b1, b2) of the hit on the triangle, weights of vertices 1 and 2.
    pub bary: Vec2,
}

#[derive(Clone, Copy)]
struct Aabb {
    lo: Vec3,
    hi: Vec3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        lo: Vec3::splat(f32::INFINITY),
        hi: Vec3::splat(f32::NEG_INFINITY),
    };
    fn grow(&mut self, p: Vec3) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }
    fn merge(&mut self, o: &Aabb) {
        self.lo = self.lo.min(o.lo);
        self.hi = self.hi.max(o.hi);
    }
    fn half_area(&self) -> f32 {
        let d = (self.hi - self.lo).max(Vec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// A BVH over `triangles`, which the build reorders so that leaves index them contiguously.
pub struct Bvh {
    /// The nodes in depth-first order with skip links (see [`BvhNode`]); node 0 is the root.
    /// Leaves index triangles in the reordered sequence `order` describes.
    pub nodes: Vec<BvhNode>,
    /// `order[i]` is the input index of the triangle now at position i.
    pub order: Vec<u32>,
}

struct Builder<'a> {
    bounds: Vec<Aabb>,
    centroids: Vec<Vec3>,
    indices: &'a mut [u32],
    nodes: Vec<BvhNode>,
}

impl Bvh {
    /// Builds the BVH over `triangles` with the binned surface area heuristic (16 bins; pbrt-v4
    /// `BVHAggregate` with SAH), falling back to the object median past depth 40. The input is
    /// left as it is: the caller reorders its triangles by `order`. An empty input gives one
    /// empty leaf.
    pub fn build(triangles: &[Triangle]) -> Bvh {
        let bounds: Vec<Aabb> = triangles
            .iter()
            .map(|t| {
                let mut b = Aabb::EMPTY;
                t.vertices().iter().for_each(|&v| b.grow(v));
                b
            })
            .collect();
        let centroids = bounds.iter().map(|b| 0.5 * (b.lo + b.hi)).collect();
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let mut builder = Builder {
            bounds,
            centroids,
            indices: &mut order,
            nodes: Vec::with_capacity(2 * triangles.len()),
        };
        builder.build(0, triangles.len(), 0);
        let nodes = builder.nodes;
        Bvh { nodes, order }
    }
}

impl Builder<'_> {
    fn range_bounds(&self, start: usize, end: usize) -> (Aabb, Aabb) {
        let mut b = Aabb::EMPTY;
        let mut c = Aabb::EMPTY;
        for &i in &self.indices[start..end] {
            b.merge(&self.bounds[i as usize]);
            c.grow(self.centroids[i as usize]);
        }
        (b, c)
    }

    fn build(&mut self, start: usize, end: usize, depth: usize) {
        let (bounds, centroid_bounds) = self.range_bounds(start, end);
        let node_index = self.nodes.len();
        let count = end - start;
        let leaf = (start as u32) << LEAF_COUNT_BITS | count as u32;
        self.nodes.push(BvhNode {
            lo: bounds.lo.into(),
            hi: bounds.hi.into(),
            skip: 0,
            leaf,
        });
        if count > MAX_LEAF_TRIANGLES {
            let split = if depth < SAH_MAX_DEPTH {
                self.sah_split(start, end, &bounds, &centroid_bounds)
            } else {
                None
            };
            let mid = match split {
                Some(mid) => Some(mid),
                None if count > MAX_SAH_LEAF_TRIANGLES || depth >= SAH_MAX_DEPTH => Some(self.median_split(start, end, &centroid_bounds)),
                None => None,
            };
            if let Some(mid) = mid {
                self.build(start, mid, depth + 1);
                self.build(mid, end, depth + 1);
                self.nodes[node_index].leaf = 0;
            }
        }
        // The subtree is complete: whatever comes next is where a miss (or a finished leaf) goes.
        self.nodes[node_index].skip = self.nodes.len() as u32;
    }

    /// Partitions by the cheapest of SAH_BINS bins per axis; `None` if a leaf is cheaper.
    fn sah_split(&mut self, start: usize, end: usize, bounds: &Aabb, cb: &Aabb) -> Option<usize> {
        let extent = cb.hi - cb.lo;
        let mut best: Option<(f32, usize, usize)> = None;
        for axis in 0..3 {
            if !(extent[axis] > 0.0) {
                continue;
            }
            let scale = SAH_BINS as f32 / extent[axis];
            let bin_of = |c: Vec3| (((c[axis] - cb.lo[axis]) * scale) as usize).min(SAH_BINS - 1);
            let mut bins = [(Aabb::EMPTY, 0usize); SAH_BINS];
            for &i in &self.indices[start..end] {
                let b = &mut bins[bin_of(self.centroids[i as usize])];
                b.0.merge(&self.bounds[i as usize]);
                b.1 += 1;
            }
            let mut right_cost = [0.0f32; SAH_BINS];
            let (mut acc, mut n) = (Aabb::EMPTY, 0);
            for k in (1..SAH_BINS).rev() {
                acc.merge(&bins[k].0);
                n += bins[k].1;
                right_cost[k] = if n > 0 { acc.half_area() * n as f32 } else { 0.0 };
            }
            let (mut acc, mut n) = (Aabb::EMPTY, 0);
            for k in 0..SAH_BINS - 1 {
                acc.merge(&bins[k].0);
                n += bins[k].1;
                if n == 0 || n == end - start {
                    continue;
                }
                let cost = acc.half_area() * n as f32 + right_cost[k + 1];
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, k));
                }
            }
        }
        let (cost, axis, k) = best?;
        // Traversal costs about one triangle test per node visit.
        let leaf_cost = bounds.half_area() * (end - start) as f32;
        if cost + bounds.half_area() >= leaf_cost && end - start <= MAX_SAH_LEAF_TRIANGLES {
            return None;
        }
        let scale = SAH_BINS as f32 / extent[axis];
        let (lo, centroids) = (cb.lo[axis], &self.centroids);
        let slice = &mut self.indices[start..end];
        let mut left = 0;
        for j in 0..slice.len() {
            let bin = (((centroids[slice[j] as usize][axis] - lo) * scale) as usize).min(SAH_BINS - 1);
            if bin <= k {
                slice.swap(left, j);
                left += 1;
            }
        }
        Some(start + left)
    }

    fn median_split(&mut self, start: usize, end: usize, cb: &Aabb) -> usize {
        let axis = (cb.hi - cb.lo).max_position();
        let centroids = &self.centroids;
        let mid = (start + end) / 2;
        self.indices[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
        });
        mid
    }
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
/// ([`crate::scene::alpha_trace::bvh_traverse`]).
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
        return crate::scene::alpha_trace::bvh_traverse(nodes, triangles, alpha, o, d, tmax, any_hit);
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
/// [`crate::scene::Scene::alpha`] honours alpha modes).
pub fn trace_closest(nodes: &[BvhNode], triangles: &[Triangle], o: Vec3, d: Vec3, tmax: f32) -> Hit {
    bvh_traverse(nodes, triangles, None, o, d, tmax, false)
}

/// Whether anything blocks the ray (o, d) before tmax, every surface opaque.
pub fn trace_occluded(nodes: &[BvhNode], triangles: &[Triangle], o: Vec3, d: Vec3, tmax: f32) -> bool {
    bvh_traverse(nodes, triangles, None, o, d, tmax, true).triangle != NO_HIT
}

/// Segment tests stop this fraction short of their (offset) end point.
pub const SEGMENT_EPSILON: f32 = 1e-4;

/// Whether anything blocks the segment between surface points p (normal np, on triangle index
/// tp) and q (normal nq, on triangle index tq): the ray of `segment_ray`, traced (the kernels
/// trace it inside `visibility_ray` of glsl/shift_vertex.glsl). Both ends are offset off their
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

/// Twin of GLSL `trace_pair` (glsl/trace_pair.glsl): the closest hit of `closest` and whether
/// anything blocks `shadow`, in one traversal of the BVH (or, with `brute_force`, one pass over
/// every triangle in index order, the closest hit being the first of equal distances). The BVH
/// form tests each ray against the same triangles in the same order as `bvh_traverse`, so its
/// results equal `trace_closest` and `trace_occluded` bit for bit. With `alpha` (`SCENE_ALPHA`)
/// each ray skips the hits `alpha_keeps` rejects for it ([`crate::scene::alpha_trace::trace_pair`]).
pub fn trace_pair(
    nodes: &[BvhNode],
    triangles: &[Triangle],
    alpha: Option<&AlphaScene>,
    brute_force: bool,
    closest: PairRay,
    shadow: PairRay,
) -> (Hit, bool) {
    if let Some(alpha) = alpha {
        return crate::scene::alpha_trace::trace_pair(nodes, triangles, alpha, brute_force, closest, shadow);
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
