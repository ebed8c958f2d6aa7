//! Speed against accuracy: the error metrics and `stability` on a small run (every pixel finite,
//! energy within 2% of the references). The equal-time lines `compare` prints are checked by
//! the unit test in src/app/compare_outputs.rs.

use glam::Vec3;
use restir_pt::metrics::{energy_ratio, flicker, rel_mse, rel_mse_trimmed, standard_error};

use crate::common::{repo_path, temp_file};
use crate::fixtures::cli::restir_pt;

#[test]
fn metrics_rel_mse_energy_flicker_and_standard_error_match_hand_values() {
    let reference = [Vec3::splat(1.0), Vec3::ZERO];
    let image = [Vec3::splat(2.0), Vec3::splat(0.1)];
    // (2-1)^2/(1+0.01) per channel, 0.01/0.01 per channel, averaged over 6 channels.
    let expected = (3.0 / 1.01 + 3.0) / 6.0;
    assert!((rel_mse(&image, &reference) - expected).abs() < 1e-6);
    assert_eq!(rel_mse(&reference, &reference), 0.0);
    assert!((energy_ratio(&image, &reference) - 2.1).abs() < 1e-5);
    // Luminance changes of 1 and 0.1 against a mean reference luminance of 0.5.
    assert!((flicker(&reference, &image, &reference) - 1.1).abs() < 1e-5);
    // 1000 pixels: one firefly (error 100 per channel against a reference of 0) and 999 with
    // error 0.01 per channel. Trimming 0.1% drops exactly the firefly.
    let mut noisy = vec![Vec3::splat(0.01); 999];
    noisy.push(Vec3::splat(1.0));
    let black = vec![Vec3::ZERO; 1000];
    assert!((rel_mse(&noisy, &black) - (999.0 * 0.01 + 100.0) / 1000.0).abs() < 1e-6);
    assert!((rel_mse_trimmed(&noisy, &black, 1e-3) - 0.01).abs() < 1e-6);
    assert!((rel_mse_trimmed(&noisy, &black, 0.0) - rel_mse(&noisy, &black)).abs() < 1e-9);
    // compare's ± over trials: mean 2.5, sample variance 5/3, so sqrt(5/3 / 4).
    assert!((standard_error(&[1.0, 2.0, 3.0, 4.0]).unwrap() - (5.0f64 / 12.0).sqrt()).abs() < 1e-12);
    assert_eq!(standard_error(&[7.0]), None);
}

/// The path tracer and ReSTIR PT (hybrid) on cornell, 64x64, 16 frames with a static and a
/// moving camera, each frame against a 256-spp reference of its pose. No pixel may be
/// non-finite, and the energy averaged over a run's frames must be within 2% of 1. This is a
/// check for NaNs and lost or runaway energy, not a precise bias test (restir_unbiased_cornell
/// is): ReSTIR PT's run means over seeds 0 to 7 were 0.980 to 1.028 (mean 1.000, SD 1.3%), so
/// about one seed in seven would miss 2%. The seed is fixed, so the test is deterministic.
#[test]
fn stability_small_run_is_finite_and_keeps_energy_within_2_percent() {
    let out = temp_file("placeholder", b"").parent().unwrap().join("stability");
    let (code, _, stderr) = restir_pt(&[
        "stability",
        "--scenes",
        repo_path("scenes/cornell.gltf").to_str().unwrap(),
        "--methods",
        "pt,restir:hybrid",
        "--frames",
        "16",
        "--width",
        "64",
        "--height",
        "64",
        "--max-depth",
        "7",
        "--reference-spp",
        "256",
        "--pt-spp",
        "4",
        "--seed",
        "3",
        "--out-dir",
        out.to_str().unwrap(),
        "--validate",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let csv = std::fs::read_to_string(out.join("stability.csv")).unwrap();
    let rows: Vec<StabilityRow> = csv.lines().skip(1).map(StabilityRow::parse).collect();
    assert_eq!(csv.lines().next(), Some(STABILITY_HEADER));
    assert_eq!(rows.len(), 2 * 2 * 16);
    assert!(rows.iter().all(|r| r.nonfinite_pixels == 0));
    for method in ["pt", "restir:hybrid/gbh"] {
        for motion in ["static", "moving"] {
            let run: Vec<_> = rows.iter().filter(|r| r.method == method && r.motion == motion).collect();
            let energy = run.iter().map(|r| r.energy_ratio).sum::<f64>() / run.len() as f64;
            assert!((energy - 1.0).abs() < 0.02, "{method} {motion}: energy {energy}");
            assert_eq!(
                run.iter().filter(|r| r.flicker.is_some()).count(),
                if motion == "static" { 15 } else { 0 }
            );
            assert!(run.iter().all(|r| r.rel_mse.is_finite() && r.rel_mse > 0.0));
            if method != "pt" {
                assert!(run.iter().all(|r| r.failed_shift_rate.is_some_and(|f| f > 0.0 && f < 0.2)));
            }
        }
    }
    assert!(std::fs::read_to_string(out.join("cornell_rel_mse.svg")).unwrap().contains("<svg"));
    assert!(std::fs::read(out.join("cornell_rel_mse.png")).unwrap().starts_with(b"\x89PNG"));
}

/// The header line `stability` writes to stability.csv.
const STABILITY_HEADER: &str = "scene,method,camera,frame,nonfinite_pixels,energy_ratio,rel_mse,flicker,failed_shift_rate";

/// A row of stability.csv; empty optional fields are None.
struct StabilityRow {
    method: String,
    motion: String,
    nonfinite_pixels: usize,
    energy_ratio: f64,
    rel_mse: f64,
    flicker: Option<f64>,
    failed_shift_rate: Option<f64>,
}

impl StabilityRow {
    fn parse(line: &str) -> Self {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 9, "{line}");
        let optional = |s: &str| (!s.is_empty()).then(|| s.parse::<f64>().unwrap());
        Self {
            method: f[1].to_string(),
            motion: f[2].to_string(),
            nonfinite_pixels: f[4].parse().unwrap(),
            energy_ratio: f[5].parse().unwrap(),
            rel_mse: f[6].parse().unwrap(),
            flicker: optional(f[7]),
            failed_shift_rate: optional(f[8]),
        }
    }
}
