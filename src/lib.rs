//! restir-pt: a Vulkan compute path tracer with ReSTIR PT reuse through explicit shift mappings.
//! Every GLSL function an oracle mirrors has a Rust twin of the same name in the matching module.

// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod error;
pub mod gpu_types;
pub mod image_io;
pub mod metrics;
pub mod reference_shard;
pub mod render;
pub mod scene;
pub mod shader_interface;
pub mod shading;
pub mod vk;
