//! The one statement of what the host and the GLSL kernels share besides struct layouts
//! (those are crates/interface/src/gpu_types.rs, checked by tests/suite/layout.rs): descriptor bindings, the
//! values of compile-time enums and the limits both sides size arrays by.
//!
//! Kernels see it as the header `shader_interface.glsl`, generated from this module by
//! [`glsl_header`] and served to `#include` by crates/vk/src/shader.rs, so no number here is
//! written a second time in GLSL. Each binding is a Rust enum variant whose name is the GLSL
//! block name; the header defines `<FAMILY>_BINDING_<NAME>` as its number, the host binds
//! buffers by variant (`restir_pt_vk::Kernel::bind`, through `restir_pt_vk::BindingFamilyExt`)
//! and `Kernel::new` refuses a kernel whose SPIR-V declares another block at a binding than the
//! one named here.

use std::fmt::Write as _;
use std::sync::OnceLock;

use crate::glsl_consts;
use crate::glsl_record::{upper_snake, GpuRecord, RecordInfo};

/// A family of descriptor bindings (one enum per kernel family, declared by `binding_family!`):
/// what a binding is, without the Vulkan types that bind a buffer to it (those are
/// `restir_pt_vk::BindingFamilyExt`, implemented for every family).
pub trait BindingFamily: Copy {
    /// The descriptor set of the family.
    const SET: u32;
    /// The GLSL block name of this binding.
    fn block(self) -> &'static str;
    /// The binding number in descriptor set [`BindingFamily::SET`].
    fn binding(self) -> u32;
}

/// Declares one family of bindings of descriptor set `$set`: the enum, its GLSL macro prefix
/// and `ALL`. Variant names are the GLSL block names.
macro_rules! binding_family {
    ($(#[$meta:meta])* $name:ident, $prefix:literal, set $set:literal { $($(#[$vmeta:meta])* $variant:ident = $number:literal,)* }) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum $name {
            $($(#[$vmeta])* $variant = $number,)*
        }

        impl $name {
            /// Every binding of the family, in binding order.
            pub const ALL: &'static [$name] = &[$($name::$variant),*];
            /// The prefix of the family's GLSL macros, e.g. `RESTIR_BINDING_`.
            pub const GLSL_PREFIX: &'static str = $prefix;
            /// The descriptor set of the family.
            pub const SET: u32 = $set;

            /// The GLSL block name, which is also the variant's name.
            pub fn block(self) -> &'static str {
                match self {
                    $($name::$variant => stringify!($variant),)*
                }
            }

            /// The binding number in descriptor set `SET`.
            pub fn binding(self) -> u32 {
                self as u32
            }
        }

        impl BindingFamily for $name {
            const SET: u32 = $set;

            fn block(self) -> &'static str {
                $name::block(self)
            }

            fn binding(self) -> u32 {
                $name::binding(self)
            }
        }
    };
}

binding_family! {
    /// Bindings 0-4 of every scene kernel (glsl/interface/scene_bindings.glsl): the frame parameters and
    /// the scene arrays. The scene arrays are storage or uniform buffers (`SceneGpu::uniform`).
    SceneBinding, "SCENE_BINDING_", set 0 {
        /// `gpu_types::FrameParams`, a host-written storage buffer.
        FrameParams = 0,
        /// `gpu_types::Triangle` array in BVH leaf order (or, addressed, its device address and
        /// length).
        Triangles = 1,
        /// `gpu_types::BvhNode` array, depth-first with skip links (or its address and length).
        Nodes = 2,
        /// `gpu_types::Material` array, indexed by `Triangle::material`.
        Materials = 3,
        /// Emissive triangles, punctual lights and the environment map's rows.
        Emitters = 4,
    }
}

binding_family! {
    /// Bindings 5-7 of glsl/pathtrace.comp, storage buffers.
    PathTraceBinding, "PATHTRACE_BINDING_", set 0 {
        /// Per pixel vec4: rgb sum of L, w sample count.
        Accum = 5,
        /// Per pixel vec4: rgb sum of L².
        AccumSq = 6,
        /// Loop and non-finite counters and the profile counters (src/render/path_tracer.rs).
        Status = 7,
    }
}

