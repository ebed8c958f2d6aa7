//! Initial candidates of ReSTIR PT: one traced path from a primary hit offers every prefix that
//! ends on a light, by NEE at a vertex (the drawn light and every directional light, each a
//! technique of its own) or by a BSDF-sampled hit, each weighted by the balance
//! heuristic of its end technique (`end_mis_weight`), to a streaming `Resampler`. Twin of
//! glsl/shading/candidates.glsl, which the initial pass runs; docs/restir.md describes the pass.

use glam::Vec3;

use restir_pt_interface::gpu_types::Material;
use restir_pt_interface::shader_interface::{RR_MAX_SURVIVAL, RR_START_DEPTH};
use restir_pt_scene::Scene;

use crate::bsdf::{bsdf_eval_pdf, LOBE_DELTA, LOBE_NONE};
use crate::gris::{resampler_offer, target_function, Resampler};
use crate::path_record::PathRecord;
use crate::rng::{rng_uniform4, STREAM_DIRECTIONAL, STREAM_RESAMPLE};
use crate::sampling::balance_heuristic;
use crate::shift::{
    bsdf_vertex, end_emission, end_mis_weight, nee_vertex, record_path, vertex_is_escaped, vertex_is_punctual, vertex_shading, visible,
    Path, ShiftParams, Vertex,
};

/// What the kernels count while streaming candidates (the pass statistics).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CandidateCounts {
    /// Candidates whose resampling weight was not finite, and so not offered.
    pub nonfinite_weights: u32,
    /// Chosen candidates that could not be recorded (the result is then empty).
    pub candidates_dropped: u32,
}

/// A candidate of the path being traced: its first `count` vertices, the last replaced by the
/// NEE light vertex `light` when `nee_end`.
#[derive(Debug, Clone, Copy)]
struct TracedCandidate {
    count: usize,
    nee_end: bool,
    nee_directional: u32,
    light: Vertex,
    nee_weight: Vec3,
    end_weight: f32,
    contribution: Vec3,
}

/// Offers a candidate of contribution f (RGB) with weight p̂(f) `scale` (its unbiased
/// contribution weight in primary sample space is 1; `scale` is the MIS weight 1/N among N
/// traced paths); true if the resampler chose it.
fn offer_candidate(s: &mut Resampler<PathRecord>, counts: &mut CandidateCounts, contribution: Vec3, scale: f32, u: f32) -> bool {
    let target = target_function(contribution);
    let w = target * scale;
    if !w.is_finite() {
        counts.nonfinite_weights += 1;
        return false;
    }
    w > 0.0 && resampler_offer(s, contribution, target, w, u)
}

/// Records the chosen candidate `c` of the finished path `p` as the resampler's sample; a path
/// that cannot be recorded (rounding) empties the result and is counted.
fn record_chosen(
    scene: &Scene,
    s: &mut Resampler<PathRecord>,
    counts: &mut CandidateCounts,
    mut p: Path,
    c: &TracedCandidate,
    params: &ShiftParams,
) {
    p.vertices.truncate(c.count);
    p.lobes.truncate(c.count - 1);
    p.weights.truncate(c.count - 1);
    p.nee_end = c.nee_end;
    p.nee_directional = c.nee_directional;
    if c.nee_end {
        // The NEE step replaces the BSDF step at x_{count-1}, which may not have been taken.
        p.vertices.truncate(c.count - 1);
        p.lobes.truncate(c.count - 2);
        p.weights.truncate(c.count - 2);
        p.vertices.push(c.light);
        p.lobes.push(LOBE_NONE);
        p.weights.push(c.nee_weight);
    }
    p.end_weight = c.end_weight;
    p.contribution = c.contribution;
    match record_path(scene, params, &p) {
        Some(record) => s.chosen = Some(record),
        None => {
            counts.candidates_dropped += 1;
            s.chosen_lost = true;
        }
    }
}

