//! Sweeps as job lists: `compare` and `stability` can write their runs as a JSON-lines plan
//! (`--plan jobs.jsonl`), run one job of it (`--job K`) and merge the jobs' files (`--merge DIR`),
//! so that any scheduler (Slurm job arrays, Ray; see tools/cluster/) runs them on many machines.
//!
//! A job K writes `<out-dir>/jobs/job_K.csv` (its rows, in the command's results format),
//! `job_K.json` (a `JobReport`: where its time went) and whatever images the merge needs. Jobs
//! need a shared file system only for these outputs.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};
use serde::{Deserialize, Serialize};

/// The commit the binary was built from (`git rev-parse --short HEAD` at build time, "unknown"
/// without git).
pub const COMMIT: &str = env!("RESTIR_PT_COMMIT");

/// How a sweep command runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SweepMode {
    /// Every job in this process (the default).
    All,
    /// Write the job list to this JSON-lines file and run nothing.
    Plan(PathBuf),
    /// Run job K (0-based) of the list and write its files under `<out-dir>/jobs/`.
    Job(usize),
    /// Read the job files in this folder and write the command's usual outputs.
    Merge(PathBuf),
}

impl SweepMode {
    /// From the `--plan`, `--job` and `--merge` flags, at most one of which may be given.
    pub fn from_flags(plan: Option<PathBuf>, job: Option<usize>, merge: Option<PathBuf>) -> Result<Self> {
        match (plan, job, merge) {
            (None, None, None) => Ok(SweepMode::All),
            (Some(p), None, None) => Ok(SweepMode::Plan(p)),
            (None, Some(k), None) => Ok(SweepMode::Job(k)),
            (None, None, Some(d)) => Ok(SweepMode::Merge(d)),
            _ => bail!("--plan, --job and --merge exclude each other"),
        }
    }
}

/// One line of a plan: job `job` of `jobs`, run as `restir-pt <argv>` from `cwd`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct JobLine {
    pub job: usize,
    pub jobs: usize,
    /// What the job runs, e.g. "pt at 20.0 ms" or "cornell restir:hybrid".
    pub label: String,
    /// The working folder relative paths in `argv` are relative to.
    pub cwd: String,
    pub argv: Vec<String>,
    /// The command that merges the jobs once all have run (the same on every line).
    pub merge_argv: Vec<String>,
}

/// Where one job's time went.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct JobReport {
    pub job: usize,
    pub jobs: usize,
    pub label: String,
    /// The Vulkan device's name.
    pub device: String,
    pub commit: String,
    /// From the start of the job's work (after argument checks) to its files, in ms.
    pub wall_ms: f64,
    /// GPU time of every frame and reference the job rendered, calibration included, in ms.
    pub gpu_ms: f64,
    /// Building and compiling the job's kernels (`KernelCompile::total_ms`), in ms.
    pub compile_ms: f64,
}

/// The folder a sweep's jobs write to.
pub fn jobs_dir(out_dir: &Path) -> PathBuf {
    out_dir.join("jobs")
}

/// `dir/job_K.<ext>`.
pub fn job_file(dir: &Path, job: usize, ext: &str) -> PathBuf {
    dir.join(format!("job_{job:04}.{ext}"))
}

/// `argv` without `--plan X` / `--plan=X`.
fn without_plan(argv: &[String]) -> Vec<String> {
    let mut out = vec![];
    let mut skip = false;
    for a in argv {
        if skip {
            skip = false;
        } else if a == "--plan" {
            skip = true;
        } else if !a.starts_with("--plan=") {
            out.push(a.clone());
        }
    }
    out
}

/// Writes the plan of `labels.len()` jobs of the command line `argv` (which holds `--plan`).
pub fn write_plan(plan: &Path, argv: &[String], labels: &[String], out_dir: &Path) -> Result<()> {
    let base = without_plan(argv);
    let cwd = std::env::current_dir().context("the working folder is unreadable")?;
    let mut merge_argv = base.clone();
    merge_argv.extend(["--merge".to_string(), jobs_dir(out_dir).display().to_string()]);
    let mut text = String::new();
    for (job, label) in labels.iter().enumerate() {
        let mut job_argv = base.clone();
        job_argv.extend(["--job".to_string(), job.to_string()]);
        let line = JobLine {
            job,
            jobs: labels.len(),
            label: label.clone(),
            cwd: cwd.display().to_string(),
            argv: job_argv,
            merge_argv: merge_argv.clone(),
        };
        text.push_str(&serde_json::to_string(&line)?);
        text.push('\n');
    }
    super::render_output::create_parent(plan)?;
    std::fs::write(plan, text).with_context(|| format!("{}: cannot write the plan", plan.display()))?;
    println!("wrote {} jobs to {}", labels.len(), plan.display());
    println!("run one: restir-pt {} --job K", base.join(" "));
    println!("merge:   restir-pt {}", merge_argv.join(" "));
    Ok(())
}

