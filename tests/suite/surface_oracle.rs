//! GLSL glsl/shading_core/surface.glsl, glsl/shading_core/texture.glsl and glsl/scene/hit_surface.glsl against crates/shading-core/src/surface.rs, crates/shading-core/src/texture.rs
//! and crates/scene/src/hit_surface.rs: surface_at, triangle_bary, texture_lookup, texture_coordinates,
//! textured_material (with emission_coverage), normal_mapped, texture_tangent_frame (the normal
//! texture's frame turned and mirrored with its transform), vertex_color, shading_normal and
//! hit_shading (Scene methods) on a scene of random triangles with random vertex attributes
//! (COLOR_0 on half of them) and small random textures (every address mode, bilinear and
//! nearest, sRGB and linear, KHR_texture_transform rows).

use glam::{Vec2, Vec3, Vec4};
use restir_pt::gpu_types::{Material, Triangle, MATERIAL_ALPHA_EMISSION, MATERIAL_BLEND_EMISSION, NO_EMITTER};
use restir_pt::oracle_types::{SurfaceOracleInput, SurfaceOracleOutput};
use restir_pt::render::SceneGpu;
use restir_pt::scene::{Camera, Scene, SceneParts};
use restir_pt::shading::surface::{pack_vertex_color, surface_at, triangle_bary, SurfaceHit, TriangleSurface};
use restir_pt::shading::texture::{
    normal_mapped, texture_coordinates, texture_lookup, texture_tangent_frame, textured_material, MaterialTextures, SceneTextures,
    TextureHeader, TextureSlot, NO_TEXTURE, TEXTURE_NEAREST,
};

use crate::common::{assert_clean, assert_vec3_close, close, gpu, run_surface_set0_oracle, TestRng};

const ITEMS: usize = 20_000;
const TEXTURES: usize = 9;
const MATERIALS: usize = 7;
/// Relative agreement; sRGB decoding goes through llvmpipe's pow.
const TOL: f32 = 2e-4;

fn random_textures(r: &mut TestRng) -> SceneTextures {
    let mut t = SceneTextures::default();
    for k in 0..TEXTURES {
        let (w, h) = (1 + (r.uniform() * 9.0) as u32, 1 + (r.uniform() * 9.0) as u32);
        // Every wrap pair, filter and a few sizes of 1 (where every mode is constant).
        let sampler_bits = (k as u32 % 3) | (((k as u32 / 3) % 3) << 2) | if r.uniform() < 0.4 { TEXTURE_NEAREST } else { 0 };
        t.headers.push(TextureHeader {
            width: w,
            height: h,
            offset: t.texels.len() as u32,
            sampler_bits,
        });
        t.texels.extend((0..w * h).map(|_| r.next_u64() as u32));
    }
    // Draws added since the scene was first written come from their own stream, so that the
    // triangles and textures stay those of the original seed.
    let mut extra = TestRng(0x5eed_0001);
    let mut slot = |r: &mut TestRng| {
        if r.uniform() < 0.2 {
            return TextureSlot::default();
        }
        // Turned, scaled and (a quarter of them) mirrored: the normal slot's tangent frame
        // turns and flips with the transform (texture_tangent_frame).
        let mirror = if extra.uniform() < 0.25 { -1.0 } else { 1.0 };
        let (u_row, v_row) = restir_pt::shading::texture::texture_transform_rows(
            [r.uniform() - 0.5, r.uniform() - 0.5],
            (r.uniform() - 0.5) * 6.0,
            [mirror * (0.2 + 2.0 * r.uniform()), 0.2 + 2.0 * r.uniform()],
        );
        TextureSlot {
            u_row,
            texture_index: (r.uniform() * TEXTURES as f32) as u32 % TEXTURES as u32,
            v_row,
            texcoord: (r.uniform() < 0.5) as u32,
        }
    };
    for _ in 0..MATERIALS {
        let m = MaterialTextures {
            base_color: slot(r),
            metal_rough: slot(r),
            emissive: slot(r),
            normal: slot(r),
            normal_scale: 2.0 * r.uniform() - 0.5,
            alpha_cutoff: 0.5,
            alpha_mode: 0,
            base_alpha: 1.0,
        };
        t.materials.push(m);
    }
    t
}

