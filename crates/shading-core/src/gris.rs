//! Generalized resampled importance sampling (GRIS) across domains with shift mappings: the
//! estimator of docs/restir.md (generalized RIS), written once over any sample type.
//! ReSTIR's reservoirs apply it per pixel; the tests check it on analytic domains.
//!
//! Inputs X_i come from their own domains with unbiased contribution weights W_{X_i}. Each is
//! shifted into the target domain, Y_i = T_i(X_i) (input 0 is the canonical sample, T_0 = id),
//! weighted by w_i = m_i(Y_i) p̂(Y_i) W_{X_i} |T_i'(X_i)|, and Y is chosen in proportion to w_i,
//! with W_Y = sum_j w_j / p̂(Y).

use glam::Vec3;

/// How the resampling MIS weights m_i are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mis {
    /// m_i(y) = c_i p̂_{<-i}(y) / sum_j c_j p̂_{<-j}(y): one inverse shift per input and
    /// candidate, O(M^2).
    GeneralizedBalance,
    /// The canonical input against each neighbour in turn, O(M); the canonical input keeps at
    /// least 1 / (k + 1) of the weight (defensive pairwise MIS).
    Pairwise,
    /// m_i = 1 / M: biased wherever some domain cannot produce a sample. A negative control only.
    Uniform,
}

/// One input: its sample, its unbiased contribution weight and its confidence weight (the
/// number of candidates it stands for).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Input<S> {
    /// X_i, in input i's own domain.
    pub sample: S,
    /// W_{X_i}: an unbiased estimate of 1 / p(X_i) (Lin et al. 2022).
    pub contribution_weight: f64,
    /// c_i, the number of candidates X_i stands for (ReSTIR's M); weights the MIS.
    pub confidence: f64,
}

/// What the estimator needs from the domains and shifts, for inputs 0..M (0 = canonical).
pub trait Domains<S> {
    /// T_i(x) and |T_i'(x)|, or `None` where input i's sample cannot be shifted.
    fn shift(&self, i: usize, x: S) -> Option<(S, f64)>;
    /// p̂_{<-i}(y) = p̂_i(T_i^{-1}(y)) |(T_i^{-1})'(y)|, and 0 where y cannot be shifted back.
    fn target_from(&self, i: usize, y: S) -> f64;
    /// p̂ of the target domain.
    fn target(&self, y: S) -> f64;
}

/// The resampling MIS weight of input `i`'s shifted sample `y`.
pub fn mis_weight<S: Copy>(domains: &impl Domains<S>, inputs: &[Input<S>], mis: Mis, i: usize, y: S) -> f64 {
    let m = inputs.len();
    let c = |j: usize| inputs[j].confidence;
    let from = |j: usize| if j == 0 { domains.target(y) } else { domains.target_from(j, y) };
    match mis {
        Mis::Uniform => 1.0 / m as f64,
        Mis::GeneralizedBalance => {
            let total: f64 = (0..m).map(|j| c(j) * from(j)).sum();
            if total > 0.0 {
                c(i) * from(i) / total
            } else {
                0.0
            }
        }
        Mis::Pairwise => {
            if m == 1 {
                return 1.0;
            }
            let k = (m - 1) as f64;
            let canonical = c(0) * domains.target(y) / k;
            let pair = |j: usize| {
                let neighbour = c(j) * domains.target_from(j, y);
                if neighbour + canonical > 0.0 {
                    neighbour / (neighbour + canonical)
                } else {
                    0.0
                }
            };
            if i == 0 {
                (1.0 + (1..m).map(|j| 1.0 - pair(j)).sum::<f64>()) / (k + 1.0)
            } else {
                pair(i) / (k + 1.0)
            }
        }
    }
}

/// Every input that shifts into the target domain, with its resampling weight
/// w_i = m_i(y_i) p̂(y_i) W_i |T_i'(x_i)|; failed shifts and zero or non-finite weights drop out.
fn weighted_candidates<S: Copy>(domains: &impl Domains<S>, inputs: &[Input<S>], mis: Mis) -> Vec<(S, f64)> {
    let mut candidates = Vec::with_capacity(inputs.len());
    for (i, input) in inputs.iter().enumerate() {
        let shifted = if i == 0 {
            Some((input.sample, 1.0))
        } else {
            domains.shift(i, input.sample)
        };
        let Some((y, jacobian)) = shifted else { continue };
        let w = mis_weight(domains, inputs, mis, i, y) * domains.target(y) * input.contribution_weight * jacobian;
        // A non-finite weight is a failed shift, never a value.
        if w.is_finite() && w > 0.0 {
            candidates.push((y, w));
        }
    }
    candidates
}

