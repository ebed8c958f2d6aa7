//! Writes the scenes of the throughput-against-scene-size benchmark (docs/performance.md): the
//! Cornell box with a tessellated sphere, about 10^2, 10^4 and 10^6 triangles in all, into the
//! folder given (default out/scaling). With `--large` it adds the scale scenes of docs/scenes.md,
//! 3 and 8 million triangles (about 70 and 190 MB), past lavapipe's 128 MiB per binding, and
//! grids of a sphere with vertex normals and UVs drawn by `EXT_mesh_gpu_instancing`
//! (`instanced-spheres-1e6`, `-1e7`: 0.99 M and 10.1 M triangles, 143 MB and 1.46 GB of vertex
//! attributes, in files of under 1 MB).
//! Run: `cargo run --release --example make_scaling_scenes [-- DIR] [--large]`.

use std::path::PathBuf;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let large = args.iter().any(|a| a == "--large");
    let dir = args
        .iter()
        .find(|a| !a.starts_with("--"))
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("out/scaling"));
    std::fs::create_dir_all(&dir).map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", dir.display()))?;
    // The sphere has 2 * segments * (rings - 1) triangles; the box adds 32.
    let mut scenes = vec![("1e2", 5, 8), ("1e4", 50, 100), ("1e6", 500, 1000)];
    if large {
        scenes.extend([("3e6", 1001, 1500), ("8e6", 2001, 2000)]);
    }
    for (name, rings, segments) in scenes {
        let path = dir.join(format!("cornell-sphere-{name}.gltf"));
        let gltf = restir_pt::scene::bundled_scenes::cornell_sphere(rings, segments);
        std::fs::write(&path, gltf).map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    if large {
        for (name, columns, rows) in [("1e6", 11, 10), ("1e7", 34, 33)] {
            let path = dir.join(format!("instanced-spheres-{name}.gltf"));
            let gltf = restir_pt::scene::bundled_scenes::instanced_spheres(columns, rows);
            std::fs::write(&path, gltf).map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
            println!("wrote {}", path.display());
        }
    }
    Ok(())
}
