//! Records against their GLSL layout: member offsets and array strides read from the SPIR-V
//! that glslang produced (OpMemberDecorate Offset, OpDecorate ArrayStride) must equal the
//! `#[repr(C)]` offsets and sizes of every record `shader_interface::records` lists, in a
//! kernel written here that declares them all and in the kernels that bind them; no GLSL file
//! declares a record or a generated constant by hand, and no Rust record escapes the
//! declaration that generates its GLSL; and every kernel's descriptor bindings (number, block
//! name, descriptor type) must be those that crates/interface/src/shader_interface.rs declares.

use std::collections::HashMap;

use crate::common::{repo_path, repository_files};

use restir_pt::glsl_record::{upper_snake, GlslDeclaration};
use restir_pt::render::{PassKernel, ReuseMis, ShiftKind};
use restir_pt::shader_interface::{records, PathTraceBinding, RestirBinding, SceneBinding, SurfaceBinding, GLSL_HEADER_NAME};
use restir_pt::vk::{
    check_bindings, compile_glsl_source, compile_kernel, glsl_source, reflect_bindings, spirv_instructions, Binding, BindingFamilyExt,
    BindingSlot, GLSL_SOURCES,
};

const OP_NAME: u32 = 5;
const OP_MEMBER_NAME: u32 = 6;
const OP_TYPE_ARRAY: u32 = 28;
const OP_TYPE_RUNTIME_ARRAY: u32 = 29;
const OP_DECORATE: u32 = 71;
const OP_MEMBER_DECORATE: u32 = 72;
const DECORATION_ARRAY_STRIDE: u32 = 6;
const DECORATION_OFFSET: u32 = 35;

#[derive(Default)]
struct Reflection {
    names: HashMap<u32, String>,
    member_names: HashMap<(u32, u32), String>,
    member_offsets: HashMap<(u32, u32), u32>,
    array_strides: HashMap<u32, u32>,
    array_elements: Vec<(u32, u32)>,
}

fn spirv_string(words: &[u32]) -> String {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).take_while(|&b| b != 0).collect();
    String::from_utf8(bytes).expect("SPIR-V strings are UTF-8")
}

fn reflect(spirv: &[u32]) -> Reflection {
    let mut r = Reflection::default();
    for (op, args) in spirv_instructions(spirv) {
        match op {
            OP_NAME => {
                r.names.insert(args[0], spirv_string(&args[1..]));
            }
            OP_MEMBER_NAME => {
                r.member_names.insert((args[0], args[1]), spirv_string(&args[2..]));
            }
            OP_MEMBER_DECORATE if args[2] == DECORATION_OFFSET => {
                r.member_offsets.insert((args[0], args[1]), args[3]);
            }
            OP_DECORATE if args[1] == DECORATION_ARRAY_STRIDE => {
                r.array_strides.insert(args[0], args[2]);
            }
            OP_TYPE_ARRAY | OP_TYPE_RUNTIME_ARRAY => r.array_elements.push((args[0], args[1])),
            _ => {}
        }
    }
    r
}

