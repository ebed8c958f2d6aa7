//! Records of the oracle kernels (glsl/oracle/), which run GLSL functions on inputs a test
//! chose and write what they returned, for tests/suite/ to compare with the Rust twins.
//! Declared here like every other record, so the kernels and the tests read one layout.

use bytemuck::{Pod, Zeroable};

use crate::gpu_record;
use crate::path_record::PathRecord;
use crate::shader_interface::MAX_PATH_LENGTH;

gpu_record! {
    struct;
    /// One input of a resampling on the GRIS toy's analytic domains (glsl/oracle/reuse_oracle.comp).
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct ReuseToyInput {
        /// The sample's position in its domain, in [0, 1].
        pub x: f32,
        /// W_X: 1 / pdf(x); 0 for an empty reservoir.
        pub weight: f32,
        /// The confidence weight c.
        pub confidence: f32,
        /// The domain: 0 (canonical), 1 or 2.
        pub domain: u32,
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/reuse_oracle.comp writes per resampling: the reservoir that
    /// `resample_inputs` returned and its counters.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct ReuseOracleOutput {
        /// The expectation of f(Y) W_Y over the choice, linear RGB.
        pub expected: [f32; 3],
        /// W of the result.
        pub weight: f32,
        /// M of the result.
        pub confidence: f32,
        /// The chosen sample's position in the canonical domain.
        pub chosen_x: f32,
        /// The input the chosen sample came from; -1: none.
        pub chosen_input: i32,
        /// The domain the chosen sample came from.
        pub chosen_domain: u32,
        /// Shifts that failed.
        pub shifts_failed: u32,
        /// Resampling weights that were not finite.
        pub nonfinite_weights: u32,
        /// Zero; pads the record to 48 bytes.
        pub pad: [u32; 2],
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/rng_oracle.comp writes per key k (its input, one `uvec4` per item): the
    /// random numbers of crates/shading-core/src/rng.rs, compared bit for bit.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct RngOracleOutput {
        /// `pcg4d(k)`, the hash of all four words.
        pub pcg4d: [u32; 4],
        /// `path_seed(k.x, k.y, k.z)`: k read as (pixel, sample index, seed).
        pub path_seed: u32,
        /// Zero; this and the next two align `uniforms` to 16 bytes.
        pub pad0: u32,
        /// Zero.
        pub pad1: u32,
        /// Zero.
        pub pad2: u32,
        /// `rng_uniform4(k.x, k.y, k.z)`: k read as (seed, vertex, stream); four uniforms in [0, 1).
        pub uniforms: [f32; 4],
    }
}

gpu_record! {
    struct;
    /// One item of glsl/oracle/sampling_oracle.comp: uniforms and a direction for the warps of
    /// crates/shading-core/src/sampling.rs.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct SamplingOracleInput {
        /// Four uniforms in [0, 1): xy feed the 2D warps, zw the disk and the scalar functions.
        pub u: [f32; 4],
        /// A direction, not necessarily unit: the normal of the frame (normalized by the kernel)
        /// and, with |z| + 0.001 for z, the GGX outgoing direction.
        pub direction: [f32; 3],
        /// The GGX roughness alpha of `sample_ggx_vndf`.
        pub alpha: f32,
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/sampling_oracle.comp writes per item, u and n the input's uniforms and
    /// normalized direction; directions are unit vectors in the frame they are sampled in.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct SamplingOracleOutput {
        /// `sample_cosine_hemisphere(u.xy)`, local frame (z up).
        pub cosine_hemisphere: [f32; 3],
        /// `pdf_cosine_hemisphere(2 u.z - 1)`: the density of a direction of that cosine, per steradian.
        pub cosine_pdf: f32,
        /// `sample_uniform_sphere(u.xy)`.
        pub uniform_sphere: [f32; 3],
        /// `power_heuristic(u.z, u.w)`.
        pub power_heuristic: f32,
        /// `sample_triangle(u.xy)`: barycentrics (b1, b2).
        pub triangle: [f32; 2],
        /// `sample_concentric_disk(u.zw)`: a point of the unit disk.
        pub concentric_disk: [f32; 2],
        /// `sample_ggx_vndf(wo, alpha, u.xy)`: a visible microfacet normal, local frame, wo the
        /// input direction with |z| + 0.001 for z, normalized.
        pub ggx_vndf: [f32; 3],
        /// Zero.
        pub pad0: f32,
        /// The tangent t of `build_onb(n)`, world space.
        pub onb_tangent: [f32; 3],
        /// Zero.
        pub pad1: f32,
        /// The bitangent b of `build_onb(n)`, world space.
        pub onb_bitangent: [f32; 3],
        /// Zero.
        pub pad2: f32,
        /// `to_world(to_local(u.xyz, t, b, n), t, b, n)`: u.xyz again, within rounding.
        pub round_trip: [f32; 3],
        /// Zero.
        pub pad3: f32,
    }
}

