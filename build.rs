//! Embeds the checkout's commit (`RESTIR_PT_COMMIT`, written into sweep records) into the CLI.
//! The GLSL sources are embedded by crates/vk/build.rs.

use std::path::Path;

/// `git rev-parse --short HEAD` of the crate, or "unknown" without git or outside a repository;
/// rebuilds when HEAD moves.
fn embed_commit() {
    let dir = manifest_dir();
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .current_dir(&dir)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .and_then(|o| String::from_utf8(o.stdout).ok())
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
    };
    let commit = git(&["rev-parse", "--short", "HEAD"]).unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=RESTIR_PT_COMMIT={commit}");
    let head_ref = git(&["symbolic-ref", "-q", "HEAD"]);
    for name in ["HEAD", "packed-refs"].into_iter().map(String::from).chain(head_ref) {
        if let Some(path) = git(&["rev-parse", "--git-path", &name]) {
            let path = Path::new(&dir).join(path);
            if path.exists() {
                println!("cargo:rerun-if-changed={}", path.display());
            }
        }
    }
}

/// The package's folder, read when the script runs: `env!` would bake in the folder the script
/// was compiled in, and a build script reused from another checkout (a copied target/) would
/// then name that checkout's commit.
fn manifest_dir() -> String {
    std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR")
}

fn main() {
    embed_commit();
}
