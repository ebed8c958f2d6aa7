//! Embeds every file under glsl/ into the binary so that kernels compile from any working
//! directory, and the `#include` resolver sees exactly the sources that were built.

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

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl");
    println!("cargo:rerun-if-changed=glsl");
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
