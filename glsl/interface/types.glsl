// The scene records (Material, Triangle, BvhNode, Emitter, LightNode) and the constants of their
// encodings. Both are declared once, in Rust (crates/interface/src/gpu_types.rs), and reach GLSL
// through the generated header; this file names what a scene include needs.
#ifndef TYPES_GLSL
#define TYPES_GLSL

#include "shader_interface.glsl"

#endif
