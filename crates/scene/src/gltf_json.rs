//! The glTF JSON before the gltf crate validates it: required extensions are checked here so
//! that an unsupported one is refused with its cause first; parts the renderer ignores
//! (animations, skins) are removed with a warning, since the crate's stricter parse of them
//! would otherwise refuse files the spec allows; `EXT_mesh_gpu_instancing`, which the crate does
//! not know, is read from the raw JSON; external buffer files are checked to exist so that a
//! missing one is named.

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::Path;

use anyhow::{bail, Result};
use serde_json::Value;

use super::gltf_loader::problem;

/// `EXT_mesh_gpu_instancing` on one node: the accessor indices of its per-instance
/// TRANSLATION (VEC3), ROTATION (VEC4 quaternion) and SCALE (VEC3) attributes.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Instancing {
    pub translation: Option<usize>,
    pub rotation: Option<usize>,
    pub scale: Option<usize>,
}

/// The parsed file: the glTF JSON ready for the crate, the GLB binary chunk, per-node instancing
/// and the warnings gathered so far.
pub(super) struct RawGltf {
    pub json: Value,
    pub blob: Option<Vec<u8>>,
    pub instancing: HashMap<usize, Instancing>,
}

/// Extensions the loader handles beyond those the gltf crate is built with.
const HANDLED_HERE: &[&str] = &["EXT_mesh_gpu_instancing"];

/// Required extensions that only change textures, which are ignored anyway (factors are used).
const TEXTURE_ONLY: &[&str] = &[
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "EXT_texture_avif",
    "MSFT_texture_dds",
    "KHR_texture_transform",
];

/// What an unsupported required extension is, for the error's first words.
fn describe_extension(name: &str) -> &'static str {
    match name {
        "KHR_draco_mesh_compression" => "Draco-compressed geometry",
        "EXT_meshopt_compression" | "KHR_meshopt_compression" => "meshopt-compressed buffers",
        "KHR_mesh_quantization" => "quantized (integer) vertex positions",
        _ => "an extension this renderer does not implement",
    }
}

/// GLB files start with this magic, then a version and the total length (12 bytes).
const GLB_MAGIC: &[u8; 4] = b"glTF";
const GLB_HEADER_BYTES: usize = 12;

/// A file's JSON and, for GLB, its binary chunk.
type GltfChunks<'a> = (Cow<'a, [u8]>, Option<Vec<u8>>);

/// Checks the length a GLB header (at the start of `start`) declares against the file's length
/// `file_bytes`.
fn check_glb_length(start: &[u8], file_bytes: u64, path: &Path) -> Result<()> {
    let declared = start.get(8..12).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64);
    match declared {
        Some(length) if (GLB_HEADER_BYTES as u64..=file_bytes).contains(&length) => Ok(()),
        Some(length) => bail!(problem(
            path,
            format!("truncated or corrupt GLB: the header declares {length} bytes, the file has {file_bytes}")
        )),
        None => bail!(problem(
            path,
            format!("truncated GLB: {file_bytes} bytes, less than its 12-byte header")
        )),
    }
}

/// Splits GLB into its JSON and binary chunks, or takes the bytes as glTF JSON. A GLB header whose
/// length is shorter than the header itself makes the gltf crate's subtraction overflow (found by
/// fuzzing), so it is checked first.
fn split_glb<'a>(bytes: &'a [u8], path: &Path) -> Result<GltfChunks<'a>> {
    if !bytes.starts_with(GLB_MAGIC) {
        // Borrowed: a .gltf with embedded data can be hundreds of megabytes.
        return Ok((Cow::Borrowed(bytes), None));
    }
    check_glb_length(bytes, bytes.len() as u64, path)?;
    let glb = gltf::Glb::from_slice(bytes).map_err(|e| problem(path, format!("invalid GLB: {e}")))?;
    Ok((Cow::Owned(glb.json.into_owned()), glb.bin.map(|b| b.into_owned())))
}

