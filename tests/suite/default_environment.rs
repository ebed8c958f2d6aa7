//! The default environment decided from what a file holds (crates/scene/src/default_environment.rs):
//! the bundled scenes, closed around their own lights, keep no environment (their images are
//! checked unchanged by tests/suite/scenes.rs); an open asset with its own emitters gets the
//! viewer-like one with a line saying so; lightless assets get it as before; `--env none` turns
//! it off.

use glam::Vec3;
use restir_pt::scene::default_environment::{light_escape_fraction, OPEN_SCENE_FRACTION};
use restir_pt::scene::{load_scene, load_scene_reporting, LoadOptions, DEFAULT_ENVIRONMENT};
use serde_json::json;

use crate::common::repo_path;

const BUNDLED: [&str; 9] = [
    "cornell",
    "cornell-glossy",
    "veach-door",
    "near-field",
    "glass",
    "mirror",
    "env-ground",
    "corridor",
    "furnace",
];

#[test]
fn default_environment_leaves_the_bundled_scenes_as_their_files_light_them() {
    for name in BUNDLED {
        let path = repo_path(&format!("scenes/{name}.gltf"));
        let scene = load_scene(&path).unwrap();
        let open = light_escape_fraction(&scene);
        eprintln!("{name}: {:.4} of the emission escapes", open);
        let own = matches!(name, "env-ground" | "furnace");
        if own {
            assert!(scene.environment.max_element() > 0.0, "{name} keeps its own sky");
        } else {
            assert!(open <= OPEN_SCENE_FRACTION, "{name}: {open} of the emission escapes");
            assert_eq!(scene.environment, Vec3::ZERO, "{name} gained an environment");
        }
        assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
    }
}

/// BoxTextured with every triangle emissive, as DamagedHelmet's emissive texture makes it.
fn emissive_box() -> std::path::PathBuf {
    let src = repo_path("../shared/assets/BoxTextured/BoxTextured.gltf");
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(&src).unwrap()).unwrap();
    v["materials"][0]["emissiveFactor"] = json!([1.0, 1.0, 1.0]);
    v["materials"][0]["emissiveTexture"] = json!({ "index": 0 });
    let dir = crate::common::temp_file("emissive-box.gltf", b"").parent().unwrap().to_path_buf();
    // The buffers and images resolve against the file's folder: keep them beside a copy.
    for f in ["BoxTextured0.bin", "CesiumLogoFlat.png"] {
        std::fs::copy(src.parent().unwrap().join(f), dir.join(f)).unwrap();
    }
    let path = dir.join("emissive-box.gltf");
    std::fs::write(&path, serde_json::to_vec(&v).unwrap()).unwrap();
    path
}

#[test]
fn default_environment_lights_an_open_asset_with_its_own_emitters_unless_env_none() {
    let box_path = repo_path("../shared/assets/BoxTextured/BoxTextured.gltf");
    if !box_path.exists() {
        eprintln!("note: ../shared/assets absent; skipped");
        return;
    }
    let path = emissive_box();
    let mut warnings = Vec::new();
    let scene = load_scene_reporting(&path, &LoadOptions::default(), &mut warnings).unwrap();
    let open = light_escape_fraction(&scene);
    eprintln!("emissive box: {open:.4} of the emission escapes");
    assert!(open > OPEN_SCENE_FRACTION, "{open}");
    assert!(!scene.emitters.is_empty());
    assert_eq!(scene.environment, DEFAULT_ENVIRONMENT);
    assert_eq!(scene.env_select_prob, 0.5);
    let said: Vec<_> = warnings.iter().filter(|w| w.contains("adding a uniform environment")).collect();
    assert_eq!(said.len(), 1, "{warnings:?}");
    let none = LoadOptions {
        no_environment: true,
        ..Default::default()
    };
    let scene = load_scene_reporting(&path, &none, &mut Vec::new()).unwrap();
    assert_eq!(scene.environment, Vec3::ZERO);
    assert_eq!(scene.env_select_prob, 0.0);
    // Lightless assets are lit by the default as before, and --env none turns that off too.
    for asset in ["BoxTextured/BoxTextured.gltf", "Avocado/Avocado.gltf"] {
        let path = repo_path(&format!("../shared/assets/{asset}"));
        let mut warnings = Vec::new();
        let scene = load_scene_reporting(&path, &LoadOptions::default(), &mut warnings).unwrap();
        assert_eq!(scene.environment, DEFAULT_ENVIRONMENT, "{asset}");
        assert!(warnings.iter().any(|w| w.contains("has no light")), "{warnings:?}");
        let mut warnings = Vec::new();
        let scene = load_scene_reporting(&path, &none, &mut warnings).unwrap();
        assert_eq!(scene.environment, Vec3::ZERO, "{asset}");
        assert!(warnings.iter().any(|w| w.contains("--env none")), "{warnings:?}");
    }
}

