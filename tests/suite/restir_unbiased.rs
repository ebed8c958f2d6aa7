//! ReSTIR PT on the GPU: unbiasedness of every shift and MIS against a path-traced reference.
//!
//! Unbiasedness: on 64x64 images with a moving camera (cameras 0, 1, 2: initial candidates,
//! temporal reuse with reprojection and spatial reuse), the mean of independent renders (fresh
//! seeds, cleared history; 32 on cornell, more on the harder scenes) is compared with a
//! 4096-spp path-traced reference of camera 2: total energy within 1%, and per 8x8 block a
//! two-sided Welch t-test at the 1% level. A configuration fails if its energy is off or more
//! blocks fail than chance allows at 1% (at most 3 of 64; see max_failing_blocks), or, on
//! scenes with a path-tracer control, than the unbiased path tracer fails with as many renders;
//! the pass rate is printed against the 99% bar.

use restir_pt::render::{History, RestirSettings, ReuseMis, ShiftKind};
use restir_pt::scene::Scene;

use crate::fixtures::normal_mapped_scene::NORMAL_MAPPED_BOX;
use crate::fixtures::unbiasedness::*;

// The default settings (one spatial neighbour) in motion, with every shift and MIS. 128 chains:
// block means of few chains are skewed (a rare bright path lifts a few chains; most fall below
// the mean), and Welch's t-test then fails blocks at negative t in every configuration at once
// (the configurations share seeds). With 32 chains three or four blocks failed at t = -3 to -4;
// with 64, once Russian roulette made the initial candidates' tails heavier, two to four (energy
// 0.997-0.998, standard error 0.0024); 256 chains of one configuration gave energy 1.0007
// (standard error 0.0013) and one failing block. A bias would fail more blocks as the standard
// errors shrink, not fewer.
#[test]
fn restir_unbiased_cornell() {
    check_unbiased(Unbiasedness {
        scene: "cornell",
        renders: 4 * RENDERS,
        candidates: 1,
        reservoirs: 1,
        path_tracer_control: false,
        static_camera: false,
        frames: FRAMES,
        configurations: EVERY_CONFIGURATION,
        base: RestirSettings::default(),
    });
}

// A static camera keeps each pixel's domain from frame to frame: temporal reuse takes the
// previous reservoir unshifted (same_domain in glsl/restir_reuse.glsl), and only spatial reuse
// shifts. Two configurations keep the test's time down; the identity is the same for all. Two
// reservoirs per pixel check that each keeps to its own layer's history and neighbours, and
// three neighbours (the default has one) the MIS weights of several inputs from other domains.
#[test]
fn restir_unbiased_cornell_static_camera() {
    check_unbiased(Unbiasedness {
        scene: "cornell",
        renders: RENDERS,
        candidates: 1,
        reservoirs: 2,
        path_tracer_control: false,
        static_camera: true,
        frames: FRAMES,
        configurations: &[
            (ShiftKind::Reconnection, ReuseMis::GeneralizedBalance),
            (ShiftKind::Hybrid, ReuseMis::Pairwise),
        ],
        base: RestirSettings {
            spatial: 3,
            ..Default::default()
        },
    });
}

// The next frame's history is the reservoir before spatial reuse (ReSTIR GI's separate temporal
// and spatial reservoirs) under a moving camera, with two spatial rounds, so that the second
// round writes the previous frame's slot after the temporal pass has read it (frame_plan);
// three neighbours per round, so that each sample is inverse-shifted into several other domains.
#[test]
fn restir_unbiased_cornell_temporal_history() {
    check_unbiased(Unbiasedness {
        scene: "cornell",
        renders: RENDERS,
        candidates: 1,
        reservoirs: 1,
        path_tracer_control: false,
        static_camera: false,
        frames: FRAMES,
        configurations: &[
            (ShiftKind::Hybrid, ReuseMis::GeneralizedBalance),
            (ShiftKind::Reconnection, ReuseMis::Pairwise),
        ],
        base: RestirSettings {
            history: History::Temporal,
            spatial: 3,
            rounds: 2,
            ..Default::default()
        },
    });
}

// Shading normals (interpolated vertex normals and normal maps) in the candidates, every shift and
// its inverse, and the path tracer: one target function, so reuse stays unbiased (a BSDF that saw
// the geometric normal on one side only would shift paths between two integrands). The scene
// (normal_mapped_scene.rs) has a glossy sphere below the reconnection threshold, whose rare
// large samples call for the path-tracer control.
#[test]
fn restir_unbiased_normal_mapped_box() {
    check_unbiased(Unbiasedness {
        scene: NORMAL_MAPPED_BOX,
        renders: RENDERS,
        candidates: 1,
        reservoirs: 1,
        path_tracer_control: true,
        static_camera: false,
        frames: FRAMES,
        configurations: EVERY_CONFIGURATION,
        base: RestirSettings::default(),
    });
}

