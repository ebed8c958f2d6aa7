//! The restir-pt binary's measurement commands (reference, profile, compare) and the check of
//! every written image for non-finite pixels.

use crate::common::temp_file;
use crate::fixtures::cli::{assert_clean_failure, render_pt, restir_pt};

/// `restir-pt reference` of cornell at 16x16 into `dir/ref.exr`.
fn reference_16x16(dir: &std::path::Path, spp: u32) -> std::path::PathBuf {
    let reference = dir.join("ref.exr");
    let (code, _, stderr) = restir_pt(&[
        "reference",
        "scenes/cornell.gltf",
        "--spp",
        &spp.to_string(),
        "--width",
        "16",
        "--height",
        "16",
        "--out",
        reference.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    reference
}

#[test]
fn cli_reference_and_profile_write_their_files() {
    let dir = temp_file("placeholder", b"").parent().unwrap().join("reference-profile");
    let reference = reference_16x16(&dir, 8);
    assert!(reference.exists() && dir.join("ref.variance.exr").exists());

    let (code, stdout, stderr) = restir_pt(&[
        "profile",
        "--frames",
        "3",
        "--width",
        "16",
        "--height",
        "16",
        "--out-dir",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let csv = std::fs::read_to_string(dir.join("passes.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3 * 4, "{csv}");
    // Each pass's time also in path-tracer samples: ms over one ratio shared by every row.
    let rows: Vec<(f64, f64)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<f64> = l.split(',').skip(2).map(|v| v.parse().unwrap()).collect();
            (f[0], f[1])
        })
        .collect();
    let longest = rows.iter().copied().fold((0.0, 0.0), |a, r| if r.0 > a.0 { r } else { a });
    let ms_per_sample = longest.0 / longest.1;
    assert!(ms_per_sample > 0.0 && ms_per_sample.is_finite(), "{csv}");
    for (ms, samples) in &rows {
        // Both columns are rounded to 4 decimals.
        assert!(
            (samples * ms_per_sample - ms).abs() < 1e-3 * ms + 1e-4 * (ms_per_sample + 1.0),
            "{csv}"
        );
    }
    assert!(stdout.contains("GPU ms per sample per pixel"), "{stdout}");
    let trace: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("trace.json")).unwrap()).unwrap();
    assert_eq!(trace["traceEvents"].as_array().unwrap().len(), 12);
    assert!(std::fs::read_to_string(dir.join("passes.svg")).unwrap().starts_with("<svg"));
    for pass in ["initial", "temporal", "spatial", "shade", "frame"] {
        assert!(stdout.lines().any(|l| l.starts_with(pass)), "{pass} median/p95 missing: {stdout}");
    }
}

#[test]
fn cli_compare_writes_results_charts_and_strip() {
    let dir = temp_file("placeholder", b"").parent().unwrap().join("compare");
    let reference = reference_16x16(&dir, 64);
    let budgets = ["200", "400"];
    let (code, stdout, stderr) = restir_pt(&[
        "compare",
        "scenes/cornell.gltf",
        "--reference",
        reference.to_str().unwrap(),
        "--methods",
        "pt,restir:hybrid",
        "--budgets-ms",
        &budgets.join(","),
        "--frames",
        "3",
        "--trials",
        "2",
        "--out-dir",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 4, "{csv}");
    let spp = |r: &Vec<&str>| r[2].trim_start_matches("spp=").parse::<u32>().unwrap();
    for row in &rows {
        let rel_mse: f64 = row[4].parse().unwrap();
        let gpu_ms: f64 = row[3].parse().unwrap();
        let trimmed: f64 = row[5].parse().unwrap();
        assert!(rel_mse.is_finite() && rel_mse > 0.0 && gpu_ms > 0.0, "{row:?}");
        assert!(trimmed > 0.0 && trimmed <= rel_mse, "trimmed relMSE: {row:?}");
        assert_eq!(row[9], "0", "non-finite pixels: {row:?}");
        // Two trials of different seeds give a spread.
        let stderr_of_mean: f64 = row[10].parse().unwrap();
        assert!(stderr_of_mean > 0.0 && stderr_of_mean < rel_mse, "relMSE standard error: {row:?}");
        let (mape, flip, pt_samples): (f64, f64, f64) = (row[11].parse().unwrap(), row[12].parse().unwrap(), row[13].parse().unwrap());
        assert!(mape > 0.0 && mape.is_finite(), "MAPE: {row:?}");
        assert!(flip > 0.0 && flip < 1.0, "HDR-FLIP: {row:?}");
        assert!(pt_samples > 0.0 && pt_samples.is_finite(), "frame in path-tracer samples: {row:?}");
    }
    // Every row's frame is measured in the one path-tracer sample cost calibrated in the run, so
    // pt_samples / gpu_ms is the same on every row (up to the CSV's four decimals). How many
    // samples a frame of n costs is a timing, which depends on the machine's load: it belongs
    // to the README's results, not to a test.
    let per_ms = |r: &Vec<&str>| r[13].parse::<f64>().unwrap() / r[3].parse::<f64>().unwrap();
    for row in &rows[1..] {
        assert!((per_ms(row) / per_ms(&rows[0]) - 1.0).abs() < 1e-3, "{csv}");
    }
    // A larger budget buys the path tracer more samples per frame.
    assert!(rows[0][0] == "pt" && rows[1][0] == "pt" && spp(&rows[1]) > spp(&rows[0]), "{csv}");
    assert!(rows[2][2].starts_with("reservoirs="), "{csv}");
    // Each budget gets its equal-time lines: the ratio, or, when a shared machine made a
    // method's frames overrun the budget, the line that leaves it out (the ratio's own rules are
    // compare_equal_time_leaves_out_runs_over_budget's).
    for budget in budgets {
        let ratio = format!("equal time {budget}.0 ms, relMSE: pt");
        let left_out = format!("equal time {budget}.0 ms: ");
        assert!(stdout.contains(&ratio) || stdout.contains(&left_out), "{stdout}");
    }
    for chart in ["rel_mse_vs_time", "mse_vs_time"] {
        assert!(std::fs::read_to_string(dir.join(format!("{chart}.svg"))).unwrap().contains("<svg"));
        assert!(std::fs::read(dir.join(format!("{chart}.png"))).unwrap().starts_with(b"\x89PNG"));
    }
    assert!(std::fs::read(dir.join("equal_time.png")).unwrap().starts_with(b"\x89PNG"));

    assert_clean_failure(
        &[
            "compare",
            "scenes/cornell.gltf",
            "--reference",
            reference.to_str().unwrap(),
            "--methods",
            "pt,restir:sideways",
        ],
        &["restir:sideways", "unknown shift"],
    );
    assert_clean_failure(
        &[
            "compare",
            "scenes/cornell.gltf",
            "--reference",
            reference.to_str().unwrap(),
            "--budgets-ms=0",
        ],
        &["--budgets-ms 0"],
    );
    assert_clean_failure(&["compare", "scenes/cornell.gltf", "--reference", "missing.exr"], &["missing.exr"]);
}

/// A lamp of radiance 3e38 (finite, so the loader takes it) whose sums overflow to infinity.
fn overflowing_lamp_scene() -> std::path::PathBuf {
    use glam::Vec3;
    use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let lamp = b.material("lamp", MaterialSpec::emitter(Vec3::splat(3e38)));
    let floor = b.mesh(
        "floor",
        &MeshData::quad(Vec3::new(-1.0, 0.0, -1.0), Vec3::Z * 2.0, Vec3::X * 2.0),
        grey,
    );
    b.instance("floor", floor, 0.0, Vec3::ZERO);
    let light = b.mesh(
        "lamp",
        &MeshData::quad(Vec3::new(-0.3, 1.0, -0.3), Vec3::X * 0.6, Vec3::Z * 0.6),
        lamp,
    );
    b.instance("lamp", light, 0.0, Vec3::ZERO);
    b.camera("camera", Vec3::new(0.0, 0.5, 3.0), Vec3::ZERO, 0.9);
    temp_file("overflow.gltf", b.finish("overflow", Vec3::ZERO).as_bytes())
}

#[test]
fn cli_nonfinite_pixels_fail_the_render_unless_allowed() {
    let scene = overflowing_lamp_scene();
    let dir = scene.parent().unwrap();
    for method in ["pt", "restir"] {
        let (exr, report) = (dir.join(format!("{method}.exr")), dir.join(format!("{method}.json")));
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--method",
            method,
            "--width",
            "16",
            "--height",
            "16",
            "--out",
            exr.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
        ];
        if method == "pt" {
            args.extend(["--spp", "4"]);
        } else {
            args.extend(["--frames", "1"]);
        }
        assert_clean_failure(&args, &["non-finite pixels", "--allow-nonfinite"]);
        assert!(!exr.exists(), "{method}: an image with non-finite pixels was written");
        let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        assert!(json["nonfinite_pixels"].as_u64().unwrap() > 0, "{method}: report {json}");
        assert!(json.get("nonfinite_weights").is_some(), "{method}: report {json}");
        if method == "restir" {
            // --allow-nonfinite takes the same path for both methods; one run of it suffices.
            continue;
        }
        args.push("--allow-nonfinite");
        let (code, stdout, stderr) = restir_pt(&args);
        assert_eq!(code, 0, "{method} with --allow-nonfinite: {stderr}");
        assert!(
            stderr.contains("warning: frame 0:") && stderr.contains("non-finite pixels"),
            "{stderr}"
        );
        assert!(stdout.contains("non-finite pixels"), "{stdout}");
        let (_, _, pixels) = restir_pt::image_io::read_exr(&exr).unwrap();
        assert!(pixels.iter().any(|p| !p.is_finite()), "{method}: the written image is finite");
    }
}

#[test]
fn cli_render_reports_zero_nonfinite_counts_on_a_clean_scene() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let report = dir.join("clean.json");
    let (code, stdout, stderr) = render_pt(
        16,
        16,
        4,
        &[
            "--out",
            dir.join("clean.exr").to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("non-finite pixels 0, weights 0"), "{stdout}");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(
        (json["nonfinite_pixels"].as_u64(), json["nonfinite_weights"].as_u64()),
        (Some(0), Some(0))
    );
}

// `reference` records which camera its image shows, and `compare` refuses a reference of
// another camera than the one its last frame sees, instead of measuring against it.
#[test]
fn cli_compare_refuses_a_reference_of_another_camera() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let reference = dir.join("ref0.exr");
    let (code, _, stderr) = restir_pt(&[
        "reference",
        "scenes/cornell.gltf",
        "--spp",
        "2",
        "--width",
        "8",
        "--height",
        "8",
        "--camera",
        "0",
        "--out",
        reference.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let record: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("ref0.json")).unwrap()).unwrap();
    assert_eq!(
        (record["camera"].as_u64(), record["scene"].as_str()),
        (Some(0), Some("cornell.gltf"))
    );
    let out = dir.join("cmp");
    // A record of another size beside the image: the two do not belong together.
    let mismatched = dir.join("mismatched.exr");
    std::fs::copy(&reference, &mismatched).unwrap();
    let mut wrong = record.clone();
    wrong["width"] = serde_json::json!(64);
    std::fs::write(dir.join("mismatched.json"), wrong.to_string()).unwrap();
    assert_clean_failure(
        &[
            "compare",
            "scenes/cornell.gltf",
            "--reference",
            mismatched.to_str().unwrap(),
            "--out-dir",
            out.to_str().unwrap(),
        ],
        &["mismatched.exr", "8x8", "64x8", "record"],
    );
    assert_clean_failure(
        &[
            "compare",
            "scenes/cornell.gltf",
            "--reference",
            reference.to_str().unwrap(),
            "--camera-path",
            "--frames",
            "3",
            "--out-dir",
            out.to_str().unwrap(),
        ],
        &["camera 0", "camera 2", "--camera 2"],
    );
    // The static camera 0 matches; the path tracer's frames outnumber the reference's 2 spp.
    let (code, _, stderr) = restir_pt(&[
        "compare",
        "scenes/cornell.gltf",
        "--reference",
        reference.to_str().unwrap(),
        "--methods",
        "pt",
        "--budgets-ms",
        "50",
        "--frames",
        "1",
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("against a reference of 2 spp"), "{stderr}");
}
