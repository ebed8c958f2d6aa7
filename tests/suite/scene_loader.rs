//! The glTF loader checks the data, not only the JSON: each problem is an error or a warning
//! that names the file.

use glam::Vec3;
use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};
use restir_pt::scene::load_scene;
use serde_json::{json, Value};

use crate::common::{repo_path, temp_file};

/// A lit quad and a camera; `edit` may change the JSON before it is written.
fn scene_file(name: &str, mesh: MeshData, emitter: Option<MeshData>, edit: impl FnOnce(&mut Value)) -> std::path::PathBuf {
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let m = b.mesh("geometry", &mesh, grey);
    b.instance("geometry", m, 0.0, Vec3::ZERO);
    if let Some(e) = emitter {
        let light = b.material("light", MaterialSpec::emitter(Vec3::splat(5.0)));
        let l = b.mesh("light", &e, light);
        b.instance("light", l, 0.0, Vec3::ZERO);
    }
    b.camera("camera", Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO, 0.8);
    let mut value: Value = serde_json::from_str(&b.finish("test", Vec3::ZERO)).unwrap();
    edit(&mut value);
    temp_file(name, serde_json::to_string(&value).unwrap().as_bytes())
}

fn floor() -> MeshData {
    MeshData::quad(Vec3::new(-1.0, 0.0, -1.0), Vec3::Z * 2.0, Vec3::X * 2.0)
}

fn lamp() -> MeshData {
    MeshData::quad(Vec3::new(-0.2, 1.0, -0.2), Vec3::X * 0.4, Vec3::Z * 0.4)
}

fn load_error(path: &std::path::Path) -> String {
    format!("{:#}", load_scene(path).err().expect("the scene must be rejected"))
}

#[test]
fn loader_reads_the_bundled_cornell_box() {
    let scene = load_scene(&repo_path("scenes/cornell.gltf")).unwrap();
    assert_eq!(scene.triangles.len(), 36);
    assert_eq!(scene.emitters.len(), 2);
    assert_eq!(scene.cameras.len(), 8);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let light_power = 0.47 * 0.38 * std::f32::consts::PI * restir_pt::scene::luminance(Vec3::new(17.0, 12.0, 4.0));
    assert!((scene.emitter_power - light_power).abs() < 1e-3 * light_power);
}

#[test]
fn loader_rejects_nan_positions_and_bad_indices_naming_the_file() {
    let mut nan = floor();
    nan.positions[2].y = f32::NAN;
    let path = scene_file("nan.gltf", nan, Some(lamp()), |_| {});
    let e = load_error(&path);
    assert!(e.contains("nan.gltf") && e.contains("NaN"), "{e}");

    let mut bad = floor();
    bad.indices[4] = 77;
    let path = scene_file("index.gltf", bad, Some(lamp()), |_| {});
    let e = load_error(&path);
    assert!(e.contains("index.gltf") && e.contains("index 77 is out of range"), "{e}");
}

#[test]
fn loader_drops_degenerate_triangles_and_zero_area_emitters_with_warnings() {
    let mut geometry = floor();
    geometry.positions.extend([Vec3::ZERO, Vec3::X, Vec3::X * 2.0]);
    geometry.indices.extend([4, 5, 6]);
    let flat_lamp = MeshData {
        positions: vec![Vec3::Y, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)],
        indices: vec![0, 1, 2],
    };
    let path = scene_file("degenerate.gltf", geometry, Some(lamp().merged(&flat_lamp)), |_| {});
    let scene = load_scene(&path).unwrap();
    assert_eq!(scene.triangles.len(), 4);
    assert_eq!(scene.emitters.len(), 2);
    let warnings = scene.warnings.join("\n");
    assert!(
        warnings.contains("degenerate.gltf") && warnings.contains("2 degenerate"),
        "{warnings}"
    );
    assert!(warnings.contains("1 zero-area emitter"), "{warnings}");
}

