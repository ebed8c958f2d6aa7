//! Rendering on the GPU: scene upload, settings, the path tracer, ReSTIR PT and their images.

mod counters;
mod frame_plan;
mod image;
mod image_readback;
mod path_tracer;
mod reservoir_layers;
mod restir;
mod restir_settings;
mod scene_gpu;
mod scene_info;
mod settings;
mod surface_gpu;

pub use counters::TraversalCounters;
pub use frame_plan::{plan_frame, FramePlan, FrameState, History, PassKernel, PlannedPass, PASS_NAMES};
pub use image::Image;
pub use path_tracer::{PathTracer, RenderStats};
pub use restir::{FrameStats, Restir};
pub use restir_settings::{RestirSettings, ReuseMis, ShiftKind, MAX_RESERVOIRS};
pub use scene_gpu::SceneGpu;
pub use scene_info::SceneInfo;
pub use settings::{RenderSettings, MAX_IMAGE_SIDE, MAX_PIXELS};
pub use surface_gpu::SurfaceGpu;
