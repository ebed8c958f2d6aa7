//! Which passes a ReSTIR PT frame runs, with which kernel and which reservoir slots: a pure
//! function of the frame's state, so that it is tested without a device.

use super::reservoir_layers::RESERVOIR_SLOTS;
pub use super::restir_passes::PassKernel;
use crate::gpu_types::{RestirPass, RESTIR_MAX_PASSES};

/// What a frame starts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct FrameState {
    /// The slot holding the previous frame's final reservoirs, if there was a previous frame.
    pub history_slot: Option<u32>,
    /// Temporal reuse is on.
    pub temporal: bool,
    /// The camera has not moved since the previous frame.
    pub unmoved: bool,
    /// The current frame's surface slot (0 or 1).
    pub surface_slot: u32,
    /// Spatial reuse rounds (0 to 3).
    pub spatial_rounds: u32,
    /// Which reservoirs the next frame's temporal reuse reads.
    pub history: History,
}

/// The reservoirs a frame leaves as the next frame's history.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum History {
    /// The reservoirs before spatial reuse (the initial or temporal pass's output), as ReSTIR GI
    /// keeps its temporal and spatial reservoirs apart (Ouyang et al. 2021): a path that spatial
    /// reuse copies into a neighbour is not carried on in the neighbour's history, so a rare
    /// bright path does not spread from pixel to pixel frame after frame.
    Temporal,
    /// The reservoirs after the last spatial round (Bitterli et al. 2020; Lin et al. 2022).
    Spatial,
}

/// One dispatch of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct PlannedPass {
    /// The kernel dispatched.
    pub kernel: PassKernel,
    /// Its entry of the pass table: the reservoir and surface slots it reads and writes, and
    /// its random-number key.
    pub slots: RestirPass,
}

/// A frame's dispatches, and the slot of the reservoirs the next frame's temporal reuse reads.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct FramePlan {
    /// The dispatches in order (at most `RESTIR_MAX_PASSES`).
    pub passes: Vec<PlannedPass>,
    /// The reservoir slot (0-2) the next frame's temporal reuse reads ([`History`] decides which).
    pub final_slot: u32,
}

const TEMPORAL_SEED: u32 = 0x7e3a_11c5;
const SPATIAL_SEED: u32 = 0x5bd1_e995;

/// Plans a frame: initial candidates into a free slot, temporal reuse when a history exists,
/// the spatial rounds, then shading of the last result. The history's slot is never written
/// before the temporal pass has read it; with `History::Temporal` the spatial rounds alternate
/// between the two slots other than the one they start from, which stays the next history.
pub(crate) fn plan_frame(state: &FrameState) -> FramePlan {
    // The previous frame's result keeps its slot; the passes alternate between the other two.
    let prev_slot = state.history_slot.unwrap_or(RESERVOIR_SLOTS as u32 - 1);
    let work: Vec<u32> = (0..RESERVOIR_SLOTS as u32).filter(|&s| s != prev_slot).collect();
    let slots = |in_slot: u32, out_slot: u32, pass_seed: u32| RestirPass {
        in_slot,
        out_slot,
        prev_slot,
        surface_slot: state.surface_slot,
        pass_seed,
    };
    let mut passes = vec![PlannedPass {
        kernel: PassKernel::Initial,
        slots: slots(0, work[0], 0),
    }];
    let mut current = 0;
    if state.temporal && state.history_slot.is_some() {
        let kernel = if state.unmoved {
            PassKernel::TemporalUnmoved
        } else {
            PassKernel::Temporal
        };
        passes.push(PlannedPass {
            kernel,
            slots: slots(work[current], work[1 - current], TEMPORAL_SEED),
        });
        current = 1 - current;
    }
    let kept = work[current];
    // With the history kept, the previous frame's slot is free once the temporal pass has read it.
    let spatial_slots = match state.history {
        History::Spatial => [work[1 - current], work[current]],
        History::Temporal => [work[1 - current], prev_slot],
    };
    let mut last = kept;
    for round in 0..state.spatial_rounds {
        let out = spatial_slots[(round % 2) as usize];
        passes.push(PlannedPass {
            kernel: PassKernel::Spatial,
            slots: slots(last, out, SPATIAL_SEED ^ (round + 1)),
        });
        last = out;
    }
    passes.push(PlannedPass {
        kernel: PassKernel::Shade,
        slots: slots(last, last, 0),
    });
    debug_assert!(passes.len() <= RESTIR_MAX_PASSES);
    FramePlan {
        passes,
        final_slot: match state.history {
            History::Spatial => last,
            History::Temporal => kept,
        },
    }
}

