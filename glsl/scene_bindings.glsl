// Set 0, bindings 0-4: the frame parameters and the scene (storage or uniform buffers, see below),
// numbered by SceneBinding in src/shader_interface.rs. Kernels add their own from binding 5.
// Twin of FrameParams: src/gpu_types.rs.
#ifndef SCENE_BINDINGS_GLSL
#define SCENE_BINDINGS_GLSL

#include "types.glsl"

// A read-only storage buffer, not a uniform buffer: lavapipe compiles a kernel again for every
// new value of a uniform or push constant that steers its control flow (src/vk/buffer.rs).
layout(std430, set = 0, binding = SCENE_BINDING_FRAME_PARAMS) readonly buffer FrameParams {
    vec4 cam_position;   // w: tan(yfov / 2)
    vec4 cam_right;      // w: aspect ratio (width / height)
    vec4 cam_up;
    vec4 cam_forward;
    vec4 scene_env;      // rgb: constant environment radiance, w: probability NEE picks it
    uint width;
    uint height;
    uint sample_offset;
    uint samples_per_dispatch;
    uint max_depth;
    uint render_seed;
    uint flags;
    uint emitter_count;
};
const uint FLAG_RUSSIAN_ROULETTE = 1u;

// On CPU devices small scenes are bound as uniform buffers, whose loads llvmpipe handles much
// faster than storage-buffer loads; the array sizes are then compile-time constants.
#ifndef SCENE_UNIFORM_BUFFERS
#define SCENE_UNIFORM_BUFFERS 0
#endif
#if SCENE_UNIFORM_BUFFERS
layout(std140, set = 0, binding = SCENE_BINDING_TRIANGLES) uniform Triangles { Triangle triangles[SCENE_TRIANGLE_COUNT]; };
layout(std140, set = 0, binding = SCENE_BINDING_NODES) uniform Nodes { BvhNode nodes[SCENE_NODE_COUNT]; };
layout(std140, set = 0, binding = SCENE_BINDING_MATERIALS) uniform Materials { Material materials[SCENE_MATERIAL_COUNT]; };
layout(std140, set = 0, binding = SCENE_BINDING_EMITTERS) uniform Emitters { Emitter emitters[SCENE_EMITTER_SLOTS]; };
#else
layout(std430, set = 0, binding = SCENE_BINDING_TRIANGLES) readonly buffer Triangles { Triangle triangles[]; };
layout(std430, set = 0, binding = SCENE_BINDING_NODES) readonly buffer Nodes { BvhNode nodes[]; };
layout(std430, set = 0, binding = SCENE_BINDING_MATERIALS) readonly buffer Materials { Material materials[]; };
layout(std430, set = 0, binding = SCENE_BINDING_EMITTERS) readonly buffer Emitters { Emitter emitters[]; };
#endif

#endif
