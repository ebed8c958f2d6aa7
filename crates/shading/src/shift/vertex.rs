//! The vertices of ReSTIR PT's paths and what the shifts evaluate between two of them: the
//! reconnection test, visibility, the emission and light pdf at the end, and the end's MIS
//! weight. Twin of glsl/shading/shift/vertex.glsl.

use glam::Vec3;

use restir_pt_interface::gpu_types::{Material, NO_EMITTER, PUNCTUAL_LIGHT_BIT};
use restir_pt_scene::PunctualKind;
use restir_pt_scene::Scene;
use restir_pt_shading_core::bvh::{segment_occluded, trace_closest, trace_occluded, NO_HIT};

use crate::bsdf::{bsdf_eval_pdf, has_specular_layer, index_matched, lobe_weights, DELTA_ALPHA};
use crate::light_tree::light_select_pmf;
use crate::lights::{
    emitted_radiance, emitter_area_pdf, environment_pdf, environment_radiance, is_punctual_light, punctual_arrival, punctual_emitter_row,
    punctual_occluded,
};
use crate::ray_offset::offset_ray_origin;
use crate::sampling::balance_heuristic;
use crate::surface::triangle_bary;

/// Roughness below which a vertex cannot be a reconnection endpoint (the public reference's 0.2).
pub const DEFAULT_ROUGHNESS_THRESHOLD: f32 = 0.2;
/// The distance threshold as a fraction of the scene's smallest bounding-box extent.
pub const DEFAULT_DISTANCE_FRACTION: f32 = 0.03;

/// The reconnection criteria of the shifts (Lin et al. 2022: a vertex is reconnectable when it
/// and its predecessor are rough and far enough apart). Twin of GLSL `ShiftParams`
/// (glsl/shading/shift/vertex.glsl); the kernels read it from [`restir_pt_interface::gpu_types::ReuseParams`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShiftParams {
    /// Perceptual roughness below which a GGX lobe counts as glossy: such a vertex cannot be a
    /// reconnection vertex.
    pub roughness_threshold: f32,
    /// Minimum distance in scene units between a reconnection vertex and its predecessor.
    pub distance_threshold: f32,
}

impl ShiftParams {
    /// The defaults for `scene`: [`DEFAULT_ROUGHNESS_THRESHOLD`] and [`DEFAULT_DISTANCE_FRACTION`]
    /// of the smallest extent of its bounding box.
    pub fn for_scene(scene: &Scene) -> ShiftParams {
        let extent = (scene.bounds.1 - scene.bounds.0).max(Vec3::splat(1e-6));
        ShiftParams {
            roughness_threshold: DEFAULT_ROUGHNESS_THRESHOLD,
            distance_threshold: DEFAULT_DISTANCE_FRACTION * extent.min_element(),
        }
    }
}

/// A path vertex: a surface point, or (triangle == NO_HIT) a direction to the environment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vertex {
    /// The point in scene coordinates (a punctual light's position); for an escaped vertex or one on a
    /// directional light, the unit direction towards the environment or the light.
    pub pos: Vec3,
    /// The geometric normal (unit, as wound; zero off surfaces); `vertex_shading` gives the
    /// shading normal.
    pub normal: Vec3,
    /// The triangle hit, [`NO_HIT`] for an escaped vertex, or [`PUNCTUAL_LIGHT_BIT`] | k on punctual
    /// light k.
    pub triangle: u32,
}

/// Whether `v` is a direction to the environment.
pub fn vertex_is_escaped(v: &Vertex) -> bool {
    v.triangle == NO_HIT
}

/// Whether `v` is on punctual light `triangle & !PUNCTUAL_LIGHT_BIT` (only as a path's last
/// vertex).
pub fn vertex_is_punctual(v: &Vertex) -> bool {
    is_punctual_light(v.triangle)
}

fn vertex_light(v: &Vertex) -> u32 {
    v.triangle & !PUNCTUAL_LIGHT_BIT
}

/// Escaped, or on a directional light: `pos` is a direction, the vertex infinitely far.
pub fn vertex_is_at_infinity(scene: &Scene, v: &Vertex) -> bool {
    vertex_is_escaped(v) || (vertex_is_punctual(v) && scene.lights[vertex_light(v) as usize].kind == PunctualKind::Directional)
}

