//! The parameter blocks a ReSTIR PT frame is run with: its reuse parameters and pass table.

use super::super::frame_plan::{pass_table, FramePlan};
use super::Restir;
use crate::gpu_types::{FrameParams, InitialParams, ReuseParams, SpatialParams, TemporalParams};

impl Restir {
    /// The reuse parameters of a frame seen from `frame` after `prev`, with its pass table.
    pub(super) fn reuse_params(&self, prev: &FrameParams, frame: &FrameParams, plan: &FramePlan, accumulate: bool) -> ReuseParams {
        let temporal_valid = self.restir.temporal && self.history.is_some();
        ReuseParams {
            temporal: TemporalParams {
                prev_cam_position: prev.cam_position,
                prev_cam_right: prev.cam_right,
                prev_cam_up: prev.cam_up,
                prev_cam_forward: prev.cam_forward,
                m_cap: self.restir.m_cap,
                valid: temporal_valid as u32,
                pad: [0; 2],
            },
            roughness_threshold: self.shift_params.roughness_threshold,
            distance_threshold: self.shift_params.distance_threshold,
            normal_threshold: self.restir.normal_threshold,
            depth_threshold: self.restir.depth_threshold,
            frame_index: self.frame_index,
            reservoirs: self.restir.reservoirs,
            initial: InitialParams {
                candidates: self.restir.candidates,
                emission_rays: self.restir.emission_rays,
                // Frames being accumulated are averaged already; a running mean inside them
                // would only weigh the early frames' rays more.
                emission_history: (temporal_valid && same_pose(prev, frame) && !accumulate) as u32,
            },
            spatial: SpatialParams {
                neighbours: self.restir.spatial,
                radius: self.restir.radius,
            },
            passes: pass_table(plan),
        }
    }
}

/// Whether two frames share a camera pose, compared as glsl/restir_reuse.glsl's same_pose does.
pub(super) fn same_pose(a: &FrameParams, b: &FrameParams) -> bool {
    a.cam_position == b.cam_position && a.cam_right == b.cam_right && a.cam_up == b.cam_up && a.cam_forward == b.cam_forward
}
