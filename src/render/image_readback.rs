//! The accumulation buffers of a renderer read back through one persistent host-visible
//! buffer: one submission per read, no allocation.

use std::sync::Arc;

use ash::vk;

use super::Image;
use crate::error::GpuError;
use crate::vk::{record_host_read_barrier, Buffer, BufferUsage, Context};

/// Per-pixel vec4 accumulations, row-major.
pub type PixelSums = Vec<[f32; 4]>;

/// A readback buffer for a renderer's two accumulation buffers (each `pixels` vec4) and a
/// small block of counters read after every submission.
pub struct AccumReadback {
    ctx: Arc<Context>,
    width: u32,
    height: u32,
    /// [sums | sums of squares], 32 bytes per pixel.
    image: Buffer,
    /// The counters block, copied at the end of each frame's command buffer.
    counters: Buffer,
}

impl AccumReadback {
    /// For a `width` x `height` image and a counters block of `counter_bytes`.
    pub fn new(ctx: &Arc<Context>, width: u32, height: u32, counter_bytes: u64) -> Result<Self, GpuError> {
        let pixels = width as u64 * height as u64;
        Ok(Self {
            ctx: ctx.clone(),
            width,
            height,
            image: Buffer::new(ctx, "image readback", 2 * pixels * 16, BufferUsage::Staging)?,
            counters: Buffer::new(ctx, "counter readback", counter_bytes, BufferUsage::Staging)?,
        })
    }

    fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Records the copy of `counters` (a storage buffer written by the frame's last dispatch)
    /// into the readback; the caller has recorded the barrier after that dispatch.
    pub fn record_counters(&self, cmd: vk::CommandBuffer, counters: &Buffer) {
        counters.record_copy_to(cmd, &self.counters, 0, self.counters.size);
        record_host_read_barrier(&self.ctx.device, cmd);
    }

    /// The first `count` elements of the counters copied by the last `record_counters`.
    pub fn counters<T: bytemuck::Pod>(&self, count: usize) -> Result<Vec<T>, GpuError> {
        self.counters.read_mapped(0, count)
    }

    /// Both accumulation buffers as they are, per pixel `[sum r, sum g, sum b, count]` and
    /// `[sum r², sum g², sum b², 0]`, in one submission.
    pub fn sums(&self, sums: &Buffer, sums_sq: &Buffer) -> Result<(PixelSums, PixelSums), GpuError> {
        let bytes = self.pixels() as u64 * 16;
        self.ctx.submit_and_wait(|cmd| {
            sums.record_copy_to(cmd, &self.image, 0, bytes);
            sums_sq.record_copy_to(cmd, &self.image, bytes, bytes);
            record_host_read_barrier(&self.ctx.device, cmd);
        })?;
        Ok((
            self.image.read_mapped(0, self.pixels())?,
            self.image.read_mapped(bytes, self.pixels())?,
        ))
    }

    /// The image of the accumulation buffers (see `Image::from_sums`).
    pub fn image(&self, sums: &Buffer, sums_sq: &Buffer) -> Result<Image, GpuError> {
        let (s, q) = self.sums(sums, sums_sq)?;
        Ok(Image::from_sums(self.width, self.height, &s, &q))
    }
}
