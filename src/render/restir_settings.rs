//! What a ReSTIR PT render is asked to do on top of the path tracer's settings.

use anyhow::{bail, Result};

use super::frame_plan::{History, PassKernel};
use crate::shading::path_record::MAX_PATH_LENGTH;

pub use crate::shader_interface::{ReuseMis, ShiftKind};
pub use crate::shader_interface::{MAX_NEIGHBOURS, MAX_SPATIAL_ROUNDS as MAX_ROUNDS};
/// The most initial candidates per reservoir that [`RestirSettings::validate`] accepts.
pub const MAX_CANDIDATES: u32 = 64;
/// The most emission rays per pixel that [`RestirSettings::validate`] accepts.
pub const MAX_EMISSION_RAYS: u32 = 64;
/// The most reservoirs per pixel that [`RestirSettings::validate`] accepts.
pub const MAX_RESERVOIRS: u32 = 16;

/// The ReSTIR PT options (Lin et al. 2022, on the reservoir reuse of Bitterli et al. 2020). Check
/// them with [`RestirSettings::validate`] before building a [`super::Restir`]. Fields whose
/// default was measured say where (docs/lab-notebook.md).
#[derive(Debug, Clone, PartialEq)]
pub struct RestirSettings {
    /// The shift mapping of temporal and spatial reuse.
    pub shift: ShiftKind,
    /// The resampling MIS weights of reuse.
    pub mis: ReuseMis,
    /// Whether each frame reuses the previous frame's reservoirs.
    pub temporal: bool,
    /// Spatial neighbours per round; 0 turns spatial reuse off. The default, 1, is the cheapest
    /// spatial reuse: two shifts per pixel under either MIS (k neighbours cost k (k + 1) under
    /// the generalized balance heuristic), and with a moving camera the one that beat spatial
    /// reuse off at equal time (docs/lab-notebook.md, "Spatial reuse that pays").
    pub spatial: u32,
    /// Radius in pixels of the disk spatial neighbours are drawn from. The default, 5, measured
    /// best of 3, 5, 10, 20 and 35 with one neighbour and a moving camera at 128×128
    /// (docs/lab-notebook.md, "Spatial reuse that pays"); a nearer neighbour passes the surface
    /// similarity test more often.
    pub radius: f32,
    /// Spatial reuse rounds per frame, 1 to `MAX_ROUNDS` (ignored when `spatial` is 0).
    pub rounds: u32,
    /// The temporal input's confidence is capped at m_cap times the current M.
    pub m_cap: f32,
    /// Initial paths per reservoir.
    pub candidates: u32,
    /// Independent reservoirs per pixel, each with its own candidates, history and neighbours;
    /// the pixel shows their mean. One reservoir holds one path, whose colour (drawn in
    /// proportion to luminance) is noise that more candidates do not remove; more reservoirs
    /// average it down.
    pub reservoirs: u32,
    /// Camera rays per pixel that estimate the emission seen at the primary hit, the
    /// reservoir's own primary ray included. The emission term is estimated apart from the
    /// reservoir's paths, so extra rays cut its anti-aliasing noise (a light's edge seen by one
    /// jittered ray) without bias, at the cost of one closest-hit trace each.
    pub emission_rays: u32,
    /// Which reservoirs the next frame's temporal reuse reads: those before spatial reuse or
    /// after it (docs/restir.md, "Which reservoirs are the history").
    pub history: History,
    /// Spatial neighbours need |dot(n, n')| of their primary hits' geometric normals at least
    /// this (default 0.9).
    pub normal_threshold: f32,
    /// Spatial neighbours need their depth to agree within this fraction (default 0.1; see
    /// [`crate::gpu_types::ReuseParams::depth_threshold`]).
    pub depth_threshold: f32,
}

impl Default for RestirSettings {
    fn default() -> Self {
        Self {
            shift: ShiftKind::Hybrid,
            mis: ReuseMis::GeneralizedBalance,
            temporal: true,
            spatial: 1,
            radius: 5.0,
            rounds: 1,
            m_cap: 20.0,
            candidates: 1,
            reservoirs: 1,
            emission_rays: 4,
            history: History::Spatial,
            normal_threshold: 0.9,
            depth_threshold: 0.1,
        }
    }
}

