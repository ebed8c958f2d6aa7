//! Recording of a planned ReSTIR PT frame (src/render/frame_plan.rs) into one command buffer:
//! the clears, one dispatch per planned pass, the pass timers and the counters' readback.

use ash::vk::CommandBuffer;

use super::super::frame_plan::{FramePlan, PlannedPass};
use super::super::restir_passes::{Dispatch, PASS_NAMES};
use super::{Restir, LOCAL_SIZE};
use crate::vk::record_compute_barrier;

impl Restir {
    /// Records a whole frame; the counters reach the readback buffer when it completes.
    pub(super) fn record_frame(&self, cmd: CommandBuffer, plan: &FramePlan, accumulate: bool) {
        self.record_clears(cmd, accumulate);
        self.timer.record_reset(cmd);
        let mut open: Option<usize> = None;
        for (index, pass) in plan.passes.iter().enumerate() {
            open = self.record_timer_switch(cmd, open, pass.kernel.timer_slot());
            self.record_pass(cmd, index as u32, pass);
        }
        self.record_timer_close(cmd, open, plan);
        self.readback.record_counters(cmd, &self.buffers.stats);
    }

    /// Zeroes the counters, and the accumulated image unless this frame is added to it.
    fn record_clears(&self, cmd: CommandBuffer, accumulate: bool) {
        self.buffers.stats.record_fill(cmd, 0);
        if !accumulate {
            self.buffers.accum.record_fill(cmd, 0);
            self.buffers.accum_sq.record_fill(cmd, 0);
        }
        record_compute_barrier(&self.ctx.device, cmd);
    }

    /// One pass: its kernel over the image with its pass-table entry `index` as push constant,
    /// which names the reservoir slots it reads (`in_slot`, `prev_slot`) and writes
    /// (`out_slot`) and the surfaces of the frame (`surface_slot`), over the image as its row's
    /// `Dispatch` says.
    fn record_pass(&self, cmd: CommandBuffer, index: u32, pass: &PlannedPass) {
        let reservoirs = match pass.kernel.declaration().dispatch {
            Dispatch::PerPixel => 1,
            Dispatch::PerReservoir => self.restir.reservoirs,
        };
        let groups = [
            self.settings.width.div_ceil(LOCAL_SIZE),
            self.settings.height.div_ceil(LOCAL_SIZE),
            reservoirs,
        ];
        // `frame` builds every kernel of its plan before recording it.
        let kernel = self.kernels[pass.kernel as usize].as_ref().expect("the frame's kernels are built");
        kernel.record_dispatch(cmd, groups, &index.to_ne_bytes());
        record_compute_barrier(&self.ctx.device, cmd);
    }

    /// Ends the open timer interval and begins `slot`'s when the pass changes timer slots.
    fn record_timer_switch(&self, cmd: CommandBuffer, open: Option<usize>, slot: usize) -> Option<usize> {
        if open != Some(slot) {
            if let Some(s) = open {
                self.timer.record_end(cmd, s as u32);
            }
            self.timer.record_begin(cmd, slot as u32);
        }
        Some(slot)
    }

    /// Ends the last interval; passes that did not run this frame get an empty one.
    fn record_timer_close(&self, cmd: CommandBuffer, open: Option<usize>, plan: &FramePlan) {
        if let Some(s) = open {
            self.timer.record_end(cmd, s as u32);
        }
        for slot in 0..PASS_NAMES.len() {
            if !plan.passes.iter().any(|p| p.kernel.timer_slot() == slot) {
                self.timer.record_begin(cmd, slot as u32);
                self.timer.record_end(cmd, slot as u32);
            }
        }
    }
}
