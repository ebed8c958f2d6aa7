//! The binary does what its help says: a static path-traced camera averages its frames, flags a
//! method ignores are named in a warning, negative values reach the checks that explain them,
//! the report keeps every frame's time, and `info` counts triangles per material, not per
//! material value.

use glam::Vec3;
use restir_pt::image_io::read_exr;
use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};

use crate::common::temp_file;
use crate::fixtures::cli::{assert_clean_failure, render_pt, restir_pt};

fn s(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}

/// `render --method pt --static-camera --frames 3 --spp 2` is one render of 6 spp: its image
/// matches `--spp 6` to float rounding (the same samples, summed in other chunks), and not the
/// last frame's 2 spp alone, which differs from it by the noise of 4 spp.
#[test]
fn cli_static_camera_path_tracing_averages_its_frames() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let render = |name: &str, extra: &[&str]| {
        let (exr, report) = (dir.join(format!("{name}.exr")), dir.join(format!("{name}.json")));
        let mut args = vec![
            "render",
            "--method",
            "pt",
            "--width",
            "16",
            "--height",
            "16",
            "--out",
            s(&exr),
            "--report",
            s(&report),
        ];
        args.extend(extra);
        let (code, stdout, stderr) = restir_pt(&args);
        assert_eq!(code, 0, "{stderr}");
        let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        (read_exr(&exr).unwrap().2, stdout, json)
    };
    let (averaged, stdout, json) = render("static", &["--static-camera", "--frames", "3", "--spp", "2"]);
    let (whole, _, _) = render("whole", &["--spp", "6"]);
    let (single, _, _) = render("single", &["--spp", "2"]);
    let largest_gap = |a: &[Vec3], b: &[Vec3]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| ((*x - *y).abs() / y.abs().max(Vec3::splat(1e-3))).max_element())
            .fold(0.0f32, f32::max)
    };
    assert!(
        largest_gap(&averaged, &whole) < 1e-4,
        "static frames vs one 6-spp render: {}",
        largest_gap(&averaged, &whole)
    );
    assert!(largest_gap(&averaged, &single) > 0.05, "the average is the last frame alone");
    assert!(stdout.lines().last().unwrap().contains("| 6 spp |"), "{stdout}");
    let times = json["frame_gpu_ms"].as_array().unwrap();
    assert_eq!(times.len(), 3, "{json}");
    let mut sorted: Vec<f64> = times.iter().map(|t| t.as_f64().unwrap()).collect();
    sorted.sort_by(f64::total_cmp);
    assert_eq!(json["median_gpu_ms"].as_f64().unwrap(), sorted[1], "{json}");
    assert_eq!(json["spp"].as_u64().unwrap(), 6, "{json}");
}

/// ReSTIR-only flags with the path tracer, and Russian roulette or --spp given to ReSTIR PT, are
/// named in a warning; the frame line of ReSTIR PT gives the non-finite counts once.
#[test]
fn cli_flags_the_method_ignores_are_named() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let out = dir.join("ignored.exr");
    let tiny = ["--width", "8", "--height", "8", "--out", s(&out)];
    let (code, _, stderr) = restir_pt(
        &[
            &["render", "--method", "pt", "--spp", "1", "--shift", "replay", "--spatial", "0"],
            &tiny[..],
        ]
        .concat(),
    );
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("warning: --method pt ignores the ReSTIR PT options --shift replay, --spatial 0"),
        "{stderr}"
    );
    let (code, _, stderr) = restir_pt(&[&["render", "--method", "pt", "--spp", "1", "--shift", "hybrid"], &tiny[..]].concat());
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("warning"), "a default value is no reason to warn: {stderr}");
    // --spp is ignored by ReSTIR PT, even a value the path tracer refuses; --russian-roulette
    // is not (its initial candidates use it).
    let (code, stdout, stderr) = restir_pt(&[&["render", "--russian-roulette", "off", "--spp", "0", "--frames", "2"], &tiny[..]].concat());
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("--russian-roulette"), "{stderr}");
    assert!(stderr.contains("warning: --spp is ignored by ReSTIR PT"), "{stderr}");
    let line = stdout.lines().find(|l| l.starts_with("frame 1 | ")).expect("a line per frame");
    assert_eq!(line.matches("non-finite").count(), 1, "{line}");
    assert!(line.contains("non-finite pixels 0, weights 0"), "{line}");
}

