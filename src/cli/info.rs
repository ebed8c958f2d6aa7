//! `restir-pt info`: what a scene contains.

use std::path::Path;

use anyhow::Result;
use glam::Vec3;

use super::{finish_device, load_with_warnings, open_device, DeviceArgs};
use crate::render::{PathTracer, RenderSettings, Restir, RestirSettings};
use crate::vk::KernelCompile;

/// Prints what `path` contains; with `kernels`, also builds the scene's kernels (the path
/// tracer's and ReSTIR PT's with the given settings) on the device and prints their costs.
pub fn info(path: &Path, kernels: Option<(RestirSettings, DeviceArgs)>) -> Result<()> {
    let scene = load_with_warnings(path)?;
    print_scene(path, &scene);
    if let Some((restir, device)) = kernels {
        let ctx = open_device(&device)?;
        let settings = RenderSettings {
            width: 8,
            height: 8,
            max_depth: crate::path_record::MAX_PATH_LENGTH as u32,
            ..Default::default()
        };
        let mut reports = vec![PathTracer::new(&ctx, &scene, &settings)?.compile_report().clone()];
        reports.extend(Restir::new(&ctx, &scene, &settings, &restir)?.compile_reports());
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

fn print_scene(path: &Path, scene: &crate::scene::Scene) {
    let (lo, hi) = scene.bounds;
    println!("scene: {}", path.display());
    println!("triangles: {}", scene.triangles.len());
    println!("BVH nodes: {}", scene.nodes.len());
    println!(
        "emitters: {} triangles, power {:.4} (luminance W)",
        scene.emitters.len(),
        scene.emitter_power
    );
    println!("environment: {:?}", scene.environment.to_array());
    println!(
        "bounds: {:?} .. {:?} (extent {:.4}), relative to the first camera at {:?} (world)",
        lo.to_array(),
        hi.to_array(),
        scene.extent(),
        scene.origin.to_array()
    );
    println!("materials: {}", scene.materials.len());
    for (m, name) in scene.materials.iter().zip(&scene.material_names) {
        let used = scene
            .triangles
            .iter()
            .filter(|t| scene.materials[t.material as usize] == *m)
            .count();
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
    }
}
