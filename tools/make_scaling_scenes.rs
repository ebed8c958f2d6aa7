//! Writes the scenes of the throughput-against-scene-size benchmark (README "Performance"): the
//! Cornell box with a tessellated sphere, about 10^2, 10^4 and 10^6 triangles in all, into the
//! folder given (default out/scaling). Run: `cargo run --release --example make_scaling_scenes`.

use std::path::PathBuf;

fn main() -> anyhow::Result<()> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("out/scaling"));
    std::fs::create_dir_all(&dir).map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", dir.display()))?;
    for (name, rings, segments) in [("1e2", 5, 8), ("1e4", 50, 100), ("1e6", 500, 1000)] {
        let path = dir.join(format!("cornell-sphere-{name}.gltf"));
        let gltf = restir_pt::scene::bundled_scenes::cornell_sphere(rings, segments);
        std::fs::write(&path, gltf).map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
