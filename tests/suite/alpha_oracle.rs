//! GLSL alpha testing in traversal (glsl/shading_core/alpha.glsl inside `bvh_traverse` and `trace_pair`)
//! against its Rust twins (crates/shading-core/src/alpha.rs `alpha_keeps` and `alpha_hash`,
//! crates/shading-core/src/bvh.rs `bvh_traverse` and `trace_pair`, crates/shading-core/src/texture.rs
//! `material_alpha`) on random triangles with opaque, MASK (textured and not) and BLEND
//! (textured and not) materials.

use glam::{Vec2, Vec3};
use restir_pt::gpu_types::{Material, Triangle, NO_EMITTER};
use restir_pt::oracle_types::{AlphaOracleInput, AlphaOracleOutput};
use restir_pt::render::SceneGpu;
use restir_pt::scene::{Camera, Scene, SceneParts};
use restir_pt::shading::alpha::{alpha_hash, alpha_keeps, AlphaScene};
use restir_pt::shading::alpha_pass::{alpha_pass_begin, alpha_pass_new, alpha_pass_resolve};
use restir_pt::shading::alpha_trace::bvh_alpha_pass;
use restir_pt::shading::bvh::{bvh_traverse, intersect_triangle, trace_pair, Hit, PairRay, NO_HIT};
use restir_pt::shading::surface::TriangleSurface;
use restir_pt::shading::texture::{
    material_alpha, MaterialTextures, SceneTextures, TextureHeader, TextureSlot, ALPHA_BLEND, ALPHA_MASK, ALPHA_OPAQUE, TEXTURE_WRAP_REPEAT,
};

use crate::common::{assert_clean, close, gpu, run_surface_set0_oracle_with, TestRng};

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

