//! `restir-pt info`: what a scene contains.

use std::path::Path;

use anyhow::Result;
use clap::Args;

use super::args::{DeviceArgs, RestirArgs, SceneArgs};
use super::{finish_device, load_with_options, open_device};
use restir_pt::render::{PathTracer, RenderSettings, Restir, SceneGpu};
use restir_pt::scene::Scene;
use restir_pt::vk::KernelCompile;

/// Materials listed one per line; a file can hold thousands.
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
    let path = args.scene.path()?;
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
            max_depth: restir_pt::shading::path_record::MAX_PATH_LENGTH as u32,
            ..Default::default()
        };
        let scene_gpu = SceneGpu::upload(&ctx, &scene)?;
        // One kernel at a time and no twin device, so that each stage's process CPU time is
        // that stage's alone.
        restir_pt::vk::set_compile_threads(0);
        restir_pt::vk::set_twin_compile(restir_pt::vk::TwinCompile::Off);
        let mut reports = vec![PathTracer::new(&scene_gpu, &settings)?.compile_report().clone()];
        reports.extend(Restir::new(&scene_gpu, &settings, &restir)?.compile_reports());
        drop(scene_gpu);
        print_kernels(&restir.label(), &reports);
        finish_device(&ctx)?;
    }
    Ok(())
}

/// One line per kernel: SPIR-V bytes and milliseconds of GLSL compile, pipeline creation and
/// first dispatch (where llvmpipe compiles), wall-clock and CPU time; the kernels are built one
/// at a time, so the CPU time of a stage is its own and other processes do not inflate it.
fn print_kernels(label: &str, reports: &[KernelCompile]) {
    println!("kernels ({label}; ms per stage: GLSL (0: from the SPIR-V cache), pipeline, first dispatch; wall-clock, then CPU):");
    for k in reports {
        println!(
            "  {:<38} {:>7} B SPIR-V | wall {:>6.0} {:>6.0} {:>6.0} = {:>6.0} | CPU {:>6.0} {:>6.0} {:>6.0} = {:>6.0}",
            k.name,
            k.spirv_bytes,
            k.glsl_ms,
            k.pipeline_ms,
            k.first_dispatch_ms,
            k.total_ms(),
            k.glsl_cpu_ms,
            k.pipeline_cpu_ms,
            k.first_dispatch_cpu_ms,
            k.total_cpu_ms()
        );
    }
    let total: f64 = reports.iter().map(|k| k.total_ms()).sum();
    let cpu: f64 = reports.iter().map(|k| k.total_cpu_ms()).sum();
    println!("  all kernels, one at a time: {total:.0} ms wall-clock, {cpu:.0} ms CPU");
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
    println!("{}", array_summary(scene));
    println!(
        "emitters: {} triangles, power {:.4} (luminance W); light tree: {} nodes",
        scene.emitters.len() - scene.lights.len(),
        scene.emitter_power,
        scene.light_nodes.len()
    );
    match &scene.environment_map {
        Some(map) => println!(
            "environment: {}x{} equirectangular map (importance-sampled by luminance)",
            map.width, map.height
        ),
        None => println!("environment: {}", rounded(scene.environment.to_array())),
    }
    println!(
        "bounds: {} .. {} (extent {}), relative to the origin at {} (world; the first camera, else the centre of the bounds)",
        rounded(lo.to_array()),
        rounded(hi.to_array()),
        round_for_people(scene.extent() as f64),
        rounded(scene.origin.to_array())
    );
    println!("punctual lights: {}", scene.lights.len());
    for (i, l) in scene.lights.iter().enumerate() {
        println!(
            "  {i}: {:?} at {} along {}, intensity {}",
            l.kind,
            rounded(l.position.to_array()),
            rounded(l.direction.to_array()),
            rounded(l.intensity.to_array())
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
            "  {name}: base {} metallic {} roughness {} transmission {} ior {} emission {}{} ({used} triangles)",
            rounded(m.base_color),
            round_for_people(m.metallic as f64),
            round_for_people(m.roughness as f64),
            round_for_people(m.transmission as f64),
            round_for_people(m.ior as f64),
            rounded(m.emission),
            if m.is_double_sided() { " double-sided" } else { "" }
        );
    }
    if scene.materials.len() > MAX_LISTED_MATERIALS {
        println!("  ... and {} more", scene.materials.len() - MAX_LISTED_MATERIALS);
    }
    println!("cameras: {}", scene.cameras.len());
    for (i, c) in scene.cameras.iter().enumerate() {
        println!(
            "  {i}: {} at {} looking {}, yfov {:.2} deg",
            c.name,
            rounded(c.position.to_array()),
            rounded(c.forward.to_array()),
            c.yfov.to_degrees()
        );
        if let Some(a) = c.aspect_ratio {
            println!("     aspect ratio {a:.4}");
        }
    }
}

