// Generated from crates/interface/ (shader_interface.rs `glsl_header`) when restir-pt-vk is built;
// edit the Rust declarations, not this text.
#ifndef SHADER_INTERFACE_GLSL
#define SHADER_INTERFACE_GLSL

#define SCENE_BINDING_FRAME_PARAMS 0
#define SCENE_BINDING_TRIANGLES 1
#define SCENE_BINDING_NODES 2
#define SCENE_BINDING_MATERIALS 3
#define SCENE_BINDING_EMITTERS 4
#define PATHTRACE_BINDING_ACCUM 5
#define PATHTRACE_BINDING_ACCUM_SQ 6
#define PATHTRACE_BINDING_STATUS 7
#define RESTIR_BINDING_REUSE_PARAMS 5
#define RESTIR_BINDING_SURFACES0 6
#define RESTIR_BINDING_SURFACES1 7
#define RESTIR_BINDING_RESERVOIR_HEADS0 8
#define RESTIR_BINDING_RESERVOIR_TAILS0 9
#define RESTIR_BINDING_RESERVOIR_HEADS1 10
#define RESTIR_BINDING_RESERVOIR_TAILS1 11
#define RESTIR_BINDING_RESERVOIR_HEADS2 12
#define RESTIR_BINDING_RESERVOIR_TAILS2 13
#define RESTIR_BINDING_DIRECT 14
#define RESTIR_BINDING_ACCUM 15
#define RESTIR_BINDING_ACCUM_SQ 16
#define RESTIR_BINDING_RESTIR_STATS 17
#define RESTIR_BINDING_EXPECTATION 18
#define SURFACE_BINDING_SURFACE_ATTRIBUTES 0
#define SURFACE_BINDING_MATERIAL_TEXTURE_TABLE 1
#define SURFACE_BINDING_TEXTURE_HEADERS 2
#define SURFACE_BINDING_TEXELS 3
#define SURFACE_DESCRIPTOR_SET 1

#define SHIFT_RECONNECTION 0
#define SHIFT_REPLAY 1
#define SHIFT_HYBRID 2
#define MIS_GBH 0
#define MIS_PAIRWISE 1

#define RESERVOIR_SLOTS 3u
#define SURFACE_SLOTS 2u
#define RESTIR_MAX_PASSES 6u
#define MAX_INPUTS 9u
#define IMAGE_LOCAL_SIZE 8u
#define COUNTER_COUNT 7u
#define RR_START_DEPTH 3u
#define MAX_PATH_LENGTH 7u
#define PUNCTUAL_ROWS 4u
#define LIGHT_NODE_ROWS 4u
#define LIGHT_TREE_MAX_DEPTH 32u
#define RR_MAX_SURVIVAL 0.95

