//! GLSL `stream_path_candidates` (glsl/shading/candidates.glsl, the initial pass's candidates)
//! against its Rust twin `stream_path_candidates` (crates/shading/src/candidates.rs): one traced path
//! per item from a primary hit of camera 0 with its own seed, its light-ending prefixes streamed
//! into a fresh Resampler on both sides, with and without Russian roulette; the chosen record,
//! the weight sum, W, the expectation and the pass counters compared.

use glam::Vec3;
use restir_pt::oracle_types::{CandidatesOracleInput, CandidatesOracleOutput, CandidatesOracleParams};
use restir_pt::render::{RenderSettings, SceneGpu};
use restir_pt::scene::Scene;
use restir_pt::shading::bvh::NO_HIT;
use restir_pt::shading::candidates::stream_path_candidates;
use restir_pt::shading::gris::{resampler_begin, resampler_finish};
use restir_pt::shading::path_record::{PathRecord, MAX_PATH_LENGTH};
use restir_pt::shading::shift::{primary_hit, ShiftParams, Vertex};
use restir_pt::vk::{Buffer, BufferUsage};

use crate::common::TestRng;
use crate::fixtures::normal_mapped_scene::{scene_named, NORMAL_MAPPED_BOX};

const ITEMS: usize = 4096;
const IMAGE: u32 = 64;

/// Relative closeness with a floor for values near zero.
fn close(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1e-30)
}

/// Whether the GLSL output `g` agrees with the Rust result: the chosen record (header
/// exactly; cached terms, contribution within 1e-3), the weight sum, W and the expectation
/// within 1e-3 relative, the counters exactly. The largest relative difference of the sums.
fn agrees(g: &CandidatesOracleOutput, record: &PathRecord, weight_sum: f32, w: f32, lost: bool, expected: Vec3) -> Option<f32> {
    let gr = &g.record;
    let header = [gr.seed, gr.info, gr.lobes, gr.rc_triangle, gr.rc_next_triangle];
    let r = record;
    if header != [r.seed, r.info, r.lobes, r.rc_triangle, r.rc_next_triangle] || (g.chosen_lost != 0) != lost {
        return None;
    }
    let floats = [
        (gr.rc_pdf, r.rc_pdf),
        (gr.rc_geometry, r.rc_geometry),
        (gr.rc_pdf_after, r.rc_pdf_after),
        (gr.contribution[0], r.contribution[0]),
        (gr.contribution[1], r.contribution[1]),
        (gr.contribution[2], r.contribution[2]),
        (g.weight_sum, weight_sum),
        (g.weight, w),
        (g.expected[0], expected.x),
        (g.expected[1], expected.y),
        (g.expected[2], expected.z),
    ];
    let worst = floats
        .iter()
        .map(|&(a, b)| if a == b { 0.0 } else { (a - b).abs() / a.abs().max(b.abs()) })
        .fold(0.0f32, f32::max);
    (worst <= 1e-3 && floats.iter().all(|&(a, b)| close(a, b, 1e-3) || a == b)).then_some(worst)
}

