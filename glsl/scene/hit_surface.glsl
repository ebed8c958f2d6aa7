// The shading frame at a hit: the material with its textures and the shading normal (the
// interpolated vertex normal, then the material's normal map with its scale), both from one
// surface_at. BSDFs take it with the geometric normal (shading_core/bsdf.glsl, docs/materials.md "Shading
// normals"); measure conversions and ray offsets keep the geometric normal.
// Kernels of a scene without vertex normals and normal maps (SCENE_SHADING_NORMALS 0, set by
// src/render/scene_gpu.rs) compile none of it and shade with the geometric normal.
// Twins: Scene::shading_normal and Scene::hit_shading (crates/scene/src/hit_surface.rs).
#ifndef SHADING_FRAME_GLSL
#define SHADING_FRAME_GLSL

#include "shading_core/texture.glsl"

#ifndef SCENE_SHADING_NORMALS
#define SCENE_SHADING_NORMALS 0
#endif

// The shading normal of triangle index `triangle` at barycentrics bary: unit, scene space, not
// flipped towards any side; the geometric normal (as wound) in a scene without shading normals.
vec3 shading_normal(uint triangle, vec2 bary) {
#if SCENE_SHADING_NORMALS
    return normal_mapped(triangles[triangle].material, surface_at(triangle, bary));
#else
    Triangle tri = triangles[triangle];
    return normalize(cross(tri.e1, tri.e2));
#endif
}

// The material m (textures applied) and the shading normal ns of triangle index `triangle` at
// barycentrics bary; ng is its unit geometric normal as wound, which ns is without shading
// normals.
void hit_shading(uint triangle, vec2 bary, vec3 ng, out Material m, out vec3 ns) {
#if SCENE_SHADING_NORMALS
    uint material = triangles[triangle].material;
    SurfaceHit s = surface_at(triangle, bary);
    m = vertex_colored(textured_material(materials[material], material, s), s);
    ns = normal_mapped(material, s);
#else
    m = material_at(triangle, bary);
    ns = ng;
#endif
}

#endif