const uint STREAM_CAMERA = 0u;
const uint STREAM_BSDF = 1u;
const uint STREAM_LIGHT = 2u;
const uint STREAM_RESAMPLE = 3u;
const uint STREAM_DIRECTIONAL = 4u;
const uint COUNTER_TRAVERSALS = 0u;
const uint COUNTER_NODE_VISITS = 1u;
const uint COUNTER_TRIANGLE_TESTS = 2u;
const uint COUNTER_PATH_STEPS = 3u;
const uint COUNTER_NODE_ITERATIONS = 4u;
const uint COUNTER_TRIANGLE_ITERATIONS = 5u;
const uint COUNTER_STEP_ITERATIONS = 6u;
const float SURFACE_MIN_LENGTH_SQUARED = 1e-12;
const float DELTA_ALPHA = 0.001;
const float INDEX_MATCHED_TOLERANCE = 1.5258789e-5;
const float SEGMENT_EPSILON = 0.0001;
const float RAY_OFFSET_SCALE = 7.6293945e-6;
const uint MATERIAL_DOUBLE_SIDED = 1u;
const uint MATERIAL_UNLIT = 2u;
const uint MATERIAL_ALPHA_EMISSION = 4u;
const uint MATERIAL_BLEND_EMISSION = 8u;
const uint NO_EMITTER = 0xffffffffu;
const uint NO_HIT = 0xffffffffu;
const uint LEAF_COUNT_BITS = 4u;
const uint LEAF_COUNT_MASK = 15u;
const uint PUNCTUAL_LIGHT_BIT = 0x80000000u;
const uint PUNCTUAL_POINT = 0u;
const uint PUNCTUAL_SPOT = 1u;
const uint PUNCTUAL_DIRECTIONAL = 2u;
const uint LIGHT_NODE_LEAF = 1u;
const uint LIGHT_NODE_TWO_SIDED = 2u;
const uint FLAG_RUSSIAN_ROULETTE = 1u;
const uint LOBE_NONE = 0u;
const uint LOBE_DIFFUSE = 1u;
const uint LOBE_CONDUCTOR = 2u;
const uint LOBE_DIELECTRIC = 4u;
const uint LOBE_DELTA = 8u;
const uint LOBE_TRANSMISSION = 16u;
const uint LOBE_BITS = 5u;
const uint INFO_LENGTH_MASK = 15u;
const uint INFO_RC_SHIFT = 4u;
const uint INFO_NEE_END = 256u;
const uint INFO_DIRECTIONAL_SHIFT = 9u;
const uint NO_TEXTURE = 0xffffffffu;
const uint TEXTURE_WRAP_REPEAT = 0u;
const uint TEXTURE_WRAP_CLAMP = 1u;
const uint TEXTURE_WRAP_MIRROR = 2u;
const uint TEXTURE_NEAREST = 16u;
const uint ALPHA_OPAQUE = 0u;
const uint ALPHA_MASK = 1u;
const uint ALPHA_BLEND = 2u;

#define FRAME_PARAMS_FIELDS vec4 cam_position; vec4 cam_right; vec4 cam_up; vec4 cam_forward; vec4 scene_env; uint width; uint height; uint sample_offset; uint samples_per_dispatch; uint max_depth; uint render_seed; uint flags; uint emitter_count;

struct Material {
    vec3 base_color;                 // glTF baseColorFactor, linear RGB in [0, 1]: the diffuse albedo of non-metals and F0 of metals.
    float metallic;                  // glTF metallicFactor in [0, 1]: the blend between the non-metal and the conductor lobes.
    vec3 emission;                   // Emitted radiance, linear RGB in W/(m² sr): emissiveFactor already multiplied by `KHR_materials_emissive_strength`.
    float roughness;                 // Perceptual (linear) roughness in [0, 1]; the GGX alpha is its square (`restir_pt_shading::bsdf::ggx_alpha`).
    float transmission;              // `KHR_materials_transmission` transmissionFactor in [0, 1]: the dielectric interface lobe replaces that share of the non-metal part only (weights `bsdf::lobe_weights`).
    float ior;                       // Index of refraction of the inside (`KHR_materials_ior`, glTF default 1.5); also sets the specular layer's F0 = ((ior - 1) / (ior + 1))² · specular_color.
    uint flags;                      // Bit set: `MATERIAL_DOUBLE_SIDED`, `MATERIAL_UNLIT`, `MATERIAL_ALPHA_EMISSION`, `MATERIAL_BLEND_EMISSION`.
    float specular;                  // `KHR_materials_specular` specularFactor: the strength of the non-metal specular layer (docs/materials.md); 0 makes the non-metal part purely Lambertian.
    vec3 specular_color;             // `KHR_materials_specular` specularColorFactor (linear RGB), scaling the layer's F0.
    uint pad;                        // Padding to a 16-byte multiple (std430); always 0.
};

struct Triangle {
    vec3 v0;                         // Vertex 0, scene coordinates.
    uint material;                   // Index into the scene's materials.
    vec3 e1;                         // Vertex 1 minus vertex 0, scene coordinates.
    uint emitter;                    // Index into the emitter table, or `NO_EMITTER` if the triangle does not emit.
    vec3 e2;                         // Vertex 2 minus vertex 0, scene coordinates.
    uint alpha_tested;               // 1 if the triangle's material is alpha-tested (`alphaMode` MASK or BLEND), else 0, set by `restir_pt_scene::Scene::build`: the traversal loops tell alpha-tested hits apart by it without loading materials (glsl/shading_core/alpha_pass.glsl, `restir_pt_shading::alpha_pass`).
};

