// Scene records shared with the host. Twin: src/gpu_types.rs (a test checks every offset).
#ifndef TYPES_GLSL
#define TYPES_GLSL

struct Material {
    vec3 base_color;
    float metallic;
    vec3 emission;      // already multiplied by KHR_materials_emissive_strength
    float roughness;    // linear (perceptual) roughness; GGX alpha = roughness^2
    float transmission;
    float ior;
    uint flags;
    uint pad;
};
const uint MATERIAL_DOUBLE_SIDED = 1u;

// Vertex 0 and two edges, so that intersection needs no subtraction.
struct Triangle {
    vec3 v0;
    uint material;
    vec3 e1;
    uint emitter;       // index into the emitter table, NO_EMITTER if not emissive
    vec3 e2;
    uint pad;
};
const uint NO_EMITTER = 0xffffffffu;

// Interior nodes have count 0: left child is the next node, right child is `index`.
// Leaves cover triangles [index, index + count).
struct BvhNode {
    vec3 lo;
    uint index;
    vec3 hi;
    uint count;
};

// One emissive triangle with its alias-table entry (selection proportional to power).
struct Emitter {
    uint triangle;
    float select_pdf;
    float alias_prob;
    uint alias;
};

#endif