// The glossy spheres (roughness 0.05 and 0.1) reflect the small light through rare, large
// samples. With 32 renders the unbiased path tracer itself fails 6 to 10 of 64 blocks (1 to 4
// spp, all too dark), 5 with 128 and 2 with 512; hence the path-tracer control. ReSTIR PT's
// renders are heavier-tailed still: with 128 renders and inputs chosen from centre surfaces,
// two configurations failed 4 blocks each, every t negative (docs/lab-notebook.md). Russian
// roulette in the initial candidates (survival weights 1/q) makes them heavier-tailed again:
// with 384 renders three configurations failed 4 or 5 blocks at unchanged energy, with 768
// all six pass (63 or 64 of 64 blocks, energy 1.0002 to 1.0004, standard error 0.0008).
#[test]
#[ignore = "minutes; run with --ignored (docs/restir.md)"]
fn restir_unbiased_cornell_glossy() {
    check_unbiased(Unbiasedness {
        scene: "cornell-glossy",
        renders: 768,
        candidates: 1,
        reservoirs: 1,
        path_tracer_control: true,
        static_camera: false,
        frames: FRAMES,
        configurations: EVERY_CONFIGURATION,
        base: RestirSettings::default(),
    });
}

// Light through the door gap makes whole-image energy vary between renders by 12.5% with one
// initial path per pixel (measured over 384 renders: energy 1.0018, standard error 0.0064),
// and by 14.5% for the path tracer at 1 spp; resolving 1% would take over a thousand renders
// per configuration. Eight initial paths bring it to 7.7%, so 256 renders measure energy to
// about 0.6%.
#[test]
#[ignore = "minutes; run with --ignored (docs/restir.md)"]
fn restir_unbiased_veach_door() {
    check_unbiased(Unbiasedness {
        scene: "veach-door",
        renders: 256,
        candidates: 8,
        reservoirs: 1,
        path_tracer_control: true,
        static_camera: false,
        frames: FRAMES,
        configurations: EVERY_CONFIGURATION,
        base: RestirSettings::default(),
    });
}

/// The Cornell box whose light shines through a screen cut out by an alpha mask (half its
/// texels below the cutoff), as ReSTIR PT's unbiasedness tests build it.
fn alpha_masked_cornell() -> Scene {
    let checker = crate::fixtures::alpha_images::png_with_alphas([0.8, 0.4, 0.4, 0.8]);
    let text = restir_pt::scene::bundled_scenes::cornell_alpha_screen(&checker);
    let scene = restir_pt::scene::load_scene_from_bytes(text.as_bytes(), None, std::path::Path::new("cornell-alpha.gltf")).unwrap();
    assert!(scene.alpha().is_some(), "the screen must be alpha-tested");
    scene
}

fn check_alpha_masked_cornell(configurations: &'static [(ShiftKind, ReuseMis)]) {
    check_unbiased_on(
        Unbiasedness {
            scene: "cornell with a masked screen",
            renders: RENDERS,
            candidates: 1,
            reservoirs: 1,
            path_tracer_control: false,
            static_camera: false,
            frames: FRAMES,
            configurations,
            base: RestirSettings::default(),
        },
        &alpha_masked_cornell(),
    );
}

// Every shift's vertices and visibility tests must see the same holes in the screen. The hybrid
// shift reconnects and replays (83 s run alone on the 2-core machine, with its own 4096-spp
// reference of this alpha-tested scene); the other shifts are in the second test, ignored for
// its time (234 s).
#[test]
fn restir_unbiased_alpha_masked_cornell() {
    check_alpha_masked_cornell(&[(ShiftKind::Hybrid, ReuseMis::GeneralizedBalance)]);
}

#[test]
#[ignore = "minutes; run with --ignored (docs/restir.md)"]
fn restir_unbiased_alpha_masked_cornell_every_shift() {
    check_alpha_masked_cornell(EVERY_CONFIGURATION);
}

/// One configuration of each shift on the scene of a hundred small lights and a sun, where every
/// shift recomputes the light tree's selection probability at the vertices it moves
/// (docs/light-sampling.md); four initial paths per pixel keep the many lights' noise to a
/// level 64 renders resolve.
const EVERY_SHIFT: &[(ShiftKind, ReuseMis)] = &[
    (ShiftKind::Reconnection, ReuseMis::Pairwise),
    (ShiftKind::Replay, ReuseMis::GeneralizedBalance),
    (ShiftKind::Hybrid, ReuseMis::GeneralizedBalance),
];

#[test]
fn restir_unbiased_many_lights() {
    check_unbiased(Unbiasedness {
        scene: "many-lights",
        renders: 64,
        candidates: 4,
        reservoirs: 1,
        path_tracer_control: true,
        static_camera: false,
        frames: FRAMES,
        configurations: EVERY_SHIFT,
        base: RestirSettings::default(),
    });
}
