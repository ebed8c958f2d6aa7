//! `restir-pt render`: progressive path tracing to EXR/PNG with a one-line summary.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::{bail, Context as _, Result};
use serde::Serialize;

use super::{finish_device, load_with_warnings, open_device, scene_path, DeviceArgs};
use crate::image_io::{write_exr, write_png};
use crate::render::{PathTracer, RenderSettings};

pub struct RenderArgs {
    pub scene: Option<PathBuf>,
    pub spp: u32,
    pub width: u32,
    pub height: u32,
    pub max_depth: u32,
    pub seed: u32,
    pub russian_roulette: bool,
    pub camera: usize,
    pub frames: u32,
    pub out_dir: Option<PathBuf>,
    pub out: Option<PathBuf>,
    pub png: Option<PathBuf>,
    pub variance: Option<PathBuf>,
    pub report: Option<PathBuf>,
    pub device: DeviceArgs,
}

#[derive(Serialize)]
pub struct RenderReport {
    pub device: String,
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub gpu_ms: f64,
    pub wall_ms: f64,
    pub paths_per_second: f64,
}

impl RenderReport {
    pub fn summary_line(&self) -> String {
        format!(
            "{} | {}x{} | {} spp | depth {} | GPU {:.1} ms | wall {:.1} ms | {:.3} M paths/s",
            self.device,
            self.width,
            self.height,
            self.spp,
            self.max_depth,
            self.gpu_ms,
            self.wall_ms,
            self.paths_per_second * 1e-6
        )
    }
}

fn progress_bar(total: u32) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(total as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} spp  {elapsed} (eta {eta})").expect("static template is valid"),
    );
    bar
}

/// Installs a Ctrl-C handler once; later renders share the flag.
fn interrupt_flag() -> Arc<AtomicBool> {
    static FLAG: std::sync::OnceLock<Arc<AtomicBool>> = std::sync::OnceLock::new();
    FLAG.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        let handler_flag = flag.clone();
        // Without a handler Ctrl-C still ends the process; only the partial image is lost.
        if let Err(e) = ctrlc::set_handler(move || handler_flag.store(true, Ordering::Relaxed)) {
            eprintln!("warning: Ctrl-C will not save a partial image: {e}");
        }
        flag
    })
    .clone()
}

fn create_parent(file: &Path) -> Result<()> {
    match file.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create the output folder", dir.display())),
        None => Ok(()),
    }
}

pub fn render(args: RenderArgs) -> Result<()> {
    let path = scene_path(args.scene.as_deref());
    let scene = load_with_warnings(&path)?;
    if args.frames == 0 {
        bail!("--frames must be at least 1");
    }
    let last_camera = args.camera + args.frames as usize - 1;
    if last_camera >= scene.cameras.len() {
        bail!(
            "{}: --frames {} from --camera {} needs camera {last_camera}, but the scene has {} camera(s)",
            path.display(),
            args.frames,
            args.camera,
            scene.cameras.len()
        );
    }
    let settings = RenderSettings {
        width: args.width,
        height: args.height,
        spp: args.spp,
        max_depth: args.max_depth,
        seed: args.seed,
        russian_roulette: args.russian_roulette,
        camera: args.camera,
    };
    settings.validate(&scene)?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    let out = args.out.unwrap_or_else(|| PathBuf::from("out").join(format!("{stem}.exr")));
    let png = args.png.unwrap_or_else(|| out.with_extension("png"));
    for file in [Some(&out), Some(&png), args.variance.as_ref(), args.report.as_ref()]
        .into_iter()
        .flatten()
    {
        create_parent(file)?;
    }
    if let Some(dir) = &args.out_dir {
        std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create the output folder", dir.display()))?;
    }

    let ctx = open_device(&args.device)?;
    let interrupt = interrupt_flag();
    let mut report = None;
    let mut tracer = PathTracer::new(&ctx, &scene, &settings)?;
    for frame in 0..args.frames {
        if frame > 0 {
            let camera = args.camera + frame as usize;
            tracer.restart(
                &scene,
                &RenderSettings {
                    camera,
                    ..settings.clone()
                },
            )?;
        }
        let bar = progress_bar(settings.spp);
        let stats = tracer.render(&|done| bar.set_position(done as u64), &interrupt)?;
        bar.finish_and_clear();
        let image = tracer.image()?;
        if let Some(dir) = &args.out_dir {
            let name = format!("frame_{frame:04}");
            write_exr(&dir.join(format!("{name}.exr")), image.width, image.height, &image.mean)?;
            write_png(&dir.join(format!("{name}.png")), &image)?;
        }
        let frame_report = RenderReport {
            device: ctx.info.name.clone(),
            scene: path.display().to_string(),
            width: settings.width,
            height: settings.height,
            spp: stats.spp,
            max_depth: settings.max_depth,
            gpu_ms: stats.gpu_ms,
            wall_ms: stats.wall_ms,
            paths_per_second: stats.paths_per_second(settings.pixel_count()),
        };
        println!(
            "{}{}",
            if args.frames > 1 {
                format!("frame {frame} | ")
            } else {
                String::new()
            },
            frame_report.summary_line()
        );
        let last = frame + 1 == args.frames || stats.interrupted;
        if stats.interrupted {
            eprintln!("interrupted: writing the {} spp of frame {frame} accumulated so far", stats.spp);
        }
        if last {
            write_exr(&out, image.width, image.height, &image.mean)?;
            write_png(&png, &image)?;
            if let Some(v) = &args.variance {
                write_exr(v, image.width, image.height, &image.variance)?;
            }
            report = Some(frame_report);
            break;
        }
    }
    drop(tracer);
    finish_device(&ctx)?;
    if let (Some(r), Some(report)) = (&args.report, &report) {
        std::fs::write(r, serde_json::to_string_pretty(report)?).with_context(|| format!("{}: cannot write the report", r.display()))?;
    }
    eprintln!("wrote {} and {}", out.display(), png.display());
    Ok(())
}
