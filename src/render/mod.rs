//! Rendering on the GPU: scene upload, settings, the path tracer and its image.

mod image;
mod path_tracer;
mod scene_gpu;
mod settings;

pub use image::Image;
pub use path_tracer::{PathTracer, RenderStats};
pub use scene_gpu::SceneGpu;
pub use settings::{RenderSettings, MAX_IMAGE_SIDE, MAX_PIXELS};
