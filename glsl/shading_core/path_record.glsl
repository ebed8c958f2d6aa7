// The path sample a reservoir stores (80 bytes). Twin: crates/shading-core/src/path_record.rs.
#ifndef PATH_RECORD_GLSL
#define PATH_RECORD_GLSL

#include "shader_interface.glsl"

const uint LOBE_BITS = 5u;
const uint INFO_LENGTH_MASK = 15u;
const uint INFO_RC_SHIFT = 4u;
const uint INFO_NEE_END = 256u;
const uint INFO_DIRECTIONAL_SHIFT = 9u;

struct PathRecord {
    uint seed;
    uint info;             // bits 0-3: length k; 4-7: reconnection index r (0: none); 8: NEE end;
                           // 9-31: NEE's technique (0: the drawn light; k + 1: directional light k)
    uint lobes;            // the lobe sampled at x1..x6, 5 bits each
    uint rc_triangle;      // x_r's triangle; NO_HIT if x_r is an escaped direction
    vec3 rc_pos;           // x_r, or its direction
    float rc_pdf;          // pdf that chose x_r from x_{r-1}
    vec3 rc_next;          // x_{r+1}, or its direction
    float rc_geometry;     // |cos_r| / |x_{r-1} - x_r|^2 (1 if escaped)
    vec3 suffix;           // what x_r receives from the suffix
    float rc_pdf_after;    // p(x_r -> x_{r+1} | x_{r-1}); 1 if x_r ends the path or x_{r+1} is the NEE end
    vec3 contribution;     // f(X)
    uint rc_next_triangle; // x_{r+1}'s triangle; NO_HIT if escaped
};

uint record_length(PathRecord r) { return r.info & INFO_LENGTH_MASK; }
uint record_reconnection_index(PathRecord r) { return (r.info >> INFO_RC_SHIFT) & 15u; }
bool record_nee_end(PathRecord r) { return (r.info & INFO_NEE_END) != 0u; }
uint record_lobe(PathRecord r, uint i) { return (r.lobes >> (LOBE_BITS * (i - 1u))) & ((1u << LOBE_BITS) - 1u); }
uint record_nee_directional(PathRecord r) { return r.info >> INFO_DIRECTIONAL_SHIFT; }
uint pack_info(uint length, uint reconnection, bool nee_end, uint nee_directional) {
    return length | (reconnection << INFO_RC_SHIFT) | (nee_end ? INFO_NEE_END : 0u) | (nee_directional << INFO_DIRECTIONAL_SHIFT);
}

#endif
