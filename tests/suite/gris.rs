//! A GRIS toy with a known answer: three one-dimensional domains on [0, 1] with analytic,
//! bijective, partial shifts into the target domain. The estimator f(Y) W_Y is unbiased with the
//! generalized balance heuristic and with pairwise MIS (|mean - I| / SE < 4 over 2 x 10^5 runs),
//! and the 1/M control, whose weights do not sum to one where a domain cannot reach, is caught.
//! The selection-free estimator the renderer shades with (`resampled_expectation`) is unbiased
//! too, for an integrand that is not the target function, and has a lower variance.

use restir_pt::shading::gris::{resample, resampled_expectation, Domains, Input, Mis};

use crate::common::TestRng;

/// The integrand of the target domain: f(y) = 1 + sin(3y), I = 1 + (1 - cos 3) / 3.
fn f(y: f64) -> f64 {
    1.0 + (3.0 * y).sin()
}

const RUNS: usize = 200_000;

/// Domain 0: the target itself (identity), samples with pdf 1.
/// Domain 1: T(x) = x^2 on [0, 0.9] (image [0, 0.81]); samples with pdf 2x; p̂_1(x) = 1 + x.
/// Domain 2: T(x) = x + 0.3 on [0, 0.7] (image [0.3, 1]); samples with pdf 3x^2; p̂_2(x) = 2 - x.
struct Toy;

impl Domains<f64> for Toy {
    fn shift(&self, i: usize, x: f64) -> Option<(f64, f64)> {
        match i {
            1 if x <= 0.9 => Some((x * x, 2.0 * x)),
            2 if x <= 0.7 => Some((x + 0.3, 1.0)),
            _ => None,
        }
    }

    fn target_from(&self, i: usize, y: f64) -> f64 {
        match i {
            1 if (0.0..=0.81).contains(&y) && y > 0.0 => {
                let x = y.sqrt();
                (1.0 + x) / (2.0 * x)
            }
            2 if (0.3..=1.0).contains(&y) => 2.0 - (y - 0.3),
            _ => 0.0,
        }
    }

    fn target(&self, y: f64) -> f64 {
        f(y)
    }
}

