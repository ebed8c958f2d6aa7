//! A new user's first run: only the kernels a run dispatches are built at start-up, with the
//! same images as a renderer built with every kernel; `render` without --frames averages
//! unmoved-camera frames until their GPU time reaches --time; without a scene it renders the
//! Cornell box built into the binary, from any folder.

use std::process::Command;
use std::sync::Arc;

use restir_pt::render::{PassKernel, Restir, RestirSettings, SceneGpu};
use restir_pt::scene::load_scene;
use restir_pt::vk::{set_twin_compile, twin_compile_pays, Context, ContextOptions, TwinCompile, TWIN_COMPILE_ENV};

use crate::common::{assert_clean, gpu, repo_path, temp_file};
use crate::fixtures::unbiasedness::settings;

#[test]
fn restir_kernels_for_cameras_are_those_the_frames_dispatch() {
    use PassKernel::*;
    let restir = RestirSettings::default();
    assert_eq!(restir.kernels_for_cameras(&[0]), [Initial, Spatial, Shade]);
    assert_eq!(restir.kernels_for_cameras(&[2, 2]), [Initial, TemporalUnmoved, Spatial, Shade]);
    assert_eq!(restir.kernels_for_cameras(&[0, 1, 2, 1]), [Initial, Temporal, Spatial, Shade]);
    assert_eq!(
        restir.kernels_for_cameras(&[0, 0, 1]),
        [Initial, TemporalUnmoved, Temporal, Spatial, Shade]
    );
    let no_reuse = RestirSettings {
        temporal: false,
        spatial: 0,
        ..RestirSettings::default()
    };
    assert_eq!(no_reuse.kernels_for_cameras(&[0, 0, 1]), [Initial, Shade]);
}

// A renderer built with two kernels builds the others when a frame first needs them, and its
// frames equal, bit for bit, those of a renderer built with all five at start-up: a still
// camera (the unmoved temporal pass), then a moving one (the shifting temporal pass).
#[test]
fn restir_kernels_built_on_demand_render_the_same_frames_bit_for_bit() {
    let ctx = gpu();
    let (scene, small) = small_scene(&ctx, "cornell", 24, 16);
    let restir = RestirSettings::default();
    let mut every = Restir::new(&scene, &small, &restir).unwrap();
    let expected = frame_bits(&mut every);
    let before = ctx.pipelines_created();
    let mut lazy = Restir::with_kernels(&scene, &small, &restir, &[PassKernel::Initial, PassKernel::Shade], &|_| {}).unwrap();
    assert_eq!(ctx.pipelines_created() - before, 2, "start-up built other kernels");
    assert_eq!(lazy.compile_reports().len(), 2);
    let got = frame_bits(&mut lazy);
    assert_eq!(ctx.pipelines_created() - before, 5, "the frames built kernels twice or not at all");
    assert_same_frames(&got, &expected);
    let names: Vec<String> = lazy.compile_reports().iter().map(|k| k.name.clone()).collect();
    assert!(names.iter().any(|n| n.contains("unmoved")), "{names:?}");
    assert!(lazy.compile_ms() > 0.0 && lazy.compile_cpu_ms() > 0.0);
    drop((every, lazy, scene));
    assert_clean(&ctx);
}

/// Bundled scene `name` uploaded to `ctx`, and settings of a `width` x `height` image of it.
fn small_scene(ctx: &Arc<Context>, name: &str, width: u32, height: u32) -> (Arc<SceneGpu>, restir_pt::render::RenderSettings) {
    let scene = load_scene(&repo_path(&format!("scenes/{name}.gltf"))).unwrap();
    let settings = restir_pt::render::RenderSettings {
        width,
        height,
        ..settings(1)
    };
    (SceneGpu::upload(ctx, &scene).unwrap(), settings)
}

/// The average's bits after each of five frames: three of a still camera (the unmoved
/// temporal pass), then two moving (the shifting temporal pass).
fn frame_bits(renderer: &mut Restir) -> Vec<Vec<u32>> {
    let poses = [(0, true), (0, true), (0, true), (1, false), (2, false)];
    poses
        .iter()
        .map(|&(camera, accumulate)| {
            renderer.frame(camera, accumulate).unwrap();
            let image = renderer.image().unwrap();
            image.mean.iter().flat_map(|v| v.to_array().map(f32::to_bits)).collect()
        })
        .collect()
}

fn assert_same_frames(got: &[Vec<u32>], expected: &[Vec<u32>]) {
    for (frame, (g, e)) in got.iter().zip(expected).enumerate() {
        let differing = g.iter().zip(e).filter(|(a, b)| a != b).count();
        assert_eq!(differing, 0, "frame {frame}: {differing} of {} values differ", g.len());
    }
}

