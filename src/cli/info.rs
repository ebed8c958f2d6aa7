//! `restir-pt info`: what a scene contains.

use std::path::Path;

use anyhow::Result;
use glam::Vec3;

use super::load_with_options;
use crate::scene::LoadOptions;

/// Materials listed one per line; vertex colours can make thousands of variants.
const MAX_LISTED_MATERIALS: usize = 64;

pub fn info(path: &Path, options: &LoadOptions) -> Result<()> {
    let start = std::time::Instant::now();
    let scene = load_with_options(path, options)?;
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    let (lo, hi) = scene.bounds;
    println!("scene: {}", path.display());
    println!("triangles: {}", scene.triangles.len());
    println!(
        "loaded in {load_ms:.0} ms, of which BVH build and emitter table {:.0} ms",
        scene.build_ms
    );
    println!("BVH nodes: {}", scene.nodes.len());
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
    println!("bounds: {:?} .. {:?} (extent {:.4})", lo.to_array(), hi.to_array(), scene.extent());
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
    let mut uses = vec![0usize; scene.materials.len()];
    scene.triangles.iter().for_each(|t| uses[t.material as usize] += 1);
    for ((m, name), used) in scene
        .materials
        .iter()
        .zip(&scene.material_names)
        .zip(uses)
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
    Ok(())
}
