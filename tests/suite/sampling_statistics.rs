//! Statistical tests of the Rust samplers (the GLSL twins are tied to them by the oracle tests):
//! chi-square goodness of fit at the 1% level, and sample/pdf consistency.

use std::f64::consts::PI;

use glam::{Vec2, Vec3};
use restir_pt::gpu_types::NO_EMITTER;
use restir_pt::metrics::{mean, standard_error};
use restir_pt::shading::bsdf::{ggx_vndf_pdf, smith_g1};
use restir_pt::shading::bvh::intersect_triangle;
use restir_pt::shading::lights::sample_light;
use restir_pt::shading::sampling::{sample_cosine_hemisphere, sample_ggx_vndf, sample_triangle};

use crate::common::TestRng;
use crate::fixtures::statistics::{chi_square_critical_1pct, test_environment_map};

/// Pearson's statistic after pooling bins whose expected count is below 5; returns (chi2, dof).
fn chi_square(observed: &[f64], expected: &[f64]) -> (f64, usize) {
    let (mut chi2, mut bins) = (0.0, 0);
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < 5.0 {
            pool_o += o;
            pool_e += e;
        } else {
            chi2 += (o - e).powi(2) / e;
            bins += 1;
        }
    }
    if pool_e > 0.0 {
        chi2 += (pool_o - pool_e).powi(2) / pool_e.max(1e-9);
        bins += 1;
    }
    (chi2, bins - 1)
}

fn assert_fits(what: &str, observed: &[f64], expected: &[f64]) {
    let (chi2, dof) = chi_square(observed, expected);
    let critical = chi_square_critical_1pct(dof);
    assert!(chi2 < critical, "{what}: chi2 {chi2:.1} >= {critical:.1} ({dof} dof)");
}

const SAMPLES: usize = 1_000_000;

#[test]
fn sample_cosine_hemisphere_chi_square() {
    let (nt, np) = (10, 20);
    let mut observed = vec![0.0; nt * np];
    let mut r = TestRng(31);
    for _ in 0..SAMPLES {
        let w = sample_cosine_hemisphere(Vec2::new(r.uniform(), r.uniform()));
        let phi = (w.y.atan2(w.x) as f64 + 2.0 * PI) % (2.0 * PI);
        let (i, j) = (
            ((w.z as f64 * nt as f64) as usize).min(nt - 1),
            ((phi / (2.0 * PI) * np as f64) as usize).min(np - 1),
        );
        observed[i * np + j] += 1.0;
    }
    // P(cos in [a, b]) = b^2 - a^2, uniform in phi.
    let expected: Vec<f64> = (0..nt * np)
        .map(|k| {
            let (a, b) = ((k / np) as f64 / nt as f64, (k / np + 1) as f64 / nt as f64);
            SAMPLES as f64 * (b * b - a * a) / np as f64
        })
        .collect();
    assert_fits("cosine hemisphere", &observed, &expected);
}

