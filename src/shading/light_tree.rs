//! Light selection by likely contribution at the shading point: the descent of the light tree
//! (src/scene/light_tree.rs builds it) and the probabilities of the choices beside it. Twin of
//! glsl/light_tree.glsl; each function is named as in GLSL.

use glam::Vec3;

use crate::gpu_types::{LightNode, LIGHT_NODE_LEAF, LIGHT_NODE_TWO_SIDED, LIGHT_TREE_MAX_DEPTH, NO_EMITTER};
use crate::scene::Scene;

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
pub fn light_tree_walk(nodes: &[LightNode], p: Vec3, normal: Vec3, mode: Walk, mut trail: u32, mut u: f32) -> (u32, f32) {
    let mut value = if mode == Walk::Estimate { 0.0 } else { 1.0f32 };
    let mut node = 0usize;
    let mut reached = -1.0f32;
    for _ in 0..=LIGHT_TREE_MAX_DEPTH {
        let n = &nodes[node];
        if n.flags & LIGHT_NODE_LEAF != 0 {
            if mode == Walk::Estimate {
                value += if reached >= 0.0 {
                    reached
                } else {
                    light_node_importance(n, p, normal)
                };
            }
            return (n.child, value);
        }
        let first = light_node_importance(&nodes[node + 1], p, normal);
        let second = light_node_importance(&nodes[n.child as usize], p, normal);
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

/// The octahedral encoding of unit `d` in two 16-bit fixed-point coordinates (low, high), as
/// directional lights' emitter rows keep their direction.
pub fn octahedral_encode(d: Vec3) -> u32 {
    let mut f = glam::Vec2::new(d.x, d.y) / (d.x.abs() + d.y.abs() + d.z.abs());
    if d.z < 0.0 {
        let sign = glam::Vec2::new(if f.x >= 0.0 { 1.0 } else { -1.0 }, if f.y >= 0.0 { 1.0 } else { -1.0 });
        f = (glam::Vec2::ONE - glam::Vec2::new(f.y.abs(), f.x.abs())) * sign;
    }
    let q = ((f * 0.5 + 0.5).clamp(glam::Vec2::ZERO, glam::Vec2::ONE) * 65535.0).round();
    q.x as u32 | (q.y as u32) << 16
}

/// The unit direction of [`octahedral_encode`]'s `bits`. Twin of GLSL `octahedral_decode`.
pub fn octahedral_decode(bits: u32) -> Vec3 {
    let f = glam::Vec2::new((bits & 0xffff) as f32, (bits >> 16) as f32) * (2.0 / 65535.0) - 1.0;
    let mut v = Vec3::new(f.x, f.y, 1.0 - f.x.abs() - f.y.abs());
    let t = (-v.z).max(0.0);
    v.x += if v.x >= 0.0 { -t } else { t };
    v.y += if v.y >= 0.0 { -t } else { t };
    v.normalize()
}

/// What directional light `row` sends to a surface of unit `normal`, for choosing: E |cos θ|,
/// the cosine floored at 1e-3 so that no light is ever left out. Twin of GLSL
/// `directional_weight`.
pub fn directional_weight(scene: &Scene, row: u32, normal: Vec3) -> f32 {
    let e = &scene.emitters[row as usize];
    e.intensity * normal.dot(octahedral_decode(e.trail)).abs().max(1e-3)
}

/// The directional lights' summed [`directional_weight`]s. Twin of GLSL `directional_total`.
pub fn directional_total(scene: &Scene, normal: Vec3) -> f32 {
    let count = scene.emitters.len() as u32;
    (count - scene.directional_count..count).fold(0.0, |a, i| a + directional_weight(scene, i, normal))
}

/// The probability of choosing the tree rather than a directional light, from the tree's
/// [`Walk::Estimate`] and [`directional_total`]. Twin of GLSL `tree_share`.
pub fn tree_share(estimate: f32, total: f32) -> f32 {
    if estimate > 0.0 {
        estimate / (estimate + total)
    } else {
        0.0
    }
}

/// The probability that light sampling at `p` (unit `normal`) chooses the light of emitter row
/// `row` (discrete; the environment's share removed): the tree's [`tree_share`] times the
/// walk's, or the rest in proportion to [`directional_weight`]. Twin of GLSL `light_select_pmf`.
pub fn light_select_pmf(scene: &Scene, p: Vec3, normal: Vec3, row: u32) -> f32 {
    let n_dir = scene.directional_count;
    let count = scene.emitters.len() as u32;
    let has_tree = count > n_dir;
    let in_tree = row < count - n_dir;
    let total = if n_dir > 0 { directional_total(scene, normal) } else { 0.0 };
    let mut share = if has_tree { 1.0 } else { 0.0 };
    let mut walk = 1.0;
    let first_pass = if has_tree && n_dir > 0 { 0 } else { 1 };
    for pass in first_pass..2 {
        if pass == 1 && !in_tree {
            break;
        }
        let mode = if pass == 0 { Walk::Estimate } else { Walk::Trail };
        let (_, value) = light_tree_walk(&scene.light_nodes, p, normal, mode, scene.emitters[row as usize].trail, 0.0);
        if pass == 0 {
            share = tree_share(value, total);
        } else {
            walk = value;
        }
    }
    let pmf = if in_tree {
        share * walk
    } else {
        (1.0 - share) * (directional_weight(scene, row, normal) / total)
    };
    pmf * (1.0 - scene.env_select_prob)
}

/// The emitter row that light sampling at `p` (unit `normal`) draws with `u` in [0, 1)
/// ([`NO_EMITTER`] when no light can reach `p`) and its probability as [`light_select_pmf`]
/// gives it. Twin of GLSL `light_select`.
pub fn light_select(scene: &Scene, p: Vec3, normal: Vec3, u: f32) -> (u32, f32) {
    let n_dir = scene.directional_count;
    let count = scene.emitters.len() as u32;
    let has_tree = count > n_dir;
    let total = if n_dir > 0 { directional_total(scene, normal) } else { 0.0 };
    let mut share = if has_tree { 1.0f32 } else { 0.0 };
    let (mut row, mut pmf) = (NO_EMITTER, 0.0f32);
    let first_pass = if has_tree && n_dir > 0 { 0 } else { 1 };
    for pass in first_pass..2 {
        if pass == 1 && !(u < share) {
            break;
        }
        let mode = if pass == 0 { Walk::Estimate } else { Walk::Sample };
        let (r, value) = light_tree_walk(&scene.light_nodes, p, normal, mode, 0, (u / share).min(0.99999994));
        if pass == 0 {
            share = tree_share(value, total);
        } else {
            row = r;
            pmf = share * value;
        }
    }
    if !(u < share) && n_dir > 0 {
        let target = (u - share) / (1.0 - share) * total;
        let mut sum = 0.0;
        row = count - 1;
        for i in count - n_dir..count {
            sum += directional_weight(scene, i, normal);
            if target < sum {
                row = i;
                break;
            }
        }
        pmf = (1.0 - share) * (directional_weight(scene, row, normal) / total);
    }
    (row, pmf * (1.0 - scene.env_select_prob))
}
