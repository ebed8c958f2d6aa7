//! Binned-SAH BVH built on the CPU and flattened depth-first with skip links; its traversal twin
//! of glsl/shading_core/bvh.glsl is `restir_pt_shading_core::bvh`.

use glam::Vec3;

use restir_pt_interface::gpu_types::{BvhNode, Triangle, LEAF_COUNT_BITS, LEAF_COUNT_MASK};

const SAH_BINS: usize = 16;
const MAX_LEAF_TRIANGLES: usize = 4;
/// A leaf may hold up to this many triangles when SAH finds no cheaper split.
const MAX_SAH_LEAF_TRIANGLES: usize = 12;
/// Past this depth splits fall back to the object median, which bounds the recursion.
const SAH_MAX_DEPTH: usize = 40;
const _: () = assert!(MAX_SAH_LEAF_TRIANGLES as u32 <= LEAF_COUNT_MASK);

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