#[test]
fn sample_ggx_vndf_chi_square() {
    let (nt, np) = (12, 16);
    for (alpha, theta_o) in [(0.1f32, 0.5f32), (0.5, 1.2), (0.9, 0.2)] {
        let wo = Vec3::new(theta_o.sin(), 0.0, theta_o.cos());
        let a2 = (alpha * alpha) as f64;
        // Bins are uniform in x = tan^2 / (alpha^2 + tan^2), GGX's own CDF variable, so that even
        // narrow lobes spread over many bins.
        let theta_of = |x: f64| (a2 * x / (1.0 - x).max(1e-300)).sqrt().atan();
        let mut observed = vec![0.0; nt * np];
        let mut r = TestRng(41);
        for _ in 0..SAMPLES {
            let h = sample_ggx_vndf(wo, alpha, Vec2::new(r.uniform(), r.uniform()));
            let t2 = ((1.0 - (h.z as f64).powi(2)).max(0.0)) / (h.z as f64).powi(2);
            let x = t2 / (a2 + t2);
            let phi = ((h.y as f64).atan2(h.x as f64) + 2.0 * PI) % (2.0 * PI);
            let (i, j) = (
                ((x * nt as f64) as usize).min(nt - 1),
                ((phi / (2.0 * PI) * np as f64) as usize).min(np - 1),
            );
            observed[i * np + j] += 1.0;
        }
        let sub = 12;
        let expected: Vec<f64> = (0..nt * np)
            .map(|k| {
                let (i, j) = (k / np, k % np);
                let (t0, t1) = (theta_of(i as f64 / nt as f64), theta_of((i + 1) as f64 / nt as f64).min(PI / 2.0));
                let (p0, p1) = (2.0 * PI * j as f64 / np as f64, 2.0 * PI * (j + 1) as f64 / np as f64);
                let mut sum = 0.0;
                for a in 0..sub {
                    for b in 0..sub {
                        let theta = t0 + (t1 - t0) * (a as f64 + 0.5) / sub as f64;
                        let phi = p0 + (p1 - p0) * (b as f64 + 0.5) / sub as f64;
                        let h = Vec3::new(
                            (theta.sin() * phi.cos()) as f32,
                            (theta.sin() * phi.sin()) as f32,
                            theta.cos() as f32,
                        );
                        sum += ggx_vndf_pdf(wo, h, alpha) as f64 * theta.sin();
                    }
                }
                SAMPLES as f64 * sum * (t1 - t0) * (p1 - p0) / (sub * sub) as f64
            })
            .collect();
        let total: f64 = expected.iter().sum::<f64>() / SAMPLES as f64;
        assert!(
            (total - 1.0).abs() < 2e-3,
            "alpha {alpha}: VNDF integrates to {total}, G1 = {}",
            smith_g1(wo, alpha)
        );
        assert_fits(&format!("GGX VNDF alpha {alpha} theta_o {theta_o}"), &observed, &expected);
    }
}

#[test]
fn sample_triangle_chi_square() {
    let (na, nb) = (10, 10);
    let mut observed = vec![0.0; na * nb];
    let mut r = TestRng(51);
    for _ in 0..SAMPLES {
        let b = sample_triangle(Vec2::new(r.uniform(), r.uniform()));
        // (1 - b1)^2 and b2 / (1 - b1) are both uniform for area-uniform points.
        let x = (1.0 - b.x as f64).powi(2);
        let y = b.y as f64 / (1.0 - b.x as f64).max(1e-12);
        observed[((x * na as f64) as usize).min(na - 1) * nb + ((y * nb as f64) as usize).min(nb - 1)] += 1.0;
    }
    let expected = vec![SAMPLES as f64 / (na * nb) as f64; na * nb];
    assert_fits("triangle area sampling", &observed, &expected);
}

