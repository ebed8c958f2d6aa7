//! Bad input, limits and faults: never a panic, a hang, a device loss or a silently wrong image.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use restir_pt::error::{vk_error, GpuError};
use restir_pt::render::{PathTracer, RenderSettings, SceneGpu};
use restir_pt::scene::{load_scene, load_scene_from_bytes};
use restir_pt::vk::{Buffer, BufferUsage};

use crate::common::{assert_clean, gpu, repo_path, temp_file};

const BIN: &str = env!("CARGO_BIN_EXE_restir-pt");

/// Runs the binary with a deadline: a hang is a failure, not a stuck suite.
fn run_with_deadline(args: &[&str], deadline: Duration) -> (i32, String) {
    let mut child = Command::new(BIN)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut stderr = String::new();
            std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut stderr).unwrap();
            return (status.code().unwrap_or(-1), stderr);
        }
        if start.elapsed() > deadline {
            child.kill().unwrap();
            panic!("{args:?} hung for {deadline:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// `render` of `path` with the path tracer at 16 x 16 and 1 spp into `out`, within 60 s: the
/// exit code and stderr.
fn render_one_spp(path: &Path, out: &Path) -> (i32, String) {
    let args = [
        "render",
        path.to_str().unwrap(),
        "--width",
        "16",
        "--height",
        "16",
        "--method",
        "pt",
        "--spp",
        "1",
    ];
    run_with_deadline(&[&args[..], &["--out", out.to_str().unwrap()]].concat(), Duration::from_secs(60))
}

/// The one `error:` line of `stderr`, of input `what`.
fn the_error_line<'a>(what: &str, stderr: &'a str) -> &'a str {
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{what}: {stderr}");
    errors[0]
}

/// A .bin shorter than its buffer's byteLength: one error line naming the glTF, the buffer's
/// file and both sizes (the gltf crate's own message names neither file).
#[test]
fn robustness_truncated_external_buffer_names_its_file() {
    let gltf = std::fs::read_to_string(repo_path("tests/data/bad/missing-bin.gltf")).unwrap();
    assert!(gltf.contains("missing.bin"));
    let path = temp_file("short-bin.gltf", gltf.replace("missing.bin", "short.bin").as_bytes());
    std::fs::write(path.with_file_name("short.bin"), [0u8; 12]).unwrap();
    let (code, stderr) = render_one_spp(&path, &path.with_file_name("short.exr"));
    assert_eq!(code, 1, "{stderr}");
    let error = the_error_line("short-bin.gltf", &stderr);
    assert!(
        error.contains("short-bin.gltf") && error.contains("\"short.bin\" holds 12 bytes") && error.contains("byteLength"),
        "{error}"
    );
}

#[test]
fn robustness_bad_input_corpus_gives_clear_errors_or_warnings() {
    let dir = repo_path("tests/data/bad");
    let expected = std::fs::read_to_string(dir.join("expected.txt")).unwrap();
    let rows: Vec<Vec<&str>> = expected
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .map(|l| l.split('\t').collect())
        .collect();
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "expected.txt")
        .collect();
    files.sort();
    assert!(files.len() >= 20, "corpus has only {} files", files.len());
    let out = temp_file("placeholder", b"").parent().unwrap().join("bad.exr");
    for file in &files {
        let row = rows
            .iter()
            .find(|r| r[0] == file)
            .unwrap_or_else(|| panic!("tests/data/bad/{file} has no line in expected.txt"));
        let (outcome, needle) = (row[1], row.get(2).copied().unwrap_or(""));
        let path = dir.join(file);
        let (code, stderr) = render_one_spp(&path, &out);
        assert!(!stderr.contains("panicked") && !stderr.contains("DEVICE_LOST"), "{file}: {stderr}");
        assert!(stderr.contains(needle), "{file}: stderr lacks {needle:?}: {stderr}");
        match outcome {
            "error" => {
                assert_eq!(code, 1, "{file} must fail: {stderr}");
                let error = the_error_line(file, &stderr);
                assert!(error.contains(file.as_str()) && error.contains(needle), "{file}: {error}");
            }
            "warning" | "ok" => {
                assert_eq!(code, 0, "{file} must render: {stderr}");
                if outcome == "warning" {
                    assert!(
                        stderr
                            .lines()
                            .any(|l| l.starts_with("warning:") && l.contains(file.as_str()) && l.contains(needle)),
                        "{file}: {stderr}"
                    );
                }
                let (_, _, pixels) = restir_pt::image_io::read_exr(&out).unwrap();
                assert!(pixels.iter().all(|p| p.is_finite()), "{file}: non-finite pixels");
                let mean = pixels.iter().map(|p| p.element_sum()).sum::<f32>() / (3 * pixels.len()) as f32;
                assert!(mean > 1e-3, "{file}: black image (mean {mean})");
            }
            other => panic!("unknown outcome {other} for {file}"),
        }
    }
    for row in &rows {
        assert!(files.iter().any(|f| f == row[0]), "expected.txt names missing file {}", row[0]);
    }
}

