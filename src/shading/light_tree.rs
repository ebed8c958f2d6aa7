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

/// How [`light_tree_walk`] chooses a child (GLSL `WALK_SAMPLE`, `WALK_TRAIL`, `WALK_ESTIMATE`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Walk {
    /// By the uniform `u`, in proportion to the children's importance.
    Sample,
    /// Along the bit trail `trail` (bit d: the second child at depth d).
    Trail,
    /// To the more important child, summing the importance of the others.
    Estimate,
}

/// Descends `nodes` from the root at `p`. [`Walk::Sample`] and [`Walk::Trail`] go to a child
/// with probability proportional to its [`light_node_importance`] and return the product of the
/// branch probabilities (the same for sampling a light and following its trail);
/// [`Walk::Estimate`] goes to the more important child and returns the importance of the leaf
/// reached plus that of every child passed by, a deterministic estimate of what the tree's
/// lights send to `p`. Also returns the emitter row of the leaf reached ([`NO_EMITTER`] where no
/// light below can reach `p`: then a probability of 0). Twin of GLSL `light_tree_walk`.
pub fn light_tree_walk(nodes: &[LightNode], p: Vec3, mode: Walk, mut trail: u32, mut u: f32) -> (u32, f32) {
    let mut value = if mode == Walk::Estimate { 0.0 } else { 1.0f32 };
    let mut node = 0usize;
    let mut reached = -1.0f32;
    for _ in 0..=LIGHT_TREE_MAX_DEPTH {
        let n = &nodes[node];
        if n.flags & LIGHT_NODE_LEAF != 0 {
            if mode == Walk::Estimate {
                value += if reached >= 0.0 { reached } else { light_node_importance(n, p) };
            }
            return (n.child, value);
        }
        let first = light_node_importance(&nodes[node + 1], p);
        let second = light_node_importance(&nodes[n.child as usize], p);
        if !(first + second > 0.0) {
            return (NO_EMITTER, if mode == Walk::Estimate { value } else { 0.0 });
        }
        let p_first = first / (first + second);
        let take_second = match mode {
            Walk::Sample => u >= p_first,
            Walk::Trail => trail & 1 != 0,
            Walk::Estimate => second > first,
        };
        if mode == Walk::Estimate {
            value += if take_second { first } else { second };
        }
        if take_second {
            if mode != Walk::Estimate {
                value *= 1.0 - p_first;
            }
            u = ((u - p_first) / (1.0 - p_first)).min(0.99999994);
            node = n.child as usize;
        } else {
            if mode != Walk::Estimate {
                value *= p_first;
            }
            u = (u / p_first).min(0.99999994);
            node += 1;
        }
        reached = if take_second { second } else { first };
        trail >>= 1;
    }
    (NO_EMITTER, 0.0)
}

/// The directional lights' summed irradiance (luminance), in row order (the light tree's
/// header holds it for the kernels). Twin of GLSL `directional_total`.
pub fn directional_total(scene: &Scene) -> f32 {
    let n = scene.emitters.len();
    scene.emitters[n - scene.directional_count as usize..]
        .iter()
        .fold(0.0, |a, e| a + e.intensity)
}

/// The probability that light sampling at `p` chooses the light of emitter row `row` (discrete;
/// the environment's share removed). The tree is chosen rather than a directional light with
/// probability (its [`Walk::Estimate`]) / (that + [`directional_total`]), a directional light
/// in proportion to its irradiance. Twin of GLSL `light_select_pmf`.
pub fn light_select_pmf(scene: &Scene, p: Vec3, row: u32) -> f32 {
    let n_dir = scene.directional_count;
    let count = scene.emitters.len() as u32;
    let has_tree = count > n_dir;
    let in_tree = row < count - n_dir;
    let mut share = if has_tree { 1.0 } else { 0.0 };
    let mut walk = 1.0;
    let first_pass = if has_tree && n_dir > 0 { 0 } else { 1 };
    for pass in first_pass..2 {
        if pass == 1 && !in_tree {
            break;
        }
        let mode = if pass == 0 { Walk::Estimate } else { Walk::Trail };
        let (_, value) = light_tree_walk(&scene.light_nodes, p, mode, scene.emitters[row as usize].trail, 0.0);
        if pass == 0 {
            share = value / (value + directional_total(scene));
        } else {
            walk = value;
        }
    }
    let pmf = if in_tree {
        share * walk
    } else {
        (1.0 - share) * (scene.emitters[row as usize].intensity / directional_total(scene))
    };
    pmf * (1.0 - scene.env_select_prob)
}

/// The emitter row that light sampling at `p` draws with `u` in [0, 1) ([`NO_EMITTER`] when no
/// light can reach `p`) and its probability as [`light_select_pmf`] gives it. Twin of GLSL
/// `light_select`.
pub fn light_select(scene: &Scene, p: Vec3, u: f32) -> (u32, f32) {
    let n_dir = scene.directional_count;
    let count = scene.emitters.len() as u32;
    let has_tree = count > n_dir;
    let mut share = if has_tree { 1.0f32 } else { 0.0 };
    let (mut row, mut pmf) = (NO_EMITTER, 0.0f32);
    let first_pass = if has_tree && n_dir > 0 { 0 } else { 1 };
    for pass in first_pass..2 {
        if pass == 1 && !(u < share) {
            break;
        }
        let mode = if pass == 0 { Walk::Estimate } else { Walk::Sample };
        let (r, value) = light_tree_walk(&scene.light_nodes, p, mode, 0, (u / share).min(0.99999994));
        if pass == 0 {
            share = value / (value + directional_total(scene));
        } else {
            row = r;
            pmf = share * value;
        }
    }
    if !(u < share) {
        let total = directional_total(scene);
        let target = (u - share) / (1.0 - share) * total;
        let mut sum = 0.0;
        row = count - 1;
        for i in count - n_dir..count {
            sum += scene.emitters[i as usize].intensity;
            if target < sum {
                row = i;
                break;
            }
        }
        pmf = (1.0 - share) * (scene.emitters[row as usize].intensity / total);
    }
    (row, pmf * (1.0 - scene.env_select_prob))
}