/// Light selection (the light tree's descent; directional lights are not drawn) at several
/// shading points against its own pmf, `light_select_pmf`, which sums to at most 1 over the
/// lights (the rest: descents where no light below can reach p): chi-square at the 1% level
/// per point.
#[test]
fn light_selection_chi_square_follows_its_pmf() {
    use restir_pt::shading::light_tree::{light_select, light_select_pmf};
    let scene = crate::fixtures::random_scenes::random_scene_with_punctual_lights(12);
    assert!(scene.directional_count == 1 && scene.light_nodes.len() > 200);
    // Directional lights are not drawn: NEE takes each of them at every vertex, with
    // probability 1, beside the light drawn from the tree.
    let n = scene.emitters.len() - scene.directional_count as usize;
    for row in n..scene.emitters.len() {
        assert_eq!(light_select_pmf(&scene, Vec3::ZERO, Vec3::Y, row as u32), 1.0);
    }
    let keep = 1.0 - scene.env_select_prob as f64;
    let mut r = TestRng(61);
    for (p, normal) in [
        (Vec3::new(0.3, -0.2, 0.1), Vec3::Y),
        (Vec3::new(-4.0, 4.5, 2.0), Vec3::new(0.6, 0.0, 0.8)),
        (Vec3::new(6.0, 0.0, -6.0), -Vec3::X),
    ] {
        // The last bin: descents that end where no child can reach p (pbrt-v4 fails them too).
        let mut observed = vec![0.0; n + 1];
        for _ in 0..SAMPLES / 2 {
            let (row, pmf) = light_select(&scene, p, normal, r.uniform());
            assert_eq!(row == NO_EMITTER, pmf == 0.0, "a light drawn with probability 0 at {p}");
            assert!(row == NO_EMITTER || (row as usize) < n, "a directional light drawn at {p}");
            observed[(row as usize).min(n)] += 1.0;
        }
        let mut pmf: Vec<f64> = (0..n as u32)
            .map(|row| light_select_pmf(&scene, p, normal, row) as f64 / keep)
            .collect();
        let total: f64 = pmf.iter().sum();
        assert!(total < 1.0 + 1e-4 && total > 0.3, "light_select_pmf sums to {total} at {p}");
        eprintln!("light selection at {p}: the pmf sums to {total:.4} (the rest: dead ends)");
        pmf.push((1.0 - total).max(0.0));
        let expected: Vec<f64> = pmf.iter().map(|q| q * (SAMPLES / 2) as f64).collect();
        assert_fits(&format!("light selection at {p}"), &observed, &expected);
    }
}

/// The pmf light sampling draws a light with equals the one `light_select_pmf` recomputes along
/// the light's bit trail, bit for bit (the shifts and MIS rely on it), and `sample_light`'s pdf
/// equals `emitter_pdf`'s (or, for a punctual light, `light_select_pmf`'s) to float rounding,
/// at 2×10^5 random shading points, normals and uniforms of the scene with every kind of light.
#[test]
fn light_select_pmf_recomputes_the_sampled_pmf_exactly() {
    use restir_pt::shading::light_tree::{light_select, light_select_pmf};
    use restir_pt::shading::lights::{emitter_pdf, is_punctual_light, punctual_emitter_row};
    let scene = crate::fixtures::random_scenes::random_scene_with_punctual_lights(14);
    let mut r = TestRng(81);
    let (mut drawn, mut triangles) = (0, 0);
    for i in 0..200_000 {
        let p = Vec3::new(r.uniform(), r.uniform(), r.uniform()) * 12.0 - 6.0;
        let n = r.unit_vector();
        let (row, pmf) = light_select(&scene, p, n, r.uniform());
        if row == NO_EMITTER {
            continue;
        }
        drawn += 1;
        assert_eq!(
            light_select_pmf(&scene, p, n, row).to_bits(),
            pmf.to_bits(),
            "draw {i}: row {row} at {p}"
        );
        let ls = sample_light(&scene, p, n, Vec3::new(r.uniform(), r.uniform(), r.uniform()));
        if ls.pdf.is_nan() || ls.pdf <= 0.0 || ls.triangle == NO_EMITTER {
            continue;
        }
        let again = if is_punctual_light(ls.triangle) {
            light_select_pmf(
                &scene,
                p,
                n,
                punctual_emitter_row(&scene, ls.triangle & !restir_pt::gpu_types::PUNCTUAL_LIGHT_BIT),
            )
        } else {
            triangles += 1;
            emitter_pdf(&scene, p, n, ls.triangle, ls.dir, ls.dist)
        };
        assert!(
            (again - ls.pdf).abs() <= 1e-5 * ls.pdf,
            "sample {i}: pdf {} recomputed as {again}",
            ls.pdf
        );
    }
    eprintln!("{drawn} lights drawn, {triangles} triangle samples");
    assert!(
        drawn > 150_000 && triangles > 30_000,
        "{drawn} lights drawn, {triangles} triangle samples"
    );
}

