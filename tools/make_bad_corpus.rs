//! Writes the malformed-input corpus in tests/data/bad/ (run:
//! `cargo run --release --example make_bad_corpus`). tests/data/bad/expected.txt says what each
//! file must produce; the suite checks every file against it.

use std::path::Path;

use glam::Vec3;
use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};
use serde_json::{json, Value};

/// A floor, a ceiling light and a camera: a valid scene that each case then breaks.
fn base(floor: MeshData, lamp: MeshData) -> Value {
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let light = b.material("light", MaterialSpec::emitter(Vec3::splat(5.0)));
    let f = b.mesh("floor", &floor, grey);
    b.instance("floor", f, 0.0, Vec3::ZERO);
    let l = b.mesh("lamp", &lamp, light);
    b.instance("lamp", l, 0.0, Vec3::ZERO);
    b.camera("camera", Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO, 0.8);
    serde_json::from_str(&b.finish("bad", Vec3::ZERO)).expect("the builder writes JSON")
}

fn floor() -> MeshData {
    MeshData::quad(Vec3::new(-1.0, 0.0, -1.0), Vec3::Z * 2.0, Vec3::X * 2.0)
}

fn lamp() -> MeshData {
    MeshData::quad(Vec3::new(-0.2, 1.0, -0.2), Vec3::X * 0.4, Vec3::Z * 0.4)
}

fn edited(edit: impl FnOnce(&mut Value)) -> Vec<u8> {
    let mut v = base(floor(), lamp());
    edit(&mut v);
    serde_json::to_vec_pretty(&v).expect("JSON values serialise")
}

