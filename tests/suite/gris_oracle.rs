//! GLSL against Rust for resampling: `mis_weight` of glsl/shading_core/gris.glsl (generalized balance
//! heuristic and pairwise MIS) against `gris::mis_weight`, and the streaming resampler of
//! glsl/shading_core/reservoir.glsl (`Resampler`, `resampler_begin`, `resampler_add`/`resampler_offer`,
//! `resampler_finish`) against its twins in crates/shading-core/src/gris.rs, on recorded inputs: tables of
//! confidence weights and p̂_{<-l}(y_i) with failed shifts (zeros) and six decades of range, and
//! offered candidates with zero weights and lost choices, as the reuse passes see them.

use glam::Vec3;
use restir_pt::oracle_types::{GrisOracleOffer, GrisOracleOutput};
use restir_pt::shading::gris::{mis_weight, resampler_begin, resampler_finish, resampler_offer, Domains, Input, Mis};

use crate::common::{close, gpu, mis_mode, run_oracle_with_defines, TestRng};

/// Inputs per resampling in the kernels (glsl/shading_core/gris.glsl MAX_INPUTS).
const MAX_INPUTS: usize = 9;
const CASES: usize = 4096;

/// One resampling: n inputs, their confidences c_l, the row p̂_{<-l}(y_i) of every input i's
/// shifted sample, and the candidates the inputs offer.
struct Case {
    n: usize,
    confidences: [f32; MAX_INPUTS],
    targets: [[f32; MAX_INPUTS]; MAX_INPUTS],
    offers: [GrisOracleOffer; MAX_INPUTS],
}

/// 10^e for e uniform in [-3, 3].
fn log_uniform(r: &mut TestRng) -> f32 {
    10f32.powf(6.0 * r.uniform() - 3.0)
}

fn recorded_cases(seed: u64) -> Vec<Case> {
    let mut r = TestRng(seed);
    (0..CASES)
        .map(|_| {
            let n = 1 + (r.next_u64() % MAX_INPUTS as u64) as usize;
            let mut case = Case {
                n,
                confidences: [0.0; MAX_INPUTS],
                targets: [[0.0; MAX_INPUTS]; MAX_INPUTS],
                offers: [GrisOracleOffer::default(); MAX_INPUTS],
            };
            for l in 0..n {
                // Reservoir confidences are whole candidate counts, capped at 20.
                case.confidences[l] = (1 + r.next_u64() % 20) as f32;
            }
            // A quarter of the rows come from a sample no other domain reaches.
            for row in case.targets.iter_mut().take(n) {
                let isolated = r.uniform() < 0.25;
                for (l, t) in row.iter_mut().enumerate().take(n) {
                    let failed = (l != 0 && isolated) || r.uniform() < 0.25;
                    *t = if failed { 0.0 } else { log_uniform(&mut r) };
                }
            }
            for offer in case.offers.iter_mut().take(n) {
                let target = log_uniform(&mut r);
                let colour = Vec3::new(r.uniform(), r.uniform(), r.uniform()) + 0.01;
                *offer = GrisOracleOffer {
                    contribution: (colour * target / restir_pt::metrics::luminance(colour)).to_array(),
                    target,
                    weight: if r.uniform() < 0.2 { 0.0 } else { log_uniform(&mut r) },
                    u: r.uniform(),
                    lost: (r.uniform() < 0.05) as u32,
                    pad: 0,
                };
            }
            case
        })
        .collect()
}

/// The recorded table as GRIS domains: sample i is input i's shifted sample y_i.
struct Recorded<'a>(&'a Case);

impl Domains<usize> for Recorded<'_> {
    fn shift(&self, _: usize, x: usize) -> Option<(usize, f64)> {
        Some((x, 1.0))
    }
    fn target_from(&self, l: usize, y: usize) -> f64 {
        self.0.targets[y][l] as f64
    }
    fn target(&self, y: usize) -> f64 {
        self.0.targets[y][0] as f64
    }
}

/// The GLSL kernel's outputs for every case.
fn run_glsl(cases: &[Case], mis: Mis) -> Vec<GrisOracleOutput> {
    let ctx = gpu();
    let counts: Vec<u32> = cases.iter().map(|c| c.n as u32).collect();
    let confidences: Vec<f32> = cases.iter().flat_map(|c| c.confidences).collect();
    let targets: Vec<f32> = cases.iter().flat_map(|c| c.targets.into_iter().flatten()).collect();
    let offers: Vec<GrisOracleOffer> = cases.iter().flat_map(|c| c.offers).collect();
    let mode = mis_mode(mis);
    let out = run_oracle_with_defines(
        &ctx,
        "oracle/gris_oracle.comp",
        &[("MIS_MODE", mode)],
        &[],
        &[
            ("Counts", bytemuck::cast_slice(&counts)),
            ("Confidences", bytemuck::cast_slice(&confidences)),
            ("Targets", bytemuck::cast_slice(&targets)),
            ("Offers", bytemuck::cast_slice(&offers)),
        ],
        cases.len() * std::mem::size_of::<GrisOracleOutput>() / 4,
        cases.len() as u32,
    );
    crate::common::assert_clean(&ctx);
    out
}