fn random_attributes(r: &mut TestRng, extra: &mut TestRng) -> TriangleSurface {
    let mut a = TriangleSurface::flat();
    for k in 0..3 {
        if r.uniform() < 0.9 {
            a.normal[k] = r.unit_vector().extend(0.0).to_array();
        }
        if r.uniform() < 0.9 {
            a.tangent[k] = r.unit_vector().extend(if r.uniform() < 0.5 { -1.0 } else { 1.0 }).to_array();
        }
        a.uv[k] = [0, 1, 2, 3].map(|_| 6.0 * r.uniform() - 3.0);
    }
    // Vertex colours (COLOR_0) on half of the triangles, all three vertices or none.
    if extra.uniform() < 0.5 {
        for k in 0..3 {
            a.normal[k][3] = pack_vertex_color(Vec3::new(extra.uniform(), extra.uniform(), extra.uniform()));
        }
    }
    a
}

pub fn textured_random_scene(seed: u64) -> Scene {
    let mut r = TestRng(seed);
    let mut triangles = Vec::new();
    let mut surfaces = Vec::new();
    let mut extra = TestRng(seed ^ 0x00c0_10c0);
    for i in 0..500 {
        let c = Vec3::new(r.uniform(), r.uniform(), r.uniform()) * 10.0 - 5.0;
        let v: Vec<Vec3> = (0..3).map(|_| c + (0.1 + r.uniform()) * r.unit_vector()).collect();
        triangles.push(Triangle {
            v0: v[0].into(),
            material: i % MATERIALS as u32,
            e1: (v[1] - v[0]).into(),
            emitter: NO_EMITTER,
            e2: (v[2] - v[0]).into(),
            alpha_tested: 0,
        });
        surfaces.push(random_attributes(&mut r, &mut extra));
    }
    // Every third material an alpha-tested emitter (MASK), every third a BLEND one: emission
    // times its coverage (emission_coverage).
    let coverage_flags = [0, MATERIAL_ALPHA_EMISSION, MATERIAL_ALPHA_EMISSION | MATERIAL_BLEND_EMISSION];
    let materials = (0..MATERIALS)
        .map(|k| Material {
            base_color: [r.uniform(), r.uniform(), r.uniform()],
            metallic: r.uniform(),
            emission: [r.uniform(), r.uniform(), r.uniform()],
            roughness: r.uniform(),
            ior: 1.5,
            flags: coverage_flags[k % 3],
            ..Default::default()
        })
        .collect();
    Scene::build(SceneParts {
        source: "random textured scene".into(),
        triangles,
        surfaces,
        textures: random_textures(&mut r),
        materials,
        material_names: (0..MATERIALS).map(|i| format!("m{i}")).collect(),
        environment: Vec3::ONE,
        environment_map: None,
        cameras: vec![Camera::look_at("test", Vec3::new(0.0, 1.0, 12.0), Vec3::ZERO, Vec3::Y, 0.8)],
        lights: vec![],
        warnings: vec![],
    })
}

/// Whether a nearest lookup of `uv` sits within a small margin of a texel edge, where the
/// GPU's rounding may pick the neighbour.
fn near_texel_edge(h: &TextureHeader, uv: Vec2) -> bool {
    let x = uv * Vec2::new(h.width as f32, h.height as f32);
    let d = (x - x.round()).abs();
    h.sampler_bits & TEXTURE_NEAREST != 0 && d.min_element() < 1e-3
}

#[test]
fn surface_at_texture_lookup_textured_material_normal_mapped_glsl_matches_rust() {
    // GLSL surface_at, triangle_bary, texture_lookup, texture_coordinates, texture_tangent_frame,
    // textured_material, normal_mapped, shading_normal and hit_shading against their Rust twins (check_item).
    compare_surfaces(&gpu(), &textured_random_scene(7));
}

/// The same comparison with the attributes and texels reached by device address (a lowered
/// binding limit sends the scene down the path of scenes past one binding).
#[test]
fn surface_at_texture_lookup_textured_material_normal_mapped_glsl_matches_rust_addressed() {
    let ctx = crate::common::gpu_with_scene_binding_limit(Some(4096));
    let scene = textured_random_scene(7);
    let scene_gpu = SceneGpu::upload(&ctx, &scene).unwrap();
    assert!(scene_gpu.addressed() && scene_gpu.surface.as_ref().unwrap().addressed());
    compare_surfaces(&ctx, &scene);
}

