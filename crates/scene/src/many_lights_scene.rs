//! The bundled scene `many-lights.gltf` (scenes/README.md): a hundred small lamps and a low sun
//! over a ground with a few blocks, the case where choosing lights by power starves every lamp.

use glam::Vec3;
use serde_json::json;

use crate::gltf_writer::{GltfBuilder, MaterialSpec, MeshData};

/// Lamps along each side of the grid (LAMP_GRID² in all: one in five, on diagonals, a point
/// light, the rest emissive panels).
pub const LAMP_GRID: usize = 10;
/// Side of an emissive lamp panel (scene units).
pub const LAMP_SIDE: f32 = 0.15;

/// A deterministic value in [0, 1) for lamp `i` and salt `k` (a 32-bit integer hash).
fn jitter(i: usize, k: u32) -> f32 {
    let mut h = (i as u32).wrapping_mul(0x9e37_79b9) ^ k.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// A dim, constant night sky written into the file (extras.environment): a scene lit by a sun
/// would otherwise get a viewer's default sky of radiance 1 (default_environment.rs), which would
/// outshine the lamps this scene exists to test.
const NIGHT_SKY: Vec3 = Vec3::new(0.02, 0.025, 0.035);

/// Scene 10: a 24 x 24 ground with four blocks, lit by a hundred small lamps on a jittered 10 x
/// 10 grid 0.5 to 1.3 above it (80 emissive panels of 0.15 x 0.15 facing down, 20 point lights)
/// and a low sun (1 lux) that casts the blocks' shadows across the lamp pools.
pub fn many_lights() -> String {
    let mut b = GltfBuilder::default();
    let ground = b.material("ground", MaterialSpec::diffuse(Vec3::splat(0.5)));
    let stone = b.material("stone", MaterialSpec::diffuse(Vec3::new(0.7, 0.65, 0.55)));
    let ground_mesh = MeshData::quad(Vec3::new(-12.0, 0.0, -12.0), Vec3::Z * 24.0, Vec3::X * 24.0);
    let m = b.mesh("ground", &ground_mesh, ground);
    b.instance("ground", m, 0.0, Vec3::ZERO);
    let mut blocks = MeshData::default();
    for (lo, hi) in [
        (Vec3::new(-5.5, 0.0, -1.0), Vec3::new(-4.5, 1.6, 0.0)),
        (Vec3::new(1.0, 0.0, 2.0), Vec3::new(3.0, 0.8, 2.6)),
        (Vec3::new(4.0, 0.0, -6.0), Vec3::new(4.6, 2.2, -5.4)),
        (Vec3::new(-2.0, 0.0, -4.0), Vec3::new(-1.2, 0.5, -3.2)),
    ] {
        blocks = blocks.merged(&MeshData::cuboid(lo, hi));
    }
    let m = b.mesh("blocks", &blocks, stone);
    b.instance("blocks", m, 0.0, Vec3::ZERO);
    let mut panels = MeshData::default();
    for i in 0..LAMP_GRID * LAMP_GRID {
        let (gx, gz) = ((i % LAMP_GRID) as f32, (i / LAMP_GRID) as f32);
        let x = -9.0 + 2.0 * gx + 1.2 * (jitter(i, 1) - 0.5);
        let z = -9.0 + 2.0 * gz + 1.2 * (jitter(i, 2) - 0.5);
        let y = 0.5 + 0.8 * jitter(i, 3);
        if (i % LAMP_GRID + 2 * (i / LAMP_GRID)).is_multiple_of(5) {
            let colour = [1.0, 0.75 + 0.2 * jitter(i, 4), 0.5 + 0.3 * jitter(i, 5)];
            b.punctual_light(
                json!({ "type": "point", "color": colour, "intensity": 0.6 }),
                Vec3::new(x, y, z),
                -Vec3::Y,
            );
        } else {
            let corner = Vec3::new(x - 0.5 * LAMP_SIDE, y, z - 0.5 * LAMP_SIDE);
            panels = panels.merged(&MeshData::quad(corner, Vec3::X * LAMP_SIDE, Vec3::Z * LAMP_SIDE));
        }
    }
    let lamp = b.material("lamp", MaterialSpec::emitter(Vec3::new(40.0, 32.0, 24.0)));
    let m = b.mesh("lamp panels", &panels, lamp);
    b.instance("lamp panels", m, 0.0, Vec3::ZERO);
    b.punctual_light(
        json!({ "type": "directional", "color": [1.0, 0.85, 0.7], "intensity": 1.0 }),
        Vec3::new(0.0, 10.0, 0.0),
        Vec3::new(-0.6, -0.45, -0.35),
    );
    for k in 0..8 {
        let offset = Vec3::new(0.1 * k as f32, 0.0, 0.0);
        b.camera(
            &format!("camera {k}"),
            Vec3::new(0.0, 5.0, 13.0) + offset,
            Vec3::new(0.0, 0.0, 1.0) + offset,
            0.9,
        );
    }
    b.finish("many-lights", NIGHT_SKY)
}
