//! Embeds every file under the repository's glsl/ (two folders up from this crate) into the
//! library so that kernels compile from any working directory, and the `#include` resolver sees
//! exactly the sources that were built.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn collect(dir: &Path, root: &Path, out: &mut Vec<(String, PathBuf)>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("glsl/ is readable")
        .flatten()
        .map(|e| e.path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            collect(&path, root, out);
        } else if matches!(path.extension().and_then(|e| e.to_str()), Some("glsl" | "comp")) {
            let name = path.strip_prefix(root).expect("under root").to_string_lossy().replace('\\', "/");
            out.push((name, path.canonicalize().expect("file exists")));
        }
    }
}

/// The crate's folder, read when the script runs: `env!` would bake in the folder the script was
/// compiled in, and a build script reused from another checkout (a copied target/) would then
/// embed that checkout's kernels.
fn manifest_dir() -> String {
    std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR")
}

fn main() {
    let root = Path::new(&manifest_dir()).join("../../glsl");
    println!("cargo:rerun-if-changed=../../glsl");
    let mut files = Vec::new();
    collect(&root, &root, &mut files);
    let mut table = String::from("&[\n");
    for (name, path) in &files {
        println!("cargo:rerun-if-changed={}", path.display());
        writeln!(table, "    ({name:?}, include_str!({:?})),", path.display().to_string()).expect("string write");
    }
    table.push_str("]\n");
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("glsl_sources.rs");
    std::fs::write(out, table).expect("OUT_DIR is writable");
}