struct BvhNode {
    vec3 lo;                         // Minimum corner of the node's bounding box, scene coordinates.
    uint skip;                       // Index of the node to visit after this subtree (or after a missed box).
    vec3 hi;                         // Maximum corner of the node's bounding box, scene coordinates.
    uint leaf;                       // For a leaf, `(first triangle << LEAF_COUNT_BITS) | count` (see `BvhNode::leaf_range`); 0 for an interior node.
};

struct Emitter {
    uint triangle;                   // The emissive triangle's index, or `PUNCTUAL_LIGHT_BIT` | the punctual light's index.
    uint trail;                      // The light tree's bit trail (pbrt-v4 `BVHLightSampler`): bit d set when the path from the root to this light's leaf takes the second child at depth d; 0 for a directional light.
    float intensity;                 // The light's largest radiant intensity, luminance (W/sr in the glTF emission unit): L·A for an emissive triangle, I for a point or spot light, the irradiance E for a directional light.
    uint leaf;                       // Index of the light's leaf among the light tree's nodes; `NO_EMITTER` for directional lights, which NEE takes beside the tree's drawn light.
};

struct LightNode {
    vec3 lo;                         // Lower corner of the bounds.
    float intensity;                 // Sum of the lights' largest radiant intensities (luminance, W/sr).
    vec3 hi;                         // Upper corner of the bounds.
    float cos_theta_o;               // cos θ_o, θ_o the half-angle of the cone of normals (1: one direction, -1: all).
    vec3 axis;                       // Unit axis of the cone of normals.
    float cos_theta_e;               // cos θ_e, θ_e the angle beyond θ_o within which the lights still emit (0: a cosine lobe).
    uint child;                      // A leaf's emitter row, an interior node's second child.
    uint flags;                      // `LIGHT_NODE_LEAF` | `LIGHT_NODE_TWO_SIDED`.
    uvec2 pad;                       // Zero; pads the node to whole rows.
};

struct RestirPass {
    uint in_slot;                    // Reservoir slot (0-2) the pass reads.
    uint out_slot;                   // Reservoir slot (0-2) the pass writes.
    uint prev_slot;                  // Reservoir slot (0-2) holding the previous frame's result, for temporal reuse.
    uint surface_slot;               // Surface slot (0-1) of the current frame; the previous frame's surfaces are the other one.
    uint pass_seed;                  // Distinguishes the random choices of passes and reuse rounds within a frame.
};

struct TemporalParams {
    vec4 prev_cam_position;          // The previous frame's camera position and tan(yfov / 2), laid out like `FrameParams::cam_position`.
    vec4 prev_cam_right;             // The previous frame's right axis and aspect ratio, as `FrameParams::cam_right`.
    vec4 prev_cam_up;                // The previous frame's up axis, as `FrameParams::cam_up`.
    vec4 prev_cam_forward;           // The previous frame's viewing direction, as `FrameParams::cam_forward`.
    float m_cap;                     // Confidence cap of the history, as a multiple of the current reservoir's M; the initial pass also caps the running mean of the emission seen directly at this many frames.
    uint valid;                      // 1 if the previous frame's reservoirs and surfaces exist and temporal reuse is on.
    uvec2 pad;                       // Zero; pads the record to its 16-byte alignment.
};

struct InitialParams {
    uint candidates;                 // Candidate paths per pixel and reservoir.
    uint emission_rays;              // Jittered camera rays per reservoir for the emission seen directly.
    uint emission_history;           // 1 if the direct-emission buffer holds the running mean for this same camera pose.
};

struct SpatialParams {
    uint neighbours;                 // Neighbours per round.
    float radius;                    // Reuse radius in pixels.
};

#define REUSE_PARAMS_FIELDS TemporalParams temporal; float roughness_threshold; float distance_threshold; float normal_threshold; float depth_threshold; uint frame_index; uint reservoirs; InitialParams initial; SpatialParams spatial; RestirPass passes[6];

