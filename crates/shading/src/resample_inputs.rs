//! The reuse loop of GRIS, twin of glsl/shading/resample_inputs.glsl: inputs from other domains are
//! shifted into the canonical domain, weighted by w_i = m_i(y_i) p̂(y_i) W_{X_i} |T_i'(X_i)|
//! with MIS weights from inverse shifts (docs/restir.md), and one is chosen by the streaming
//! resampler ([`crate::gris::Resampler`]). Single precision and step for step as the
//! kernels run it, so that an oracle test can compare the two on any [`ReuseBridge`]; the
//! reference estimator it must agree with is [`crate::gris::resample`].

use glam::Vec3;

use crate::gris::{mis_weight, resampler_begin, resampler_finish, resampler_offer, target_function, Domains, Input, Mis};
use crate::path_record::PathRecord;
use crate::rng::{rng_uniform4, STREAM_RESAMPLE};
use crate::shift::ShiftResult;

/// A reservoir: a path sample with its unbiased contribution weight W and confidence M. Twin of
/// GLSL `Reservoir` (glsl/shading_core/reservoir.glsl).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reservoir {
    /// The sample Y.
    pub record: PathRecord,
    /// W_Y, an unbiased estimate of 1 / p(Y) in Y's domain; 0 for an empty reservoir.
    pub weight: f32,
    /// M, the number of candidates the reservoir stands for.
    pub confidence: f32,
}

/// What the reuse loop needs from the domains and shifts, the twin of the functions a kernel
/// defines before it includes glsl/shading/resample_inputs.glsl (`input_reservoir`, `input_domain`,
/// `same_domain`, `shift_path`), as RTXDI's resampling runs on its `RAB_*` bridge.
pub trait ReuseBridge {
    /// Where a sample lives: for ReSTIR PT a pixel seen from one frame's camera.
    type Domain: Copy;
    /// Input `i`'s reservoir (0: the canonical domain's own).
    fn input_reservoir(&self, i: usize) -> Reservoir;
    /// Input `i`'s domain; input 0's is the canonical domain the loop resamples into.
    fn input_domain(&self, i: usize) -> Self::Domain;
    /// Whether a shift from `a` to `b` is the identity, which the loop skips.
    fn same_domain(&self, a: Self::Domain, b: Self::Domain) -> bool;
    /// `record`'s sample shifted into domain `to`: the shifted record, |T'| and f of the result,
    /// or an invalid result where the shift fails.
    fn shift_path(&mut self, record: &PathRecord, to: Self::Domain) -> ShiftResult;
}

/// Counts of the loop, as the kernels' counters take them (glsl/interface/restir_bindings.glsl).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReuseCounters {
    /// Shifts that failed, and resampling weights that came out non-finite for an input of
    /// another domain.
    pub shifts_failed: u32,
    /// Non-finite resampling weights and inverse-shift targets, each dropped.
    pub nonfinite_weights: u32,
}

/// Whether input `i`'s MIS weight needs p̂_{<-l} of its shifted sample for l >= 1, l != i: for
/// every l under the generalized balance heuristic, only for the canonical input under pairwise
/// MIS. Twin of GLSL `needs_targets_from` (glsl/shading_core/gris.glsl).
pub fn needs_targets_from(mis: Mis, i: usize) -> bool {
    match mis {
        Mis::Pairwise => i == 0,
        Mis::GeneralizedBalance | Mis::Uniform => true,
    }
}

/// The row the loop has filled for one shifted sample, as the `Domains` the MIS weight reads:
/// confidences c_l and p̂_{<-l}(y) (index 0: p̂(y) in the canonical domain).
struct TargetsFrom<'a> {
    targets: &'a [f32],
}

impl Domains<()> for TargetsFrom<'_> {
    fn shift(&self, _: usize, x: ()) -> Option<((), f64)> {
        Some((x, 1.0))
    }
    fn target_from(&self, l: usize, _: ()) -> f64 {
        self.targets[l] as f64
    }
    fn target(&self, _: ()) -> f64 {
        self.targets[0] as f64
    }
}

