// Set 0, bindings 0-4: the frame parameters and the scene (storage or uniform buffers, see below),
// numbered by SceneBinding in crates/interface/src/shader_interface.rs. Kernels add their own from binding 5.
// Twin of FrameParams: crates/interface/src/gpu_types.rs.
#ifndef SCENE_BINDINGS_GLSL
#define SCENE_BINDINGS_GLSL

#include "interface/types.glsl"

// A read-only storage buffer, not a uniform buffer: lavapipe compiles a kernel again for every
// new value of a uniform or push constant that steers its control flow (crates/vk/src/buffer.rs).
layout(std430, set = 0, binding = SCENE_BINDING_FRAME_PARAMS) readonly buffer FrameParams { FRAME_PARAMS_FIELDS };

// On CPU devices small scenes are bound as uniform buffers, whose loads llvmpipe handles much
// faster than storage-buffer loads; the array sizes are then compile-time constants.
#ifndef SCENE_UNIFORM_BUFFERS
#define SCENE_UNIFORM_BUFFERS 0
#endif
#ifndef SCENE_ADDRESSED
#define SCENE_ADDRESSED 0
#endif
#if SCENE_UNIFORM_BUFFERS
layout(std140, set = 0, binding = SCENE_BINDING_TRIANGLES) uniform Triangles { Triangle triangles[SCENE_TRIANGLE_COUNT]; };
layout(std140, set = 0, binding = SCENE_BINDING_NODES) uniform Nodes { BvhNode nodes[SCENE_NODE_COUNT]; };
layout(std140, set = 0, binding = SCENE_BINDING_MATERIALS) uniform Materials { Material materials[SCENE_MATERIAL_COUNT]; };
layout(std140, set = 0, binding = SCENE_BINDING_EMITTERS) uniform Emitters { Emitter emitters[SCENE_EMITTER_SLOTS]; };
#elif SCENE_ADDRESSED
// Scenes whose triangles, BVH nodes or emitters exceed one binding's range
// (maxStorageBufferRange, 128 MiB on lavapipe: about 2.8 M triangles) reach those arrays by
// buffer device address (GL_EXT_buffer_reference), which is bounded by the allocation size only.
// Bindings 1, 2 and 4 then hold each array's address and element count; the names below keep
// `triangles[i]`, `nodes[i]` and `emitters[i]` meaning what they mean in the other layouts.
#extension GL_EXT_buffer_reference : require
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer TriangleArray { Triangle items[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer NodeArray { BvhNode items[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer EmitterArray { Emitter items[]; };
layout(std430, set = 0, binding = SCENE_BINDING_TRIANGLES) readonly buffer Triangles { TriangleArray triangle_array; uint triangle_array_length; };
layout(std430, set = 0, binding = SCENE_BINDING_NODES) readonly buffer Nodes { NodeArray node_array; uint node_array_length; };
layout(std430, set = 0, binding = SCENE_BINDING_MATERIALS) readonly buffer Materials { Material materials[]; };
layout(std430, set = 0, binding = SCENE_BINDING_EMITTERS) readonly buffer Emitters { EmitterArray emitter_array; };
#define triangles (triangle_array.items)
#define nodes (node_array.items)
#define emitters (emitter_array.items)
#define SCENE_TRIANGLES_LENGTH triangle_array_length
#define SCENE_NODES_LENGTH node_array_length
#else
layout(std430, set = 0, binding = SCENE_BINDING_TRIANGLES) readonly buffer Triangles { Triangle triangles[]; };
layout(std430, set = 0, binding = SCENE_BINDING_NODES) readonly buffer Nodes { BvhNode nodes[]; };
layout(std430, set = 0, binding = SCENE_BINDING_MATERIALS) readonly buffer Materials { Material materials[]; };
layout(std430, set = 0, binding = SCENE_BINDING_EMITTERS) readonly buffer Emitters { Emitter emitters[]; };
#endif
// The element counts of `triangles` and `nodes`, whatever the layout.
#ifndef SCENE_TRIANGLES_LENGTH
#define SCENE_TRIANGLES_LENGTH triangles.length()
#define SCENE_NODES_LENGTH nodes.length()
#endif

#endif
