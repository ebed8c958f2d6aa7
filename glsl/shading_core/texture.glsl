// Material textures from the texel buffer: address modes, bilinear or nearest filtering, sRGB
// decoding, and the material and shading normal a hit sees. Expects the scene bindings.
// Twin: crates/shading-core/src/texture.rs (docs/textures.md says why a buffer and not sampled images).
#ifndef TEXTURE_GLSL
#define TEXTURE_GLSL

#include "shading_core/surface.glsl"

#if SCENE_TEXTURES
float srgb_to_linear(float c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }

uint wrap_texel(int i, uint n, uint mode) {
    int m = int(n);
    if (mode == TEXTURE_WRAP_CLAMP) return uint(clamp(i, 0, m - 1));
    int r = i % (2 * m);
    r = r < 0 ? r + 2 * m : r;
    if (mode == TEXTURE_WRAP_MIRROR) return uint(r >= m ? 2 * m - 1 - r : r);
    return uint(r % m);
}

// Whole periods of 2 (repeat, mirror) or a clamp keep texel indices within an int.
float reduce_coordinate(float u, uint mode) {
    if (!(abs(u) < 1e30)) return 0.0;
    return mode == TEXTURE_WRAP_CLAMP ? clamp(u, -1.0, 2.0) : u - 2.0 * floor(u * 0.5);
}

vec4 texel(TextureHeader h, int x, int y, bool srgb) {
    uint sx = wrap_texel(x, h.width, h.sampler_bits & 3u);
    uint sy = wrap_texel(y, h.height, (h.sampler_bits >> 2u) & 3u);
    vec4 c = unpackUnorm4x8(texels[h.offset + sy * h.width + sx]);
    return srgb ? vec4(srgb_to_linear(c.r), srgb_to_linear(c.g), srgb_to_linear(c.b), c.a) : c;
}

// Texture `texture` at uv (v down from the top row): bilinear, or nearest by its sampler, over
// texels decoded to linear first when srgb.
vec4 texture_lookup(uint texture_index, vec2 uv, bool srgb) {
    TextureHeader h = texture_headers[texture_index];
    float u = reduce_coordinate(uv.x, h.sampler_bits & 3u) * float(h.width);
    float v = reduce_coordinate(uv.y, (h.sampler_bits >> 2u) & 3u) * float(h.height);
    if ((h.sampler_bits & TEXTURE_NEAREST) != 0u) return texel(h, int(floor(u)), int(floor(v)), srgb);
    vec2 p = vec2(u, v) - 0.5;
    vec2 p0 = floor(p);
    vec2 f = p - p0;
    ivec2 i = ivec2(p0);
    vec4 top = mix(texel(h, i.x, i.y, srgb), texel(h, i.x + 1, i.y, srgb), f.x);
    vec4 bottom = mix(texel(h, i.x, i.y + 1, srgb), texel(h, i.x + 1, i.y + 1, srgb), f.x);
    return mix(top, bottom, f.y);
}

vec2 texture_coordinates(TextureSlot slot, SurfaceHit s) {
    vec3 uv = vec3(slot.texcoord == 1u ? s.uv1 : s.uv0, 1.0);
    return vec2(dot(slot.u_row, uv), dot(slot.v_row, uv));
}

// The tangent frame of the coordinates slot looks its texture up with: KHR_texture_transform's
// linear part A turns the frame with the lookup, tangent = normalize((A11 t + A10 b) / det A),
// handedness flipped where det A < 0 (MikkTSpace's frame of the transform baked in). Twin:
// texture::texture_tangent_frame.
void texture_tangent_frame(TextureSlot slot, SurfaceHit s, out vec3 tangent, out float handedness) {
    float a00 = slot.u_row.x, a01 = slot.u_row.y, a10 = slot.v_row.x, a11 = slot.v_row.y;
    float det = a00 * a11 - a01 * a10;
    tangent = s.tangent;
    handedness = s.handedness;
    if (det == 0.0 || isinf(det) || isnan(det)) return;
    float sign_det = det < 0.0 ? -1.0 : 1.0;
    if (a10 == 0.0) {
        tangent = a11 * sign_det < 0.0 ? -s.tangent : s.tangent;
        handedness = s.handedness * sign_det;
        return;
    }
    vec3 b = s.handedness * cross(s.normal, s.tangent);
    vec3 t = (s.tangent * a11 + b * a10) * sign_det;
    if (dot(t, t) > 1e-12) {
        tangent = normalize(t);
        handedness = s.handedness * sign_det;
    }
}
#endif

