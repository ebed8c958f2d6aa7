// Warping uniforms to directions and points. Twin: crates/shading-core/src/sampling.rs.
#ifndef SAMPLING_GLSL
#define SAMPLING_GLSL

const float PI = 3.14159265358979;
const float INV_PI = 0.318309886183791;

// Orthonormal basis around a unit normal without branches on its sign (Duff et al., JCGT 2017).
void build_onb(vec3 n, out vec3 t, out vec3 b) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

vec3 to_local(vec3 v, vec3 t, vec3 b, vec3 n) { return vec3(dot(v, t), dot(v, b), dot(v, n)); }
vec3 to_world(vec3 v, vec3 t, vec3 b, vec3 n) { return v.x * t + v.y * b + v.z * n; }

// Shirley-Chiu concentric mapping of the square onto the unit disk.
vec2 sample_concentric_disk(vec2 u) {
    vec2 o = 2.0 * u - 1.0;
    if (o.x == 0.0 && o.y == 0.0) return vec2(0.0);
    float r, phi;
    if (abs(o.x) > abs(o.y)) { r = o.x; phi = (PI / 4.0) * (o.y / o.x); }
    else { r = o.y; phi = PI / 2.0 - (PI / 4.0) * (o.x / o.y); }
    return r * vec2(cos(phi), sin(phi));
}

vec3 sample_cosine_hemisphere(vec2 u) {
    vec2 d = sample_concentric_disk(u);
    return vec3(d, sqrt(max(0.0, 1.0 - dot(d, d))));
}

float pdf_cosine_hemisphere(float cos_theta) { return max(cos_theta, 0.0) * INV_PI; }

vec3 sample_uniform_sphere(vec2 u) {
    float z = 1.0 - 2.0 * u.x;
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = 2.0 * PI * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

const float UNIFORM_SPHERE_PDF = 1.0 / (4.0 * PI);

// Barycentrics (b1, b2) uniform over a triangle; b0 = 1 - b1 - b2.
vec2 sample_triangle(vec2 u) {
    float su = sqrt(u.x);
    return vec2(1.0 - su, u.y * su);
}

// GGX visible-normal sampling by spherical caps (Dupuy and Benyoub 2023); wo.z >= 0 in the local frame.
vec3 sample_ggx_vndf(vec3 wo, float alpha, vec2 u) {
    vec3 wo_std = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
    float phi = 2.0 * PI * u.x;
    float z = (1.0 - u.y) * (1.0 + wo_std.z) - wo_std.z;
    float sin_theta = sqrt(clamp(1.0 - z * z, 0.0, 1.0));
    vec3 h_std = vec3(sin_theta * cos(phi), sin_theta * sin(phi), z) + wo_std;
    return normalize(vec3(alpha * h_std.x, alpha * h_std.y, max(h_std.z, 0.0)));
}

float max_component(vec3 v) { return max(v.x, max(v.y, v.z)); }

// The balance-heuristic weight of the technique of pdf a beside one of pdf b (0 where a is).
float balance_heuristic(float a, float b) { return a > 0.0 ? a / (a + b) : 0.0; }

float power_heuristic(float a, float b) {
    float a2 = a * a;
    float b2 = b * b;
    return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}

#endif