/// (struct name, size in bytes, (field, offset) pairs) of a Rust record.
type StructLayout = (&'static str, usize, Vec<(String, u32)>);

/// The layouts of the records `names`, read from their declarations.
fn layouts(names: &[&str]) -> Vec<StructLayout> {
    let all = records();
    names
        .iter()
        .map(|name| {
            let r = all
                .iter()
                .find(|r| r.name == *name)
                .unwrap_or_else(|| panic!("{name} is not a declared record"));
            (
                r.name,
                r.size,
                r.fields.iter().map(|f| (f.name.to_string(), f.offset as u32)).collect(),
            )
        })
        .collect()
}

fn scene_structs() -> Vec<StructLayout> {
    layouts(&["Material", "Triangle", "BvhNode", "Emitter", "FrameParams"])
}

fn check_layout(kernel: &str, defines: &[(&str, &str)], structs: Vec<StructLayout>) -> usize {
    let spirv = compile_kernel(kernel, defines).expect("kernel compiles");
    check_spirv_layout(kernel, &spirv, structs)
}

fn check_spirv_layout(kernel: &str, spirv: &[u32], structs: Vec<StructLayout>) -> usize {
    let r = reflect(spirv);
    let mut checked = 0;
    for (name, size, fields) in structs {
        // glslang also emits an undecorated copy of each struct for locals; only the copies with
        // explicit offsets describe memory.
        let ids: Vec<u32> = r
            .names
            .iter()
            .filter(|(id, n)| n.as_str() == name && r.member_offsets.contains_key(&(**id, 0)))
            .map(|(&id, _)| id)
            .collect();
        assert!(!ids.is_empty(), "{kernel}: struct {name} with explicit layout not found in SPIR-V");
        for id in ids {
            let mut glsl: Vec<(String, u32)> = (0..)
                .map_while(|m| Some((r.member_names.get(&(id, m))?.clone(), *r.member_offsets.get(&(id, m))?)))
                .collect();
            glsl.sort_by_key(|(_, o)| *o);
            assert_eq!(glsl, fields, "{kernel}: member names/offsets of {name} (GLSL left, Rust right)");
            for (array, _) in r.array_elements.iter().filter(|(_, element)| *element == id) {
                let stride = r.array_strides[array];
                assert_eq!(stride as usize, size, "{kernel}: array stride of {name}[] vs size_of::<{name}>()");
            }
            checked += 1;
        }
    }
    checked
}

/// The records of set 1 (glsl/interface/surface_bindings.glsl): per-triangle attributes, whose normals'
/// w carries the packed COLOR_0 (`surface::pack_vertex_color`), and the texture records.
fn surface_structs() -> Vec<StructLayout> {
    layouts(&["TriangleSurface", "TextureHeader", "TextureSlot", "MaterialTextures"])
}

#[test]
fn surface_records_match_glsl_layout() {
    let textured = [("SCENE_SURFACE", "1"), ("SCENE_TEXTURES", "1"), ("SCENE_SHADING_NORMALS", "1")];
    assert!(check_layout("pathtrace.comp", &textured, surface_structs()) >= 4);
}

#[test]
fn gpu_types_match_glsl_layout_in_storage_and_uniform_bindings() {
    assert!(check_layout("pathtrace.comp", &[], scene_structs()) >= 5);
    let uniform = [
        ("SCENE_UNIFORM_BUFFERS", "1"),
        ("SCENE_TRIANGLE_COUNT", "4"),
        ("SCENE_NODE_COUNT", "3"),
        ("SCENE_MATERIAL_COUNT", "2"),
        ("SCENE_EMITTER_SLOTS", "1"),
    ];
    assert!(check_layout("pathtrace.comp", &uniform, scene_structs()) >= 5);
}

#[test]
fn path_record_matches_glsl_layout() {
    let record = layouts(&["PathRecord"]);
    assert_eq!(check_layout("oracle/shift_oracle.comp", &[("ORACLE_SHIFT", "0")], record), 1);
}

#[test]
fn restir_structs_match_glsl_layout() {
    let structs = layouts(&[
        "ReuseParams",
        "Surface",
        "ReservoirHead",
        "ReservoirTail",
        "RestirStats",
        "RestirPass",
    ]);
    assert_eq!(check_layout("restir_spatial.comp", &[], structs), 6);
    let halves: usize = layouts(&["ReservoirHead", "ReservoirTail"]).iter().map(|(_, size, _)| size).sum();
    assert_eq!(halves, 96);
}

/// A kernel that declares every record: an array of each struct record and each block record as
/// its block, every one read so that glslang keeps it.
fn every_record_kernel() -> String {
    let mut declarations = String::new();
    let mut reads = String::new();
    for (i, r) in records().iter().enumerate() {
        let binding = i + 1;
        match r.declaration {
            GlslDeclaration::Struct => {
                declarations += &format!(
                    "layout(std430, set = 0, binding = {binding}) readonly buffer Records{i} {{ {} items{i}[]; }};\n",
                    r.name
                );
                reads += &format!("    sink[{i}] = uint(items{i}.length());\n");
            }
            GlslDeclaration::BlockFields => {
                let word = r
                    .fields
                    .iter()
                    .find(|f| f.glsl.starts_with("uint "))
                    .expect("a block record has a uint member");
                declarations += &format!(
                    "layout(std430, set = 0, binding = {binding}) readonly buffer {} {{ {}_FIELDS }} block{i};\n",
                    r.name,
                    upper_snake(r.name)
                );
                reads += &format!("    sink[{i}] = block{i}.{};\n", word.name);
            }
        }
    }
    format!(
        "#version 460\n#extension GL_GOOGLE_include_directive : require\n#include \"{GLSL_HEADER_NAME}\"\n\
         layout(local_size_x = 1) in;\n\
         layout(std430, set = 0, binding = 0) writeonly buffer Sink {{ uint sink[]; }};\n{declarations}\
         void main() {{\n{reads}}}\n"
    )
}

/// Every record of `shader_interface::records`, struct or block, nested or not, has glslang's
/// std430 offsets and stride; a record left out of the list is caught by the next test.
#[test]
fn every_declared_record_matches_glslang_layout() {
    let all = records();
    let spirv = compile_glsl_source("every_record.comp", &every_record_kernel(), &[]).expect("the generated records compile");
    let names: Vec<&str> = all.iter().map(|r| r.name).collect();
    assert_eq!(check_spirv_layout("every_record.comp", &spirv, layouts(&names)), all.len());
}

/// Records and constants are written once, in Rust: no GLSL source declares a struct of a
/// record's name, a block of a block record's name without its generated member list, or a
/// constant the header generates; and no Rust source outside the `gpu_record!` macro writes
/// `#[repr(C)]`, so every record shared with GLSL is a declared one.
#[test]
fn records_and_constants_are_declared_only_in_rust() {
    let all = records();
    let header = glsl_source(GLSL_HEADER_NAME).expect("the generated header is embedded");
    let constants: Vec<&str> = header
        .lines()
        .filter_map(|l| l.strip_prefix("const ")?.split_whitespace().nth(1))
        .collect();
    assert!(constants.len() >= 50 && constants.contains(&"NO_HIT"), "{constants:?}");
    let mut problems = Vec::new();
    for (name, text) in GLSL_SOURCES.iter().filter(|(n, _)| *n != GLSL_HEADER_NAME) {
        for line in text.lines().map(str::trim) {
            for r in &all {
                let by_hand = match r.declaration {
                    GlslDeclaration::Struct => line.starts_with(&format!("struct {} ", r.name)),
                    GlslDeclaration::BlockFields => {
                        line.contains(&format!("buffer {} ", r.name)) && !line.contains(&format!("{}_FIELDS", upper_snake(r.name)))
                    }
                };
                if by_hand {
                    problems.push(format!("glsl/{name}: {line}"));
                }
            }
            if let Some(rest) = line.strip_prefix("const ").or_else(|| line.strip_prefix("#define ")) {
                let words: Vec<&str> = rest.split_whitespace().collect();
                if words.iter().take(2).any(|w| constants.contains(w)) {
                    problems.push(format!("glsl/{name}: {line}"));
                }
            }
        }
    }
    let rust = repository_files("", "rs");
    assert!(rust.len() > 50, "the repository's Rust sources are found: {}", rust.len());
    let repr_c = "#[repr(".to_string() + "C)]";
    for path in &rust {
        let text = std::fs::read_to_string(repo_path(path)).expect("readable source");
        if path != "crates/interface/src/glsl_record.rs" && text.lines().any(|l| l.trim() == repr_c) {
            problems.push(format!("{path}: a `{repr_c}` struct not declared by gpu_record!"));
        }
        // Every record `gpu_record!` declares is listed in `records()`, so the header has it.
        let mut lines = text.lines().map(str::trim);
        while let Some(line) = lines.next() {
            if line != "gpu_record! {" {
                continue;
            }
            let declared = lines
                .find_map(|l| l.strip_prefix("pub struct "))
                .and_then(|l| l.split_whitespace().next());
            if let Some(name) = declared.filter(|n| !all.iter().any(|r| r.name == *n)) {
                problems.push(format!(
                    "{path}: {name} is declared by gpu_record! but not listed in shader_interface::records()"
                ));
            }
        }
    }
    assert!(problems.is_empty(), "written by hand:\n{}", problems.join("\n"));
}

/// Every repository path that a source file, kernel or document names (`glsl/...`,
/// `crates/.../*.rs`, `docs/*.md`, ...) exists: comments that point at moved or deleted files
/// are how twins drift apart. Placeholders in capitals (`scenes/NAME.gltf`) are not paths.
#[test]
fn no_source_or_document_names_a_missing_file() {
    let files: Vec<String> = ["rs", "md", "glsl", "comp", "py", "sh", "toml"]
        .iter()
        .flat_map(|ext| repository_files("", ext))
        .collect();
    let folders = [
        "glsl", "crates", "src", "tests", "docs", "tools", "scenes", "python", "examples", "fuzz",
    ];
    let extensions = [".rs", ".glsl", ".comp", ".md", ".py", ".sh", ".gltf", ".toml"];
    let path_char = |c: char| c.is_ascii_alphanumeric() || "_./-".contains(c);
    let mut missing = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(repo_path(file)).expect("readable source");
        for (start, _) in text.match_indices('/') {
            let head = text[..start]
                .char_indices()
                .rev()
                .find(|&(_, c)| !path_char(c))
                .map_or(0, |(i, c)| i + c.len_utf8());
            if !folders.contains(&&text[head..start]) || text[..head].ends_with(|c: char| path_char(c) || c == '/') {
                continue;
            }
            let end = text[start..].find(|c: char| !path_char(c)).map_or(text.len(), |i| start + i);
            let path = text[head..end].trim_end_matches('.');
            let Some(ext) = extensions.iter().find(|e| path.ends_with(*e)) else {
                continue;
            };
            let placeholder = path[..path.len() - ext.len()]
                .split('/')
                .any(|w| !w.is_empty() && w.chars().all(|c| c.is_ascii_uppercase()));
            if !placeholder && !repo_path(path).exists() {
                missing.push(format!("{file}: {path}"));
            }
        }
    }
    missing.sort();
    missing.dedup();
    assert!(missing.is_empty(), "names of files that do not exist:\n{}", missing.join("\n"));
}

