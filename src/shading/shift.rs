//! Shift mappings of ReSTIR PT in the primary-sample-space (PSS) measure: the Rust reference that
//! glsl/shift.glsl is to mirror. A path is regenerated from its primary hit and its seed (the
//! counter-based RNG of src/shading/rng.rs), so random replay needs nothing else; reconnection and hybrid
//! keep the base path's suffix from the reconnection vertex x_r on.
//!
//! Contribution f(X) of a path x0 (camera), x1 (primary hit), ..., xk: the product over the
//! scattering vertices of f_s |cos| / p (p the solid-angle pdf that sampled the next vertex: the
//! BSDF's, or the light's for an NEE end) times the emitted radiance at xk. Jacobians are
//! |du_Y / du_X| of the random numbers: 1 for replay; for a reconnection at x_r from y_{r-1}
//! instead of x_{r-1}
//!   |T'| = [p(y_{r-1} -> x_r) |cos_r(y)| / |y_{r-1} - x_r|^2] / [p(x_{r-1} -> x_r) |cos_r(x)| / |x_{r-1} - x_r|^2]
//!          * p(x_r -> x_{r+1} | y_{r-1}) / p(x_r -> x_{r+1} | x_{r-1}),
//! where the first ratio is 1 for a light point chosen by NEE (area sampling ignores the shading
//! point), only the pdf ratio remains for an escaped direction, and the second ratio is 1 when
//! x_r is the end or x_{r+1} is the NEE end.
//!
//! Punctual (delta) lights end paths only through NEE. Their "pdf" is the discrete probability
//! of choosing the light and their geometry term is 1: the light is one fixed point (or, for a
//! directional light, one direction) whichever vertex joins it, so a reconnection onto it has a
//! first Jacobian ratio of 1. Random replay chooses the same light again (the choice depends on
//! the random number alone); reconnection and hybrid may reconnect onto it as onto any rough end
//! vertex (docs/shift-mappings.md, "Delta lights").

use glam::Vec3;

use crate::gpu_types::{Material, NO_EMITTER, PUNCTUAL_LIGHT_BIT};
use crate::scene::bvh::{segment_occluded, trace_closest, trace_occluded, NO_HIT};
use crate::scene::PunctualKind;
use crate::scene::Scene;
use crate::shading::bsdf::{
    bsdf_eval_pdf, bsdf_sample, has_specular_layer, index_matched, lobe_weights, BsdfSample, DELTA_ALPHA, LOBE_DELTA, LOBE_NONE,
};
use crate::shading::lights::{
    emitted_radiance, emitter_pdf, environment_pdf, environment_radiance, is_punctual_light, punctual_arrival, punctual_occluded,
    punctual_pdf, sample_light, LightSample,
};
use crate::shading::path_record::{record_length, record_lobe, record_nee_end, record_reconnection_index, PathRecord, MAX_PATH_LENGTH};
use crate::shading::ray_offset::offset_ray_origin;
use crate::shading::rng::{rng_uniform4, STREAM_BSDF, STREAM_LIGHT};
use crate::shading::sampling::balance_heuristic;

/// Roughness below which a vertex cannot be a reconnection endpoint (the public reference's 0.2).
pub const DEFAULT_ROUGHNESS_THRESHOLD: f32 = 0.2;
/// The distance threshold as a fraction of the scene's smallest bounding-box extent.
pub const DEFAULT_DISTANCE_FRACTION: f32 = 0.03;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShiftParams {
    pub roughness_threshold: f32,
    pub distance_threshold: f32,
}

impl ShiftParams {
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
    pub pos: Vec3,
    pub normal: Vec3,
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

fn vertex_escaped(dir: Vec3) -> Vertex {
    Vertex {
        pos: dir,
        normal: Vec3::ZERO,
        triangle: NO_HIT,
    }
}

/// A path x1..xk from a camera position, with what regenerating it needs (seed, end type) and
/// what sampling it produced (lobes, pdfs, per-vertex weights).
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    pub seed: u32,
    pub camera: Vec3,
    /// x1..xk.
    pub vertices: Vec<Vertex>,
    /// True if xk is a light sample taken by NEE at x_{k-1}; false if BSDF sampling hit it.
    pub nee_end: bool,
    /// The lobe sampled at x1..x_{k-1} (LOBE_NONE where NEE chose the next vertex).
    pub lobes: Vec<u32>,
    /// f_s |cos| / p at x1..x_{k-1}.
    pub weights: Vec<Vec3>,
    /// f(X); zero if the end emits nothing towards x_{k-1}.
    pub contribution: Vec3,
    /// `end_mis_weight` of the technique that made x_k, as `generate_path` evaluated it.
    pub end_weight: f32,
}

