//! Embeds every file under the repository's glsl/ (two folders up from this crate) into the
//! library so that kernels compile from any working directory, and the `#include` resolver sees
//! exactly the sources that were built; and writes the header `shader_interface.glsl` from the
//! Rust declarations of crates/interface/ (records, constants, bindings, limits), embedded
//! beside them. glsl/generated/ holds a copy of that header for GLSL tools, which a test keeps
//! equal to it; the kernels never read the copy.

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
            if path.file_name().is_some_and(|n| n == "generated") {
                continue;
            }
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
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let header = out_dir.join(restir_pt_interface::shader_interface::GLSL_HEADER_NAME);
    std::fs::write(&header, restir_pt_interface::shader_interface::glsl_header()).expect("OUT_DIR is writable");
    files.push((restir_pt_interface::shader_interface::GLSL_HEADER_NAME.to_string(), header));
    let mut table = String::from("&[\n");
    for (name, path) in &files {
        println!("cargo:rerun-if-changed={}", path.display());
        writeln!(table, "    ({name:?}, include_str!({:?})),", path.display().to_string()).expect("string write");
    }
    table.push_str("]\n");
    std::fs::write(out_dir.join("glsl_sources.rs"), table).expect("OUT_DIR is writable");
}