struct Surface {
    vec3 pos;                        // Hit point of the ray through the pixel centre, scene coordinates.
    uint triangle;                   // The hit triangle, or `restir_pt_shading::bvh::NO_HIT` if the camera ray escaped.
    vec3 camera;                     // The camera position the ray left from, scene coordinates.
    float depth;                     // Distance from the camera to `pos`, scene units.
};

struct ReservoirHead {
    uint seed;                       // `restir_pt_shading::path_record::PathRecord::seed`.
    uint info;                       // `restir_pt_shading::path_record::PathRecord::info`.
    uint lobes;                      // `restir_pt_shading::path_record::PathRecord::lobes`.
    uint rc_triangle;                // `restir_pt_shading::path_record::PathRecord::rc_triangle`.
    vec3 rc_pos;                     // `restir_pt_shading::path_record::PathRecord::rc_pos`.
    float rc_pdf;                    // `restir_pt_shading::path_record::PathRecord::rc_pdf`.
    vec3 rc_next;                    // `restir_pt_shading::path_record::PathRecord::rc_next`.
    float rc_geometry;               // `restir_pt_shading::path_record::PathRecord::rc_geometry`.
};

struct ReservoirTail {
    vec3 suffix;                     // `restir_pt_shading::path_record::PathRecord::suffix`.
    float rc_pdf_after;              // `restir_pt_shading::path_record::PathRecord::rc_pdf_after`.
    vec3 contribution;               // `restir_pt_shading::path_record::PathRecord::contribution`.
    uint rc_next_triangle;           // `restir_pt_shading::path_record::PathRecord::rc_next_triangle`.
    float weight;                    // The unbiased contribution weight W.
    float confidence;                // The confidence weight M.
    uint pad0;                       // Padding to 48 bytes; always 0.
    uint pad1;                       // Padding to 48 bytes; always 0.
};

#define RESTIR_STATS_FIELDS uint max_loop_iterations; uint loop_budget_cut_groups; uint shifts_attempted; uint shifts_failed; uint nonfinite_weights; uint candidates_dropped; uint nonfinite_pixels; uint reuse_traversals; uint shift_subgroup_runs; uint subgroup_size;

struct PathRecord {
    uint seed;                       // The path's random-number key (`restir_pt_shading_core::rng::path_seed`): random replay regenerates the path from it.
    uint info;                       // Bits 0-3: the length k; bits 4-7: the reconnection index r (0: none); bit 8: NEE end; bits 9-31: which NEE technique made the end (0: the light NEE draws; k + 1: directional light k, which NEE takes at every vertex).
    uint lobes;                      // The lobe sampled at x1..x_{k-1}, 5 bits each (LOBE_NONE where NEE chose the next vertex).
    uint rc_triangle;                // The triangle of x_r; NO_HIT if x_r is an escaped direction.
    vec3 rc_pos;                     // x_r, or its direction if escaped.
    float rc_pdf;                    // The solid-angle pdf that chose x_r from x_{r-1} (the BSDF's, or the light's for an NEE end).
    vec3 rc_next;                    // x_{r+1}, or its direction if escaped; unused when x_r ends the path.
    float rc_geometry;               // |cos_r| / |x_{r-1} - x_r|^2 at x_r (1 for an escaped x_r).
    vec3 suffix;                     // prod_{i > r} f_s |cos| / p times the emission at the end: what x_r receives from the suffix (1 when x_r ends the path: its emission depends on the predecessor).
    float rc_pdf_after;              // p(x_r -> x_{r+1} | x_{r-1}); 1 when x_r ends the path or NEE chose x_{r+1}.
    vec3 contribution;               // f(X).
    uint rc_next_triangle;           // The triangle of x_{r+1}; NO_HIT if escaped.
};

struct TriangleSurface {
    vec4 normal[3];                  // xyz: the vertex normal (unit, or zero where the file gave none or the triangle is flat: the face normal is used); w: the vertex's COLOR_0 packed by `restir_pt_shading_core::surface::pack_vertex_color` (its bits; 0.0: no colour).
    vec4 tangent[3];                 // xyz: the vertex tangent (along +u of the normal texture's coordinates); w: its handedness ±1, the bitangent being w · cross(normal, tangent) (glTF 2.0, section 3.7.2.1).
    vec4 uv[3];                      // xy: TEXCOORD_0, zw: TEXCOORD_1 of each vertex (0 where absent).
};