gpu_record! {
    struct;
    /// A ray given to an oracle kernel; positions and directions in scene coordinates.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct OracleRay {
        /// The ray's origin.
        pub origin: [f32; 3],
        /// The largest ray parameter that counts, in units of |dir| (0: an inactive ray).
        pub tmax: f32,
        /// The ray's direction, not necessarily unit.
        pub dir: [f32; 3],
        /// Zero; pads the record to 32 bytes.
        pub pad: f32,
    }
}

gpu_record! {
    struct;
    /// A closest hit as an oracle kernel writes it (GLSL `Hit`, Rust `restir_pt_shading_core::bvh::Hit`).
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct OracleHit {
        /// The ray parameter of the hit, in units of |dir|.
        pub t: f32,
        /// The triangle hit (in the scene's BVH leaf order), or `NO_HIT`.
        pub triangle: u32,
        /// The barycentrics (b1, b2) of the hit, weights of vertices 1 and 2.
        pub bary: [f32; 2],
    }
}

gpu_record! {
    struct;
    /// One item of glsl/oracle/trace_pair_oracle.comp: the two rays `trace_pair` traces together.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct TracePairOracleInput {
        /// The closest-hit ray.
        pub closest: OracleRay,
        /// The shadow ray, occluded by any hit before its tmax.
        pub shadow: OracleRay,
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/trace_pair_oracle.comp writes per item: `trace_pair`'s results.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct TracePairOracleOutput {
        /// The closest ray's hit.
        pub hit: OracleHit,
        /// 1 if the shadow ray is occluded, else 0.
        pub occluded: u32,
        /// Zero; this and the next two pad the record to 32 bytes.
        pub pad0: u32,
        /// Zero.
        pub pad1: u32,
        /// Zero.
        pub pad2: u32,
    }
}

gpu_record! {
    struct;
    /// One item of glsl/oracle/bsdf_oracle.comp (the material is the item's entry of the
    /// `Materials` binding): the directions of `bsdf_eval_pdf` and the uniforms of
    /// `bsdf_sample`, all vectors unit and in world space.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct BsdfOracleInput {
        /// The geometric normal.
        pub geometric_normal: [f32; 3],
        /// Zero.
        pub pad0: f32,
        /// The shading normal.
        pub shading_normal: [f32; 3],
        /// Zero.
        pub pad1: f32,
        /// The outgoing direction wo, pointing away from the surface.
        pub wo: [f32; 3],
        /// Zero.
        pub pad2: f32,
        /// The incident direction wi of `bsdf_eval_pdf`, pointing away from the surface.
        pub wi: [f32; 3],
        /// Zero.
        pub pad3: f32,
        /// The uniforms of `bsdf_sample` (xy: direction, z: lobe choice, w: reflect/refract choice).
        pub u: [f32; 4],
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/bsdf_oracle.comp writes per item: `bsdf_eval_pdf(wi)` and `bsdf_sample(u)`.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct BsdfOracleOutput {
        /// The BSDF value f(wo, wi), linear RGB, per steradian.
        pub f: [f32; 3],
        /// The solid-angle pdf of sampling wi, per steradian.
        pub pdf: f32,
        /// The sampled direction, world space.
        pub sample_wi: [f32; 3],
        /// The sampled direction's solid-angle pdf, per steradian.
        pub sample_pdf: f32,
        /// The sample's weight f |cos| / pdf, linear RGB.
        pub sample_weight: [f32; 3],
        /// The lobe sampled (`LOBE_*` bits); `LOBE_NONE` if sampling failed.
        pub sample_lobe: u32,
    }
}

