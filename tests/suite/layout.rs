//! Host structs against the GLSL layout: member offsets and array strides read from the SPIR-V
//! that glslang produced (OpMemberDecorate Offset, OpDecorate ArrayStride) must equal the
//! `#[repr(C)]` offsets and sizes of the Rust twins in crates/interface/src/gpu_types.rs; and every kernel's
//! descriptor bindings (number, block name, descriptor type) must be those that
//! crates/interface/src/shader_interface.rs declares.

use std::collections::HashMap;

use restir_pt::gpu_types::{
    BvhNode, Emitter, FrameParams, Material, ReservoirHead, ReservoirTail, RestirPass, RestirStats, ReuseParams, Surface, Triangle,
};
use restir_pt::render::{PassKernel, ReuseMis, ShiftKind};
use restir_pt::shader_interface::{PathTraceBinding, RestirBinding, SceneBinding, SurfaceBinding};
use restir_pt::shading::path_record::PathRecord;
use restir_pt::vk::{check_bindings, compile_kernel, reflect_bindings, Binding, BindingFamilyExt, BindingSlot};

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
    let mut i = 5;
    while i < spirv.len() {
        let (count, op) = ((spirv[i] >> 16) as usize, spirv[i] & 0xffff);
        let args = &spirv[i + 1..i + count];
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
        i += count.max(1);
    }
    r
}

macro_rules! rust_fields {
    ($t:ty: $($f:ident),*) => {
        (stringify!($t), std::mem::size_of::<$t>(), vec![$((stringify!($f).to_string(), std::mem::offset_of!($t, $f) as u32)),*])
    };
}

/// (struct name, size in bytes, (field, offset) pairs) of a Rust twin.
type StructLayout = (&'static str, usize, Vec<(String, u32)>);

fn scene_structs() -> Vec<StructLayout> {
    vec![
        rust_fields!(Material: base_color, metallic, emission, roughness, transmission, ior, flags, specular, specular_color, pad),
        rust_fields!(Triangle: v0, material, e1, emitter, e2, alpha_tested),
        rust_fields!(BvhNode: lo, skip, hi, leaf),
        rust_fields!(Emitter: triangle, trail, intensity, leaf),
        rust_fields!(FrameParams: cam_position, cam_right, cam_up, cam_forward, scene_env, width, height, sample_offset,
            samples_per_dispatch, max_depth, render_seed, flags, emitter_count),
    ]
}

fn check_layout(kernel: &str, defines: &[(&str, &str)], structs: Vec<StructLayout>) -> usize {
    let spirv = compile_kernel(kernel, defines).expect("kernel compiles");
    let r = reflect(&spirv);
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
    use restir_pt::shading::surface::TriangleSurface;
    use restir_pt::shading::texture::{MaterialTextures, TextureHeader, TextureSlot};
    vec![
        rust_fields!(TriangleSurface: normal, tangent, uv),
        rust_fields!(TextureHeader: width, height, offset, sampler_bits),
        rust_fields!(TextureSlot: u_row, texture_index, v_row, texcoord),
        rust_fields!(MaterialTextures: base_color, metal_rough, emissive, normal, normal_scale, alpha_cutoff, alpha_mode, base_alpha),
    ]
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
    let record = vec![
        rust_fields!(PathRecord: seed, info, lobes, rc_triangle, rc_pos, rc_pdf, rc_next, rc_geometry, suffix,
        rc_pdf_after, contribution, rc_next_triangle),
    ];
    assert_eq!(check_layout("oracle/shift_oracle.comp", &[("ORACLE_SHIFT", "0")], record), 1);
}

#[test]
fn restir_structs_match_glsl_layout() {
    let structs = vec![
        rust_fields!(ReuseParams: prev_cam_position, prev_cam_right, prev_cam_up, prev_cam_forward, roughness_threshold,
            distance_threshold, m_cap, radius, normal_threshold, depth_threshold, frame_index, candidates, neighbours,
            temporal_valid, emission_rays, reservoirs, emission_history, passes),
        rust_fields!(Surface: pos, triangle, camera, depth),
        rust_fields!(ReservoirHead: seed, info, lobes, rc_triangle, rc_pos, rc_pdf, rc_next, rc_geometry),
        rust_fields!(ReservoirTail: suffix, rc_pdf_after, contribution, rc_next_triangle, weight, confidence, pad0, pad1),
        rust_fields!(RestirStats: max_loop_iterations, loop_budget_cut_groups, shifts_attempted, shifts_failed, nonfinite_weights,
            candidates_dropped, nonfinite_pixels, reuse_traversals, shift_subgroup_runs, subgroup_size),
        rust_fields!(RestirPass: in_slot, out_slot, prev_slot, surface_slot, pass_seed),
    ];
    assert_eq!(check_layout("restir_spatial.comp", &[], structs), 6);
    assert_eq!(std::mem::size_of::<ReservoirHead>() + std::mem::size_of::<ReservoirTail>(), 96);
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
