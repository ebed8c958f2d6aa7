//! GLSL `trace_pair` (glsl/shading_core/trace_pair.glsl) against its Rust twin `trace_pair` (crates/shading-core/src/bvh.rs), in
//! both forms: the BVH traversed once for a closest-hit and a shadow ray, and the brute-force
//! pass of small uniform-buffer scenes; and the twin against `trace_closest`/`trace_occluded`.

use std::sync::Arc;

use glam::{Vec2, Vec3};
use restir_pt::oracle_types::{OracleRay, TracePairOracleInput, TracePairOracleOutput};
use restir_pt::render::{RenderSettings, SceneGpu};
use restir_pt::scene::{load_scene, Scene};
use restir_pt::shading::bvh::{trace_closest, trace_occluded, trace_pair, Hit, PairRay, NO_HIT, SEGMENT_EPSILON};
use restir_pt::vk::{BindingSlot, Buffer, BufferUsage, Context, Kernel};

use crate::common::{assert_clean, close, gpu, TestRng};
use crate::fixtures::random_scenes::random_scene;

const PAIRS: usize = 12_000;

/// Random pairs inside a cube of half-size `extent` around `centre`: closest rays from random
/// points, and shadow rays that are segments between two random points, a tenth of either kind
/// inactive.
fn random_pairs(seed: u64, centre: Vec3, extent: f32) -> Vec<(PairRay, PairRay)> {
    let mut r = TestRng(seed);
    let point = |r: &mut TestRng| centre + (Vec3::new(r.uniform(), r.uniform(), r.uniform()) * 2.0 - 1.0) * extent;
    (0..PAIRS)
        .map(|i| {
            let closest = PairRay {
                origin: point(&mut r),
                dir: r.unit_vector(),
                tmax: if i % 10 == 3 { 0.0 } else { 1e30 },
            };
            let (p, q) = (point(&mut r), point(&mut r));
            let (origin, dir) = (p, q - p);
            let shadow = PairRay {
                origin,
                dir,
                tmax: if i % 10 == 7 { 0.0 } else { 1.0 - SEGMENT_EPSILON },
            };
            (closest, shadow)
        })
        .collect()
}

fn run_gpu(ctx: &Arc<Context>, scene: &Scene, brute_force: bool, pairs: &[(PairRay, PairRay)]) -> Vec<(Hit, bool)> {
    let scene_gpu = SceneGpu::upload(ctx, scene).unwrap();
    let params = Buffer::new(
        ctx,
        "params",
        std::mem::size_of::<restir_pt::gpu_types::FrameParams>() as u64,
        BufferUsage::Params,
    )
    .unwrap();
    params.write(&[RenderSettings::default().frame_params(scene_gpu.info())]).unwrap();
    let ray = |r: &PairRay| OracleRay {
        origin: r.origin.to_array(),
        tmax: r.tmax,
        dir: r.dir.to_array(),
        pad: 0.0,
    };
    let inputs: Vec<TracePairOracleInput> = pairs
        .iter()
        .map(|(c, s)| TracePairOracleInput {
            closest: ray(c),
            shadow: ray(s),
        })
        .collect();
    let input = Buffer::from_slice(ctx, "pairs", &inputs).unwrap();
    let output_size = std::mem::size_of::<TracePairOracleOutput>() as u64;
    let output = Buffer::new(ctx, "hits", pairs.len() as u64 * output_size, BufferUsage::Storage).unwrap();
    let mut defines = scene_gpu.defines();
    defines.push(("SCENE_BRUTE_FORCE", if brute_force { "1" } else { "0" }));
    let mut buffers = scene_gpu.buffers(&params);
    buffers.extend([
        BindingSlot::storage(5, "Inputs").to(&input),
        BindingSlot::storage(6, "Outputs").to(&output),
    ]);
    let layout: Vec<BindingSlot> = buffers.iter().map(|b| b.slot).collect();
    let kernel = Kernel::new(ctx, "oracle/trace_pair_oracle.comp", &defines, &layout, 4).unwrap();
    kernel.bind(&buffers).unwrap();
    let count = pairs.len() as u32;
    kernel.run_1d(count, 64, bytemuck::bytes_of(&count)).unwrap();
    let out = output.read::<TracePairOracleOutput>(pairs.len()).unwrap();
    out.iter()
        .map(|o| {
            let hit = Hit {
                t: o.hit.t,
                triangle: o.hit.triangle,
                bary: Vec2::from_array(o.hit.bary),
            };
            (hit, o.occluded == 1)
        })
        .collect()
}