binding_family! {
    /// Bindings 5-18 of the ReSTIR PT kernels (glsl/interface/restir_bindings.glsl), storage buffers.
    /// Surfaces alternate between frames; reservoir slots rotate within and between frames
    /// (src/render/frame_plan.rs), each slot a head and a tail buffer.
    RestirBinding, "RESTIR_BINDING_", set 0 {
        /// `gpu_types::ReuseParams`, host-written, with the frame's pass table.
        ReuseParams = 5,
        /// Surface slot 0: one `gpu_types::Surface` per pixel.
        Surfaces0 = 6,
        /// Surface slot 1: one `gpu_types::Surface` per pixel.
        Surfaces1 = 7,
        /// Reservoir slot 0, first halves: one `gpu_types::ReservoirHead` per reservoir.
        ReservoirHeads0 = 8,
        /// Reservoir slot 0, second halves: one `gpu_types::ReservoirTail` per reservoir.
        ReservoirTails0 = 9,
        /// Reservoir slot 1, first halves.
        ReservoirHeads1 = 10,
        /// Reservoir slot 1, second halves.
        ReservoirTails1 = 11,
        /// Reservoir slot 2, first halves.
        ReservoirHeads2 = 12,
        /// Reservoir slot 2, second halves.
        ReservoirTails2 = 13,
        /// Per reservoir vec4: the emission seen directly (w: frames in its running mean).
        Direct = 14,
        /// Per pixel vec4: rgb sum of the frames' estimates, w their count.
        Accum = 15,
        /// Per pixel vec4: rgb sum of squared estimates.
        AccumSq = 16,
        /// `gpu_types::RestirStats`.
        RestirStats = 17,
        /// Per reservoir vec4: the last resampling's expectation of f(Y) W_Y.
        Expectation = 18,
    }
}

binding_family! {
    /// Descriptor set 1 of scene kernels whose scene has surface attributes or textures
    /// (glsl/interface/surface_bindings.glsl, src/render/surface_gpu.rs), storage buffers. Set 0 keeps
    /// what traversal reads; these are read only at hits. Oracle kernels that bind everything
    /// in set 0 move the family there (`SURFACE_SET`, `SURFACE_BINDING` in the GLSL).
    SurfaceBinding, "SURFACE_BINDING_", set 1 {
        /// `TriangleSurface` per triangle (crates/shading-core/src/surface.rs).
        SurfaceAttributes = 0,
        /// `MaterialTextures` per material (crates/shading-core/src/texture.rs); this and the next two only with
        /// textures.
        MaterialTextureTable = 1,
        /// `TextureHeader` per texture.
        TextureHeaders = 2,
        /// RGBA8 texels.
        Texels = 3,
    }
}

impl RestirBinding {
    /// The head and tail bindings of reservoir slot `slot` (0 to RESERVOIR_SLOTS - 1).
    pub fn reservoir_slot(slot: usize) -> (RestirBinding, RestirBinding) {
        use RestirBinding::*;
        [
            (ReservoirHeads0, ReservoirTails0),
            (ReservoirHeads1, ReservoirTails1),
            (ReservoirHeads2, ReservoirTails2),
        ][slot]
    }

    /// The surface binding of surface slot `slot` (0 or 1).
    pub fn surface_slot(slot: usize) -> RestirBinding {
        [RestirBinding::Surfaces0, RestirBinding::Surfaces1][slot]
    }
}

/// The shift mapping used for reuse (and, inverted, for its MIS weights). The discriminant is
/// the value of the kernels' SHIFT_MODE ([`glsl_header`] writes the GLSL names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[repr(u32)]
pub enum ShiftKind {
    /// Reconnection shift: the offset path keeps its own primary hit y1 and connects it to the
    /// base path's x2, keeping x2..xk; defined only where the base reconnects at r = 2
    /// (docs/shift-mappings.md).
    Reconnection = 0,
    /// Random replay: the offset path is traced anew from y1 with the base path's random numbers;
    /// its Jacobian is 1.
    Replay = 1,
    /// Hybrid shift (Lin et al. 2022; the default): random replay of y2..y_{r-1}, then a
    /// reconnection to the base path's x_r; random replay alone where the base has no
    /// reconnection vertex.
    Hybrid = 2,
}

