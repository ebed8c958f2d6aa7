//! Recipes for the bundled scenes in scenes/, each built to exercise one property of path reuse
//! with only the geometry, materials and lights it needs. tools/make_scenes.rs writes them; a test
//! checks that the committed files equal what these recipes produce. scenes/README.md says what
//! each scene tests and which shift is expected to fail there.

use glam::Vec3;

use crate::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};

/// One bundled scene: its file under scenes/ and the recipe that writes it.
pub struct BundledScene {
    /// The file name in scenes/, e.g. "cornell.gltf".
    pub file_name: &'static str,
    /// Produces the file's complete glTF text, byte-for-byte what is committed.
    pub build: fn() -> String,
}

/// Every bundled scene, in the order scenes/README.md lists them.
pub const BUNDLED_SCENES: &[BundledScene] = &[
    BundledScene {
        file_name: "cornell.gltf",
        build: cornell,
    },
    BundledScene {
        file_name: "cornell-glossy.gltf",
        build: cornell_glossy,
    },
    BundledScene {
        file_name: "veach-door.gltf",
        build: veach_door,
    },
    BundledScene {
        file_name: "near-field.gltf",
        build: near_field,
    },
    BundledScene {
        file_name: "glass.gltf",
        build: glass,
    },
    BundledScene {
        file_name: "mirror.gltf",
        build: mirror,
    },
    BundledScene {
        file_name: "env-ground.gltf",
        build: env_ground,
    },
    BundledScene {
        file_name: "corridor.gltf",
        build: corridor,
    },
    BundledScene {
        file_name: "furnace.gltf",
        build: furnace,
    },
    BundledScene {
        file_name: "many-lights.gltf",
        build: crate::many_lights_scene::many_lights,
    },
];

const WHITE: Vec3 = Vec3::new(0.73, 0.73, 0.73);
const RED: Vec3 = Vec3::new(0.63, 0.065, 0.05);
const GREEN: Vec3 = Vec3::new(0.14, 0.45, 0.091);
const CORNELL_LIGHT: Vec3 = Vec3::new(17.0, 12.0, 4.0);
const CORNELL_LIGHT_SIZE: (f32, f32) = (0.47, 0.38);
const CORNELL_EYE: Vec3 = Vec3::new(0.0, 0.0, 3.9);
const CORNELL_YFOV: f32 = 0.686;
/// Index ranges of the -x and +x faces in `MeshData::cuboid` (faces: -z, +z, -x, +x, -y, +y).
const CUBOID_LOW_X_FACE: std::ops::Range<usize> = 12..18;
const CUBOID_HIGH_X_FACE: std::ops::Range<usize> = 18..24;
/// Camera poses per scene for temporal reuse (`--frames F` uses pose k for frame k).
const CAMERA_PATH_POSES: usize = 8;

/// A camera path: `CAMERA_PATH_POSES` nodes sliding from `eye` by `step` each, all aimed at `target`.
fn camera_path(b: &mut GltfBuilder, eye: Vec3, target: Vec3, step: Vec3, yfov: f32) {
    for k in 0..CAMERA_PATH_POSES {
        let offset = step * k as f32;
        b.camera(&format!("camera {k}"), eye + offset, target + offset, yfov);
    }
}

/// Adds `mesh` with `material` as one root node at the origin.
fn add(b: &mut GltfBuilder, name: &str, mesh: &MeshData, material: usize) {
    let m = b.mesh(name, mesh, material);
    b.instance(name, m, 0.0, Vec3::ZERO);
}

/// A ceiling light of `size` centred below the ceiling of the 2x2x2 room, facing down.
fn ceiling_lamp(size: (f32, f32), center_x: f32) -> MeshData {
    MeshData::quad(
        Vec3::new(center_x - 0.5 * size.0, 0.998, -0.5 * size.1),
        Vec3::X * size.0,
        Vec3::Z * size.1,
    )
}

