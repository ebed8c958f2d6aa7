//! The methods `compare` and `stability` run, written `pt` or `restir:SHIFT[/MIS]`, and a
//! renderer that runs either one frame at a time.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::{bail, Result};

use restir_pt::render::{Image, PathTracer, RenderSettings, Restir, RestirSettings, ReuseMis, SceneGpu, ShiftKind, MAX_RESERVOIRS};

#[derive(Debug, Clone, PartialEq)]
pub enum MethodSpec {
    PathTracing,
    Restir(RestirSettings),
}

impl MethodSpec {
    /// Parses `pt`, `restir` (the default hybrid shift), `restir:SHIFT` or `restir:SHIFT/MIS`,
    /// each ReSTIR form optionally followed by `@sK` for K spatial neighbours (`@s0`: spatial
    /// reuse off); unnamed ReSTIR settings come from `base`.
    pub fn parse(text: &str, base: &RestirSettings) -> Result<Self> {
        let text = text.trim();
        if text == "pt" {
            return Ok(MethodSpec::PathTracing);
        }
        let Some(rest) = text.strip_prefix("restir") else {
            bail!("method '{text}': expected pt or restir:reconnection|replay|hybrid[/gbh|pairwise][@sK]");
        };
        let mut settings = base.clone();
        let rest = match rest.split_once('@') {
            Some((r, spatial)) => {
                settings.spatial = spatial
                    .strip_prefix('s')
                    .and_then(|k| k.parse().ok())
                    .ok_or_else(|| anyhow::anyhow!("method '{text}': expected @sK, K spatial neighbours"))?;
                r
            }
            None => rest,
        };
        let rest = match rest.strip_prefix(':') {
            Some(r) => r,
            None if rest.is_empty() => return Ok(MethodSpec::Restir(settings)),
            None => bail!("method '{text}': expected restir:SHIFT"),
        };
        let (shift, mis) = match rest.split_once('/') {
            Some((s, m)) => (s, Some(m)),
            None => (rest, None),
        };
        settings.shift = ShiftKind::from_name(shift)
            .ok_or_else(|| anyhow::anyhow!("method '{text}': unknown shift '{shift}' (reconnection, replay or hybrid)"))?;
        if let Some(mis) = mis {
            settings.mis =
                ReuseMis::from_name(mis).ok_or_else(|| anyhow::anyhow!("method '{text}': unknown MIS '{mis}' (gbh or pairwise)"))?;
        }
        Ok(MethodSpec::Restir(settings))
    }

    pub fn label(&self) -> String {
        match self {
            MethodSpec::PathTracing => "pt".into(),
            MethodSpec::Restir(r) => r.label(),
        }
    }
}

/// `--methods` of `compare` and `stability` by default: the path tracer and every shift.
pub const DEFAULT_METHODS: &str = "pt,restir:reconnection,restir:replay,restir:hybrid";

/// Parses a comma-separated method list.
pub fn parse_methods(list: &[String], base: &RestirSettings) -> Result<Vec<MethodSpec>> {
    if list.is_empty() {
        bail!("--methods names no method");
    }
    list.iter().map(|m| MethodSpec::parse(m, base)).collect()
}

/// The most samples per pixel a path-traced frame of `compare` or `stability` takes.
const MAX_FRAME_SPP: u32 = 1 << 16;

/// A compiled renderer for one method; its kernels are reused across runs.
pub enum MethodRenderer {
    /// The path tracer and its paths per pixel and frame. Both renderers are boxed: each holds
    /// over a kilobyte of handles.
    PathTracing(Box<PathTracer>, u32),
    Restir(Box<Restir>),
}

/// What one frame cost and how its shifts went.
pub struct FrameOutcome {
    pub gpu_ms: f64,
    /// Failed over attempted shifts (ReSTIR PT), None for the path tracer.
    pub failed_shift_rate: Option<f64>,
}

impl MethodRenderer {
    /// The renderer of `method` for the uploaded `scene` (shared, not uploaded again).
    pub fn new(scene: &Arc<SceneGpu>, settings: &RenderSettings, method: &MethodSpec) -> Result<Self> {
        Ok(match method {
            MethodSpec::PathTracing => MethodRenderer::PathTracing(Box::new(PathTracer::new(scene, settings)?), settings.spp),
            MethodSpec::Restir(r) => MethodRenderer::Restir(Box::new(Restir::new(scene, settings, r)?)),
        })
    }