/// The resampling MIS weights of reuse (`--mis gbh|pairwise`). The discriminant is the value of
/// the kernels' MIS_MODE.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[repr(u32)]
pub enum ReuseMis {
    /// Generalized balance heuristic with confidence weights, O(M^2) inverse shifts.
    #[cfg_attr(feature = "clap", value(name = "gbh"))]
    GeneralizedBalance = 0,
    /// Defensive pairwise MIS, O(M).
    Pairwise = 1,
}

impl ShiftKind {
    /// Every shift, in discriminant order.
    pub const ALL: [ShiftKind; 3] = [ShiftKind::Reconnection, ShiftKind::Replay, ShiftKind::Hybrid];

    /// The kind called `name` (`reconnection`, `replay` or `hybrid`).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The CLI name: `reconnection`, `replay` or `hybrid`.
    pub fn name(self) -> &'static str {
        match self {
            ShiftKind::Reconnection => "reconnection",
            ShiftKind::Replay => "replay",
            ShiftKind::Hybrid => "hybrid",
        }
    }

    /// The GLSL macro of this kind, a value of SHIFT_MODE in glsl/restir_reuse.glsl.
    pub fn glsl_name(self) -> &'static str {
        match self {
            ShiftKind::Reconnection => "SHIFT_RECONNECTION",
            ShiftKind::Replay => "SHIFT_REPLAY",
            ShiftKind::Hybrid => "SHIFT_HYBRID",
        }
    }
}

impl ReuseMis {
    /// Every MIS, in discriminant order.
    pub const ALL: [ReuseMis; 2] = [ReuseMis::GeneralizedBalance, ReuseMis::Pairwise];

    /// The MIS called `name` (`gbh` or `pairwise`).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The CLI name: `gbh` or `pairwise`.
    pub fn name(self) -> &'static str {
        match self {
            ReuseMis::GeneralizedBalance => "gbh",
            ReuseMis::Pairwise => "pairwise",
        }
    }

    /// The GLSL macro of this MIS, a value of MIS_MODE in glsl/restir_reuse.glsl.
    pub fn glsl_name(self) -> &'static str {
        match self {
            ReuseMis::GeneralizedBalance => "MIS_GBH",
            ReuseMis::Pairwise => "MIS_PAIRWISE",
        }
    }
}

/// At most this many path vertices x1..xk (4 bits of length, 5 bits of lobe for each of x1..x6
/// in `restir_pt_shading::path_record::PathRecord`).
pub const MAX_PATH_LENGTH: usize = 7;
/// Reservoir slots of the ReSTIR PT kernels: the previous frame's result and two that the
/// passes of a frame alternate between (src/render/frame_plan.rs).
pub const RESERVOIR_SLOTS: usize = 3;
/// Surface slots: the current frame's and the previous frame's.
pub const SURFACE_SLOTS: usize = 2;
/// The most passes a ReSTIR PT frame runs: initial, temporal, 3 spatial rounds and shading.
pub const RESTIR_MAX_PASSES: usize = 6;
/// The most spatial reuse rounds of a frame.
pub const MAX_SPATIAL_ROUNDS: u32 = 3;
/// The most spatial neighbours of a reuse round.
pub const MAX_NEIGHBOURS: u32 = 8;
/// The most inputs of one resampling: the canonical reservoir and the neighbours.
pub const MAX_INPUTS: u32 = MAX_NEIGHBOURS + 1;
/// Width and height of a 2D workgroup of the image kernels (pathtrace.comp, restir_*.comp).
pub const IMAGE_LOCAL_SIZE: u32 = 8;
/// Russian roulette starts at path vertex x_3 (x_1 the primary hit): the path tracer decides
/// there, after its NEE, whether to trace on; ReSTIR PT's initial candidates decide before
/// their NEE at x_3 (glsl/shading/candidates.glsl). The first two bounces always continue.
pub const RR_START_DEPTH: u32 = 3;
/// Russian roulette's survival probability is the path throughput's largest channel, at most
/// this, so that paths of throughput near 1 (closed scenes of albedo near 1) still end.
pub const RR_MAX_SURVIVAL: f32 = 0.95;
/// Profile counters of glsl/interface/counters.glsl, in its order (COUNTER_TRAVERSALS ...
/// COUNTER_STEP_ITERATIONS), each a 64-bit sum.
pub const COUNTER_COUNT: usize = 7;

