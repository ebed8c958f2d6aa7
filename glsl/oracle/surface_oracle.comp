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

layout(std430, set = 0, binding = 9) readonly buffer Inputs { SurfaceOracleInput inputs[]; };
layout(std430, set = 0, binding = 10) writeonly buffer Outputs { SurfaceOracleOutput outputs[]; };
layout(push_constant) uniform Push { uint count; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    SurfaceOracleInput item = inputs[i];
    vec2 bary = item.bary;
    vec3 p = item.point;
    uint tri = item.triangle;
    SurfaceHit s = surface_at(tri, bary);
    uint material = triangles[tri].material;
    Material m = textured_material(materials[material], material, s);
    SurfaceOracleOutput o;
    o.normal = s.normal;
    o.handedness = s.handedness;
    o.tangent = s.tangent;
    o.uv0 = s.uv0;
    o.uv1 = s.uv1;
    o.texel = texture_lookup(item.texture_index, item.lookup_uv, item.srgb != 0u);
    o.base_color = m.base_color;
    o.metallic = m.metallic;
    o.emission = m.emission;
    o.roughness = m.roughness;
    o.normal_mapped = normal_mapped(material, s);
    o.bary = triangle_bary(triangles[tri], p);
    o.base_color_uv = texture_coordinates(material_textures[material].base_color, s);
    Material hm;
    vec3 ns;
    hit_shading(tri, bary, normalize(cross(triangles[tri].e1, triangles[tri].e2)), hm, ns);
    o.shading_normal = shading_normal(tri, bary);
    o.hit_roughness = hm.roughness;
    o.hit_normal = ns;
    o.hit_metallic = hm.metallic;
    texture_tangent_frame(material_textures[material].normal, s, o.frame_tangent, o.frame_handedness);
    o.color = s.color;
    o.pad0 = 0.0;
    o.pad1 = 0.0;
    o.pad2 = 0.0;
    outputs[i] = o;
}
