//! The restir-pt binary: a render with its summary and JSON report, and bad input that must
//! exit non-zero with one clear line on stderr (never a panic).

use crate::common::{repo_path, temp_file};
use crate::fixtures::cli::{assert_clean_failure, render_pt, restir_pt};

#[test]
fn cli_render_writes_images_summary_and_report() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let (exr, png, report) = (dir.join("c.exr"), dir.join("c.png"), dir.join("r.json"));
    let (code, stdout, stderr) = render_pt(
        32,
        24,
        4,
        &[
            "--validate",
            "--out",
            exr.to_str().unwrap(),
            "--png",
            png.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
        ],
    );
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

/// glTF JSON cut off inside its second object.
const CUT_OFF_JSON: &[u8] = b"{ \"asset\": { \"version\": ";

#[test]
fn cli_bad_input_fails_with_one_clear_line() {
    let missing = "no/such/scene.gltf";
    assert_clean_failure(&["render", missing], &[missing, "cannot read"]);
    let broken = temp_file("broken.gltf", CUT_OFF_JSON);
    assert_clean_failure(&["render", broken.to_str().unwrap()], &["broken.gltf", "invalid glTF"]);
    let truncated = temp_file("truncated.glb", b"glTF\x02\x00\x00\x00\xff\x00\x00\x00");
    assert_clean_failure(&["info", truncated.to_str().unwrap()], &["truncated.glb"]);
    assert_clean_failure(&["render", "--width", "0"], &["--width 0", "at least 1 pixel"]);
    assert_clean_failure(&["bench", "--runs", "0", "--width", "8", "--height", "8"], &["--runs"]);
    assert_clean_failure(&["render", "--width", "100000", "--height", "100000"], &["too large"]);
    assert_clean_failure(&["render", "--method", "pt", "--spp", "0"], &["--spp"]);
    assert_clean_failure(&["render", "--max-depth", "0"], &["--max-depth"]);
    assert_clean_failure(&["render", "--camera", "99"], &["--camera 99"]);
    assert_clean_failure(
        &["render", "--device", "no-such-gpu", "--width", "8", "--height", "8"],
        &["no-such-gpu", "available"],
    );
}

/// A missing scene file, a file that is no glTF and numbers out of range fail before the device
/// opens (no `device:` line): they need no Vulkan, which takes a second or more to start on
/// lavapipe.
#[test]
fn cli_bad_input_fails_before_the_device_opens() {
    let not_gltf = temp_file("notes.gltf", b"# restir-pt\nnot a scene\n");
    let empty = temp_file("empty.gltf", b"  \n");
    let truncated = temp_file("cut.glb", b"glTF\x02\x00\x00\x00\xff\x00\x00\x00");
    for args in [
        &["render", "no/such/scene.gltf"][..],
        &["render", not_gltf.to_str().unwrap()],
        &["render", empty.to_str().unwrap()],
        &["render", truncated.to_str().unwrap()],
        &["render", "--width", "100000", "--height", "100000"],
        &["render", "--width", "0"],
        &["render", "--height", "0"],
        &["render", "--method", "pt", "--spp", "0"],
        &["render", "--max-depth", "0"],
        &["render", "--out", "a.exr", "--png", "a.jpg"],
        &["render", "--out", "a.exr", "--png", "a.exr"],
        &["render", "--out", "a.jpg"],
        &["reference", "scenes/cornell.gltf", "--spp", "4", "--out", "r.png"],
        &["reference", "scenes/cornell.gltf", "--spp", "0", "--out", "r.exr"],
        &["render", "--spatial", "9"],
    ] {
        assert_clean_failure(args, &[]);
        let (_, _, stderr) = restir_pt(args);
        assert!(!stderr.contains("device: "), "{args:?} opened the device first: {stderr}");
    }
}

#[test]
fn cli_max_depth_one_shows_only_emitters() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let exr = dir.join("d1.exr");
    let (code, _, stderr) = render_pt(32, 32, 2, &["--max-depth", "1", "--out", exr.to_str().unwrap()]);
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
    let (code, stdout, stderr) = render_pt(
        16,
        16,
        2,
        &[
            "--frames",
            "3",
            "--camera",
            "2",
            "--validate",
            "--out-dir",
            dir.to_str().unwrap(),
            "--out",
            last.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(stdout.lines().filter(|l| l.starts_with("frame ")).count(), 3, "{stdout}");
    for k in 0..3 {
        assert!(dir.join(format!("frame_{k:04}.exr")).exists() && dir.join(format!("frame_{k:04}.png")).exists());
    }
    // The last frame is also the --out image.
    assert_eq!(std::fs::read(dir.join("frame_0002.exr")).unwrap(), std::fs::read(&last).unwrap());
    // More frames than the scene has cameras walk its camera path back and forth.
    let (code, stdout, stderr) = render_pt(8, 8, 1, &["--frames", "16", "--out", last.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(stdout.lines().filter(|l| l.starts_with("frame ")).count(), 16, "{stdout}");
}

#[test]
fn cli_device_by_index_is_chosen_and_printed() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let out = dir.join("dev.exr");
    let (code, _, stderr) = render_pt(8, 8, 1, &["--device", "0", "--out", out.to_str().unwrap()]);
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
    // Every shift traces its primary ray, and a run of the shift code keeps at least one lane busy.
    let rays = json["restir"]["traversals_per_shift"].as_f64().unwrap();
    let lanes = json["restir"]["shift_lane_use"].as_f64().unwrap();
    assert!((1.0..10.0).contains(&rays), "rays per shift {rays}");
    assert!(lanes > 0.0 && lanes <= 1.0, "lanes busy in shifts {lanes}");
    assert!(
        last.contains("traversals per shift") && last.contains("lanes busy in shifts"),
        "{last}"
    );
    assert!(exr.exists());
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
