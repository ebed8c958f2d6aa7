//! The light tree: a bounding-volume hierarchy over the emissive triangles and the point and spot
//! lights that next-event estimation descends to choose a light by its likely contribution at the
//! shading point rather than by its power alone (pbrt-v4 `BVHLightSampler`; Conty Estevez and
//! Kulla, "Importance Sampling of Many Lights with Adaptive Tree Splitting", 2018). Built here on
//! the host, flattened depth first into [`LightNode`]s; glsl/shading/light_tree.glsl and its twin
//! crates/shading/src/light_tree.rs walk it.

use glam::{Quat, Vec3};

use restir_pt_interface::gpu_types::{LightNode, LIGHT_NODE_LEAF, LIGHT_NODE_TWO_SIDED, LIGHT_TREE_MAX_DEPTH};

/// The spatial and directional bounds of one light or a group of lights (pbrt-v4 `LightBounds`).
/// Directions are unit vectors in scene coordinates; `intensity` is luminance in W/sr.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightBounds {
    /// Lower corner of the lights' bounds.
    pub lo: Vec3,
    /// Upper corner of the lights' bounds.
    pub hi: Vec3,
    /// Sum of the lights' largest radiant intensities.
    pub intensity: f32,
    /// Axis of the cone that holds the lights' normals (or spot axes).
    pub axis: Vec3,
    /// Cosine of that cone's half-angle θ_o.
    pub cos_theta_o: f32,
    /// Cosine of θ_e, how far beyond the normal cone the lights still emit.
    pub cos_theta_e: f32,
    /// Whether some light emits on both sides.
    pub two_sided: bool,
}

impl LightBounds {
    /// An emissive triangle with vertices `v` emitting `luminance` (cd/m²) from its front face
    /// (counter-clockwise), or both faces when `two_sided`: a cosine lobe about its normal,
    /// largest radiant intensity L·A.
    pub fn triangle(v: [Vec3; 3], luminance: f32, two_sided: bool) -> Self {
        let n2 = (v[1] - v[0]).cross(v[2] - v[0]);
        Self {
            lo: v[0].min(v[1]).min(v[2]),
            hi: v[0].max(v[1]).max(v[2]),
            intensity: luminance * 0.5 * n2.length(),
            axis: n2.normalize_or(Vec3::Z),
            cos_theta_o: 1.0,
            cos_theta_e: 0.0,
            two_sided,
        }
    }

    /// A point light (`cos_outer` -1) or a spot light of luminous intensity `intensity` (cd)
    /// at `position` shining along `direction` within the cone of cosine `cos_outer`.
    pub fn punctual(position: Vec3, direction: Vec3, intensity: f32, cos_outer: f32) -> Self {
        let spot = cos_outer > -1.0;
        Self {
            lo: position,
            hi: position,
            intensity,
            axis: if spot { direction } else { Vec3::Z },
            cos_theta_o: cos_outer,
            // A spot emits nothing past its outer cone: no spread beyond θ_o.
            cos_theta_e: if spot { 1.0 } else { 0.0 },
            two_sided: false,
        }
    }

    /// The bounds of both groups (pbrt-v4 `Union(LightBounds, LightBounds)`).
    pub fn union(&self, b: &Self) -> Self {
        let (axis, cos_theta_o) = cone_union(self.axis, self.cos_theta_o, b.axis, b.cos_theta_o);
        Self {
            lo: self.lo.min(b.lo),
            hi: self.hi.max(b.hi),
            intensity: self.intensity + b.intensity,
            axis,
            cos_theta_o,
            cos_theta_e: self.cos_theta_e.min(b.cos_theta_e),
            two_sided: self.two_sided || b.two_sided,
        }
    }

    fn centroid(&self) -> Vec3 {
        0.5 * (self.lo + self.hi)
    }

