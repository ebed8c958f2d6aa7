//! Scenes as exporters write them: no camera, no light, strips and fans, instancing, vertex
//! colours, animations, unlit and spec-gloss materials, several scenes. The small files are in
//! tests/data/bad/ (written by tools/make_bad_corpus.rs).

use glam::{Vec2, Vec3};
use restir_pt::scene::{
    collapse_warnings, load_scene, load_scene_reporting, spec_gloss_to_metal_rough, triangle_indices, LoadOptions, Scene,
};

use crate::common::repo_path;
use crate::fixtures::corpus;

/// Each triangle as its three vertices rotated to start at the smallest, so that two lists of
/// the same triangles with the same winding compare equal.
fn canonical_triangles(scene: &Scene) -> Vec<[[i64; 3]; 3]> {
    let key = |v: Vec3| (v * 1e5).round().as_i64vec3().to_array();
    let mut out: Vec<[[i64; 3]; 3]> = scene
        .triangles
        .iter()
        .map(|t| {
            let v = t.vertices().map(key);
            let first = (0..3).min_by_key(|&i| v[i]).unwrap();
            [v[first], v[(first + 1) % 3], v[(first + 2) % 3]]
        })
        .collect();
    out.sort();
    out
}

#[test]
fn real_scenes_strip_and_fan_indices_follow_the_gltf_winding() {
    use gltf::mesh::Mode;
    let strip = triangle_indices(Mode::TriangleStrip, &[0, 1, 2, 3, 4]).unwrap();
    assert_eq!(strip, vec![[0, 1, 2], [1, 3, 2], [2, 3, 4]]);
    let fan = triangle_indices(Mode::TriangleFan, &[0, 1, 2, 3]).unwrap();
    assert_eq!(fan, vec![[1, 2, 0], [2, 3, 0]]);
    // Stitched strips repeat a vertex; the triangles that repeat one are not triangles.
    let stitched = triangle_indices(Mode::TriangleStrip, &[0, 1, 2, 2, 3, 4, 5]).unwrap();
    assert_eq!(stitched, vec![[0, 1, 2], [2, 4, 3], [3, 4, 5]]);
    assert_eq!(triangle_indices(Mode::Lines, &[0, 1]), None);
    assert_eq!(triangle_indices(Mode::Points, &[0]), None);
}

#[test]
fn real_scenes_strips_and_fans_load_as_the_same_triangles_as_lists() {
    let lists = load_scene(&corpus("valid.glb")).unwrap();
    let strips = load_scene(&corpus("strips-and-fans.gltf")).unwrap();
    assert_eq!(lists.triangles.len(), 4);
    assert_eq!(canonical_triangles(&strips), canonical_triangles(&lists));
    let lines: Vec<_> = strips.warnings.iter().filter(|w| w.contains("points or lines")).collect();
    assert_eq!(lines.len(), 1, "{:?}", strips.warnings);
}

#[test]
fn real_scenes_gpu_instancing_expands_every_instance() {
    let scene = load_scene(&corpus("instanced.gltf")).unwrap();
    // Three tiles of two triangles, and the lamp.
    assert_eq!(scene.triangles.len(), 8);
    // In world coordinates: scene coordinates are relative to scene.origin.
    let world = |t: &restir_pt::gpu_types::Triangle| t.vertices().map(|v| v.as_dvec3() + scene.origin);
    let mut centres: Vec<i32> = scene
        .triangles
        .iter()
        .map(world)
        .filter(|v| v[0].y.abs() < 1e-6)
        .map(|v| {
            let c = (v[0] + v[1] + v[2]) / 3.0;
            (c.x / 0.7).round() as i32
        })
        .collect();
    centres.sort();
    centres.dedup();
    assert_eq!(centres, vec![-1, 0, 1]);
}

/// COLOR_0 multiplies the base colour, interpolated per hit: the floor's corners are red, green,
/// blue and white, each triangle's centroid the mean of its three corners' colours, and no
/// material is split by colour.
#[test]
fn real_scenes_vertex_colours_multiply_the_base_colour_per_hit() {
    let scene = load_scene(&corpus("vertex-colours.gltf")).unwrap();
    assert_eq!(scene.materials.len(), 2, "{:?}", scene.material_names);
    let mut corners: Vec<[i32; 3]> = Vec::new();
    for t in 0..scene.triangles.len() as u32 {
        if scene.materials[scene.triangles[t as usize].material as usize].emission != [0.0; 3] {
            continue;
        }
        let at = |b: Vec2| Vec3::from(scene.material_at(t, b).base_color);
        let c = [at(Vec2::ZERO), at(Vec2::X), at(Vec2::Y)];
        let centroid = at(Vec2::splat(1.0 / 3.0));
        assert!((centroid - (c[0] + c[1] + c[2]) / 3.0).abs().max_element() < 1e-5, "triangle {t}");
        corners.extend(c.iter().map(|v| v.round().as_ivec3().to_array()));
    }
    corners.sort();
    corners.dedup();
    assert_eq!(corners, vec![[0, 0, 1], [0, 1, 0], [1, 0, 0], [1, 1, 1]]);
    assert!(!scene.warnings.iter().any(|w| w.contains("COLOR_0")), "{:?}", scene.warnings);
}