/// glsl/generated/ holds the header the build generates, for GLSL tools (`glslangValidator -I
/// glsl/generated`), which cannot run the build script. `RESTIR_PT_BLESS=1` rewrites it.
#[test]
fn the_header_copy_for_glsl_tools_is_current() {
    let header = glsl_source(GLSL_HEADER_NAME).expect("the generated header is embedded");
    let copy = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("glsl/generated")
        .join(GLSL_HEADER_NAME);
    if std::env::var_os("RESTIR_PT_BLESS").is_some() {
        std::fs::write(&copy, header).expect("glsl/generated/ is writable");
    }
    let text = std::fs::read_to_string(&copy).unwrap_or_default();
    assert!(
        text == header,
        "{} differs from the header the build generated: run `RESTIR_PT_BLESS=1 cargo test --release --test suite the_header_copy` and commit it",
        copy.display()
    );
}

/// The uniform-buffer variant's defines, with small array sizes.
const UNIFORM_SCENE: [(&str, &str); 5] = [
    ("SCENE_UNIFORM_BUFFERS", "1"),
    ("SCENE_TRIANGLE_COUNT", "4"),
    ("SCENE_NODE_COUNT", "3"),
    ("SCENE_MATERIAL_COUNT", "2"),
    ("SCENE_EMITTER_SLOTS", "1"),
];