impl Path {
    pub fn length(&self) -> usize {
        self.vertices.len()
    }
}

/// The result of a shift: the shifted path's record and Jacobian, or an explicit failure that
/// carries no value.
#[derive(Debug, Clone, PartialEq)]
pub struct ShiftResult {
    pub valid: bool,
    pub record: PathRecord,
    pub jacobian: f32,
    pub contribution: Vec3,
    /// The vertices the shift made: y1..y_{r-1} for a reconnection, the whole path for a replay.
    pub vertices: Vec<Vertex>,
    /// The reconnection's Jacobian terms, for shifts that reconnected.
    pub reconnection: Option<ReconnectionTerms>,
}

fn shift_failed() -> ShiftResult {
    ShiftResult {
        valid: false,
        record: PathRecord::default(),
        jacobian: 0.0,
        contribution: Vec3::ZERO,
        vertices: vec![],
        reconnection: None,
    }
}

/// A valid shift; a non-finite or non-positive Jacobian counts as a failed shift, never as a
/// value.
fn shift_ok(record: PathRecord, jacobian: f32, vertices: Vec<Vertex>) -> ShiftResult {
    let contribution = record.contribution();
    if !jacobian.is_finite() || jacobian <= 0.0 || !contribution.is_finite() {
        return shift_failed();
    }
    ShiftResult {
        valid: true,
        record,
        jacobian,
        contribution,
        vertices,
        reconnection: None,
    }
}