/// Punctual light `id` as a vertex: its position, or the direction towards a directional one.
pub fn vertex_punctual(scene: &Scene, id: u32) -> Vertex {
    let l = &scene.lights[(id & !PUNCTUAL_LIGHT_BIT) as usize];
    let pos = if l.kind == PunctualKind::Directional {
        -l.direction
    } else {
        l.position
    };
    Vertex {
        pos,
        normal: Vec3::ZERO,
        triangle: id,
    }
}

/// The point `pos` on `triangle`, with the triangle's geometric normal.
pub fn vertex_on_surface(scene: &Scene, triangle: u32, pos: Vec3) -> Vertex {
    let normal = scene.triangles[triangle as usize].normal_area2().normalize();
    Vertex { pos, normal, triangle }
}

pub(super) fn vertex_escaped(dir: Vec3) -> Vertex {
    Vertex {
        pos: dir,
        normal: Vec3::ZERO,
        triangle: NO_HIT,
    }
}

/// Whether a vertex may be a reconnection endpoint: every lobe of its material is rough
/// (diffuse, or GGX, including a non-metal's specular layer, at least as rough as the threshold).
/// Escaped directions count as rough.
pub fn vertex_is_rough(scene: &Scene, v: &Vertex, params: &ShiftParams) -> bool {
    if vertex_is_escaped(v) || vertex_is_punctual(v) {
        return true;
    }
    let m = &material_of(scene, v);
    let (_, w_c, w_t) = lobe_weights(m);
    let w_c = if has_specular_layer(m) { 1.0 } else { w_c };
    let rough_ggx = m.roughness >= params.roughness_threshold && m.roughness * m.roughness >= DELTA_ALPHA;
    // An index-matched dielectric is a pass-through, a delta lobe at any roughness.
    (w_c <= 0.0 || rough_ggx) && (w_t <= 0.0 || (rough_ggx && !index_matched(m.ior)))
}

/// The reconnection test for the pair (prev, cur): both rough and far enough apart.
pub fn is_reconnectable(scene: &Scene, prev: &Vertex, cur: &Vertex, params: &ShiftParams) -> bool {
    let far = vertex_is_at_infinity(scene, cur) || prev.pos.distance(cur.pos) >= params.distance_threshold;
    !vertex_is_escaped(prev) && far && vertex_is_rough(scene, prev, params) && vertex_is_rough(scene, cur, params)
}

pub(crate) fn material_of(scene: &Scene, v: &Vertex) -> Material {
    scene.material_at(v.triangle, triangle_bary(&scene.triangles[v.triangle as usize], v.pos))
}

/// The material at surface vertex `v` (textures applied) and its shading normal `ns` (unit, world
/// space): the path tracer's `Scene::hit_shading` (the interpolated vertex normal with the
/// material's normal map applied; the geometric normal in a scene without shading normals).
/// BSDFs evaluate in the frame of `ns`, as the path tracer's do, so that candidates, shifts and
/// the path tracer share one target function; `v.normal` keeps deciding sides, ray offsets and
/// the measure (docs/shift-mappings.md, "Shading frame").
pub fn vertex_shading(scene: &Scene, v: &Vertex) -> (Material, Vec3) {
    scene.hit_shading(v.triangle, triangle_bary(&scene.triangles[v.triangle as usize], v.pos))
}

/// Direction from `from` to `to` and the distance (infinite for an escaped `to`).
pub(super) fn direction(scene: &Scene, from: &Vertex, to: &Vertex) -> (Vec3, f32) {
    if vertex_is_at_infinity(scene, to) {
        (to.pos, f32::INFINITY)
    } else {
        let d = to.pos - from.pos;
        let len = d.length();
        (d / len, len)
    }
}

