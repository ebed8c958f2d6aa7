//! The shift mappings' Rust reference (crates/shading/src/shift/) on the bundled scenes: round trips,
//! reciprocal Jacobians, finite-difference Jacobians, injectivity and clean failure; the GLSL
//! twins against it are in shift_oracle.rs.
//! `cargo test --release shift` runs them all.

use std::collections::HashSet;

use glam::Vec3;
use restir_pt::shading::path_record::{
    record_length, record_lobe, record_nee_directional, record_nee_end, record_reconnection_index, PathRecord,
};
use restir_pt::shading::shift::*;

use crate::fixtures::normal_mapped_scene::{scene_named, NORMAL_MAPPED_BOX};
use crate::fixtures::shift_cases::{cases, inverse, shift, Kind, BASE_PATHS, IMAGE};

/// Relative closeness of record values that the round trip recomputes.
fn near(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1e-30)
}

/// Shifts every case and checks, for every valid shift: finite positive Jacobian and finite
/// contribution; the inverse is valid and returns the base record (its cached terms within
/// 1e-4, its contribution within 1e-3) and the base's vertices (within 1e-4 of the scene's
/// extent); the Jacobians are reciprocal within 1e-3. Failed shifts carry no value.
#[derive(Default, Debug)]
struct Stats {
    valid: usize,
    failed: usize,
}

fn check_round_trips(name: &str, kind: Kind) -> Stats {
    let scene = scene_named(name);
    let params = ShiftParams::for_scene(&scene);
    let camera = scene.cameras[0].position;
    let tol = 1e-4 * scene.extent();
    let mut stats = Stats::default();
    let cases = cases(&scene, 1234, BASE_PATHS);
    for (i, case) in cases.iter().enumerate() {
        let y = shift(kind, &scene, &params, &case.record, camera, case.y1);
        if !y.valid {
            assert!(
                y.jacobian == 0.0 && y.contribution == Vec3::ZERO && y.vertices.is_empty(),
                "{name} {kind:?} case {i}: a failed shift carries a value"
            );
            stats.failed += 1;
            continue;
        }
        stats.valid += 1;
        assert!(
            y.jacobian.is_finite() && y.jacobian > 0.0 && y.contribution.is_finite(),
            "{name} {kind:?} case {i}: {y:?}"
        );
        let back = inverse(kind, &scene, &params, &y.record, camera, case.base.vertices[0]);
        assert!(back.valid, "{name} {kind:?} case {i}: the inverse shift failed on a shifted path");
        let (a, b) = (&back.record, &case.record);
        assert_eq!(
            (a.seed, a.info, a.lobes, a.rc_triangle, a.rc_next_triangle, a.rc_pos, a.rc_next),
            (b.seed, b.info, b.lobes, b.rc_triangle, b.rc_next_triangle, b.rc_pos, b.rc_next),
            "{name} {kind:?} case {i}: record"
        );
        for (what, x, z) in [
            ("rc_pdf", a.rc_pdf, b.rc_pdf),
            ("rc_geometry", a.rc_geometry, b.rc_geometry),
            ("rc_pdf_after", a.rc_pdf_after, b.rc_pdf_after),
        ] {
            assert!(near(x, z, 1e-4), "{name} {kind:?} case {i}: {what} {x} vs {z}");
        }
        for c in 0..3 {
            assert!(
                near(a.contribution[c], b.contribution[c], 1e-3),
                "{name} {kind:?} case {i}: contribution {:?} vs {:?}",
                a.contribution,
                b.contribution
            );
        }
        for (v, x) in back.vertices.iter().zip(&case.base.vertices) {
            assert!(
                v.pos.distance(x.pos) <= tol,
                "{name} {kind:?} case {i}: round trip moved a vertex {} -> {}",
                x.pos,
                v.pos
            );
        }
        let product = y.jacobian * back.jacobian;
        assert!((product - 1.0).abs() <= 1e-3, "{name} {kind:?} case {i}: |T'| |T^-1'| = {product}");
    }
    eprintln!("{name} {kind:?}: {} valid, {} failed of {}", stats.valid, stats.failed, cases.len());
    stats
}

