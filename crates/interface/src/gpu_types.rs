//! The records of the scene bindings (set 0) and of the ReSTIR PT kernels, with the constants
//! of their encodings, each declared once by `gpu_record!` / `glsl_consts!`: the GLSL structs
//! and constants are generated from these declarations (docs/layout.md). Positions are in scene coordinates: world space moved by -`Scene::origin`
//! (`restir_pt_scene::Scene`).

use bytemuck::{Pod, Zeroable};

use crate::{glsl_consts, gpu_record};

glsl_consts! {
    /// The GLSL declarations of this module's constants, for the generated header.
    fn glsl_constants;
    /// [`Material::flags`] bit: both faces scatter and emit (glTF `doubleSided`); otherwise only the
    /// front face (counter-clockwise winding) emits.
    pub const MATERIAL_DOUBLE_SIDED: u32 = 1;
    /// [`Material::flags`] bit: a `KHR_materials_unlit` material, drawn as emission of its base
    /// colour, so that COLOR_0 multiplies its emission (`texture::vertex_colored`).
    pub const MATERIAL_UNLIT: u32 = 2;
    /// [`Material::flags`] bit: an emitter with an alpha mode, whose emission is multiplied by its
    /// coverage at the point (`texture::textured_material`): 0 where alpha < alphaCutoff (the
    /// surface is not there for traversal either), else 1, or alpha with
    /// [`MATERIAL_BLEND_EMISSION`]. Every estimator reads emission through it, so a light sample
    /// on a hole adds nothing and a label's letters glow while its background stays transparent.
    pub const MATERIAL_ALPHA_EMISSION: u32 = 4;
    /// [`Material::flags`] bit beside [`MATERIAL_ALPHA_EMISSION`]: a BLEND emitter, traversed where
    /// alpha > 0 and emitting alpha × emission (over-blending's weight of its own colour).
    pub const MATERIAL_BLEND_EMISSION: u32 = 8;
    /// [`Triangle::emitter`] of a triangle that emits nothing.
    pub const NO_EMITTER: u32 = u32::MAX;
    /// A closest-hit query's triangle when the ray hit nothing (`Surface::triangle`,
    /// `PathRecord::rc_triangle` of an escaped vertex).
    pub const NO_HIT: u32 = u32::MAX;
    /// Bits of [`BvhNode::leaf`] that hold a leaf's triangle count: leaves hold at most 15 triangles.
    pub const LEAF_COUNT_BITS: u32 = 4;
    /// Mask of the triangle count in [`BvhNode::leaf`], `(1 << LEAF_COUNT_BITS) - 1`.
    pub const LEAF_COUNT_MASK: u32 = 15;
    /// Set in `Emitter::triangle` (and in path vertices' triangle ids) for a punctual light: the low
    /// bits are the light's index in `Scene::lights`. Triangle indices stay below 2^26.
    pub const PUNCTUAL_LIGHT_BIT: u32 = 1 << 31;
    /// The `kind` word of a punctual light's first emitter row: a point light.
    pub const PUNCTUAL_POINT: u32 = 0;
    /// A spot light (glTF `KHR_lights_punctual` `spot`).
    pub const PUNCTUAL_SPOT: u32 = 1;
    /// A directional light.
    pub const PUNCTUAL_DIRECTIONAL: u32 = 2;
    /// [`LightNode::flags`] bit: a leaf, whose `child` is the light's emitter row.
    pub const LIGHT_NODE_LEAF: u32 = 1;
    /// [`LightNode::flags`] bit: the lights below may emit on both sides of their cone (pbrt-v4
    /// `LightBounds::twoSided`): the importance folds the angle to the axis into [0, π/2].
    pub const LIGHT_NODE_TWO_SIDED: u32 = 2;
    /// [`FrameParams::flags`] bit: the path tracer ends paths by Russian roulette after a few bounces
    /// (glsl/path_tracer.glsl) instead of only at `max_depth`.
    pub const FLAG_RUSSIAN_ROULETTE: u32 = 1;
}