glsl_consts! {
    /// The GLSL declarations of this module's typed constants (random-number streams, profile
    /// counters, tolerances), for the generated header.
    fn glsl_constants;
    /// Stream of `rng_uniform4` (`restir_pt_shading_core::rng`): the camera ray's jitter within the pixel (vertex 0).
    pub const STREAM_CAMERA: u32 = 0;
    /// Stream of `rng_uniform4` (`restir_pt_shading_core::rng`): BSDF sampling at a vertex (xy: direction, z: lobe choice, w:
    /// reflect/refract choice).
    pub const STREAM_BSDF: u32 = 1;
    /// Stream of `rng_uniform4` (`restir_pt_shading_core::rng`): next-event estimation at a vertex (the light choice and the point
    /// or direction on it).
    pub const STREAM_LIGHT: u32 = 2;
    /// ReSTIR's choices among candidates, keyed by a pass seed.
    pub const STREAM_RESAMPLE: u32 = 3;
    /// ReSTIR's choice of directional light k's NEE candidate at a vertex: stream
    /// `STREAM_DIRECTIONAL + k` (x).
    pub const STREAM_DIRECTIONAL: u32 = 4;
    /// Profile counter (glsl/interface/counters.glsl): traversals a lane started (one ray or one pair).
    pub const COUNTER_TRAVERSALS: u32 = 0;
    /// Profile counter: BVH nodes a lane visited.
    pub const COUNTER_NODE_VISITS: u32 = 1;
    /// Profile counter: ray-triangle tests a lane ran.
    pub const COUNTER_TRIANGLE_TESTS: u32 = 2;
    /// Profile counter: path steps a lane took.
    pub const COUNTER_PATH_STEPS: u32 = 3;
    /// Profile counter: node-loop iterations of a subgroup, counted by its elected lane.
    pub const COUNTER_NODE_ITERATIONS: u32 = 4;
    /// Profile counter: triangle-loop iterations of a subgroup.
    pub const COUNTER_TRIANGLE_ITERATIONS: u32 = 5;
    /// Profile counter: path-step iterations of a subgroup.
    pub const COUNTER_STEP_ITERATIONS: u32 = 6;
    /// Interpolated vectors shorter than this (squared) count as missing (glsl/shading_core/surface.glsl,
    /// `restir_pt_shading_core::surface`).
    pub const SURFACE_MIN_LENGTH_SQUARED: f32 = 1e-12;
    /// Below this alpha (roughness ~0.032) a lobe is a perfect (delta) specular: narrower GGX lobes
    /// are ill-conditioned in f32 (pdf errors grow like epsilon / alpha).
    pub const DELTA_ALPHA: f32 = 1e-3;
    /// Relative IORs this close to 1 (2⁻¹⁶) are index-matched: the interface neither reflects nor
    /// bends light, and the dielectric lobe is an exact pass-through whatever the roughness. Closer
    /// to 1 the generalized half-vector wi η + wo, of length about |η − 1|, is lost in rounding.
    pub const INDEX_MATCHED_TOLERANCE: f32 = 1.0 / 65536.0;
    /// Segment tests stop this fraction short of their (offset) end point.
    pub const SEGMENT_EPSILON: f32 = 1e-4;
    /// 2⁻¹⁷: the offset per unit of |v0| + |e1| + |e2| (`restir_pt_shading_core::ray_offset`).
    pub const RAY_OFFSET_SCALE: f32 = 1.0 / 131072.0;
}

