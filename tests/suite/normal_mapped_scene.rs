//! A generated scene whose shading frames differ from the geometric ones almost everywhere, for
//! the shift and ReSTIR tests: the Cornell room with a normal-mapped floor and back wall, a
//! coarse sphere with interpolated normals and a normal-mapped one (tangents from MikkTSpace),
//! beside walls without vertex attributes (face normals). Written with crates/scene/src/gltf_writer.

use glam::{Vec2, Vec3};
use restir_pt::scene::gltf_writer::{textured_sphere, GltfBuilder, MaterialSpec, MeshData, FILTER_LINEAR, WRAP_REPEAT};
use restir_pt::scene::{load_scene_from_bytes, Scene};
use serde_json::json;

/// The scene's name in test messages, in place of a file under scenes/.
pub const NORMAL_MAPPED_BOX: &str = "normal-mapped-box";

/// Bumps per texture period along u and v, and the largest slope of the height field
/// h = SLOPE / (2π BUMPS) sin(2π BUMPS u) sin(2π BUMPS v): tilts of up to atan(SLOPE · √2).
const BUMPS: f32 = 3.0;
const SLOPE: f32 = 0.45;

/// A tangent-space normal map (glTF 2.0 section 3.9.3: RGB = (n + 1) / 2, +y along +v of the
/// texture coordinates) of `side` x `side` texels of the bumps above.
pub fn bump_normal_map_png(side: u32) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(side, side, |x, y| {
        let (u, v) = ((x as f32 + 0.5) / side as f32, (y as f32 + 0.5) / side as f32);
        let w = 2.0 * std::f32::consts::PI * BUMPS;
        let (du, dv) = (SLOPE * (w * u).cos() * (w * v).sin(), SLOPE * (w * u).sin() * (w * v).cos());
        let n = Vec3::new(-du, -dv, 1.0).normalize();
        let c = (n * 0.5 + Vec3::splat(0.5)) * 255.0;
        image::Rgba([c.x.round() as u8, c.y.round() as u8, c.z.round() as u8, 255])
    });
    let mut out = std::io::Cursor::new(Vec::new());
    image::DynamicImage::ImageRgba8(img)
        .write_to(&mut out, image::ImageFormat::Png)
        .unwrap();
    out.into_inner()
}

/// A quad (MeshData::quad's corners c, c+a, c+a+b, c+b) with its face normal at every vertex
/// and texture coordinates covering `repeats` texture periods along each side.
fn quad_with_attributes(c: Vec3, a: Vec3, b: Vec3, repeats: f32) -> (MeshData, Vec<Vec3>, Vec<Vec2>) {
    let n = a.cross(b).normalize();
    let uv = [Vec2::ZERO, Vec2::new(repeats, 0.0), Vec2::splat(repeats), Vec2::new(0.0, repeats)];
    (MeshData::quad(c, a, b), vec![n; 4], uv.to_vec())
}

/// Adds a mesh with vertex normals and TEXCOORD_0 as one root node at the origin.
fn add_with_attributes(b: &mut GltfBuilder, name: &str, (mesh, normals, uv): &(MeshData, Vec<Vec3>, Vec<Vec2>), material: usize) {
    let m = b.mesh_with_attributes(name, mesh, Some(normals), &[uv], material);
    b.instance(name, m, 0.0, Vec3::ZERO);
}

/// Adds a mesh without vertex attributes (face normals) as one root node at the origin.
fn add_flat(b: &mut GltfBuilder, name: &str, mesh: &MeshData, material: usize) {
    let m = b.mesh(name, mesh, material);
    b.instance(name, m, 0.0, Vec3::ZERO);
}