gpu_record! {
    struct;
    /// A material's constant factors, as the kernels read them (glsl/interface/types.glsl `Material`, 64 bytes,
    /// std430); textures scale them per hit (see `restir_pt_shading::texture`). The BSDF built from it is
    /// described in docs/materials.md.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct Material {
        /// glTF baseColorFactor, linear RGB in [0, 1]: the diffuse albedo of non-metals and F0 of metals.
        pub base_color: [f32; 3],
        /// glTF metallicFactor in [0, 1]: the blend between the non-metal and the conductor lobes.
        pub metallic: f32,
        /// Emitted radiance, linear RGB in W/(m² sr): emissiveFactor already multiplied by
        /// `KHR_materials_emissive_strength`.
        pub emission: [f32; 3],
        /// Perceptual (linear) roughness in [0, 1]; the GGX alpha is its square
        /// (`restir_pt_shading::bsdf::ggx_alpha`).
        pub roughness: f32,
        /// `KHR_materials_transmission` transmissionFactor in [0, 1]: the dielectric interface lobe
        /// replaces that share of the non-metal part only (weights `bsdf::lobe_weights`).
        pub transmission: f32,
        /// Index of refraction of the inside (`KHR_materials_ior`, glTF default 1.5); also sets the
        /// specular layer's F0 = ((ior - 1) / (ior + 1))² · specular_color.
        pub ior: f32,
        /// Bit set: [`MATERIAL_DOUBLE_SIDED`], [`MATERIAL_UNLIT`], [`MATERIAL_ALPHA_EMISSION`],
        /// [`MATERIAL_BLEND_EMISSION`].
        pub flags: u32,
        /// `KHR_materials_specular` specularFactor: the strength of the non-metal specular layer
        /// (docs/materials.md); 0 makes the non-metal part purely Lambertian.
        pub specular: f32,
        /// `KHR_materials_specular` specularColorFactor (linear RGB), scaling the layer's F0.
        pub specular_color: [f32; 3],
        /// Padding to a 16-byte multiple (std430); always 0.
        pub pad: u32,
    }
}

gpu_record! {
    struct;
    /// A triangle in scene coordinates, stored as vertex 0 and two edges so that the ray-triangle test
    /// (Möller-Trumbore) needs no subtraction (glsl/interface/types.glsl `Triangle`, 48 bytes, std430). The
    /// counter-clockwise winding v0, v0 + e1, v0 + e2 defines the front face.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct Triangle {
        /// Vertex 0, scene coordinates.
        pub v0: [f32; 3],
        /// Index into the scene's materials.
        pub material: u32,
        /// Vertex 1 minus vertex 0, scene coordinates.
        pub e1: [f32; 3],
        /// Index into the emitter table, or [`NO_EMITTER`] if the triangle does not emit.
        pub emitter: u32,
        /// Vertex 2 minus vertex 0, scene coordinates.
        pub e2: [f32; 3],
        /// 1 if the triangle's material is alpha-tested (`alphaMode` MASK or BLEND), else 0, set by
        /// `restir_pt_scene::Scene::build`: the traversal loops tell alpha-tested hits apart by it
        /// without loading materials (glsl/shading_core/alpha_pass.glsl, `restir_pt_shading::alpha_pass`).
        pub alpha_tested: u32,
    }
}

gpu_record! {
    struct;
    /// A node of the BVH in depth-first order with skip links, for stackless traversal
    /// (glsl/interface/types.glsl `BvhNode`, 32 bytes, std430): on a box hit an interior node continues at the
    /// next node (its left child) and a leaf tests its triangles and continues at `skip`; on a miss
    /// traversal continues at `skip`. A `skip` equal to the node count ends the traversal.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct BvhNode {
        /// Minimum corner of the node's bounding box, scene coordinates.
        pub lo: [f32; 3],
        /// Index of the node to visit after this subtree (or after a missed box).
        pub skip: u32,
        /// Maximum corner of the node's bounding box, scene coordinates.
        pub hi: [f32; 3],
        /// For a leaf, `(first triangle << LEAF_COUNT_BITS) | count` (see [`BvhNode::leaf_range`]);
        /// 0 for an interior node.
        pub leaf: u32,
    }
}