/// Resamples the bridge's inputs 0..n-1 (n = `confidences.len()`, at most
/// [`restir_pt_interface::shader_interface::MAX_INPUTS`]; `confidences[l]` is c_l) into one reservoir of the
/// canonical domain; `seed` keys the choice (stream [`STREAM_RESAMPLE`], vertex i for input i).
/// Returns the reservoir (empty, W = 0, when nothing was chosen; M the sum of the confidences)
/// and E[f(Y) W_Y] over the choice (linear RGB), and adds to `counters`.
///
/// Step (i, l) of the n x n steps makes at most one shift: for l = 0 the shift of input i's
/// sample into the canonical domain, y_i = T_i(X_i); for l >= 1 (l != i) the inverse shift of
/// y_i into domain l, for p̂_{<-l}(y_i) = p̂_l(T_l^{-1}(y_i)) |(T_l^{-1})'(y_i)|. Input i's own
/// p̂_{<-i}(y_i) is p̂_i(X_i) / |T_i'(X_i)|, from its stored target. Twin of GLSL
/// `resample_inputs`.
pub fn resample_inputs<B: ReuseBridge>(
    bridge: &mut B,
    confidences: &[f32],
    mis: Mis,
    seed: u32,
    counters: &mut ReuseCounters,
) -> (Reservoir, Vec3) {
    let n = confidences.len();
    let mut s = resampler_begin::<PathRecord>();
    let mut targets_from = vec![0.0f32; n];
    let mut y = PathRecord::default();
    let (mut weight, mut own_target, mut jacobian, mut alive) = (0.0f32, 0.0f32, 1.0f32, false);
    let canonical = bridge.input_domain(0);
    // The MIS weight reads only the confidences of these; the samples are the targets' row.
    let inputs: Vec<Input<()>> = confidences
        .iter()
        .map(|&c| Input {
            sample: (),
            contribution_weight: 1.0,
            confidence: c as f64,
        })
        .collect();
    for step in 0..n * n {
        let (i, l) = (step / n, step % n);
        let forward = l == 0;
        if forward {
            s.confidence += confidences[i];
            // An empty reservoir offers no sample, but its domain still counts in the MIS weights.
            let input = bridge.input_reservoir(i);
            weight = input.weight;
            own_target = target_function(input.record.contribution());
            alive = weight > 0.0;
            y = input.record;
            jacobian = 1.0;
        }
        let (from, to) = if forward {
            (bridge.input_domain(i), canonical)
        } else {
            (canonical, bridge.input_domain(l))
        };
        let wanted = forward || (l != i && needs_targets_from(mis, i));
        let shift = alive && wanted && !bridge.same_domain(from, to);
        let shifted = shift.then(|| bridge.shift_path(&y, to));
        let valid = shifted.as_ref().is_some_and(|r| r.valid);
        if shift && !valid {
            counters.shifts_failed += 1;
        }
        if forward {
            if let Some(r) = shifted.as_ref().filter(|r| r.valid) {
                y = r.record;
                jacobian = r.jacobian;
            }
            alive = alive && (!shift || valid);
            targets_from[0] = target_function(y.contribution());
            if i != 0 {
                targets_from[i] = own_target / jacobian;
            }
        } else if alive && wanted {
            let mut t = target_function(y.contribution());
            if let Some(r) = &shifted {
                t = if r.valid {
                    target_function(r.contribution) * r.jacobian
                } else {
                    0.0
                };
                if !t.is_finite() {
                    counters.nonfinite_weights += 1;
                    counters.shifts_failed += 1;
                    t = 0.0;
                }
            }
            targets_from[l] = t;
        }
        if l + 1 == n && alive {
            let p0 = targets_from[0];
            let m = mis_weight(&TargetsFrom { targets: &targets_from }, &inputs, mis, i, ()) as f32;
            let w = m * p0 * weight * jacobian;
            if !w.is_finite() {
                counters.nonfinite_weights += 1;
                if !bridge.same_domain(bridge.input_domain(i), canonical) {
                    counters.shifts_failed += 1;
                }
            } else if w > 0.0 && resampler_offer(&mut s, y.contribution(), p0, w, rng_uniform4(seed, i as u32, STREAM_RESAMPLE).x) {
                s.chosen = Some(y);
            }
        }
    }
    let (chosen, weight, confidence) = resampler_finish(&s);
    let reservoir = Reservoir {
        record: chosen.unwrap_or_default(),
        weight,
        confidence,
    };
    (reservoir, s.expected)
}
