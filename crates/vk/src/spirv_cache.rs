//! The on-disk SPIR-V cache. Compiling GLSL with shaderc takes 0.1 to 1.9 s per kernel on one
//! core, most of a start-up once Mesa's shader cache holds the driver's own compile; the cache
//! keeps the SPIR-V of every kernel and set of defines across processes.
//!
//! An entry is `<key>.spv` in the cache folder, the key a SHA-256 over everything that decides the
//! SPIR-V: every embedded GLSL source and the generated interface header (any of them may be
//! included), the kernel's name, its defines in order, and the text of crates/vk/src/shader.rs, which
//! sets the compile options. A change to any of them is a new key, so entries never go stale; old
//! ones are only left behind. A cache that cannot be read or written is passed over: the kernel
//! is compiled as without it.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use sha2::{Digest, Sha256};

use super::shader::GLSL_SOURCES;

/// The environment variable that names the cache folder; the value `off` turns the cache off.
pub const SPIRV_CACHE_ENV: &str = "RESTIR_PT_SPIRV_CACHE";

/// The first word of every SPIR-V module (SPIR-V specification §3.1).
const SPIRV_MAGIC: u32 = 0x0723_0203;

/// The cache folder: `$RESTIR_PT_SPIRV_CACHE`, else `$XDG_CACHE_HOME/restir-pt/spirv`, else
/// `$HOME/.cache/restir-pt/spirv`; None when the variable is `off` or no folder is known.
pub fn cache_dir() -> Option<PathBuf> {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    if let Some(dir) = var(SPIRV_CACHE_ENV) {
        return (dir != "off").then(|| PathBuf::from(dir));
    }
    let base = var("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| var("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
    Some(base.join("restir-pt").join("spirv"))
}

/// The digest of every input shared by all kernels: the embedded GLSL tree with the generated
/// header, and the compile options' source, computed once per process.
fn sources_digest() -> &'static [u8; 32] {
    static DIGEST: OnceLock<[u8; 32]> = OnceLock::new();
    DIGEST.get_or_init(|| {
        let mut h = Sha256::new();
        for (name, text) in GLSL_SOURCES {
            hash_field(&mut h, name.as_bytes());
            hash_field(&mut h, text.as_bytes());
        }
        hash_field(&mut h, include_str!("shader.rs").as_bytes());
        h.finalize().into()
    })
}

/// Hashes `bytes` with its length first, so that no two sequences of fields hash alike.
fn hash_field(h: &mut Sha256, bytes: &[u8]) {
    h.update((bytes.len() as u64).to_le_bytes());
    h.update(bytes);
}

/// The cache key of kernel `name` (a path under glsl/) compiled with `defines`: 64 hex digits.
pub fn cache_key(name: &str, defines: &[(&str, &str)]) -> String {
    let mut h = Sha256::new();
    h.update(sources_digest());
    hash_field(&mut h, name.as_bytes());
    for (k, v) in defines {
        hash_field(&mut h, k.as_bytes());
        hash_field(&mut h, v.as_bytes());
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The SPIR-V words stored under `key` in `dir`, if there is a well-formed entry (a whole
/// number of words starting with the SPIR-V magic number).
pub fn load(dir: &Path, key: &str) -> Option<Vec<u32>> {
    let bytes = std::fs::read(dir.join(format!("{key}.spv"))).ok()?;
    if bytes.len() < 20 || bytes.len() % 4 != 0 {
        return None;
    }
    let words: Vec<u32> = bytes
        .chunks_exact(4)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        .collect();
    (words[0] == SPIRV_MAGIC).then_some(words)
}

/// Stores `spirv` under `key` in `dir`, creating the folder; written to a file of its own and
/// renamed into place, so that processes and threads compiling the same kernel at once never
/// read half an entry (each writer has a file name of its own). Failures are ignored: the cache
/// only saves time.
pub fn store(dir: &Path, key: &str, spirv: &[u32]) {
    static WRITES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    if std::fs::create_dir_all(dir).is_err() {
        return;
    }
    let write = WRITES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let temp = dir.join(format!("{key}.{}-{write}.tmp", std::process::id()));
    let bytes: Vec<u8> = spirv.iter().flat_map(|w| w.to_le_bytes()).collect();
    if std::fs::write(&temp, bytes).is_ok() && std::fs::rename(&temp, dir.join(format!("{key}.spv"))).is_err() {
        let _ = std::fs::remove_file(&temp);
    }
}