/// Every file in the fuzz corpus, the inputs that once crashed the loader (fuzz/regressions),
/// the bad-input corpus and the bundled scenes goes through the loader without a panic: an error
/// is fine, a crash is not.
#[test]
fn robustness_fuzz_corpus_replays_without_panic() {
    let mut count = 0;
    for dir in ["fuzz/corpus/load_scene", "fuzz/regressions/load_scene", "tests/data/bad", "scenes"] {
        for entry in std::fs::read_dir(repo_path(dir)).unwrap() {
            let path = entry.unwrap().path();
            let bytes = std::fs::read(&path).unwrap();
            let _ = load_scene_from_bytes(&bytes, None, &path);
            count += 1;
        }
    }
    assert!(count >= 40, "only {count} corpus files");
    // Each of these once panicked the loader; each is malformed and must now be refused.
    let mut regressions = 0;
    for entry in std::fs::read_dir(repo_path("fuzz/regressions/load_scene")).unwrap() {
        let path = entry.unwrap().path();
        let bytes = std::fs::read(&path).unwrap();
        assert!(load_scene_from_bytes(&bytes, None, &path).is_err(), "{}: loaded", path.display());
        regressions += 1;
    }
    assert!(regressions >= 4, "only {regressions} crash regressions");
}

fn render_at(width: u32, height: u32) -> anyhow::Result<restir_pt::render::Image> {
    let ctx = gpu();
    let scene = load_scene(&repo_path("scenes/cornell.gltf")).unwrap();
    let settings = RenderSettings {
        width,
        height,
        spp: 2,
        ..Default::default()
    };
    let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, &scene)?, &settings)?;
    tracer.render(&|_| {}, &std::sync::atomic::AtomicBool::new(false))?;
    let image = tracer.image()?;
    drop(tracer);
    assert_clean(&ctx);
    Ok(image)
}

#[test]
fn robustness_odd_resolutions_write_every_pixel() {
    // Unwritten pixels would read NaN (Image::from_sums), so finiteness means every pixel,
    // edges included, received its samples.
    for (w, h) in [(1, 1), (7, 13), (16384, 1), (1, 300)] {
        let image = render_at(w, h).unwrap();
        assert_eq!(image.mean.len(), (w * h) as usize);
        assert_eq!(image.non_finite_count(), 0, "{w}x{h}");
    }
}

#[test]
fn robustness_impossible_resolutions_fail_before_gpu_allocation() {
    for (w, h, needle) in [
        (0, 0, "empty"),
        (0, 16, "empty"),
        (100_000, 100_000, "too large"),
        (70_000, 1, "too large"),
    ] {
        let err = format!("{:#}", render_at(w, h).err().unwrap_or_else(|| panic!("{w}x{h} must fail")));
        assert!(err.contains(needle), "{w}x{h}: {err}");
    }
    // 4096x4096 is allowed by the settings but its accumulation image exceeds lavapipe's
    // 128 MiB storage-binding limit: a typed error naming the limit, before allocating it.
    let ctx = gpu();
    if ctx.info.max_storage_buffer_range < 4096 * 4096 * 16 {
        let err = render_at(4096, 4096).expect_err("binding too large");
        let typed = err.downcast_ref::<GpuError>();
        assert!(matches!(typed, Some(GpuError::BindingTooLarge { .. })), "{err:#}");
        assert!(format!("{err:#}").contains("maxStorageBufferRange"));
    }
}

#[test]
fn robustness_out_of_memory_and_device_loss_are_typed_errors() {
    let ctx = gpu();
    let err = Buffer::new(&ctx, "absurd staging buffer", 1 << 46, BufferUsage::Staging)
        .err()
        .expect("64 TiB cannot be allocated");
    assert!(matches!(err, GpuError::OutOfMemory { .. }), "{err}");
    assert!(err.to_string().contains("absurd staging buffer"));
    let lost = vk_error("a test submission")(ash::vk::Result::ERROR_DEVICE_LOST);
    assert!(matches!(lost, GpuError::DeviceLost { .. }) && lost.to_string().contains("VK_ERROR_DEVICE_LOST"));
    assert_clean(&ctx);
}

#[test]
fn robustness_no_vulkan_object_leaks_at_shutdown() {
    let ctx = gpu();
    let log = ctx.validation_log();
    let scene = load_scene(&repo_path("scenes/cornell.gltf")).unwrap();
    let mut tracer = PathTracer::new(
        &SceneGpu::upload(&ctx, &scene).unwrap(),
        &RenderSettings {
            width: 16,
            height: 16,
            spp: 2,
            ..Default::default()
        },
    )
    .unwrap();
    tracer.render(&|_| {}, &std::sync::atomic::AtomicBool::new(false)).unwrap();
    drop(tracer);
    drop(ctx);
    assert!(log.messages().is_empty(), "{:?}", log.messages());

    // The check can fail: a buffer created behind the wrappers' backs is reported at shutdown.
    let ctx = gpu();
    let log = ctx.validation_log();
    let info = ash::vk::BufferCreateInfo::default()
        .size(64)
        .usage(ash::vk::BufferUsageFlags::STORAGE_BUFFER);
    let _leaked = unsafe { ctx.device.create_buffer(&info, None) }.unwrap();
    drop(ctx);
    assert!(
        log.messages().iter().any(|m| m.contains("VkBuffer")),
        "the leak went unreported: {:?}",
        log.messages()
    );
}

#[test]
fn robustness_ctrl_c_writes_the_partial_image() {
    let out = temp_file("placeholder", b"").parent().unwrap().join("partial.exr");
    let child = Command::new(BIN)
        .args([
            "render",
            "--method",
            "pt",
            "--spp",
            "100000",
            "--width",
            "64",
            "--height",
            "64",
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(2500));
    let status = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(status.success());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    let (_, _, pixels) = restir_pt::image_io::read_exr(&out).unwrap();
    assert!(pixels.iter().all(|p| p.is_finite()) && pixels.iter().any(|p| p.max_element() > 0.0));
}
