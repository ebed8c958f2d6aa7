//! `compare --plan/--job/--merge`: one job per method and budget (method-major, as the rows of
//! results.csv), each calibrating its own method. The merge writes the same results.csv, charts
//! and strip as one process, plus accounting.csv.

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};

use super::compare::{measure, note_camera_path, reservoir_cap_note, CompareArgs, CompareRow, Setup};
use super::compare_outputs::{write_csv, write_outputs, CSV_HEADER as HEADER};
use super::method_spec::MethodRenderer;
use super::sweep::{
    devices, job_file, parse_optional, read_job_reports, read_job_rows, start_job, write_accounting, write_job_report, write_plan,
    JobReport, SweepMode, COMMIT,
};
use super::{finish_device, open_device};
use restir_pt::image_io::{read_exr, write_exr};
use restir_pt::render::{Image, SceneGpu};

/// The jobs' labels: every method at every budget.
fn labels(setup: &Setup, budgets: &[f64]) -> Vec<String> {
    setup
        .methods
        .iter()
        .flat_map(|m| budgets.iter().map(move |b| format!("{} at {b} ms", m.label())))
        .collect()
}

pub(super) fn compare_sweep(args: &CompareArgs, setup: &Setup, mode: &SweepMode) -> Result<Vec<CompareRow>> {
    if args.budgets_ms.is_empty() {
        bail!("--plan, --job and --merge need --budgets-ms: the default budgets are measured across all methods in one process");
    }
    let labels = labels(setup, &args.budgets_ms);
    match mode {
        SweepMode::All => unreachable!("compare runs All itself"),
        SweepMode::Plan(plan) => {
            write_plan(plan, &super::args::argv(), &labels, &args.out_dir)?;
            Ok(vec![])
        }
        SweepMode::Job(k) => run_job(args, setup, *k, &labels),
        SweepMode::Merge(dir) => merge(args, setup, dir, labels.len()),
    }
}

fn run_job(args: &CompareArgs, setup: &Setup, k: usize, labels: &[String]) -> Result<Vec<CompareRow>> {
    let dir = start_job(k, labels.len(), &args.out_dir)?;
    let start = Instant::now();
    let budgets = &args.budgets_ms;
    let (method, budget) = (&setup.methods[k / budgets.len()], budgets[k % budgets.len()]);
    let ctx = open_device(&args.device)?;
    let run = setup.run(args.camera_path);
    note_camera_path(args, &run);
    let mut renderer = MethodRenderer::new(&SceneGpu::upload(&ctx, &setup.scene)?, &setup.settings, method)?;
    let mut cost = run.calibrate(&mut renderer)?;
    if let Some(most_ms) = run.extend(&mut renderer, &mut cost, budget)? {
        eprintln!("{}", reservoir_cap_note(&method.label(), most_ms));
    }
    let measured = measure(&run, &mut renderer, &cost, &method.label(), budget, &setup.reference, args)?;
    let compile_ms = renderer.compile_ms();
    drop(renderer);
    finish_device(&ctx)?;
    let rows: Vec<CompareRow> = measured
        .map(|(row, image)| -> Result<CompareRow> {
            write_exr(&job_file(&dir, k, "exr"), image.width, image.height, &image.mean)?;
            Ok(row)
        })
        .transpose()?
        .into_iter()
        .collect();
    write_csv(&job_file(&dir, k, "csv"), &rows)?;
    write_job_report(
        &dir,
        &JobReport {
            job: k,
            jobs: labels.len(),
            label: labels[k].clone(),
            device: ctx.info.name.clone(),
            commit: COMMIT.to_string(),
            wall_ms: start.elapsed().as_secs_f64() * 1e3,
            gpu_ms: run.gpu_ms.get(),
            compile_ms,
        },
    )?;
    Ok(rows)
}

fn parse_row(fields: &[String], path: &Path) -> Result<CompareRow> {
    let bad = || format!("{}: a row that is not {HEADER}", path.display());
    if fields.len() != HEADER.split(',').count() {
        bail!("{}", bad());
    }
    let num = |i: usize| fields[i].parse::<f64>().with_context(bad);
    Ok(CompareRow {
        method: fields[0].clone(),
        budget_ms: num(1)?,
        knob: fields[2].clone(),
        gpu_ms_per_frame: num(3)?,
        rel_mse: num(4)?,
        rel_mse_stderr: parse_optional(&fields[10]).with_context(bad)?,
        rel_mse_trimmed: num(5)?,
        mse: num(6)?,
        energy_ratio: num(7)?,
        failed_shift_rate: parse_optional(&fields[8]).with_context(bad)?,
        nonfinite_pixels: fields[9].parse().with_context(bad)?,
        mape: num(11)?,
        hdr_flip: num(12)?,
        pt_samples_per_frame: parse_optional(&fields[13]).with_context(bad)?,
    })
}

fn merge(args: &CompareArgs, setup: &Setup, dir: &Path, jobs: usize) -> Result<Vec<CompareRow>> {
    let reports = read_job_reports(dir, jobs)?;
    let mut rows = vec![];
    let mut images = vec![];
    for (k, path, fields) in read_job_rows(dir, jobs, HEADER)? {
        let row = parse_row(&fields, &path)?;
        // The budget as given, not as the CSV rounded it: the strip and equal-time lines match
        // rows to budgets exactly.
        let budget = args.budgets_ms[k % args.budgets_ms.len()];
        let exr = job_file(dir, k, "exr");
        let (width, height, mean) = read_exr(&exr)?;
        if (width, height) != (setup.width, setup.height) {
            bail!(
                "{}: {width}x{height}, but the reference is {}x{}",
                exr.display(),
                setup.width,
                setup.height
            );
        }
        images.push((
            row.method.clone(),
            budget,
            Image {
                width,
                height,
                mean,
                variance: vec![],
            },
        ));
        rows.push(CompareRow { budget_ms: budget, ..row });
    }
    write_outputs(args, setup, &args.budgets_ms, &rows, &images, &devices(&reports))?;
    write_accounting(&args.out_dir, &reports)?;
    Ok(rows)
}
