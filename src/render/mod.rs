//! Rendering on the GPU: scene upload, settings, the path tracer, ReSTIR PT and their images.
//!
//! A scene is uploaded once ([`SceneGpu::upload`]) and shared by `Arc`: every renderer is built
//! from the uploaded scene and reads its cameras and counts from it ([`SceneGpu::info`]), so no
//! call can pass a scene that differs from the one in the buffers. Both renderers of one scene:
//!
//! ```no_run
//! use std::sync::{atomic::AtomicBool, Arc};
//!
//! use restir_pt::render::{PathTracer, RenderSettings, Restir, RestirSettings, SceneGpu};
//! use restir_pt::scene::load_scene;
//! use restir_pt::vk::{Context, ContextOptions};
//!
//! fn main() -> anyhow::Result<()> {
//!     let scene = load_scene(std::path::Path::new("scenes/cornell.gltf"))?;
//!     let options = ContextOptions { device: None, validation: false, ..Default::default() };
//!     let ctx = Arc::new(Context::new(&options)?);
//!     let scene = SceneGpu::upload(&ctx, &scene)?;
//!     let settings = RenderSettings::default();
//!     // 64 paths per pixel from camera 0: the mean and its variance, 256x256, row-major.
//!     let mut tracer = PathTracer::new(&scene, &settings)?;
//!     tracer.render(&|_| {}, &AtomicBool::new(false))?;
//!     let path_traced = tracer.image()?;
//!     // ReSTIR PT along the scene's cameras, sharing the same upload.
//!     let mut restir = Restir::new(&scene, &settings, &RestirSettings::default())?;
//!     for camera in 0..scene.info().cameras.len() {
//!         restir.frame(camera, false)?;
//!     }
//!     let last_frame = restir.image()?;
//!     println!("{} and {} pixels", path_traced.mean.len(), last_frame.mean.len());
//!     Ok(())
//! }
//! ```

mod counters;
mod frame_plan;
mod image;
mod image_readback;
mod path_tracer;
mod reservoir_layers;
mod restir;
mod restir_passes;
mod restir_settings;
mod scene_gpu;
mod scene_info;
mod settings;
mod surface_gpu;

pub use counters::TraversalCounters;
pub use frame_plan::History;
pub use image::Image;
pub use path_tracer::{PathTracer, RenderStats};
pub use restir::{FrameStats, Restir};
pub use restir_passes::{Dispatch, PassDeclaration, PassKernel, PassTimes, PASSES, PASS_COUNT, PASS_NAMES};
pub use restir_settings::{RestirSettings, ReuseMis, ShiftKind, MAX_RESERVOIRS};
pub use scene_gpu::{scene_array_limit, SceneGpu};
pub use scene_info::SceneInfo;
pub use settings::{RenderSettings, MAX_IMAGE_SIDE, MAX_PIXELS};
pub use surface_gpu::SurfaceGpu;
