// The scene's surface attributes and textures: descriptor set 1 of scene kernels (set 0 keeps the
// frame parameters and the scene arrays that traversal reads). Only kernels of a scene that has
// them declare these bindings: SCENE_SURFACE (vertex normals, tangents, texture coordinates) and
// SCENE_TEXTURES (textures, which need the coordinates), set by src/render/scene_gpu.rs.
// Twins: crates/shading-core/src/surface.rs (TriangleSurface), crates/shading-core/src/texture.rs (TextureHeader, TextureSlot,
// MaterialTextures).
#ifndef SURFACE_BINDINGS_GLSL
#define SURFACE_BINDINGS_GLSL

#include "shader_interface.glsl"

#ifndef SCENE_SURFACE
#define SCENE_SURFACE 0
#endif
#ifndef SCENE_TEXTURES
#define SCENE_TEXTURES 0
#endif
// The set and the first binding of SurfaceBinding (crates/interface/src/shader_interface.rs). Oracle kernels,
// which bind everything in set 0, move these bindings there.
#ifndef SURFACE_SET
#define SURFACE_SET SURFACE_DESCRIPTOR_SET
#define SURFACE_BINDING 0
#endif

// One triangle's vertex attributes, in the triangles' order (scene space).
struct TriangleSurface {
    vec4 normal[3];     // xyz: vertex normal (zero: none, the face normal is used); w: COLOR_0 bits
    vec4 tangent[3];    // xyz: vertex tangent, w: handedness (bitangent = w * cross(n, t))
    vec4 uv[3];         // xy: TEXCOORD_0, zw: TEXCOORD_1
};

// A texture's place in the texel array and its sampler.
struct TextureHeader {
    uint width;
    uint height;
    uint offset;        // index of its first texel (row-major from the image's top row)
    uint sampler_bits;       // wrap S (bits 0-1), wrap T (bits 2-3): TEXTURE_WRAP_*; bit 4: nearest
};
const uint TEXTURE_WRAP_REPEAT = 0u;
const uint TEXTURE_WRAP_CLAMP = 1u;
const uint TEXTURE_WRAP_MIRROR = 2u;
const uint TEXTURE_NEAREST = 16u;
const uint NO_TEXTURE = 0xffffffffu;

// A material's use of one texture: uv' = (dot(u_row, (uv, 1)), dot(v_row, (uv, 1))) of its
// coordinate set (KHR_texture_transform folded into the two rows).
struct TextureSlot {
    vec3 u_row;
    uint texture_index; // NO_TEXTURE: none
    vec3 v_row;
    uint texcoord;      // 0 or 1
};

// The textures of one material (parallel to `materials`).
struct MaterialTextures {
    TextureSlot base_color;     // sRGB; alpha in a
    TextureSlot metal_rough;    // linear; B metallic, G roughness
    TextureSlot emissive;       // sRGB
    TextureSlot normal;         // linear; tangent-space normal
    float normal_scale;
    float alpha_cutoff;
    uint alpha_mode;            // ALPHA_*
    float base_alpha;           // baseColorFactor's alpha
};
const uint ALPHA_OPAQUE = 0u;
const uint ALPHA_MASK = 1u;
const uint ALPHA_BLEND = 2u;

#ifndef SCENE_ADDRESSED
#define SCENE_ADDRESSED 0
#endif
#if SCENE_ADDRESSED && (SCENE_SURFACE || SCENE_TEXTURES)
// In the addressed layout (glsl/interface/scene_bindings.glsl) the attributes (144 bytes a triangle, the
// largest per-triangle array) and the texels are reached by device address too: their bindings
// hold the address and the element count, and the names below keep their meaning.
#extension GL_EXT_buffer_reference : require
#endif
#if SCENE_SURFACE
#if SCENE_ADDRESSED
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer TriangleSurfaceArray { TriangleSurface items[]; };
layout(std430, set = SURFACE_SET, binding = SURFACE_BINDING + SURFACE_BINDING_SURFACE_ATTRIBUTES) readonly buffer SurfaceAttributes {
    TriangleSurfaceArray surface_attribute_array;
};
#define surface_attributes (surface_attribute_array.items)
#else
layout(std430, set = SURFACE_SET, binding = SURFACE_BINDING + SURFACE_BINDING_SURFACE_ATTRIBUTES) readonly buffer SurfaceAttributes {
    TriangleSurface surface_attributes[];
};
#endif
#endif
#if SCENE_TEXTURES
layout(std430, set = SURFACE_SET, binding = SURFACE_BINDING + SURFACE_BINDING_MATERIAL_TEXTURE_TABLE) readonly buffer MaterialTextureTable {
    MaterialTextures material_textures[];
};
layout(std430, set = SURFACE_SET, binding = SURFACE_BINDING + SURFACE_BINDING_TEXTURE_HEADERS) readonly buffer TextureHeaders {
    TextureHeader texture_headers[];
};
// RGBA8 texels, R in the low byte.
#if SCENE_ADDRESSED
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer TexelArray { uint items[]; };
layout(std430, set = SURFACE_SET, binding = SURFACE_BINDING + SURFACE_BINDING_TEXELS) readonly buffer Texels { TexelArray texel_array; };
#define texels (texel_array.items)
#else
layout(std430, set = SURFACE_SET, binding = SURFACE_BINDING + SURFACE_BINDING_TEXELS) readonly buffer Texels { uint texels[]; };
#endif
#endif

#endif
