//! Paths regenerated in primary sample space from a primary hit and a seed (random replay's map,
//! and the replayed prefix of the hybrid shift), and the result every shift returns. Twin of
//! glsl/shading/shift/path.glsl.

use glam::Vec3;

use restir_pt_interface::gpu_types::{Material, NO_EMITTER};
use restir_pt_scene::Scene;
use restir_pt_shading_core::bvh::{trace_closest, NO_HIT};

use super::reconnection::ReconnectionTerms;
use super::vertex::{
    end_emission, end_mis_weight, hit_vertex, is_reconnectable, vertex_escaped, vertex_is_escaped, vertex_on_surface, vertex_punctual,
    vertex_shading, visible, ShiftParams, Vertex,
};
use crate::bsdf::{bsdf_eval_pdf, bsdf_sample, BsdfSample, LOBE_DELTA, LOBE_NONE};
use crate::lights::{is_punctual_light, sample_directional, sample_light, LightSample};
use crate::path_record::PathRecord;
use crate::ray_offset::offset_ray_origin;
use crate::rng::{rng_uniform4, STREAM_BSDF, STREAM_LIGHT};

/// A path x1..xk from a camera position, with what regenerating it needs (seed, end type) and
/// what sampling it produced (lobes, pdfs, per-vertex weights).
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    /// The path's random-number key ([`crate::rng::path_seed`]).
    pub seed: u32,
    /// The camera position x0, scene coordinates.
    pub camera: Vec3,
    /// x1..xk.
    pub vertices: Vec<Vertex>,
    /// True if xk is a light sample taken by NEE at x_{k-1}; false if BSDF sampling hit it.
    pub nee_end: bool,
    /// NEE's technique at the end: 0 for the light it draws (`sample_light`), k + 1 for
    /// directional light k, which it takes at every vertex (`sample_directional`).
    pub nee_directional: u32,
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
    /// k, the number of vertices after the camera.
    pub fn length(&self) -> usize {
        self.vertices.len()
    }
}

/// The result of a shift: the shifted path's record and Jacobian, or an explicit failure that
/// carries no value.
#[derive(Debug, Clone, PartialEq)]
pub struct ShiftResult {
    /// Whether the shift produced a path; when false every other field is zero or empty.
    pub valid: bool,
    /// The shifted path's record, as a reservoir would store it.
    pub record: PathRecord,
    /// The shift's Jacobian determinant in primary sample space, |dU_Y / dU_X|
    /// (docs/shift-mappings.md); finite and positive when valid.
    pub jacobian: f32,
    /// f(T(x)) of the shifted path, linear RGB (the record's contribution).
    pub contribution: Vec3,
    /// The vertices the shift made: y1..y_{r-1} for a reconnection, the whole path for a replay.
    pub vertices: Vec<Vertex>,
    /// The reconnection's Jacobian terms, for shifts that reconnected.
    pub reconnection: Option<ReconnectionTerms>,
}

pub(super) fn shift_failed() -> ShiftResult {
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
pub(super) fn shift_ok(record: PathRecord, jacobian: f32, vertices: Vec<Vertex>) -> ShiftResult {
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

/// The first index r >= 2 (1-based, x_r = vertices[r - 1]) whose pair (x_{r-1}, x_r) passes the
/// reconnection test, if any.
pub fn reconnection_index(scene: &Scene, path: &Path, params: &ShiftParams) -> Option<usize> {
    (2..=path.length()).find(|&r| is_reconnectable(scene, &path.vertices[r - 2], &path.vertices[r - 1], params))
}

/// Regenerates the path of `length` vertices from the primary hit `x1` seen from `camera`, with
/// the random numbers of `seed`: BSDF sampling at x1..x_{k-2} and, at x_{k-1}, NEE when
/// `nee_end` (with technique `nee_directional`, as [`Path::nee_directional`]), else BSDF
/// sampling. `None` if the path ends early (a miss, a failed sample, an occluded light sample)
/// or its end emits nothing towards it.
pub fn generate_path(
    scene: &Scene,
    camera: Vec3,
    x1: Vertex,
    seed: u32,
    length: usize,
    nee_end: bool,
    nee_directional: u32,
) -> Option<Path> {
    let mut path = trace_vertices(scene, camera, x1, seed, length, nee_end, nee_directional)?;
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
pub(super) fn trace_vertices(
    scene: &Scene,
    camera: Vec3,
    x1: Vertex,
    seed: u32,
    length: usize,
    nee_end: bool,
    nee_directional: u32,
) -> Option<Path> {
    let mut path = Path {
        seed,
        camera,
        vertices: vec![x1],
        nee_end,
        nee_directional,
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
        let (m, ns) = vertex_shading(scene, &x);
        let (next, lobe, weight) = if i + 1 == length && nee_end {
            let (ls, end) = nee_vertex(scene, &x, seed, i, nee_directional)?;
            if !visible(scene, &x, &end) {
                return None;
            }
            (end, LOBE_NONE, bsdf_eval_pdf(&m, x.normal, ns, wo, ls.dir).0 / ls.pdf)
        } else {
            let (s, next) = bsdf_vertex(scene, &x, wo, &m, ns, seed, i)?;
            (next, s.lobe, s.weight)
        };
        path.lobes.push(lobe);
        path.weights.push(weight);
        path.vertices.push(next);
        prev_pos = x.pos;
    }
    Some(path)
}

/// The light point NEE at x_i takes with technique `directional` (directional light
/// `directional` - 1, or for 0 the light it draws with the path's random numbers), and its
/// light sample; `None` if none can be chosen. Visibility is left to the caller.
pub(crate) fn nee_vertex(scene: &Scene, x: &Vertex, seed: u32, i: usize, directional: u32) -> Option<(LightSample, Vertex)> {
    let ls = if directional > 0 {
        sample_directional(scene, directional - 1)
    } else {
        sample_light(scene, x.pos, x.normal, rng_uniform4(seed, i as u32, STREAM_LIGHT).truncate())
    };
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

/// The BSDF sample at x_i (material `m`, shading normal `ns` from `vertex_shading`, leaving
/// towards `wo`) drawn with the path's random numbers, and the vertex its ray, offset along the
/// geometric normal, reaches (its hit, or the environment); `None` if no lobe was sampled.
pub(crate) fn bsdf_vertex(
    scene: &Scene,
    x: &Vertex,
    wo: Vec3,
    m: &Material,
    ns: Vec3,
    seed: u32,
    i: usize,
) -> Option<(BsdfSample, Vertex)> {
    let s = bsdf_sample(m, x.normal, ns, wo, rng_uniform4(seed, i as u32, STREAM_BSDF));
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
