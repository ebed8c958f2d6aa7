//! The on-disk SPIR-V cache (crates/vk/src/spirv_cache.rs): an entry is written on a miss and read back
//! on the next compile, a corrupt entry is compiled again and replaced, other defines are another
//! entry, and `RESTIR_PT_SPIRV_CACHE` places the cache or turns it off for the binary.

use std::process::Command;

use restir_pt::vk::{compile_kernel_cached_in, SPIRV_CACHE_ENV};

use crate::common::temp_file;

fn entries(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn spirv_cache_reuses_entries_and_replaces_corrupt_ones() {
    let dir = temp_file("placeholder", b"").parent().unwrap().join("spirv-cache");
    let _ = std::fs::remove_dir_all(&dir);
    let kernel = "oracle/bsdf_oracle.comp";
    let (first, hit) = compile_kernel_cached_in(kernel, &[], &dir).unwrap();
    assert!(!hit && first[0] == 0x0723_0203, "a miss compiles SPIR-V");
    let files = entries(&dir);
    assert_eq!(files.len(), 1, "{files:?}");
    let (again, hit) = compile_kernel_cached_in(kernel, &[], &dir).unwrap();
    assert!(hit && again == first, "the entry is read back word for word");
    std::fs::write(&files[0], b"not SPIR-V at all").unwrap();
    let (repaired, hit) = compile_kernel_cached_in(kernel, &[], &dir).unwrap();
    assert!(!hit && repaired == first, "a corrupt entry is compiled again");
    assert!(compile_kernel_cached_in(kernel, &[], &dir).unwrap().1, "and replaced");
    let (_, hit) = compile_kernel_cached_in(kernel, &[("SOME_DEFINE", "1")], &dir).unwrap();
    assert!(!hit && entries(&dir).len() == 2, "other defines are another entry");
}

#[test]
fn spirv_cache_follows_its_environment_variable() {
    let root = temp_file("placeholder", b"").parent().unwrap().join("spirv-cache-env");
    let _ = std::fs::remove_dir_all(&root);
    let run = |cache: &str, out: &str| {
        let status = Command::new(env!("CARGO_BIN_EXE_restir-pt"))
            .args(["render", "--method", "pt", "--spp", "1", "--width", "8", "--height", "8", "--out"])
            .arg(root.join(out))
            .env(SPIRV_CACHE_ENV, cache)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .unwrap();
        assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    };
    let dir = root.join("cache");
    run(dir.to_str().unwrap(), "a.exr");
    assert_eq!(entries(&dir).len(), 1, "the path tracer's kernel is cached in the named folder");
    std::fs::remove_dir_all(&dir).unwrap();
    run("off", "b.exr");
    assert!(!dir.exists(), "off writes nothing");
    assert_eq!(
        std::fs::read(root.join("a.exr")).unwrap(),
        std::fs::read(root.join("b.exr")).unwrap()
    );
}
