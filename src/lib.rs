//! restir-pt: a Vulkan compute path tracer with ReSTIR PT reuse through explicit shift mappings.
//! Every GLSL function an oracle mirrors has a Rust twin of the same name in the matching module.

// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bsdf;
pub mod bundled_scenes;
pub mod bvh;
pub mod charts;
pub mod cli;
pub mod environment;
pub mod error;
pub mod gltf_writer;
pub mod gpu_types;
pub mod gris;
pub mod image_io;
pub mod lights;
pub mod metrics;
pub mod path_record;
pub mod ray_offset;
pub mod render;
pub mod rng;
pub mod sampling;
pub mod scene;
pub mod shift;
pub mod surface;
pub mod texture;
pub mod vk;