/// The same comparison on the public Avocado sample: three 2048x2048 textures (48 MiB of
/// texels), vertex normals and tangents from the file.
#[test]
fn surface_oracle_on_the_avocado_sample() {
    let path = crate::common::repo_path("../shared/assets/Avocado/Avocado.gltf");
    if !path.exists() {
        eprintln!("skipped: {} is absent", path.display());
        return;
    }
    let scene = restir_pt::scene::load_scene(&path).unwrap();
    assert_eq!(scene.textures.headers.len(), 3);
    compare_surfaces(&gpu(), &scene);
}

/// Runs surface_oracle.comp over random hits of `scene` and compares each output with its
/// Rust twin.
fn compare_surfaces(ctx: &std::sync::Arc<restir_pt::vk::Context>, scene: &Scene) {
    let scene_gpu = SceneGpu::upload(ctx, scene).unwrap();
    let inputs = random_hits(scene);
    let out = run_surface_oracle(ctx, &scene_gpu, &inputs);
    let (mut skipped, mut compared) = (0, 0);
    for (i, (input, g)) in inputs.iter().zip(&out).enumerate() {
        if check_item(scene, input, g, i) {
            compared += 1;
        } else {
            skipped += 1;
        }
    }
    assert!(skipped < ITEMS / 20, "{skipped} of {ITEMS} items near a nearest-filter texel edge");
    assert!(compared > 0);
    assert_clean(ctx);
}

/// `ITEMS` random points on the scene's triangles, each with a random texture lookup.
fn random_hits(scene: &Scene) -> Vec<SurfaceOracleInput> {
    let textures = scene.textures.headers.len();
    let mut r = TestRng(11);
    let mut inputs = Vec::with_capacity(ITEMS);
    for _ in 0..ITEMS {
        let tri = (r.uniform() * scene.triangles.len() as f32) as u32 % scene.triangles.len() as u32;
        let b = restir_pt::shading::sampling::sample_triangle(Vec2::new(r.uniform(), r.uniform()));
        let texture = (r.uniform() * textures as f32) as u32 % textures as u32;
        let t = &scene.triangles[tri as usize];
        let p = Vec3::from(t.v0) + b.x * Vec3::from(t.e1) + b.y * Vec3::from(t.e2);
        let lookup_uv = [10.0 * r.uniform() - 5.0, 10.0 * r.uniform() - 5.0];
        inputs.push(SurfaceOracleInput {
            bary: b.to_array(),
            triangle: tri,
            texture_index: texture,
            lookup_uv,
            srgb: (r.uniform() < 0.5) as u32,
            point: p.to_array(),
            ..Default::default()
        });
    }
    inputs
}

/// Dispatches surface_oracle.comp over `inputs`.
fn run_surface_oracle(
    ctx: &std::sync::Arc<restir_pt::vk::Context>,
    scene_gpu: &SceneGpu,
    inputs: &[SurfaceOracleInput],
) -> Vec<SurfaceOracleOutput> {
    let surface = scene_gpu.surface.as_ref().expect("the scene has attributes");
    assert_eq!(surface.buffers.len(), 4, "attributes and three texture buffers");
    run_surface_set0_oracle(ctx, scene_gpu, "oracle/surface_oracle.comp", inputs)
}