/// GLSL mis_weight against gris::mis_weight for every input of every case, within 1e-5 (the
/// weights lie in [0, 1]; single against double precision over at most 9 terms).
fn check_mis_weight(mis: Mis) {
    let cases = recorded_cases(2024 + mis as u64);
    let out = run_glsl(&cases, mis);
    let mut positive = 0;
    for (k, (case, g)) in cases.iter().zip(&out).enumerate() {
        let gpu_weights: Vec<f32> = g.mis_weights.iter().flatten().copied().collect();
        let inputs: Vec<Input<usize>> = (0..case.n)
            .map(|i| Input {
                sample: i,
                contribution_weight: 1.0,
                confidence: case.confidences[i] as f64,
            })
            .collect();
        for (i, &gpu_weight) in gpu_weights.iter().enumerate().take(case.n) {
            let rust = mis_weight(&Recorded(case), &inputs, mis, i, i) as f32;
            assert!(
                close(gpu_weight, rust, 1e-5),
                "case {k} (n = {}) input {i} {mis:?}: GLSL mis_weight {gpu_weight} vs Rust gris::mis_weight {rust}",
                case.n
            );
            positive += (rust > 0.0) as usize;
        }
    }
    eprintln!("{mis:?}: {positive} positive weights compared over {CASES} cases");
    assert!(positive > CASES, "{mis:?}: only {positive} positive weights");
}

#[test]
fn gris_mis_weight_generalized_balance_glsl_matches_rust() {
    // GLSL mis_weight against its Rust twin.
    check_mis_weight(Mis::GeneralizedBalance);
}

#[test]
fn gris_mis_weight_pairwise_glsl_matches_rust() {
    check_mis_weight(Mis::Pairwise);
}

/// GLSL Resampler (resampler_begin, resampler_add, resampler_finish) against the Rust twins
/// (resampler_begin, resampler_offer, resampler_finish): the same chosen input, except where
/// u sum w lies within 1e-5 of w (counted, at most 0.1%), W and `expected` within 1e-5
/// relative, M exactly.
#[test]
fn gris_resampler_glsl_matches_rust() {
    let cases = recorded_cases(77);
    let out = run_glsl(&cases, Mis::GeneralizedBalance);
    let (mut ties, mut chosen, mut lost) = (0, 0, 0);
    for (k, (case, g)) in cases.iter().zip(&out).enumerate() {
        let mut s = resampler_begin::<usize>();
        let mut tie = false;
        for (i, o) in case.offers.iter().enumerate().take(case.n) {
            s.confidence += case.confidences[i];
            // The recorded weights are finite: zero stands for a failed shift.
            if o.weight <= 0.0 {
                continue;
            }
            let sum = s.weight_sum + o.weight;
            tie |= (o.u * sum - o.weight).abs() <= 1e-5 * o.weight;
            if resampler_offer(&mut s, Vec3::from_array(o.contribution), o.target, o.weight, o.u) {
                s.chosen = Some(i);
            }
        }
        if let Some(i) = s.chosen {
            s.chosen_lost = case.offers[i].lost != 0;
        }
        let (sample, w, m) = resampler_finish(&s);
        let gpu_chosen = (g.chosen_input >= 0).then_some(g.chosen_input as usize);
        if gpu_chosen != sample {
            assert!(tie, "case {k}: GLSL chose {gpu_chosen:?}, Rust {sample:?}");
            ties += 1;
            continue;
        }
        chosen += sample.is_some() as usize;
        lost += s.chosen_lost as usize;
        let rel = |a: f32, b: f32| (a - b).abs() <= 1e-5 * a.abs().max(b.abs());
        assert!(rel(g.weight, w) || g.weight == w, "case {k}: W GLSL {} vs Rust {w}", g.weight);
        assert_eq!(g.confidence, m, "case {k}: M");
        for c in 0..3 {
            let (a, b) = (g.expected[c], s.expected[c]);
            assert!(
                rel(a, b) || a == b,
                "case {k}: expected GLSL {:?} vs Rust {}",
                g.expected,
                s.expected
            );
        }
    }
    eprintln!("resampler: {chosen} choices compared ({lost} lost), {ties} ties excluded of {CASES}");
    assert!(ties * 1000 <= CASES, "{ties} ties");
    assert!(chosen > CASES / 2 && lost > 0, "{chosen} choices, {lost} lost");
}
