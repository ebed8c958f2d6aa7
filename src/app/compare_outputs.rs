//! `compare`'s outputs: results.csv, the error-against-time charts, the equal-time strip and
//! the equal-time lines, from the rows of one process or of merged jobs.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context as _, Result};
use glam::Vec3;

use super::compare::{CompareArgs, CompareRow, Setup};
use super::method_spec::MethodSpec;
use crate::app::charts::{write_image_strip, write_line_chart, Inset, LineChart, Series, StripPanel};
use restir_pt::metrics::{rel_mse, rel_squared_error};
use restir_pt::render::Image;

/// The inset window: the square (a quarter of the image's width) where `image` is furthest
/// from the reference.
fn worst_window(image: &[Vec3], reference: &[Vec3], width: u32, height: u32) -> Inset {
    let size = (width.min(height) / 4).max(4).min(width.min(height));
    let error = |x: u32, y: u32| {
        let i = (y * width + x) as usize;
        rel_squared_error(image[i], reference[i])
    };
    let mut best = (f64::NEG_INFINITY, Inset { x: 0, y: 0, size });
    let step = (size / 2).max(1);
    for y in (0..=height - size).step_by(step as usize) {
        for x in (0..=width - size).step_by(step as usize) {
            let e: f64 = (y..y + size)
                .flat_map(|yy| (x..x + size).map(move |xx| (xx, yy)))
                .map(|(xx, yy)| error(xx, yy))
                .filter(|e| e.is_finite())
                .sum();
            if e > best.0 {
                best = (e, Inset { x, y, size });
            }
        }
    }
    best.1
}

/// results.csv's columns; `rel_mse_stderr` is empty for one trial, `pt_samples_per_frame`
/// where the run has no path tracer to measure it by.
pub(super) const CSV_HEADER: &str =
    "method,budget_ms,knob,gpu_ms_per_frame,rel_mse,rel_mse_trimmed,mse,energy_ratio,failed_shift_rate,nonfinite_pixels,rel_mse_stderr,mape,hdr_flip,pt_samples_per_frame";

pub(super) fn write_csv(path: &Path, rows: &[CompareRow]) -> Result<()> {
    let mut csv = format!("{CSV_HEADER}\n");
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{:.3},{},{:.4},{:.6e},{:.6e},{:.6e},{:.5},{},{},{},{:.6e},{:.6e},{}",
            r.method,
            r.budget_ms,
            r.knob,
            r.gpu_ms_per_frame,
            r.rel_mse,
            r.rel_mse_trimmed,
            r.mse,
            r.energy_ratio,
            r.failed_shift_rate.map(|f| format!("{f:.5}")).unwrap_or_default(),
            r.nonfinite_pixels,
            r.rel_mse_stderr.map(|e| format!("{e:.6e}")).unwrap_or_default(),
            r.mape,
            r.hdr_flip,
            r.pt_samples_per_frame.map(|s| format!("{s:.4}")).unwrap_or_default()
        );
    }
    std::fs::write(path, csv).with_context(|| format!("{}: cannot write", path.display()))
}

/// The equal-time lines, results.csv, the charts and the strip of a whole sweep; `device`
/// names the device(s) in the charts' titles.
pub(super) fn write_outputs(
    args: &CompareArgs,
    setup: &Setup,
    budgets: &[f64],
    rows: &[CompareRow],
    images: &[(String, f64, Image)],
    device: &str,
) -> Result<()> {
    for line in equal_time_lines(rows, budgets) {
        println!("{line}");
    }
    write_csv(&args.out_dir.join("results.csv"), rows)?;
    let motion = if args.camera_path { "a moving camera" } else { "a static camera" };
    let title = format!(
        "{} {}x{}, frame {} (the last of {}) of {motion}, {device}",
        setup
            .path
            .file_name()
            .map_or_else(|| setup.path.display().to_string(), |n| n.to_string_lossy().into_owned()),
        setup.width,
        setup.height,
        args.frames - 1,
        args.frames
    );
    for (metric, name, value) in [
        ("rel_mse", "relMSE", (|r: &CompareRow| r.rel_mse) as fn(&CompareRow) -> f64),
        ("mse", "MSE", |r| r.mse),
    ] {
        let series: Vec<Series> = setup
            .methods
            .iter()
            .map(|m| Series {
                name: m.label(),
                points: rows
                    .iter()
                    .filter(|r| r.method == m.label())
                    .map(|r| (r.gpu_ms_per_frame, value(r)))
                    .collect(),
            })
            .collect();
        write_line_chart(
            &args.out_dir.join(format!("{metric}_vs_time")),
            &LineChart {
                title: &title,
                x_label: "GPU ms per frame",
                y_label: name,
                log_x: true,
                series: &series,
            },
        )?;
    }
    write_strip(
        &args.out_dir.join("equal_time.png"),
        budgets,
        &setup.methods,
        images,
        &setup.reference,
        setup.width,
        setup.height,
    )?;
    eprintln!(
        "wrote results.csv, rel_mse_vs_time.svg/png, mse_vs_time.svg/png and equal_time.png in {}",
        args.out_dir.display()
    );
    Ok(())
}

/// A run whose frames took longer than this multiple of its budget is not an equal-time point:
/// the cost model fits budgets from a few calibration frames, and a method whose cost grows
/// faster than linearly with its knob can overshoot.
const OVER_BUDGET_TOLERANCE: f64 = 1.2;