gpu_record! {
    struct;
    /// One candidate that an input offers to the resampler of glsl/oracle/gris_oracle.comp.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct GrisOracleOffer {
        /// The candidate's contribution f, linear RGB.
        pub contribution: [f32; 3],
        /// Its target p̂.
        pub target: f32,
        /// Its resampling weight w; zero or less: the input offers nothing (a failed shift).
        pub weight: f32,
        /// The uniform in [0, 1) that decides whether it replaces the chosen candidate.
        pub u: f32,
        /// 1 if recording the candidate fails when it is chosen (`record_chosen`'s loss), else 0.
        pub lost: u32,
        /// Zero; pads the record to 32 bytes.
        pub pad: u32,
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/gris_oracle.comp writes per resampling of n inputs: the MIS weights of
    /// `mis_weight` and the reservoir of `resampler_finish`.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct GrisOracleOutput {
        /// The MIS weight m_i of input i at `[i / 4][i % 4]` for i < n; zero past n.
        pub mis_weights: [[f32; 4]; 3],
        /// The expectation of f(Y) W_Y over the choice, linear RGB.
        pub expected: [f32; 3],
        /// The input the chosen candidate came from; -1: none.
        pub chosen_input: i32,
        /// W of the result.
        pub weight: f32,
        /// M of the result.
        pub confidence: f32,
        /// Zero; this and the next pad the record to 80 bytes.
        pub pad0: f32,
        /// Zero.
        pub pad1: f32,
    }
}

gpu_record! {
    struct;
    /// One item of glsl/oracle/scene_oracle.comp: a ray and the random numbers of light sampling
    /// and the camera at its origin.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct SceneOracleInput {
        /// The ray of `trace_closest` and `trace_occluded`; its origin is also the shading point
        /// of `sample_light`, and its direction that point's normal.
        pub ray: OracleRay,
        /// The uniforms of `sample_light` (the light choice and the point or direction on it).
        pub light_uniforms: [f32; 3],
        /// Zero.
        pub pad0: f32,
        /// The image point of `camera_ray_dir`, in pixels of the frame parameters' image.
        pub image_point: [f32; 2],
        /// Zero; pads the record to 64 bytes.
        pub pad1: [f32; 2],
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/scene_oracle.comp writes per item; positions and directions in scene
    /// coordinates, radiance linear RGB.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct SceneOracleOutput {
        /// `trace_closest` of the ray.
        pub hit: OracleHit,
        /// `offset_ray_origin` of the ray's origin and direction off triangle i mod the
        /// triangle count (i the item).
        pub offset_origin: [f32; 3],
        /// 1 if `trace_occluded` found the ray occluded, else 0.
        pub occluded: u32,
        /// The sampled light's direction from the shading point, unit.
        pub light_dir: [f32; 3],
        /// The distance to the sampled point, scene units; infinite for the environment and
        /// distant lights.
        pub light_dist: f32,
        /// The sampled radiance.
        pub light_radiance: [f32; 3],
        /// The sample's solid-angle pdf, per steradian (a probability for a punctual light).
        pub light_pdf: f32,
        /// `camera_ray_dir` of the image point: camera 0's ray direction, unit.
        pub camera_dir: [f32; 3],
        /// The sampled emitter (`LightSample::triangle`): a triangle, a punctual light with
        /// `PUNCTUAL_LIGHT_BIT` set, or `NO_EMITTER` for the environment.
        pub light_triangle: u32,
        /// 1 if the sample is a punctual light and `punctual_occluded` blocks it, else 0.
        pub punctual_shadowed: u32,
        /// The sample's pdf recomputed as MIS and the shifts do (`environment_pdf`,
        /// `light_select_pmf` or `emitter_pdf`); 0 when the sample's pdf is 0.
        pub pdf_again: f32,
        /// Zero; pads the record to 96 bytes.
        pub pad: [u32; 2],
    }
}