#[test]
fn loader_gives_a_lightless_scene_the_default_environment_and_rejects_one_without_triangles() {
    let path = scene_file("dark.gltf", floor(), None, |_| {});
    let scene = load_scene(&path).unwrap();
    assert_eq!(scene.environment, restir_pt::scene::DEFAULT_ENVIRONMENT);
    assert_eq!(scene.environment, Vec3::ONE);
    assert_eq!(scene.env_select_prob, 1.0);
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.contains("dark.gltf") && w.contains("no light") && w.contains("radiance 1")),
        "{:?}",
        scene.warnings
    );
    let empty = MeshData {
        positions: vec![Vec3::ZERO; 3],
        indices: vec![0, 1, 2],
    };
    let path = scene_file("empty.gltf", empty, None, |v| {
        v["scenes"][0]["extras"] = json!({ "environment": [1, 1, 1] })
    });
    assert!(load_error(&path).contains("no renderable triangles"));
}

#[test]
fn loader_reads_environment_and_rejects_bad_values() {
    let path = scene_file("env.gltf", floor(), None, |v| {
        v["scenes"][0]["extras"] = json!({ "environment": [0.5, 1.0, 2.0] })
    });
    let scene = load_scene(&path).unwrap();
    assert_eq!(scene.environment, Vec3::new(0.5, 1.0, 2.0));
    assert_eq!(scene.env_select_prob, 1.0);
    let path = scene_file("badenv.gltf", floor(), None, |v| {
        v["scenes"][0]["extras"] = json!({ "environment": [-1, 0, 0] })
    });
    assert!(load_error(&path).contains("environment"));
    let path = scene_file("badmat.gltf", floor(), Some(lamp()), |v| {
        v["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] = json!(-0.5)
    });
    let e = load_error(&path);
    assert!(
        e.contains("badmat.gltf") && e.contains("grey") && e.contains("roughnessFactor"),
        "{e}"
    );
}

#[test]
fn loader_warns_about_textures_and_rejects_unsupported_required_extensions() {
    // A texture the renderer does not read is reported and its image never opened (it is
    // missing here); one it reads (base colour, docs/textures.md) whose file is missing is
    // warned about and left out.
    let path = scene_file("texture.gltf", floor(), Some(lamp()), |v| {
        v["images"] = json!([{ "uri": "missing.png" }]);
        v["textures"] = json!([{ "source": 0 }]);
        v["extensionsUsed"] = json!(["KHR_materials_transmission"]);
        v["materials"][0]["extensions"] =
            json!({ "KHR_materials_transmission": { "transmissionFactor": 0.5, "transmissionTexture": { "index": 0 } } });
    });
    let scene = load_scene(&path).unwrap();
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.contains("texture.gltf") && w.contains("transmission texture ignored")),
        "{:?}",
        scene.warnings
    );
    let path = scene_file("missing-image.gltf", floor(), Some(lamp()), |v| {
        v["images"] = json!([{ "uri": "missing.png" }]);
        v["textures"] = json!([{ "source": 0 }]);
        v["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": 0 });
    });
    // A missing image file is not fatal, as in viewers: a warning, and the factor alone.
    let scene = load_scene(&path).unwrap();
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.contains("missing-image.gltf") && w.contains("image 0 (missing.png) cannot be read") && w.contains("factors alone")),
        "{:?}",
        scene.warnings
    );
    assert_eq!(
        scene.textures.materials[0].base_color.texture_index,
        restir_pt::shading::texture::NO_TEXTURE
    );
    assert_eq!(scene.materials[0].base_color, [0.5; 3]);
    let path = scene_file("required.gltf", floor(), Some(lamp()), |v| {
        v["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
        v["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    });
    let e = load_error(&path);
    assert!(e.contains("required.gltf") && e.contains("KHR_draco_mesh_compression"), "{e}");
}

#[test]
fn loader_applies_node_transforms_and_mirroring_flips_the_front_face() {
    let path = scene_file("mirrored.gltf", floor(), Some(lamp()), |v| {
        v["nodes"][1]["scale"] = json!([1.0, -1.0, 1.0]);
        v["nodes"][1]["translation"] = json!([0.0, 3.0, 0.0]);
    });
    let scene = load_scene(&path).unwrap();
    let light = scene
        .triangles
        .iter()
        .find(|t| t.emitter != restir_pt::gpu_types::NO_EMITTER)
        .unwrap();
    // Scene coordinates are relative to the first camera; scene.origin is its world position.
    let v = light.vertices().map(|p| p.as_dvec3() + scene.origin);
    assert!(v.iter().all(|p| (p.y - 2.0).abs() < 1e-6), "light moved to y = -1 + 3: {v:?}");
    // The lamp faced down (-y); mirrored in y it faces up, and the winding must say so.
    assert!(light.normal_area2().y > 0.0);
}

#[test]
fn loader_takes_the_environment_from_the_scene_extras_then_the_root_extras() {
    let root_only = scene_file("root-env.gltf", floor(), None, |v| {
        v["extras"] = json!({ "environment": [0.25, 0.5, 1.0] });
    });
    let scene = load_scene(&root_only).unwrap();
    assert_eq!(scene.environment, Vec3::new(0.25, 0.5, 1.0));
    assert_eq!(scene.env_select_prob, 1.0);
    let both = scene_file("both-env.gltf", floor(), None, |v| {
        v["extras"] = json!({ "environment": [0.25, 0.5, 1.0] });
        v["scenes"][0]["extras"] = json!({ "environment": [2.0, 2.0, 2.0] });
    });
    assert_eq!(load_scene(&both).unwrap().environment, Vec3::splat(2.0));
    // The scene's extras without an environment do not hide the root's.
    let other_scene_extras = scene_file("other-extras.gltf", floor(), None, |v| {
        v["extras"] = json!({ "environment": [1.0, 1.0, 1.0] });
        v["scenes"][0]["extras"] = json!({ "author": "someone" });
    });
    assert_eq!(load_scene(&other_scene_extras).unwrap().environment, Vec3::ONE);
    let bad_root = scene_file("bad-root-env.gltf", floor(), None, |v| {
        v["extras"] = json!({ "environment": [1.0, -1.0, 1.0] });
    });
    let err = load_error(&bad_root);
    assert!(err.contains("bad-root-env.gltf") && err.contains("root extras"), "{err}");
}

#[test]
fn loader_recentres_the_scene_on_its_first_camera_in_f64() {
    let far = 1e5f64;
    let moved = scene_file("far.gltf", floor(), Some(lamp()), |v| {
        let roots = v["scenes"][0]["nodes"].clone();
        let nodes = v["nodes"].as_array_mut().unwrap();
        nodes.push(json!({ "children": roots, "translation": [far, 0.0, -far] }));
        v["scenes"][0]["nodes"] = json!([nodes.len() - 1]);
    });
    let near = load_scene(&scene_file("near.gltf", floor(), Some(lamp()), |_| {})).unwrap();
    let far_scene = load_scene(&moved).unwrap();
    assert_eq!(far_scene.origin, near.origin + glam::DVec3::new(far, 0.0, -far));
    assert_eq!(far_scene.cameras[0].position, Vec3::ZERO);
    // Camera-relative coordinates are the same wherever the scene sits.
    let sorted = |s: &restir_pt::scene::Scene| {
        let mut v: Vec<[u32; 9]> = s
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.vertices();
                [a, b, c]
                    .map(|p| p.to_array())
                    .concat()
                    .try_into()
                    .map(|x: [f32; 9]| x.map(f32::to_bits))
                    .unwrap()
            })
            .collect();
        v.sort();
        v
    };
    assert_eq!(sorted(&far_scene), sorted(&near));
}

#[test]
fn loader_recentres_a_scene_without_camera_on_its_bounds_centre_in_f64() {
    // No camera, and a point light at (0.5, 2, 0) beside the floor and the lamp.
    let camera_less = |v: &mut Value| {
        v.as_object_mut().unwrap().remove("cameras");
        for node in v["nodes"].as_array_mut().unwrap() {
            node.as_object_mut().unwrap().remove("camera");
        }
        let used = v.as_object_mut().unwrap().entry("extensionsUsed").or_insert(json!([]));
        used.as_array_mut().unwrap().push(json!("KHR_lights_punctual"));
        v["extensions"]["KHR_lights_punctual"] = json!({ "lights": [{ "type": "point", "intensity": 10.0 }] });
        let nodes = v["nodes"].as_array_mut().unwrap();
        nodes.push(json!({ "translation": [0.5, 2.0, 0.0], "extensions": { "KHR_lights_punctual": { "light": 0 } } }));
        let light = nodes.len() - 1;
        v["scenes"][0]["nodes"].as_array_mut().unwrap().push(json!(light));
    };
    let far = 1e5f64;
    let moved = scene_file("far-no-camera.gltf", floor(), Some(lamp()), |v| {
        camera_less(v);
        let roots = v["scenes"][0]["nodes"].clone();
        let nodes = v["nodes"].as_array_mut().unwrap();
        nodes.push(json!({ "children": roots, "translation": [far, 0.0, -far] }));
        v["scenes"][0]["nodes"] = json!([nodes.len() - 1]);
    });
    let near = load_scene(&scene_file("near-no-camera.gltf", floor(), Some(lamp()), camera_less)).unwrap();
    let far_scene = load_scene(&moved).unwrap();
    // The vertices span (-1, 0, -1) .. (1, 1, 1); the light is not geometry.
    assert_eq!(near.origin, glam::DVec3::new(0.0, 0.5, 0.0));
    assert_eq!(far_scene.origin, near.origin + glam::DVec3::new(far, 0.0, -far));
    assert_eq!(near.bounds, (Vec3::new(-1.0, -0.5, -1.0), Vec3::new(1.0, 0.5, 1.0)));
    assert_eq!(far_scene.bounds, near.bounds);
    assert_eq!(far_scene.lights[0].position, Vec3::new(0.5, 1.5, 0.0));
    assert_eq!(far_scene.lights[0].position, near.lights[0].position);
    // The default camera frames the re-centred bounds, so it too is the same wherever the scene sits.
    assert_eq!(far_scene.cameras[0].position, near.cameras[0].position);
    assert_eq!(far_scene.cameras[0].forward, near.cameras[0].forward);
    let bits = |s: &restir_pt::scene::Scene| {
        let mut v: Vec<[u32; 9]> = s
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.vertices().map(|p| p.to_array().map(f32::to_bits));
                [a, b, c].concat().try_into().unwrap()
            })
            .collect();
        v.sort();
        v
    };
    assert_eq!(bits(&far_scene), bits(&near));
}

#[test]
fn loader_names_a_file_that_is_not_gltf_in_one_line() {
    let png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR";
    for (name, bytes) in [
        ("notes.gltf", b"hello world\n".as_slice()),
        ("model.obj", b"v 0 0 0\nv 1 0 0\nf 1 2 3\n"),
        ("picture.png", png),
    ] {
        let e = load_error(&temp_file(name, bytes));
        assert!(
            e.contains(name) && e.contains("not a glTF file") && !e.contains("line 1 column"),
            "{name}: {e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    let e = load_error(&temp_file("empty.gltf", b" \n"));
    assert!(e.contains("empty.gltf") && e.contains("empty, not a glTF file"), "{e}");
    // JSON that is broken or not glTF stays "invalid glTF" with the parser's position or field.
    let e = load_error(&temp_file("cut.gltf", b"{ \"asset\": { \"version\": "));
    assert!(e.contains("cut.gltf") && e.contains("invalid glTF") && e.contains("line"), "{e}");
    let e = load_error(&temp_file("other.gltf", b"{ \"name\": 1 }"));
    assert!(e.contains("other.gltf") && e.contains("invalid glTF") && e.contains("asset"), "{e}");
}