/// For each budget where the path tracer and ReSTIR PT both ran within it: the path tracer's
/// relMSE over the best ReSTIR PT method's, plain and trimmed, and a line for each run left out
/// for overshooting its budget. Each ratio also comes as relMSE × frame time, which does not
/// favour the method that ran shorter (a knob fits a budget only in whole steps: ReSTIR PT's
/// reservoirs, capped at 16, may use a fraction of it).
pub fn equal_time_lines(rows: &[CompareRow], budgets: &[f64]) -> Vec<String> {
    type Error = fn(&CompareRow) -> f64;
    let mut lines = vec![];
    for &budget in budgets {
        let within = |r: &&CompareRow| r.gpu_ms_per_frame <= OVER_BUDGET_TOLERANCE * budget;
        for r in rows.iter().filter(|r| r.budget_ms == budget && !within(r)) {
            lines.push(format!(
                "equal time {budget:.1} ms: {} left out, its frames took {:.1} ms",
                r.method, r.gpu_ms_per_frame
            ));
        }
        let lowest = |pt: bool, error: Error| {
            rows.iter()
                .filter(|r| r.budget_ms == budget && (r.method == "pt") == pt)
                .filter(within)
                .min_by(|a, b| error(a).total_cmp(&error(b)))
        };
        let plain: Error = |r| r.rel_mse;
        let trimmed: Error = |r| r.rel_mse_trimmed;
        for (name, error) in [("relMSE", plain), ("trimmed relMSE", trimmed)] {
            if let (Some(pt), Some(best)) = (lowest(true, error), lowest(false, error)) {
                lines.push(format!(
                    "equal time {budget:.1} ms, {name}: pt {:.4e} ({:.1} ms) / {} {:.4e} ({:.1} ms) = {:.2}x (by {name} × time {:.2}x)",
                    error(pt),
                    pt.gpu_ms_per_frame,
                    best.method,
                    error(best),
                    best.gpu_ms_per_frame,
                    error(pt) / error(best),
                    error(pt) * pt.gpu_ms_per_frame / (error(best) * best.gpu_ms_per_frame)
                ));
            }
        }
    }
    lines
}

/// The strip of the largest budget every method fit (or the largest budget run at all).
fn write_strip(
    path: &Path,
    budgets: &[f64],
    methods: &[MethodSpec],
    images: &[(String, f64, Image)],
    reference: &[Vec3],
    width: u32,
    height: u32,
) -> Result<()> {
    let complete = |b: f64| methods.iter().all(|m| images.iter().any(|(l, ib, _)| *l == m.label() && *ib == b));
    let largest_complete = budgets.iter().copied().filter(|&b| complete(b)).reduce(f64::max);
    let Some(budget) = largest_complete.or_else(|| images.iter().map(|i| i.1).reduce(f64::max)) else {
        return Ok(());
    };
    let chosen: Vec<&(String, f64, Image)> = images.iter().filter(|i| i.1 == budget).collect();
    let inset = worst_window(&chosen[0].2.mean, reference, width, height);
    let mut panels = vec![StripPanel {
        label: "reference".into(),
        pixels: reference,
    }];
    panels.extend(chosen.iter().map(|(label, _, image)| StripPanel {
        label: format!(
            "{label} ({:.3} relMSE, last run at {budget:.0} ms)",
            rel_mse(&image.mean, reference)
        ),
        pixels: &image.mean,
    }));
    write_image_strip(path, width, height, &panels, inset)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn compare_row(method: &str, gpu_ms_per_frame: f64, rel_mse: f64) -> CompareRow {
        CompareRow {
            method: method.to_string(),
            budget_ms: 100.0,
            knob: String::new(),
            gpu_ms_per_frame,
            rel_mse,
            rel_mse_stderr: None,
            rel_mse_trimmed: rel_mse / 2.0,
            mse: rel_mse,
            energy_ratio: 1.0,
            failed_shift_rate: None,
            nonfinite_pixels: 0,
            mape: rel_mse,
            hdr_flip: rel_mse,
            pt_samples_per_frame: None,
        }
    }

    /// The equal-time ratio takes the best ReSTIR PT run within 20% of the budget; a run that
    /// overshot it (here 190 ms for 100) is named and left out, however low its error.
    #[test]
    fn compare_equal_time_leaves_out_runs_over_budget() {
        let rows = [
            compare_row("pt", 95.0, 0.4),
            compare_row("restir:reconnection/gbh", 110.0, 0.2),
            compare_row("restir:hybrid/gbh", 190.0, 0.01),
        ];
        let lines = equal_time_lines(&rows, &[100.0]);
        assert_eq!(
            lines,
            [
                "equal time 100.0 ms: restir:hybrid/gbh left out, its frames took 190.0 ms",
                "equal time 100.0 ms, relMSE: pt 4.0000e-1 (95.0 ms) / restir:reconnection/gbh 2.0000e-1 (110.0 ms) = 2.00x (by relMSE × time 1.73x)",
                "equal time 100.0 ms, trimmed relMSE: pt 2.0000e-1 (95.0 ms) / restir:reconnection/gbh 1.0000e-1 (110.0 ms) = 2.00x (by trimmed relMSE × time 1.73x)",
            ]
        );
    }
}