/// A binary glTF of `json`, with its (decoded) buffer as the BIN chunk.
fn glb(mut json: Value) -> Vec<u8> {
    let uri = json["buffers"][0]["uri"].as_str().expect("embedded buffer").to_string();
    let bin = decode_base64(uri.split(',').nth(1).expect("data URI"));
    json["buffers"][0].as_object_mut().expect("buffer object").remove("uri");
    let mut text = serde_json::to_vec(&json).expect("JSON values serialise");
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut bin = bin;
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(text);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// The floor drawn as a triangle strip and the lamp as a triangle fan (same triangles, same
/// winding as the quads' lists).
fn strips_and_fans() -> Value {
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let light = b.material("light", MaterialSpec::emitter(Vec3::splat(5.0)));
    let f = b.mesh_primitive("floor strip", &floor().positions, &[1, 2, 0, 3], 5, None, grey);
    b.instance("floor", f, 0.0, Vec3::ZERO);
    let l = b.mesh_primitive("lamp fan", &lamp().positions, &[0, 1, 2, 3], 6, None, light);
    b.instance("lamp", l, 0.0, Vec3::ZERO);
    let segment = b.mesh_primitive("a line", &[Vec3::ZERO, Vec3::Y], &[0, 1], 1, None, grey);
    b.instance("line", segment, 0.0, Vec3::ZERO);
    b.camera("camera", Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO, 0.8);
    serde_json::from_str(&b.finish("strips and fans", Vec3::ZERO)).expect("the builder writes JSON")
}

/// Three instances of a small floor tile through EXT_mesh_gpu_instancing, under the lamp.
fn instanced() -> Value {
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let light = b.material("light", MaterialSpec::emitter(Vec3::splat(5.0)));
    let tile = MeshData::quad(Vec3::new(-0.3, 0.0, -0.3), Vec3::Z * 0.6, Vec3::X * 0.6);
    let t = b.mesh("tile", &tile, grey);
    b.instanced("tiles", t, &[Vec3::new(-0.7, 0.0, 0.0), Vec3::ZERO, Vec3::new(0.7, 0.0, 0.0)]);
    let l = b.mesh("lamp", &lamp(), light);
    b.instance("lamp", l, 0.0, Vec3::ZERO);
    b.camera("camera", Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO, 0.8);
    serde_json::from_str(&b.finish("instanced", Vec3::ZERO)).expect("the builder writes JSON")
}

/// A floor with per-vertex colours (red, green, blue, white corners) and the lamp.
fn vertex_colours() -> Value {
    let mut b = GltfBuilder::default();
    let white = b.material("white", MaterialSpec::diffuse(Vec3::ONE));
    let light = b.material("light", MaterialSpec::emitter(Vec3::splat(5.0)));
    let f = floor();
    let colours = [Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE];
    let m = b.mesh_primitive("floor", &f.positions, &f.indices, 4, Some(&colours), white);
    b.instance("floor", m, 0.0, Vec3::ZERO);
    let l = b.mesh("lamp", &lamp(), light);
    b.instance("lamp", l, 0.0, Vec3::ZERO);
    b.camera("camera", Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO, 0.8);
    serde_json::from_str(&b.finish("vertex colours", Vec3::ZERO)).expect("the builder writes JSON")
}

/// The floor lit by a point light 1 above it (no emissive triangle, no environment).
fn punctual_lit() -> Value {
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let f = b.mesh("floor", &floor(), grey);
    b.instance("floor", f, 0.0, Vec3::ZERO);
    b.punctual_light(
        json!({ "type": "point", "color": [1.0, 0.9, 0.8], "intensity": 3.0 }),
        Vec3::Y,
        -Vec3::Y,
    );
    b.punctual_light(
        json!({ "type": "spot", "intensity": 5.0, "spot": { "innerConeAngle": 0.3, "outerConeAngle": 0.6 } }),
        Vec3::new(0.5, 1.5, 0.5),
        -Vec3::Y,
    );
    b.punctual_light(
        json!({ "type": "directional", "intensity": 0.5 }),
        Vec3::ZERO,
        Vec3::new(0.3, -1.0, 0.2),
    );
    b.camera("camera", Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO, 0.8);
    serde_json::from_str(&b.finish("punctual", Vec3::ZERO)).expect("the builder writes JSON")
}

fn decode_base64(s: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    };
    let digits: Vec<u8> = s.bytes().filter(|&c| c != b'=').map(value).collect();
    digits
        .chunks(4)
        .flat_map(|c| {
            let n = c.iter().enumerate().fold(0u32, |n, (i, &d)| n | (d as u32) << (18 - 6 * i));
            let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
            bytes.into_iter().take(c.len() - 1)
        })
        .collect()
}