struct TextureHeader {
    uint width;                      // Width in texels.
    uint height;                     // Height in texels.
    uint offset;                     // Index of the first texel; rows run from the image's top row (v = 0) down.
    uint sampler_bits;               // Wrap S in bits 0-1, wrap T in bits 2-3 (`TEXTURE_WRAP_*`), `TEXTURE_NEAREST`.
};

struct TextureSlot {
    vec3 u_row;                      // First row of the affine uv map (identity: (1, 0, 0)).
    uint texture_index;              // Index into the headers, or `NO_TEXTURE`.
    vec3 v_row;                      // Second row of the affine uv map (identity: (0, 1, 0)).
    uint texcoord;                   // TEXCOORD_0 or TEXCOORD_1.
};

struct MaterialTextures {
    TextureSlot base_color;          // sRGB colour and linear alpha, multiplying the base colour factor.
    TextureSlot metal_rough;         // Linear; B multiplies metallic, G roughness.
    TextureSlot emissive;            // sRGB, multiplying the emission.
    TextureSlot normal;              // Tangent-space normal, (x, y) scaled by `normal_scale`.
    float normal_scale;              // glTF `normalTexture.scale`: multiplies the tangent-space normal's x and y (default 1).
    float alpha_cutoff;              // glTF `alphaCutoff` (default 0.5): the alpha below which an `ALPHA_MASK` hit is discarded.
    uint alpha_mode;                 // `ALPHA_OPAQUE`, `ALPHA_MASK` or `ALPHA_BLEND`.
    float base_alpha;                // The alpha of the base colour factor.
};

struct ReuseToyInput {
    float x;                         // The sample's position in its domain, in [0, 1].
    float weight;                    // W_X: 1 / pdf(x); 0 for an empty reservoir.
    float confidence;                // The confidence weight c.
    uint domain;                     // The domain: 0 (canonical), 1 or 2.
};

struct ReuseOracleOutput {
    vec3 expected;                   // The expectation of f(Y) W_Y over the choice, linear RGB.
    float weight;                    // W of the result.
    float confidence;                // M of the result.
    float chosen_x;                  // The chosen sample's position in the canonical domain.
    int chosen_input;                // The input the chosen sample came from; -1: none.
    uint chosen_domain;              // The domain the chosen sample came from.
    uint shifts_failed;              // Shifts that failed.
    uint nonfinite_weights;          // Resampling weights that were not finite.
    uvec2 pad;                       // Zero; pads the record to 48 bytes.
};

struct RngOracleOutput {
    uvec4 pcg4d;                     // `pcg4d(k)`, the hash of all four words.
    uint path_seed;                  // `path_seed(k.x, k.y, k.z)`: k read as (pixel, sample index, seed).
    uint pad0;                       // Zero; this and the next two align `uniforms` to 16 bytes.
    uint pad1;                       // Zero.
    uint pad2;                       // Zero.
    vec4 uniforms;                   // `rng_uniform4(k.x, k.y, k.z)`: k read as (seed, vertex, stream); four uniforms in [0, 1).
};

struct SamplingOracleInput {
    vec4 u;                          // Four uniforms in [0, 1): xy feed the 2D warps, zw the disk and the scalar functions.
    vec3 direction;                  // A direction, not necessarily unit: the normal of the frame (normalized by the kernel) and, with |z| + 0.001 for z, the GGX outgoing direction.
    float alpha;                     // The GGX roughness alpha of `sample_ggx_vndf`.
};

