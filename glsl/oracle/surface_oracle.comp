#version 460
// Oracle kernel: surface_at (with vertex_color), triangle_bary, texture_lookup,
// texture_coordinates, texture_tangent_frame, textured_material, normal_mapped, shading_normal and
// hit_shading on a scene with attributes
// and textures (twins: crates/shading-core/src/surface.rs, crates/shading-core/src/texture.rs, crates/scene/src/hit_surface.rs). Everything is bound in set 0: the scene at 0-4,
// the surface bindings at 5-8, then inputs and outputs.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#define SURFACE_SET 0
#define SURFACE_BINDING 5
#include "interface/scene_bindings.glsl"
#include "scene/hit_surface.glsl"

// Per item: (triangle bits, b1, b2, texture bits), (u, v, srgb, -), (point xyz, -).
layout(std430, set = 0, binding = 9) readonly buffer Inputs { vec4 inputs[]; };
layout(std430, set = 0, binding = 10) writeonly buffer Outputs { vec4 outputs[]; };
layout(push_constant) uniform Push { uint count; };

const uint OUT_ROWS = 12u;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    vec4 a = inputs[3u * i];
    vec4 b = inputs[3u * i + 1u];
    vec3 p = inputs[3u * i + 2u].xyz;
    uint tri = floatBitsToUint(a.x);
    SurfaceHit s = surface_at(tri, a.yz);
    uint material = triangles[tri].material;
    Material m = textured_material(materials[material], material, s);
    uint o = OUT_ROWS * i;
    outputs[o] = vec4(s.normal, s.handedness);
    outputs[o + 1u] = vec4(s.tangent, 0.0);
    outputs[o + 2u] = vec4(s.uv0, s.uv1);
    outputs[o + 3u] = texture_lookup(floatBitsToUint(a.w), b.xy, b.z > 0.5);
    outputs[o + 4u] = vec4(m.base_color, m.metallic);
    outputs[o + 5u] = vec4(m.emission, m.roughness);
    outputs[o + 6u] = vec4(normal_mapped(material, s), 0.0);
    outputs[o + 7u] = vec4(triangle_bary(triangles[tri], p), texture_coordinates(material_textures[material].base_color, s));
    Material hm;
    vec3 ns;
    hit_shading(tri, a.yz, normalize(cross(triangles[tri].e1, triangles[tri].e2)), hm, ns);
    outputs[o + 8u] = vec4(shading_normal(tri, a.yz), hm.roughness);
    outputs[o + 9u] = vec4(ns, hm.metallic);
    vec3 frame_tangent;
    float frame_handedness;
    texture_tangent_frame(material_textures[material].normal, s, frame_tangent, frame_handedness);
    outputs[o + 10u] = vec4(frame_tangent, frame_handedness);
    outputs[o + 11u] = vec4(s.color, 0.0);
}
