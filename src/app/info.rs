//! `restir-pt info`: what a scene contains.

use std::path::Path;

use anyhow::Result;
use clap::Args;
use glam::Vec3;

use super::args::{DeviceArgs, RestirArgs, SceneArgs};
use super::{finish_device, load_with_options, open_device};
use crate::render::{PathTracer, RenderSettings, Restir, SceneGpu};
use crate::scene::Scene;
use crate::vk::KernelCompile;

/// Materials listed one per line; vertex colours can make thousands of variants.
const MAX_LISTED_MATERIALS: usize = 64;

/// `restir-pt info`.
#[derive(Args, Debug, Clone)]
pub struct InfoArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Also build every kernel of the path tracer and of ReSTIR PT (with the shift and MIS
    /// given) and print its SPIR-V size and compile time per stage.
    #[arg(long)]
    pub kernels: bool,
    #[command(flatten)]
    pub restir: RestirArgs,
    #[command(flatten)]
    pub device: DeviceArgs,
}

/// Prints what the scene contains and how long the load took; with --kernels, also builds the
/// scene's kernels (the path tracer's and ReSTIR PT's with the given settings) on the device
/// and prints their costs.
pub fn info(args: InfoArgs) -> Result<()> {
    let path = args.scene.path();
    let start = std::time::Instant::now();
    let scene = load_with_options(&path, &args.scene.load_options(None))?;
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    print_scene(&path, &scene, load_ms);
    if args.kernels {
        let restir = args.restir.settings();
        let ctx = open_device(&args.device)?;
        let settings = RenderSettings {
            width: 8,
            height: 8,
            max_depth: crate::shading::path_record::MAX_PATH_LENGTH as u32,
            ..Default::default()
        };
        let scene_gpu = SceneGpu::upload(&ctx, &scene)?;
        let mut reports = vec![PathTracer::new(&scene_gpu, &settings)?.compile_report().clone()];
        reports.extend(Restir::new(&scene_gpu, &settings, &restir)?.compile_reports());
        drop(scene_gpu);
        print_kernels(&restir.label(), &reports);
        finish_device(&ctx)?;
    }
    Ok(())
}

/// One line per kernel: SPIR-V bytes and milliseconds of GLSL compile, pipeline creation and
/// first dispatch (where llvmpipe compiles).
fn print_kernels(label: &str, reports: &[KernelCompile]) {
    println!("kernels ({label}; compile stages in ms: GLSL, pipeline, first dispatch):");
    for k in reports {
        println!(
            "  {:<40} {:>8} B SPIR-V | {:>7.0} {:>7.0} {:>7.0} | total {:>7.0} ms",
            k.name,
            k.spirv_bytes,
            k.glsl_ms,
            k.pipeline_ms,
            k.first_dispatch_ms,
            k.total_ms()
        );
    }
    let total: f64 = reports.iter().map(|k| k.total_ms()).sum();
    println!("  all kernels: {total:.0} ms");
}

/// Triangles of each material, by material index: materials of equal parameters (two glTF
/// materials alike, or a material and its vertex-colour variant of colour 1) count apart.
pub fn triangles_per_material(scene: &Scene) -> Vec<usize> {
    let mut uses = vec![0usize; scene.materials.len()];
    for t in &scene.triangles {
        if let Some(u) = uses.get_mut(t.material as usize) {
            *u += 1;
        }
    }
    uses
}

fn print_scene(path: &Path, scene: &Scene, load_ms: f64) {
    let (lo, hi) = scene.bounds;
    println!("scene: {}", path.display());
    println!("triangles: {}", scene.triangles.len());
    println!(
        "loaded in {load_ms:.0} ms, of which BVH build and emitter table {:.0} ms",
        scene.build_ms
    );
    println!("BVH nodes: {}", scene.nodes.len());
    if let Some(line) = scene.surface_summary() {
        println!("{line}");
    }
    println!(
        "emitters: {} triangles, power {:.4} (luminance W)",
        scene.emitters.len(),
        scene.emitter_power
    );
    match &scene.environment_map {
        Some(map) => println!(
            "environment: {}x{} equirectangular map (importance-sampled by luminance)",
            map.width, map.height
        ),
        None => println!("environment: {:?}", scene.environment.to_array()),
    }
    println!(
        "bounds: {:?} .. {:?} (extent {:.4}), relative to the origin at {:?} (world; the first camera, else the centre of the bounds)",
        lo.to_array(),
        hi.to_array(),
        scene.extent(),
        scene.origin.to_array()
    );
    println!("punctual lights: {}", scene.lights.len());
    for (i, l) in scene.lights.iter().enumerate() {
        println!(
            "  {i}: {:?} at {:?} along {:?}, intensity {:?}",
            l.kind,
            l.position.to_array(),
            l.direction.to_array(),
            l.intensity.to_array()
        );
    }
    println!("materials: {}", scene.materials.len());
    for ((m, name), used) in scene
        .materials
        .iter()
        .zip(&scene.material_names)
        .zip(triangles_per_material(scene))
        .take(MAX_LISTED_MATERIALS)
    {
        println!(
            "  {name}: base {:?} metallic {} roughness {} transmission {} ior {} emission {:?}{} ({used} triangles)",
            m.base_color,
            m.metallic,
            m.roughness,
            m.transmission,
            m.ior,
            m.emission,
            if m.is_double_sided() { " double-sided" } else { "" }
        );
    }
    if scene.materials.len() > MAX_LISTED_MATERIALS {
        println!("  ... and {} more", scene.materials.len() - MAX_LISTED_MATERIALS);
    }
    println!("cameras: {}", scene.cameras.len());
    for (i, c) in scene.cameras.iter().enumerate() {
        let p: Vec3 = c.position;
        println!(
            "  {i}: {} at {:?} looking {:?}, yfov {:.2} deg",
            c.name,
            p.to_array(),
            c.forward.to_array(),
            c.yfov.to_degrees()
        );
        if let Some(a) = c.aspect_ratio {
            println!("     aspect ratio {a:.4}");
        }
    }
}
