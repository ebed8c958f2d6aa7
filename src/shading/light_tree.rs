//! Light selection by likely contribution at the shading point: the descent of the light tree
//! (src/scene/light_tree.rs builds it) and the probabilities of the choices beside it. Twin of
//! glsl/light_tree.glsl; each function is named as in GLSL.

use glam::Vec3;

use crate::gpu_types::{LightNode, LIGHT_NODE_LEAF, LIGHT_NODE_TWO_SIDED, LIGHT_TREE_MAX_DEPTH, NO_EMITTER};
use crate::scene::Scene;

/// pbrt-v4 `LightBounds::Importance` without a receiver normal: intensity · cos θ' / d² for a
/// node seen from `p`, θ' the smallest angle between the node's emission cone and the
/// direction to `p` over the node's bounding sphere, d² clamped below by that sphere's squared
/// radius; 0 where no light below can reach `p`. Twin of GLSL `light_node_importance`.
pub fn light_node_importance(n: &LightNode, p: Vec3) -> f32 {
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
    let mut cos_p = 1.0;
    if d2 > r2 {
        let sin_b2 = r2 / d2;
        let cos_b = (1.0 - sin_b2).max(0.0).sqrt();
        if cos_x < cos_b {
            cos_p = cos_x * cos_b + sin_x * sin_b2.sqrt();
        }
    }
    if cos_p < n.cos_theta_e {
        return 0.0;
    }
    n.intensity * cos_p.max(0.0) / d2_clamped
}

/// Descends `nodes` from the root at `p`, at each node to a child with probability proportional
/// to its [`light_node_importance`]: by `u` in [0, 1) when `sampling`, else along the bit trail
/// `trail` (bit d: the second child at depth d). Returns the emitter row of the leaf reached
/// ([`NO_EMITTER`] if no light can reach `p`) and the product of the branch probabilities; for
/// the same `p`, sampling a light and following its trail give the same product. Twin of GLSL
/// `light_tree_walk`.
pub fn light_tree_walk(nodes: &[LightNode], p: Vec3, sampling: bool, mut trail: u32, mut u: f32) -> (u32, f32) {
    let mut pmf = 1.0f32;
    let mut node = 0usize;
    for _ in 0..=LIGHT_TREE_MAX_DEPTH {
        let n = &nodes[node];
        if n.flags & LIGHT_NODE_LEAF != 0 {
            return (n.child, pmf);
        }
        let first = light_node_importance(&nodes[node + 1], p);
        let second = light_node_importance(&nodes[n.child as usize], p);
        if !(first + second > 0.0) {
            return (NO_EMITTER, 0.0);
        }
        let p_first = first / (first + second);
        let take_second = if sampling { u >= p_first } else { trail & 1 != 0 };
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

/// The choices beside the environment, each as likely as the others: every directional light,
/// and the tree when it holds a light. Twin of GLSL `light_groups`.
pub fn light_groups(scene: &Scene) -> u32 {
    scene.directional_count + (scene.emitters.len() as u32 > scene.directional_count) as u32
}

/// The probability that light sampling at `p` chooses the light of emitter row `row` (discrete;
/// the environment's share excluded): its group's, times its path's through the tree. Twin of
/// GLSL `light_select_pmf`.
pub fn light_select_pmf(scene: &Scene, p: Vec3, row: u32) -> f32 {
    let mut pmf = 1.0;
    if row < scene.emitters.len() as u32 - scene.directional_count {
        pmf = light_tree_walk(&scene.light_nodes, p, false, scene.emitters[row as usize].trail, 0.0).1;
    }
    pmf * ((1.0 - scene.env_select_prob) / light_groups(scene) as f32)
}

/// The emitter row and selection probability (as [`light_select_pmf`]) that light sampling at
/// `p` draws with `u` in [0, 1): a group by `u`, then, in the tree, a leaf by what is left of
/// `u`. [`NO_EMITTER`] and 0 when no light can reach `p`. Twin of GLSL `light_select`.
pub fn light_select(scene: &Scene, p: Vec3, u: f32) -> (u32, f32) {
    let groups = light_groups(scene);
    let scaled = u * groups as f32;
    let group = (scaled as u32).min(groups - 1);
    let n_dir = scene.directional_count;
    let (row, pmf) = if group < n_dir {
        (scene.emitters.len() as u32 - n_dir + group, 1.0)
    } else {
        light_tree_walk(&scene.light_nodes, p, true, 0, (scaled - group as f32).min(0.99999994))
    };
    (row, pmf * ((1.0 - scene.env_select_prob) / groups as f32))
}
