//! GLSL alpha testing in traversal (glsl/alpha.glsl inside `bvh_traverse` and `trace_pair`)
//! against its Rust twins (src/shading/alpha.rs `alpha_keeps` and `alpha_hash`,
//! src/scene/bvh.rs `bvh_traverse` and `trace_pair`, src/shading/texture.rs
//! `material_alpha`) on random triangles with opaque, MASK (textured and not) and BLEND
//! (textured and not) materials.

use glam::{Vec2, Vec3, Vec4};
use restir_pt::gpu_types::{Material, Triangle, NO_EMITTER};
use restir_pt::render::SceneGpu;
use restir_pt::scene::bvh::{bvh_traverse, intersect_triangle, trace_pair, PairRay, NO_HIT};
use restir_pt::scene::{Camera, Scene, SceneParts};
use restir_pt::shading::alpha::{alpha_hash, alpha_keeps, AlphaScene};
use restir_pt::shading::surface::TriangleSurface;
use restir_pt::shading::texture::{
    material_alpha, MaterialTextures, SceneTextures, TextureHeader, TextureSlot, ALPHA_BLEND, ALPHA_MASK, ALPHA_OPAQUE, TEXTURE_WRAP_REPEAT,
};

use crate::common::{assert_clean, close, gpu, run_surface_set0_oracle, TestRng};

const RAYS: usize = 20_000;
/// Alpha decisions closer than this to their threshold may differ between llvmpipe's and
/// Rust's rounding of the bilinear lookup; rays that meet one are not compared.
const MARGIN: f32 = 2e-4;

/// (alpha mode, cutoff, base alpha, textured) of the scene's five materials.
const MATERIALS: [(u32, f32, f32, bool); 5] = [
    (ALPHA_OPAQUE, 0.5, 1.0, false),
    (ALPHA_MASK, 0.5, 1.0, true),
    (ALPHA_MASK, 0.5, 0.3, false),
    (ALPHA_BLEND, 0.5, 0.6, false),
    (ALPHA_BLEND, 0.5, 0.9, true),
];

/// 600 random triangles with random texture coordinates, cycling through [`MATERIALS`]; one
/// 7 x 5 bilinear, repeating texture of random RGBA texels.
pub fn alpha_random_scene(seed: u64) -> Scene {
    let mut r = TestRng(seed);
    let (w, h) = (7, 5);
    let mut textures = SceneTextures {
        headers: vec![TextureHeader {
            width: w,
            height: h,
            offset: 0,
            sampler_bits: TEXTURE_WRAP_REPEAT | TEXTURE_WRAP_REPEAT << 2,
        }],
        texels: (0..w * h).map(|_| r.next_u64() as u32).collect(),
        materials: vec![],
    };
    for (alpha_mode, alpha_cutoff, base_alpha, textured) in MATERIALS {
        let base_color = if textured {
            TextureSlot {
                texture_index: 0,
                ..Default::default()
            }
        } else {
            TextureSlot::default()
        };
        textures.materials.push(MaterialTextures {
            base_color,
            normal_scale: 1.0,
            alpha_cutoff,
            alpha_mode,
            base_alpha,
            ..Default::default()
        });
    }
    let (mut triangles, mut surfaces) = (Vec::new(), Vec::new());
    for i in 0..600 {
        let c = Vec3::new(r.uniform(), r.uniform(), r.uniform()) * 10.0 - 5.0;
        let v: Vec<Vec3> = (0..3).map(|_| c + (0.2 + r.uniform()) * r.unit_vector()).collect();
        triangles.push(Triangle {
            v0: v[0].into(),
            material: i % MATERIALS.len() as u32,
            e1: (v[1] - v[0]).into(),
            emitter: NO_EMITTER,
            e2: (v[2] - v[0]).into(),
            alpha_tested: 0,
        });
        let mut a = TriangleSurface::flat();
        for k in 0..3 {
            a.uv[k] = [0, 1, 2, 3].map(|_| 4.0 * r.uniform() - 2.0);
        }
        surfaces.push(a);
    }
    Scene::build(SceneParts {
        source: "random alpha-tested scene".into(),
        triangles,
        surfaces,
        textures,
        materials: vec![
            Material {
                base_color: [0.5; 3],
                roughness: 1.0,
                ior: 1.5,
                ..Default::default()
            };
            MATERIALS.len()
        ],
        material_names: (0..MATERIALS.len()).map(|i| format!("m{i}")).collect(),
        environment: Vec3::ONE,
        environment_map: None,
        cameras: vec![Camera::look_at("test", Vec3::new(0.0, 1.0, 12.0), Vec3::ZERO, Vec3::Y, 0.8)],
        lights: vec![],
        warnings: vec![],
    })
}

/// The smallest distance of an alpha decision from its threshold over every non-opaque
/// triangle the ray (o, d) crosses before `tmax`.
fn decision_margin(scene: &Scene, alpha: &AlphaScene, o: Vec3, d: Vec3, tmax: f32) -> f32 {
    let mut margin = f32::INFINITY;
    for (i, tri) in scene.triangles.iter().enumerate() {
        let Some((_, bary)) = intersect_triangle(o, d, tri, tmax) else {
            continue;
        };
        let t = &alpha.textures.materials[tri.material as usize];
        let a = material_alpha(t, alpha.textures, &scene.surface_at(i as u32, bary));
        margin = margin.min(match t.alpha_mode {
            ALPHA_MASK => (a - t.alpha_cutoff).abs(),
            ALPHA_BLEND => (alpha_hash(o, d, i as u32) - a).abs(),
            _ => f32::INFINITY,
        });
    }
    margin
}