/// Asserts item `i`'s GLSL outputs `g` against the Rust twins; false when the item was skipped
/// because a nearest-filter lookup sits on a texel edge.
fn check_item(scene: &Scene, input: &SurfaceOracleInput, g: &SurfaceOracleOutput, i: usize) -> bool {
    let tri = input.triangle;
    let bary = Vec2::from_array(input.bary);
    let s = surface_at(&scene.triangles[tri as usize], &scene.surfaces[tri as usize], bary);
    assert_vec3_close(format!("surface_at normal, item {i}"), Vec3::from_array(g.normal), s.normal, TOL);
    assert_eq!(g.handedness, s.handedness, "surface_at handedness, item {i}");
    assert_vec3_close(format!("surface_at tangent, item {i}"), Vec3::from_array(g.tangent), s.tangent, TOL);
    let uv = Vec4::new(s.uv0.x, s.uv0.y, s.uv1.x, s.uv1.y);
    let g_uv = Vec4::new(g.uv0[0], g.uv0[1], g.uv1[0], g.uv1[1]);
    assert!((g_uv - uv).abs().max_element() < 1e-4, "surface_at uv, item {i}: {g_uv} vs {uv}");
    let bary_rust = triangle_bary(&scene.triangles[tri as usize], Vec3::from_array(input.point));
    assert!(
        (Vec2::from_array(g.bary) - bary_rust).abs().max_element() < 1e-3,
        "triangle_bary, item {i}"
    );
    assert!(
        (bary_rust - bary).abs().max_element() < 1e-3,
        "triangle_bary recovers the barycentrics, item {i}"
    );

    let t = &scene.textures;
    let texture = input.texture_index;
    let header = &t.headers[texture as usize];
    let lookup_uv = Vec2::from_array(input.lookup_uv);
    let material = scene.triangles[tri as usize].material as usize;
    let mt = &t.materials[material];
    let slots = [mt.base_color, mt.metal_rough, mt.emissive, mt.normal];
    let any_near_edge = near_texel_edge(header, lookup_uv)
        || slots.iter().any(|sl| {
            sl.texture_index != NO_TEXTURE && near_texel_edge(&t.headers[sl.texture_index as usize], texture_coordinates(sl, &s))
        });
    if any_near_edge {
        return false;
    }
    let c = texture_lookup(t, texture, lookup_uv, input.srgb != 0);
    for k in 0..4 {
        assert!(
            close(g.texel[k], c[k], TOL),
            "texture_lookup, item {i}: GLSL {:?} vs Rust {c}",
            g.texel
        );
    }
    let coords = texture_coordinates(&mt.base_color, &s);
    assert!(
        (Vec2::from_array(g.base_color_uv) - coords).abs().max_element() < 1e-4,
        "texture_coordinates, item {i}"
    );
    check_textured_material(scene, material, &s, g, i);
    check_shading_frame(scene, g, tri, bary, i);
    let (tangent, handedness) = texture_tangent_frame(&mt.normal, &s);
    assert_vec3_close(
        format!("texture_tangent_frame tangent, item {i}"),
        Vec3::from_array(g.frame_tangent),
        tangent,
        1e-3,
    );
    assert_eq!(g.frame_handedness, handedness, "texture_tangent_frame handedness, item {i}");
    assert_vec3_close(format!("vertex_color, item {i}"), Vec3::from_array(g.color), s.color, 1e-5);
    true
}

/// textured_material and normal_mapped of item `i` against their Rust twins.
fn check_textured_material(scene: &Scene, material: usize, s: &SurfaceHit, g: &SurfaceOracleOutput, i: usize) {
    let (t, mt) = (&scene.textures, &scene.textures.materials[material]);
    let m = textured_material(&scene.materials[material], mt, t, s);
    assert_vec3_close(
        format!("textured_material base colour, item {i}"),
        Vec3::from_array(g.base_color),
        m.base_color.into(),
        TOL,
    );
    assert!(close(g.metallic, m.metallic, TOL), "textured_material metallic, item {i}");
    assert_vec3_close(
        format!("textured_material emission, item {i}"),
        Vec3::from_array(g.emission),
        m.emission.into(),
        TOL,
    );
    assert!(close(g.roughness, m.roughness, TOL), "textured_material roughness, item {i}");
    assert_vec3_close(
        format!("normal_mapped, item {i}"),
        Vec3::from_array(g.normal_mapped),
        normal_mapped(mt, t, s),
        1e-3,
    );
}

/// GLSL `shading_normal` and `hit_shading` (its normal, and its material's roughness and
/// metallic) of item `i` against `Scene::shading_normal` and `Scene::hit_shading`.
fn check_shading_frame(scene: &Scene, g: &SurfaceOracleOutput, tri: u32, bary: Vec2, i: usize) {
    let (m, ns) = scene.hit_shading(tri, bary);
    assert_vec3_close(
        format!("shading_normal, item {i}"),
        Vec3::from_array(g.shading_normal),
        scene.shading_normal(tri, bary),
        1e-3,
    );
    assert_vec3_close(format!("hit_shading normal, item {i}"), Vec3::from_array(g.hit_normal), ns, 1e-3);
    assert!(
        close(g.hit_roughness, m.roughness, TOL) && close(g.hit_metallic, m.metallic, TOL),
        "hit_shading material, item {i}"
    );
}
