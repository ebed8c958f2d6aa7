//! Alpha tests out of the triangle loops, the twin of glsl/shading_core/alpha_pass.glsl: a traversal pass
//! records, per ray, the nearest hit on a triangle without alpha testing and the nearest
//! alpha-tested hit before it, and `alpha_keeps` runs once after the loop (llvmpipe would run a
//! test inside the loop under a mask on every iteration). A rejected hit sends the ray through
//! another pass only when the pass met more than one alpha-tested hit before the opaque one; that
//! pass counts only hits after the rejected one in (t, triangle index) order, the order in which
//! both traversals visit triangles. The result is the hit a test inside the loop finds: the first
//! of the nearest kept hits. `alpha_pass_new`, `alpha_pass_begin`, `alpha_pass_record` and
//! `alpha_pass_resolve` have GLSL functions of the same names (tests/suite/alpha_oracle.rs).

use glam::{Vec2, Vec3};

use restir_pt_interface::gpu_types::Triangle;

use crate::alpha::{alpha_keeps, AlphaScene};
use crate::bvh::{Hit, NO_HIT};

/// One ray's candidates over a traversal pass (GLSL `AlphaPass`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlphaPass {
    /// Nearest hit on a triangle without alpha testing; `t` = tmax and `NO_HIT` if none.
    pub opaque: Hit,
    /// Nearest alpha-tested hit met while it was nearer than `opaque` then was.
    pub tested: Hit,
    /// Alpha-tested hits met before the then-nearest opaque hit (at least those before it).
    pub count: u32,
    /// Distance of the last rejected hit: hits at or before (`bound_t`, `bound_triangle`) in
    /// (t, index) order do not count (0 before any rejection).
    pub bound_t: f32,
    /// Triangle index of the last rejected hit (`NO_HIT` before any rejection).
    pub bound_triangle: u32,
}

fn no_hit(tmax: f32) -> Hit {
    Hit {
        t: tmax,
        triangle: NO_HIT,
        bary: Vec2::ZERO,
    }
}

/// A ray's state before its first pass up to tmax: every hit with t > 0 counts.
pub fn alpha_pass_new(tmax: f32) -> AlphaPass {
    AlphaPass {
        opaque: no_hit(tmax),
        tested: no_hit(tmax),
        count: 0,
        bound_t: 0.0,
        bound_triangle: NO_HIT,
    }
}

/// Starts a pass up to tmax, keeping the bound.
pub fn alpha_pass_begin(p: &mut AlphaPass, tmax: f32) {
    p.opaque = no_hit(tmax);
    p.tested = p.opaque;
    p.count = 0;
}

/// Records the hit of triangle index `i` at distance `t` (below `p.opaque.t`, as
/// `intersect_triangle` with that tmax returns it) and barycentrics `bary`; `alpha_tested` is
/// the triangle's [`Triangle::alpha_tested`] flag.
pub fn alpha_pass_record(p: &mut AlphaPass, i: u32, alpha_tested: u32, t: f32, bary: Vec2) {
    let counts = t > p.bound_t || (t == p.bound_t && i > p.bound_triangle);
    let opaque = alpha_tested == 0;
    if counts && opaque {
        p.opaque = Hit { t, triangle: i, bary };
    }
    if counts && !opaque {
        p.count += 1;
        if t < p.tested.t {
            p.tested = Hit { t, triangle: i, bary };
        }
    }
}

/// After a pass of the ray (o, d): `Some(hit)` when done (`NO_HIT` for a miss), `None` (the
/// bound moved past the rejected hit) when it needs another pass. With `any_hit`, any opaque hit
/// is the answer.
pub fn alpha_pass_resolve(p: &mut AlphaPass, alpha: &AlphaScene, triangles: &[Triangle], o: Vec3, d: Vec3, any_hit: bool) -> Option<Hit> {
    if any_hit && p.opaque.triangle != NO_HIT {
        return Some(p.opaque);
    }
    // Equal t: the alpha-tested hit was met first, or the opaque one would have excluded it.
    if p.tested.triangle == NO_HIT || p.tested.t > p.opaque.t {
        return Some(p.opaque);
    }
    if alpha_keeps(alpha, triangles, p.tested.triangle, p.tested.bary, o, d) {
        return Some(p.tested);
    }
    if p.count == 1 {
        return Some(p.opaque);
    }
    p.bound_t = p.tested.t;
    p.bound_triangle = p.tested.triangle;
    None
}