/// The host layout of a scene kernel: bindings 0-4 (the scene arrays as `scene`), then `own`.
fn host_layout(scene: Binding, own: impl Iterator<Item = BindingSlot>) -> Vec<BindingSlot> {
    let scene_slots = SceneBinding::ALL.iter().map(|&b| {
        let kind = if b == SceneBinding::FrameParams { Binding::Storage } else { scene };
        b.slot(kind)
    });
    scene_slots.chain(own).collect()
}

/// Every binding a kernel's SPIR-V declares, as (number, block, kind), must be the host's of
/// that number (the compiler drops blocks a kernel never reads). Returns the numbers found.
fn assert_bindings(kernel: &str, defines: &[(&str, &str)], layout: &[BindingSlot]) -> Vec<u32> {
    let spirv = compile_kernel(kernel, defines).expect("kernel compiles");
    let found = reflect_bindings(&spirv);
    for b in &found {
        assert_eq!(b.set, 0, "{kernel}: {} in set {}", b.block, b.set);
        let host = layout.iter().find(|s| s.binding == b.binding);
        assert_eq!(
            host.map(|s| (s.block, s.kind)),
            Some((b.block.as_str(), b.kind)),
            "{kernel} {defines:?}: binding {} in crates/interface/src/shader_interface.rs (left) vs SPIR-V (right)",
            b.binding
        );
    }
    check_bindings(kernel, &spirv, layout).expect("the start-up check agrees");
    found.iter().map(|b| b.binding).collect()
}