/// Negative numbers are taken as values, so that the command's own check or clap's value parser
/// explains what is wrong with them (clap took `-1,0,0` and `-1` for flags), and a negative EV
/// works.
#[test]
fn cli_negative_values_are_values() {
    let out = temp_file("placeholder", b"").parent().unwrap().join("negative.exr");
    let (code, _, stderr) = restir_pt(&["render", "--env", "-1,0,0", "--frames", "0"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("non-negative") && !stderr.contains("unexpected argument"),
        "{stderr}"
    );
    assert_clean_failure(&["render", "--radius", "-3"], &["--radius -3"]);
    // An unsigned option given a negative number names the option and the value.
    let (code, _, stderr) = restir_pt(&["render", "--frames", "-1"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("invalid value '-1' for '--frames") && !stderr.contains("unexpected argument"),
        "{stderr}"
    );
    assert_clean_failure(
        &["compare", "scenes/cornell.gltf", "--reference", "x.exr", "--budgets-ms", "-5"],
        &["--budgets-ms -5"],
    );
    let (code, _, stderr) = render_pt(8, 8, 1, &["--exposure", "-2", "--out", s(&out)]);
    assert_eq!(code, 0, "{stderr}");
}

/// Two glTF materials of equal parameters are two materials: `info` counts each one's own
/// triangles (2 and 12) instead of both materials' (14 each).
#[test]
fn cli_info_counts_triangles_of_identical_materials_apart() {
    let mut b = GltfBuilder::default();
    let left = b.material("left grey", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let right = b.material("right grey", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let lamp = b.material("lamp", MaterialSpec::emitter(Vec3::splat(4.0)));
    let quad = b.mesh(
        "quad",
        &MeshData::quad(Vec3::new(-1.0, 0.0, -1.0), Vec3::Z * 2.0, Vec3::X * 2.0),
        left,
    );
    b.instance("quad", quad, 0.0, Vec3::ZERO);
    let cube = b.mesh("cube", &MeshData::cuboid(Vec3::splat(-0.2), Vec3::splat(0.2)), right);
    b.instance("cube", cube, 0.0, Vec3::ZERO);
    let light = b.mesh(
        "lamp",
        &MeshData::quad(Vec3::new(-0.3, 1.0, -0.3), Vec3::X * 0.6, Vec3::Z * 0.6),
        lamp,
    );
    b.instance("lamp", light, 0.0, Vec3::ZERO);
    b.camera("camera", Vec3::new(0.0, 0.5, 3.0), Vec3::ZERO, 0.9);
    let scene = temp_file("twins.gltf", b.finish("twins", Vec3::ZERO).as_bytes());
    let (code, stdout, stderr) = restir_pt(&["info", s(&scene)]);
    assert_eq!(code, 0, "{stderr}");
    let count = |name: &str| {
        let line = stdout
            .lines()
            .find(|l| l.trim_start().starts_with(name))
            .unwrap_or_else(|| panic!("{name}: {stdout}"));
        line.rsplit_once('(')
            .unwrap()
            .1
            .split_whitespace()
            .next()
            .unwrap()
            .parse::<usize>()
            .unwrap()
    };
    assert_eq!((count("left grey:"), count("right grey:"), count("lamp:")), (2, 12, 2), "{stdout}");
}

/// `--out image.png` would have the PNG preview overwrite the EXR: refused with one line, before
/// the device opens.
#[test]
fn cli_out_with_a_png_name_is_refused() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let out = dir.join("image.png");
    let (code, stdout, stderr) = render_pt(8, 8, 1, &["--out", s(&out)]);
    assert_eq!(code, 1, "{stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    assert!(errors[0].contains("image.png") && errors[0].contains("overwrite"), "{stderr}");
    assert!(
        !stdout.contains("device:") && !stderr.contains("device:"),
        "checked before the device opens: {stderr}"
    );
}

/// `--out` into a folder that does not exist creates it and says so on stderr.
#[test]
fn cli_out_into_a_missing_folder_creates_it_with_a_note() {
    let dir = temp_file("placeholder", b"").parent().unwrap().join("missing-folder");
    let _ = std::fs::remove_dir_all(&dir);
    let out = dir.join("nested").join("image.exr");
    let (code, _, stderr) = render_pt(8, 8, 1, &["--out", s(&out)]);
    assert_eq!(code, 0, "{stderr}");
    assert!(out.exists(), "{stderr}");
    let folder = out.parent().unwrap().display().to_string();
    assert!(stderr.contains(&format!("note: created the folder {folder}")), "{stderr}");
}

/// Each output file is named for the format written into it, and the error names the option at
/// fault.
#[test]
fn cli_output_names_must_match_their_formats() {
    assert_clean_failure(
        &["render", "--out", "a.exr", "--png", "a.jpg"],
        &["--png a.jpg", "PNG", ".png name"],
    );
    assert_clean_failure(
        &["render", "--out", "a.exr", "--png", "a.exr"],
        &["--png a.exr", "same file as --out"],
    );
    assert_clean_failure(&["render", "--out", "a.jpg"], &["--out a.jpg", "OpenEXR", ".exr name"]);
    assert_clean_failure(&["render", "--variance", "v.png"], &["--variance v.png", ".exr name"]);
    assert_clean_failure(
        &["reference", "scenes/cornell.gltf", "--spp", "4", "--out", "r.png"],
        &["--out r.png", "OpenEXR"],
    );
    assert_clean_failure(&["merge", "a.exr", "--out", "m.png"], &["--out m.png", "OpenEXR"]);
    assert_clean_failure(
        &["reference", "scenes/cornell.gltf", "--spp", "0", "--out", "r.exr"],
        &["--spp must be at least 1"],
    );
}
