//! The reconnection of a predecessor to a record's x_r: the edge's BSDF, pdf and geometry term,
//! the BSDF at x_r towards x_{r+1}, the Jacobian of the shift that makes it, and the path record
//! that caches the base side's terms. Twin of glsl/shading/shift/reconnection.glsl.

use glam::Vec3;

use restir_pt_scene::Scene;
use restir_pt_shading_core::bvh::NO_HIT;

use super::path::{reconnection_index, shift_failed, shift_ok, trace_vertices, Path, ShiftResult};
use super::vertex::{
    direction, end_emission, end_mis_weight, is_reconnectable, light_pdf, vertex_escaped, vertex_is_escaped, vertex_is_punctual,
    vertex_on_surface, vertex_punctual, vertex_shading, visible, ShiftParams, Vertex,
};
use crate::bsdf::{bsdf_eval_pdf, LOBE_DELTA};
use crate::lights::is_punctual_light;
use crate::path_record::{record_length, record_lobe, record_nee_end, record_reconnection_index, PathRecord, MAX_PATH_LENGTH};

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
        info: PathRecord::pack_info(k, r, path.nee_end, path.nee_directional),
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
    let (m, ns) = vertex_shading(scene, prev);
    let (f_cos, bsdf_pdf) = bsdf_eval_pdf(&m, prev.normal, ns, (before - prev.pos).normalize(), dir);
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
    let (m, ns) = vertex_shading(scene, x_r);
    let (f_cos, pdf) = bsdf_eval_pdf(&m, x_r.normal, ns, -dir_in, dir_next);
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

/// Replays y1..y_{r-1} and reconnects y_{r-1} to the record's x_r (1-based indices).
pub(super) fn reconnect_at(scene: &Scene, params: &ShiftParams, base: &PathRecord, camera: Vec3, y1: Vertex, r: usize) -> ShiftResult {
    // The replayed prefix y1..y_{r-1}: BSDF sampling only, whatever the base's end type.
    let Some(prefix) = trace_vertices(scene, camera, y1, base.seed, r - 1, false, 0) else {
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
    /// |cos_r| / |y_{r-1} - x_r|² on the offset path (1 for an escaped x_r).
    pub geometry_y: f32,
    /// |cos_r| / |x_{r-1} - x_r|² on the base path (1 for an escaped x_r).
    pub geometry_x: f32,
    /// Solid-angle pdf with which the offset path's y_{r-1} would choose x_r.
    pub pdf_y: f32,
    /// Solid-angle pdf with which the base path's x_{r-1} chose x_r.
    pub pdf_x: f32,
    /// p(x_r -> x_{r+1} | y_{r-1}) on the offset path; 1 when x_r ends the path or NEE chose x_{r+1}.
    pub pdf_after_y: f32,
    /// p(x_r -> x_{r+1} | x_{r-1}) on the base path; 1 in the same cases.
    pub pdf_after_x: f32,
}

impl ReconnectionTerms {
    /// The reconnection shift's Jacobian in primary sample space,
    /// (p_y G_y) / (p_x G_x) · (p_after_y / p_after_x), unitless (Lin et al. 2022, reconnection shift).
    pub fn jacobian(&self) -> f32 {
        (self.pdf_y * self.geometry_y) / (self.pdf_x * self.geometry_x) * (self.pdf_after_y / self.pdf_after_x)
    }
}