/// E[1 / pdf] over light samples equals the total solid angle the emitters subtend (each
/// counted once per emitter), which uniform sphere sampling estimates independently.
#[test]
fn sample_light_pdf_is_consistent_with_solid_angle() {
    let mut scene = crate::fixtures::random_scenes::random_scene(13);
    scene.environment = Vec3::ZERO;
    scene.env_select_prob = 0.0;
    let p = Vec3::new(0.3, -0.2, 0.1);
    let mut r = TestRng(71);
    let n = 400_000;
    let light: Vec<f64> = (0..n)
        .map(|_| {
            let ls = sample_light(&scene, p, Vec3::Y, Vec3::new(r.uniform(), r.uniform(), r.uniform()));
            if ls.pdf > 0.0 {
                1.0 / ls.pdf as f64
            } else {
                0.0
            }
        })
        .collect();
    // Light sampling reaches every emitter whose selection probability at p is positive.
    let emitters: Vec<_> = (0..scene.emitters.len() as u32)
        .filter(|&row| restir_pt::shading::light_tree::light_select_pmf(&scene, p, Vec3::Y, row) > 0.0)
        .map(|row| scene.triangles[scene.emitters[row as usize].triangle as usize])
        .collect();
    assert!(emitters.len() > 20, "{} emitters reachable", emitters.len());
    let sphere: Vec<f64> = (0..n)
        .map(|_| {
            let d = r.unit_vector();
            4.0 * PI * emitters.iter().filter(|t| intersect_triangle(p, d, t, 1e30).is_some()).count() as f64
        })
        .collect();
    let stats = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (
            m,
            v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() as f64 - 1.0) / v.len() as f64,
        )
    };
    let ((a, va), (b, vb)) = (stats(&light), stats(&sphere));
    assert!(
        (a - b).abs() < 4.0 * (va + vb).sqrt(),
        "light sampling {a:.5} vs sphere sampling {b:.5} sr"
    );
}

/// Environment-map importance sampling: the texel counts of a million samples against
/// probabilities computed independently of the sampler's tables (luminance times sin θ at the
/// row centre, normalised), at the 1% level; every sampled direction lands in a texel of positive
/// probability, and the pdf integrates to 1 over the sphere (uniform-sphere Monte Carlo, 4
/// standard errors).
/// Run unrotated and turned by -120 degrees (`--env-rotation`): texels are counted in the map's
/// own frame, so the rotation must leave every count where it was.
#[test]
fn environment_map_sampling_chi_square_and_pdf() {
    for degrees in [0.0, -120.0] {
        environment_map_sampling_fits(test_environment_map().with_rotation(degrees));
    }
}

fn environment_map_sampling_fits(map: restir_pt::scene::environment::EnvironmentMap) {
    use restir_pt::scene::environment::{env_rotate, equirect_uv};
    let undo = Vec2::new(map.rotation.x, -map.rotation.y);
    let (w, h) = (map.width as usize, map.height as usize);
    let weight: Vec<f64> = (0..w * h)
        .map(|k| {
            let theta = PI * ((k / w) as f64 + 0.5) / h as f64;
            restir_pt::scene::luminance(map.texels[k]) as f64 * theta.sin()
        })
        .collect();
    let total: f64 = weight.iter().sum();
    let mut observed = vec![0.0; w * h];
    let mut r = TestRng(91);
    for _ in 0..SAMPLES {
        let d = map.sample_environment(Vec2::new(r.uniform(), r.uniform()));
        assert!((d.length() - 1.0).abs() < 1e-4);
        let uv = equirect_uv(env_rotate(d, undo));
        let (i, j) = (((uv.y * h as f32) as usize).min(h - 1), ((uv.x * w as f32) as usize).min(w - 1));
        observed[i * w + j] += 1.0;
        assert!(map.pdf(d) > 0.0, "a sample at {d} has pdf 0");
    }
    // Texels of zero probability (the black band) must get no sample at all.
    for k in 0..w * h {
        if weight[k] == 0.0 {
            assert_eq!(observed[k], 0.0, "texel {k} has probability 0 but was sampled");
        }
    }
    let keep: Vec<usize> = (0..w * h).filter(|&k| weight[k] > 0.0).collect();
    let obs: Vec<f64> = keep.iter().map(|&k| observed[k]).collect();
    let exp: Vec<f64> = keep.iter().map(|&k| SAMPLES as f64 * weight[k] / total).collect();
    assert_fits("environment map texels", &obs, &exp);
    let n = 400_000;
    let values: Vec<f64> = (0..n).map(|_| map.pdf(r.unit_vector()) as f64 * 4.0 * PI).collect();
    let (mean, se) = (mean(values.iter().copied()), standard_error(&values).unwrap());
    assert!((mean - 1.0).abs() < 4.0 * se, "pdf integrates to {mean} +- {se}");
}

