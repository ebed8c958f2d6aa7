//! The per-reservoir buffers of ReSTIR PT: one width x height layer per reservoir of a pixel
//! (glsl/interface/restir_bindings.glsl's reservoir_index).

use std::sync::Arc;

use anyhow::Result;

use crate::gpu_types::{ReservoirHead, ReservoirTail};
use crate::vk::{Buffer, BufferUsage, Context};

pub use crate::shader_interface::RESERVOIR_SLOTS;

pub struct ReservoirLayers {
    pub heads: [Buffer; RESERVOIR_SLOTS],
    pub tails: [Buffer; RESERVOIR_SLOTS],
    /// Each reservoir's estimate of the emission seen directly (w: the frames in its running
    /// mean under an unmoved camera).
    pub direct: Buffer,
    /// Each reservoir's expectation of f(Y) W_Y over its last resampling.
    pub expectation: Buffer,
}

impl ReservoirLayers {
    pub fn new(ctx: &Arc<Context>, pixels: u64, reservoirs: u32) -> Result<Self> {
        let entries = pixels * reservoirs as u64;
        let half = std::mem::size_of::<ReservoirHead>() as u64;
        let tail = std::mem::size_of::<ReservoirTail>() as u64;
        ctx.check_binding_size(
            &format!("a reservoir half of {reservoirs} reservoir(s) per pixel"),
            entries * half.max(tail),
        )?;
        let storage = |name: &str, bytes: u64| Buffer::new(ctx, name, bytes, BufferUsage::Storage);
        Ok(Self {
            heads: [
                storage("reservoir heads 0", entries * half)?,
                storage("reservoir heads 1", entries * half)?,
                storage("reservoir heads 2", entries * half)?,
            ],
            tails: [
                storage("reservoir tails 0", entries * tail)?,
                storage("reservoir tails 1", entries * tail)?,
                storage("reservoir tails 2", entries * tail)?,
            ],
            direct: storage("primary emission", entries * 16)?,
            expectation: storage("resampled expectation", entries * 16)?,
        })
    }
}
