//! `restir-pt info`: what a scene contains.

use std::path::Path;

use anyhow::Result;
use glam::Vec3;

use super::load_with_warnings;

pub fn info(path: &Path) -> Result<()> {
    let scene = load_with_warnings(path)?;
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
    Ok(())
}