impl BvhNode {
    /// (first triangle, count) of a leaf; count 0 for interior nodes.
    pub fn leaf_range(&self) -> (u32, u32) {
        (self.leaf >> LEAF_COUNT_BITS, self.leaf & LEAF_COUNT_MASK)
    }
}

gpu_record! {
    struct;
    /// One light that next-event estimation can choose (glsl/interface/types.glsl `Emitter`, 16 bytes, std430):
    /// the emissive triangles first (a triangle's [`Triangle::emitter`] is its row), then the point
    /// and spot lights, then the directional lights. The lights before the directional ones are the
    /// leaves of the light tree ([`LightNode`]); each row keeps the path from the tree's root to its
    /// leaf so that the selection probability can be recomputed at any shading point. The light
    /// tree, the punctual lights' parameter rows and the environment map follow in the same buffer
    /// ([`LightNode::rows`], `restir_pt_scene::Scene::punctual_rows`), each 16-byte row read as four 32-bit words.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct Emitter {
        /// The emissive triangle's index, or [`PUNCTUAL_LIGHT_BIT`] | the punctual light's index.
        pub triangle: u32,
        /// The light tree's bit trail (pbrt-v4 `BVHLightSampler`): bit d set when the path from the
        /// root to this light's leaf takes the second child at depth d; 0 for a directional light.
        pub trail: u32,
        /// The light's largest radiant intensity, luminance (W/sr in the glTF emission unit): L·A
        /// for an emissive triangle, I for a point or spot light, the irradiance E for a
        /// directional light.
        pub intensity: f32,
        /// Index of the light's leaf among the light tree's nodes; `NO_EMITTER` for directional
        /// lights, which NEE takes beside the tree's drawn light.
        pub leaf: u32,
    }
}

impl Emitter {
    /// A row of four raw words (the punctual, light-tree and environment rows).
    pub fn from_words(w: [u32; 4]) -> Self {
        Self {
            triangle: w[0],
            trail: w[1],
            intensity: f32::from_bits(w[2]),
            leaf: w[3],
        }
    }
}

/// Rows of the emitter buffer per punctual light, after the light tree (glsl/interface/types.glsl):
/// (position, kind), (direction, cos outer), (intensity, cos inner), (emitter row, 0, 0, 0).
pub const PUNCTUAL_ROWS: usize = 4;

/// Emitter-buffer rows per light-tree node ([`LightNode::rows`]).
pub const LIGHT_NODE_ROWS: usize = 4;
/// The light tree is at most this deep: a bit trail is one 32-bit word.
pub const LIGHT_TREE_MAX_DEPTH: usize = 32;

gpu_record! {
    struct;
    /// A node of the light tree (pbrt-v4 `LightBVHNode` with uncompressed `LightBounds`; Conty
    /// Estevez & Kulla 2018): the bounds of the lights below it in scene coordinates, the sum of
    /// their largest radiant intensities, and the cone of their emission directions: every light
    /// below emits only along directions within θ_o + θ_e of `axis` (θ_o bounds the lights'
    /// normals or spot axes, θ_e the spread about each). Depth-first: an interior node's first child
    /// follows it, `child` is its second. glsl/shading/light_tree.glsl reads it as [`LIGHT_NODE_ROWS`] rows.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct LightNode {
        /// Lower corner of the bounds.
        pub lo: [f32; 3],
        /// Sum of the lights' largest radiant intensities (luminance, W/sr).
        pub intensity: f32,
        /// Upper corner of the bounds.
        pub hi: [f32; 3],
        /// cos θ_o, θ_o the half-angle of the cone of normals (1: one direction, -1: all).
        pub cos_theta_o: f32,
        /// Unit axis of the cone of normals.
        pub axis: [f32; 3],
        /// cos θ_e, θ_e the angle beyond θ_o within which the lights still emit (0: a cosine lobe).
        pub cos_theta_e: f32,
        /// A leaf's emitter row, an interior node's second child.
        pub child: u32,
        /// [`LIGHT_NODE_LEAF`] | [`LIGHT_NODE_TWO_SIDED`].
        pub flags: u32,
        /// Zero; pads the node to whole rows.
        pub pad: [u32; 2],
    }
}