#[test]
fn every_kernel_declares_the_bindings_of_the_shader_interface() {
    let restir = || RestirBinding::ALL.iter().map(|b| b.slot(Binding::Storage));
    let pathtrace = || PathTraceBinding::ALL.iter().map(|b| b.slot(Binding::Storage));
    for (scene, defines) in [(Binding::Storage, &[][..]), (Binding::Uniform, &UNIFORM_SCENE[..])] {
        let layout = host_layout(scene, pathtrace());
        let found = assert_bindings("pathtrace.comp", defines, &layout);
        assert_eq!(found, (0..8).collect::<Vec<u32>>(), "pathtrace.comp reads every binding");
        let layout = host_layout(scene, restir());
        let mut used = vec![false; layout.len()];
        // Every kernel with the default shift and MIS, and the reuse kernels with the others
        // (each variant is a glslang compile of seconds, so not every product).
        let mut variants: Vec<(PassKernel, ShiftKind, ReuseMis)> = PassKernel::ALL
            .iter()
            .map(|&k| (k, ShiftKind::Hybrid, ReuseMis::GeneralizedBalance))
            .collect();
        if scene == Binding::Storage {
            variants.extend([
                (PassKernel::Spatial, ShiftKind::Reconnection, ReuseMis::Pairwise),
                (PassKernel::Temporal, ShiftKind::Replay, ReuseMis::Pairwise),
            ]);
        }
        for (kernel, shift, mis) in variants {
            let (file, extra) = kernel.source();
            let mut all: Vec<(&str, &str)> = defines.iter().chain(extra).copied().collect();
            all.extend([("SHIFT_MODE", shift.glsl_name()), ("MIS_MODE", mis.glsl_name())]);
            for b in assert_bindings(file, &all, &layout) {
                used[b as usize] = true;
            }
        }
        // Each binding is checked against a kernel that declares it.
        assert!(used.iter().all(|&u| u), "bindings no ReSTIR kernel declares: {used:?}");
    }
}

