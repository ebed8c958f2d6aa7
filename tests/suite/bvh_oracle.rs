//! GLSL glsl/shading_core/bvh.glsl, glsl/shading/lights.glsl and glsl/scene/camera.glsl against their Rust twins on a non-trivial scene:
//! 6000 random triangles (some emissive) around a tessellated sphere, with an environment.

use std::sync::Arc;

use glam::{Vec2, Vec3};
use restir_pt::gpu_types::{NO_EMITTER, PUNCTUAL_LIGHT_BIT};
use restir_pt::oracle_types::{OracleRay, SceneOracleInput, SceneOracleOutput};
use restir_pt::render::{RenderSettings, SceneGpu};
use restir_pt::scene::Scene;
use restir_pt::shading::bvh::{trace_closest, trace_occluded, NO_HIT};
use restir_pt::shading::light_tree::light_select_pmf;
use restir_pt::shading::lights::{
    emitter_pdf, environment_pdf, is_punctual_light, punctual_emitter_row, punctual_occluded, sample_light, LightSample,
};
use restir_pt::shading::ray_offset::offset_ray_origin;
use restir_pt::vk::{Buffer, BufferUsage, Context};

use crate::common::{assert_clean, close, gpu, run_oracle_with_defines, TestRng};
use crate::fixtures::random_scenes::{random_scene, random_scene_full, random_scene_with_punctual_lights};

const RAYS: usize = 20_000;

#[test]
fn bvh_traversal_lights_and_camera_glsl_matches_rust() {
    // GLSL trace_closest, trace_occluded, offset_ray_origin, sample_light, environment_pdf,
    // light_select_pmf, emitter_pdf and punctual_occluded against their Rust twins (check_scene_oracle).
    let ctx = gpu();
    let scene = random_scene_with_punctual_lights(1);
    let scene_gpu = SceneGpu::upload(&ctx, &scene).unwrap();
    assert!(
        !scene_gpu.uniform && !scene_gpu.addressed(),
        "this scene is meant to exercise the storage-buffer path"
    );
    check_scene_oracle(&ctx, &scene, &scene_gpu, &[]);
}

/// The same comparison with the scene's triangles, BVH nodes and emitters reached by device
/// address (SCENE_ADDRESSED), as scenes past one binding's range are: a 4 KiB binding limit
/// sends this 6000-triangle scene down that path.
#[test]
fn bvh_traversal_lights_and_camera_glsl_matches_rust_addressed() {
    let ctx = crate::common::gpu_with_scene_binding_limit(Some(4096));
    assert!(ctx.info.buffer_device_address, "the device lacks bufferDeviceAddress");
    let scene = random_scene_with_punctual_lights(1);
    let scene_gpu = SceneGpu::upload(&ctx, &scene).unwrap();
    assert!(scene_gpu.addressed() && !scene_gpu.uniform);
    check_scene_oracle(&ctx, &scene, &scene_gpu, &[("SCENE_ADDRESSED", "1")]);
}

/// The image size the oracle's camera rays and frame parameters use.
fn oracle_settings() -> RenderSettings {
    RenderSettings {
        width: 64,
        height: 48,
        ..Default::default()
    }
}

/// The frame parameters of the uploaded `scene` at `settings`, on its device.
fn params_buffer(scene: &SceneGpu, settings: &RenderSettings) -> Buffer {
    let params = Buffer::new(
        scene.ctx(),
        "params",
        std::mem::size_of::<restir_pt::gpu_types::FrameParams>() as u64,
        BufferUsage::Params,
    )
    .unwrap();
    params.write(&[settings.frame_params(scene.info())]).unwrap();
    params
}

/// How many of check_scene_oracle's items reached the branches it must exercise.
#[derive(Default)]
struct Coverage {
    hits: usize,
    light_samples: usize,
    punctual_samples: usize,
    punctual_shadowed: usize,
}