/// The Cornell box's 2x2x2 room, open at +z, with a ceiling light of `light_size`.
fn cornell_room(b: &mut GltfBuilder, light: Vec3, light_size: (f32, f32)) {
    let white = b.material("white", MaterialSpec::diffuse(WHITE));
    let red = b.material("red", MaterialSpec::diffuse(RED));
    let green = b.material("green", MaterialSpec::diffuse(GREEN));
    let emitter = b.material("light", MaterialSpec::emitter(light));
    let (x2, y2, z2) = (Vec3::X * 2.0, Vec3::Y * 2.0, Vec3::Z * 2.0);
    let corner = Vec3::splat(-1.0);
    let white_walls = MeshData::quad(corner, z2, x2)
        .merged(&MeshData::quad(Vec3::new(-1.0, 1.0, -1.0), x2, z2))
        .merged(&MeshData::quad(corner, x2, y2));
    add(b, "white walls", &white_walls, white);
    add(b, "left wall", &MeshData::quad(corner, y2, z2), red);
    add(b, "right wall", &MeshData::quad(Vec3::new(1.0, -1.0, -1.0), z2, y2), green);
    add(b, "ceiling light", &ceiling_lamp(light_size, 0.0), emitter);
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

fn cornell_camera_path(b: &mut GltfBuilder) {
    camera_path(b, CORNELL_EYE, Vec3::ZERO, Vec3::new(0.02, 0.0, 0.0), CORNELL_YFOV);
}

/// Scene 1: The classic diffuse Cornell box (the default scene).
pub fn cornell() -> String {
    let mut b = GltfBuilder::default();
    cornell_room(&mut b, CORNELL_LIGHT, CORNELL_LIGHT_SIZE);
    let white = b.material("box white", MaterialSpec::diffuse(WHITE));
    cornell_boxes(&mut b, white, white);
    cornell_camera_path(&mut b);
    b.finish("cornell", Vec3::ZERO)
}

/// The Cornell box with a horizontal white screen under the light (y = 0.55, x and z in
/// [-0.7, 0.7], facing down) cut out by `mask_png` (alphaMode MASK, cutoff 0.5, nearest
/// filtering, repeated 5 times each way): light reaches the room through its holes and shifted
/// paths must see the same holes. Not a bundled file; tests of alpha testing build it.
pub fn cornell_alpha_screen(mask_png: &[u8]) -> String {
    use crate::gltf_writer::{FILTER_NEAREST, WRAP_REPEAT};
    let mut b = GltfBuilder::default();
    cornell_room(&mut b, CORNELL_LIGHT, CORNELL_LIGHT_SIZE);
    let white = b.material("box white", MaterialSpec::diffuse(WHITE));
    cornell_boxes(&mut b, white, white);
    let screen = b.material("masked screen", MaterialSpec::diffuse(WHITE));
    let texture = b.texture(mask_png, "image/png", [WRAP_REPEAT, WRAP_REPEAT], FILTER_NEAREST);
    b.set_material_field(
        screen,
        &["pbrMetallicRoughness", "baseColorTexture"],
        serde_json::json!({ "index": texture }),
    );
    b.set_material_field(screen, &["alphaMode"], serde_json::json!("MASK"));
    let quad = MeshData::quad(Vec3::new(-0.7, 0.55, -0.7), Vec3::X * 1.4, Vec3::Z * 1.4);
    let uv: Vec<glam::Vec2> = quad
        .positions
        .iter()
        .map(|p| glam::Vec2::new(p.x + 0.7, p.z + 0.7) * (5.0 / 1.4))
        .collect();
    let mesh = b.mesh_with_attributes("masked screen", &quad, None, &[&uv], screen);
    b.instance("masked screen", mesh, 0.0, Vec3::ZERO);
    cornell_camera_path(&mut b);
    b.finish("cornell with a masked screen", Vec3::ZERO)
}

/// Scene 2: The Cornell box with five GGX conductor spheres at roughness 0.05 to 0.5, straddling the
/// reconnection roughness threshold (0.2).
pub fn cornell_glossy() -> String {
    let mut b = GltfBuilder::default();
    cornell_room(&mut b, CORNELL_LIGHT, CORNELL_LIGHT_SIZE);
    for (k, roughness) in [0.05f32, 0.1, 0.2, 0.3, 0.5].into_iter().enumerate() {
        let metal = b.material(
            &format!("conductor r{roughness}"),
            MaterialSpec::conductor(Vec3::new(0.95, 0.85, 0.6), roughness),
        );
        let x = -0.72 + 0.36 * k as f32;
        let z = if k % 2 == 0 { -0.25 } else { 0.25 };
        add(
            &mut b,
            &format!("sphere r{roughness}"),
            &MeshData::sphere(Vec3::new(x, -0.83, z), 0.17, 8, 16),
            metal,
        );
    }
    cornell_camera_path(&mut b);
    b.finish("cornell-glossy", Vec3::ZERO)
}

/// An axis-aligned wall rectangle with a rectangular hole, as up to four quads. `origin` is a
/// corner, `u` and `v` span the wall, and the hole covers [u0, u1] x [v0, v1] in fractions.
fn wall_with_hole(origin: Vec3, u: Vec3, v: Vec3, hole: (f32, f32, f32, f32)) -> MeshData {
    let (u0, u1, v0, v1) = hole;
    let pieces = [(0.0, u0, 0.0, 1.0), (u1, 1.0, 0.0, 1.0), (u0, u1, 0.0, v0), (u0, u1, v1, 1.0)];
    pieces
        .iter()
        .filter(|(a, b, c, d)| b > a && d > c)
        .map(|&(a, bu, c, d)| MeshData::quad(origin + u * a + v * c, u * (bu - a), v * (d - c)))
        .fold(MeshData::default(), |acc, q| acc.merged(&q))
}

/// Scene 3: A closed room lit only through the slit of a door left ajar, by a bright light in the
/// closed hallway outside: indirect-dominated, multi-bounce.
pub fn veach_door() -> String {
    let mut b = GltfBuilder::default();
    let white = b.material("white", MaterialSpec::diffuse(WHITE));
    let wood = b.material("wood", MaterialSpec::diffuse(Vec3::new(0.45, 0.3, 0.18)));
    let emitter = b.material("hallway light", MaterialSpec::emitter(Vec3::splat(60.0)));
    // Room x in [-2, 2], y in [0, 2.5], z in [-2, 2]; the door is in the wall x = 2.
    let (lo, hi) = (Vec3::new(-2.0, 0.0, -2.0), Vec3::new(2.0, 2.5, 2.0));
    let room = MeshData::cuboid(lo, hi).flipped();
    // Drop the room's +x face and rebuild it with a door opening.
    let mut walls = room;
    walls.indices.drain(CUBOID_HIGH_X_FACE);
    let door_wall = wall_with_hole(Vec3::new(2.0, 0.0, 2.0), Vec3::Z * -4.0, Vec3::Y * 2.5, (0.4, 0.6, 0.0, 0.8));
    add(&mut b, "room", &walls.merged(&door_wall), white);
    // The door covers the opening but for a 0.06-wide slit at its free edge.
    add(
        &mut b,
        "door",
        &MeshData::cuboid(Vec3::new(2.0, 0.0, -0.34), Vec3::new(2.05, 2.0, 0.4)),
        wood,
    );
    // The hallway outside, closed except towards the door, with the light on its far wall.
    let mut hallway = MeshData::cuboid(Vec3::new(2.0, 0.0, -2.0), Vec3::new(4.0, 2.5, 2.0)).flipped();
    hallway.indices.drain(CUBOID_LOW_X_FACE);
    add(&mut b, "hallway", &hallway, white);
    add(
        &mut b,
        "hallway light",
        &MeshData::quad(Vec3::new(3.99, 0.5, 1.0), Vec3::Y * 1.5, Vec3::Z * -2.0),
        emitter,
    );
    add(
        &mut b,
        "table",
        &MeshData::cuboid(Vec3::new(-1.2, 0.0, -1.5), Vec3::new(0.2, 0.75, -0.5)),
        wood,
    );
    add(
        &mut b,
        "crate",
        &MeshData::cuboid(Vec3::new(0.6, 0.0, 0.7), Vec3::new(1.2, 0.6, 1.3)),
        white,
    );
    camera_path(
        &mut b,
        Vec3::new(-1.8, 1.4, 1.7),
        Vec3::new(1.5, 0.8, -0.3),
        Vec3::new(0.0, 0.0, -0.03),
        1.1,
    );
    b.finish("veach-door", Vec3::ZERO)
}

/// Scene 4: Surfaces 0.02 to 0.2 apart in the Cornell room: a slab hovering 0.02 above the floor, a box
/// 0.05 from a wall, and two boxes 0.1 and 0.2 apart: reconnection distance tests and 1/d^2
/// Jacobian spikes.
pub fn near_field() -> String {
    let mut b = GltfBuilder::default();
    cornell_room(&mut b, CORNELL_LIGHT, CORNELL_LIGHT_SIZE);
    let white = b.material("box white", MaterialSpec::diffuse(WHITE));
    let boxes = MeshData::cuboid(Vec3::new(-0.6, -0.98, -0.2), Vec3::new(0.0, -0.93, 0.4))
        .merged(&MeshData::cuboid(Vec3::new(-0.95, -1.0, -0.8), Vec3::new(-0.55, 0.2, -0.4)))
        .merged(&MeshData::cuboid(Vec3::new(0.2, -1.0, -0.6), Vec3::new(0.5, -0.4, -0.3)))
        .merged(&MeshData::cuboid(Vec3::new(0.6, -1.0, -0.6), Vec3::new(0.9, -0.2, -0.3)))
        .merged(&MeshData::cuboid(Vec3::new(0.2, -1.0, -0.1), Vec3::new(0.9, -0.8, 0.2)));
    add(&mut b, "near boxes", &boxes, white);
    cornell_camera_path(&mut b);
    b.finish("near-field", Vec3::ZERO)
}

/// Scene 5: A smooth glass sphere (IOR 1.5) between a small bright light and a diffuse wall: delta
/// vertices and caustics.
pub fn glass() -> String {
    let mut b = GltfBuilder::default();
    let white = b.material("white", MaterialSpec::diffuse(WHITE));
    let emitter = b.material("small light", MaterialSpec::emitter(Vec3::splat(120.0)));
    let glass = b.material("glass", MaterialSpec::glass(1.5, 0.0));
    let (x2, y2, z2) = (Vec3::X * 2.0, Vec3::Y * 2.0, Vec3::Z * 2.0);
    let corner = Vec3::splat(-1.0);
    let room = MeshData::quad(corner, z2, x2)
        .merged(&MeshData::quad(Vec3::new(-1.0, 1.0, -1.0), x2, z2))
        .merged(&MeshData::quad(corner, x2, y2))
        .merged(&MeshData::quad(corner, y2, z2))
        .merged(&MeshData::quad(Vec3::new(1.0, -1.0, -1.0), z2, y2));
    add(&mut b, "room", &room, white);
    add(
        &mut b,
        "small light",
        &MeshData::quad(Vec3::new(-0.96, 0.6, -0.06), Vec3::Z * 0.12, Vec3::Y * 0.12).flipped(),
        emitter,
    );
    add(
        &mut b,
        "glass sphere",
        &MeshData::sphere(Vec3::new(0.0, -0.2, -0.2), 0.4, 24, 48),
        glass,
    );
    cornell_camera_path(&mut b);
    b.finish("glass", Vec3::ZERO)
}

/// Scene 6: A near-specular mirror (roughness 0.02, a delta lobe in the material model) on the right
/// wall of the Cornell room, seen directly and reflecting the red wall and the boxes:
/// reconnection must move past the mirror vertex.
pub fn mirror() -> String {
    let mut b = GltfBuilder::default();
    cornell_room(&mut b, CORNELL_LIGHT, CORNELL_LIGHT_SIZE);
    let white = b.material("box white", MaterialSpec::diffuse(WHITE));
    let mirror = b.material("mirror", MaterialSpec::conductor(Vec3::splat(0.95), 0.02));
    add(
        &mut b,
        "mirror",
        &MeshData::quad(Vec3::new(0.99, -0.7, -0.9), Vec3::Z * 1.6, Vec3::Y * 1.4),
        mirror,
    );
    cornell_boxes(&mut b, white, white);
    cornell_camera_path(&mut b);
    b.finish("mirror", Vec3::ZERO)
}

/// Scene 7: A ground plane with a few objects under a constant sky: escaped (direction-only)
/// reconnection vertices and NEE/BSDF MIS with the environment.
pub fn env_ground() -> String {
    let mut b = GltfBuilder::default();
    let ground = b.material("ground", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let clay = b.material("clay", MaterialSpec::diffuse(Vec3::new(0.8, 0.45, 0.3)));
    let metal = b.material("brushed metal", MaterialSpec::conductor(Vec3::new(0.9, 0.9, 0.92), 0.3));
    add(
        &mut b,
        "ground",
        &MeshData::quad(Vec3::new(-10.0, 0.0, -10.0), Vec3::Z * 20.0, Vec3::X * 20.0),
        ground,
    );
    add(
        &mut b,
        "block",
        &MeshData::cuboid(Vec3::new(-1.6, 0.0, -0.8), Vec3::new(-0.6, 1.2, 0.2)),
        clay,
    );
    add(&mut b, "ball", &MeshData::sphere(Vec3::new(0.6, 0.6, 0.0), 0.6, 12, 24), metal);
    add(&mut b, "pebble", &MeshData::sphere(Vec3::new(-0.2, 0.25, 1.1), 0.25, 8, 16), clay);
    camera_path(
        &mut b,
        Vec3::new(0.0, 2.2, 5.0),
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::new(0.05, 0.0, 0.0),
        0.8,
    );
    b.finish("env-ground", Vec3::new(0.7, 0.8, 1.0))
}

/// Scene 8: A closed U-shaped corridor whose light hides behind a baffle at the far end: light reaches
/// what the camera sees only after 4 to 6 diffuse bounces (round the two corners, then under the
/// baffle).
pub fn corridor() -> String {
    let mut b = GltfBuilder::default();
    let white = b.material("white", MaterialSpec::diffuse(Vec3::splat(0.8)));
    let emitter = b.material("light", MaterialSpec::emitter(Vec3::splat(100.0)));
    // Outer shell x in [0, 4], y in [0, 1.5], z in [0, 4]; the core x in [1, 3], z in [0, 3] leaves
    // corridors A (x < 1, the camera), B (z > 3) and C (x > 3, the light).
    let shell = MeshData::cuboid(Vec3::ZERO, Vec3::new(4.0, 1.5, 4.0)).flipped();
    let core = MeshData::cuboid(Vec3::new(1.0, 0.0, 0.0), Vec3::new(3.0, 1.5, 3.0));
    // The baffle closes C above 0.4, so the light's end of C is reached only under it.
    let baffle = MeshData::cuboid(Vec3::new(3.0, 0.4, 1.45), Vec3::new(4.0, 1.5, 1.55));
    add(&mut b, "corridor walls", &shell.merged(&core).merged(&baffle), white);
    add(
        &mut b,
        "light",
        &MeshData::quad(Vec3::new(3.05, 1.49, 0.1), Vec3::X * 0.9, Vec3::Z * 1.2),
        emitter,
    );
    camera_path(
        &mut b,
        Vec3::new(0.5, 0.8, 0.2),
        Vec3::new(0.5, 0.6, 4.0),
        Vec3::new(0.0, 0.0, 0.05),
        1.0,
    );
    b.finish("corridor", Vec3::ZERO)
}

/// Scene 9: The white furnace: a diffuse sphere of albedo 1 inside a uniform environment of radiance 1.
/// Camera 0 sees only the sphere; cameras 1 to 8 (the camera path) show it against the sky.
pub fn furnace() -> String {
    let mut b = GltfBuilder::default();
    let white = b.material("albedo 1", MaterialSpec::diffuse(Vec3::ONE));
    add(&mut b, "sphere", &MeshData::sphere(Vec3::ZERO, 1.0, 24, 48), white);
    b.camera("filled by the sphere", Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 0.3);
    camera_path(&mut b, Vec3::new(0.0, 0.5, 4.0), Vec3::ZERO, Vec3::new(0.05, 0.0, 0.0), 0.9);
    b.finish("furnace", Vec3::ONE)
}

/// The Cornell box with a diffuse sphere of `2 * segments * (rings - 1)` triangles floating in it:
/// the scenes of the throughput-against-scene-size benchmark (tools/make_scaling_scenes.rs).
pub fn cornell_sphere(rings: u32, segments: u32) -> String {
    let mut b = GltfBuilder::default();
    cornell_room(&mut b, CORNELL_LIGHT, CORNELL_LIGHT_SIZE);
    let white = b.material("box white", MaterialSpec::diffuse(WHITE));
    cornell_boxes(&mut b, white, white);
    add(
        &mut b,
        "sphere",
        &MeshData::sphere(Vec3::new(0.0, 0.3, 0.25), 0.3, rings, segments),
        white,
    );
    cornell_camera_path(&mut b);
    b.finish("cornell-sphere", Vec3::ZERO)
}

/// Triangles of one tile of [`tiled_floor`]: a 32 x 32 grid of quads.
pub const TILE_TRIANGLES: usize = 2 * 32 * 32;

/// A floor of 2^`levels` unit tiles of [`TILE_TRIANGLES`] triangles each (2^levels x 2048
/// triangles: 1.05 M at 9 levels, 4.2 M at 11, 8.4 M at 12) under a uniform environment, for
/// scale tests. The tiles are instanced through a binary node tree (each level doubles the
/// floor along x or z), so the file stays small whatever the triangle count.
pub fn tiled_floor(levels: u32) -> String {
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(0.6)));
    let n = 32u32;
    let mut tile = MeshData::default();
    for i in 0..=n {
        for j in 0..=n {
            // A gentle bump keeps the BVH honest: a flat grid would be one plane.
            let (x, z) = (i as f32 / n as f32, j as f32 / n as f32);
            let y = 0.02 * ((x * 6.3).sin() * (z * 6.3).cos());
            tile.positions.push(Vec3::new(x, y, z));
        }
    }
    for i in 0..n {
        for j in 0..n {
            let (a, c) = (i * (n + 1) + j, (i + 1) * (n + 1) + j);
            tile.indices.extend([a, a + 1, c + 1, a, c + 1, c]);
        }
    }
    let mesh = b.mesh("tile", &tile, grey);
    let side = 2f32.powf(levels as f32 / 2.0);
    let centre = Vec3::new(side / 2.0, 0.0, side / 2.0);
    b.camera("camera", centre + Vec3::new(0.0, 0.6 * side, 0.9 * side), centre, 0.8);
    let mut root: serde_json::Value = serde_json::from_str(&b.finish("tiled floor", Vec3::splat(1.0))).expect("the builder writes JSON");
    let nodes = root["nodes"].as_array_mut().expect("nodes");
    // Level 0 is the tile; level l + 1 holds level l twice, the second copy shifted along x
    // (l even) or z (l odd) by the width of level l.
    nodes.push(serde_json::json!({ "mesh": mesh }));
    let mut top = nodes.len() - 1;
    for level in 0..levels {
        let offset = 2f32.powi((level / 2) as i32);
        let shift = if level % 2 == 0 { [offset, 0.0, 0.0] } else { [0.0, 0.0, offset] };
        let parent = nodes.len();
        nodes.push(serde_json::json!({ "children": [parent + 1, parent + 2] }));
        nodes.push(serde_json::json!({ "children": [top] }));
        nodes.push(serde_json::json!({ "children": [top], "translation": shift }));
        top = parent;
    }
    root["scenes"][0]["nodes"] = serde_json::json!([0, top]);
    let mut text = serde_json::to_string_pretty(&root).expect("JSON values always serialise");
    text.push('\n');
    text
}