struct SamplingOracleOutput {
    vec3 cosine_hemisphere;          // `sample_cosine_hemisphere(u.xy)`, local frame (z up).
    float cosine_pdf;                // `pdf_cosine_hemisphere(2 u.z - 1)`: the density of a direction of that cosine, per steradian.
    vec3 uniform_sphere;             // `sample_uniform_sphere(u.xy)`.
    float power_heuristic;           // `power_heuristic(u.z, u.w)`.
    vec2 triangle;                   // `sample_triangle(u.xy)`: barycentrics (b1, b2).
    vec2 concentric_disk;            // `sample_concentric_disk(u.zw)`: a point of the unit disk.
    vec3 ggx_vndf;                   // `sample_ggx_vndf(wo, alpha, u.xy)`: a visible microfacet normal, local frame, wo the input direction with |z| + 0.001 for z, normalized.
    float pad0;                      // Zero.
    vec3 onb_tangent;                // The tangent t of `build_onb(n)`, world space.
    float pad1;                      // Zero.
    vec3 onb_bitangent;              // The bitangent b of `build_onb(n)`, world space.
    float pad2;                      // Zero.
    vec3 round_trip;                 // `to_world(to_local(u.xyz, t, b, n), t, b, n)`: u.xyz again, within rounding.
    float pad3;                      // Zero.
};

struct OracleRay {
    vec3 origin;                     // The ray's origin.
    float tmax;                      // The largest ray parameter that counts, in units of |dir| (0: an inactive ray).
    vec3 dir;                        // The ray's direction, not necessarily unit.
    float pad;                       // Zero; pads the record to 32 bytes.
};

struct OracleHit {
    float t;                         // The ray parameter of the hit, in units of |dir|.
    uint triangle;                   // The triangle hit (in the scene's BVH leaf order), or `NO_HIT`.
    vec2 bary;                       // The barycentrics (b1, b2) of the hit, weights of vertices 1 and 2.
};

struct TracePairOracleInput {
    OracleRay closest;               // The closest-hit ray.
    OracleRay shadow;                // The shadow ray, occluded by any hit before its tmax.
};

struct TracePairOracleOutput {
    OracleHit hit;                   // The closest ray's hit.
    uint occluded;                   // 1 if the shadow ray is occluded, else 0.
    uint pad0;                       // Zero; this and the next two pad the record to 32 bytes.
    uint pad1;                       // Zero.
    uint pad2;                       // Zero.
};

struct BsdfOracleInput {
    vec3 geometric_normal;           // The geometric normal.
    float pad0;                      // Zero.
    vec3 shading_normal;             // The shading normal.
    float pad1;                      // Zero.
    vec3 wo;                         // The outgoing direction wo, pointing away from the surface.
    float pad2;                      // Zero.
    vec3 wi;                         // The incident direction wi of `bsdf_eval_pdf`, pointing away from the surface.
    float pad3;                      // Zero.
    vec4 u;                          // The uniforms of `bsdf_sample` (xy: direction, z: lobe choice, w: reflect/refract choice).
};

struct BsdfOracleOutput {
    vec3 f;                          // The BSDF value f(wo, wi), linear RGB, per steradian.
    float pdf;                       // The solid-angle pdf of sampling wi, per steradian.
    vec3 sample_wi;                  // The sampled direction, world space.
    float sample_pdf;                // The sampled direction's solid-angle pdf, per steradian.
    vec3 sample_weight;              // The sample's weight f |cos| / pdf, linear RGB.
    uint sample_lobe;                // The lobe sampled (`LOBE_*` bits); `LOBE_NONE` if sampling failed.
};

struct GrisOracleOffer {
    vec3 contribution;               // The candidate's contribution f, linear RGB.
    float target;                    // Its target p̂.
    float weight;                    // Its resampling weight w; zero or less: the input offers nothing (a failed shift).
    float u;                         // The uniform in [0, 1) that decides whether it replaces the chosen candidate.
    uint lost;                       // 1 if recording the candidate fails when it is chosen (`record_chosen`'s loss), else 0.
    uint pad;                        // Zero; pads the record to 32 bytes.
};

struct GrisOracleOutput {
    vec4 mis_weights[3];             // The MIS weight m_i of input i at `[i / 4][i % 4]` for i < n; zero past n.
    vec3 expected;                   // The expectation of f(Y) W_Y over the choice, linear RGB.
    int chosen_input;                // The input the chosen candidate came from; -1: none.
    float weight;                    // W of the result.
    float confidence;                // M of the result.
    float pad0;                      // Zero; this and the next pad the record to 80 bytes.
    float pad1;                      // Zero.
};

