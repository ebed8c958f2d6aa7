//! The reuse loop of ReSTIR PT on the GRIS toy's analytic domains (tests/suite/gris.rs): GLSL
//! `resample_inputs` (glsl/shading/resample_inputs.glsl, run by glsl/oracle/reuse_oracle.comp on the toy
//! bridge) against its twin `resample_inputs` (crates/shading/src/resample_inputs.rs on the same bridge,
//! `ToyDomains`), the twin against the reference estimator `gris::resampled_expectation`, and
//! the twin's f(Y) W_Y against the integral. Up to 9 inputs per resampling, from the canonical
//! domain (identity shifts), from domains whose shifts fail on part of them, and empty ones.

use glam::Vec3;
use restir_pt::oracle_types::{ReuseOracleOutput, ReuseToyInput};
use restir_pt::shading::gris::{resampled_expectation, Domains, Input, Mis};
use restir_pt::shading::path_record::PathRecord;
use restir_pt::shading::resample_inputs::{resample_inputs, Reservoir, ReuseBridge, ReuseCounters};
use restir_pt::shading::shift::ShiftResult;

use crate::common::{assert_clean, close, gpu, mis_mode, run_oracle_with_defines, TestRng};

/// Inputs per resampling in the kernels.
const MAX_INPUTS: usize = restir_pt::shader_interface::MAX_INPUTS as usize;
const CASES: usize = 4096;

struct Case {
    seed: u32,
    inputs: Vec<ReuseToyInput>,
}

/// p̂ of each toy domain (GLSL `toy_target`): 1 + sin 3y in the canonical domain, 1 + x in
/// domain 1, 2 - x in domain 2.
fn toy_target(domain: u32, x: f32) -> f32 {
    match domain {
        1 => 1.0 + x,
        2 => 2.0 - x,
        _ => 1.0 + (3.0 * x).sin(),
    }
}

/// A toy sample as a path record (GLSL `toy_record`): rc_pos.x its position, info its domain,
/// seed its input, the grey p̂ of its domain its contribution.
fn toy_record(input: u32, domain: u32, x: f32) -> PathRecord {
    PathRecord {
        seed: input,
        info: domain,
        rc_pos: [x, 0.0, 0.0],
        contribution: [toy_target(domain, x); 3],
        ..Default::default()
    }
}

/// The toy's bridge, twin of the functions glsl/oracle/reuse_oracle.comp defines.
struct ToyDomains<'a>(&'a Case);

impl ReuseBridge for ToyDomains<'_> {
    type Domain = u32;

    fn input_reservoir(&self, i: usize) -> Reservoir {
        let t = self.0.inputs[i];
        Reservoir {
            record: toy_record(i as u32, t.domain, t.x),
            weight: t.weight,
            confidence: t.confidence,
        }
    }

    fn input_domain(&self, i: usize) -> u32 {
        self.0.inputs[i].domain
    }

    fn same_domain(&self, a: u32, b: u32) -> bool {
        a == b
    }

    fn shift_path(&mut self, record: &PathRecord, to: u32) -> ShiftResult {
        let (from, p) = (record.info, record.rc_pos[0]);
        let shifted = match (from, to) {
            (1, 0) if p <= 0.9 => Some((p * p, 2.0 * p)),
            (2, 0) if p <= 0.7 => Some((p + 0.3, 1.0)),
            (0, 1) if p > 0.0 && p <= 0.81 => {
                let y = p.sqrt();
                Some((y, 0.5 / y))
            }
            (0, 2) if p >= 0.3 => Some((p - 0.3, 1.0)),
            _ => None,
        };
        let (record, jacobian, valid) = match shifted {
            Some((y, jacobian)) => (toy_record(record.seed, to, y), jacobian, true),
            None => (PathRecord::default(), 0.0, false),
        };
        ShiftResult {
            valid,
            record,
            jacobian,
            contribution: if valid { record.contribution() } else { Vec3::ZERO },
            vertices: vec![],
            reconnection: None,
        }
    }
}

/// The same domains in double precision for the reference estimator (crates/shading-core/src/gris.rs):
/// sample i is input i's position, shifted by its domain's map.
impl Domains<f64> for ToyDomains<'_> {
    fn shift(&self, i: usize, x: f64) -> Option<(f64, f64)> {
        match self.0.inputs[i].domain {
            1 => (x <= 0.9).then_some((x * x, 2.0 * x)),
            2 => (x <= 0.7).then_some((x + 0.3, 1.0)),
            _ => Some((x, 1.0)),
        }
    }

    fn target_from(&self, i: usize, y: f64) -> f64 {
        match self.0.inputs[i].domain {
            1 if y > 0.0 && y <= 0.81 => (1.0 + y.sqrt()) / (2.0 * y.sqrt()),
            2 if (0.3..=1.0).contains(&y) => 2.0 - (y - 0.3),
            1 | 2 => 0.0,
            _ => self.target(y),
        }
    }

    fn target(&self, y: f64) -> f64 {
        1.0 + (3.0 * y).sin()
    }
}

