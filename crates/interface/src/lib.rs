//! restir-pt-interface: what the host and the GLSL kernels share, stated once on the Rust side.
//! The records the kernels read and write ([`gpu_types`]: scene and ReSTIR PT; [`path_record`];
//! [`surface_types`]: vertex attributes and textures; [`oracle_types`]: the oracle kernels')
//! and the constants of their encodings are declared by [`gpu_record!`] and [`glsl_consts!`]
//! ([`glsl_record`]), which also write their GLSL; [`shader_interface`] holds the descriptor
//! bindings, the values of compile-time enums and the limits, and collects all of it into the
//! GLSL header the kernels include (`shader_interface::glsl_header`, written by
//! crates/vk/build.rs; tests/suite/layout.rs checks every record against glslang's layout).
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

pub mod glsl_record;
pub mod gpu_types;
pub mod oracle_types;
pub mod path_record;
pub mod shader_interface;
pub mod surface_types;