/// The map's orientation is Mitsuba 3's (crates/scene/src/environment.rs): the centre column faces +Z,
/// u = 1/4 faces +X, the left edge -Z, the top row +Y; `--env-rotation 90` brings the centre
/// column to +X (right-handed about +Y), and radiance, pdf and sampling turn together.
#[test]
fn environment_map_orientation_is_mitsubas_and_rotation_turns_it_about_up() {
    use restir_pt::scene::environment::{equirect_dir, equirect_uv, EnvironmentMap};
    let close = |a: Vec2, b: Vec2| (a - b).abs().max_element() < 1e-6;
    assert!(close(equirect_uv(Vec3::Z), Vec2::new(0.5, 0.5)));
    assert!(close(equirect_uv(Vec3::X), Vec2::new(0.25, 0.5)));
    assert!(close(equirect_uv(-Vec3::X), Vec2::new(0.75, 0.5)));
    assert!(equirect_uv(-Vec3::Z).x.abs() < 1e-6 || (equirect_uv(-Vec3::Z).x - 1.0).abs() < 1e-6);
    assert!(close(equirect_uv(Vec3::Y), Vec2::new(0.5, 0.0)) || equirect_uv(Vec3::Y).y.abs() < 1e-6);
    for uv in [Vec2::new(0.1, 0.3), Vec2::new(0.6, 0.8), Vec2::new(0.95, 0.5)] {
        assert!(close(equirect_uv(equirect_dir(uv)), uv), "{uv}");
    }
    // Two bright texel columns around the centre (u in [7/16, 9/16)): they must light +Z
    // unrotated, +X at 90.
    let (w, h) = (16u32, 8u32);
    let texels: Vec<Vec3> = (0..w * h)
        .map(|k| {
            if k % w == 7 || k % w == 8 {
                Vec3::splat(10.0)
            } else {
                Vec3::splat(0.1)
            }
        })
        .collect();
    let map = EnvironmentMap::new(w, h, texels).unwrap();
    assert_eq!(map.radiance(Vec3::new(0.01, 0.0, 1.0).normalize()), Vec3::splat(10.0));
    assert_eq!(map.radiance(Vec3::X), Vec3::splat(0.1));
    let turned = map.clone().with_rotation(90.0);
    assert_eq!(turned.radiance(Vec3::new(1.0, 0.0, -0.01).normalize()), Vec3::splat(10.0));
    assert_eq!(turned.radiance(Vec3::Z), Vec3::splat(0.1));
    let mut r = TestRng(5);
    // Rounding can move a direction within ~1e-7 of a texel edge across it: at most a few.
    let mut differ = 0;
    for _ in 0..1000 {
        let d = r.unit_vector();
        let e = restir_pt::scene::environment::env_rotate(d, turned.rotation);
        differ += (turned.radiance(e) != map.radiance(d) || (turned.pdf(e) - map.pdf(d)).abs() > 1e-4 * map.pdf(d)) as u32;
        let s = turned.sample_environment(Vec2::new(r.uniform(), r.uniform()));
        assert!(turned.radiance(s) == Vec3::splat(10.0) || turned.radiance(s) == Vec3::splat(0.1));
    }
    assert!(differ <= 3, "{differ} of 1000 directions differ");
}