/// A corpus file: its name in tests/data/bad/ and its bytes.
type Case = (&'static str, Vec<u8>);

/// glTF JSON cut off inside the scene list.
const CUT_OFF_JSON: &[u8] = b"{ \"asset\": { \"version\": \"2.0\" }, \"scenes\": [ { \"nodes\": [0";

/// Files that are not a readable glTF at all (and the valid binary one they are cut from).
fn unreadable_files() -> anyhow::Result<Vec<Case>> {
    let valid = glb(base(floor(), lamp()));
    Ok(vec![
        ("truncated.glb", valid[..valid.len() / 2].to_vec()),
        ("valid.glb", valid.clone()),
        ("bad-json.gltf", CUT_OFF_JSON.to_vec()),
        ("not-gltf.gltf", b"this is not a glTF file\n".to_vec()),
        ("empty-file.gltf", Vec::new()),
        ("missing-bin.gltf", edited(|v| v["buffers"][0]["uri"] = json!("missing.bin"))),
    ])
}

/// Valid glTF using features the loader handles or warns about.
fn odd_but_usable() -> anyhow::Result<Vec<Case>> {
    Ok(vec![
        ("strips-and-fans.gltf", serde_json::to_vec_pretty(&strips_and_fans())?),
        ("instanced.gltf", serde_json::to_vec_pretty(&instanced())?),
        ("vertex-colours.gltf", serde_json::to_vec_pretty(&vertex_colours())?),
        ("punctual-lit.gltf", serde_json::to_vec_pretty(&punctual_lit())?),
        (
            "animated.gltf",
            edited(|v| {
                // A channel without a target node is valid glTF (KHR_animation_pointer uses it).
                v["animations"] = json!([{
                    "channels": [{ "sampler": 0, "target": { "path": "translation" } }],
                    "samplers": [{ "input": 0, "output": 0 }],
                }]);
                v["meshes"][0]["primitives"][0]["targets"] = json!([{ "POSITION": 0 }]);
            }),
        ),
        (
            "unlit.gltf",
            edited(|v| {
                v["materials"][0]["extensions"] = json!({ "KHR_materials_unlit": {} });
                v["extensionsUsed"] = json!(["KHR_materials_unlit"]);
                v["extensionsRequired"] = json!(["KHR_materials_unlit"]);
            }),
        ),
        (
            "spec-gloss.gltf",
            edited(|v| {
                v["materials"][0]["extensions"] = json!({ "KHR_materials_pbrSpecularGlossiness": {
                    "diffuseFactor": [0.5, 0.4, 0.3, 1.0], "specularFactor": [0.04, 0.04, 0.04], "glossinessFactor": 0.2 } });
                v["extensionsUsed"] = json!(["KHR_materials_pbrSpecularGlossiness"]);
                v["extensionsRequired"] = json!(["KHR_materials_pbrSpecularGlossiness"]);
            }),
        ),
        (
            "meshopt-required.gltf",
            edited(|v| {
                v["extensionsUsed"] = json!(["EXT_meshopt_compression"]);
                v["extensionsRequired"] = json!(["EXT_meshopt_compression"]);
            }),
        ),
    ])
}

/// Broken or degenerate geometry and out-of-range material values.
fn bad_geometry_and_materials() -> anyhow::Result<Vec<Case>> {
    let mut nan = floor();
    nan.positions[1].x = f32::NAN;
    let mut inf = floor();
    inf.positions[2].z = f32::INFINITY;
    let mut out_of_range = floor();
    out_of_range.indices[5] = 1000;
    let flat = MeshData {
        positions: vec![Vec3::Y, Vec3::new(1.0, 1.0, 0.0), Vec3::new(2.0, 1.0, 0.0)],
        indices: vec![0, 1, 2],
    };
    let degenerate = floor().merged(&MeshData {
        positions: vec![Vec3::ZERO; 3],
        indices: vec![0, 1, 2],
    });
    Ok(vec![
        (
            "warnings-then-error.gltf",
            edited(|v| {
                v["animations"] = json!([{ "channels": [], "samplers": [] }]);
                v["accessors"][0]["count"] = json!(1_000_000_000u64);
            }),
        ),
        ("index-out-of-range.gltf", serde_json::to_vec_pretty(&base(out_of_range, lamp()))?),
        (
            "index-accessor-overflow.gltf",
            edited(|v| {
                // One index more than the buffer view holds: without a check the reader gives up
                // and the vertices would be drawn in order.
                let i = v["meshes"][0]["primitives"][0]["indices"].as_u64().expect("indexed floor") as usize;
                let count = v["accessors"][i]["count"].as_u64().expect("a count");
                v["accessors"][i]["count"] = json!(count + 1);
            }),
        ),
        ("nan-position.gltf", serde_json::to_vec_pretty(&base(nan, lamp()))?),
        ("inf-position.gltf", serde_json::to_vec_pretty(&base(inf, lamp()))?),
        (
            "negative-roughness.gltf",
            edited(|v| v["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] = json!(-0.5)),
        ),
        (
            "negative-base-color.gltf",
            edited(|v| v["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = json!([-1.0, 0.5, 0.5, 1.0])),
        ),
        (
            "negative-emission.gltf",
            edited(|v| v["materials"][1]["emissiveFactor"] = json!([-1.0, 1.0, 1.0])),
        ),
        (
            "ior-below-one.gltf",
            edited(|v| {
                v["materials"][0]["extensions"] =
                    json!({ "KHR_materials_ior": { "ior": 0.5 }, "KHR_materials_transmission": { "transmissionFactor": 1.0 } });
                v["extensionsUsed"] = json!(["KHR_materials_ior", "KHR_materials_transmission"]);
            }),
        ),
        (
            "zero-area-emitter.gltf",
            serde_json::to_vec_pretty(&base(floor(), lamp().merged(&flat)))?,
        ),
        (
            "only-zero-area-emitter.gltf",
            serde_json::to_vec_pretty(&base(floor(), flat.clone()))?,
        ),
        ("degenerate-triangles.gltf", serde_json::to_vec_pretty(&base(degenerate, lamp()))?),
        (
            "no-light.gltf",
            edited(|v| {
                v["materials"][1]
                    .as_object_mut()
                    .expect("material")
                    .remove("emissiveFactor")
                    .map(|_| ())
                    .unwrap_or(())
            }),
        ),
    ])
}

/// Broken document structure: extensions, references, scenes and node graphs.
fn bad_structure() -> anyhow::Result<Vec<Case>> {
    Ok(vec![
        (
            "unsupported-required-extension.gltf",
            edited(|v| {
                v["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
                v["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
            }),
        ),
        (
            "texture.gltf",
            edited(|v| {
                v["images"] = json!([{ "uri": "no-such-image.png" }]);
                v["textures"] = json!([{ "source": 0 }]);
                v["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": 0 });
            }),
        ),
        ("no-camera.gltf", edited(|v| v["scenes"][0]["nodes"] = json!([0, 1]))),
        (
            "no-scene.gltf",
            edited(|v| {
                let o = v.as_object_mut().expect("root object");
                o.remove("scene");
                o.remove("scenes");
            }),
        ),
        (
            "accessor-overflow.gltf",
            edited(|v| v["accessors"][0]["count"] = json!(1_000_000_000u64)),
        ),
    ])
}

/// Each node instances the next twice: 2^40 instances of the floor if walked naively.
fn absurd_node_count(v: &mut Value) {
    let mut nodes: Vec<Value> = (0..40).map(|i| json!({ "children": [i + 1, i + 1] })).collect();
    nodes.push(json!({ "mesh": 0 }));
    let offset = v["nodes"].as_array().expect("nodes").len();
    for n in nodes.iter_mut() {
        if let Some(c) = n.get_mut("children") {
            *c = json!(c
                .as_array()
                .expect("children")
                .iter()
                .map(|x| x.as_u64().expect("index") as usize + offset)
                .collect::<Vec<_>>());
        }
    }
    v["nodes"].as_array_mut().expect("nodes").extend(nodes);
    v["scenes"][0]["nodes"].as_array_mut().expect("roots").push(json!(offset));
}

/// A chain of 400 nodes, each the only child of the one before, ending in the floor mesh.
fn deep_hierarchy(v: &mut Value) {
    let offset = v["nodes"].as_array().expect("nodes").len();
    let chain: Vec<Value> = (0..400)
        .map(|i| {
            if i < 399 {
                json!({ "children": [offset + i + 1] })
            } else {
                json!({ "mesh": 0 })
            }
        })
        .collect();
    v["nodes"].as_array_mut().expect("nodes").extend(chain);
    v["scenes"][0]["nodes"].as_array_mut().expect("roots").push(json!(offset));
}

fn main() -> anyhow::Result<()> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad");
    let mut cases = unreadable_files()?;
    cases.extend(odd_but_usable()?);
    cases.extend(bad_geometry_and_materials()?);
    cases.extend(bad_structure()?);
    cases.push(("absurd-node-count.gltf", edited(absurd_node_count)));
    cases.push(("deep-hierarchy.gltf", edited(deep_hierarchy)));
    for (name, bytes) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
