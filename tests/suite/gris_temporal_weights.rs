//! The generalized balance heuristic on temporal inputs as the reuse kernels form them
//! (`resample_inputs` in glsl/restir_reuse.glsl): is m_0(y) + m_1(y) = 1 for every shifted
//! history sample y?
//!
//! For the history's own sample y = T_1(x_1) the kernel does not shift y back: it takes
//! p̂_{<-1}(y) = p̂_1(x_1) / |T_1'(x_1)| from the stored target and the forward Jacobian (the
//! shortcut of docs/restir.md). The canonical input's weight at the same y needs p̂_{<-1}(y) as
//! the inverse shift gives it, p̂_1(T_1^{-1}(y)) |(T_1^{-1})'(y)|. The two weights sum to one
//! exactly when the two values agree; this test computes both with the Rust twins of the shifts
//! (`inverse_reconnection`, `inverse_random_replay`, `inverse_hybrid`, `stream_path_candidates`)
//! on recorded temporal inputs: a pixel's initial reservoir seen from camera 0 (the history) and
//! the canonical pixel of camera 1 (the camera path's next pose), in the generated rough-metal
//! scene, with the confidence weights the temporal pass uses (c_0 = 1; c_1 = 1 and the M-cap 20).
//! Under an unmoved camera the shift is the identity, both values are the stored p̂ and the
//! weights are c_i / Σ c_j.

use glam::Vec3;
use restir_pt::render::ShiftKind;
use restir_pt::scene::Scene;
use restir_pt::shading::candidates::stream_path_candidates;
use restir_pt::shading::gris::{resampler_begin, resampler_finish, target_function};
use restir_pt::shading::path_record::{PathRecord, MAX_PATH_LENGTH};
use restir_pt::shading::rng::{path_seed, rng_uniform4, STREAM_CAMERA};
use restir_pt::shading::shift::{
    inverse_hybrid, inverse_random_replay, inverse_reconnection, primary_hit, ShiftParams, ShiftResult, Vertex,
};

use crate::fixtures::metal_box_scene::{metal_box, MetalBoxLights};

const SIDE: u32 = 64;
/// The temporal pass's confidence weights: the canonical M of one candidate; the history's
/// from its second frame (1) up to the M-cap (20 times the canonical M).
const C0: f64 = 1.0;
const C1: [f64; 2] = [1.0, 20.0];

fn inverse(kind: ShiftKind, scene: &Scene, params: &ShiftParams, record: &PathRecord, camera: Vec3, x1: Vertex) -> ShiftResult {
    match kind {
        ShiftKind::Reconnection => inverse_reconnection(scene, params, record, camera, x1),
        ShiftKind::Replay => inverse_random_replay(scene, params, record, camera, x1),
        ShiftKind::Hybrid => inverse_hybrid(scene, params, record, camera, x1),
    }
}

/// The primary vertex of a path with sub-pixel `offset` in `pixel` of camera `camera`.
fn domain_primary(scene: &Scene, camera: usize, pixel: (u32, u32), offset: glam::Vec4) -> Option<Vertex> {
    primary_hit(scene, camera, pixel.0 as f32 + offset.x, pixel.1 as f32 + offset.y, SIDE, SIDE)
}

#[test]
fn gbh_weights_of_temporal_inputs_sum_to_one() {
    let scene = metal_box(0.3, MetalBoxLights::PointSpotSun);
    let params = ShiftParams::for_scene(&scene);
    let (history_camera, canonical_camera) = (scene.cameras[0].position, scene.cameras[1].position);
    for kind in [ShiftKind::Reconnection, ShiftKind::Replay, ShiftKind::Hybrid] {
        let (mut shifted, mut worst, mut beyond) = (0usize, 0.0f64, 0usize);
        for pixel_index in 0..SIDE * SIDE {
            let pixel = (pixel_index % SIDE, pixel_index / SIDE);
            let seed = path_seed(pixel_index, 0, 4242);
            let offset = rng_uniform4(seed, 0, STREAM_CAMERA);
            // The history: the pixel's initial reservoir seen from camera 0.
            let Some(x1_primary) = domain_primary(&scene, 0, pixel, offset) else {
                continue;
            };
            let mut s = resampler_begin();
            stream_path_candidates(
                &scene,
                &mut s,
                history_camera,
                x1_primary,
                seed,
                MAX_PATH_LENGTH,
                &params,
                1.0,
                true,
            );
            let (Some(x1), w, _) = resampler_finish(&s) else { continue };
            if w <= 0.0 {
                continue;
            }
            // The same pixel of camera 1 is the canonical domain (the camera moved by 0.05).
            let Some(canonical_primary) = domain_primary(&scene, 1, pixel, offset) else {
                continue;
            };
            let forward = inverse(kind, &scene, &params, &x1, canonical_camera, canonical_primary);
            if !forward.valid {
                continue;
            }
            let shortcut = target_function(x1.contribution.into()) as f64 / forward.jacobian as f64;
            let back = inverse(kind, &scene, &params, &forward.record, history_camera, x1_primary);
            let explicit = if back.valid {
                target_function(back.contribution) as f64 * back.jacobian as f64
            } else {
                0.0
            };
            let p = target_function(forward.contribution) as f64;
            let sum = |c1: f64| c1 * shortcut / (C0 * p + c1 * shortcut) + C0 * p / (C0 * p + c1 * explicit);
            let error = C1.iter().map(|&c1| (sum(c1) - 1.0).abs()).fold(0.0, f64::max);
            shifted += 1;
            worst = worst.max(error);
            beyond += (error > 1e-3) as usize;
        }
        println!("{kind:?}: {shifted} shifted history samples, largest |m_0 + m_1 - 1| {worst:.2e}, {beyond} beyond 1e-3");
        assert!(shifted > 300, "{kind:?}: only {shifted} history samples shifted");
        assert!(
            beyond * 1000 <= shifted,
            "{kind:?}: {beyond} of {shifted} weight sums beyond 1e-3 (largest {worst:.2e})"
        );
    }
}