#[test]
fn stream_path_candidates_glsl_matches_rust() {
    let ctx = crate::common::gpu();
    let scenes = [
        ("cornell", true),
        ("cornell-glossy", true),
        ("glass", false),
        ("env-ground", true),
        (NORMAL_MAPPED_BOX, false),
    ];
    for (name, russian_roulette) in scenes {
        let scene = scene_named(name);
        let params = ShiftParams::for_scene(&scene);
        let items = primary_hits(&scene);
        let scale = 0.5f32;
        let out = run_candidates_oracle(&ctx, &scene, &items, &params, scale, russian_roulette);
        let camera = scene.cameras[0].position;
        let (mut chosen, mut differ, mut beyond_1e4, mut dropped, mut cut) = (0, 0, 0, 0, 0);
        for (i, ((y1, seed), g)) in items.iter().zip(&out).enumerate() {
            let mut s = resampler_begin();
            let counts = stream_path_candidates(
                &scene,
                &mut s,
                camera,
                *y1,
                *seed,
                MAX_PATH_LENGTH,
                &params,
                scale,
                russian_roulette,
            );
            let (record, w, _) = resampler_finish(&s);
            if russian_roulette {
                // Paths that the roulette changed, so that the flag is seen to reach the kernel.
                let mut without = resampler_begin();
                stream_path_candidates(&scene, &mut without, camera, *y1, *seed, MAX_PATH_LENGTH, &params, scale, false);
                cut += (without.weight_sum != s.weight_sum) as usize;
            }
            let gr = &g.record;
            let floats = [gr.rc_pos, gr.rc_next, gr.suffix, gr.contribution, g.expected];
            let scalars = [gr.rc_pdf, gr.rc_geometry, gr.rc_pdf_after, g.weight_sum, g.chosen_target, g.weight];
            assert!(
                floats.iter().flatten().chain(&scalars).all(|x| !x.is_nan()),
                "{name} item {i}: NaN in the GLSL output {g:?}"
            );
            assert_eq!(
                (g.nonfinite_weights, g.candidates_dropped),
                (counts.nonfinite_weights, counts.candidates_dropped),
                "{name} item {i}: counters"
            );
            dropped += counts.candidates_dropped as usize;
            // The GLSL resampler starts from reservoir_empty's record.
            let record = record.unwrap_or(PathRecord {
                rc_triangle: NO_HIT,
                rc_next_triangle: NO_HIT,
                ..Default::default()
            });
            match agrees(g, &record, s.weight_sum, w, s.chosen_lost, s.expected) {
                Some(worst) => {
                    chosen += (s.weight_sum > 0.0) as usize;
                    beyond_1e4 += (worst > 1e-4) as usize;
                }
                None => {
                    eprintln!(
                        "{name} item {i}: GLSL {g:?}\n  Rust {record:?} sum {} W {w} expected {}",
                        s.weight_sum, s.expected
                    );
                    differ += 1;
                }
            }
        }
        eprintln!(
            "{name}: {chosen} chosen paths agree, {beyond_1e4} beyond 1e-4, {differ} differ, {dropped} dropped, {cut} changed by Russian roulette, of {ITEMS}"
        );
        assert_eq!(
            cut > ITEMS / 20,
            russian_roulette,
            "{name}: {cut} paths changed by Russian roulette"
        );
        assert!(differ * 1000 <= ITEMS, "{name}: {differ} items differ");
        assert!(beyond_1e4 * 100 <= ITEMS, "{name}: {beyond_1e4} items beyond 1e-4");
        assert!(chosen > ITEMS / 4, "{name}: only {chosen} items chose a path");
    }
    crate::common::assert_clean(&ctx);
}

/// ITEMS primary hits of camera 0 at random points of an IMAGE x IMAGE image, each with its
/// own path seed (pixels that see nothing are drawn again).
fn primary_hits(scene: &Scene) -> Vec<(Vertex, u32)> {
    let mut rng = TestRng(808);
    let mut items: Vec<(Vertex, u32)> = Vec::with_capacity(ITEMS);
    while items.len() < ITEMS {
        let (px, py) = (rng.uniform() * IMAGE as f32, rng.uniform() * IMAGE as f32);
        let seed = rng.next_u64() as u32;
        if let Some(y1) = primary_hit(scene, 0, px, py, IMAGE, IMAGE) {
            items.push((y1, seed));
        }
    }
    items
}

/// Runs oracle/candidates_oracle.comp over `items`.
fn run_candidates_oracle(
    ctx: &std::sync::Arc<restir_pt::vk::Context>,
    scene: &Scene,
    items: &[(Vertex, u32)],
    params: &ShiftParams,
    scale: f32,
    russian_roulette: bool,
) -> Vec<CandidatesOracleOutput> {
    let camera = scene.cameras[0].position;
    let scene_gpu = SceneGpu::upload(ctx, scene).unwrap();
    let frame = Buffer::new(
        ctx,
        "params",
        std::mem::size_of::<restir_pt::gpu_types::FrameParams>() as u64,
        BufferUsage::Params,
    )
    .unwrap();
    let settings = RenderSettings {
        russian_roulette,
        ..Default::default()
    };
    frame.write(&[settings.frame_params(scene_gpu.info())]).unwrap();
    let kernel_params = CandidatesOracleParams {
        max_path_length: MAX_PATH_LENGTH as u32,
        roughness_threshold: params.roughness_threshold,
        distance_threshold: params.distance_threshold,
        mis_scale: scale,
    };
    let inputs: Vec<CandidatesOracleInput> = items
        .iter()
        .map(|(y1, seed)| CandidatesOracleInput {
            primary_hit: y1.pos.to_array(),
            triangle: y1.triangle,
            camera: camera.to_array(),
            seed: *seed,
        })
        .collect();
    crate::common::run_scene_oracle(
        ctx,
        &scene_gpu,
        &frame,
        "oracle/candidates_oracle.comp",
        &[],
        &[
            ("Params", bytemuck::bytes_of(&kernel_params)),
            ("Items", bytemuck::cast_slice(&inputs)),
        ],
        ITEMS * std::mem::size_of::<CandidatesOracleOutput>() / 4,
        ITEMS as u32,
    )
}