/// Random triangles with random texture coordinates, cycling through [`MATERIALS`]; one 7 x 5
/// bilinear, repeating texture of random RGBA texels. `count` triangles centred in
/// [-extent, extent]^3; with `twins`, each is followed by a copy of itself with the next
/// material, so that rays meet hits of equal distance (the first in traversal order wins).
pub fn alpha_random_scene(seed: u64, count: u32, extent: f32, twins: bool) -> Scene {
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
    for i in 0..count {
        let c = (Vec3::new(r.uniform(), r.uniform(), r.uniform()) * 2.0 - 1.0) * extent;
        let v: Vec<Vec3> = (0..3).map(|_| c + (0.2 + r.uniform()) * r.unit_vector()).collect();
        let tri = Triangle {
            v0: v[0].into(),
            material: i % MATERIALS.len() as u32,
            e1: (v[1] - v[0]).into(),
            emitter: NO_EMITTER,
            e2: (v[2] - v[0]).into(),
            alpha_tested: 0,
        };
        let mut a = TriangleSurface::flat();
        for k in 0..3 {
            a.uv[k] = [0, 1, 2, 3].map(|_| 4.0 * r.uniform() - 2.0);
        }
        triangles.push(tri);
        surfaces.push(a);
        if twins {
            triangles.push(Triangle {
                material: (i + 1) % MATERIALS.len() as u32,
                ..tri
            });
            surfaces.push(a);
        }
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

/// `RAYS` random rays from [-extent, extent]^3 as oracle/alpha_oracle.comp takes them, with a
/// random triangle and barycentrics for the per-triangle functions.
fn alpha_oracle_inputs(scene: &Scene, seed: u64, extent: f32) -> Vec<AlphaOracleInput> {
    let mut r = TestRng(seed);
    let mut inputs = Vec::with_capacity(RAYS);
    for _ in 0..RAYS {
        let o = (Vec3::new(r.uniform(), r.uniform(), r.uniform()) * 2.0 - 1.0) * extent;
        let shadow_tmax = 0.5 + 6.0 * r.uniform();
        let dir = r.unit_vector();
        let tri = (r.uniform() * scene.triangles.len() as f32) as u32 % scene.triangles.len() as u32;
        let b = restir_pt::shading::sampling::sample_triangle(Vec2::new(r.uniform(), r.uniform()));
        inputs.push(AlphaOracleInput {
            origin: o.to_array(),
            shadow_tmax,
            dir: dir.to_array(),
            triangle: tri,
            bary: b.to_array(),
            pad: [0.0; 2],
        });
    }
    inputs
}

/// Runs oracle/alpha_oracle.comp over `inputs`, `trace_pair` in its brute-force form if
/// `brute_force`.
fn run_alpha_oracle(scene: &Scene, inputs: &[AlphaOracleInput], brute_force: bool) -> Vec<AlphaOracleOutput> {
    let ctx = gpu();
    let scene_gpu = SceneGpu::upload(&ctx, scene).unwrap();
    let defines = scene_gpu.defines();
    assert!(defines.contains(&("SCENE_ALPHA", "1")), "the scene must compile alpha testing in");
    if brute_force {
        assert!(
            defines.contains(&("SCENE_UNIFORM_BUFFERS", "1")),
            "brute force needs uniform buffers"
        );
    }
    let extra: &[(&str, &str)] = if brute_force { &[("SCENE_BRUTE_FORCE", "1")] } else { &[] };
    let out = run_surface_set0_oracle_with(&ctx, &scene_gpu, "oracle/alpha_oracle.comp", extra, inputs);
    assert_clean(&ctx);
    out
}

/// What an oracle run compared: rays set aside near an alpha threshold, closest hits alpha
/// changed, and `alpha_keeps` decisions.
#[derive(Debug, Default)]
struct OracleCounts {
    set_aside: usize,
    changed: usize,
    kept: usize,
    dropped: usize,
}

/// Compares the GLSL results `out` with the Rust twins ray by ray (asserting), `trace_pair` in
/// its brute-force form if `brute_force`.
fn compare_alpha_oracle(scene: &Scene, inputs: &[AlphaOracleInput], out: &[AlphaOracleOutput], brute_force: bool) -> OracleCounts {
    let alpha = scene.alpha().expect("the scene has non-opaque materials");
    let mut n = OracleCounts::default();
    for (i, (input, g)) in inputs.iter().zip(out).enumerate() {
        let (o, tmax_s, d) = (Vec3::from_array(input.origin), input.shadow_tmax, Vec3::from_array(input.dir));
        let (tri, bary) = (input.triangle, Vec2::from_array(input.bary));
        assert_eq!(g.hash.to_bits(), alpha_hash(o, d, tri).to_bits(), "alpha_hash, item {i}");
        let t = &scene.textures.materials[scene.triangles[tri as usize].material as usize];
        let a = material_alpha(t, &scene.textures, &scene.surface_at(tri, bary));
        assert!(close(g.alpha, a, 1e-4), "material_alpha, item {i}: GLSL {} vs Rust {a}", g.alpha);
        let threshold = if t.alpha_mode == ALPHA_MASK {
            t.alpha_cutoff
        } else {
            alpha_hash(o, d, tri)
        };
        if t.alpha_mode == ALPHA_OPAQUE || (a - threshold).abs() > MARGIN {
            let keeps = alpha_keeps(&alpha, &scene.triangles, tri, bary, o, d);
            assert_eq!(g.keeps == 1, keeps, "alpha_keeps, item {i}");
            n.kept += keeps as usize;
            n.dropped += !keeps as usize;
        }
        if decision_margin(scene, &alpha, o, d, 1e30) < MARGIN {
            n.set_aside += 1;
            continue;
        }
        let h = bvh_traverse(&scene.nodes, &scene.triangles, Some(&alpha), o, d, 1e30, false);
        let opaque = bvh_traverse(&scene.nodes, &scene.triangles, None, o, d, 1e30, false);
        n.changed += (opaque.triangle != h.triangle) as usize;
        assert_eq!(g.hit.triangle, h.triangle, "bvh_traverse closest triangle, ray {i}");
        assert_eq!(g.pair_hit.triangle, h.triangle, "trace_pair closest triangle, ray {i}");
        if h.triangle != NO_HIT {
            assert!(close(g.hit.t, h.t, 1e-4) && close(g.pair_hit.t, h.t, 1e-4), "hit distance, ray {i}");
            assert!(
                (Vec2::from_array(g.hit.bary) - h.bary).abs().max_element() < 1e-4,
                "barycentrics, ray {i}"
            );
        }
        let any = bvh_traverse(&scene.nodes, &scene.triangles, Some(&alpha), o, d, tmax_s, true).triangle != NO_HIT;
        assert_eq!(g.any_hit == 1, any, "bvh_traverse any hit, ray {i}");
        let shadow = PairRay {
            origin: o,
            dir: d,
            tmax: tmax_s,
        };
        let closest = PairRay { tmax: 1e30, ..shadow };
        let (ph, occluded) = trace_pair(&scene.nodes, &scene.triangles, Some(&alpha), brute_force, closest, shadow);
        assert_eq!(
            (ph.triangle, occluded),
            (h.triangle, any),
            "Rust trace_pair against bvh_traverse, ray {i}"
        );
        assert_eq!(g.pair_occluded == 1, occluded, "trace_pair occlusion, ray {i}");
    }
    n
}

/// GLSL `bvh_traverse` (closest and any hit), `trace_pair`, `alpha_keeps`, `alpha_hash` and
/// `material_alpha` against the Rust twins of the same names: hits and occlusion equal, hashes
/// bit-equal, alpha within 1e-4, on every ray whose alpha decisions are not within 2e-4 of
/// their threshold (at most 1% of rays are set aside so).
#[test]
fn alpha_traversal_glsl_matches_rust() {
    // GLSL bvh_traverse, trace_pair, alpha_hash, alpha_keeps and material_alpha of a scene with alpha
    // tests against their Rust twins (compare_alpha_oracle).
    let scene = alpha_random_scene(21, 600, 5.0, false);
    let inputs = alpha_oracle_inputs(&scene, 22, 5.0);
    let out = run_alpha_oracle(&scene, &inputs, false);
    let n = compare_alpha_oracle(&scene, &inputs, &out, false);
    println!(
        "alpha oracle: {} of {RAYS} closest hits changed by alpha, {} set aside, alpha_keeps kept {} and dropped {}",
        n.changed, n.set_aside, n.kept, n.dropped
    );
    assert!(n.set_aside * 100 <= RAYS, "{} rays set aside", n.set_aside);
    assert!(n.changed * 20 > RAYS, "only {} rays see alpha testing change their hit", n.changed);
    assert!(
        n.kept * 5 > RAYS && n.dropped * 5 > RAYS,
        "alpha_keeps kept {}, dropped {}",
        n.kept,
        n.dropped
    );
}

/// The brute-force `trace_pair` (small scenes bound as uniform buffers) against its Rust twin,
/// with `bvh_traverse` and the per-triangle functions as above, on 24 random triangles each
/// followed by a twin of another material (equal hit distances): equal hits and occlusion.
#[test]
fn alpha_brute_force_pair_glsl_matches_rust() {
    let scene = alpha_random_scene(31, 24, 1.0, true);
    assert!(scene.triangles.len() <= restir_pt::shading::bvh::BRUTE_FORCE_MAX_TRIANGLES);
    let inputs = alpha_oracle_inputs(&scene, 32, 1.5);
    let out = run_alpha_oracle(&scene, &inputs, true);
    let n = compare_alpha_oracle(&scene, &inputs, &out, true);
    println!(
        "alpha brute-force oracle: {} of {RAYS} closest hits changed by alpha, {} set aside",
        n.changed, n.set_aside
    );
    assert!(n.set_aside * 100 <= RAYS, "{} rays set aside", n.set_aside);
    assert!(n.changed * 20 > RAYS, "only {} rays see alpha testing change their hit", n.changed);
}

/// The closest kept hit as a test inside the triangle loop finds it: every triangle in index
/// order, a hit counting when nearer than the nearest kept one so far and kept by `alpha_keeps`.
fn closest_kept_in_loop(scene: &Scene, alpha: &AlphaScene, o: Vec3, d: Vec3, tmax: f32) -> Hit {
    let mut hit = Hit {
        t: tmax,
        triangle: NO_HIT,
        bary: Vec2::ZERO,
    };
    for (i, tri) in scene.triangles.iter().enumerate() {
        if let Some((t, bary)) = intersect_triangle(o, d, tri, hit.t) {
            if alpha_keeps(alpha, &scene.triangles, i as u32, bary, o, d) {
                hit = Hit {
                    t,
                    triangle: i as u32,
                    bary,
                };
            }
        }
    }
    hit
}

/// How many passes the Rust `bvh_traverse` makes for the closest hit of the ray (o, d).
fn closest_passes(scene: &Scene, alpha: &AlphaScene, o: Vec3, d: Vec3) -> u32 {
    let mut p = alpha_pass_new(1e30);
    for passes in 1.. {
        alpha_pass_begin(&mut p, 1e30);
        bvh_alpha_pass(&scene.nodes, &scene.triangles, o, d, false, &mut p);
        if alpha_pass_resolve(&mut p, alpha, &scene.triangles, o, d, false).is_some() {
            return passes;
        }
    }
    unreachable!()
}

/// The deferred alpha tests (Rust `bvh_traverse` and `trace_pair`, BVH and brute force) find
/// bit for bit the hit and occlusion of a test inside the loop, on 20000 rays through the 600
/// triangles of the GLSL oracle and through 300 triangles with twins (equal distances). Rays
/// needing more than one pass (a rejected hit with a second alpha-tested hit before the opaque
/// one) and rays won by the first of two equal distances must both occur.
#[test]
fn alpha_passes_find_the_hits_of_a_test_inside_the_loop() {
    for (scene, extent, twins) in [
        (alpha_random_scene(21, 600, 5.0, false), 5.0, false),
        (alpha_random_scene(23, 300, 2.0, true), 2.5, true),
    ] {
        let alpha = scene.alpha().unwrap();
        let mut r = TestRng(24);
        let (mut multi_pass, mut ties) = (0, 0);
        for i in 0..RAYS {
            let o = (Vec3::new(r.uniform(), r.uniform(), r.uniform()) * 2.0 - 1.0) * extent;
            let d = r.unit_vector();
            let tmax_s = 0.5 + 6.0 * r.uniform();
            let want = closest_kept_in_loop(&scene, &alpha, o, d, 1e30);
            let occluded = closest_kept_in_loop(&scene, &alpha, o, d, tmax_s).triangle != NO_HIT;
            let h = bvh_traverse(&scene.nodes, &scene.triangles, Some(&alpha), o, d, 1e30, false);
            assert_eq!(
                (h.triangle, h.t.to_bits()),
                (want.triangle, want.t.to_bits()),
                "closest hit, ray {i}"
            );
            assert_eq!(h.bary, want.bary, "barycentrics, ray {i}");
            let any = bvh_traverse(&scene.nodes, &scene.triangles, Some(&alpha), o, d, tmax_s, true).triangle != NO_HIT;
            assert_eq!(any, occluded, "any hit, ray {i}");
            for brute_force in [false, true] {
                let shadow = PairRay {
                    origin: o,
                    dir: d,
                    tmax: tmax_s,
                };
                let (ph, p_occluded) = trace_pair(
                    &scene.nodes,
                    &scene.triangles,
                    Some(&alpha),
                    brute_force,
                    PairRay { tmax: 1e30, ..shadow },
                    shadow,
                );
                assert_eq!(
                    (ph.triangle, ph.t.to_bits(), p_occluded),
                    (want.triangle, want.t.to_bits(), occluded),
                    "trace_pair (brute force {brute_force}), ray {i}"
                );
            }
            multi_pass += (closest_passes(&scene, &alpha, o, d) > 1) as usize;
            let equal_t = |(k, tri): (usize, &Triangle)| {
                k as u32 != want.triangle && intersect_triangle(o, d, tri, 1e30).is_some_and(|(t, _)| t == want.t)
            };
            ties += (want.triangle != NO_HIT && scene.triangles.iter().enumerate().any(equal_t)) as usize;
        }
        println!(
            "alpha passes (twins {twins}): {multi_pass} of {RAYS} rays needed more than one pass, {ties} hits had an equal-distance rival"
        );
        assert!(multi_pass * 100 > RAYS, "only {multi_pass} rays needed a second pass");
        assert!(!twins || ties * 20 > RAYS, "only {ties} equal-distance hits");
    }
}