impl LightNode {
    /// The node as emitter-buffer rows.
    pub fn rows(&self) -> [Emitter; LIGHT_NODE_ROWS] {
        bytemuck::cast(*self)
    }

    /// Whether the node is a leaf.
    pub fn is_leaf(&self) -> bool {
        self.flags & LIGHT_NODE_LEAF != 0
    }
}

impl Material {
    /// Whether [`MATERIAL_DOUBLE_SIDED`] is set in `flags`.
    pub fn is_double_sided(&self) -> bool {
        self.flags & MATERIAL_DOUBLE_SIDED != 0
    }
}

impl Triangle {
    /// The three vertices in scene coordinates, in winding order.
    pub fn vertices(&self) -> [glam::Vec3; 3] {
        let v0 = glam::Vec3::from(self.v0);
        [v0, v0 + glam::Vec3::from(self.e1), v0 + glam::Vec3::from(self.e2)]
    }

    /// Unnormalised geometric normal; its winding (counter-clockwise) defines the front face.
    pub fn normal_area2(&self) -> glam::Vec3 {
        glam::Vec3::from(self.e1).cross(glam::Vec3::from(self.e2))
    }

    /// Area in square scene units.
    pub fn area(&self) -> f32 {
        0.5 * self.normal_area2().length()
    }
}

gpu_record! {
    block;
    /// Binding 0 of every scene kernel (glsl/interface/scene_bindings.glsl), std430 with only vec4-sized rows.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct FrameParams {
        /// xyz: camera position, scene coordinates; w: tan(vertical field of view / 2) for this image
        /// (`restir_pt_scene::Camera::fill_params`).
        pub cam_position: [f32; 4],
        /// xyz: the camera's unit right axis, scene coordinates; w: aspect ratio width / height.
        pub cam_right: [f32; 4],
        /// xyz: the camera's unit up axis, scene coordinates; w unused (0).
        pub cam_up: [f32; 4],
        /// xyz: the camera's unit viewing direction, scene coordinates; w unused (0).
        pub cam_forward: [f32; 4],
        /// rgb: constant environment radiance (linear, W/(m² sr)); w: probability that light
        /// sampling picks the environment instead of another light.
        pub scene_env: [f32; 4],
        /// Image width in pixels.
        pub width: u32,
        /// Image height in pixels.
        pub height: u32,
        /// Sample index of a pixel's first path in this dispatch; with `render_seed` it keys the
        /// path's random numbers (`restir_pt_shading::rng::path_seed`).
        pub sample_offset: u32,
        /// Paths each pixel adds to its sums in one path-tracer dispatch.
        pub samples_per_dispatch: u32,
        /// Maximum path segments: 1 shows emitters seen directly, 2 adds direct lighting.
        pub max_depth: u32,
        /// The render's seed, mixed into every path's random-number key.
        pub render_seed: u32,
        /// Bit set: [`FLAG_RUSSIAN_ROULETTE`].
        pub flags: u32,
        /// Rows of [`Emitter`]s (every light but the environment); the punctual-light rows, the
        /// light tree and the environment map follow them in the buffer.
        pub emitter_count: u32,
    }
}

pub use crate::shader_interface::RESTIR_MAX_PASSES;