/// Whether a vertex may be a reconnection endpoint: every lobe of its material is rough
/// (diffuse, or GGX, including a non-metal's specular layer, at least as rough as the threshold).
/// Escaped directions count as rough.
pub fn vertex_is_rough(scene: &Scene, v: &Vertex, params: &ShiftParams) -> bool {
    if vertex_is_escaped(v) || vertex_is_punctual(v) {
        return true;
    }
    let m = &scene.materials[scene.triangles[v.triangle as usize].material as usize];
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

/// The first index r >= 2 (1-based, x_r = vertices[r - 1]) whose pair (x_{r-1}, x_r) passes the
/// reconnection test, if any.
pub fn reconnection_index(scene: &Scene, path: &Path, params: &ShiftParams) -> Option<usize> {
    (2..=path.length()).find(|&r| is_reconnectable(scene, &path.vertices[r - 2], &path.vertices[r - 1], params))
}

pub(crate) fn material_of(scene: &Scene, v: &Vertex) -> Material {
    scene.materials[scene.triangles[v.triangle as usize].material as usize]
}

/// Direction from `from` to `to` and the distance (infinite for an escaped `to`).
fn direction(scene: &Scene, from: &Vertex, to: &Vertex) -> (Vec3, f32) {
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
    emitted_radiance(scene, tri, (from.pos - end.pos).normalize())
}

/// Solid-angle pdf that NEE at `from` picks `end`; for a punctual light the discrete probability
/// of choosing it.
fn light_pdf(scene: &Scene, from: &Vertex, end: &Vertex) -> f32 {
    if vertex_is_punctual(end) {
        return punctual_pdf(scene, vertex_light(end));
    }
    let (dir, dist) = direction(scene, from, end);
    if vertex_is_escaped(end) {
        environment_pdf(scene, dir)
    } else {
        emitter_pdf(scene, end.triangle, dir, dist)
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
    let (_, bsdf_pdf) = bsdf_eval_pdf(&material_of(scene, x), x.normal, x.normal, (before - x.pos).normalize(), dir);
    let light = light_pdf(scene, x, end);
    if nee_end {
        balance_heuristic(light, bsdf_pdf)
    } else {
        balance_heuristic(bsdf_pdf, light)
    }
}

/// Regenerates the path of `length` vertices from the primary hit `x1` seen from `camera`, with
/// the random numbers of `seed`: BSDF sampling at x1..x_{k-2} and, at x_{k-1}, NEE when
/// `nee_end`, else BSDF sampling. `None` if the path ends early (a miss, a failed sample, an
/// occluded light sample) or its end emits nothing towards it.
pub fn generate_path(scene: &Scene, camera: Vec3, x1: Vertex, seed: u32, length: usize, nee_end: bool) -> Option<Path> {
    let mut path = trace_vertices(scene, camera, x1, seed, length, nee_end)?;
    finish_path(scene, &mut path).then_some(path)
}

/// The end weight and contribution of a path whose vertices `trace_vertices` made; false if it
/// carries no light.
fn finish_path(scene: &Scene, path: &mut Path) -> bool {
    let k = path.length();
    let emitted = if k >= 2 {
        let before = if k >= 3 { path.vertices[k - 3].pos } else { path.camera };
        let after_delta = path.lobes[k - 2] & LOBE_DELTA != 0;
        path.end_weight = end_mis_weight(
            scene,
            &path.vertices[k - 2],
            before,
            &path.vertices[k - 1],
            path.nee_end,
            after_delta,
        );
        end_emission(scene, &path.vertices[k - 2], &path.vertices[k - 1]) * path.end_weight
    } else {
        Vec3::ZERO
    };
    path.contribution = path.weights.iter().fold(emitted, |acc, &w| acc * w);
    path.contribution.max_element() > 0.0
}

/// The vertices, lobes and weights of `generate_path`, without the emission at the end.
fn trace_vertices(scene: &Scene, camera: Vec3, x1: Vertex, seed: u32, length: usize, nee_end: bool) -> Option<Path> {
    let mut path = Path {
        seed,
        camera,
        vertices: vec![x1],
        nee_end,
        lobes: Vec::new(),
        weights: Vec::new(),
        contribution: Vec3::ZERO,
        end_weight: 0.0,
    };
    let mut prev_pos = camera;
    while path.length() < length {
        let i = path.length();
        let x = *path.vertices.last().expect("x1 is present");
        if vertex_is_escaped(&x) {
            return None;
        }
        let wo = (prev_pos - x.pos).normalize();
        let m = material_of(scene, &x);
        let (next, lobe, weight) = if i + 1 == length && nee_end {
            let (ls, end) = nee_vertex(scene, &x, seed, i)?;
            if !visible(scene, &x, &end) {
                return None;
            }
            (end, LOBE_NONE, bsdf_eval_pdf(&m, x.normal, x.normal, wo, ls.dir).0 / ls.pdf)
        } else {
            let (s, next) = bsdf_vertex(scene, &x, wo, &m, seed, i)?;
            (next, s.lobe, s.weight)
        };
        path.lobes.push(lobe);
        path.weights.push(weight);
        path.vertices.push(next);
        prev_pos = x.pos;
    }
    Some(path)
}

/// The light point NEE at x_i chooses with the path's random numbers, and its light sample;
/// `None` if none can be chosen. Visibility is left to the caller.
pub(crate) fn nee_vertex(scene: &Scene, x: &Vertex, seed: u32, i: usize) -> Option<(LightSample, Vertex)> {
    let ls = sample_light(scene, x.pos, rng_uniform4(seed, i as u32, STREAM_LIGHT).truncate());
    if !(ls.pdf > 0.0) {
        return None;
    }
    let light = if is_punctual_light(ls.triangle) {
        vertex_punctual(scene, ls.triangle)
    } else if ls.triangle == NO_EMITTER {
        vertex_escaped(ls.dir)
    } else {
        vertex_on_surface(scene, ls.triangle, x.pos + ls.dir * ls.dist)
    };
    Some((ls, light))
}

/// The BSDF sample at x_i (material `m`, leaving towards `wo`) drawn with the path's random
/// numbers, and the vertex its ray reaches (its hit, or the environment); `None` if no lobe was
/// sampled.
pub(crate) fn bsdf_vertex(scene: &Scene, x: &Vertex, wo: Vec3, m: &Material, seed: u32, i: usize) -> Option<(BsdfSample, Vertex)> {
    let s = bsdf_sample(m, x.normal, x.normal, wo, rng_uniform4(seed, i as u32, STREAM_BSDF));
    if s.lobe == LOBE_NONE {
        return None;
    }
    let side = if s.wi.dot(x.normal) > 0.0 { x.normal } else { -x.normal };
    let origin = offset_ray_origin(x.pos, side, &scene.triangles[x.triangle as usize]);
    let hit = trace_closest(&scene.nodes, &scene.triangles, origin, s.wi, 1e30);
    let next = if hit.triangle == NO_HIT {
        vertex_escaped(s.wi)
    } else {
        hit_vertex(scene, hit)
    };
    Some((s, next))
}

fn hit_vertex(scene: &Scene, hit: crate::scene::bvh::Hit) -> Vertex {
    let t = &scene.triangles[hit.triangle as usize];
    vertex_on_surface(
        scene,
        hit.triangle,
        Vec3::from(t.v0) + hit.bary.x * Vec3::from(t.e1) + hit.bary.y * Vec3::from(t.e2),
    )
}

/// The record of `path`: its reconnection index and the base-side Jacobian terms there, the
/// suffix's radiance and the contribution. `None` if the path is longer than a record holds, or
/// if, evaluated from its vertices, its reconnection carries no light (grazing edges whose
/// sampled direction and vertex-to-vertex direction fall on two sides of a surface).
pub fn record_path(scene: &Scene, params: &ShiftParams, path: &Path) -> Option<PathRecord> {
    let k = path.length();
    if k > MAX_PATH_LENGTH {
        return None;
    }
    let r = reconnection_index(scene, path, params);
    let mut record = PathRecord {
        seed: path.seed,
        info: PathRecord::pack_info(k, r, path.nee_end),
        lobes: PathRecord::pack_lobes(&path.lobes),
        rc_triangle: NO_HIT,
        rc_pdf: 1.0,
        rc_geometry: 1.0,
        suffix: [1.0; 3],
        rc_pdf_after: 1.0,
        rc_next_triangle: NO_HIT,
        contribution: path.contribution.into(),
        ..Default::default()
    };
    let Some(r) = r else { return Some(record) };
    let x_r = path.vertices[r - 1];
    record.rc_triangle = x_r.triangle;
    record.rc_pos = x_r.pos.into();
    if r < k {
        let x_next = path.vertices[r];
        record.rc_next = x_next.pos.into();
        record.rc_next_triangle = x_next.triangle;
        let mut emitted = end_emission(scene, &path.vertices[k - 2], &path.vertices[k - 1]);
        // The end's MIS weight belongs to the suffix unless x_r is the last scattering vertex,
        // whose incoming direction a join changes.
        if r + 1 < k {
            emitted *= path.end_weight;
        }
        record.suffix = path.weights[r..].iter().fold(emitted, |acc, &w| acc * w).into();
    }
    // The edges into and out of x_r are evaluated from the vertices, as every shift evaluates
    // them: the sampled directions left from offset origins and differ slightly, which grazing
    // angles magnify.
    let x_before = if r >= 3 { path.vertices[r - 3].pos } else { path.camera };
    let joined = join_at_reconnection(
        scene,
        &record,
        &path.vertices[r - 2],
        x_before,
        &x_r,
        path.weights[..r - 2].iter().product(),
    )?;
    Some(joined.record)
}

/// A path joined at x_r: the record with the terms from the given predecessor, and the Jacobian
/// terms on that side.
struct Joined {
    record: PathRecord,
    pdf_after: Option<f32>,
}

/// Joins the predecessor `prev` (reached from `before`, with prefix weight `prefix_weight` for
/// the vertices before it) to the record's x_r: the pdf and geometry of the edge, the pdf out of
/// x_r, and the contribution. `None` where the join carries no light or is impossible.
fn join_at_reconnection(
    scene: &Scene,
    base: &PathRecord,
    prev: &Vertex,
    before: Vec3,
    x_r: &Vertex,
    prefix_weight: Vec3,
) -> Option<Joined> {
    let (k, r) = (record_length(base), record_reconnection_index(base)?);
    let link = reconnection_link(scene, prev, before, x_r, r == k && record_nee_end(base));
    if !(link.pdf > 0.0) || link.f_cos.max_element() <= 0.0 {
        return None;
    }
    let mut record = PathRecord {
        rc_pdf: link.pdf,
        rc_geometry: link.geometry,
        rc_pdf_after: 1.0,
        ..*base
    };
    let weight = prefix_weight * link.f_cos / link.pdf;
    let mut pdf_after_x_r = None;
    let contribution = if r == k {
        let after_delta = record_lobe(base, k - 1) & LOBE_DELTA != 0;
        weight * end_emission(scene, prev, x_r) * end_mis_weight(scene, prev, before, x_r, record_nee_end(base), after_delta)
    } else {
        // x_r scatters towards x_{r+1} with this predecessor's incoming direction.
        let x_next = record_vertex(scene, base.rc_next_triangle, base.rc_next);
        let next_is_nee = r + 1 == k && record_nee_end(base);
        let (f_r, q) = pdf_after(scene, x_r, link.dir, &x_next, next_is_nee);
        if !(q > 0.0) || f_r.max_element() <= 0.0 || record_lobe(base, r) & LOBE_DELTA != 0 {
            return None;
        }
        if !next_is_nee {
            record.rc_pdf_after = q;
            pdf_after_x_r = Some(q);
        }
        let end_weight = if r + 1 == k {
            end_mis_weight(scene, x_r, prev.pos, &x_next, record_nee_end(base), false)
        } else {
            1.0
        };
        weight * f_r / q * Vec3::from(base.suffix) * end_weight
    };
    if !(contribution.max_element() > 0.0) {
        return None;
    }
    record.contribution = contribution.into();
    Some(Joined {
        record,
        pdf_after: pdf_after_x_r,
    })
}

/// The edge from a predecessor to x_r: its direction, f_s |cos| at the predecessor, the pdf that
/// chose x_r from it and the geometry term |cos_r| / d^2 at x_r.
struct Link {
    dir: Vec3,
    f_cos: Vec3,
    pdf: f32,
    geometry: f32,
}

fn reconnection_link(scene: &Scene, prev: &Vertex, before: Vec3, x_r: &Vertex, nee_at_r: bool) -> Link {
    let (dir, dist) = direction(scene, prev, x_r);
    let (f_cos, bsdf_pdf) = bsdf_eval_pdf(
        &material_of(scene, prev),
        prev.normal,
        prev.normal,
        (before - prev.pos).normalize(),
        dir,
    );
    let pdf = if nee_at_r { light_pdf(scene, prev, x_r) } else { bsdf_pdf };
    // A punctual x_r is one fixed point or direction whatever joins it: no area factor.
    let geometry = if vertex_is_escaped(x_r) || vertex_is_punctual(x_r) {
        1.0
    } else {
        x_r.normal.dot(dir).abs() / (dist * dist)
    };
    Link { dir, f_cos, pdf, geometry }
}

/// f_s |cos| at x_r arriving along `dir_in` and leaving to `next`, and the pdf that chose `next`
/// from x_r (the light's when NEE chose it).
fn pdf_after(scene: &Scene, x_r: &Vertex, dir_in: Vec3, next: &Vertex, next_is_nee: bool) -> (Vec3, f32) {
    let (dir_next, _) = direction(scene, x_r, next);
    let (f_cos, pdf) = bsdf_eval_pdf(&material_of(scene, x_r), x_r.normal, x_r.normal, -dir_in, dir_next);
    (f_cos, if next_is_nee { light_pdf(scene, x_r, next) } else { pdf })
}

fn record_vertex(scene: &Scene, triangle: u32, pos: [f32; 3]) -> Vertex {
    if is_punctual_light(triangle) {
        vertex_punctual(scene, triangle)
    } else if triangle == NO_HIT {
        vertex_escaped(Vec3::from(pos))
    } else {
        vertex_on_surface(scene, triangle, Vec3::from(pos))
    }
}

/// Random replay: regenerate the record's random numbers from the target's primary hit. Valid
/// only with the same length, end type and lobes at every vertex; Jacobian 1.
pub fn shift_random_replay(scene: &Scene, params: &ShiftParams, base: &PathRecord, camera: Vec3, y1: Vertex) -> ShiftResult {
    let replayed = generate_path(scene, camera, y1, base.seed, record_length(base), record_nee_end(base));
    match replayed.as_ref().and_then(|y| Some((y, record_path(scene, params, y)?))) {
        Some((y, record)) if record.lobes == base.lobes => shift_ok(record, 1.0, y.vertices.clone()),
        _ => shift_failed(),
    }
}

/// The inverse of random replay is random replay back to the base's primary hit.
pub fn inverse_random_replay(scene: &Scene, params: &ShiftParams, shifted: &PathRecord, camera: Vec3, x1: Vertex) -> ShiftResult {
    shift_random_replay(scene, params, shifted, camera, x1)
}

/// Hybrid shift: replay up to x_{r-1} (r the record's reconnection index), then reconnect to x_r
/// and keep the suffix. Without a reconnection index it is random replay; it fails where the
/// replayed prefix would reconnect earlier than r, so that its inverse is defined.
pub fn shift_hybrid(scene: &Scene, params: &ShiftParams, base: &PathRecord, camera: Vec3, y1: Vertex) -> ShiftResult {
    match record_reconnection_index(base) {
        None => {
            let replay = shift_random_replay(scene, params, base, camera, y1);
            if replay.valid && record_reconnection_index(&replay.record).is_none() {
                replay
            } else {
                shift_failed()
            }
        }
        Some(r) => reconnect_at(scene, params, base, camera, y1, r),
    }
}

/// The inverse of the hybrid shift is the hybrid shift back: the shifted record has the same
/// reconnection index, seed and suffix.
pub fn inverse_hybrid(scene: &Scene, params: &ShiftParams, shifted: &PathRecord, camera: Vec3, x1: Vertex) -> ShiftResult {
    shift_hybrid(scene, params, shifted, camera, x1)
}

/// Reconnection shift: y0, y1 of the target, then x2..xk of the base. Valid only if the base
/// reconnects at r = 2 (x1 and x2 rough, far enough apart) and so does the shifted path.
pub fn shift_reconnection(scene: &Scene, params: &ShiftParams, base: &PathRecord, camera: Vec3, y1: Vertex) -> ShiftResult {
    match record_reconnection_index(base) {
        Some(2) => reconnect_at(scene, params, base, camera, y1, 2),
        _ => shift_failed(),
    }
}

/// The inverse of the reconnection shift is the reconnection shift back to x1.
pub fn inverse_reconnection(scene: &Scene, params: &ShiftParams, shifted: &PathRecord, camera: Vec3, x1: Vertex) -> ShiftResult {
    shift_reconnection(scene, params, shifted, camera, x1)
}

/// Replays y1..y_{r-1} and reconnects y_{r-1} to the record's x_r (1-based indices).
fn reconnect_at(scene: &Scene, params: &ShiftParams, base: &PathRecord, camera: Vec3, y1: Vertex, r: usize) -> ShiftResult {
    // The replayed prefix y1..y_{r-1}: BSDF sampling only, whatever the base's end type.
    let Some(prefix) = trace_vertices(scene, camera, y1, base.seed, r - 1, false) else {
        return shift_failed();
    };
    if (1..r - 1).any(|i| prefix.lobes[i - 1] != record_lobe(base, i)) {
        return shift_failed();
    }
    // Invertibility: the shifted path must first become reconnectable at r, not earlier.
    if (2..r).any(|i| is_reconnectable(scene, &prefix.vertices[i - 2], &prefix.vertices[i - 1], params)) {
        return shift_failed();
    }
    let y_prev = prefix.vertices[r - 2];
    let x_r = record_vertex(scene, base.rc_triangle, base.rc_pos);
    if !is_reconnectable(scene, &y_prev, &x_r, params) || !visible(scene, &y_prev, &x_r) {
        return shift_failed();
    }
    let y_before = if r >= 3 { prefix.vertices[r - 3].pos } else { camera };
    let prefix_weight = prefix.weights.iter().product();
    let Some(joined) = join_at_reconnection(scene, base, &y_prev, y_before, &x_r, prefix_weight) else {
        return shift_failed();
    };
    if !(base.rc_pdf > 0.0 && base.rc_pdf_after > 0.0) {
        return shift_failed();
    }
    let terms = ReconnectionTerms {
        geometry_y: joined.record.rc_geometry,
        geometry_x: base.rc_geometry,
        pdf_y: joined.record.rc_pdf,
        pdf_x: base.rc_pdf,
        pdf_after_y: joined.pdf_after.unwrap_or(1.0),
        pdf_after_x: joined.pdf_after.map_or(1.0, |_| base.rc_pdf_after),
    };
    let mut result = shift_ok(joined.record, terms.jacobian(), prefix.vertices);
    if result.valid {
        result.reconnection = Some(terms);
    }
    result
}

/// The parts of a reconnection's Jacobian: the solid-angle-to-area factor |cos_r| / d^2 at x_r
/// seen from each predecessor (1 for an escaped x_r) and the pdfs that chose x_r and x_{r+1}.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReconnectionTerms {
    pub geometry_y: f32,
    pub geometry_x: f32,
    pub pdf_y: f32,
    pub pdf_x: f32,
    pub pdf_after_y: f32,
    pub pdf_after_x: f32,
}

impl ReconnectionTerms {
    pub fn jacobian(&self) -> f32 {
        (self.pdf_y * self.geometry_y) / (self.pdf_x * self.geometry_x) * (self.pdf_after_y / self.pdf_after_x)
    }
}

/// The primary hit through image point (px, py) of `camera_index`, if any.
pub fn primary_hit(scene: &Scene, camera_index: usize, px: f32, py: f32, width: u32, height: u32) -> Option<Vertex> {
    let cam = &scene.cameras[camera_index];
    let dir = cam.ray_dir(px, py, width, height);
    let hit = trace_closest(&scene.nodes, &scene.triangles, cam.position, dir, 1e30);
    (hit.triangle != NO_HIT).then(|| hit_vertex(scene, hit))
}