    /// The split cost of a group (pbrt-v4 `BVHLightSampler::EvaluateCost`): intensity times
    /// the solid-angle measure of the directions it may emit in times its surface area, the
    /// longest side's share `kr` keeping splits from producing thin slabs.
    fn cost(&self, kr: f32) -> f64 {
        let theta_o = self.cos_theta_o.clamp(-1.0, 1.0).acos() as f64;
        let theta_e = self.cos_theta_e.clamp(-1.0, 1.0).acos() as f64;
        let theta_w = (theta_o + theta_e).min(std::f64::consts::PI);
        let (sin_o, cos_o) = theta_o.sin_cos();
        let pi = std::f64::consts::PI;
        let m_omega =
            2.0 * pi * (1.0 - cos_o) + pi / 2.0 * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o + cos_o);
        let d = (self.hi - self.lo).as_dvec3();
        let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
        self.intensity as f64 * m_omega * area.max(0.0) * kr as f64
    }

    /// The node that holds these bounds; `child` and `flags` as [`LightNode`] says.
    fn node(&self, child: u32, leaf: bool) -> LightNode {
        LightNode {
            lo: self.lo.into(),
            intensity: self.intensity,
            hi: self.hi.into(),
            cos_theta_o: self.cos_theta_o,
            axis: self.axis.into(),
            cos_theta_e: self.cos_theta_e,
            child,
            flags: if leaf { LIGHT_NODE_LEAF } else { 0 } | if self.two_sided { LIGHT_NODE_TWO_SIDED } else { 0 },
            pad: [0; 2],
        }
    }
}

/// The smallest cone (axis, cosine of its half-angle) around both cones (pbrt-v4
/// `DirectionCone::Union`).
fn cone_union(a: Vec3, cos_a: f32, b: Vec3, cos_b: f32) -> (Vec3, f32) {
    use std::f32::consts::PI;
    let theta_a = cos_a.clamp(-1.0, 1.0).acos();
    let theta_b = cos_b.clamp(-1.0, 1.0).acos();
    let theta_d = a.dot(b).clamp(-1.0, 1.0).acos();
    if (theta_d + theta_b).min(PI) <= theta_a {
        return (a, cos_a);
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return (b, cos_b);
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    let axis = a.cross(b);
    if theta_o >= PI || axis.length_squared() < 1e-12 {
        return (a, -1.0);
    }
    let rotated = Quat::from_axis_angle(axis.normalize(), theta_o - theta_a) * a;
    (rotated.normalize(), theta_o.cos())
}

/// A flattened light tree and where each light ended up.
#[derive(Debug, Clone, Default)]
pub struct LightTree {
    /// Depth first, the root first; empty when there are no lights.
    pub nodes: Vec<LightNode>,
    /// Per light (the order given to [`LightTree::build`]): its bit trail, bit d set where the
    /// path to its leaf takes the second child at depth d.
    pub trails: Vec<u32>,
    /// Per light: the index of its leaf in `nodes`.
    pub leaves: Vec<u32>,
}

/// Buckets per axis of the split search (pbrt-v4 uses 12).
const BUCKETS: usize = 12;

impl LightTree {
    /// Builds the tree over `lights` (light i becomes the leaf whose `child` is i), splitting
    /// each group where the summed [`LightBounds`] cost of the two halves is least, over
    /// 12 centroid buckets on each axis. At most [`LIGHT_TREE_MAX_DEPTH`] deep: near
    /// that depth groups are halved in centroid order.
    pub fn build(lights: &[LightBounds]) -> Self {
        let mut tree = Self {
            nodes: Vec::with_capacity(2 * lights.len()),
            trails: vec![0; lights.len()],
            leaves: vec![0; lights.len()],
        };
        if !lights.is_empty() {
            let mut order: Vec<u32> = (0..lights.len() as u32).collect();
            tree.build_node(lights, &mut order, 0, 0);
        }
        tree
    }

    fn build_node(&mut self, lights: &[LightBounds], group: &mut [u32], depth: usize, trail: u32) -> LightBounds {
        if let [only] = group {
            let b = lights[*only as usize];
            self.trails[*only as usize] = trail;
            self.leaves[*only as usize] = self.nodes.len() as u32;
            self.nodes.push(b.node(*only, true));
            return b;
        }
        let levels_left = LIGHT_TREE_MAX_DEPTH - depth;
        let balanced = (group.len() as u64).next_power_of_two().trailing_zeros() as usize + 1 >= levels_left;
        let mid = if balanced { None } else { split_by_cost(lights, group) };
        let mid = mid.unwrap_or_else(|| halve(lights, group));
        let at = self.nodes.len();
        self.nodes.push(LightNode::default());
        let (left, right) = group.split_at_mut(mid);
        let a = self.build_node(lights, left, depth + 1, trail);
        let second = self.nodes.len() as u32;
        let b = self.build_node(lights, right, depth + 1, trail | 1 << depth);
        let bounds = a.union(&b);
        self.nodes[at] = bounds.node(second, false);
        bounds
    }
}

/// Sorts `group` by centroid along its bounds' longest axis and returns the middle.
fn halve(lights: &[LightBounds], group: &mut [u32]) -> usize {
    let (lo, hi) = centroid_range(lights, group);
    let axis = (hi - lo).max_position();
    group.sort_by(|&a, &b| lights[a as usize].centroid()[axis].total_cmp(&lights[b as usize].centroid()[axis]));
    group.len() / 2
}

fn centroid_range(lights: &[LightBounds], group: &[u32]) -> (Vec3, Vec3) {
    group.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &i| {
        let c = lights[i as usize].centroid();
        (lo.min(c), hi.max(c))
    })
}