#[test]
fn real_scenes_animations_and_morph_targets_are_ignored_with_warnings() {
    let scene = load_scene(&corpus("animated.gltf")).unwrap();
    assert_eq!(scene.triangles.len(), 4);
    for needle in ["1 animation(s) ignored", "morph targets of 1 primitive(s) ignored"] {
        assert!(scene.warnings.iter().any(|w| w.contains(needle)), "{needle}: {:?}", scene.warnings);
    }
}

#[test]
fn real_scenes_unlit_is_emission_of_the_base_colour() {
    let scene = load_scene(&corpus("unlit.gltf")).unwrap();
    let floor = scene.material_names.iter().position(|n| n == "grey").unwrap();
    let m = scene.materials[floor];
    assert_eq!(m.emission, [0.5; 3]);
    assert_eq!(m.base_color, [0.0; 3]);
    // The unlit floor is now an emitter beside the lamp: 2 + 2 emissive triangles.
    assert_eq!(scene.emitters.len(), 4);
}

#[test]
fn real_scenes_spec_gloss_converts_to_metallic_roughness() {
    // A dielectric's 4% specular: metallic 0, base colour the diffuse colour.
    let (base, metallic, roughness) = spec_gloss_to_metal_rough(Vec3::new(0.5, 0.4, 0.3), Vec3::splat(0.04), 0.2);
    assert_eq!(metallic, 0.0);
    assert!((base - Vec3::new(0.5, 0.4, 0.3)).abs().max_element() < 1e-6, "{base}");
    assert!((roughness - 0.8).abs() < 1e-6);
    // A conductor: black diffuse, coloured specular: metallic 1, base colour the specular colour.
    let (base, metallic, roughness) = spec_gloss_to_metal_rough(Vec3::ZERO, Vec3::new(0.95, 0.64, 0.54), 1.0);
    assert!((metallic - 1.0).abs() < 1e-6, "{metallic}");
    assert!((base - Vec3::new(0.95, 0.64, 0.54)).abs().max_element() < 1e-5, "{base}");
    assert_eq!(roughness, 0.0);
    let scene = load_scene(&corpus("spec-gloss.gltf")).unwrap();
    let grey = scene.material_names.iter().position(|n| n == "grey").unwrap();
    assert_eq!(scene.materials[grey].metallic, 0.0);
    assert!((scene.materials[grey].roughness - 0.8).abs() < 1e-6);
}

#[test]
fn real_scenes_default_camera_frames_every_vertex() {
    let scene = load_scene(&corpus("no-camera.gltf")).unwrap();
    assert_eq!(scene.cameras.len(), 1);
    let c = &scene.cameras[0];
    assert!(scene
        .warnings
        .iter()
        .any(|w| w.contains("no perspective camera: using a default one")));
    assert!((c.forward - -restir_pt::scene::DEFAULT_VIEW_DIRECTION).length() < 1e-6);
    let tan_half = (0.5 * c.yfov).tan();
    for v in scene.triangles.iter().flat_map(|t| t.vertices()) {
        let d = v - c.position;
        let z = d.dot(c.forward);
        assert!(z > 0.0);
        assert!(
            d.dot(c.right).abs() / z <= tan_half + 1e-5 && d.dot(c.up).abs() / z <= tan_half + 1e-5,
            "{v} is outside the view"
        );
    }
}

#[test]
fn real_scenes_warnings_survive_a_failed_load_and_identical_ones_collapse() {
    let mut warnings = Vec::new();
    let e = load_scene_reporting(&corpus("warnings-then-error.gltf"), &LoadOptions::default(), &mut warnings)
        .err()
        .unwrap();
    assert!(format!("{e:#}").contains("does not fit its buffer"));
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("warnings-then-error.gltf") && w.contains("animation(s) ignored")),
        "{warnings:?}"
    );
    let lines = ["a".to_string(), "b".to_string(), "a".to_string(), "a".to_string()];
    assert_eq!(collapse_warnings(&lines), vec!["a (x3)".to_string(), "b".to_string()]);
}

#[test]
fn real_scenes_scene_option_picks_a_scene() {
    let path = repo_path("../shared/assets/MultipleScenes/MultipleScenes.gltf");
    if !path.exists() {
        eprintln!("note: {} is absent; test skipped", path.display());
        return;
    }
    // The file's default scene is scene 1 (a quad); scene 0 is one triangle.
    assert_eq!(load_scene(&path).unwrap().triangles.len(), 2);
    let mut w = Vec::new();
    let options = LoadOptions {
        scene: Some(0),
        ..Default::default()
    };
    assert_eq!(load_scene_reporting(&path, &options, &mut w).unwrap().triangles.len(), 1);
    let e = load_scene_reporting(
        &path,
        &LoadOptions {
            scene: Some(7),
            ..Default::default()
        },
        &mut w,
    )
    .err()
    .unwrap();
    assert!(
        format!("{e:#}").contains("--scene 7 does not exist; the file has 2 scene(s)"),
        "{e:#}"
    );
}
