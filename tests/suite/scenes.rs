//! The bundled scenes: committed files equal the generator's output, the README's table matches
//! the loaded scenes, and every scene renders to a finite, non-black image.

use restir_pt::render::{PathTracer, RenderSettings, SceneGpu};
use restir_pt::scene::bundled_scenes::BUNDLED_SCENES;
use restir_pt::scene::load_scene;

use crate::common::{assert_clean, gpu, repo_path};

#[test]
fn scenes_committed_files_equal_generator_output() {
    for scene in BUNDLED_SCENES {
        let committed = std::fs::read_to_string(repo_path(&format!("scenes/{}", scene.file_name))).unwrap();
        assert!(
            committed == (scene.build)(),
            "scenes/{} differs from its recipe: run `cargo run --release --example make_scenes`",
            scene.file_name
        );
    }
}

#[test]
fn scenes_readme_table_matches_the_scenes() {
    let readme = std::fs::read_to_string(repo_path("scenes/README.md")).unwrap();
    for scene in BUNDLED_SCENES {
        let row = readme
            .lines()
            .find(|l| l.starts_with(&format!("| `{}`", scene.file_name)))
            .unwrap_or_else(|| panic!("no README row for {}", scene.file_name));
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let loaded = load_scene(&repo_path(&format!("scenes/{}", scene.file_name))).unwrap();
        assert_eq!(cells[4], loaded.triangles.len().to_string(), "{} triangles", scene.file_name);
        assert_eq!(cells[5], loaded.emitters.len().to_string(), "{} emitters", scene.file_name);
        assert!(loaded.cameras.len() >= 8, "{} needs a camera path", scene.file_name);
        assert!(loaded.warnings.is_empty(), "{}: {:?}", scene.file_name, loaded.warnings);
    }
}

#[test]
fn scenes_every_scene_renders_finite_and_non_black_at_64_spp() {
    let ctx = gpu();
    for scene in BUNDLED_SCENES {
        let loaded = load_scene(&repo_path(&format!("scenes/{}", scene.file_name))).unwrap();
        let settings = RenderSettings {
            width: 48,
            height: 48,
            spp: 64,
            ..Default::default()
        };
        let mut tracer = PathTracer::new(&SceneGpu::upload(&ctx, &loaded).unwrap(), &settings).unwrap();
        tracer.render(&|_| {}, &std::sync::atomic::AtomicBool::new(false)).unwrap();
        let image = tracer.image().unwrap();
        assert_eq!(image.non_finite_count(), 0, "{}: non-finite pixels", scene.file_name);
        assert!(image.average().max_element() > 1e-3, "{}: black image", scene.file_name);
    }
    assert_clean(&ctx);
}