// Kernels warmed up on a twin device (crates/vk/src/twin_compile.rs) while the renderer's device
// compiles the others: the renderer still creates and dispatches every kernel itself, and its
// frames equal, bit for bit, those of a renderer built without a twin. The twin runs only on
// unvalidated CPU devices with a second core (the validation layer of Debian 12 races between
// devices on two threads).
#[test]
fn restir_kernels_warmed_up_on_a_twin_device_render_the_same_frames_bit_for_bit() {
    assert!(!twin_compile_pays(&gpu(), false), "a validated device must not get a twin");
    let ctx = Arc::new(Context::new(&ContextOptions::default()).unwrap());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cpu_device = ctx.info.device_type == ash::vk::PhysicalDeviceType::CPU;
    let mesa_cache_off = std::env::var("MESA_SHADER_CACHE_DISABLE").is_ok_and(|v| v == "true" || v == "1");
    let expected_twin = cpu_device && cores >= 2 && !mesa_cache_off && std::env::var(TWIN_COMPILE_ENV).map_or(true, |v| v != "0");
    assert_eq!(
        twin_compile_pays(&ctx, false),
        expected_twin,
        "{} with {cores} cores",
        ctx.info.name
    );
    let (scene, small) = small_scene(&ctx, "cornell-glossy", 20, 12);
    let restir = RestirSettings::default();
    set_twin_compile(TwinCompile::Off);
    let alone = Restir::new(&scene, &small, &restir);
    // The kernels' SPIR-V now comes from the process's cache, which WhenCold takes for a warm
    // driver cache.
    set_twin_compile(TwinCompile::Always);
    let expected = frame_bits(&mut alone.unwrap());
    let mut twinned = Restir::new(&scene, &small, &restir).unwrap();
    assert_eq!(twinned.compile_reports().len(), PassKernel::ALL.len());
    let warmed = twinned.twin_warmed_kernels();
    let expected_warmed = if expected_twin { 1..PassKernel::ALL.len() } else { 0..1 };
    assert!(expected_warmed.contains(&warmed), "{warmed} kernels warmed on the twin");
    set_twin_compile(TwinCompile::WhenCold);
    if std::env::var(TWIN_COMPILE_ENV).is_err() {
        assert!(
            !twin_compile_pays(&ctx, true),
            "kernels whose SPIR-V was cached must not get a twin"
        );
    }
    assert_same_frames(&frame_bits(&mut twinned), &expected);
}

/// Runs the binary in the folder `dir`.
fn restir_pt_in(dir: &std::path::Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_restir-pt"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.code().unwrap_or(-1), text(&out.stdout), text(&out.stderr))
}

fn report(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

// Without --frames, ReSTIR PT renders frames until their GPU time reaches the budget: the
// last frame is the one that reaches it (the frames before it stay under), one summary line
// is printed, and --frames keeps its exact count.
#[test]
fn cli_render_without_frames_accumulates_to_its_time_budget() {
    let dir = temp_file("placeholder", b"").parent().unwrap().to_path_buf();
    let scene = repo_path("scenes/cornell.gltf");
    let scene = scene.to_str().unwrap();
    let json = dir.join("budget.json");
    let size = ["--width", "16", "--height", "16", "--validate"];
    let mut args = vec!["render", scene, "--time", "0.25", "--report", json.to_str().unwrap()];
    args.extend(size);
    let (code, stdout, stderr) = restir_pt_in(&dir, &args);
    assert_eq!(code, 0, "{stderr}");
    let r = report(&json);
    assert_eq!(r["time_budget_ms"].as_f64(), Some(250.0), "{r}");
    let frame_ms: Vec<f64> = r["frame_gpu_ms"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let total: f64 = frame_ms.iter().sum();
    let before_last: f64 = frame_ms[..frame_ms.len() - 1].iter().sum();
    assert!(before_last < 250.0 && total >= 250.0, "frame GPU ms {frame_ms:?}");
    assert_eq!(stdout.lines().filter(|l| l.contains("restir:")).count(), 1, "{stdout}");
    let frames = format!("{} frames", frame_ms.len());
    assert!(frame_ms.len() == 1 || stderr.contains(&frames), "{stderr}");
    assert!(stderr.contains("start-up: 4 kernel(s)"), "{stderr}");

    let mut args = vec!["render", scene, "--frames", "3", "--report", json.to_str().unwrap()];
    args.extend(size);
    let (code, stdout, stderr) = restir_pt_in(&dir, &args);
    assert_eq!(code, 0, "{stderr}");
    let r = report(&json);
    assert_eq!(r["frame_gpu_ms"].as_array().unwrap().len(), 3, "{r}");
    assert!(r.get("time_budget_ms").is_none(), "{r}");
    assert_eq!(stdout.lines().filter(|l| l.starts_with("frame ")).count(), 3, "{stdout}");
    // Three frames along the camera path: no frame keeps its camera.
    assert!(stderr.contains("start-up: 4 kernel(s)"), "{stderr}");
}

// `cargo install` copies the binary alone: without a scene it renders the Cornell box built
// into it, from a folder with no scenes/ in it, and names the outputs after it.
#[test]
fn cli_render_without_a_scene_uses_the_built_in_cornell_box_in_any_folder() {
    let dir = temp_file("placeholder", b"").parent().unwrap().join("elsewhere");
    std::fs::create_dir_all(&dir).unwrap();
    let (code, _, stderr) = restir_pt_in(&dir, &["render", "--frames", "1", "--width", "8", "--height", "8"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("built-in Cornell box"), "{stderr}");
    let (w, h, pixels) = restir_pt::image_io::read_exr(&dir.join("out/cornell.exr")).unwrap();
    assert_eq!((w, h), (8, 8));
    assert!(pixels.iter().all(|p| p.is_finite()) && pixels.iter().any(|p| p.max_element() > 0.0));
    let written = stderr
        .lines()
        .find_map(|l| l.split_once("written to ").and_then(|(_, p)| p.split_once(");")).map(|(p, _)| p))
        .unwrap_or_else(|| panic!("no path of the built-in scene in {stderr}"));
    assert!(!std::path::Path::new(written).starts_with(&dir), "{written}");
    assert_eq!(
        std::fs::read(written).unwrap(),
        std::fs::read(repo_path("scenes/cornell.gltf")).unwrap()
    );
    let (code, stdout, stderr) = restir_pt_in(&dir, &["info"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("triangles: 36"), "{stdout}");
}