gpu_record! {
    struct;
    /// One item of glsl/oracle/alpha_oracle.comp: a ray, and a point on a triangle for the
    /// per-triangle alpha functions; scene coordinates.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct AlphaOracleInput {
        /// The ray's origin.
        pub origin: [f32; 3],
        /// The shadow ray's tmax, in units of |dir| (the closest ray has none).
        pub shadow_tmax: f32,
        /// The ray's direction, unit.
        pub dir: [f32; 3],
        /// The triangle of `material_alpha` and `alpha_keeps`, and of `alpha_hash` with the ray.
        pub triangle: u32,
        /// The barycentrics (b1, b2) on that triangle.
        pub bary: [f32; 2],
        /// Zero; pads the record to 48 bytes.
        pub pad: [f32; 2],
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/alpha_oracle.comp writes per item.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct AlphaOracleOutput {
        /// `bvh_traverse`'s closest hit kept by alpha testing.
        pub hit: OracleHit,
        /// 1 if `bvh_traverse`'s any-hit query meets a kept hit before the shadow tmax, else 0.
        pub any_hit: u32,
        /// 1 if `trace_pair`'s shadow ray is occluded, else 0.
        pub pair_occluded: u32,
        /// `alpha_hash` of the ray and the item's triangle, in [0, 1).
        pub hash: f32,
        /// `material_alpha` at the item's point: the coverage alpha, in [0, 1].
        pub alpha: f32,
        /// `trace_pair`'s closest hit.
        pub pair_hit: OracleHit,
        /// 1 if `alpha_keeps` keeps the item's point as a hit of the ray, else 0.
        pub keeps: u32,
        /// Zero; this and the next two pad the record to 64 bytes.
        pub pad0: u32,
        /// Zero.
        pub pad1: u32,
        /// Zero.
        pub pad2: u32,
    }
}

gpu_record! {
    struct;
    /// One item of glsl/oracle/surface_oracle.comp: a point on a triangle, and a texture lookup.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct SurfaceOracleInput {
        /// The barycentrics (b1, b2) of the point on the triangle.
        pub bary: [f32; 2],
        /// The triangle.
        pub triangle: u32,
        /// The texture of `texture_lookup`.
        pub texture_index: u32,
        /// The texture coordinates of `texture_lookup` (any real values: the address modes apply).
        pub lookup_uv: [f32; 2],
        /// 1 if `texture_lookup` decodes sRGB texels, else 0.
        pub srgb: u32,
        /// Zero.
        pub pad0: u32,
        /// The point in scene coordinates (the barycentrics' point), for `triangle_bary`.
        pub point: [f32; 3],
        /// Zero; pads the record to 48 bytes.
        pub pad1: f32,
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/surface_oracle.comp writes per item: the surface functions at the
    /// item's point; vectors in scene coordinates, colours linear RGB.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct SurfaceOracleOutput {
        /// `surface_at`'s interpolated normal.
        pub normal: [f32; 3],
        /// `surface_at`'s tangent handedness, ±1.
        pub handedness: f32,
        /// `surface_at`'s tangent.
        pub tangent: [f32; 3],
        /// Zero.
        pub pad0: f32,
        /// `surface_at`'s texture coordinates of set 0.
        pub uv0: [f32; 2],
        /// `surface_at`'s texture coordinates of set 1.
        pub uv1: [f32; 2],
        /// `texture_lookup` of the input's texture and coordinates: RGBA.
        pub texel: [f32; 4],
        /// `textured_material`'s base colour.
        pub base_color: [f32; 3],
        /// `textured_material`'s metallic factor.
        pub metallic: f32,
        /// `textured_material`'s emission, radiance.
        pub emission: [f32; 3],
        /// `textured_material`'s perceptual roughness.
        pub roughness: f32,
        /// `normal_mapped`: the shading normal the normal texture gives, unit.
        pub normal_mapped: [f32; 3],
        /// Zero.
        pub pad1: f32,
        /// `triangle_bary` of the input's point: barycentrics (b1, b2).
        pub bary: [f32; 2],
        /// `texture_coordinates` of the material's base-colour slot: the coordinates its lookup uses.
        pub base_color_uv: [f32; 2],
        /// `shading_normal` of the point.
        pub shading_normal: [f32; 3],
        /// The roughness of the material `hit_shading` returns.
        pub hit_roughness: f32,
        /// The shading normal `hit_shading` returns.
        pub hit_normal: [f32; 3],
        /// The metallic factor of the material `hit_shading` returns.
        pub hit_metallic: f32,
        /// `texture_tangent_frame` of the material's normal texture: the tangent.
        pub frame_tangent: [f32; 3],
        /// `texture_tangent_frame`'s handedness, ±1.
        pub frame_handedness: f32,
        /// `surface_at`'s vertex colour (COLOR_0; white without one).
        pub color: [f32; 3],
        /// Zero; pads the record to 192 bytes.
        pub pad2: f32,
    }
}

