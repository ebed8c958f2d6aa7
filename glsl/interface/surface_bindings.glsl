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