/// The sizes of the scene's per-triangle and per-node device arrays, and what happens to an
/// array past one storage binding: scenes with one are reached by device address
/// (`SceneGpu::addressed`), each array then bounded by maxMemoryAllocationSize.
fn array_summary(scene: &Scene) -> String {
    let mib = |bytes: usize| bytes as f64 / (1024.0 * 1024.0);
    let arrays = [
        ("triangles", std::mem::size_of_val(scene.triangles.as_slice())),
        ("BVH nodes", std::mem::size_of_val(scene.nodes.as_slice())),
        ("vertex attributes", std::mem::size_of_val(scene.surfaces.as_slice())),
        ("texels", std::mem::size_of_val(scene.textures.texels.as_slice())),
    ];
    let parts: Vec<String> = arrays
        .iter()
        .map(|(name, bytes)| format!("{name} {:.2} MiB", mib(*bytes)))
        .collect();
    let largest = arrays.iter().map(|a| a.1).max().unwrap_or(0);
    format!(
        "device arrays: {}; the largest ({:.2} MiB) {} one storage binding of 128 MiB (lavapipe's maxStorageBufferRange; past it the arrays are reached by device address, each up to maxMemoryAllocationSize)",
        parts.join(", "),
        mib(largest),
        if largest as u64 > 1 << 27 { "exceeds" } else { "fits" }
    )
}

/// `x` to 4 significant digits, written as briefly as that value allows (3.9000000953674316
/// prints 3.9, 11.999994 prints 12, -0 prints 0): the file's values as a person wrote them.
fn round_for_people(x: f64) -> String {
    if !x.is_finite() {
        return x.to_string();
    }
    let four_digits: f64 = format!("{x:.3e}").parse().unwrap_or(x);
    // Adding 0 turns -0 into 0.
    (four_digits + 0.0).to_string()
}

/// A vector's components through [`round_for_people`], as `[x, y, z]`.
fn rounded<T: Copy + Into<f64>, const N: usize>(v: [T; N]) -> String {
    let parts: Vec<String> = v.iter().map(|&c| round_for_people(c.into())).collect();
    format!("[{}]", parts.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn info_rounds_numbers_to_four_significant_digits() {
        assert_eq!(round_for_people(3.9000000953674316), "3.9");
        assert_eq!(round_for_people(11.999994), "12");
        assert_eq!(round_for_people(-0.0), "0");
        assert_eq!(round_for_people(0.0), "0");
        assert_eq!(round_for_people(0.05), "0.05");
        assert_eq!(round_for_people(123456.0), "123500");
        assert_eq!(round_for_people(-1.23456e-7), "-0.0000001235");
        assert_eq!(round_for_people(f64::INFINITY), "inf");
        assert_eq!(rounded([17.0f32, 11.999994, 3.999998]), "[17, 12, 4]");
    }

    /// 110 instanced spheres with normals and UVs: 992,640 triangles, whose 144-byte vertex
    /// attributes (142,940,160 bytes) are the largest array and pass one 128 MiB binding.
    #[test]
    fn info_array_summary_names_the_largest_array_past_one_binding() {
        use restir_pt::scene::bundled_scenes::instanced_spheres;
        let text = instanced_spheres(11, 10);
        let scene = restir_pt::scene::load_scene_from_bytes(text.as_bytes(), None, Path::new("s.gltf")).unwrap();
        let line = array_summary(&scene);
        let expected = format!(
            "device arrays: triangles 45.44 MiB, BVH nodes {:.2} MiB, vertex attributes 136.32 MiB, texels 0.00 MiB; the largest (136.32 MiB) exceeds one storage binding",
            (scene.nodes.len() * 32) as f64 / (1024.0 * 1024.0)
        );
        assert!(line.starts_with(&expected), "{line}");
    }
}