/// Runs oracle/alpha_oracle.comp over `inputs` (three rows per item); four rows per item back.
fn run_alpha_oracle(scene: &Scene, inputs: &[Vec4]) -> Vec<Vec4> {
    let ctx = gpu();
    let scene_gpu = SceneGpu::upload(&ctx, scene).unwrap();
    assert!(
        scene_gpu.defines().contains(&("SCENE_ALPHA", "1")),
        "the scene must compile alpha testing in"
    );
    let out = run_surface_set0_oracle(&ctx, &scene_gpu, "oracle/alpha_oracle.comp", inputs, inputs.len() / 3, 4);
    assert_clean(&ctx);
    out
}

/// GLSL `bvh_traverse` (closest and any hit), `trace_pair`, `alpha_keeps`, `alpha_hash` and
/// `material_alpha` against the Rust twins of the same names: hits and occlusion equal, hashes
/// bit-equal, alpha within 1e-4, on every ray whose alpha decisions are not within 2e-4 of
/// their threshold (at most 1% of rays are set aside so).
#[test]
fn alpha_traversal_glsl_matches_rust() {
    let scene = alpha_random_scene(21);
    let alpha = scene.alpha().expect("the scene has non-opaque materials");
    let mut r = TestRng(22);
    let mut inputs = Vec::with_capacity(3 * RAYS);
    for _ in 0..RAYS {
        let o = Vec3::new(r.uniform(), r.uniform(), r.uniform()) * 10.0 - 5.0;
        inputs.push(o.extend(0.5 + 6.0 * r.uniform()));
        inputs.push(r.unit_vector().extend(0.0));
        let tri = (r.uniform() * scene.triangles.len() as f32) as u32 % scene.triangles.len() as u32;
        let b = restir_pt::shading::sampling::sample_triangle(Vec2::new(r.uniform(), r.uniform()));
        inputs.push(Vec4::new(f32::from_bits(tri), b.x, b.y, 0.0));
    }
    let out = run_alpha_oracle(&scene, &inputs);
    let (mut set_aside, mut changed, mut kept, mut dropped) = (0, 0, 0, 0);
    for i in 0..RAYS {
        let (o, tmax_s, d) = (inputs[3 * i].truncate(), inputs[3 * i].w, inputs[3 * i + 1].truncate());
        let (tri, bary) = (inputs[3 * i + 2].x.to_bits(), Vec2::new(inputs[3 * i + 2].y, inputs[3 * i + 2].z));
        let g = &out[4 * i..4 * i + 4];
        assert_eq!(g[1].z.to_bits(), alpha_hash(o, d, tri).to_bits(), "alpha_hash, item {i}");
        let t = &scene.textures.materials[scene.triangles[tri as usize].material as usize];
        let a = material_alpha(t, &scene.textures, &scene.surface_at(tri, bary));
        assert!(close(g[1].w, a, 1e-4), "material_alpha, item {i}: GLSL {} vs Rust {a}", g[1].w);
        let threshold = if t.alpha_mode == ALPHA_MASK {
            t.alpha_cutoff
        } else {
            alpha_hash(o, d, tri)
        };
        if t.alpha_mode == ALPHA_OPAQUE || (a - threshold).abs() > MARGIN {
            let keeps = alpha_keeps(&alpha, &scene.triangles, tri, bary, o, d);
            assert_eq!(g[3].x == 1.0, keeps, "alpha_keeps, item {i}");
            kept += keeps as usize;
            dropped += !keeps as usize;
        }
        if decision_margin(&scene, &alpha, o, d, 1e30) < MARGIN {
            set_aside += 1;
            continue;
        }
        let h = bvh_traverse(&scene.nodes, &scene.triangles, Some(&alpha), o, d, 1e30, false);
        let opaque = bvh_traverse(&scene.nodes, &scene.triangles, None, o, d, 1e30, false);
        changed += (opaque.triangle != h.triangle) as usize;
        assert_eq!(g[0].y.to_bits(), h.triangle, "bvh_traverse closest triangle, ray {i}");
        assert_eq!(g[2].y.to_bits(), h.triangle, "trace_pair closest triangle, ray {i}");
        if h.triangle != NO_HIT {
            assert!(close(g[0].x, h.t, 1e-4) && close(g[2].x, h.t, 1e-4), "hit distance, ray {i}");
            assert!(
                (Vec2::new(g[0].z, g[0].w) - h.bary).abs().max_element() < 1e-4,
                "barycentrics, ray {i}"
            );
        }
        let any = bvh_traverse(&scene.nodes, &scene.triangles, Some(&alpha), o, d, tmax_s, true).triangle != NO_HIT;
        assert_eq!(g[1].x == 1.0, any, "bvh_traverse any hit, ray {i}");
        let shadow = PairRay {
            origin: o,
            dir: d,
            tmax: tmax_s,
        };
        let closest = PairRay { tmax: 1e30, ..shadow };
        let (ph, occluded) = trace_pair(&scene.nodes, &scene.triangles, Some(&alpha), false, closest, shadow);
        assert_eq!(
            (ph.triangle, occluded),
            (h.triangle, any),
            "Rust trace_pair against bvh_traverse, ray {i}"
        );
        assert_eq!(g[1].y == 1.0, occluded, "trace_pair occlusion, ray {i}");
    }
    println!("alpha oracle: {changed} of {RAYS} closest hits changed by alpha, {set_aside} set aside, alpha_keeps kept {kept} and dropped {dropped}");
    assert!(set_aside * 100 <= RAYS, "{set_aside} rays set aside");
    assert!(changed * 20 > RAYS, "only {changed} rays see alpha testing change their hit");
    assert!(kept * 5 > RAYS && dropped * 5 > RAYS, "alpha_keeps kept {kept}, dropped {dropped}");
}