    /// Starts an independent sequence with `seed`: the path tracer's sums or ReSTIR's history
    /// are cleared.
    pub fn reset(&mut self, settings: &RenderSettings) -> Result<()> {
        match self {
            MethodRenderer::PathTracing(t, _) => t.restart(settings),
            MethodRenderer::Restir(r) => r.reset(settings.seed),
        }
    }

    /// Sets the frame-cost knob: the path tracer's paths per pixel, or ReSTIR PT's reservoirs
    /// per pixel (its candidates per reservoir stay as set).
    pub fn set_cost_knob(&mut self, value: u32) -> Result<()> {
        match self {
            MethodRenderer::PathTracing(_, spp) => {
                if !(1..=MAX_FRAME_SPP).contains(&value) {
                    bail!("a path-traced frame takes 1 to {MAX_FRAME_SPP} samples per pixel, not {value}");
                }
                *spp = value;
                Ok(())
            }
            MethodRenderer::Restir(r) => r.set_reservoirs(value),
        }
    }

    /// The largest value set_cost_knob takes.
    pub fn max_cost_knob(&self) -> u32 {
        match self {
            MethodRenderer::PathTracing(..) => MAX_FRAME_SPP,
            MethodRenderer::Restir(_) => MAX_RESERVOIRS,
        }
    }

    /// Building and compiling this renderer's kernels, in ms (`KernelCompile::total_ms`).
    pub fn compile_ms(&self) -> f64 {
        match self {
            MethodRenderer::PathTracing(t, _) => t.compile_report().total_ms(),
            MethodRenderer::Restir(r) => r.compile_reports().iter().map(|k| k.total_ms()).sum(),
        }
    }

    pub fn cost_knob_name(&self) -> &'static str {
        match self {
            MethodRenderer::PathTracing(..) => "spp",
            MethodRenderer::Restir(_) => "reservoirs",
        }
    }

    /// One frame from `camera`: the knob's fresh paths per pixel for the path tracer (its frames
    /// share nothing), one ReSTIR PT frame (reusing the history) otherwise. The image is the
    /// frame alone.
    pub fn frame(&mut self, settings: &RenderSettings, camera: usize, frame: u32) -> Result<(FrameOutcome, Image)> {
        match self {
            MethodRenderer::PathTracing(t, spp) => {
                // Distinct frames need distinct random numbers: the seed advances per frame.
                t.restart(&RenderSettings {
                    camera,
                    seed: settings.seed.wrapping_mul(0x9e37_79b9).wrapping_add(frame),
                    spp: *spp,
                    ..settings.clone()
                })?;
                let stats = t.render(&|_| {}, &AtomicBool::new(false))?;
                let outcome = FrameOutcome {
                    gpu_ms: stats.gpu_ms,
                    failed_shift_rate: None,
                };
                Ok((outcome, t.image()?))
            }
            MethodRenderer::Restir(r) => {
                let stats = r.frame(camera, false)?;
                let outcome = FrameOutcome {
                    gpu_ms: stats.gpu_ms().unwrap_or(stats.wall_ms),
                    failed_shift_rate: Some(stats.failed_shift_rate()),
                };
                Ok((outcome, r.image()?))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_spec_parses_shift_mis_and_spatial_neighbours() {
        let base = RestirSettings::default();
        let MethodSpec::Restir(r) = MethodSpec::parse("restir:reconnection/pairwise@s0", &base).unwrap() else {
            panic!("a ReSTIR method")
        };
        assert_eq!((r.shift, r.mis, r.spatial), (ShiftKind::Reconnection, ReuseMis::Pairwise, 0));
        assert_eq!(r.label(), "restir:reconnection/pairwise@s0");
        let MethodSpec::Restir(r) = MethodSpec::parse("restir@s5", &base).unwrap() else {
            panic!("a ReSTIR method")
        };
        assert_eq!((r.shift, r.spatial), (base.shift, 5));
        assert_eq!(MethodSpec::parse("restir", &base).unwrap().label(), base.label());
        assert!(!base.label().contains('@'));
        for bad in ["restir@x", "restir:hybrid@s", "restir@s-1", "restir:warp"] {
            assert!(MethodSpec::parse(bad, &base).is_err(), "{bad}");
        }
        assert_eq!(MethodSpec::parse(" pt ", &base).unwrap(), MethodSpec::PathTracing);
    }
}