impl RestirSettings {
    /// Checks every option against its range and `max_depth` (the render's) against the path
    /// record's [`MAX_PATH_LENGTH`]. Errors: one line naming the CLI flag and the allowed range.
    pub fn validate(&self, max_depth: u32) -> Result<()> {
        if max_depth as usize > MAX_PATH_LENGTH {
            bail!("--max-depth {max_depth} is too deep for ReSTIR PT: its path records hold at most {MAX_PATH_LENGTH} segments");
        }
        if self.spatial > MAX_NEIGHBOURS {
            bail!("--spatial {} is too many neighbours: at most {MAX_NEIGHBOURS}", self.spatial);
        }
        if self.spatial > 0 && !(1..=MAX_ROUNDS).contains(&self.rounds) {
            bail!("--rounds {} is out of range: 1 to {MAX_ROUNDS} spatial rounds", self.rounds);
        }
        if !(self.radius.is_finite() && self.radius >= 1.0) {
            bail!("--radius {} must be a finite number of pixels, at least 1", self.radius);
        }
        if !(self.m_cap.is_finite() && self.m_cap > 0.0) {
            bail!("--m-cap {} must be finite and positive", self.m_cap);
        }
        if !(1..=MAX_CANDIDATES).contains(&self.candidates) {
            bail!(
                "--candidates {} is out of range: 1 to {MAX_CANDIDATES} paths per pixel",
                self.candidates
            );
        }
        if !(1..=MAX_RESERVOIRS).contains(&self.reservoirs) {
            bail!(
                "--reservoirs {} is out of range: 1 to {MAX_RESERVOIRS} reservoirs per pixel",
                self.reservoirs
            );
        }
        if !(1..=MAX_EMISSION_RAYS).contains(&self.emission_rays) {
            bail!(
                "--emission-rays {} is out of range: 1 to {MAX_EMISSION_RAYS} camera rays per pixel",
                self.emission_rays
            );
        }
        Ok(())
    }

    /// The spatial rounds actually run.
    pub fn spatial_rounds(&self) -> u32 {
        if self.spatial == 0 {
            0
        } else {
            self.rounds
        }
    }

    /// The kernels a run dispatches whose frames are seen from the scene cameras `cameras`, in
    /// order: initial candidates and shading always, spatial reuse when on, and from the second
    /// frame on, with temporal reuse, the unmoved-camera variant where a frame keeps the
    /// previous frame's camera and the shifting one where it changes. Two cameras of one pose
    /// are told apart here but not by the frames, which build the kernel they need then.
    pub fn kernels_for_cameras(&self, cameras: &[usize]) -> Vec<PassKernel> {
        let mut kernels = vec![PassKernel::Initial];
        if self.temporal {
            if cameras.windows(2).any(|w| w[0] == w[1]) {
                kernels.push(PassKernel::TemporalUnmoved);
            }
            if cameras.windows(2).any(|w| w[0] != w[1]) {
                kernels.push(PassKernel::Temporal);
            }
        }
        if self.spatial_rounds() > 0 {
            kernels.push(PassKernel::Spatial);
        }
        kernels.push(PassKernel::Shade);
        kernels
    }

    /// The `#define`s that select the shift and the MIS in the reuse kernels.
    pub fn defines(&self) -> [(&'static str, &'static str); 2] {
        [("SHIFT_MODE", self.shift.glsl_name()), ("MIS_MODE", self.mis.glsl_name())]
    }

    /// A short label such as `restir:hybrid/gbh`, with `@sK` when the spatial neighbours are not
    /// the default's.
    pub fn label(&self) -> String {
        let spatial = if self.spatial == RestirSettings::default().spatial {
            String::new()
        } else {
            format!("@s{}", self.spatial)
        };
        format!("restir:{}/{}{spatial}", self.shift.name(), self.mis.name())
    }
}
