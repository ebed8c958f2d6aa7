//! Shift mappings of ReSTIR PT in the primary-sample-space (PSS) measure: the Rust reference that
//! glsl/shading/shift.glsl is to mirror, file by file: `vertex.rs` (glsl/shading/shift/vertex.glsl), `path.rs`
//! (glsl/shading/shift/path.glsl), `reconnection.rs` (glsl/shading/shift/reconnection.glsl) and the shifts here
//! (glsl/shading/shift.glsl). A path is regenerated from its primary hit and its seed (the counter-based RNG
//! of crates/shading-core/src/rng.rs), so random replay needs nothing else; reconnection and hybrid keep the
//! base path's suffix from the reconnection vertex x_r on.
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

mod path;
mod reconnection;
mod vertex;

use glam::Vec3;

pub use path::*;
pub use reconnection::*;
pub use vertex::*;

use path::{shift_failed, shift_ok};
use reconnection::reconnect_at;
use restir_pt_scene::Scene;

use crate::path_record::{record_length, record_nee_directional, record_nee_end, record_reconnection_index, PathRecord};

/// Random replay: regenerate the record's random numbers from the target's primary hit. Valid
/// only with the same length, end type (and NEE technique) and lobes at every vertex; Jacobian 1.
pub fn shift_random_replay(scene: &Scene, params: &ShiftParams, base: &PathRecord, camera: Vec3, y1: Vertex) -> ShiftResult {
    let replayed = generate_path(
        scene,
        camera,
        y1,
        base.seed,
        record_length(base),
        record_nee_end(base),
        record_nee_directional(base),
    );
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