/// The pass table of ReuseParams: the plan's slots in dispatch order, unused entries zero.
pub(crate) fn pass_table(plan: &FramePlan) -> [RestirPass; RESTIR_MAX_PASSES] {
    let mut table = [RestirPass::default(); RESTIR_MAX_PASSES];
    for (entry, pass) in table.iter_mut().zip(&plan.passes) {
        *entry = pass.slots;
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(history_slot: Option<u32>, unmoved: bool, spatial_rounds: u32) -> FrameState {
        FrameState {
            history_slot,
            temporal: true,
            unmoved,
            surface_slot: 1,
            spatial_rounds,
            history: History::Spatial,
        }
    }

    #[test]
    fn first_frame_has_no_temporal_pass_and_keeps_slot_2_free() {
        let plan = plan_frame(&state(None, false, 1));
        let kernels: Vec<_> = plan.passes.iter().map(|p| p.kernel).collect();
        assert_eq!(kernels, [PassKernel::Initial, PassKernel::Spatial, PassKernel::Shade]);
        assert_eq!(plan.passes[0].slots.out_slot, 0);
        assert_eq!(plan.passes[1].slots.in_slot, 0);
        assert_eq!(plan.passes[1].slots.out_slot, 1);
        assert_eq!(plan.final_slot, 1);
        assert!(plan.passes.iter().all(|p| p.slots.surface_slot == 1));
    }

    #[test]
    fn history_slot_is_read_never_written() {
        for history in 0..RESERVOIR_SLOTS as u32 {
            for rounds in 0..=3 {
                for unmoved in [false, true] {
                    let plan = plan_frame(&state(Some(history), unmoved, rounds));
                    assert!(plan
                        .passes
                        .iter()
                        .all(|p| p.slots.out_slot != history && p.slots.prev_slot == history));
                    assert_ne!(plan.final_slot, history);
                    assert_eq!(plan.passes.len(), 3 + rounds as usize);
                    assert!(plan.passes.len() <= RESTIR_MAX_PASSES);
                    let temporal = if unmoved {
                        PassKernel::TemporalUnmoved
                    } else {
                        PassKernel::Temporal
                    };
                    assert_eq!(plan.passes[1].kernel, temporal);
                    // Each reuse pass reads what the pass before it wrote.
                    for pair in plan.passes.windows(2) {
                        assert_eq!(pair[1].slots.in_slot, pair[0].slots.out_slot);
                    }
                    let shade = plan.passes.last().expect("a plan ends with shading");
                    assert_eq!(shade.kernel, PassKernel::Shade);
                    assert_eq!(shade.slots.in_slot, plan.final_slot);
                }
            }
        }
    }

    #[test]
    fn temporal_history_is_the_pre_spatial_reservoir_and_no_later_pass_writes_it() {
        for history in [None, Some(0), Some(1), Some(2)] {
            for rounds in 0..=3 {
                let plan = plan_frame(&FrameState {
                    history: History::Temporal,
                    ..state(history, false, rounds)
                });
                let reuse = if history.is_some() { 2 } else { 1 };
                let kept = plan.passes[reuse - 1].slots.out_slot;
                assert_eq!(plan.final_slot, kept);
                assert_eq!(plan.passes.len(), reuse + 1 + rounds as usize);
                for pass in &plan.passes[..reuse] {
                    assert!(history.is_none_or(|h| pass.slots.out_slot != h));
                }
                for pass in &plan.passes[reuse..] {
                    assert!(pass.slots.out_slot != kept || pass.kernel == PassKernel::Shade && rounds == 0);
                }
                for pair in plan.passes.windows(2) {
                    assert_eq!(pair[1].slots.in_slot, pair[0].slots.out_slot);
                }
                // One round gives the same passes as the spatial history; only the next
                // frame's history differs.
                if rounds == 1 {
                    let spatial = plan_frame(&state(history, false, rounds));
                    assert_eq!(spatial.passes, plan.passes);
                }
            }
        }
    }

    #[test]
    fn temporal_reuse_off_keeps_the_history_slot_unwritten_and_skips_the_pass() {
        let plan = plan_frame(&FrameState {
            temporal: false,
            ..state(Some(1), false, 1)
        });
        let kernels: Vec<_> = plan.passes.iter().map(|p| p.kernel).collect();
        assert_eq!(kernels, [PassKernel::Initial, PassKernel::Spatial, PassKernel::Shade]);
        assert!(plan.passes.iter().all(|p| p.slots.out_slot != 1));
    }

    #[test]
    fn spatial_rounds_draw_distinct_random_numbers() {
        let plan = plan_frame(&state(Some(0), false, 3));
        let seeds: Vec<u32> = plan.passes.iter().map(|p| p.slots.pass_seed).collect();
        let mut unique = seeds[1..4].to_vec();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), 3, "temporal and spatial rounds: {seeds:?}");
        let table = pass_table(&plan);
        assert_eq!(plan.passes.len(), RESTIR_MAX_PASSES);
        assert_eq!(&table[..], &plan.passes.iter().map(|p| p.slots).collect::<Vec<_>>()[..]);
        let short = plan_frame(&state(None, false, 0));
        assert_eq!(
            pass_table(&short)[short.passes.len()..],
            [RestirPass::default(); RESTIR_MAX_PASSES - 2]
        );
    }
}