gpu_record! {
    struct;
    /// What the temporal pass reads of [`ReuseParams`]: the previous frame's camera, through which
    /// it reprojects, and the history's confidence cap.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct TemporalParams {
        /// The previous frame's camera position and tan(yfov / 2), laid out like
        /// [`FrameParams::cam_position`].
        pub prev_cam_position: [f32; 4],
        /// The previous frame's right axis and aspect ratio, as [`FrameParams::cam_right`].
        pub prev_cam_right: [f32; 4],
        /// The previous frame's up axis, as [`FrameParams::cam_up`].
        pub prev_cam_up: [f32; 4],
        /// The previous frame's viewing direction, as [`FrameParams::cam_forward`].
        pub prev_cam_forward: [f32; 4],
        /// Confidence cap of the history, as a multiple of the current reservoir's M; the initial
        /// pass also caps the running mean of the emission seen directly at this many frames.
        pub m_cap: f32,
        /// 1 if the previous frame's reservoirs and surfaces exist and temporal reuse is on.
        pub valid: u32,
        /// Zero; pads the record to its 16-byte alignment.
        pub pad: [u32; 2],
    }
}

gpu_record! {
    struct;
    /// What the initial pass reads of [`ReuseParams`].
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct InitialParams {
        /// Candidate paths per pixel and reservoir.
        pub candidates: u32,
        /// Jittered camera rays per reservoir for the emission seen directly.
        pub emission_rays: u32,
        /// 1 if the direct-emission buffer holds the running mean for this same camera pose.
        pub emission_history: u32,
    }
}

gpu_record! {
    struct;
    /// What a spatial round reads of [`ReuseParams`].
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct SpatialParams {
        /// Neighbours per round.
        pub neighbours: u32,
        /// Reuse radius in pixels.
        pub radius: f32,
    }
}

gpu_record! {
    block;
    /// Binding 5 of the ReSTIR kernels (glsl/interface/restir_bindings.glsl), std430: what every pass
    /// shares, a group per pass that reads it alone (as RTXDI's per-pass parameter structs),
    /// and the frame's pass table.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct ReuseParams {
        /// The temporal pass's parameters.
        pub temporal: TemporalParams,
        /// Perceptual roughness below which a glossy vertex cannot be a reconnection vertex
        /// (`restir_pt_shading::shift::ShiftParams`): where the initial pass records a path's
        /// reconnection vertex and the reuse passes' shifts reconnect.
        pub roughness_threshold: f32,
        /// Minimum distance, in scene units, between a reconnection vertex and its predecessor.
        pub distance_threshold: f32,
        /// Reused surfaces (temporal and spatial) need |dot(n, n')| >= this (unit geometric
        /// normals).
        pub normal_threshold: f32,
        /// Reused surfaces need |depth' - |x - camera'|| <= this * depth', x the canonical
        /// pixel's hit: a relative depth tolerance.
        pub depth_threshold: f32,
        /// Frames rendered since the renderer was built or last reset; keys the frame's random
        /// numbers.
        pub frame_index: u32,
        /// Independent reservoirs per pixel.
        pub reservoirs: u32,
        /// The initial pass's parameters.
        pub initial: InitialParams,
        /// The spatial rounds' parameters.
        pub spatial: SpatialParams,
        /// The frame's passes in dispatch order; a dispatch's push constant indexes them.
        pub passes: [RestirPass; RESTIR_MAX_PASSES],
    }
}

gpu_record! {
    struct;
    /// A pixel's primary hit in one frame (glsl/interface/restir_bindings.glsl).
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct Surface {
        /// Hit point of the ray through the pixel centre, scene coordinates.
        pub pos: [f32; 3],
        /// The hit triangle, or `restir_pt_shading::bvh::NO_HIT` if the camera ray escaped.
        pub triangle: u32,
        /// The camera position the ray left from, scene coordinates.
        pub camera: [f32; 3],
        /// Distance from the camera to `pos`, scene units.
        pub depth: f32,
    }
}

