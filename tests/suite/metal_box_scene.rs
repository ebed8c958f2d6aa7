//! A generated scene of the kind real files hold, for the unbiasedness tests of temporal reuse:
//! a GGX conductor box standing on a large diffuse floor, lit by punctual lights placed behind it,
//! so that the faces the cameras see receive their light only through the floor (camera → metal →
//! floor → light). Written with crates/scene/src/gltf_writer.

use glam::Vec3;
use restir_pt::scene::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};
use restir_pt::scene::{load_scene_from_bytes, Scene};
use serde_json::json;

/// Which punctual lights light the box.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MetalBoxLights {
    /// Two point lights behind the box.
    Points,
    /// A point light, a spot light and a sun (directional), all from behind the box.
    PointSpotSun,
}

/// The scene as glTF text: the box (1.2 × 1.2 × 1.2, rotated 0.5 rad about +Y) of GGX
/// `roughness` on an 8 × 8 floor, four cameras 0.05 apart along +X (a camera path) looking at
/// the box's two lit-through faces.
pub fn metal_box_gltf(roughness: f32, lights: MetalBoxLights) -> String {
    let mut b = GltfBuilder::default();
    let floor = b.material("floor", MaterialSpec::diffuse(Vec3::splat(0.73)));
    let metal = b.material("rough metal", MaterialSpec::conductor(Vec3::new(0.95, 0.8, 0.55), roughness));
    let floor_mesh = b.mesh(
        "floor",
        &MeshData::quad(Vec3::new(-4.0, 0.0, 4.0), Vec3::X * 8.0, Vec3::Z * -8.0),
        floor,
    );
    b.instance("floor", floor_mesh, 0.0, Vec3::ZERO);
    let box_mesh = b.mesh(
        "box",
        &MeshData::cuboid(Vec3::new(-0.6, 0.0, -0.6), Vec3::new(0.6, 1.2, 0.6)),
        metal,
    );
    b.instance("box", box_mesh, 0.5, Vec3::ZERO);
    let point = |intensity: f32| json!({ "type": "point", "color": [1.0, 0.95, 0.9], "intensity": intensity });
    b.punctual_light(point(30.0), Vec3::new(2.2, 2.0, -1.6), Vec3::NEG_Y);
    match lights {
        MetalBoxLights::Points => b.punctual_light(point(15.0), Vec3::new(-2.4, 1.5, -1.2), Vec3::NEG_Y),
        MetalBoxLights::PointSpotSun => {
            let spot = json!({ "type": "spot", "color": [0.9, 0.95, 1.0], "intensity": 40.0,
                               "spot": { "innerConeAngle": 0.3, "outerConeAngle": 0.6 } });
            b.punctual_light(spot, Vec3::new(-1.5, 3.0, -2.5), Vec3::new(0.6, -1.0, 1.2));
            let sun = json!({ "type": "directional", "color": [1.0, 1.0, 0.95], "intensity": 1.5 });
            b.punctual_light(sun, Vec3::ZERO, Vec3::new(0.3, -1.0, 0.6));
        }
    }
    for k in 0..4 {
        let offset = Vec3::X * (0.05 * k as f32);
        b.camera(
            &format!("camera {k}"),
            Vec3::new(0.6, 1.0, 3.4) + offset,
            Vec3::new(0.0, 0.55, 0.0) + offset,
            0.55,
        );
    }
    b.finish("metal-box", Vec3::ZERO)
}

/// The scene loaded, as the tests use it.
pub fn metal_box(roughness: f32, lights: MetalBoxLights) -> Scene {
    let text = metal_box_gltf(roughness, lights);
    load_scene_from_bytes(text.as_bytes(), None, std::path::Path::new("metal-box.gltf")).unwrap()
}
