// Counter-based random numbers keyed by (pixel, sample, seed) -> path seed, then by
// (path seed, vertex, stream). Any prefix of a path can be regenerated from its seed alone,
// which random replay relies on. Twin: crates/shading-core/src/rng.rs (bit-exact).
#ifndef RNG_GLSL
#define RNG_GLSL

// The streams used at each vertex (STREAM_*) are in the generated header.
#include "shader_interface.glsl"

// The 4D permuted congruential hash of Jarzynski and Olano (JCGT 2020).
uvec4 pcg4d(uvec4 v) {
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
    v ^= v >> 16u;
    v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
    return v;
}

uint path_seed(uint pixel, uint sample_index, uint seed) {
    return pcg4d(uvec4(pixel, sample_index, seed, 0x9e3779b9u)).x;
}

// 24 random bits to a float in [0, 1): exact in f32, identical on host and device.
float u32_to_unit_float(uint x) {
    return float(x >> 8u) * (1.0 / 16777216.0);
}

// Four uniforms for stream `stream` at path vertex `vertex`.
vec4 rng_uniform4(uint seed, uint vertex, uint stream) {
    uvec4 h = pcg4d(uvec4(seed, vertex, stream, 0x68e31da4u));
    return vec4(u32_to_unit_float(h.x), u32_to_unit_float(h.y), u32_to_unit_float(h.z), u32_to_unit_float(h.w));
}

#endif
