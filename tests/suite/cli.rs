//! The restir-pt binary: a render with its summary and JSON report, and bad input that must
//! exit non-zero with one clear line on stderr (never a panic).

use std::process::Command;

use crate::common::{repo_path, temp_file};

pub(crate) fn restir_pt(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_restir-pt"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Exit code 1 and exactly one `error:` line that mentions every `needle`.
pub(crate) fn assert_clean_failure(args: &[&str], needles: &[&str]) {
    let (code, _, stderr) = restir_pt(args);
    assert_eq!(code, 1, "{args:?} should fail; stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{args:?}: expected one error line, got: {stderr}");
    for n in needles {
        assert!(errors[0].contains(n), "{args:?}: error line {:?} does not mention {n:?}", errors[0]);
    }
}

#[test]
fn cli_render_writes_images_summary_and_report() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let (exr, png, report) = (dir.join("c.exr"), dir.join("c.png"), dir.join("r.json"));
    let (code, stdout, stderr) = restir_pt(&[
        "render",
        "--width",
        "32",
        "--height",
        "24",
        "--method",
        "pt",
        "--spp",
        "4",
        "--validate",
        "--out",
        exr.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("device: "), "the chosen device is printed: {stderr}");
    assert!(
        stdout.contains("32x24 | 4 spp") && stdout.contains("M paths/s"),
        "summary line: {stdout}"
    );
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    for key in [
        "device",
        "width",
        "height",
        "spp",
        "max_depth",
        "gpu_ms",
        "wall_ms",
        "paths_per_second",
    ] {
        assert!(json.get(key).is_some(), "report lacks {key}: {json}");
    }
    assert_eq!(json["width"], 32);
    let (w, h, pixels) = restir_pt::image_io::read_exr(&exr).unwrap();
    assert_eq!((w, h), (32, 24));
    assert!(pixels.iter().all(|p| p.is_finite()) && pixels.iter().any(|p| p.max_element() > 0.0));
    assert!(std::fs::metadata(&png).unwrap().len() > 100);
}

#[test]
fn cli_info_describes_the_default_scene() {
    let (code, stdout, stderr) = restir_pt(&["info", repo_path("scenes/cornell.gltf").to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("triangles: 36") && stdout.contains("emitters: 2 triangles") && stdout.contains("cameras: 8"),
        "{stdout}"
    );
}

#[test]
fn cli_bad_input_fails_with_one_clear_line() {
    let missing = "no/such/scene.gltf";
    assert_clean_failure(&["render", missing], &[missing, "cannot read"]);
    let broken = temp_file("broken.gltf", b"{ \"asset\": { \"version\": ");
    assert_clean_failure(&["render", broken.to_str().unwrap()], &["broken.gltf", "invalid glTF"]);
    let truncated = temp_file("truncated.glb", b"glTF\x02\x00\x00\x00\xff\x00\x00\x00");
    assert_clean_failure(&["info", truncated.to_str().unwrap()], &["truncated.glb"]);
    assert_clean_failure(&["render", "--width", "0"], &["resolution 0x256"]);
    assert_clean_failure(&["render", "--width", "100000", "--height", "100000"], &["too large"]);
    assert_clean_failure(&["render", "--method", "pt", "--spp", "0"], &["--spp"]);
    assert_clean_failure(&["render", "--max-depth", "0"], &["--max-depth"]);
    assert_clean_failure(&["render", "--camera", "99"], &["--camera 99"]);
    assert_clean_failure(
        &["render", "--device", "no-such-gpu", "--width", "8", "--height", "8"],
        &["no-such-gpu", "available"],
    );
}

#[test]
fn cli_max_depth_one_shows_only_emitters() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let exr = dir.join("d1.exr");
    let (code, _, stderr) = restir_pt(&[
        "render",
        "--width",
        "32",
        "--height",
        "32",
        "--method",
        "pt",
        "--spp",
        "2",
        "--max-depth",
        "1",
        "--out",
        exr.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let (_, _, pixels) = restir_pt::image_io::read_exr(&exr).unwrap();
    let lit = pixels.iter().filter(|p| p.max_element() > 0.0).count();
    assert!(
        lit > 0 && lit < pixels.len() / 10,
        "{lit} lit pixels: depth 1 must show only the ceiling light"
    );
    // Lit pixels see the light's radiance (17, 12, 4), scaled by the pixel's light coverage.
    assert!(pixels
        .iter()
        .all(|p| p.max_element() == 0.0 || ((p.x / p.z - 17.0 / 4.0).abs() < 1e-3 && p.x <= 17.0 + 1e-3)));
}

#[test]
fn cli_frames_render_along_the_camera_path() {
    let dir = temp_file("placeholder", b"").parent().unwrap().join("frames");
    let last = dir.join("last.exr");
    let (code, stdout, stderr) = restir_pt(&[
        "render",
        "--frames",
        "3",
        "--camera",
        "2",
        "--width",
        "16",
        "--height",
        "16",
        "--method",
        "pt",
        "--spp",
        "2",
        "--validate",
        "--out-dir",
        dir.to_str().unwrap(),
        "--out",
        last.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(stdout.lines().filter(|l| l.starts_with("frame ")).count(), 3, "{stdout}");
    for k in 0..3 {
        assert!(dir.join(format!("frame_{k:04}.exr")).exists() && dir.join(format!("frame_{k:04}.png")).exists());
    }
    // The last frame is also the --out image.
    assert_eq!(std::fs::read(dir.join("frame_0002.exr")).unwrap(), std::fs::read(&last).unwrap());
    // More frames than the scene has cameras walk its camera path back and forth.
    let (code, stdout, stderr) = restir_pt(&[
        "render",
        "--frames",
        "16",
        "--width",
        "8",
        "--height",
        "8",
        "--method",
        "pt",
        "--spp",
        "1",
        "--out",
        last.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(stdout.lines().filter(|l| l.starts_with("frame ")).count(), 16, "{stdout}");
}

#[test]
fn cli_device_by_index_is_chosen_and_printed() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let out = dir.join("dev.exr");
    let (code, _, stderr) = restir_pt(&[
        "render",
        "--device",
        "0",
        "--width",
        "8",
        "--height",
        "8",
        "--method",
        "pt",
        "--spp",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.lines().any(|l| l.starts_with("device: ")), "{stderr}");
}

#[test]
fn cli_restir_render_prints_passes_and_failed_shifts() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let (exr, report) = (dir.join("restir.exr"), dir.join("restir.json"));
    let (code, stdout, stderr) = restir_pt(&[
        "render",
        "--width",
        "16",
        "--height",
        "16",
        "--frames",
        "2",
        "--shift",
        "reconnection",
        "--mis",
        "pairwise",
        "--spatial",
        "2",
        "--validate",
        "--out",
        exr.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let last = stdout.lines().find(|l| l.starts_with("frame 1 | ")).expect("a line per frame");
    for needle in [
        "restir:reconnection/pairwise",
        "initial",
        "temporal",
        "spatial",
        "shade",
        "failed shifts",
        "non-finite pixels 0",
    ] {
        assert!(last.contains(needle), "{needle} missing: {last}");
    }
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    // --spatial 2 is not the default, so the label names it.
    assert_eq!(json["method"], "restir:reconnection/pairwise@s2");
    assert!(json["restir"]["shifts_attempted"].as_u64().unwrap() > 0, "{json}");
    assert!(exr.exists());
    assert_clean_failure(&["render", "--spp", "4"], &["--spp", "ReSTIR"]);
    assert_clean_failure(&["render", "--max-depth", "8"], &["--max-depth 8", "at most 7"]);
    assert_clean_failure(&["render", "--spatial", "9"], &["--spatial 9"]);
    assert_clean_failure(&["render", "--rounds", "4"], &["--rounds 4"]);
    assert_clean_failure(&["render", "--m-cap", "NaN"], &["--m-cap"]);
    assert_clean_failure(&["render", "--emission-rays", "0"], &["--emission-rays 0", "1 to 64"]);
    assert_clean_failure(&["render", "--reservoirs", "0"], &["--reservoirs 0", "1 to 16"]);
    assert_clean_failure(
        &["render", "--width", "2048", "--height", "2048", "--reservoirs", "16"],
        &["16 reservoir(s) per pixel", "maxStorageBufferRange"],
    );
}

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
        "--out-dir",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 4, "{csv}");
    for row in &rows {
        let rel_mse: f64 = row[4].parse().unwrap();
        let gpu_ms: f64 = row[3].parse().unwrap();
        let trimmed: f64 = row[5].parse().unwrap();
        assert!(rel_mse.is_finite() && rel_mse > 0.0 && gpu_ms > 0.0, "{row:?}");
        assert!(trimmed > 0.0 && trimmed <= rel_mse, "trimmed relMSE: {row:?}");
        assert_eq!(row[9], "0", "non-finite pixels: {row:?}");
    }
    // A larger budget buys the path tracer more samples per frame.
    let spp = |r: &Vec<&str>| r[2].trim_start_matches("spp=").parse::<u32>().unwrap();
    assert!(rows[0][0] == "pt" && rows[1][0] == "pt" && spp(&rows[1]) > spp(&rows[0]), "{csv}");
    assert!(rows[2][2].starts_with("reservoirs="), "{csv}");
    assert!(stdout.contains("equal time 200.0 ms, relMSE: pt"), "{stdout}");
    assert!(stdout.contains("equal time 200.0 ms, trimmed relMSE: pt"), "{stdout}");
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
    let (code, stdout, stderr) = restir_pt(&[
        "render",
        "--width",
        "16",
        "--height",
        "16",
        "--method",
        "pt",
        "--spp",
        "4",
        "--out",
        dir.join("clean.exr").to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
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
