//! Sweeps beyond one process: reference shards that merge into the one-process reference, and
//! `compare`/`stability` plans run job by job and merged into the one-process results.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::temp_file;
use crate::fixtures::cli::restir_pt;

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
    assert_shard_alone_differs(&whole, &shards[0]);
    check_merge_problems(&dir, &whole, &shards);
}

/// The shards' sums are disjoint shares: shard 0 of 3 alone is a different, 4-spp estimate.
fn assert_shard_alone_differs(whole: &Path, shard: &Path) {
    let (_, _, one) = restir_pt::image_io::read_exr(whole).unwrap();
    let shard0 = restir_pt::reference_shard::read_shard(shard).unwrap();
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
}

/// A missing shard warns; a shard twice, a shard of another seed, a plain EXR and a bad
/// --shard fail with one clear line each and write nothing.
fn check_merge_problems(dir: &Path, whole: &Path, shards: &[PathBuf]) {
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
        &["merge", s(whole), "--out", s(&dir.join("x.exr"))],
        &["whole.exr", "not a reference shard"],
    );
    fails(
        &["reference", "scenes/cornell.gltf", "--out", s(&dir.join("x.exr")), "--shard", "3/3"],
        &["--shard '3/3'"],
    );
    assert!(!dir.join("x.exr").exists());
}

/// A line of a plan (jobs.jsonl) as docs/cluster.md describes it: the fields the scripts read.
#[derive(serde::Deserialize)]
struct JobLine {
    job: usize,
    jobs: usize,
    argv: Vec<String>,
    merge_argv: Vec<String>,
}

/// Runs every job of the plan at `plan` as the cluster scripts do (each line's argv from its
/// cwd), then its merge command; returns the merge's stdout.
fn run_plan(plan: &Path, jobs: usize) -> String {
    let text = std::fs::read_to_string(plan).unwrap();
    let lines: Vec<JobLine> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), jobs, "{text}");
    for (k, line) in lines.iter().enumerate() {
        assert_eq!((line.job, line.jobs), (k, jobs));
        assert_eq!(line.argv[line.argv.len() - 2..], ["--job".to_string(), k.to_string()]);
        assert!(!line.argv.iter().any(|a| a.starts_with("--plan")), "{:?}", line.argv);
        let args: Vec<&str> = line.argv.iter().map(String::as_str).collect();
        let (code, _, stderr) = restir_pt(&args);
        assert_eq!(code, 0, "job {k}: {stderr}");
        assert!(stderr.contains(&format!("job {k} of {jobs}")), "{stderr}");
    }
    let merge: Vec<&str> = lines[0].merge_argv.iter().map(String::as_str).collect();
    ok(&merge).0
}