#if SCENE_TEXTURES
// The opacity of material `material` at s: baseColorFactor's alpha times the base colour
// texture's (linear) alpha.
float material_alpha(uint material, SurfaceHit s) {
    TextureSlot slot = material_textures[material].base_color;
    float a = material_textures[material].base_alpha;
    if (slot.texture_index == NO_TEXTURE) return a;
    return a * texture_lookup(slot.texture_index, texture_coordinates(slot, s), true).a;
}

// The share of an alpha-tested emitter's emission at s: 0 below the cutoff traversal uses, else
// 1, or alpha for a BLEND emitter. Twin: texture::emission_coverage.
float emission_coverage(Material m, uint material, SurfaceHit s) {
    float a = material_alpha(material, s);
    if (!(a >= material_textures[material].alpha_cutoff)) return 0.0;
    return (m.flags & MATERIAL_BLEND_EMISSION) != 0u ? a : 1.0;
}
#endif

// Material `m` (index `material`) with its textures applied at surface s.
Material textured_material(Material m, uint material, SurfaceHit s) {
#if SCENE_TEXTURES
    MaterialTextures t = material_textures[material];
    if (t.base_color.texture_index != NO_TEXTURE) {
        m.base_color *= texture_lookup(t.base_color.texture_index, texture_coordinates(t.base_color, s), true).rgb;
    }
    if (t.metal_rough.texture_index != NO_TEXTURE) {
        vec4 c = texture_lookup(t.metal_rough.texture_index, texture_coordinates(t.metal_rough, s), false);
        m.metallic *= c.b;
        m.roughness *= c.g;
    }
    if (t.emissive.texture_index != NO_TEXTURE) {
        m.emission *= texture_lookup(t.emissive.texture_index, texture_coordinates(t.emissive, s), true).rgb;
    }
    if ((m.flags & MATERIAL_ALPHA_EMISSION) != 0u) m.emission *= emission_coverage(m, material, s);
#endif
    return m;
}

// The shading normal at s with material `material`'s normal map (scaled) applied; s.normal
// without one.
vec3 normal_mapped(uint material, SurfaceHit s) {
#if SCENE_TEXTURES
    MaterialTextures t = material_textures[material];
    if (t.normal.texture_index == NO_TEXTURE) return s.normal;
    vec3 c = texture_lookup(t.normal.texture_index, texture_coordinates(t.normal, s), false).rgb;
    vec3 local = (c * 2.0 - 1.0) * vec3(t.normal_scale, t.normal_scale, 1.0);
    vec3 tangent;
    float handedness;
    texture_tangent_frame(t.normal, s, tangent, handedness);
    vec3 n = tangent * local.x + (handedness * cross(s.normal, tangent)) * local.y + s.normal * local.z;
    return dot(n, n) > 1e-12 ? normalize(n) : s.normal;
#else
    return s.normal;
#endif
}


// m with the vertex colour of s applied: COLOR_0 multiplies the base colour, and the emission of
// an unlit material (its base colour). Twin: texture::vertex_colored.
Material vertex_colored(Material m, SurfaceHit s) {
    m.base_color *= s.color;
    if ((m.flags & MATERIAL_UNLIT) != 0u) m.emission *= s.color;
    return m;
}

// The material of triangle index `triangle` at barycentrics bary, textures and vertex colour
// applied. Twin: Scene::material_at.
Material material_at(uint triangle, vec2 bary) {
    uint material = triangles[triangle].material;
    Material m = materials[material];
#if SCENE_SURFACE
    SurfaceHit s = surface_at(triangle, bary);
    m = vertex_colored(textured_material(m, material, s), s);
#endif
    return m;
}

#endif