gpu_record! {
    struct;
    /// The reconnection criteria given to glsl/oracle/shift_oracle.comp (GLSL `ShiftParams`).
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct ShiftOracleParams {
        /// Perceptual roughness below which a GGX lobe counts as glossy: such a vertex cannot be a
        /// reconnection vertex.
        pub roughness_threshold: f32,
        /// Minimum distance in scene units between a reconnection vertex and its predecessor.
        pub distance_threshold: f32,
    }
}

gpu_record! {
    struct;
    /// The target domain of one shift of glsl/oracle/shift_oracle.comp (the record shifted is
    /// the item's entry of the `Records` binding); scene coordinates.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct ShiftOracleTarget {
        /// The target domain's primary hit y1 (for an inverse shift, the base path's x1).
        pub primary_hit: [f32; 3],
        /// The triangle of that hit.
        pub triangle: u32,
        /// The target domain's camera position x0.
        pub camera: [f32; 3],
        /// Zero; pads the record to 32 bytes.
        pub pad: f32,
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/shift_oracle.comp writes per item: the `ShiftResult` of the shift
    /// under test; scene coordinates.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct ShiftOracleOutput {
        /// The shifted path's record.
        pub record: PathRecord,
        /// The shifted path's contribution f(Y), linear RGB; zero for a failed shift.
        pub contribution: [f32; 3],
        /// 1 if the shift succeeded, else 0.
        pub valid: u32,
        /// The shift's Jacobian |dY/dX|.
        pub jacobian: f32,
        /// How many vertices of the shifted path `vertices` holds.
        pub vertex_count: u32,
        /// Zero.
        pub pad0: u32,
        /// Zero.
        pub pad1: u32,
        /// The shifted path's vertices y1..yk as (position, 0); zero past `vertex_count`.
        pub vertices: [[f32; 4]; MAX_PATH_LENGTH],
    }
}

gpu_record! {
    struct;
    /// The parameters of every item of glsl/oracle/candidates_oracle.comp.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct CandidatesOracleParams {
        /// The longest path, in vertices x1..xk.
        pub max_path_length: u32,
        /// Perceptual roughness below which a GGX lobe counts as glossy (`ShiftParams`).
        pub roughness_threshold: f32,
        /// Minimum distance in scene units between a reconnection vertex and its predecessor.
        pub distance_threshold: f32,
        /// The candidates' MIS weight 1/N among N paths, which scales their resampling weights.
        pub mis_scale: f32,
    }
}

gpu_record! {
    struct;
    /// One item of glsl/oracle/candidates_oracle.comp: the traced path's start; scene coordinates.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct CandidatesOracleInput {
        /// The primary hit y1.
        pub primary_hit: [f32; 3],
        /// The triangle of that hit.
        pub triangle: u32,
        /// The camera position x0.
        pub camera: [f32; 3],
        /// The path's random-number key (`path_seed`).
        pub seed: u32,
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/candidates_oracle.comp writes per item: the Resampler after
    /// `stream_path_candidates` and the pass counters.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct CandidatesOracleOutput {
        /// The chosen path's record (`reservoir_empty`'s if none was chosen).
        pub record: PathRecord,
        /// The expectation of f(Y) W_Y over the choice, linear RGB.
        pub expected: [f32; 3],
        /// The sum of the candidates' resampling weights.
        pub weight_sum: f32,
        /// p̂ of the chosen candidate.
        pub chosen_target: f32,
        /// W of the result.
        pub weight: f32,
        /// 1 if the chosen path could not be recorded (`chosen_lost`), else 0.
        pub chosen_lost: u32,
        /// Candidates whose resampling weight was not finite.
        pub nonfinite_weights: u32,
        /// Candidates dropped (`local_candidates_dropped`).
        pub candidates_dropped: u32,
        /// Zero; this and the next two pad the record to 128 bytes.
        pub pad0: u32,
        /// Zero.
        pub pad1: u32,
        /// Zero.
        pub pad2: u32,
    }
}
