//! restir-pt-interface: what the host and the GLSL kernels share, stated once on the Rust side.
//! [`gpu_types`] holds the `#[repr(C)]` records the kernels read and write (checked against
//! the GLSL layouts by tests/suite/layout.rs); [`shader_interface`] holds the descriptor
//! bindings, the values of compile-time enums and the limits, and writes them as the GLSL
//! header the kernels include.
//!
//! The bottom layer of the workspace (docs/layout.md): it may use glam and bytemuck
//! only (clap behind the `clap` feature, for the CLI's enum options), so that every other
//! crate, host or twin, can name a record without pulling in Vulkan, scenes or shading. The
//! Vulkan side of the bindings (`slot`, `to`) is `restir_pt_vk::BindingFamilyExt`.

// Every public item carries a doc comment (units, spaces, layouts, errors, sources): a new
// undocumented one fails the build, clippy and rustdoc alike.
#![deny(missing_docs)]
// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod gpu_types;
pub mod shader_interface;
