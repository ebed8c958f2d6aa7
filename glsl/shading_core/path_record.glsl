// The path sample a reservoir stores (80 bytes). Twin: crates/shading-core/src/path_record.rs.
#ifndef PATH_RECORD_GLSL
#define PATH_RECORD_GLSL

#include "shader_interface.glsl"

uint record_length(PathRecord r) { return r.info & INFO_LENGTH_MASK; }
uint record_reconnection_index(PathRecord r) { return (r.info >> INFO_RC_SHIFT) & 15u; }
bool record_nee_end(PathRecord r) { return (r.info & INFO_NEE_END) != 0u; }
uint record_lobe(PathRecord r, uint i) { return (r.lobes >> (LOBE_BITS * (i - 1u))) & ((1u << LOBE_BITS) - 1u); }
uint record_nee_directional(PathRecord r) { return r.info >> INFO_DIRECTIONAL_SHIFT; }
uint pack_info(uint length, uint reconnection, bool nee_end, uint nee_directional) {
    return length | (reconnection << INFO_RC_SHIFT) | (nee_end ? INFO_NEE_END : 0u) | (nee_directional << INFO_DIRECTIONAL_SHIFT);
}

#endif
