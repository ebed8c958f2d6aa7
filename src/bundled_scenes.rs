//! Recipes for the bundled scenes in scenes/, each built to exercise one property of path reuse
//! with only the geometry, materials and lights it needs. tools/make_scenes.rs writes them; a test
//! checks that the committed files equal what these recipes produce.

use glam::Vec3;

use crate::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};

pub struct BundledScene {
    pub file_name: &'static str,
    pub build: fn() -> String,
}

pub const BUNDLED_SCENES: &[BundledScene] = &[
    BundledScene {
        file_name: "cornell.gltf",
        build: cornell,
    },
    BundledScene {
        file_name: "furnace.gltf",
        build: furnace,
    },
];

const WHITE: Vec3 = Vec3::new(0.73, 0.73, 0.73);
const RED: Vec3 = Vec3::new(0.63, 0.065, 0.05);
const GREEN: Vec3 = Vec3::new(0.14, 0.45, 0.091);
const CORNELL_LIGHT: Vec3 = Vec3::new(17.0, 12.0, 4.0);
const CORNELL_YFOV: f32 = 0.686;
/// Camera poses per scene for temporal reuse (`--frames F` uses pose k for frame k).
const CAMERA_PATH_POSES: usize = 8;

/// A camera path: `CAMERA_PATH_POSES` nodes sliding from `eye` by `step` each, all aimed at `target`.
fn camera_path(b: &mut GltfBuilder, eye: Vec3, target: Vec3, step: Vec3, yfov: f32) {
    for k in 0..CAMERA_PATH_POSES {
        let offset = step * k as f32;
        b.camera(&format!("camera {k}"), eye + offset, target + offset, yfov);
    }
}

/// The closed-on-five-sides 2x2x2 room of the Cornell box with a ceiling light.
fn cornell_room(b: &mut GltfBuilder, light: Vec3) {
    let white = b.material("white", MaterialSpec::diffuse(WHITE));
    let red = b.material("red", MaterialSpec::diffuse(RED));
    let green = b.material("green", MaterialSpec::diffuse(GREEN));
    let emitter = b.material("light", MaterialSpec::emitter(light));
    let (x2, y2, z2) = (Vec3::X * 2.0, Vec3::Y * 2.0, Vec3::Z * 2.0);
    let corner = Vec3::splat(-1.0);
    let white_walls = MeshData::quad(corner, z2, x2)
        .merged(&MeshData::quad(Vec3::new(-1.0, 1.0, -1.0), x2, z2))
        .merged(&MeshData::quad(corner, x2, y2));
    let walls = b.mesh("white walls", &white_walls, white);
    b.instance("white walls", walls, 0.0, Vec3::ZERO);
    let left = b.mesh("left wall", &MeshData::quad(corner, y2, z2), red);
    b.instance("left wall", left, 0.0, Vec3::ZERO);
    let right = b.mesh("right wall", &MeshData::quad(Vec3::new(1.0, -1.0, -1.0), z2, y2), green);
    b.instance("right wall", right, 0.0, Vec3::ZERO);
    let lamp = MeshData::quad(Vec3::new(-0.235, 0.998, -0.19), Vec3::X * 0.47, Vec3::Z * 0.38);
    let lamp = b.mesh("ceiling light", &lamp, emitter);
    b.instance("ceiling light", lamp, 0.0, Vec3::ZERO);
}

fn cornell_boxes(b: &mut GltfBuilder, tall_material: usize, short_material: usize) {
    let tall = b.mesh(
        "tall box",
        &MeshData::cuboid(Vec3::new(-0.3, -0.6, -0.3), Vec3::new(0.3, 0.6, 0.3)),
        tall_material,
    );
    b.instance("tall box", tall, 0.3, Vec3::new(-0.33, -0.4, -0.3));
    let short = b.mesh("short box", &MeshData::cuboid(Vec3::splat(-0.3), Vec3::splat(0.3)), short_material);
    b.instance("short box", short, -0.3, Vec3::new(0.35, -0.7, 0.3));
}

/// 1. The classic diffuse Cornell box (the default scene).
pub fn cornell() -> String {
    let mut b = GltfBuilder::default();
    cornell_room(&mut b, CORNELL_LIGHT);
    let white = b.material("box white", MaterialSpec::diffuse(WHITE));
    cornell_boxes(&mut b, white, white);
    camera_path(
        &mut b,
        Vec3::new(0.0, 0.0, 3.9),
        Vec3::ZERO,
        Vec3::new(0.02, 0.0, 0.0),
        CORNELL_YFOV,
    );
    b.finish("cornell", Vec3::ZERO)
}

/// 9. The white furnace: a diffuse sphere of albedo 1 inside a uniform environment of radiance 1.
/// Camera 0 sees only the sphere; camera 1 shows it against the environment.
pub fn furnace() -> String {
    let mut b = GltfBuilder::default();
    let white = b.material("albedo 1", MaterialSpec::diffuse(Vec3::ONE));
    let sphere = b.mesh("sphere", &MeshData::sphere(Vec3::ZERO, 1.0, 24, 48), white);
    b.instance("sphere", sphere, 0.0, Vec3::ZERO);
    b.camera("filled by the sphere", Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 0.3);
    camera_path(&mut b, Vec3::new(0.0, 0.5, 4.0), Vec3::ZERO, Vec3::new(0.05, 0.0, 0.0), 0.9);
    b.finish("furnace", Vec3::ONE)
}