fn csv_rows(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

/// Each job's report: the device, positive wall, GPU and compile ms, and the build's commit.
fn check_job_reports(jobs_dir: &Path, jobs: usize) {
    let head = Command::new("git")
        .args(["rev-parse", "--short", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
    for k in 0..jobs {
        let path = jobs_dir.join(format!("job_{k:04}.json"));
        let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert!(!report["device"].as_str().unwrap().is_empty(), "{report}");
        for field in ["wall_ms", "gpu_ms", "compile_ms"] {
            assert!(report[field].as_f64().unwrap() > 0.0, "{field}: {report}");
        }
        assert!(
            report["wall_ms"].as_f64().unwrap() >= report["compile_ms"].as_f64().unwrap(),
            "{report}"
        );
        let commit = report["commit"].as_str().unwrap();
        assert_eq!(commit, head.as_deref().unwrap_or("unknown"), "{report}");
    }
}

/// `compare` on cornell at 4x4 as 4 jobs (pt and ReSTIR PT at 0.001 ms and 1e6 ms, where the knobs do not depend
/// on timing: 1 spp, 65536 spp, skipped, 16 reservoirs) run one by one and merged, against one
/// process: every column but the GPU time equal.
#[test]
fn sweeps_compare_jobs_merge_into_the_one_process_results() {
    let dir = fresh_dir("compare-sweep");
    let reference = dir.join("ref.exr");
    ok(&[
        "reference",
        "scenes/cornell.gltf",
        "--spp",
        "16",
        "--width",
        "4",
        "--height",
        "4",
        "--max-depth",
        "3",
        "--out",
        s(&reference),
    ]);
    let (one, split) = (dir.join("one"), dir.join("split"));
    let args = |out: &Path| compare_args(&reference, out);
    let one_args = args(&one);
    ok(&one_args.iter().map(String::as_str).collect::<Vec<_>>());
    let plan = split.join("jobs.jsonl");
    let mut plan_args = args(&split);
    plan_args.extend(["--plan".into(), s(&plan).into()]);
    let (stdout, _) = ok(&plan_args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(stdout.contains("wrote 4 jobs"), "{stdout}");
    assert!(!split.join("results.csv").exists(), "--plan runs nothing");
    let merged = run_plan(&plan, 4);
    assert!(merged.contains("4 jobs: wall"), "{merged}");
    assert_same_compare_results(&one, &split);
    check_job_reports(&split.join("jobs"), 4);
    check_compare_sweep_problems(&split, &args(&split));
}

/// The arguments of the `compare` run the sweep test splits, writing into `out`.
fn compare_args(reference: &Path, out: &Path) -> Vec<String> {
    vec![
        "compare".to_string(),
        "scenes/cornell.gltf".into(),
        "--reference".into(),
        s(reference).into(),
        "--methods".into(),
        "pt,restir:hybrid".into(),
        "--budgets-ms".into(),
        "0.001,1000000".into(),
        "--frames".into(),
        "2".into(),
        "--trials".into(),
        "2".into(),
        "--max-depth".into(),
        "3".into(),
        "--out-dir".into(),
        s(out).into(),
    ]
}

/// The merged results equal one process's in every column but the GPU time (and the frame in
/// path-tracer samples, which a job of one method cannot measure), with the
/// charts, the image strip and the accounting of 4 jobs.
fn assert_same_compare_results(one: &Path, split: &Path) {
    let (a, b) = (csv_rows(&one.join("results.csv")), csv_rows(&split.join("results.csv")));
    assert_eq!(a.len(), 1 + 3, "pt twice, ReSTIR PT once (skipped at 0.001 ms): {a:?}");
    assert_eq!(a.len(), b.len());
    let knobs: Vec<&str> = a[1..].iter().map(|r| r[2].as_str()).collect();
    assert_eq!(knobs, ["spp=1", "spp=65536", "reservoirs=16"]);
    for (ra, rb) in a.iter().zip(&b) {
        for (c, (x, y)) in ra.iter().zip(rb).enumerate() {
            // Times differ between processes; a job has no path tracer to express its frame in.
            if !["gpu_ms_per_frame", "pt_samples_per_frame"].contains(&a[0][c].as_str()) {
                assert_eq!(x, y, "column {}: {ra:?} vs {rb:?}", a[0][c]);
            }
        }
    }
    for file in [
        "rel_mse_vs_time.svg",
        "rel_mse_vs_time.png",
        "mse_vs_time.svg",
        "mse_vs_time.png",
        "equal_time.png",
    ] {
        assert!(std::fs::metadata(split.join(file)).unwrap().len() > 100, "{file}");
    }
    let accounting = csv_rows(&split.join("accounting.csv"));
    assert_eq!(accounting.len(), 1 + 4, "{accounting:?}");
}

/// A missing job, a job out of range, flags together, a plan without budgets: one clear line
/// each. `args` are the sweep's `compare` arguments writing into `split`.
fn check_compare_sweep_problems(split: &Path, args: &[String]) {
    std::fs::remove_file(split.join("jobs/job_0002.csv")).unwrap();
    let mut merge_args = args.to_vec();
    merge_args.extend(["--merge".into(), s(&split.join("jobs")).into()]);
    fails(
        &merge_args.iter().map(String::as_str).collect::<Vec<_>>(),
        &["job_0002.csv", "job 2"],
    );
    let mut bad = args.to_vec();
    bad.extend(["--job".into(), "4".into()]);
    fails(&bad.iter().map(String::as_str).collect::<Vec<_>>(), &["--job 4", "4 jobs"]);
    bad.extend(["--plan".into(), "x.jsonl".into()]);
    fails(&bad.iter().map(String::as_str).collect::<Vec<_>>(), &["exclude each other"]);
    let mut no_budgets = args.to_vec();
    no_budgets.drain(6..8);
    no_budgets.extend(["--plan".into(), "x.jsonl".into()]);
    fails(&no_budgets.iter().map(String::as_str).collect::<Vec<_>>(), &["need --budgets-ms"]);
}

/// `stability` on cornell at 8x8, 3 frames, pt and ReSTIR PT, into `out`.
fn stability_args(out: &Path) -> Vec<String> {
    [
        "stability",
        "--scenes",
        "scenes/cornell.gltf",
        "--methods",
        "pt,restir:hybrid",
        "--frames",
        "3",
        "--width",
        "8",
        "--height",
        "8",
        "--reference-spp",
        "8",
        "--out-dir",
        s(out),
    ]
    .map(String::from)
    .to_vec()
}

fn run(args: &[String]) -> (String, String) {
    ok(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// Writes the stability plan (2 jobs, one per method) for `out` and returns its path.
fn stability_plan(out: &Path) -> PathBuf {
    let plan = out.join("jobs.jsonl");
    let mut args = stability_args(out);
    args.extend(["--plan".into(), s(&plan).into()]);
    run(&args);
    plan
}

/// The one-process stability.csv (made once per test binary run).
fn stability_one_process() -> String {
    static ONE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    ONE.get_or_init(|| {
        let out = fresh_dir("stability-one");
        run(&stability_args(&out));
        std::fs::read_to_string(out.join("stability.csv")).unwrap()
    })
    .clone()
}

/// `stability` as 2 jobs merged: the same stability.csv as one process (no column depends on
/// timing), the summary, the chart, and each job's report.
#[test]
fn sweeps_stability_jobs_merge_into_the_one_process_results() {
    let split = fresh_dir("stability-split");
    let merged = run_plan(&stability_plan(&split), 2);
    assert!(merged.contains("cornell") && merged.contains("relMSE last"), "summary: {merged}");
    let one = stability_one_process();
    assert_eq!(one.lines().count(), 1 + 2 * 2 * 3, "{one}");
    assert_eq!(one, std::fs::read_to_string(split.join("stability.csv")).unwrap());
    assert!(std::fs::metadata(split.join("cornell_rel_mse.png")).unwrap().len() > 100);
    check_job_reports(&split.join("jobs"), 2);
}

fn script(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/cluster").join(name)
}

/// tools/cluster/slurm.sh: valid bash; `submit` asks sbatch (a stand-in here that logs its
/// arguments) for an array of one task per job and a merge after the whole array; the array
/// tasks (SLURM_ARRAY_TASK_ID set as Slurm sets it) and the merge make stability.csv equal
/// to one process's.
#[test]
fn sweeps_slurm_script_submits_runs_and_merges_a_plan() {
    let slurm = script("slurm.sh");
    let syntax = Command::new("bash").arg("-n").arg(&slurm).output().unwrap();
    assert!(syntax.status.success(), "bash -n: {}", String::from_utf8_lossy(&syntax.stderr));

    let out = fresh_dir("stability-slurm");
    let plan = stability_plan(&out);
    let bin = out.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let log = out.join("sbatch.log");
    std::fs::write(bin.join("sbatch"), format!("#!/bin/sh\necho \"$*\" >> {}\necho 4242\n", s(&log))).unwrap();
    Command::new("chmod").arg("+x").arg(bin.join("sbatch")).status().unwrap();
    let path = format!("{}:{}", s(&bin), std::env::var("PATH").unwrap_or_default());
    let slurm_run = |args: &[&str], task: Option<usize>| {
        let mut cmd = Command::new("bash");
        cmd.arg(&slurm)
            .args(args)
            .env("PATH", &path)
            .env("RESTIR_PT", env!("CARGO_BIN_EXE_restir-pt"));
        if let Some(k) = task {
            cmd.env("SLURM_ARRAY_TASK_ID", k.to_string());
        }
        let done = cmd.output().unwrap();
        let stdout = String::from_utf8_lossy(&done.stdout).into_owned();
        assert!(
            done.status.success(),
            "slurm.sh {args:?}: {}",
            String::from_utf8_lossy(&done.stderr)
        );
        stdout
    };
    let stdout = slurm_run(&["submit", s(&plan), "--partition=gpu"], None);
    assert!(stdout.contains("submitted 2 jobs as array 4242 and the merge as 4242"), "{stdout}");
    let calls = std::fs::read_to_string(&log).unwrap();
    let calls: Vec<&str> = calls.lines().collect();
    assert_eq!(calls.len(), 2, "{calls:?}");
    assert!(
        calls[0].starts_with("--parsable --array=0-1 --partition=gpu ") && calls[0].ends_with(&format!("job {}", s(&plan))),
        "{calls:?}"
    );
    assert!(
        calls[1].starts_with("--parsable --dependency=afterok:4242 --partition=gpu ") && calls[1].ends_with(&format!("merge {}", s(&plan))),
        "{calls:?}"
    );
    for k in 0..2 {
        slurm_run(&["job", s(&plan)], Some(k));
    }
    slurm_run(&["merge", s(&plan)], None);
    assert_eq!(stability_one_process(), std::fs::read_to_string(out.join("stability.csv")).unwrap());
}

/// tools/cluster/ray_sweep.py on a local Ray instance with two workers runs the plan and the
/// merge: stability.csv equal to one process's. Runs when the Python of $RESTIR_PT_PYTHON
/// (default python3) imports ray (tools/setup.sh installs it); otherwise prints why it skipped.
#[test]
fn sweeps_ray_script_runs_a_plan_on_two_local_workers_and_merges() {
    let python = std::env::var("RESTIR_PT_PYTHON").unwrap_or_else(|_| "python3".into());
    let has_ray = Command::new(&python)
        .args(["-c", "import ray"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_ray {
        eprintln!("SKIPPED sweeps_ray_script_runs_a_plan_on_two_local_workers_and_merges: {python} cannot import ray (pip install ray, or set RESTIR_PT_PYTHON)");
        return;
    }
    let out = fresh_dir("stability-ray");
    let plan = stability_plan(&out);
    let done = Command::new(&python)
        .arg(script("ray_sweep.py"))
        .arg(&plan)
        .args(["--num-cpus", "2"])
        .env("RESTIR_PT", env!("CARGO_BIN_EXE_restir-pt"))
        .output()
        .unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&done.stdout), String::from_utf8_lossy(&done.stderr));
    assert!(done.status.success(), "ray_sweep.py: {stdout}{stderr}");
    for k in 0..2 {
        assert!(stdout.contains(&format!("job {k} of 2")), "{stdout}");
    }
    assert!(stdout.contains("2 jobs: wall"), "the merge ran: {stdout}");
    assert_eq!(stability_one_process(), std::fs::read_to_string(out.join("stability.csv")).unwrap());
    check_job_reports(&out.join("jobs"), 2);
}
