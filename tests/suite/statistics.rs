//! The statistics the unbiasedness tests use: Student's t two-sided p-values (through the
//! regularised incomplete beta function) and the binomial bound on chance failures, each
//! checked against tables.

/// The level of each block's t-test in the unbiasedness tests.
pub const ALPHA: f64 = 0.01;

/// ln Γ(x) for x > 0 (Lanczos, g = 7).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let t = x + 7.5;
    let series: f64 = C[0] + (1..9).map(|i| C[i] / (x + i as f64)).sum::<f64>();
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + series.ln()
}

/// The regularised incomplete beta function I_x(a, b) (continued fraction, Lentz's method).
fn incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    if x > (a + 1.0) / (a + b + 2.0) {
        return 1.0 - incomplete_beta(1.0 - x, b, a);
    }
    let front = (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp() / a;
    let tiny = 1e-300;
    let (mut c, mut d) = (1.0, 1.0 - (a + b) * x / (a + 1.0));
    d = 1.0 / if d.abs() < tiny { tiny } else { d };
    let mut f = d;
    for m in 1..300 {
        let m = m as f64;
        for numerator in [
            m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m)),
            -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0)),
        ] {
            d = 1.0 + numerator * d;
            d = 1.0 / if d.abs() < tiny { tiny } else { d };
            c = 1.0 + numerator / c;
            if c.abs() < tiny {
                c = tiny;
            }
            f *= c * d;
        }
        if (c * d - 1.0).abs() < 1e-12 {
            break;
        }
    }
    front * f
}

/// Two-sided p-value of Student's t with `dof` degrees of freedom.
pub fn student_t_two_sided(t: f64, dof: f64) -> f64 {
    incomplete_beta(dof / (dof + t * t), 0.5 * dof, 0.5)
}

#[test]
fn restir_student_t_matches_tables() {
    // t_{0.995} quantiles: 2.744 at 31 dof, 2.576 in the normal limit.
    assert!((student_t_two_sided(2.744, 31.0) - 0.01).abs() < 2e-4);
    assert!((student_t_two_sided(2.576, 1e7) - 0.01).abs() < 2e-4);
    assert!((student_t_two_sided(0.0, 10.0) - 1.0).abs() < 1e-9);
}

/// P(X >= k) for X ~ Binomial(n, p).
fn binomial_tail(n: usize, p: f64, k: usize) -> f64 {
    let mut term = (1.0 - p).powi(n as i32);
    let mut below = 0.0;
    for i in 0..k {
        below += term;
        term *= (n - i) as f64 / (i + 1) as f64 * p / (1.0 - p);
    }
    (1.0 - below).max(0.0)
}

/// The most failing blocks an unbiased renderer shows with 99% probability. Each block fails
/// at the 1% level by chance alone, so with 64 blocks "at least 99% pass" (no failure at all)
/// holds only with probability 0.99^64 = 53% for an exact renderer; the count of chance failures
/// is Binomial(blocks, 1%), and more failures than this bound are evidence of bias at 1%.
pub fn max_failing_blocks(blocks: usize) -> usize {
    (0..blocks)
        .find(|&k| binomial_tail(blocks, ALPHA, k + 1) < 0.01)
        .expect("the tail vanishes")
}

#[test]
fn restir_binomial_bound_on_chance_failures() {
    assert!((binomial_tail(64, 0.01, 1) - (1.0 - 0.99f64.powi(64))).abs() < 1e-12);
    assert!((binomial_tail(64, 0.01, 0) - 1.0).abs() < 1e-12);
    // P(X >= 3) = 0.0265 and P(X >= 4) = 0.0040 for 64 blocks: at most 3 chance failures.
    assert!((binomial_tail(64, 0.01, 4) - 0.0040).abs() < 1e-4);
    assert_eq!(max_failing_blocks(64), 3);
}