/// Runs oracle/scene_oracle.comp (compiled with `defines`) over random rays and compares every
/// output with the Rust twins.
fn check_scene_oracle(ctx: &Arc<Context>, scene: &Scene, scene_gpu: &SceneGpu, defines: &[(&str, &str)]) {
    // Punctual lights are chosen beside emissive triangles: light sampling's delta branch is compared too.
    let settings = oracle_settings();
    let params = params_buffer(scene_gpu, &settings);
    let mut r = TestRng(2);
    let mut inputs = Vec::with_capacity(RAYS);
    for i in 0..RAYS {
        let o = Vec3::new(r.uniform(), r.uniform(), r.uniform()) * 10.0 - 5.0;
        // Half the rays are shadow-ray-like segments with a finite tmax.
        let tmax = if i % 2 == 0 { 1e30 } else { 0.5 + 6.0 * r.uniform() };
        let dir = r.unit_vector();
        let light_uniforms = [r.uniform(), r.uniform(), r.uniform()];
        let image_point = [r.uniform() * 64.0, r.uniform() * 48.0];
        inputs.push(scene_input(o, tmax, dir, light_uniforms, image_point));
    }
    let out = run_scene_oracle_kernel(ctx, scene_gpu, &params, defines, &inputs);
    let mut coverage = Coverage::default();
    for (i, (input, g)) in inputs.iter().zip(&out).enumerate() {
        check_traversal(scene, input, g, i, &mut coverage);
        check_light_and_camera(scene, &settings, input, g, i, &mut coverage);
    }
    let Coverage {
        hits,
        light_samples,
        punctual_samples,
        punctual_shadowed,
    } = coverage;
    assert!(light_samples > RAYS / 2, "only {light_samples} of {RAYS} light samples succeeded");
    assert!(
        punctual_samples > RAYS / 20,
        "only {punctual_samples} light samples chose a punctual light: the delta branch is not exercised"
    );
    assert!(
        punctual_shadowed > 0 && punctual_shadowed < punctual_samples,
        "punctual shadow rays: {punctual_shadowed} of {punctual_samples} blocked; both outcomes must occur"
    );
    assert!(
        hits > RAYS / 4,
        "only {hits} of {RAYS} rays hit: the scene does not exercise traversal"
    );
    assert_clean(ctx);
}

/// An item of oracle/scene_oracle.comp: the ray (o, dir) up to `tmax`, light-sample uniforms
/// and an image point in pixels.
fn scene_input(o: Vec3, tmax: f32, dir: Vec3, light_uniforms: [f32; 3], image_point: [f32; 2]) -> SceneOracleInput {
    SceneOracleInput {
        ray: OracleRay {
            origin: o.to_array(),
            tmax,
            dir: dir.to_array(),
            pad: 0.0,
        },
        light_uniforms,
        image_point,
        ..Default::default()
    }
}

/// Runs oracle/scene_oracle.comp, compiled with `defines`, over `inputs`.
fn run_scene_oracle_kernel(
    ctx: &Arc<Context>,
    scene_gpu: &SceneGpu,
    params: &Buffer,
    defines: &[(&str, &str)],
    inputs: &[SceneOracleInput],
) -> Vec<SceneOracleOutput> {
    run_oracle_with_defines(
        ctx,
        "oracle/scene_oracle.comp",
        defines,
        &scene_gpu.buffers(params),
        &[("Inputs", bytemuck::cast_slice(inputs))],
        inputs.len() * std::mem::size_of::<SceneOracleOutput>() / 4,
        inputs.len() as u32,
    )
}

/// trace_closest, trace_occluded and offset_ray_origin of ray `i` against their Rust twins.
fn check_traversal(scene: &Scene, input: &SceneOracleInput, g: &SceneOracleOutput, i: usize, coverage: &mut Coverage) {
    let (o, d, tmax) = (Vec3::from_array(input.ray.origin), Vec3::from_array(input.ray.dir), input.ray.tmax);
    let h = trace_closest(&scene.nodes, &scene.triangles, o, d, tmax);
    assert_eq!(
        g.hit.triangle, h.triangle,
        "trace_closest triangle, ray {i}: GLSL t {} vs Rust t {}",
        g.hit.t, h.t
    );
    if h.triangle != NO_HIT {
        coverage.hits += 1;
        assert!(close(g.hit.t, h.t, 1e-4), "trace_closest t, ray {i}");
        assert!(
            close(g.hit.bary[0], h.bary.x, 1e-4) && close(g.hit.bary[1], h.bary.y, 1e-4),
            "trace_closest barycentrics, ray {i}"
        );
    }
    let occluded = trace_occluded(&scene.nodes, &scene.triangles, o, d, tmax);
    assert_eq!(g.occluded == 1, occluded, "trace_occluded, ray {i}");
    let off = offset_ray_origin(o, d, &scene.triangles[i % scene.triangles.len()]);
    for k in 0..3 {
        assert!(close(g.offset_origin[k], off[k], 1e-6), "offset_ray_origin, ray {i}");
    }
}