// The GLSL reservoir loads and stores branch over exactly these slots.
const _: () = assert!(RESERVOIR_SLOTS == 3 && SURFACE_SLOTS == 2);
// Initial, temporal, the spatial rounds and shading.
const _: () = assert!(RESTIR_MAX_PASSES == 3 + MAX_SPATIAL_ROUNDS as usize);

/// The include name under which kernels see [`glsl_header`].
pub const GLSL_HEADER_NAME: &str = "shader_interface.glsl";

fn write_family<T: Copy>(out: &mut String, prefix: &str, all: &[T], name: impl Fn(T) -> (&'static str, u32)) {
    for &b in all {
        let (block, number) = name(b);
        writeln!(out, "#define {prefix}{} {number}", upper_snake(block)).expect("string write");
    }
}

fn build_header() -> String {
    let mut h = String::from(
        "// Generated from crates/interface/ (shader_interface.rs `glsl_header`) when restir-pt-vk is built;\n\
         // edit the Rust declarations, not this text.\n\
         #ifndef SHADER_INTERFACE_GLSL\n#define SHADER_INTERFACE_GLSL\n\n",
    );
    write_family(&mut h, SceneBinding::GLSL_PREFIX, SceneBinding::ALL, |b| (b.block(), b.binding()));
    write_family(&mut h, PathTraceBinding::GLSL_PREFIX, PathTraceBinding::ALL, |b| {
        (b.block(), b.binding())
    });
    write_family(&mut h, RestirBinding::GLSL_PREFIX, RestirBinding::ALL, |b| (b.block(), b.binding()));
    write_family(&mut h, SurfaceBinding::GLSL_PREFIX, SurfaceBinding::ALL, |b| {
        (b.block(), b.binding())
    });
    writeln!(h, "#define SURFACE_DESCRIPTOR_SET {}", SurfaceBinding::SET).expect("string write");
    h.push('\n');
    for kind in ShiftKind::ALL {
        writeln!(h, "#define {} {}", kind.glsl_name(), kind as u32).expect("string write");
    }
    for mis in ReuseMis::ALL {
        writeln!(h, "#define {} {}", mis.glsl_name(), mis as u32).expect("string write");
    }
    let limits = [
        ("RESERVOIR_SLOTS", RESERVOIR_SLOTS as u32),
        ("SURFACE_SLOTS", SURFACE_SLOTS as u32),
        ("RESTIR_MAX_PASSES", RESTIR_MAX_PASSES as u32),
        ("MAX_INPUTS", MAX_INPUTS),
        ("IMAGE_LOCAL_SIZE", IMAGE_LOCAL_SIZE),
        ("COUNTER_COUNT", COUNTER_COUNT as u32),
        ("RR_START_DEPTH", RR_START_DEPTH),
        ("MAX_PATH_LENGTH", MAX_PATH_LENGTH as u32),
        ("PUNCTUAL_ROWS", crate::gpu_types::PUNCTUAL_ROWS as u32),
        ("LIGHT_NODE_ROWS", crate::gpu_types::LIGHT_NODE_ROWS as u32),
        ("LIGHT_TREE_MAX_DEPTH", crate::gpu_types::LIGHT_TREE_MAX_DEPTH as u32),
    ];
    h.push('\n');
    for (name, value) in limits {
        writeln!(h, "#define {name} {value}u").expect("string write");
    }
    writeln!(h, "#define RR_MAX_SURVIVAL {RR_MAX_SURVIVAL:?}").expect("string write");
    h.push('\n');
    let constants = [
        glsl_constants(),
        crate::gpu_types::glsl_constants(),
        crate::path_record::glsl_constants(),
        crate::surface_types::glsl_constants(),
    ];
    for line in constants.iter().flatten() {
        writeln!(h, "{line}").expect("string write");
    }
    for record in records() {
        h.push('\n');
        h.push_str(&record.glsl());
    }
    h.push_str("\n#endif\n");
    h
}

/// Every record shared with GLSL, in the order the generated header declares them (a record
/// before those that contain it); tests/suite/layout.rs checks each against glslang's layout.
pub fn records() -> Vec<RecordInfo> {
    use crate::gpu_types::*;
    use crate::oracle_types::*;
    use crate::path_record::PathRecord;
    use crate::surface_types::*;
    vec![
        FrameParams::info(),
        Material::info(),
        Triangle::info(),
        BvhNode::info(),
        Emitter::info(),
        LightNode::info(),
        RestirPass::info(),
        TemporalParams::info(),
        InitialParams::info(),
        SpatialParams::info(),
        ReuseParams::info(),
        Surface::info(),
        ReservoirHead::info(),
        ReservoirTail::info(),
        RestirStats::info(),
        PathRecord::info(),
        TriangleSurface::info(),
        TextureHeader::info(),
        TextureSlot::info(),
        MaterialTextures::info(),
        ReuseToyInput::info(),
        ReuseOracleOutput::info(),
        RngOracleOutput::info(),
        SamplingOracleInput::info(),
        SamplingOracleOutput::info(),
        OracleRay::info(),
        OracleHit::info(),
        TracePairOracleInput::info(),
        TracePairOracleOutput::info(),
        BsdfOracleInput::info(),
        BsdfOracleOutput::info(),
        GrisOracleOffer::info(),
        GrisOracleOutput::info(),
        SceneOracleInput::info(),
        SceneOracleOutput::info(),
        AlphaOracleInput::info(),
        AlphaOracleOutput::info(),
        SurfaceOracleInput::info(),
        SurfaceOracleOutput::info(),
        ShiftOracleParams::info(),
        ShiftOracleTarget::info(),
        ShiftOracleOutput::info(),
        CandidatesOracleParams::info(),
        CandidatesOracleInput::info(),
        CandidatesOracleOutput::info(),
    ]
}

/// The GLSL header of bindings, enum values and limits, built once per process.
pub fn glsl_header() -> &'static str {
    static HEADER: OnceLock<String> = OnceLock::new();
    HEADER.get_or_init(build_header)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_defines_every_binding_enum_and_limit_once() {
        let h = glsl_header();
        assert!(h.contains("#define RESTIR_BINDING_RESERVOIR_HEADS0 8\n"));
        assert!(h.contains("#define SCENE_BINDING_FRAME_PARAMS 0\n"));
        assert!(h.contains("#define PATHTRACE_BINDING_ACCUM_SQ 6\n"));
        assert!(h.contains("#define SURFACE_BINDING_TEXELS 3\n"));
        assert!(h.contains("#define SURFACE_DESCRIPTOR_SET 1\n"));
        assert!(h.contains("#define SHIFT_HYBRID 2\n"));
        assert!(h.contains("#define MIS_PAIRWISE 1\n"));
        assert!(h.contains("#define MAX_INPUTS 9u\n"));
        let names: Vec<&str> = h.lines().filter_map(|l| l.strip_prefix("#define ")?.split(' ').next()).collect();
        let mut unique = names.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "a macro defined twice: {names:?}");
    }

    #[test]
    fn binding_numbers_are_contiguous_per_kernel() {
        let scene: Vec<u32> = SceneBinding::ALL.iter().map(|b| b.binding()).collect();
        assert_eq!(scene, (0..5).collect::<Vec<_>>());
        let restir: Vec<u32> = RestirBinding::ALL.iter().map(|b| b.binding()).collect();
        assert_eq!(restir, (5..19).collect::<Vec<_>>());
        let pt: Vec<u32> = PathTraceBinding::ALL.iter().map(|b| b.binding()).collect();
        assert_eq!(pt, (5..8).collect::<Vec<_>>());
        let surface: Vec<u32> = SurfaceBinding::ALL.iter().map(|b| b.binding()).collect();
        assert_eq!(surface, (0..4).collect::<Vec<_>>());
        assert_eq!((SceneBinding::SET, RestirBinding::SET, SurfaceBinding::SET), (0, 0, 1));
        for slot in 0..RESERVOIR_SLOTS {
            let (h, t) = RestirBinding::reservoir_slot(slot);
            assert_eq!(
                (h.block(), t.block()),
                (&*format!("ReservoirHeads{slot}"), &*format!("ReservoirTails{slot}"))
            );
        }
    }
}