/// GPU against twin for every pair; returns how many closest rays hit.
fn assert_gpu_matches_twin(scene: &Scene, gpu_hits: &[(Hit, bool)], pairs: &[(PairRay, PairRay)], brute_force: bool) -> usize {
    let mut hits = 0;
    for (i, ((g, g_occluded), (c, s))) in gpu_hits.iter().zip(pairs).enumerate() {
        let (h, occluded) = trace_pair(&scene.nodes, &scene.triangles, None, brute_force, *c, *s);
        assert_eq!(g.triangle, h.triangle, "pair {i}: GLSL t {} vs Rust t {}", g.t, h.t);
        assert_eq!(*g_occluded, occluded, "pair {i}: occlusion");
        if h.triangle != NO_HIT {
            hits += 1;
            assert!(close(g.t, h.t, 1e-5), "pair {i}: t {} vs {}", g.t, h.t);
            assert!((g.bary - h.bary).abs().max_element() < 1e-5, "pair {i}: barycentrics");
        }
    }
    hits
}

/// GLSL `trace_pair` against its twin with the scene's triangles and BVH nodes reached by device
/// address (SCENE_ADDRESSED), as scenes past one binding's range are: a 4 KiB binding limit sends
/// this 6000-triangle scene down that path.
#[test]
fn trace_pair_glsl_matches_rust_bvh_addressed() {
    let ctx = crate::common::gpu_with_scene_binding_limit(Some(4096));
    let big = random_scene(5);
    assert!(SceneGpu::upload(&ctx, &big).unwrap().addressed());
    let pairs = random_pairs(6, Vec3::ZERO, 6.0);
    let gpu_hits = run_gpu(&ctx, &big, false, &pairs);
    let hits = assert_gpu_matches_twin(&big, &gpu_hits, &pairs, false);
    assert!(hits > PAIRS / 4, "only {hits} of {PAIRS} closest rays hit");
    assert_clean(&ctx);
}

#[test]
fn trace_pair_glsl_matches_rust_bvh_and_brute_force() {
    // GLSL trace_pair against its Rust twin (assert_gpu_matches_twin).
    let ctx = gpu();
    let big = random_scene(5);
    let pairs = random_pairs(6, Vec3::ZERO, 6.0);
    let gpu_hits = run_gpu(&ctx, &big, false, &pairs);
    let hits = assert_gpu_matches_twin(&big, &gpu_hits, &pairs, false);
    assert!(hits > PAIRS / 4, "only {hits} of {PAIRS} closest rays hit");
    let occluded = gpu_hits.iter().filter(|g| g.1).count();
    assert!(
        occluded > PAIRS / 10 && occluded < PAIRS * 9 / 10,
        "{occluded} of {PAIRS} shadow rays occluded"
    );

    // The Cornell box is small enough for uniform buffers on lavapipe: both forms there.
    let cornell = load_scene(&crate::common::repo_path("scenes/cornell.gltf")).unwrap();
    // The loader re-centres a scene on its first camera: the box is around its bounds' centre.
    let (lo, hi) = cornell.bounds;
    let pairs = random_pairs(7, 0.5 * (lo + hi), 0.99);
    for brute_force in [false, true] {
        let gpu_hits = run_gpu(&ctx, &cornell, brute_force, &pairs);
        let hits = assert_gpu_matches_twin(&cornell, &gpu_hits, &pairs, brute_force);
        assert!(hits > PAIRS * 6 / 10, "only {hits} of {PAIRS} closest rays hit the box");
    }
    assert_clean(&ctx);
}

#[test]
fn trace_pair_twin_equals_single_ray_traversals() {
    for (scene, extent) in [(random_scene(3), 6.0), (random_scene(11), 2.0)] {
        let (mut ties, mut hits) = (0, 0);
        for (i, (c, s)) in random_pairs(12, Vec3::ZERO, extent).into_iter().enumerate() {
            let (h, occluded) = trace_pair(&scene.nodes, &scene.triangles, None, false, c, s);
            let (b, b_occluded) = trace_pair(&scene.nodes, &scene.triangles, None, true, c, s);
            if c.tmax > 0.0 {
                let single = trace_closest(&scene.nodes, &scene.triangles, c.origin, c.dir, c.tmax);
                assert_eq!(
                    (h.triangle, h.t.to_bits()),
                    (single.triangle, single.t.to_bits()),
                    "pair {i}: closest"
                );
            } else {
                assert_eq!(h.triangle, NO_HIT, "pair {i}: an inactive ray hit");
            }
            let single = s.tmax > 0.0 && trace_occluded(&scene.nodes, &scene.triangles, s.origin, s.dir, s.tmax);
            assert_eq!(occluded, single, "pair {i}: occlusion");
            assert_eq!(b_occluded, single, "pair {i}: brute-force occlusion");
            // Brute force keeps the first of equal distances in index order, the BVH the first it
            // meets: only exact ties may name another triangle.
            assert_eq!(b.t.to_bits(), h.t.to_bits(), "pair {i}: brute-force distance");
            hits += (h.triangle != NO_HIT) as usize;
            ties += (b.triangle != h.triangle) as usize;
        }
        assert!(hits > PAIRS / 4 && ties * 1000 <= hits, "{ties} ties in {hits} hits");
    }
}
