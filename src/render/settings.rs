//! What a render is asked to do, validated before any GPU allocation.

use anyhow::{bail, Result};

use crate::gpu_types::{FrameParams, FLAG_RUSSIAN_ROULETTE};
use crate::scene::Camera;
use crate::shading::path_record::MAX_PATH_LENGTH;

use super::SceneInfo;

/// Sides beyond this are refused: per-pixel indices stay far inside u32, and 8x8 workgroups
/// stay within 8192 per axis, below the 65535 every Vulkan device supports.
pub const MAX_IMAGE_SIDE: u32 = 1 << 16;
/// The most pixels an image may have (2²⁶, e.g. 8192 × 8192); [`RenderSettings::validate`]
/// refuses more before any GPU allocation.
pub const MAX_PIXELS: u64 = 1 << 26;

/// What both renderers share: image, path length, randomness and camera. Check it with
/// [`RenderSettings::validate`] before building a renderer.
#[derive(Debug, Clone)]
pub struct RenderSettings {
    /// Image width in pixels (at most [`MAX_IMAGE_SIDE`] per side and [`MAX_PIXELS`] in all).
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The path tracer's samples per pixel; ReSTIR PT ignores it.
    pub spp: u32,
    /// The longest path, in segments from the camera (1: only emitters seen directly).
    pub max_depth: u32,
    /// Seeds every random number of the render: equal settings and seed give equal images.
    pub seed: u32,
    /// Russian roulette in the path tracer's paths and ReSTIR PT's initial candidates (never in
    /// its shifts; glsl/shading/candidates.glsl).
    pub russian_roulette: bool,
    /// Index into the scene's cameras.
    pub camera: usize,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: Self::DEFAULT_WIDTH,
            height: Self::DEFAULT_HEIGHT,
            spp: Self::DEFAULT_SPP,
            max_depth: Self::DEFAULT_MAX_DEPTH,
            seed: 0,
            russian_roulette: true,
            camera: 0,
        }
    }
}

impl RenderSettings {
    /// Image width in pixels when none is asked for.
    pub const DEFAULT_WIDTH: u32 = 256;
    /// Image height in pixels when none is asked for.
    pub const DEFAULT_HEIGHT: u32 = 256;
    /// Paths per pixel of a path-traced image.
    pub const DEFAULT_SPP: u32 = 64;
    /// Path segments: the most ReSTIR PT's path records hold, so that one default serves both
    /// methods.
    pub const DEFAULT_MAX_DEPTH: u32 = MAX_PATH_LENGTH as u32;

    /// Checks the image size, spp, depth and camera against `scene` (from
    /// [`SceneInfo::of`] before upload, or [`SceneGpu::info`](super::SceneGpu::info)). Errors:
    /// one line naming the bad value (and the scene's file for a missing camera).
    pub fn validate(&self, scene: &SceneInfo) -> Result<()> {
        self.validate_numbers()?;
        if self.camera >= scene.cameras.len() {
            bail!(
                "{}: --camera {} does not exist; the scene has {} camera(s)",
                scene.source.display(),
                self.camera,
                scene.cameras.len()
            );
        }
        Ok(())
    }

    /// The part of [`RenderSettings::validate`] that needs no scene: image size, spp and depth.
    /// Errors: one line naming the bad value.
    pub fn validate_numbers(&self) -> Result<()> {
        let (w, h) = (self.width, self.height);
        if w == 0 || h == 0 {
            bail!("resolution {w}x{h} is empty: --width and --height must be at least 1");
        }
        if w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE || w as u64 * h as u64 > MAX_PIXELS {
            bail!("resolution {w}x{h} is too large: at most {MAX_IMAGE_SIDE} per side and {MAX_PIXELS} pixels");
        }
        if self.spp == 0 {
            bail!("--spp must be at least 1");
        }
        if self.max_depth == 0 {
            bail!("--max-depth must be at least 1 (1 shows only directly visible emitters)");
        }
        Ok(())
    }

    /// `width * height`.
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The frame parameters for this render, before the per-dispatch sample range is set.
    /// `self.camera` must index `scene.cameras` (see `validate`).
    pub fn frame_params(&self, scene: &SceneInfo) -> FrameParams {
        self.frame_params_from(scene, &scene.cameras[self.camera])
    }

    /// [`RenderSettings::frame_params`] seen from `camera` (scene coordinates, as
    /// [`SceneInfo::cameras`]) instead of the scene's camera `self.camera`: a pose a caller
    /// scripts frame by frame.
    pub fn frame_params_from(&self, scene: &SceneInfo, camera: &Camera) -> FrameParams {
        let mut params = FrameParams {
            scene_env: scene.environment.extend(scene.env_select_prob).into(),
            width: self.width,
            height: self.height,
            max_depth: self.max_depth,
            render_seed: self.seed,
            flags: if self.russian_roulette { FLAG_RUSSIAN_ROULETTE } else { 0 },
            emitter_count: scene.emitter_count,
            ..Default::default()
        };
        camera.fill_params(&mut params, self.width, self.height);
        params
    }
}