/// The first non-blank byte of JSON text: an object's or an array's opening bracket (RFC 8259).
const JSON_TEXT_START: [u8; 2] = [b'{', b'['];

/// Why bytes that are neither GLB nor parseable JSON are no glTF file, from their first
/// non-blank byte (`None`: there is none): past leading white space JSON text starts with a
/// bracket; anything else is another kind of file (an image, an OBJ, a Blender file), which a
/// JSON parser's position says little about. `None` where they may be glTF JSON.
fn not_gltf_reason(first_non_blank: Option<&u8>) -> Option<&'static str> {
    match first_non_blank {
        Some(b) if JSON_TEXT_START.contains(b) => None,
        None => Some("the file is empty, not a glTF file"),
        Some(_) => Some("not a glTF file: neither glTF JSON (.gltf) nor binary glTF (.glb); convert it to glTF 2.0"),
    }
}

/// Checks that a file of `file_bytes` bytes whose first bytes are `start` can be glTF: GLB
/// whose header declares a length the file has, or JSON text. Fails with the loader's own
/// message otherwise, so that a command can refuse the file before the slow work that comes
/// before loading it (opening a device).
pub fn check_gltf_start(start: &[u8], file_bytes: u64, path: &Path) -> Result<()> {
    if start.starts_with(GLB_MAGIC) {
        return check_glb_length(start, file_bytes, path);
    }
    let whole = start.len() as u64 >= file_bytes;
    let first = start.iter().find(|b| !b.is_ascii_whitespace());
    match not_gltf_reason(first) {
        // White space up to the end of a prefix says nothing yet.
        Some(_) if first.is_none() && !whole => Ok(()),
        Some(reason) => bail!(problem(path, reason)),
        None => Ok(()),
    }
}

/// Reads the JSON and applies the checks and removals described in the module comment;
/// `warn` receives each warning (without the file name).
pub(super) fn read_raw(bytes: &[u8], path: &Path, warn: &mut dyn FnMut(String)) -> Result<RawGltf> {
    let (json_bytes, blob) = split_glb(bytes, path)?;
    let mut json: Value =
        serde_json::from_slice(&json_bytes).map_err(|e| match not_gltf_reason(json_bytes.iter().find(|b| !b.is_ascii_whitespace())) {
            Some(reason) => problem(path, reason),
            None => problem(path, format!("invalid glTF: {e}")),
        })?;
    if !json.is_object() {
        bail!(problem(path, "invalid glTF: the top level is not a JSON object"));
    }
    check_required_extensions(&mut json, path, warn)?;
    strip_animation(&mut json, warn);
    let instancing = read_instancing(&json);
    Ok(RawGltf { json, blob, instancing })
}

fn check_required_extensions(json: &mut Value, path: &Path, warn: &mut dyn FnMut(String)) -> Result<()> {
    let Some(required) = json.get_mut("extensionsRequired").and_then(Value::as_array_mut) else {
        return Ok(());
    };
    let names: Vec<String> = required.iter().filter_map(|v| v.as_str().map(str::to_string)).collect();
    for name in &names {
        let crate_handles = gltf::json::extensions::ENABLED_EXTENSIONS.contains(&name.as_str());
        if crate_handles || HANDLED_HERE.contains(&name.as_str()) {
            continue;
        }
        if TEXTURE_ONLY.contains(&name.as_str()) {
            warn(format!("required extension {name} only changes textures, which are ignored"));
            continue;
        }
        bail!(problem(
            path,
            format!(
                "{} (required extension {name}): not supported; export or convert the file without it",
                describe_extension(name)
            )
        ));
    }
    // The crate refuses required extensions it was not built with; those left are handled here.
    required.retain(|v| v.as_str().is_some_and(|n| gltf::json::extensions::ENABLED_EXTENSIONS.contains(&n)));
    Ok(())
}

