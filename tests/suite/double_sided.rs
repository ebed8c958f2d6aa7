//! glTF `doubleSided` (docs/materials.md, "Sides"): it decides which faces of an emitter emit
//! and never removes geometry. A square facing +z fills the view of a camera in front of it
//! (z = 2) or behind it (z = -2), under a uniform sky of radiance 1: an emitter of radiance 2
//! (black base) shows 2 from the front, 0 from behind when single-sided (it still blocks the
//! sky: a culled face would show 1) and 2 when double-sided; a white Lambertian square of albedo
//! 0.5 reflects the sky (0.5) from either side, single-sided or not.

use glam::Vec3;
use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};
use restir_pt::scene::{load_scene_from_bytes, Scene};

use crate::fixtures::alpha_images::{mean_and_error, render};

fn square_under_the_sky(material: MaterialSpec) -> Scene {
    let mut b = GltfBuilder::default();
    let m = b.material("square", material);
    let mesh = b.mesh(
        "square",
        &MeshData::quad(Vec3::new(-2.0, -2.0, 0.0), Vec3::X * 4.0, Vec3::Y * 4.0),
        m,
    );
    b.instance("square", mesh, 0.0, Vec3::ZERO);
    b.camera("front", Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, 0.9);
    b.camera("back", Vec3::new(0.0, 0.0, -2.0), Vec3::ZERO, 0.9);
    let text = b.finish("square under the sky", Vec3::ONE);
    load_scene_from_bytes(text.as_bytes(), None, std::path::Path::new("square.gltf")).unwrap()
}

#[test]
fn double_sided_decides_which_faces_emit_and_never_culls() {
    let lamp = MaterialSpec::emitter(Vec3::splat(2.0));
    let white = MaterialSpec::diffuse(Vec3::splat(0.5));
    let cases = [
        ("single-sided emitter", lamp, [2.0, 0.0]),
        (
            "double-sided emitter",
            MaterialSpec {
                double_sided: true,
                ..lamp
            },
            [2.0, 2.0],
        ),
        ("single-sided white", white, [0.5, 0.5]),
        (
            "double-sided white",
            MaterialSpec {
                double_sided: true,
                ..white
            },
            [0.5, 0.5],
        ),
    ];
    for (what, material, expected) in cases {
        let mut scene = square_under_the_sky(material);
        for (camera, side) in ["front", "back"].iter().enumerate() {
            // Camera 0 is the one rendered: bring the wanted one first.
            if camera == 1 {
                scene.cameras.swap(0, 1);
            }
            let (mean, error) = mean_and_error(&render(&scene, 8, 3));
            println!(
                "{what}, seen from the {side}: {mean:.5} (standard error {error:.5}) vs {}",
                expected[camera]
            );
            assert!(
                (mean - expected[camera]).abs() <= 0.01 * expected[camera].max(0.1),
                "{what} seen from the {side}: {mean}, expected {}",
                expected[camera]
            );
        }
    }
}
