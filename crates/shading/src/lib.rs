//! The shading twins: the Rust oracles of the GLSL functions the kernels run. Each function an
//! oracle test pairs with a GLSL function has the same name as it, in the module named for the
//! GLSL include (`bsdf` for glsl/bsdf.glsl, `shift` for glsl/shift.glsl, ...), and `gris` holds
//! the reuse estimator the ReSTIR passes implement.

pub mod alpha;
pub mod alpha_pass;
pub mod bsdf;
pub mod candidates;
pub mod gris;
pub mod light_tree;
pub mod lights;
pub mod path_record;
pub mod ray_offset;
pub mod rng;
pub mod sampling;
pub mod shift;
pub mod surface;
pub mod texture;