struct SceneOracleInput {
    OracleRay ray;                   // The ray of `trace_closest` and `trace_occluded`; its origin is also the shading point of `sample_light`, and its direction that point's normal.
    vec3 light_uniforms;             // The uniforms of `sample_light` (the light choice and the point or direction on it).
    float pad0;                      // Zero.
    vec2 image_point;                // The image point of `camera_ray_dir`, in pixels of the frame parameters' image.
    vec2 pad1;                       // Zero; pads the record to 64 bytes.
};

struct SceneOracleOutput {
    OracleHit hit;                   // `trace_closest` of the ray.
    vec3 offset_origin;              // `offset_ray_origin` of the ray's origin and direction off triangle i mod the triangle count (i the item).
    uint occluded;                   // 1 if `trace_occluded` found the ray occluded, else 0.
    vec3 light_dir;                  // The sampled light's direction from the shading point, unit.
    float light_dist;                // The distance to the sampled point, scene units; infinite for the environment and distant lights.
    vec3 light_radiance;             // The sampled radiance.
    float light_pdf;                 // The sample's solid-angle pdf, per steradian (a probability for a punctual light).
    vec3 camera_dir;                 // `camera_ray_dir` of the image point: camera 0's ray direction, unit.
    uint light_triangle;             // The sampled emitter (`LightSample::triangle`): a triangle, a punctual light with `PUNCTUAL_LIGHT_BIT` set, or `NO_EMITTER` for the environment.
    uint punctual_shadowed;          // 1 if the sample is a punctual light and `punctual_occluded` blocks it, else 0.
    float pdf_again;                 // The sample's pdf recomputed as MIS and the shifts do (`environment_pdf`, `light_select_pmf` or `emitter_pdf`); 0 when the sample's pdf is 0.
    uvec2 pad;                       // Zero; pads the record to 96 bytes.
};

struct AlphaOracleInput {
    vec3 origin;                     // The ray's origin.
    float shadow_tmax;               // The shadow ray's tmax, in units of |dir| (the closest ray has none).
    vec3 dir;                        // The ray's direction, unit.
    uint triangle;                   // The triangle of `material_alpha` and `alpha_keeps`, and of `alpha_hash` with the ray.
    vec2 bary;                       // The barycentrics (b1, b2) on that triangle.
    vec2 pad;                        // Zero; pads the record to 48 bytes.
};

struct AlphaOracleOutput {
    OracleHit hit;                   // `bvh_traverse`'s closest hit kept by alpha testing.
    uint any_hit;                    // 1 if `bvh_traverse`'s any-hit query meets a kept hit before the shadow tmax, else 0.
    uint pair_occluded;              // 1 if `trace_pair`'s shadow ray is occluded, else 0.
    float hash;                      // `alpha_hash` of the ray and the item's triangle, in [0, 1).
    float alpha;                     // `material_alpha` at the item's point: the coverage alpha, in [0, 1].
    OracleHit pair_hit;              // `trace_pair`'s closest hit.
    uint keeps;                      // 1 if `alpha_keeps` keeps the item's point as a hit of the ray, else 0.
    uint pad0;                       // Zero; this and the next two pad the record to 64 bytes.
    uint pad1;                       // Zero.
    uint pad2;                       // Zero.
};

struct SurfaceOracleInput {
    vec2 bary;                       // The barycentrics (b1, b2) of the point on the triangle.
    uint triangle;                   // The triangle.
    uint texture_index;              // The texture of `texture_lookup`.
    vec2 lookup_uv;                  // The texture coordinates of `texture_lookup` (any real values: the address modes apply).
    uint srgb;                       // 1 if `texture_lookup` decodes sRGB texels, else 0.
    uint pad0;                       // Zero.
    vec3 point;                      // The point in scene coordinates (the barycentrics' point), for `triangle_bary`.
    float pad1;                      // Zero; pads the record to 48 bytes.
};