/// The NEE candidate of technique `t` at x_i (material `m` and shading normal `ns`, leaving
/// towards `wo`, after the prefix weight `prefix` of x1..x_{i-1}): the path x1..x_i plus the
/// light vertex NEE takes with it (`nee_vertex`: the drawn light for 0, directional light t - 1
/// otherwise); `None` if it carries no light.
#[allow(clippy::too_many_arguments)]
fn nee_candidate(
    scene: &Scene,
    x: &Vertex,
    m: &Material,
    ns: Vec3,
    wo: Vec3,
    seed: u32,
    i: usize,
    t: u32,
    prefix: Vec3,
) -> Option<TracedCandidate> {
    let (ls, light) = nee_vertex(scene, x, seed, i, t)?;
    let (f_cos, bsdf_pdf) = bsdf_eval_pdf(m, x.normal, ns, wo, ls.dir);
    if f_cos.max_element() <= 0.0 || !visible(scene, x, &light) {
        return None;
    }
    let weight = f_cos / ls.pdf;
    // end_mis_weight(x, prev_pos, light, true, false) from the pdfs at hand.
    let end_weight = if vertex_is_punctual(&light) {
        1.0
    } else {
        balance_heuristic(ls.pdf, bsdf_pdf)
    };
    let contribution = prefix * weight * end_emission(scene, x, &light) * end_weight;
    (contribution.max_element() > 0.0).then_some(TracedCandidate {
        count: i + 1,
        nee_end: true,
        nee_directional: t,
        light,
        nee_weight: weight,
        end_weight,
        contribution,
    })
}

/// Streams every light-ending prefix of at most `max_length` vertices of the path from `y1`
/// (seen from `camera`) with `seed`'s random numbers into `s`. With `russian_roulette` the
/// path goes on from x_i (i >= [`RR_START_DEPTH`]) with probability q = min(throughput /
/// (product of the earlier q), [`RR_MAX_SURVIVAL`]), drawn from `STREAM_RESAMPLE`'s z at x_i;
/// the later candidates' resampling weights are divided by the product of the q (their source
/// pdf carries it) and their contributions are the path's own (Lin, Kettunen and Wyman 2026,
/// "ReSTIR PT Enhanced": Russian roulette at initial sampling only).
#[allow(clippy::too_many_arguments)]
pub fn stream_path_candidates(
    scene: &Scene,
    s: &mut Resampler<PathRecord>,
    camera: Vec3,
    y1: Vertex,
    seed: u32,
    max_length: usize,
    params: &ShiftParams,
    scale: f32,
    russian_roulette: bool,
) -> CandidateCounts {
    let mut counts = CandidateCounts::default();
    let mut p = Path {
        seed,
        camera,
        vertices: vec![y1],
        nee_end: false,
        nee_directional: 0,
        lobes: Vec::new(),
        weights: Vec::new(),
        contribution: Vec3::ZERO,
        end_weight: 0.0,
    };
    let mut prefix = Vec3::ONE;
    let mut prev_pos = camera;
    let mut chosen = None;
    // 1 / the product of the survival probabilities so far.
    let mut roulette = 1.0f32;
    for i in 1..max_length {
        let x = p.vertices[i - 1];
        if vertex_is_escaped(&x) {
            break;
        }
        let u = rng_uniform4(seed, i as u32, STREAM_RESAMPLE);
        if russian_roulette && i as u32 >= RR_START_DEPTH {
            let survive = (prefix.max_element() * roulette).min(RR_MAX_SURVIVAL);
            if u.z >= survive {
                break;
            }
            roulette /= survive;
        }
        let wo = (prev_pos - x.pos).normalize();
        let (m, ns) = vertex_shading(scene, &x);
        // NEE's techniques at x: the drawn light, then every directional light.
        for t in 0..=scene.directional_count {
            if let Some(c) = nee_candidate(scene, &x, &m, ns, wo, seed, i, t, prefix) {
                let u_offer = if t == 0 {
                    u.x
                } else {
                    rng_uniform4(seed, i as u32, STREAM_DIRECTIONAL + t - 1).x
                };
                if offer_candidate(s, &mut counts, c.contribution, scale * roulette, u_offer) {
                    chosen = Some(c);
                }
            }
        }
        let Some((b, next)) = bsdf_vertex(scene, &x, wo, &m, ns, seed, i) else {
            break;
        };
        p.lobes.push(b.lobe);
        p.weights.push(b.weight);
        p.vertices.push(next);
        prefix *= b.weight;
        let emitted = end_emission(scene, &x, &next);
        if emitted.max_element() > 0.0 {
            let end_weight = end_mis_weight(scene, &x, prev_pos, &next, false, b.lobe & LOBE_DELTA != 0);
            let contribution = prefix * emitted * end_weight;
            if contribution.max_element() > 0.0 && offer_candidate(s, &mut counts, contribution, scale * roulette, u.y) {
                chosen = Some(TracedCandidate {
                    count: i + 1,
                    nee_end: false,
                    nee_directional: 0,
                    light: next,
                    nee_weight: Vec3::ZERO,
                    end_weight,
                    contribution,
                });
            }
        }
        prev_pos = x.pos;
    }
    if let Some(c) = chosen {
        record_chosen(scene, s, &mut counts, p, &c, params);
    }
    counts
}
