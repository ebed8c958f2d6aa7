//! The functions that read a reservoir's path sample ([`PathRecord`], a record of the interface
//! crate): twins of glsl/shading_core/path_record.glsl.

pub use restir_pt_interface::path_record::{PathRecord, INFO_DIRECTIONAL_SHIFT, INFO_LENGTH_MASK, INFO_NEE_END, INFO_RC_SHIFT, LOBE_BITS};
pub use restir_pt_interface::shader_interface::MAX_PATH_LENGTH;

/// The path's length k (its vertices x1..xk).
pub fn record_length(r: &PathRecord) -> usize {
    (r.info & INFO_LENGTH_MASK) as usize
}

/// The reconnection index r (1-based: x_r is the r-th vertex after the camera).
pub fn record_reconnection_index(r: &PathRecord) -> Option<usize> {
    match (r.info >> INFO_RC_SHIFT) & 0xf {
        0 => None,
        i => Some(i as usize),
    }
}

/// Whether NEE chose the path's last vertex.
pub fn record_nee_end(r: &PathRecord) -> bool {
    r.info & INFO_NEE_END != 0
}

/// Which NEE technique made the path's end: 0 for the light NEE draws, k + 1 for directional
/// light k (always 0 when the end is not NEE's).
pub fn record_nee_directional(r: &PathRecord) -> u32 {
    r.info >> INFO_DIRECTIONAL_SHIFT
}

/// The lobe sampled at x_i (1-based).
pub fn record_lobe(r: &PathRecord, i: usize) -> u32 {
    (r.lobes >> (LOBE_BITS * (i as u32 - 1))) & ((1 << LOBE_BITS) - 1)
}
