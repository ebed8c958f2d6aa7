//! GPU timestamps around passes: a begin/end query pair per pass slot.

use std::sync::Arc;

use ash::vk;

use super::Context;
use crate::error::{vk_error, GpuError};

/// A timestamp query pool of `slots` begin/end pairs, one pair per pass; read back as
/// milliseconds of GPU time per slot.
pub struct PassTimer {
    pool: vk::QueryPool,
    slots: u32,
    ctx: Arc<Context>,
}

impl PassTimer {
    /// A pool for `slots` passes. Errors: [`GpuError::Vulkan`] or [`GpuError::OutOfMemory`] if the
    /// query pool cannot be created.
    pub fn new(ctx: &Arc<Context>, slots: u32) -> Result<Self, GpuError> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(2 * slots);
        let pool = unsafe { ctx.device.create_query_pool(&info, None) }.map_err(vk_error("creating a timestamp query pool"))?;
        Ok(Self {
            pool,
            slots,
            ctx: ctx.clone(),
        })
    }

    /// Records the reset of every slot; call once per command buffer before the first pass.
    pub fn record_reset(&self, cmd: vk::CommandBuffer) {
        unsafe { self.ctx.device.cmd_reset_query_pool(cmd, self.pool, 0, 2 * self.slots) };
    }

    /// Records the begin timestamp of `slot` (top of pipe). Panics if `slot` >= the slot count.
    pub fn record_begin(&self, cmd: vk::CommandBuffer, slot: u32) {
        self.record(cmd, 2 * slot, vk::PipelineStageFlags::TOP_OF_PIPE);
    }

    /// Records the end timestamp of `slot` (bottom of pipe). Panics if `slot` >= the slot count.
    pub fn record_end(&self, cmd: vk::CommandBuffer, slot: u32) {
        self.record(cmd, 2 * slot + 1, vk::PipelineStageFlags::BOTTOM_OF_PIPE);
    }

    fn record(&self, cmd: vk::CommandBuffer, query: u32, stage: vk::PipelineStageFlags) {
        assert!(query < 2 * self.slots, "timestamp slot out of range");
        unsafe { self.ctx.device.cmd_write_timestamp(cmd, stage, self.pool, query) };
    }

    /// Milliseconds of the first `used` slots; `None` where the device has no compute timestamps.
    pub fn read_ms(&self, used: u32) -> Result<Option<Vec<f64>>, GpuError> {
        if !self.ctx.info.timestamps_supported || used == 0 {
            return Ok(None);
        }
        let mut ticks = vec![0u64; 2 * used as usize];
        unsafe {
            self.ctx
                .device
                .get_query_pool_results(self.pool, 0, &mut ticks, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT)
        }
        .map_err(vk_error("reading timestamps"))?;
        let period = self.ctx.info.timestamp_period_ns as f64;
        Ok(Some(
            ticks.chunks(2).map(|p| p[1].saturating_sub(p[0]) as f64 * period * 1e-6).collect(),
        ))
    }
}

impl Drop for PassTimer {
    fn drop(&mut self) {
        if self.ctx.is_hung() {
            // An unfinished submission may still write its timestamps (Context::is_hung).
            return;
        }
        unsafe { self.ctx.device.destroy_query_pool(self.pool, None) };
    }
}