/// A uniform in (0, 1), never 0, where the pdfs 2x and 3x^2 vanish.
fn open_uniform(r: &mut TestRng) -> f64 {
    ((r.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
}

/// An input of `domain` drawn from its pdf (1, 2x, 3x^2 on [0, 1]) with W = 1 / pdf.
fn drawn_input(r: &mut TestRng, domain: u32, confidence: f32) -> ReuseToyInput {
    let u = open_uniform(r);
    let (x, pdf) = match domain {
        1 => (u.sqrt(), 2.0 * u.sqrt()),
        2 => (u.cbrt(), 3.0 * u.cbrt() * u.cbrt()),
        _ => (u, 1.0),
    };
    ReuseToyInput {
        x: x as f32,
        weight: (1.0 / pdf) as f32,
        confidence,
        domain,
    }
}

/// 1 to 9 inputs: input 0 of the canonical domain, the others of any domain (the canonical one
/// too, as the temporal input under an unmoved camera); a tenth of them empty; confidences 1 to 20.
fn recorded_cases(seed: u64) -> Vec<Case> {
    let mut r = TestRng(seed);
    (0..CASES)
        .map(|_| {
            let n = 1 + (r.next_u64() % MAX_INPUTS as u64) as usize;
            let inputs = (0..n)
                .map(|i| {
                    let domain = if i == 0 { 0 } else { (r.next_u64() % 3) as u32 };
                    let confidence = (1 + r.next_u64() % 20) as f32;
                    let mut input = drawn_input(&mut r, domain, confidence);
                    if r.uniform() < 0.1 {
                        input.weight = 0.0;
                    }
                    input
                })
                .collect();
            Case {
                seed: r.next_u64() as u32,
                inputs,
            }
        })
        .collect()
}

fn rust_resample(case: &Case, mis: Mis) -> (Reservoir, Vec3, ReuseCounters) {
    let confidences: Vec<f32> = case.inputs.iter().map(|t| t.confidence).collect();
    let mut counters = ReuseCounters::default();
    let (reservoir, expected) = resample_inputs(&mut ToyDomains(case), &confidences, mis, case.seed, &mut counters);
    (reservoir, expected, counters)
}

fn run_glsl(cases: &[Case], mis: Mis) -> Vec<ReuseOracleOutput> {
    let ctx = gpu();
    let heads: Vec<[u32; 2]> = cases.iter().map(|c| [c.inputs.len() as u32, c.seed]).collect();
    let inputs: Vec<ReuseToyInput> = cases
        .iter()
        .flat_map(|c| (0..MAX_INPUTS).map(|i| c.inputs.get(i).copied().unwrap_or_default()))
        .collect();
    let mode = mis_mode(mis);
    let out = run_oracle_with_defines(
        &ctx,
        "oracle/reuse_oracle.comp",
        &[("MIS_MODE", mode)],
        &[],
        &[("Cases", bytemuck::cast_slice(&heads)), ("Inputs", bytemuck::cast_slice(&inputs))],
        cases.len() * std::mem::size_of::<ReuseOracleOutput>() / 4,
        cases.len() as u32,
    );
    assert_clean(&ctx);
    out
}

/// GLSL resample_inputs against Rust resample_inputs on 4096 recorded cases: the same chosen
/// input and position, W and E[f(Y) W_Y] within 1e-4 relative (the MIS weight is summed in
/// double precision on the host, sin differs by ulps), M and both counters exactly.
fn check_glsl_matches_rust(mis: Mis) {
    let cases = recorded_cases(9001 + mis as u64);
    let out = run_glsl(&cases, mis);
    let (mut shifted_choices, mut failed) = (0, 0);
    for (k, (case, g)) in cases.iter().zip(&out).enumerate() {
        let (reservoir, expected, counters) = rust_resample(case, mis);
        let chosen = if reservoir.weight > 0.0 { reservoir.record.seed as i32 } else { -1 };
        let what = format!("case {k} ({} inputs, {mis:?})", case.inputs.len());
        assert_eq!(
            g.chosen_input, chosen,
            "{what}: GLSL resample_inputs chose {}, Rust {chosen}",
            g.chosen_input
        );
        assert!(
            close(g.weight, reservoir.weight, 1e-4),
            "{what}: W GLSL {} vs Rust {}",
            g.weight,
            reservoir.weight
        );
        assert_eq!(g.confidence, reservoir.confidence, "{what}: M");
        for c in 0..3 {
            assert!(
                close(g.expected[c], expected[c], 1e-4),
                "{what}: expected GLSL {:?} vs Rust {expected}",
                g.expected
            );
        }
        assert_eq!(
            (g.shifts_failed, g.nonfinite_weights),
            (counters.shifts_failed, counters.nonfinite_weights),
            "{what}: counters (failed shifts, non-finite weights)"
        );
        if chosen >= 0 {
            assert!(close(g.chosen_x, reservoir.record.rc_pos[0], 1e-6), "{what}: chosen position");
            assert_eq!(g.chosen_domain, 0, "{what}: the result lives in the canonical domain");
            shifted_choices += (case.inputs[chosen as usize].domain != 0) as usize;
        }
        failed += counters.shifts_failed as usize;
    }
    eprintln!("{mis:?}: {CASES} resamplings, {shifted_choices} chose a shifted input, {failed} failed shifts");
    assert!(
        shifted_choices > CASES / 5 && failed > CASES / 5,
        "too few shifted choices or failed shifts"
    );
}

#[test]
fn resample_inputs_generalized_balance_glsl_matches_rust() {
    // GLSL resample_inputs against its Rust twin on the toy bridge.
    check_glsl_matches_rust(Mis::GeneralizedBalance);
}

#[test]
fn resample_inputs_pairwise_glsl_matches_rust() {
    check_glsl_matches_rust(Mis::Pairwise);
}

/// The loop computes GRIS's weights: its E[f(Y) W_Y] (grey, so one channel is sum_i w_i) equals
/// the reference estimator's sum_i w_i f(y_i) / p̂(y_i) with f = p̂, within 1e-4 relative
/// (single against double precision), and W p̂(Y) = sum_i w_i.
#[test]
fn resample_inputs_weights_are_the_gris_estimators() {
    for mis in [Mis::GeneralizedBalance, Mis::Pairwise] {
        for (k, case) in recorded_cases(31 + mis as u64).iter().enumerate() {
            let (reservoir, expected, _) = rust_resample(case, mis);
            let inputs: Vec<Input<f64>> = case
                .inputs
                .iter()
                .map(|t| Input {
                    sample: t.x as f64,
                    contribution_weight: t.weight as f64,
                    confidence: t.confidence as f64,
                })
                .collect();
            let toy = ToyDomains(case);
            let reference = resampled_expectation(&toy, &inputs, mis, |y| toy.target(y));
            // The luminance weights sum to 1 within a few ulps, so grey f / p̂ is 1.
            assert!(
                close(expected.x, reference as f32, 1e-4),
                "case {k} {mis:?}: loop {} vs gris {reference}",
                expected.x
            );
            if reservoir.weight > 0.0 {
                let total = reservoir.weight * toy_target(0, reservoir.record.rc_pos[0]);
                assert!(
                    close(total, reference as f32, 1e-4),
                    "case {k} {mis:?}: W p̂(Y) {total} vs sum w {reference}"
                );
            }
        }
    }
}

/// f(Y) W_Y of the loop is unbiased: three inputs, one per domain (confidences 1, 2 and 3), 2 x 10^5
/// resamplings; the mean within 4 standard errors of I = 1 + (1 - cos 3) / 3 for both MIS.
#[test]
fn resample_inputs_is_unbiased_on_the_gris_toy() {
    const RUNS: usize = 200_000;
    let exact = 1.0 + (1.0 - 3f64.cos()) / 3.0;
    for mis in [Mis::GeneralizedBalance, Mis::Pairwise] {
        let mut r = TestRng(77);
        let (mut sum, mut sum_sq) = (0.0, 0.0);
        for _ in 0..RUNS {
            let case = Case {
                inputs: (0..3).map(|d| drawn_input(&mut r, d, (d + 1) as f32)).collect(),
                seed: r.next_u64() as u32,
            };
            let (reservoir, _, _) = rust_resample(&case, mis);
            let estimate = (toy_target(0, reservoir.record.rc_pos[0]) * reservoir.weight) as f64;
            sum += estimate;
            sum_sq += estimate * estimate;
        }
        let mean = sum / RUNS as f64;
        let se = ((sum_sq / RUNS as f64 - mean * mean) / (RUNS as f64 - 1.0)).sqrt();
        let z = (mean - exact) / se;
        eprintln!("{mis:?}: mean {mean:.5}, exact {exact:.5}, z = {z:.2}");
        assert!(z.abs() < 4.0, "{mis:?}: f(Y) W_Y mean {mean} against {exact} (z = {z:.2})");
    }
}
