//! Writes every bundled scene into scenes/ (run: `cargo run --release --example make_scenes`), or
//! with `--tiled-floor LEVELS OUT.gltf` a scale-test floor of 2^LEVELS x 2048 triangles
//! (`bundled_scenes::tiled_floor`).

use std::path::Path;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [flag, levels, out] = &args[..] {
        anyhow::ensure!(flag == "--tiled-floor", "usage: make_scenes [--tiled-floor LEVELS OUT.gltf]");
        let levels: u32 = levels.parse()?;
        std::fs::write(out, restir_pt::scene::bundled_scenes::tiled_floor(levels))?;
        println!(
            "wrote {out} ({} triangles)",
            (1usize << levels) * restir_pt::scene::bundled_scenes::TILE_TRIANGLES
        );
        return Ok(());
    }
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for scene in restir_pt::scene::bundled_scenes::BUNDLED_SCENES {
        let path = dir.join(scene.file_name);
        std::fs::write(&path, (scene.build)()).map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