struct SurfaceOracleOutput {
    vec3 normal;                     // `surface_at`'s interpolated normal.
    float handedness;                // `surface_at`'s tangent handedness, ±1.
    vec3 tangent;                    // `surface_at`'s tangent.
    float pad0;                      // Zero.
    vec2 uv0;                        // `surface_at`'s texture coordinates of set 0.
    vec2 uv1;                        // `surface_at`'s texture coordinates of set 1.
    vec4 texel;                      // `texture_lookup` of the input's texture and coordinates: RGBA.
    vec3 base_color;                 // `textured_material`'s base colour.
    float metallic;                  // `textured_material`'s metallic factor.
    vec3 emission;                   // `textured_material`'s emission, radiance.
    float roughness;                 // `textured_material`'s perceptual roughness.
    vec3 normal_mapped;              // `normal_mapped`: the shading normal the normal texture gives, unit.
    float pad1;                      // Zero.
    vec2 bary;                       // `triangle_bary` of the input's point: barycentrics (b1, b2).
    vec2 base_color_uv;              // `texture_coordinates` of the material's base-colour slot: the coordinates its lookup uses.
    vec3 shading_normal;             // `shading_normal` of the point.
    float hit_roughness;             // The roughness of the material `hit_shading` returns.
    vec3 hit_normal;                 // The shading normal `hit_shading` returns.
    float hit_metallic;              // The metallic factor of the material `hit_shading` returns.
    vec3 frame_tangent;              // `texture_tangent_frame` of the material's normal texture: the tangent.
    float frame_handedness;          // `texture_tangent_frame`'s handedness, ±1.
    vec3 color;                      // `surface_at`'s vertex colour (COLOR_0; white without one).
    float pad2;                      // Zero; pads the record to 192 bytes.
};

struct ShiftOracleParams {
    float roughness_threshold;       // Perceptual roughness below which a GGX lobe counts as glossy: such a vertex cannot be a reconnection vertex.
    float distance_threshold;        // Minimum distance in scene units between a reconnection vertex and its predecessor.
};

struct ShiftOracleTarget {
    vec3 primary_hit;                // The target domain's primary hit y1 (for an inverse shift, the base path's x1).
    uint triangle;                   // The triangle of that hit.
    vec3 camera;                     // The target domain's camera position x0.
    float pad;                       // Zero; pads the record to 32 bytes.
};

struct ShiftOracleOutput {
    PathRecord record;               // The shifted path's record.
    vec3 contribution;               // The shifted path's contribution f(Y), linear RGB; zero for a failed shift.
    uint valid;                      // 1 if the shift succeeded, else 0.
    float jacobian;                  // The shift's Jacobian |dY/dX|.
    uint vertex_count;               // How many vertices of the shifted path `vertices` holds.
    uint pad0;                       // Zero.
    uint pad1;                       // Zero.
    vec4 vertices[7];                // The shifted path's vertices y1..yk as (position, 0); zero past `vertex_count`.
};

struct CandidatesOracleParams {
    uint max_path_length;            // The longest path, in vertices x1..xk.
    float roughness_threshold;       // Perceptual roughness below which a GGX lobe counts as glossy (`ShiftParams`).
    float distance_threshold;        // Minimum distance in scene units between a reconnection vertex and its predecessor.
    float mis_scale;                 // The candidates' MIS weight 1/N among N paths, which scales their resampling weights.
};

struct CandidatesOracleInput {
    vec3 primary_hit;                // The primary hit y1.
    uint triangle;                   // The triangle of that hit.
    vec3 camera;                     // The camera position x0.
    uint seed;                       // The path's random-number key (`path_seed`).
};

struct CandidatesOracleOutput {
    PathRecord record;               // The chosen path's record (`reservoir_empty`'s if none was chosen).
    vec3 expected;                   // The expectation of f(Y) W_Y over the choice, linear RGB.
    float weight_sum;                // The sum of the candidates' resampling weights.
    float chosen_target;             // p̂ of the chosen candidate.
    float weight;                    // W of the result.
    uint chosen_lost;                // 1 if the chosen path could not be recorded (`chosen_lost`), else 0.
    uint nonfinite_weights;          // Candidates whose resampling weight was not finite.
    uint candidates_dropped;         // Candidates dropped (`local_candidates_dropped`).
    uint pad0;                       // Zero; this and the next two pad the record to 128 bytes.
    uint pad1;                       // Zero.
    uint pad2;                       // Zero.
};

#endif
