// The surface at a hit: interpolated shading normal, tangent frame, texture coordinates and
// vertex colour.
// Expects the scene bindings. Twin: crates/shading-core/src/surface.rs.
#ifndef SURFACE_GLSL
#define SURFACE_GLSL

#include "shading_core/sampling.glsl"
#include "interface/surface_bindings.glsl"
#include "interface/types.glsl"

struct SurfaceHit {
    vec3 normal;        // unit, interpolated (the face normal where there is none); not flipped
    vec3 tangent;       // unit, orthogonal to normal
    float handedness;   // ±1: bitangent = handedness * cross(normal, tangent)
    vec2 uv0;
    vec2 uv1;
    vec3 color;         // interpolated COLOR_0 (linear RGB); 1 where the vertices have none
};

// Barycentrics (b1, b2) of point p (on or near the triangle's plane) in tri: the least-squares
// solution of p - v0 = b1 e1 + b2 e2.
vec2 triangle_bary(Triangle tri, vec3 p) {
    vec3 d = p - tri.v0;
    float d00 = dot(tri.e1, tri.e1), d01 = dot(tri.e1, tri.e2), d11 = dot(tri.e2, tri.e2);
    float d20 = dot(d, tri.e1), d21 = dot(d, tri.e2);
    float inv = 1.0 / (d00 * d11 - d01 * d01);
    return vec2(d11 * d20 - d01 * d21, d00 * d21 - d01 * d20) * inv;
}

#if SCENE_SURFACE
// One vertex's COLOR_0 from the bits in its normal's w (surface::pack_vertex_color): 10 bits
// per channel, bit 31 set where there is one.
bool unpack_vertex_color(float w, out vec3 c) {
    uint b = floatBitsToUint(w);
    c = vec3(float(b & 1023u), float((b >> 10u) & 1023u), float((b >> 20u) & 1023u)) / 1023.0;
    return (b & 0x80000000u) != 0u;
}

// COLOR_0 of attributes a at vertex weights w, interpolated; 1 without colours. Twin:
// surface::vertex_color.
vec3 vertex_color(TriangleSurface a, vec3 w) {
    vec3 c0, c1, c2;
    bool has0 = unpack_vertex_color(a.normal[0].w, c0);
    bool has1 = unpack_vertex_color(a.normal[1].w, c1);
    bool has2 = unpack_vertex_color(a.normal[2].w, c2);
    return has0 && has1 && has2 ? c0 * w.x + c1 * w.y + c2 * w.z : vec3(1.0);
}
#endif

// The surface of triangle index `triangle` at barycentrics (b1, b2) of v0 + e1 and v0 + e2.
SurfaceHit surface_at(uint triangle, vec2 bary) {
    Triangle tri = triangles[triangle];
    SurfaceHit s;
    s.uv0 = vec2(0.0);
    s.uv1 = vec2(0.0);
    s.handedness = 1.0;
    s.color = vec3(1.0);
#if SCENE_SURFACE
    vec3 w = vec3(1.0 - bary.x - bary.y, bary.x, bary.y);
    TriangleSurface a = surface_attributes[triangle];
    vec3 n = (a.normal[0] * w.x + a.normal[1] * w.y + a.normal[2] * w.z).xyz;
    s.normal = dot(n, n) > SURFACE_MIN_LENGTH_SQUARED ? normalize(n) : normalize(cross(tri.e1, tri.e2));
    vec4 t4 = a.tangent[0] * w.x + a.tangent[1] * w.y + a.tangent[2] * w.z;
    vec3 t = t4.xyz - s.normal * dot(s.normal, t4.xyz);
    vec3 b;
    if (dot(t, t) > SURFACE_MIN_LENGTH_SQUARED) {
        s.tangent = normalize(t);
    } else {
        build_onb(s.normal, s.tangent, b);
    }
    s.handedness = t4.w < 0.0 ? -1.0 : 1.0;
    vec4 uv = a.uv[0] * w.x + a.uv[1] * w.y + a.uv[2] * w.z;
    s.uv0 = uv.xy;
    s.uv1 = uv.zw;
    s.color = vertex_color(a, w);
#else
    vec3 b;
    s.normal = normalize(cross(tri.e1, tri.e2));
    build_onb(s.normal, s.tangent, b);
#endif
    return s;
}

#endif
