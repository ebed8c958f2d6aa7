//! Writes every bundled scene into scenes/ (run: `cargo run --release --example make_scenes`).

use std::path::Path;

fn main() -> anyhow::Result<()> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for scene in restir_pt::bundled_scenes::BUNDLED_SCENES {
        let path = dir.join(scene.file_name);
        std::fs::write(&path, (scene.build)()).map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