/// sample_light, the pdf of its sample, camera_ray_dir and punctual_occluded of item `i` against
/// their Rust twins.
fn check_light_and_camera(
    scene: &Scene,
    settings: &RenderSettings,
    input: &SceneOracleInput,
    g: &SceneOracleOutput,
    i: usize,
    coverage: &mut Coverage,
) {
    let (o, d) = (Vec3::from_array(input.ray.origin), Vec3::from_array(input.ray.dir));
    let (u, px) = (Vec3::from_array(input.light_uniforms), Vec2::from_array(input.image_point));
    let ls = sample_light(scene, o, d, u);
    let dist_ok = (ls.dist.is_infinite() && g.light_dist.is_infinite()) || close(g.light_dist, ls.dist, 1e-4);
    assert!(
        dist_ok && (Vec3::from_array(g.light_dir) - ls.dir).abs().max_element() < 1e-4,
        "sample_light direction, item {i}: {g:?} vs {ls:?}"
    );
    assert!(
        (Vec3::from_array(g.light_radiance) - ls.radiance).abs().max_element() < 1e-4 && close(g.light_pdf, ls.pdf, 1e-3),
        "sample_light value, item {i}"
    );
    let dir = scene.cameras[0].ray_dir(px.x, px.y, settings.width, settings.height);
    assert!(
        (Vec3::from_array(g.camera_dir) - dir).abs().max_element() < 1e-5,
        "camera_ray_dir, item {i}"
    );
    assert_eq!(g.light_triangle, ls.triangle, "sample_light triangle, item {i}");
    // GLSL's own pdf of its sample, recomputed along the light's bit trail, equals the pdf it
    // sampled with (what MIS and the shifts rely on), to float rounding.
    assert!(
        close(g.pdf_again, g.light_pdf, 1e-5),
        "light_select_pmf / emitter_pdf vs sample pdf, item {i}: {} vs {}",
        g.pdf_again,
        g.light_pdf
    );
    if ls.pdf > 0.0 {
        coverage.light_samples += 1;
        // The same recomputation by the Rust twins: the emitter before is_punctual_light, since
        // NO_EMITTER has the punctual bit set.
        let again = if ls.triangle == NO_EMITTER {
            environment_pdf(scene, ls.dir)
        } else if is_punctual_light(ls.triangle) {
            light_select_pmf(scene, o, d, punctual_emitter_row(scene, ls.triangle & !PUNCTUAL_LIGHT_BIT))
        } else {
            emitter_pdf(scene, o, d, ls.triangle, ls.dir, ls.dist)
        };
        assert!(
            close(g.pdf_again, again, 1e-3),
            "environment_pdf / light_select_pmf / emitter_pdf, item {i}: GLSL {} vs Rust {again}",
            g.pdf_again
        );
    }
    if is_punctual_light(ls.triangle) {
        coverage.punctual_samples += 1;
        let shadowed = punctual_occluded(scene, o, d, (i % scene.triangles.len()) as u32, ls.dir, ls.dist);
        assert_eq!(g.punctual_shadowed == 1, shadowed, "punctual_occluded, item {i}");
        coverage.punctual_shadowed += shadowed as usize;
    }
}

#[test]
fn bvh_closest_hit_equals_brute_force() {
    let scene = random_scene(4);
    let mut r = TestRng(8);
    for i in 0..5000 {
        let o = Vec3::new(r.uniform(), r.uniform(), r.uniform()) * 14.0 - 7.0;
        let d = r.unit_vector();
        let h = trace_closest(&scene.nodes, &scene.triangles, o, d, 1e30);
        let mut best = (1e30f32, NO_HIT);
        for (k, tri) in scene.triangles.iter().enumerate() {
            if let Some((t, _)) = restir_pt::shading::bvh::intersect_triangle(o, d, tri, best.0) {
                best = (t, k as u32);
            }
        }
        assert_eq!(h.triangle, best.1, "ray {i}: BVH t {} vs brute force t {}", h.t, best.0);
    }
}

#[test]
fn bvh_leaves_cover_every_triangle_once_and_bound_it() {
    let scene = random_scene(9);
    let mut seen = vec![0u32; scene.triangles.len()];
    for node in &scene.nodes {
        let (first, count) = node.leaf_range();
        for t in first..first + count {
            seen[t as usize] += 1;
            for v in scene.triangles[t as usize].vertices() {
                assert!(
                    v.cmpge(Vec3::from(node.lo) - 1e-5).all() && v.cmple(Vec3::from(node.hi) + 1e-5).all(),
                    "leaf does not bound its triangle"
                );
            }
        }
        assert!(node.skip as usize <= scene.nodes.len());
    }
    assert!(seen.iter().all(|&c| c == 1), "a triangle is in no leaf or in two");
}