/// A textured scene's kernels declare descriptor set 1 as SurfaceBinding numbers it, and the
/// start-up check covers that set: two of its blocks swapped, or the set left out of the host
/// layout, are refused.
#[test]
fn textured_scene_kernels_declare_the_surface_set() {
    let textured = [("SCENE_SURFACE", "1"), ("SCENE_TEXTURES", "1"), ("SCENE_SHADING_NORMALS", "1")];
    let surface = || SurfaceBinding::ALL.iter().map(|b| b.slot(Binding::Storage));
    let expected: Vec<(u32, u32, String)> = SurfaceBinding::ALL
        .iter()
        .map(|b| (1, b.binding(), b.block().to_string()))
        .collect();
    let restir = || RestirBinding::ALL.iter().map(|b| b.slot(Binding::Storage));
    let pathtrace = || PathTraceBinding::ALL.iter().map(|b| b.slot(Binding::Storage));
    let (spatial, _) = PassKernel::Spatial.source();
    for (kernel, own) in [
        ("pathtrace.comp", pathtrace().collect::<Vec<_>>()),
        (spatial, restir().collect::<Vec<_>>()),
    ] {
        let spirv = compile_kernel(kernel, &textured).expect("kernel compiles");
        let set1: Vec<(u32, u32, String)> = reflect_bindings(&spirv)
            .into_iter()
            .filter(|b| b.set != 0)
            .map(|b| (b.set, b.binding, b.block))
            .collect();
        assert_eq!(set1, expected, "{kernel}: set 1 in the SPIR-V");
        let layout = host_layout(Binding::Storage, own.iter().copied().chain(surface()));
        check_bindings(kernel, &spirv, &layout).expect("the shader interface's own layout");

        let mut swapped = layout.clone();
        let at = |block: &str| swapped.iter().position(|s| s.set == 1 && s.block == block).expect("in the layout");
        let (headers, texels) = (at("TextureHeaders"), at("Texels"));
        swapped[headers].block = "Texels";
        swapped[texels].block = "TextureHeaders";
        let error = check_bindings(kernel, &spirv, &swapped).expect_err("swapped names are refused");
        assert!(
            error.contains("binding 2 is TextureHeaders") && error.contains("(set 1)"),
            "{error}"
        );

        let set0_only = host_layout(Binding::Storage, own.iter().copied());
        let error = check_bindings(kernel, &spirv, &set0_only).expect_err("set 1 missing from the host layout");
        assert!(error.contains("binding 0 (SurfaceAttributes) of set 1"), "{error}");
    }
}

#[test]
fn a_host_layout_with_two_buffers_swapped_is_refused() {
    let spirv = compile_kernel("restir_spatial.comp", &[]).expect("kernel compiles");
    let mut layout = host_layout(Binding::Storage, RestirBinding::ALL.iter().map(|b| b.slot(Binding::Storage)));
    check_bindings("restir_spatial.comp", &spirv, &layout).expect("the shader interface's own layout");
    let (heads0, heads1) = (
        RestirBinding::ReservoirHeads0.binding() as usize,
        RestirBinding::ReservoirHeads1.binding() as usize,
    );
    let (a, b) = (layout[heads0].block, layout[heads1].block);
    layout[heads0].block = b;
    layout[heads1].block = a;
    let error = check_bindings("restir_spatial.comp", &spirv, &layout).expect_err("swapped names are refused");
    assert!(
        error.contains("binding 8 is ReservoirHeads0") && error.contains("ReservoirHeads1"),
        "{error}"
    );
    let mut uniform = host_layout(Binding::Uniform, RestirBinding::ALL.iter().map(|b| b.slot(Binding::Storage)));
    let error = check_bindings("restir_spatial.comp", &spirv, &uniform).expect_err("a uniform scene against storage blocks");
    assert!(error.contains("binding 1 is Triangles (Storage)"), "{error}");
    uniform.truncate(18);
    let error = check_bindings("restir_spatial.comp", &spirv, &uniform[..]).expect_err("a missing binding");
    assert!(error.contains("binding 1") || error.contains("binding 18"), "{error}");
}