/// Triangles of one sphere of [`instanced_spheres`].
pub const INSTANCED_SPHERE_TRIANGLES: usize = 2 * 96 * 47;

/// A `columns` x `rows` grid (x, z; spacing 1) of one sphere of radius 0.45 with vertex normals
/// and texture coordinates ([`INSTANCED_SPHERE_TRIANGLES`] triangles), drawn once per grid cell
/// by `EXT_mesh_gpu_instancing`, under a uniform environment: a scene whose 144-byte vertex
/// attributes per triangle pass one binding at 110 instances (143 MB) in a file of 0.35 MB, as
/// instanced exports (Blender's) do.
pub fn instanced_spheres(columns: u32, rows: u32) -> String {
    let mut b = GltfBuilder::default();
    let grey = b.material("grey", MaterialSpec::diffuse(Vec3::splat(0.6)));
    let (mesh, normals, uv) = crate::gltf_writer::textured_sphere(Vec3::ZERO, 0.45, 48, 96);
    let sphere = b.mesh_with_attributes("sphere", &mesh, Some(&normals), &[&uv], grey);
    let cells: Vec<Vec3> = (0..rows)
        .flat_map(|z| (0..columns).map(move |x| Vec3::new(x as f32, 0.0, z as f32)))
        .collect();
    b.instanced("spheres", sphere, &cells);
    let (w, d) = (columns as f32 - 1.0, rows as f32 - 1.0);
    let centre = Vec3::new(w / 2.0, 0.0, d / 2.0);
    b.camera("camera", centre + Vec3::new(0.0, 0.8 * w.max(d) + 2.0, 0.6 * d + 2.0), centre, 0.9);
    b.finish("instanced spheres", Vec3::ONE)
}
