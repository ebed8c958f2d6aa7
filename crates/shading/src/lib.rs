//! restir-pt-shading, the shading twins: the Rust oracles of the GLSL functions the kernels run.
//! Each function an oracle test pairs with a GLSL function has the same name as it, in the
//! module named for the GLSL include (`bsdf` for glsl/shading_core/bsdf.glsl, `shift` for glsl/shading/shift.glsl,
//! ...), and `gris` holds the reuse estimator the ReSTIR passes implement (`resample_inputs`
//! their loop, step for step).
//!
//! The twins over a whole [`restir_pt_scene::Scene`] (light sampling, light-tree selection,
//! initial candidates, shift mappings) are defined here; those that read only records (BSDF,
//! sampling, RNG, surfaces, textures, alpha tests, BVH traversal, GRIS, path records) are
//! restir-pt-shading-core's, re-exported under the same names, so that `shading::bsdf` and
//! `shading::shift` name every twin alike. It may use restir-pt-interface, -shading-core and
//! -scene; nothing of the Vulkan layer or the renderer (docs/layout.md).

// Every public item carries a doc comment (units, spaces, layouts, errors, sources): a new
// undocumented one fails the build, clippy and rustdoc alike.
#![deny(missing_docs)]
// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub use restir_pt_shading_core::{
    alpha, alpha_pass, alpha_trace, bsdf, bvh, gris, path_record, ray_offset, rng, sampling, surface, texture,
};

pub mod candidates;
pub mod light_tree;
pub mod lights;
pub mod resample_inputs;
pub mod shift;
