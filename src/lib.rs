//! restir-pt: a Vulkan compute path tracer with ReSTIR PT reuse through explicit shift mappings.
//!
//! The library is the renderer; the `restir-pt` binary (src/main.rs, src/app/) is one user of
//! it. It is the top layer of a workspace whose crates are the layers below it, re-exported here
//! under their module names (docs/layout.md): [`gpu_types`] and [`shader_interface`]
//! (restir-pt-interface), [`vk`] and [`error`] (restir-pt-vk), [`scene`] (restir-pt-scene) and
//! [`shading`] (restir-pt-shading, with restir-pt-shading-core's twins). This crate holds
//! what needs both a scene and a device: [`render`], and what works on its images:
//! [`metrics`], [`image_io`], [`reference_shard`]. Embedding it takes four steps: load a [`scene::Scene`], open a [`vk::Context`], upload
//! the scene once ([`render::SceneGpu::upload`]) and build renderers on the upload, as many as
//! needed ([`render::PathTracer`] for progressive path tracing, [`render::Restir`] for ReSTIR
//! PT frames). Images come back as [`render::Image`] (linear RGB, row-major from the top left);
//! [`metrics`] compares them with a reference and [`image_io`] writes them.
//!
//! ```no_run
//! use std::path::Path;
//! use std::sync::{atomic::AtomicBool, Arc};
//!
//! use restir_pt::render::{PathTracer, RenderSettings, Restir, RestirSettings, SceneGpu};
//! use restir_pt::vk::{Context, ContextOptions};
//!
//! fn main() -> anyhow::Result<()> {
//!     let scene = restir_pt::scene::load_scene(Path::new("scenes/cornell.gltf"))?;
//!     let ctx = Arc::new(Context::new(&ContextOptions::default())?);
//!     let uploaded = SceneGpu::upload(&ctx, &scene)?;
//!     let settings = RenderSettings { width: 128, height: 128, spp: 256, ..Default::default() };
//!     settings.validate(uploaded.info())?;
//!
//!     // A converged path-traced reference: `settings.spp` samples per pixel.
//!     let mut tracer = PathTracer::new(&uploaded, &settings)?;
//!     tracer.render(&|_done| {}, &AtomicBool::new(false))?;
//!     let reference = tracer.image()?;
//!
//!     // Eight ReSTIR PT frames from camera 0, each reusing the last one's reservoirs.
//!     let mut restir = Restir::new(&uploaded, &settings, &RestirSettings::default())?;
//!     for _ in 0..8 {
//!         restir.frame(0, false)?;
//!     }
//!     let image = restir.image()?;
//!     println!("relMSE {:.3e}", restir_pt::metrics::rel_mse(&image.mean, &reference.mean));
//!     restir_pt::image_io::write_exr(Path::new("restir.exr"), image.width, image.height, &image.mean)?;
//!     // With `ContextOptions::validation` set, anything the validation layer reported fails here.
//!     ctx.check_validation()?;
//!     Ok(())
//! }
//! ```
//!
//! Errors are `anyhow::Error` with one readable line naming the file or the value at fault;
//! GPU failures a caller may want to tell apart (device loss, out of memory, limits) are
//! [`error::GpuError`] inside them. The shading code exists twice: every GLSL function an
//! oracle test mirrors has a Rust twin of the same name in [`shading`] (the BVH traversal in
//! [`shading::bvh`]).

// Every public item carries a doc comment (units, spaces, layouts, errors, sources): a new
// undocumented one fails the build, clippy and rustdoc alike.
#![deny(missing_docs)]
// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod image_io;
pub mod metrics;
pub mod reference_shard;
pub mod render;

pub use restir_pt_interface::{glsl_record, gpu_types, oracle_types, shader_interface, surface_types};
pub use restir_pt_scene as scene;
pub use restir_pt_shading as shading;
pub use restir_pt_vk as vk;
pub use restir_pt_vk::error;