/// The environment half of light sampling with an equirectangular map (the scene's emitters beside
/// it): GLSL `sample_light`, `environment_radiance` and `environment_pdf` (glsl/shading/lights.glsl, compiled
/// with the scene's SCENE_ENV_MAP defines) against their Rust twins in crates/shading/src/lights.rs.
/// Run unrotated and turned by 37 degrees (`--env-rotation`, the header's cosine and sine).
#[test]
fn environment_map_light_sampling_glsl_matches_rust() {
    for degrees in [0.0, 37.0] {
        environment_map_light_sampling_matches(degrees);
    }
}

fn environment_map_light_sampling_matches(degrees: f32) {
    let ctx = gpu();
    let map = crate::fixtures::statistics::test_environment_map().with_rotation(degrees);
    let scene = random_scene_full(5, vec![], Some(map));
    assert!(scene.env_select_prob > 0.0 && scene.env_select_prob < 1.0);
    let scene_gpu = SceneGpu::upload(&ctx, &scene).unwrap();
    let params = params_buffer(&scene_gpu, &oracle_settings());
    let mut r = TestRng(6);
    let mut inputs = Vec::with_capacity(RAYS);
    for _ in 0..RAYS {
        let o = Vec3::new(r.uniform(), r.uniform(), r.uniform()) * 10.0 - 5.0;
        let dir = r.unit_vector();
        let light_uniforms = [r.uniform(), r.uniform(), r.uniform()];
        inputs.push(scene_input(o, 1e30, dir, light_uniforms, [0.0; 2]));
    }
    let defines = scene_gpu.defines();
    assert!(defines.contains(&("SCENE_ENV_MAP", "1")));
    let out = run_scene_oracle_kernel(&ctx, &scene_gpu, &params, &defines, &inputs);
    let (mut env_samples, mut near_edges) = (0, 0);
    for (i, (input, g)) in inputs.iter().zip(&out).enumerate() {
        let (o, u) = (Vec3::from_array(input.ray.origin), Vec3::from_array(input.light_uniforms));
        let ls = sample_light(&scene, o, Vec3::from_array(input.ray.dir), u);
        assert_eq!(g.light_triangle, ls.triangle, "sample_light choice, item {i}");
        let light_dir = Vec3::from_array(g.light_dir);
        assert!(
            (light_dir - ls.dir).abs().max_element() < 1e-4,
            "sample_light direction, item {i}: {} vs {}",
            light_dir,
            ls.dir
        );
        if ls.triangle == NO_EMITTER && ls.dist.is_infinite() {
            env_samples += 1;
            if !check_environment_sample(&scene, &ls, g, i) {
                near_edges += 1;
                continue;
            }
        }
        assert!(close(g.light_pdf, ls.pdf, 1e-3), "sample_light pdf, item {i}");
    }
    assert!(env_samples > RAYS / 4, "only {env_samples} environment samples");
    assert!(
        near_edges * 50 < env_samples,
        "{near_edges} of {env_samples} samples on texel edges"
    );
    assert_clean(&ctx);
}

/// environment_radiance and environment_pdf of environment sample `i` (GLSL output `g`)
/// against their Rust twins; false (nothing compared) when the direction sits on a texel edge.
fn check_environment_sample(scene: &Scene, ls: &LightSample, g: &SceneOracleOutput, i: usize) -> bool {
    use restir_pt::shading::lights::{environment_pdf, environment_radiance};
    // The map is piecewise constant: radiance and pdf must agree unless the direction
    // sits within 0.005 texels of a texel edge, where llvmpipe's atan/acos and Rust's
    // may round to different texels.
    use restir_pt::scene::environment::{env_rotate, equirect_uv};
    let cs = scene.environment_map.as_ref().unwrap().rotation;
    let uv = equirect_uv(env_rotate(ls.dir, Vec2::new(cs.x, -cs.y))) * Vec2::new(24.0, 12.0);
    if (uv - uv.round()).abs().min_element() < 5e-3 {
        return false;
    }
    assert_eq!(
        Vec3::from_array(g.light_radiance),
        environment_radiance(scene, ls.dir),
        "environment radiance, item {i}"
    );
    assert!(
        close(g.light_pdf, environment_pdf(scene, ls.dir), 1e-4),
        "environment pdf, item {i}: {} vs {}",
        g.light_pdf,
        ls.pdf
    );
    true
}
