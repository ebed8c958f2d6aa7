//! GLSL `stream_path_candidates` (glsl/shading/candidates.glsl, the initial pass's candidates)
//! against its Rust twin `stream_path_candidates` (crates/shading/src/candidates.rs): one traced path
//! per item from a primary hit of camera 0 with its own seed, its light-ending prefixes streamed
//! into a fresh Resampler on both sides, with and without Russian roulette; the chosen record,
//! the weight sum, W, the expectation and the pass counters compared.

use glam::{Vec3, Vec4};
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

/// Whether the GLSL output `g` (8 vec4) agrees with the Rust result: the chosen record (header
/// exactly; cached terms, contribution within 1e-3), the weight sum, W and the expectation
/// within 1e-3 relative, the counters exactly. The largest relative difference of the sums.
fn agrees(g: &[Vec4], record: &PathRecord, weight_sum: f32, w: f32, lost: bool, expected: Vec3) -> Option<f32> {
    let header = [
        g[0].x.to_bits(),
        g[0].y.to_bits(),
        g[0].z.to_bits(),
        g[0].w.to_bits(),
        g[4].w.to_bits(),
    ];
    let r = record;
    if header != [r.seed, r.info, r.lobes, r.rc_triangle, r.rc_next_triangle] || (g[5].w != 0.0) != lost {
        return None;
    }
    let floats = [
        (g[1].w, r.rc_pdf),
        (g[2].w, r.rc_geometry),
        (g[3].w, r.rc_pdf_after),
        (g[4].x, r.contribution[0]),
        (g[4].y, r.contribution[1]),
        (g[4].z, r.contribution[2]),
        (g[5].x, weight_sum),
        (g[5].z, w),
        (g[6].x, expected.x),
        (g[6].y, expected.y),
        (g[6].z, expected.z),
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
        for (i, (y1, seed)) in items.iter().enumerate() {
            let g = &out[8 * i..8 * i + 8];
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
            // Float fields only: the record's uint fields travel as float bits.
            assert!(
                g[1..4].iter().chain(&g[5..]).all(|v| !v.is_nan()) && !g[4].truncate().is_nan(),
                "{name} item {i}: NaN in the GLSL output {g:?}"
            );
            assert_eq!(
                (g[7].x as u32, g[7].y as u32),
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

/// Runs oracle/candidates_oracle.comp over `items`: eight vec4s of results per item.
fn run_candidates_oracle(
    ctx: &std::sync::Arc<restir_pt::vk::Context>,
    scene: &Scene,
    items: &[(Vertex, u32)],
    params: &ShiftParams,
    scale: f32,
    russian_roulette: bool,
) -> Vec<Vec4> {
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
    let kernel_params = [
        MAX_PATH_LENGTH as u32,
        params.roughness_threshold.to_bits(),
        params.distance_threshold.to_bits(),
        scale.to_bits(),
    ];
    let inputs: Vec<Vec4> = items
        .iter()
        .flat_map(|(y1, seed)| [y1.pos.extend(f32::from_bits(y1.triangle)), camera.extend(f32::from_bits(*seed))])
        .collect();
    crate::common::run_scene_oracle(
        ctx,
        &scene_gpu,
        &frame,
        "oracle/candidates_oracle.comp",
        &[],
        &[
            ("Params", bytemuck::cast_slice(&kernel_params)),
            ("Items", bytemuck::cast_slice(&inputs)),
        ],
        ITEMS * 8 * 4,
        ITEMS as u32,
    )
}