/// The resampled sample Y and its unbiased contribution weight W_Y; `None` if every weight is
/// zero. `u` in [0, 1) picks among the candidates.
pub fn resample<S: Copy>(domains: &impl Domains<S>, inputs: &[Input<S>], mis: Mis, u: f64) -> Option<(S, f64)> {
    let candidates = weighted_candidates(domains, inputs, mis);
    let total: f64 = candidates.iter().map(|c| c.1).sum();
    if !(total > 0.0) {
        return None;
    }
    let mut threshold = u * total;
    let chosen = candidates.iter().find(|c| {
        threshold -= c.1;
        threshold < 0.0
    });
    let (y, _) = *chosen.unwrap_or(candidates.last().expect("total > 0 means a candidate"));
    Some((y, total / domains.target(y)))
}

/// The expectation of `integrand(Y) W_Y` over the choice of Y among the candidates,
/// sum_i w_i integrand(y_i) / p̂(y_i): the same estimator without the selection noise (Rao-
/// Blackwellized). The renderer shades with it, where the integrand is RGB and p̂ its luminance.
pub fn resampled_expectation<S: Copy>(domains: &impl Domains<S>, inputs: &[Input<S>], mis: Mis, integrand: impl Fn(S) -> f64) -> f64 {
    weighted_candidates(domains, inputs, mis)
        .iter()
        .map(|&(y, w)| w * integrand(y) / domains.target(y))
        .sum()
}

/// The target function p̂ of a path: the luminance of its contribution f (RGB). Every channel
/// has a positive weight, so p̂ > 0 wherever f is non-zero, as unbiased resampling requires.
/// Twin of `target_function` in glsl/shading_core/reservoir.glsl.
pub fn target_function(contribution: Vec3) -> f32 {
    contribution.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Streaming weighted selection, candidate by candidate, as the kernels resample: after
/// `resampler_offer` of candidates with weights w_i, candidate i is chosen with probability
/// w_i / sum_j w_j, and `resampler_finish` gives W = sum_j w_j / p̂(chosen). `expected` is
/// sum_i w_i f(y_i) / p̂(y_i), the expectation of f(Y) W_Y over the choice (see
/// `resampled_expectation`), in RGB. Single precision, as on the GPU. Twin: `Resampler` and
/// its functions in glsl/shading_core/reservoir.glsl.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resampler<S> {
    /// The chosen candidate so far; `None` before the first is chosen.
    pub chosen: Option<S>,
    /// p̂ of the chosen candidate.
    pub chosen_target: f32,
    /// sum_j w_j over the candidates offered so far.
    pub weight_sum: f32,
    /// The confidence M of the result: the sum of the inputs' confidence weights, which the
    /// caller adds.
    pub confidence: f32,
    /// sum_i w_i f(y_i) / p̂(y_i) over the candidates offered (linear RGB).
    pub expected: Vec3,
    /// The chosen candidate could not be recorded: the result is empty.
    pub chosen_lost: bool,
}

/// An empty resampler: nothing chosen, all sums 0. Twin of GLSL `resampler_begin`.
pub fn resampler_begin<S>() -> Resampler<S> {
    Resampler {
        chosen: None,
        chosen_target: 0.0,
        weight_sum: 0.0,
        confidence: 0.0,
        expected: Vec3::ZERO,
        chosen_lost: false,
    }
}

/// Offers a candidate of contribution f (RGB) and target p̂ = `target` with weight `w` (finite,
/// positive); true if it becomes the chosen one, which the caller then stores in `chosen`. `u`
/// is uniform in [0, 1): the candidate replaces the chosen one when u < w / sum w.
pub fn resampler_offer<S>(s: &mut Resampler<S>, contribution: Vec3, target: f32, w: f32, u: f32) -> bool {
    s.weight_sum += w;
    s.expected += (w / target) * contribution;
    if u * s.weight_sum >= w {
        return false;
    }
    s.chosen_target = target;
    s.chosen_lost = false;
    true
}

/// The chosen sample, its unbiased contribution weight W (0 if nothing was chosen or the choice
/// was lost) and the confidence M.
pub fn resampler_finish<S: Copy>(s: &Resampler<S>) -> (Option<S>, f32, f32) {
    let w = if s.weight_sum > 0.0 && !s.chosen_lost {
        s.weight_sum / s.chosen_target
    } else {
        0.0
    };
    (s.chosen, w, s.confidence)
}