pub(crate) fn visible(scene: &Scene, from: &Vertex, to: &Vertex) -> bool {
    if vertex_is_punctual(to) {
        let (dir, dist) = direction(scene, from, to);
        return !punctual_occluded(scene, from.pos, from.normal, from.triangle, dir, dist);
    }
    if !vertex_is_escaped(to) {
        return !segment_occluded(
            &scene.nodes,
            &scene.triangles,
            from.pos,
            from.normal,
            from.triangle,
            to.pos,
            to.normal,
            to.triangle,
        );
    }
    let side = if to.pos.dot(from.normal) > 0.0 { from.normal } else { -from.normal };
    let origin = offset_ray_origin(from.pos, side, &scene.triangles[from.triangle as usize]);
    !trace_occluded(&scene.nodes, &scene.triangles, origin, to.pos, 1e30)
}

/// Radiance emitted by the end vertex `end` towards `from`.
pub(crate) fn end_emission(scene: &Scene, from: &Vertex, end: &Vertex) -> Vec3 {
    if vertex_is_escaped(end) {
        return environment_radiance(scene, end.pos);
    }
    if vertex_is_punctual(end) {
        return punctual_arrival(&scene.lights[vertex_light(end) as usize], from.pos).2;
    }
    let tri = &scene.triangles[end.triangle as usize];
    if tri.emitter == NO_EMITTER {
        return Vec3::ZERO;
    }
    emitted_radiance(scene, end.triangle, triangle_bary(tri, end.pos), (from.pos - end.pos).normalize())
}

/// The pdf that NEE at `from` picks `end` (solid angle); for a punctual light the discrete
/// probability of choosing it. Twin of GLSL `light_pdf`.
pub(super) fn light_pdf(scene: &Scene, from: &Vertex, end: &Vertex) -> f32 {
    let (dir, dist) = direction(scene, from, end);
    if vertex_is_escaped(end) {
        return environment_pdf(scene, dir);
    }
    let punctual = vertex_is_punctual(end);
    let row = if punctual {
        punctual_emitter_row(scene, vertex_light(end))
    } else {
        scene.triangles[end.triangle as usize].emitter
    };
    if row == NO_EMITTER {
        return 0.0;
    }
    let pmf = light_select_pmf(scene, from.pos, from.normal, row);
    if punctual {
        pmf
    } else {
        emitter_area_pdf(scene, pmf, end.triangle, dir, dist)
    }
}

/// Balance-heuristic weight of the technique that ended a path at `end` from `x` (reached from
/// `before`): NEE (`nee_end`) or BSDF sampling, evaluated from the vertices so that a shifted
/// path gets its own weight. After a delta lobe only BSDF sampling reaches the end: weight 1.
pub fn end_mis_weight(scene: &Scene, x: &Vertex, before: Vec3, end: &Vertex, nee_end: bool, after_delta: bool) -> f32 {
    // NEE alone reaches a punctual light.
    if vertex_is_punctual(end) {
        return if nee_end { 1.0 } else { 0.0 };
    }
    if after_delta {
        return if nee_end { 0.0 } else { 1.0 };
    }
    let (dir, _) = direction(scene, x, end);
    let (m, ns) = vertex_shading(scene, x);
    let (_, bsdf_pdf) = bsdf_eval_pdf(&m, x.normal, ns, (before - x.pos).normalize(), dir);
    let light = light_pdf(scene, x, end);
    if nee_end {
        balance_heuristic(light, bsdf_pdf)
    } else {
        balance_heuristic(bsdf_pdf, light)
    }
}

pub(super) fn hit_vertex(scene: &Scene, hit: restir_pt_shading_core::bvh::Hit) -> Vertex {
    let t = &scene.triangles[hit.triangle as usize];
    vertex_on_surface(
        scene,
        hit.triangle,
        Vec3::from(t.v0) + hit.bary.x * Vec3::from(t.e1) + hit.bary.y * Vec3::from(t.e2),
    )
}

/// The primary hit through image point (px, py) of `camera_index`, if any.
pub fn primary_hit(scene: &Scene, camera_index: usize, px: f32, py: f32, width: u32, height: u32) -> Option<Vertex> {
    let cam = &scene.cameras[camera_index];
    let dir = cam.ray_dir(px, py, width, height);
    let hit = trace_closest(&scene.nodes, &scene.triangles, cam.position, dir, 1e30);
    (hit.triangle != NO_HIT).then(|| hit_vertex(scene, hit))
}