gpu_record! {
    struct;
    /// The first half of a stored reservoir (glsl/shading_core/reservoir.glsl).
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct ReservoirHead {
        /// `restir_pt_shading::path_record::PathRecord::seed`.
        pub seed: u32,
        /// `restir_pt_shading::path_record::PathRecord::info`.
        pub info: u32,
        /// `restir_pt_shading::path_record::PathRecord::lobes`.
        pub lobes: u32,
        /// `restir_pt_shading::path_record::PathRecord::rc_triangle`.
        pub rc_triangle: u32,
        /// `restir_pt_shading::path_record::PathRecord::rc_pos`.
        pub rc_pos: [f32; 3],
        /// `restir_pt_shading::path_record::PathRecord::rc_pdf`.
        pub rc_pdf: f32,
        /// `restir_pt_shading::path_record::PathRecord::rc_next`.
        pub rc_next: [f32; 3],
        /// `restir_pt_shading::path_record::PathRecord::rc_geometry`.
        pub rc_geometry: f32,
    }
}

gpu_record! {
    struct;
    /// The second half of a stored reservoir, with W and M (glsl/shading_core/reservoir.glsl).
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct ReservoirTail {
        /// `restir_pt_shading::path_record::PathRecord::suffix`.
        pub suffix: [f32; 3],
        /// `restir_pt_shading::path_record::PathRecord::rc_pdf_after`.
        pub rc_pdf_after: f32,
        /// `restir_pt_shading::path_record::PathRecord::contribution`.
        pub contribution: [f32; 3],
        /// `restir_pt_shading::path_record::PathRecord::rc_next_triangle`.
        pub rc_next_triangle: u32,
        /// The unbiased contribution weight W.
        pub weight: f32,
        /// The confidence weight M.
        pub confidence: f32,
        /// Padding to 48 bytes; always 0.
        pub pad0: u32,
        /// Padding to 48 bytes; always 0.
        pub pad1: u32,
    }
}

gpu_record! {
    block;
    /// The per-frame counters of the ReSTIR kernels (glsl/interface/restir_bindings.glsl).
    #[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
    pub struct RestirStats {
        /// The most iterations any subgroup's guarded loop ran (glsl/interface/loop_budget.glsl).
        pub max_loop_iterations: u32,
        /// Subgroups whose loop hit the iteration budget and was cut short (reported as
        /// `restir_pt_vk::error::GpuError::LoopLimit`).
        pub loop_budget_cut_groups: u32,
        /// Shift mappings attempted by the reuse passes.
        pub shifts_attempted: u32,
        /// Shifts that found no valid offset path (or whose weight was not finite).
        pub shifts_failed: u32,
        /// Resampling weights that came out NaN or infinite and were dropped.
        pub nonfinite_weights: u32,
        /// Initial candidates that could not be recorded as a path record and were dropped.
        pub candidates_dropped: u32,
        /// Pixels whose shaded estimate was NaN or infinite.
        pub nonfinite_pixels: u32,
        /// Traversals (a closest-hit or shadow ray, or a pair traced together) started by the
        /// temporal and spatial kernels, every one of them inside a shift.
        pub reuse_traversals: u32,
        /// Runs of the shift code by a subgroup, counted once for all its lanes that shift.
        pub shift_subgroup_runs: u32,
        /// Lanes per subgroup (llvmpipe: one SIMD group run in lockstep); 0 if no shift ran.
        pub subgroup_size: u32,
    }
}

gpu_record! {
    struct;
    /// One entry of the ReSTIR kernels' pass table (ReuseParams::passes): which slots a pass reads
    /// and writes, and its random-number key.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
    pub struct RestirPass {
        /// Reservoir slot (0-2) the pass reads.
        pub in_slot: u32,
        /// Reservoir slot (0-2) the pass writes.
        pub out_slot: u32,
        /// Reservoir slot (0-2) holding the previous frame's result, for temporal reuse.
        pub prev_slot: u32,
        /// Surface slot (0-1) of the current frame; the previous frame's surfaces are the other one.
        pub surface_slot: u32,
        /// Distinguishes the random choices of passes and reuse rounds within a frame.
        pub pass_seed: u32,
    }
}