/// Removes animations and skins (the bind pose is rendered) and reports morph targets, which the
/// crate parses and the loader ignores (the base shape is rendered).
fn strip_animation(json: &mut Value, warn: &mut dyn FnMut(String)) {
    let root = json.as_object_mut().expect("checked to be an object");
    if let Some(a) = root.remove("animations") {
        let n = a.as_array().map_or(0, Vec::len);
        if n > 0 {
            warn(format!(
                "{n} animation(s) ignored: the bind pose (node transforms as written) is rendered"
            ));
        }
    }
    let mut skinned = 0;
    if let Some(nodes) = root.get_mut("nodes").and_then(Value::as_array_mut) {
        for node in nodes.iter_mut().filter_map(Value::as_object_mut) {
            skinned += node.remove("skin").is_some() as usize;
        }
    }
    if root.remove("skins").is_some() || skinned > 0 {
        warn(format!("skins ignored on {skinned} node(s): the bind pose is rendered"));
    }
    let morphed = root.get("meshes").and_then(Value::as_array).map_or(0, |meshes| {
        meshes
            .iter()
            .filter_map(|m| m.get("primitives").and_then(Value::as_array))
            .flatten()
            .filter(|p| p.get("targets").is_some_and(|t| t.as_array().is_some_and(|t| !t.is_empty())))
            .count()
    });
    if morphed > 0 {
        warn(format!(
            "morph targets of {morphed} primitive(s) ignored: the base shape is rendered"
        ));
    }
}

fn read_instancing(json: &Value) -> HashMap<usize, Instancing> {
    let mut out = HashMap::new();
    let Some(nodes) = json.get("nodes").and_then(Value::as_array) else {
        return out;
    };
    for (i, node) in nodes.iter().enumerate() {
        let Some(attributes) = node.pointer("/extensions/EXT_mesh_gpu_instancing/attributes") else {
            continue;
        };
        let index = |name: &str| attributes.get(name).and_then(Value::as_u64).map(|v| v as usize);
        out.insert(
            i,
            Instancing {
                translation: index("TRANSLATION"),
                rotation: index("ROTATION"),
                scale: index("SCALE"),
            },
        );
    }
    out
}

/// Decodes the %XX escapes of a relative URI (glTF URIs are percent-encoded).
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (bytes[i], hex) {
            (b'%', Some(v)) => {
                out.push(v);
                i += 3;
            }
            (b, _) => {
                out.push(b);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Names the first external buffer file that does not exist or is shorter than its byteLength
/// (the crate's errors would not).
pub(super) fn check_external_buffers(json: &Value, base: Option<&Path>, path: &Path) -> Result<()> {
    let Some(buffers) = json.get("buffers").and_then(Value::as_array) else {
        return Ok(());
    };
    for (i, buffer) in buffers.iter().enumerate() {
        let Some(uri) = buffer.get("uri").and_then(Value::as_str) else {
            continue;
        };
        if uri.starts_with("data:") {
            continue;
        }
        let Some(base) = base else {
            bail!(problem(
                path,
                format!("buffer {i} refers to the external file {uri:?}, but the input has no folder")
            ));
        };
        let file = base.join(percent_decode(uri));
        let held = match std::fs::metadata(&file) {
            Ok(m) if m.is_file() => m.len(),
            _ => bail!(problem(
                path,
                format!("buffer {i}: external file {uri:?} not found (looked for {})", file.display())
            )),
        };
        // A truncated .bin is named here: the gltf crate's own message names neither the buffer's
        // file nor the glTF.
        let declared = buffer.get("byteLength").and_then(Value::as_u64).unwrap_or(0);
        if held < declared {
            bail!(problem(
                path,
                format!("buffer {i}: external file {uri:?} holds {held} bytes, fewer than its byteLength {declared} (truncated?)")
            ));
        }
    }
    Ok(())
}