/// The scene as glTF text: the 2x2x2 room open at +z (white ceiling, red and green side walls
/// with face normals; a diffuse floor and a plastic back wall of roughness 0.35, both
/// normal-mapped), a ceiling light, a rough plastic sphere (roughness 0.3) of 12 x 24 facets with
/// interpolated normals, a normal-mapped conductor sphere (roughness 0.3) and a glossy conductor
/// sphere (roughness 0.15, not reconnectable) with interpolated normals; cameras 0 to 3 slide
/// along +x by 0.02 as the bundled Cornell box's do.
pub fn normal_mapped_box_gltf() -> String {
    let mut b = GltfBuilder::default();
    let normal_map = b.texture(&bump_normal_map_png(64), "image/png", [WRAP_REPEAT, WRAP_REPEAT], FILTER_LINEAR);
    let mapped = |b: &mut GltfBuilder, name: &str, spec: MaterialSpec, scale: f32| {
        let m = b.material(name, spec);
        b.set_material_field(m, &["normalTexture"], json!({ "index": normal_map, "scale": scale }));
        m
    };
    let floor = mapped(&mut b, "bumpy floor", MaterialSpec::diffuse(Vec3::splat(0.73)), 1.0);
    let back = mapped(&mut b, "bumpy plastic", MaterialSpec::plastic(Vec3::new(0.6, 0.6, 0.7), 0.35), 0.8);
    let metal = mapped(&mut b, "bumpy metal", MaterialSpec::conductor(Vec3::new(0.95, 0.8, 0.55), 0.3), 1.0);
    let white = b.material("white", MaterialSpec::diffuse(Vec3::splat(0.73)));
    let red = b.material("red", MaterialSpec::diffuse(Vec3::new(0.63, 0.065, 0.05)));
    let green = b.material("green", MaterialSpec::diffuse(Vec3::new(0.14, 0.45, 0.091)));
    let light = b.material("light", MaterialSpec::emitter(Vec3::new(17.0, 12.0, 4.0)));
    let plastic = b.material("smooth plastic", MaterialSpec::plastic(Vec3::new(0.2, 0.4, 0.7), 0.3));
    let glossy = b.material("glossy metal", MaterialSpec::conductor(Vec3::new(0.9, 0.9, 0.9), 0.15));
    let (x2, y2, z2, corner) = (Vec3::X * 2.0, Vec3::Y * 2.0, Vec3::Z * 2.0, Vec3::splat(-1.0));
    add_with_attributes(&mut b, "floor", &quad_with_attributes(corner, z2, x2, 2.0), floor);
    add_with_attributes(&mut b, "back wall", &quad_with_attributes(corner, x2, y2, 2.0), back);
    add_flat(&mut b, "ceiling", &MeshData::quad(Vec3::new(-1.0, 1.0, -1.0), x2, z2), white);
    add_flat(&mut b, "left wall", &MeshData::quad(corner, y2, z2), red);
    add_flat(&mut b, "right wall", &MeshData::quad(Vec3::new(1.0, -1.0, -1.0), z2, y2), green);
    let lamp = MeshData::quad(Vec3::new(-0.235, 0.998, -0.19), Vec3::X * 0.47, Vec3::Z * 0.38);
    add_flat(&mut b, "ceiling light", &lamp, light);
    add_with_attributes(
        &mut b,
        "smooth sphere",
        &textured_sphere(Vec3::new(-0.45, -0.6, -0.3), 0.4, 12, 24),
        plastic,
    );
    add_with_attributes(
        &mut b,
        "bumpy sphere",
        &textured_sphere(Vec3::new(0.45, -0.7, 0.2), 0.3, 16, 32),
        metal,
    );
    add_with_attributes(
        &mut b,
        "glossy sphere",
        &textured_sphere(Vec3::new(0.3, 0.3, -0.5), 0.2, 10, 20),
        glossy,
    );
    for k in 0..4 {
        let offset = Vec3::new(0.02 * k as f32, 0.0, 0.0);
        b.camera(&format!("camera {k}"), Vec3::new(0.0, 0.0, 3.9) + offset, offset, 0.686);
    }
    b.finish(NORMAL_MAPPED_BOX, Vec3::ZERO)
}

/// The scene loaded, as the tests use it.
pub fn normal_mapped_box() -> Scene {
    let text = normal_mapped_box_gltf();
    load_scene_from_bytes(text.as_bytes(), None, std::path::Path::new("normal-mapped-box.gltf")).unwrap()
}

/// A bundled scene by name, or the generated [`NORMAL_MAPPED_BOX`].
pub fn scene_named(name: &str) -> Scene {
    if name == NORMAL_MAPPED_BOX {
        return normal_mapped_box();
    }
    restir_pt::scene::load_scene(&crate::common::repo_path(&format!("scenes/{name}.gltf"))).unwrap()
}

/// The scene exercises the shading frame: it has vertex attributes and its normal map, and at
/// over a third of the primary hits of camera 0 (64 x 64 pixel centres; the rest see the flat
/// walls) the shading normal `vertex_shading` gives differs from the geometric normal by over 1°
/// (measured 1917 of 3839), by up to over 20° (measured 27.5°).
#[test]
fn normal_mapped_box_shading_normals_differ_from_geometric_ones() {
    use restir_pt::shading::shift::{primary_hit, vertex_shading};
    let scene = normal_mapped_box();
    assert!(!scene.surfaces.is_empty() && scene.textures.headers.len() == 1);
    let (mut hits, mut tilted, mut largest) = (0, 0, 0.0f32);
    for py in 0..64 {
        for px in 0..64 {
            let Some(v) = primary_hit(&scene, 0, px as f32 + 0.5, py as f32 + 0.5, 64, 64) else {
                continue;
            };
            let (_, ns) = vertex_shading(&scene, &v);
            let angle = ns.dot(v.normal).clamp(-1.0, 1.0).acos().to_degrees();
            hits += 1;
            tilted += (angle > 1.0) as usize;
            largest = largest.max(angle);
        }
    }
    eprintln!("normal-mapped box: {tilted} of {hits} primary hits tilted by over 1°, largest {largest:.1}°");
    assert!(tilted * 3 > hits, "only {tilted} of {hits} hits have a tilted shading normal");
    assert!(largest > 20.0, "largest tilt {largest}°");
}
