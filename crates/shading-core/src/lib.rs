//! restir-pt-shading-core: the Rust twins of the GLSL functions that read only host–shader
//! records (triangles, BVH nodes, materials, surfaces, textures, path records), not a whole
//! scene. Each function an oracle test pairs with a GLSL function has the same name as it, in
//! the module named for the GLSL include (`bsdf` for glsl/shading_core/bsdf.glsl, `bvh` for glsl/shading_core/bvh.glsl,
//! ...); `gris` holds the reuse estimator the ReSTIR passes implement.
//!
//! It may use restir-pt-interface (the records) and nothing else of the workspace. It sits below
//! restir-pt-scene because building and loading a scene runs some of these twins (the default
//! environment traces rays from the lights; a scene's alpha tests, surfaces and textures are
//! these records), and below restir-pt-shading, whose twins over a whole scene (lights, shift
//! mappings) call them and re-export every module here (docs/layout.md).

// Every public item carries a doc comment (units, spaces, layouts, errors, sources): a new
// undocumented one fails the build, clippy and rustdoc alike.
#![deny(missing_docs)]
// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod alpha;
pub mod alpha_pass;
pub mod alpha_trace;
pub mod bsdf;
pub mod bvh;
pub mod gris;
pub mod path_record;
pub mod ray_offset;
pub mod rng;
pub mod sampling;
pub mod surface;
pub mod texture;
