//! Light selection by likely contribution at the shading point: the descent of the light tree
//! (crates/scene/src/light_tree.rs builds it) and the probability of its choice. Twin of
//! glsl/shading/light_tree.glsl; each function is named as in GLSL.

use glam::Vec3;

use restir_pt_interface::gpu_types::{LightNode, LIGHT_NODE_LEAF, LIGHT_NODE_TWO_SIDED, LIGHT_TREE_MAX_DEPTH, NO_EMITTER};
use restir_pt_scene::Scene;

/// pbrt-v4 `LightBounds::Importance`: intensity · cos θ' · |cos θ_i'| / d² for a node seen from
/// `p` with unit `normal`, θ' the smallest angle between the node's emission cone and the
/// direction to `p` over the node's bounding sphere, θ_i' the smallest angle between ±normal and
/// the directions to that sphere (a surface may transmit), d² clamped below by the sphere's
/// squared radius; 0 where no light below can reach `p`. Twin of GLSL `light_node_importance`.
pub fn light_node_importance(n: &LightNode, p: Vec3, normal: Vec3) -> f32 {
    let (lo, hi, axis) = (Vec3::from(n.lo), Vec3::from(n.hi), Vec3::from(n.axis));
    let half_diag = 0.5 * (hi - lo);
    let r2 = half_diag.dot(half_diag);
    let from_centre = p - 0.5 * (lo + hi);
    let d2 = from_centre.dot(from_centre);
    let d2_clamped = d2.max(r2);
    if !(d2_clamped > 0.0) {
        return 0.0;
    }
    let mut cos_w = if d2 > 0.0 {
        (axis.dot(from_centre) / d2.sqrt()).clamp(-1.0, 1.0)
    } else {
        1.0
    };
    if n.flags & LIGHT_NODE_TWO_SIDED != 0 {
        cos_w = cos_w.abs();
    }
    let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
    let sin_o = (1.0 - n.cos_theta_o * n.cos_theta_o).max(0.0).sqrt();
    let (mut cos_x, mut sin_x) = (1.0, 0.0);
    if cos_w < n.cos_theta_o {
        cos_x = cos_w * n.cos_theta_o + sin_w * sin_o;
        sin_x = sin_w * n.cos_theta_o - cos_w * sin_o;
    }
    let (mut cos_p, mut cos_i) = (1.0, 1.0);
    if d2 > r2 {
        let sin_b2 = r2 / d2;
        let cos_b = (1.0 - sin_b2).max(0.0).sqrt();
        let sin_b = sin_b2.sqrt();
        if cos_x < cos_b {
            cos_p = cos_x * cos_b + sin_x * sin_b;
        }
        let cos_n = (normal.dot(from_centre).abs() / d2.sqrt()).min(1.0);
        if cos_n < cos_b {
            cos_i = cos_n * cos_b + (1.0 - cos_n * cos_n).max(0.0).sqrt() * sin_b;
        }
    }
    if cos_p < n.cos_theta_e {
        return 0.0;
    }
    n.intensity * cos_p.max(0.0) * cos_i / d2_clamped
}

/// How [`light_tree_walk`] chooses a child (GLSL `WALK_SAMPLE`, `WALK_TRAIL`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Walk {
    /// By the uniform `u`, in proportion to the children's importance.
    Sample,
    /// Along the bit trail `trail` (bit d: the second child at depth d).
    Trail,
}

/// Descends `nodes` from the root at `p` to a child with probability proportional to its
/// [`light_node_importance`], by `u` in [0, 1) or along `trail`, and returns the emitter row of
/// the leaf reached ([`NO_EMITTER`] where no light below can reach `p`: then a probability of 0)
/// and the product of the branch probabilities (the same for sampling a light and following its
/// trail). Twin of GLSL `light_tree_walk`.
pub fn light_tree_walk(nodes: &[LightNode], p: Vec3, normal: Vec3, mode: Walk, mut trail: u32, mut u: f32) -> (u32, f32) {
    let mut pmf = 1.0f32;
    let mut node = 0usize;
    for _ in 0..=LIGHT_TREE_MAX_DEPTH {
        let n = &nodes[node];
        if n.flags & LIGHT_NODE_LEAF != 0 {
            return (n.child, pmf);
        }
        let first = light_node_importance(&nodes[node + 1], p, normal);
        let second = light_node_importance(&nodes[n.child as usize], p, normal);
        if !(first + second > 0.0) {
            return (NO_EMITTER, 0.0);
        }
        let p_first = first / (first + second);
        let take_second = match mode {
            Walk::Sample => u >= p_first,
            Walk::Trail => trail & 1 != 0,
        };
        if take_second {
            pmf *= 1.0 - p_first;
            u = ((u - p_first) / (1.0 - p_first)).min(0.99999994);
            node = n.child as usize;
        } else {
            pmf *= p_first;
            u = (u / p_first).min(0.99999994);
            node += 1;
        }
        trail >>= 1;
    }
    (NO_EMITTER, 0.0)
}

/// The emitter row of directional light `k` (`k` < `scene.directional_count`). Twin of GLSL
/// `directional_row`.
pub fn directional_row(scene: &Scene, k: u32) -> u32 {
    scene.emitters.len() as u32 - scene.directional_count + k
}

/// The probability that light sampling at `p` (unit `normal`) chooses the light of emitter row
/// `row`: for a light of the tree its walk's, the environment's share removed; 1 for a
/// directional light, which NEE takes at every vertex beside the drawn light
/// (`lights::sample_directional`). Twin of GLSL `light_select_pmf`.
pub fn light_select_pmf(scene: &Scene, p: Vec3, normal: Vec3, row: u32) -> f32 {
    if row >= scene.emitters.len() as u32 - scene.directional_count {
        return 1.0;
    }
    let (_, walk) = light_tree_walk(&scene.light_nodes, p, normal, Walk::Trail, scene.emitters[row as usize].trail, 0.0);
    walk * (1.0 - scene.env_select_prob)
}

/// The emitter row of the light tree that light sampling at `p` (unit `normal`) draws with `u`
/// in [0, 1) ([`NO_EMITTER`] when the tree is empty or none of its lights can reach `p`) and
/// its probability as [`light_select_pmf`] gives it. Twin of GLSL `light_select`.
pub fn light_select(scene: &Scene, p: Vec3, normal: Vec3, u: f32) -> (u32, f32) {
    if scene.emitters.len() as u32 == scene.directional_count {
        return (NO_EMITTER, 0.0);
    }
    let (row, walk) = light_tree_walk(&scene.light_nodes, p, normal, Walk::Sample, 0, u);
    (row, walk * (1.0 - scene.env_select_prob))
}