fn round_trip_all_scenes(kind: Kind) {
    for name in [
        "cornell",
        "cornell-glossy",
        "glass",
        "near-field",
        "mirror",
        "veach-door",
        "env-ground",
        NORMAL_MAPPED_BOX,
    ] {
        let stats = check_round_trips(name, kind);
        // Every shift must work somewhere in the diffuse Cornell box.
        if name == "cornell" {
            assert!(
                stats.valid > BASE_PATHS / 10,
                "{kind:?} is almost never valid in the Cornell box: {stats:?}"
            );
        }
    }
}

#[test]
fn shift_reconnection_round_trip_and_jacobian_reciprocal() {
    round_trip_all_scenes(Kind::Reconnection);
}

#[test]
fn shift_random_replay_round_trip_and_jacobian_reciprocal() {
    round_trip_all_scenes(Kind::RandomReplay);
}

#[test]
fn shift_hybrid_round_trip_and_jacobian_reciprocal() {
    round_trip_all_scenes(Kind::Hybrid);
}

/// Within a batch shifted into one target pixel, distinct base paths give distinct shifted paths.
fn check_injective(kind: Kind) {
    for name in ["cornell", "cornell-glossy", "near-field", NORMAL_MAPPED_BOX] {
        let scene = scene_named(name);
        let params = ShiftParams::for_scene(&scene);
        let camera = scene.cameras[0].position;
        let y1 = primary_hit(&scene, 0, 31.5, 40.5, IMAGE, IMAGE).unwrap();
        let mut inputs = HashSet::new();
        let mut outputs = HashSet::new();
        for case in cases(&scene, 99, 3000) {
            // A record and the vertices its shift rebuilt determine the whole path.
            let key = |record: &PathRecord, vertices: &[Vertex]| {
                let positions: Vec<[u32; 3]> = vertices.iter().map(|v| v.pos.to_array().map(f32::to_bits)).collect();
                (
                    record.seed,
                    record.info,
                    record.rc_pos.map(f32::to_bits),
                    record.rc_next.map(f32::to_bits),
                    positions,
                )
            };
            if !inputs.insert(key(&case.record, &case.base.vertices)) {
                continue;
            }
            let y = shift(kind, &scene, &params, &case.record, camera, y1);
            if y.valid {
                assert!(
                    outputs.insert(key(&y.record, &y.vertices)),
                    "{name} {kind:?}: two distinct base paths shifted to the same path"
                );
            }
        }
        assert!(!outputs.is_empty() || kind != Kind::Hybrid, "{name} {kind:?}: nothing shifted");
    }
}

#[test]
fn shift_reconnection_injective() {
    check_injective(Kind::Reconnection);
}

#[test]
fn shift_random_replay_injective() {
    check_injective(Kind::RandomReplay);
}

#[test]
fn shift_hybrid_injective() {
    check_injective(Kind::Hybrid);
}

/// Where reconnection cannot work it fails, cleanly: delta vertices (mirror, glass), too-short
/// connections (near-field). Random replay fails where lengths or lobes differ.
#[test]
fn shift_fails_cleanly_where_it_must() {
    for (name, kind, min_failure_share) in [
        ("mirror", Kind::Reconnection, 0.05),
        ("glass", Kind::Reconnection, 0.05),
        ("near-field", Kind::Reconnection, 0.01),
        ("cornell-glossy", Kind::RandomReplay, 0.05),
        ("veach-door", Kind::RandomReplay, 0.2),
    ] {
        let stats = check_round_trips(name, kind);
        let share = stats.failed as f64 / (stats.valid + stats.failed) as f64;
        assert!(share >= min_failure_share, "{name} {kind:?}: only {:.1}% failed", 100.0 * share);
    }
}