/// Checks `job` against the plan's size and makes the jobs folder.
pub fn start_job(job: usize, jobs: usize, out_dir: &Path) -> Result<PathBuf> {
    if job >= jobs {
        bail!("--job {job}: the plan has {jobs} jobs (0 to {})", jobs.saturating_sub(1));
    }
    let dir = jobs_dir(out_dir);
    std::fs::create_dir_all(&dir).with_context(|| format!("{}: cannot create the jobs folder", dir.display()))?;
    Ok(dir)
}

pub fn write_job_report(dir: &Path, report: &JobReport) -> Result<()> {
    let path = job_file(dir, report.job, "json");
    std::fs::write(&path, serde_json::to_string_pretty(report)?).with_context(|| format!("{}: cannot write", path.display()))?;
    eprintln!(
        "job {} of {} ({}): wall {:.0} ms, GPU {:.0} ms, compile {:.0} ms on {} at {}",
        report.job, report.jobs, report.label, report.wall_ms, report.gpu_ms, report.compile_ms, report.device, report.commit
    );
    Ok(())
}

/// Reads the reports of jobs 0..jobs from `dir`; a missing one is an error naming the job.
pub fn read_job_reports(dir: &Path, jobs: usize) -> Result<Vec<JobReport>> {
    (0..jobs)
        .map(|k| {
            let path = job_file(dir, k, "json");
            let text = std::fs::read_to_string(&path)
                .with_context(|| format!("{}: cannot read job {k}'s report (was job {k} of {jobs} run?)", path.display()))?;
            let report: JobReport = serde_json::from_str(&text).with_context(|| format!("{}: not a job report", path.display()))?;
            if report.job != k || report.jobs != jobs {
                bail!(
                    "{}: the report of job {} of {}, not {k} of {jobs}",
                    path.display(),
                    report.job,
                    report.jobs
                );
            }
            Ok(report)
        })
        .collect()
}

/// The jobs' rows of a results CSV with header `header`, in job order.
pub fn read_job_rows(dir: &Path, jobs: usize, header: &str) -> Result<Vec<(usize, PathBuf, Vec<String>)>> {
    let mut rows = vec![];
    for k in 0..jobs {
        let path = job_file(dir, k, "csv");
        let text = std::fs::read_to_string(&path).with_context(|| format!("{}: cannot read job {k}'s rows", path.display()))?;
        let mut lines = text.lines();
        if lines.next() != Some(header) {
            bail!("{}: not a results file of this command (its header differs)", path.display());
        }
        rows.extend(lines.map(|l| (k, path.clone(), l.split(',').map(str::to_string).collect())));
    }
    Ok(rows)
}

/// The distinct devices of `reports`, joined for a chart title.
pub fn devices(reports: &[JobReport]) -> String {
    let mut names: Vec<&str> = vec![];
    for r in reports {
        if !names.contains(&r.device.as_str()) {
            names.push(&r.device);
        }
    }
    names.join(" + ")
}

/// Writes `accounting.csv` (one line per job) into `out_dir` and prints the totals.
pub fn write_accounting(out_dir: &Path, reports: &[JobReport]) -> Result<()> {
    let mut csv = String::from("job,label,device,commit,wall_ms,gpu_ms,compile_ms\n");
    for r in reports {
        csv.push_str(&format!(
            "{},{},{},{},{:.1},{:.1},{:.1}\n",
            r.job,
            r.label.replace(',', ";"),
            r.device.replace(',', ";"),
            r.commit,
            r.wall_ms,
            r.gpu_ms,
            r.compile_ms
        ));
    }
    let path = out_dir.join("accounting.csv");
    std::fs::write(&path, csv).with_context(|| format!("{}: cannot write", path.display()))?;
    let total = |f: fn(&JobReport) -> f64| reports.iter().map(f).sum::<f64>() / 1e3;
    let mut commits: Vec<&str> = reports.iter().map(|r| r.commit.as_str()).collect();
    commits.dedup();
    println!(
        "{} jobs: wall {:.1} s, GPU {:.1} s, kernel compiles {:.1} s (sums over jobs) on {}; commits {}",
        reports.len(),
        total(|r| r.wall_ms),
        total(|r| r.gpu_ms),
        total(|r| r.compile_ms),
        devices(reports),
        commits.join(", ")
    );
    Ok(())
}

/// Parses an optional CSV number (empty: None).
pub fn parse_optional(field: &str) -> Result<Option<f64>> {
    if field.is_empty() {
        Ok(None)
    } else {
        Ok(Some(field.parse()?))
    }
}