/// A uniform in (0, 1) with 53 random bits (never 0, where the pdfs 2x and 3x^2 vanish).
fn uniform(r: &mut TestRng) -> f64 {
    ((r.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
}

/// A second integrand whose ratio to the target varies, as an RGB path's colour varies against
/// its luminance: g(y) = f(y) (1 + 4y).
fn g(y: f64) -> f64 {
    f(y) * (1.0 + 4.0 * y)
}

fn exact_g() -> f64 {
    3.0 + (1.0 - 3f64.cos()) / 3.0 + 4.0 * (3f64.sin() / 9.0 - 3f64.cos() / 3.0)
}

/// One estimate from the inputs and a uniform for the selection.
type Estimator = dyn Fn(&[Input<f64>], f64) -> f64;

fn selected(mis: Mis, integrand: fn(f64) -> f64) -> Box<Estimator> {
    Box::new(move |inputs, u| match resample(&Toy, inputs, mis, u) {
        Some((y, w)) => integrand(y) * w,
        None => 0.0,
    })
}

fn run(mis: Mis, confidence: [f64; 3]) -> (f64, f64) {
    let (mean, se) = run_estimator(&*selected(mis, f), confidence);
    eprintln!(
        "GRIS toy {mis:?} {confidence:?}: mean {mean:.5}, exact {:.5}, z = {:.2}",
        exact(),
        (mean - exact()) / se
    );
    (mean, se)
}

fn run_estimator(estimator: &Estimator, confidence: [f64; 3]) -> (f64, f64) {
    let mut r = TestRng(2024);
    let mut sum = 0.0;
    let mut sum_sq = 0.0;
    for _ in 0..RUNS {
        // Inverse-CDF sampling: pdf 1, pdf 2x (x = sqrt u), pdf 3x^2 (x = cbrt u).
        let (a, b, c) = (uniform(&mut r), uniform(&mut r).sqrt(), uniform(&mut r).cbrt());
        let inputs = [
            Input {
                sample: a,
                contribution_weight: 1.0,
                confidence: confidence[0],
            },
            Input {
                sample: b,
                contribution_weight: 1.0 / (2.0 * b),
                confidence: confidence[1],
            },
            Input {
                sample: c,
                contribution_weight: 1.0 / (3.0 * c * c),
                confidence: confidence[2],
            },
        ];
        let estimate = estimator(&inputs, uniform(&mut r));
        sum += estimate;
        sum_sq += estimate * estimate;
    }
    let mean = sum / RUNS as f64;
    let var = (sum_sq / RUNS as f64 - mean * mean) * RUNS as f64 / (RUNS as f64 - 1.0);
    (mean, (var / RUNS as f64).sqrt())
}

fn exact() -> f64 {
    1.0 + (1.0 - 3f64.cos()) / 3.0
}

#[test]
fn gris_toy_generalized_balance_heuristic_is_unbiased() {
    for confidence in [[1.0, 1.0, 1.0], [1.0, 4.0, 0.5]] {
        let (mean, se) = run(Mis::GeneralizedBalance, confidence);
        assert!(
            (mean - exact()).abs() / se < 4.0,
            "GBH {confidence:?}: {mean} vs {} (SE {se})",
            exact()
        );
    }
}

#[test]
fn gris_toy_pairwise_mis_is_unbiased() {
    for confidence in [[1.0, 1.0, 1.0], [2.0, 1.0, 3.0]] {
        let (mean, se) = run(Mis::Pairwise, confidence);
        assert!(
            (mean - exact()).abs() / se < 4.0,
            "pairwise {confidence:?}: {mean} vs {} (SE {se})",
            exact()
        );
    }
}

#[test]
fn gris_toy_uniform_weights_are_detected_as_biased() {
    let (mean, se) = run(Mis::Uniform, [1.0, 1.0, 1.0]);
    assert!(
        (mean - exact()).abs() / se > 4.0,
        "1/M weights went undetected: {mean} vs {} (SE {se})",
        exact()
    );
}

#[test]
fn gris_toy_resampled_expectation_is_unbiased_with_lower_variance() {
    for mis in [Mis::GeneralizedBalance, Mis::Pairwise] {
        let confidence = [1.0, 4.0, 0.5];
        let expected: Box<Estimator> = Box::new(move |inputs, _| resampled_expectation(&Toy, inputs, mis, g));
        let (mean, se) = run_estimator(&*expected, confidence);
        let (selected_mean, selected_se) = run_estimator(&*selected(mis, g), confidence);
        eprintln!(
            "GRIS toy {mis:?} g: expectation {mean:.5} (SE {se:.1e}), selection {selected_mean:.5} (SE {selected_se:.1e}), exact {:.5}",
            exact_g()
        );
        assert!(
            (mean - exact_g()).abs() / se < 4.0,
            "{mis:?}: expectation {mean} vs {} (SE {se})",
            exact_g()
        );
        assert!(
            (selected_mean - exact_g()).abs() / selected_se < 4.0,
            "{mis:?}: selection {selected_mean} vs {} (SE {selected_se})",
            exact_g()
        );
        assert!(
            se < selected_se,
            "{mis:?}: the expectation's SE {se} is not below the selection's {selected_se}"
        );
    }
}

/// The streaming resampler (gris::resampler_offer, twin of the kernels' Resampler) chooses
/// candidate i with probability w_i / sum w: 4 candidates, 2 x 10^5 runs, every frequency within
/// 4 standard errors; W = sum w / p̂(chosen) and `expected` = sum w_i f_i / p̂_i.
#[test]
fn gris_resampler_chooses_in_proportion_to_weight() {
    use glam::Vec3;
    use restir_pt::shading::gris::{resampler_begin, resampler_finish, resampler_offer};
    let weights = [0.5f32, 2.0, 0.0, 1.5];
    let targets = [1.0f32, 4.0, 1.0, 0.5];
    let total: f32 = weights.iter().sum();
    let mut r = TestRng(31);
    let mut counts = [0usize; 4];
    const N: usize = 200_000;
    for _ in 0..N {
        let mut s = resampler_begin::<usize>();
        for i in 0..4 {
            if weights[i] > 0.0 && resampler_offer(&mut s, Vec3::splat(targets[i]), targets[i], weights[i], r.uniform()) {
                s.chosen = Some(i);
            }
        }
        let (chosen, w, _) = resampler_finish(&s);
        let i = chosen.expect("a positive weight was offered");
        assert!((w - total / targets[i]).abs() <= 1e-6 * w);
        assert!((s.expected - Vec3::splat(total)).abs().max_element() <= 1e-5 * total);
        counts[i] += 1;
    }
    for i in 0..4 {
        let p = (weights[i] / total) as f64;
        let se = (p * (1.0 - p) / N as f64).sqrt().max(1e-9);
        let freq = counts[i] as f64 / N as f64;
        assert!((freq - p).abs() <= 4.0 * se, "candidate {i}: chosen {freq:.4}, expected {p:.4}");
    }
}