/// Solid angle of the triangle (a, b, c) seen from q (Van Oosterom and Strackee 1983).
fn solid_angle(q: glam::DVec3, a: glam::DVec3, b: glam::DVec3, c: glam::DVec3) -> f64 {
    let (a, b, c) = (a - q, b - q, c - q);
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let numerator = a.dot(b.cross(c)).abs();
    let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * numerator.atan2(denominator)
}

/// The analytic Jacobian of each valid reconnecting shift equals a finite-difference one: the
/// solid angle a tiny triangle around x_r subtends from y_{r-1} over the one from x_{r-1}
/// (the measure change of the reconnection), times the same pdf ratios. Within 1e-2 relative.
fn check_jacobian_finite_difference(kind: Kind) {
    for name in ["cornell", "cornell-glossy", "glass", "near-field", NORMAL_MAPPED_BOX] {
        let scene = scene_named(name);
        let params = ShiftParams::for_scene(&scene);
        let camera = scene.cameras[0].position;
        let h = 1e-5 * scene.extent() as f64;
        let mut checked = 0;
        for (i, case) in cases(&scene, 777, 2000).iter().enumerate() {
            let y = shift(kind, &scene, &params, &case.record, camera, case.y1);
            let Some(terms) = y.reconnection else {
                continue;
            };
            let r = reconnection_index(&scene, &case.base, &params).unwrap();
            let x_r = case.base.vertices[r - 1];
            if vertex_is_escaped(&x_r) {
                continue;
            }
            let p = x_r.pos.as_dvec3();
            let (t1, t2) = restir_pt::shading::sampling::build_onb(x_r.normal);
            let (a, b) = (p + h * t1.as_dvec3(), p + h * t2.as_dvec3());
            let omega_y = solid_angle(y.vertices[r - 2].pos.as_dvec3(), p, a, b);
            let omega_x = solid_angle(case.base.vertices[r - 2].pos.as_dvec3(), p, a, b);
            let finite_difference = omega_y / omega_x * (terms.pdf_y / terms.pdf_x) as f64 * (terms.pdf_after_y / terms.pdf_after_x) as f64;
            let analytic = y.jacobian as f64;
            assert!(
                (finite_difference - analytic).abs() <= 1e-2 * analytic,
                "{name} {kind:?} case {i}: analytic {analytic} vs finite difference {finite_difference}"
            );
            checked += 1;
        }
        assert!(checked > 100, "{name} {kind:?}: only {checked} reconnections checked");
    }
}

#[test]
fn shift_reconnection_jacobian_finite_difference() {
    check_jacobian_finite_difference(Kind::Reconnection);
}

#[test]
fn shift_hybrid_jacobian_finite_difference() {
    check_jacobian_finite_difference(Kind::Hybrid);
}

#[test]
fn shift_path_record_is_80_bytes_and_packs_its_fields() {
    assert_eq!(std::mem::size_of::<PathRecord>(), 80);
    let info = PathRecord::pack_info(6, Some(3), true, 2);
    let lobes = PathRecord::pack_lobes(&[1, 2, 4 | 8, 16 | 4, 0]);
    let record = PathRecord {
        info,
        lobes,
        ..Default::default()
    };
    assert_eq!(
        (
            record_length(&record),
            record_reconnection_index(&record),
            record_nee_end(&record),
            record_nee_directional(&record)
        ),
        (6, Some(3), true, 2)
    );
    assert_eq!((1..=5).map(|i| record_lobe(&record, i)).collect::<Vec<_>>(), vec![1, 2, 12, 20, 0]);
    let unconnected = PathRecord {
        info: PathRecord::pack_info(2, None, false, 0),
        ..Default::default()
    };
    assert_eq!(record_reconnection_index(&unconnected), None);
}

