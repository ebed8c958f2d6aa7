//! What the command line makes of files as exporters write them: warnings printed before a
//! load error, the default camera in `info`, the camera's aspect ratio and the PNG preview's
//! automatic exposure.

use glam::Vec3;

use crate::common::repo_path;
use crate::fixtures::cli::restir_pt;
use crate::fixtures::corpus;

#[test]
fn real_scenes_cli_prints_warnings_before_a_load_error_and_info_describes_defaulted_files() {
    let path = corpus("warnings-then-error.gltf");
    let (code, _, stderr) = restir_pt(&["info", path.to_str().unwrap()]);
    assert_eq!(code, 1);
    let lines: Vec<&str> = stderr.lines().collect();
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("warning:") && l.contains("animation(s) ignored")),
        "{stderr}"
    );
    assert_eq!(lines.iter().filter(|l| l.starts_with("error:")).count(), 1, "{stderr}");
    let path = corpus("no-camera.gltf");
    let (code, stdout, stderr) = restir_pt(&["info", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("default camera") && stdout.contains("cameras: 1"), "{stdout}");
}

#[test]
fn real_scenes_camera_aspect_ratio_sets_the_missing_side_and_is_fitted_otherwise() {
    let mut c = restir_pt::scene::Camera::look_at("c", Vec3::Z, Vec3::ZERO, Vec3::Y, 0.8);
    assert_eq!(c.image_size(None, None), (256, 256));
    assert_eq!(c.image_size(Some(100), None), (100, 256));
    c.aspect_ratio = Some(2.0);
    assert_eq!(c.image_size(Some(200), None), (200, 100));
    assert_eq!(c.image_size(None, Some(50)), (100, 50));
    assert_eq!(c.image_size(Some(64), Some(64)), (64, 64));
    let t = (0.4f32).tan();
    // Wider than 2:1: yfov kept. Square: the camera's horizontal extent (2 tan) fits the width.
    assert_eq!(c.tan_half_fov(400, 100), t);
    assert!((c.tan_half_fov(64, 64) - 2.0 * t).abs() < 1e-6);
    // The twin of the GLSL camera ray uses the same fitted field of view: a ray through the
    // right edge of a square image leaves at the camera's horizontal half-angle.
    let d = c.ray_dir(64.0, 32.0, 64, 64);
    assert!((d.dot(c.right) / d.dot(c.forward) - 2.0 * t).abs() < 1e-5);
}

#[test]
fn real_scenes_auto_exposure_maps_the_log_average_to_middle_grey() {
    use restir_pt::image_io::{auto_exposure_ev, AUTO_EXPOSURE_KEY};
    let dark = vec![Vec3::splat(0.004); 16];
    let ev = auto_exposure_ev(&dark);
    assert!((0.004f32 + 1e-4) * ev.exp2() - AUTO_EXPOSURE_KEY < 1e-4, "{ev}");
    assert!((ev - (0.18f32 / 0.0041).log2()).abs() < 1e-3, "{ev}");
    assert_eq!(auto_exposure_ev(&[Vec3::ZERO; 4]), 0.0);
    assert_eq!(auto_exposure_ev(&[Vec3::NAN; 4]), 0.0);
}

#[test]
fn real_scenes_cli_width_alone_follows_the_aspect_ratio_and_exposure_is_printed() {
    let path = repo_path("../shared/assets/Cameras/Cameras.gltf");
    if !path.exists() {
        eprintln!("note: {} is absent; test skipped", path.display());
        return;
    }
    let dir = crate::common::temp_file("placeholder", b"").parent().unwrap().join("aspect");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("cameras.exr");
    let args = [
        "render",
        path.to_str().unwrap(),
        "--method",
        "pt",
        "--spp",
        "2",
        "--width",
        "24",
        "--out",
        out.to_str().unwrap(),
    ];
    let (code, _, stderr) = restir_pt(&args);
    assert_eq!(code, 0, "{stderr}");
    // The file's camera has aspectRatio 1: 24 x 24.
    let (w, h, pixels) = restir_pt::image_io::read_exr(&out).unwrap();
    assert_eq!((w, h), (24, 24));
    assert!(pixels.iter().all(|p| p.is_finite()));
    assert!(
        stderr.contains("PNG preview: exposure") && stderr.contains("(automatic"),
        "{stderr}"
    );
}