fn union_of(lights: &[LightBounds], group: impl Iterator<Item = u32>) -> Option<LightBounds> {
    group.map(|i| lights[i as usize]).reduce(|a, b| a.union(&b))
}

/// The cheapest bucket split of `group` (reordered so that the first returned-count lights
/// form the first half), or None when every centroid coincides.
fn split_by_cost(lights: &[LightBounds], group: &mut [u32]) -> Option<usize> {
    let (lo, hi) = centroid_range(lights, group);
    let extent = hi - lo;
    let whole = union_of(lights, group.iter().copied())?;
    let diag = whole.hi - whole.lo;
    let bucket_of = |i: u32, axis: usize| {
        let t = (lights[i as usize].centroid()[axis] - lo[axis]) / extent[axis];
        ((t * BUCKETS as f32) as usize).min(BUCKETS - 1)
    };
    let mut best: Option<(f64, usize, usize)> = None;
    for axis in 0..3 {
        if !(extent[axis] > 0.0) {
            continue;
        }
        let kr = diag.max_element() / diag[axis].max(f32::MIN_POSITIVE);
        let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
        for &i in group.iter() {
            let k = bucket_of(i, axis);
            let b = lights[i as usize];
            buckets[k] = Some(buckets[k].map_or(b, |u| u.union(&b)));
        }
        for split in 1..BUCKETS {
            let below = buckets[..split].iter().flatten().copied().reduce(|a, b| a.union(&b));
            let above = buckets[split..].iter().flatten().copied().reduce(|a, b| a.union(&b));
            if let (Some(a), Some(b)) = (below, above) {
                let cost = a.cost(kr) + b.cost(kr);
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, split));
                }
            }
        }
    }
    let (_, axis, split) = best?;
    let (mut first, mut second): (Vec<u32>, Vec<u32>) = group.iter().partition(|&&i| bucket_of(i, axis) < split);
    let mid = first.len();
    first.append(&mut second);
    group.copy_from_slice(&first);
    Some(mid)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cone_union_holds_both_cones() {
        let (a, b) = (Vec3::X, Vec3::Y);
        let (axis, cos) = cone_union(a, 0.9, b, 1.0);
        for d in [a, b] {
            assert!(axis.dot(d) >= cos - 1e-5, "{axis} {cos} misses {d}");
        }
        assert_eq!(cone_union(a, 1.0, -a, 1.0).1, -1.0);
    }

    #[test]
    fn every_light_has_one_leaf_and_its_trail_leads_there() {
        let lights: Vec<LightBounds> = (0..300)
            .map(|i| {
                let p = Vec3::new((i * 37 % 101) as f32, (i * 17 % 13) as f32, (i % 7) as f32);
                LightBounds::punctual(p, Vec3::Z, 1.0 + (i % 5) as f32, -1.0)
            })
            .collect();
        let tree = LightTree::build(&lights);
        assert_eq!(tree.nodes.len(), 2 * lights.len() - 1);
        for (i, (&trail, &leaf)) in tree.trails.iter().zip(&tree.leaves).enumerate() {
            let (mut node, mut bits) = (0usize, trail);
            while !tree.nodes[node].is_leaf() {
                node = if bits & 1 == 0 { node + 1 } else { tree.nodes[node].child as usize };
                bits >>= 1;
            }
            assert_eq!((node as u32, tree.nodes[node].child), (leaf, i as u32));
        }
    }
}