/// The reconnection y1 -> x2 checked from the geometry alone, with the public BVH and BSDF:
/// which of the failure causes the issue names apply.
#[derive(Default, Debug)]
struct Causes {
    delta: usize,
    occluded: usize,
    too_short: usize,
    back_facing: usize,
}

#[test]
fn shift_fails_cleanly_on_delta_occluded_short_back_facing_and_diverging_paths() {
    use restir_pt::shading::bsdf::{bsdf_eval_pdf, has_specular_layer, lobe_weights};
    use restir_pt::shading::bvh::trace_occluded;
    use restir_pt::shading::ray_offset::offset_ray_origin;
    let mut total = Causes::default();
    let mut diverged = 0;
    for name in ["mirror", "glass", "near-field", "cornell", "veach-door"] {
        let scene = scene_named(name);
        let params = ShiftParams::for_scene(&scene);
        let camera = scene.cameras[0].position;
        for case in cases(&scene, 555, 4000) {
            let (y1, x1) = (case.y1, case.base.vertices[0]);
            let material = |v: &Vertex| scene.materials[scene.triangles[v.triangle as usize].material as usize];
            let is_delta = |v: &Vertex| {
                let m = material(v);
                let (_, w_c, w_t) = lobe_weights(&m);
                (w_c > 0.0 || w_t > 0.0 || has_specular_layer(&m)) && m.roughness * m.roughness < restir_pt::shading::bsdf::DELTA_ALPHA
            };
            let check = |result: &ShiftResult, what: &str| {
                assert!(
                    !result.valid && result.jacobian == 0.0 && result.contribution == Vec3::ZERO,
                    "{name}: {what} must fail cleanly: {result:?}"
                );
            };
            let rec = shift_reconnection(&scene, &params, &case.record, camera, y1);
            if case.base.length() >= 2 && !vertex_is_escaped(&case.base.vertices[1]) {
                let x2 = case.base.vertices[1];
                let d = x2.pos - y1.pos;
                let dir = d.normalize();
                let facing = |n: Vec3, v: Vec3| if v.dot(n) > 0.0 { n } else { -n };
                let origin = offset_ray_origin(y1.pos, facing(y1.normal, dir), &scene.triangles[y1.triangle as usize]);
                let target = offset_ray_origin(x2.pos, facing(x2.normal, -dir), &scene.triangles[x2.triangle as usize]);
                let wo = (camera - y1.pos).normalize();
                let (f, _) = bsdf_eval_pdf(&material(&y1), y1.normal, y1.normal, wo, dir);
                if is_delta(&y1) || is_delta(&x1) || is_delta(&x2) {
                    check(&rec, "a reconnection at a delta vertex");
                    total.delta += 1;
                } else if d.length() < params.distance_threshold {
                    check(&rec, "a too-short reconnection");
                    total.too_short += 1;
                } else if trace_occluded(&scene.nodes, &scene.triangles, origin, target - origin, 1.0 - 1e-4) {
                    check(&rec, "an occluded reconnection");
                    total.occluded += 1;
                } else if f.max_element() == 0.0 {
                    check(&rec, "a back-facing reconnection");
                    total.back_facing += 1;
                }
            }
            // A replay whose regenerated path has another length or other lobes must fail.
            let replayed = generate_path(
                &scene,
                camera,
                y1,
                case.base.seed,
                case.base.length(),
                case.base.nee_end,
                case.base.nee_directional,
            );
            if replayed.as_ref().is_none_or(|y| y.lobes != case.base.lobes) {
                check(
                    &shift_random_replay(&scene, &params, &case.record, camera, y1),
                    "a diverging replay",
                );
                diverged += 1;
            }
        }
    }
    eprintln!("clean failures: {total:?}, {diverged} diverging replays");
    assert!(
        total.delta > 0 && total.occluded > 0 && total.too_short > 0 && total.back_facing > 0 && diverged > 0,
        "{total:?}, {diverged}"
    );
}
