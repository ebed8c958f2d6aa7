//! Sweeps beyond one process: reference shards that merge into the one-process reference, and
//! `compare`/`stability` plans run job by job and merged into the one-process results.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::temp_file;

fn restir_pt(args: &[&str]) -> (i32, String, String) {
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

fn ok(args: &[&str]) -> (String, String) {
    let (code, stdout, stderr) = restir_pt(args);
    assert_eq!(code, 0, "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    (stdout, stderr)
}

/// Exit code 1 and one `error:` line mentioning every needle.
fn fails(args: &[&str], needles: &[&str]) {
    let (code, _, stderr) = restir_pt(args);
    assert_eq!(code, 1, "{args:?} should fail: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{args:?}: {stderr}");
    for n in needles {
        assert!(errors[0].contains(n), "{:?} lacks {n:?}", errors[0]);
    }
}

fn fresh_dir(name: &str) -> PathBuf {
    let dir = temp_file("placeholder", b"").parent().unwrap().join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `reference` of cornell at 16x16, 12 spp, seed 7, optionally one shard of it.
fn reference(out: &Path, shard: Option<&str>) -> (String, String) {
    let mut args = vec![
        "reference",
        "scenes/cornell.gltf",
        "--spp",
        "12",
        "--width",
        "16",
        "--height",
        "16",
        "--seed",
        "7",
        "--out",
        s(out),
    ];
    if let Some(shard) = shard {
        args.extend(["--shard", shard]);
    }
    ok(&args)
}

/// |a - b| within `rel` of their magnitude, or both tiny beside `floor`.
fn assert_images_close(what: &str, a: &Path, b: &Path, rel: f32, floor: f32) {
    let (wa, ha, pa) = restir_pt::image_io::read_exr(a).unwrap();
    let (wb, hb, pb) = restir_pt::image_io::read_exr(b).unwrap();
    assert_eq!((wa, ha), (wb, hb), "{what}: sizes");
    let mut worst = 0.0f32;
    for (i, (x, y)) in pa.iter().zip(&pb).enumerate() {
        for c in 0..3 {
            let (x, y) = (x[c], y[c]);
            assert!(x.is_finite() && y.is_finite(), "{what}: pixel {i} not finite");
            let d = (x - y).abs();
            worst = worst.max(d / x.abs().max(y.abs()).max(floor));
            assert!(d <= rel * x.abs().max(y.abs()) + floor, "{what}: pixel {i} channel {c}: {x} vs {y}");
        }
    }
    eprintln!("{what}: worst relative difference {worst:.3e}");
}

#[test]
fn sweeps_reference_shards_merge_into_the_one_process_reference() {
    let dir = fresh_dir("shards");
    let whole = dir.join("whole.exr");
    reference(&whole, None);
    let shards: Vec<PathBuf> = (0..3).map(|i| dir.join(format!("shard{i}.exr"))).collect();
    for (i, shard) in shards.iter().enumerate() {
        let (_, stderr) = reference(shard, Some(&format!("{i}/3")));
        let range = format!("samples {}..{} of 12", 4 * i, 4 * (i + 1));
        assert!(stderr.contains(&range), "{stderr}");
    }
    let merged = dir.join("merged.exr");
    let mut args = vec!["merge"];
    args.extend(shards.iter().map(|p| s(p)));
    args.extend(["--out", s(&merged)]);
    let (stdout, _) = ok(&args);
    assert!(stdout.contains("merged 3 shards") && stdout.contains("12 spp"), "{stdout}");
    // Same samples, summed in another order: f32 rounding only.
    assert_images_close("mean", &whole, &merged, 1e-5, 1e-7);
    assert_images_close(
        "variance",
        &dir.join("whole.variance.exr"),
        &dir.join("merged.variance.exr"),
        1e-3,
        1e-7,
    );

    // The shards' sums are disjoint shares: a shard alone is a different, 4-spp estimate.
    let (_, _, one) = restir_pt::image_io::read_exr(&whole).unwrap();
    let shard0 = restir_pt::cli::read_shard(&shards[0]).unwrap();
    assert_eq!((shard0.meta.first_sample, shard0.meta.spp, shard0.sums[0][3]), (0, 4, 4.0));
    let differs = shard0
        .sums
        .iter()
        .zip(&one)
        .filter(|(s, m)| (s[0] / s[3] - m.x).abs() > 1e-4 * m.x.abs())
        .count();
    assert!(
        differs > 100,
        "shard 0 alone should differ from the whole in most pixels: {differs} of 256"
    );

    // Missing shard: a warning and the mean of the shards given.
    let (code, stdout, stderr) = restir_pt(&["merge", s(&shards[0]), s(&shards[2]), "--out", s(&dir.join("part.exr"))]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("warning: shards [1] of 3 are missing") && stdout.contains("8 spp"),
        "{stderr}{stdout}"
    );
    // A shard twice, a shard of another seed, a plain EXR, a bad --shard: one clear line each.
    fails(
        &["merge", s(&shards[0]), s(&shards[0]), "--out", s(&dir.join("x.exr"))],
        &["shard0.exr", "already given"],
    );
    let other = dir.join("other.exr");
    ok(&[
        "reference",
        "scenes/cornell.gltf",
        "--spp",
        "12",
        "--width",
        "16",
        "--height",
        "16",
        "--seed",
        "8",
        "--out",
        s(&other),
        "--shard",
        "1/3",
    ]);
    fails(
        &["merge", s(&shards[0]), s(&other), "--out", s(&dir.join("x.exr"))],
        &["other.exr", "another reference"],
    );
    fails(
        &["merge", s(&whole), "--out", s(&dir.join("x.exr"))],
        &["whole.exr", "not a reference shard"],
    );
    fails(
        &["reference", "scenes/cornell.gltf", "--out", s(&dir.join("x.exr")), "--shard", "3/3"],
        &["--shard '3/3'"],
    );
    assert!(!dir.join("x.exr").exists());
}