/// `--env-rotation` and `--env none` through the CLI: a map bright only in its two centre columns
/// (u in [7/16, 9/16), around Mitsuba 3's +Z) seen by a camera looking along +X is dark unrotated, bright turned by 90
/// degrees (the column comes to +X) and dark at -90; `--env none` renders a lightless file black
/// with a warning; a bad angle is one error line.
#[test]
fn default_environment_cli_env_rotation_turns_the_map_and_env_none_turns_it_off() {
    use crate::fixtures::cli::restir_pt;
    use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};
    let dir = crate::common::temp_file("placeholder", b"").parent().unwrap().join("env-rotation");
    std::fs::create_dir_all(&dir).unwrap();
    let (w, h) = (16u32, 8u32);
    let texels: Vec<Vec3> = (0..w * h)
        .map(|k| {
            if k % w == 7 || k % w == 8 {
                Vec3::splat(10.0)
            } else {
                Vec3::splat(0.1)
            }
        })
        .collect();
    let sky = dir.join("column.exr");
    restir_pt::image_io::write_exr(&sky, w, h, &texels).unwrap();
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let m = b.mesh(
        "speck",
        &MeshData::quad(Vec3::new(-50.0, 0.0, 0.0), Vec3::Y * 0.1, Vec3::Z * 0.1),
        grey,
    );
    b.instance("speck", m, 0.0, Vec3::ZERO);
    b.camera("along +x", Vec3::ZERO, Vec3::X, 0.1);
    let scene = dir.join("looking-east.gltf");
    std::fs::write(&scene, b.finish("looking east", Vec3::ZERO)).unwrap();
    let mean = |extra: &[&str]| {
        let out = dir.join("out.exr");
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--method",
            "pt",
            "--width",
            "4",
            "--height",
            "4",
            "--spp",
            "4",
        ];
        args.extend_from_slice(extra);
        args.extend(["--out", out.to_str().unwrap()]);
        let (code, _, stderr) = restir_pt(&args);
        assert_eq!(code, 0, "{extra:?}: {stderr}");
        let (_, _, pixels) = restir_pt::image_io::read_exr(&out).unwrap();
        (pixels.iter().sum::<Vec3>() / pixels.len() as f32, stderr)
    };
    let sky = sky.to_str().unwrap();
    let (unrotated, _) = mean(&["--env", sky]);
    let (turned, _) = mean(&["--env", sky, "--env-rotation", "90"]);
    let (back, _) = mean(&["--env", sky, "--env-rotation", "-90"]);
    eprintln!("looking along +X: {unrotated} unrotated, {turned} at 90, {back} at -90");
    assert!((unrotated - Vec3::splat(0.1)).abs().max_element() < 1e-4, "{unrotated}");
    assert!((turned - Vec3::splat(10.0)).abs().max_element() < 1e-3, "{turned}");
    assert!((back - Vec3::splat(0.1)).abs().max_element() < 1e-4, "{back}");
    let (none, stderr) = mean(&["--env", "none"]);
    assert_eq!(none, Vec3::ZERO);
    assert!(stderr.contains("--env none leaves it without an environment"), "{stderr}");
    let (code, _, stderr) = restir_pt(&["render", scene.to_str().unwrap(), "--env-rotation", "east"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("not a finite angle in degrees"), "{stderr}");
}
