//! The renderers: `PathTracer` and `Restir`, with every setting of `restir-pt render` as a
//! keyword argument, checked by the library's own validation (the CLI's messages).

use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::scene::{PyCamera, PyUploadedScene};
use crate::{check_signals, error_of, py_error, to_array, without_gil, Kind, OnThisThread};
use restir_pt::render::{
    FrameStats, History, PathTracer, RenderSettings, RenderStats, Restir, RestirSettings, ReuseMis, SceneGpu, ShiftKind, PASS_NAMES,
};
use restir_pt::scene::Camera;

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPathTracer>()?;
    m.add_class::<PyRestir>()?;
    Ok(())
}

/// The settings both renderers share; a missing side follows the camera as in the CLI.
#[allow(clippy::too_many_arguments)]
fn render_settings(
    gpu: &SceneGpu,
    width: Option<u32>,
    height: Option<u32>,
    spp: u32,
    max_depth: u32,
    seed: u32,
    russian_roulette: bool,
    camera: usize,
) -> PyResult<RenderSettings> {
    let cameras = &gpu.info().cameras;
    let (width, height) = cameras.get(camera).unwrap_or(&cameras[0]).image_size(width, height);
    let settings = RenderSettings {
        width,
        height,
        spp,
        max_depth,
        seed,
        russian_roulette,
        camera,
    };
    settings.validate(gpu.info()).map_err(|e| py_error(Kind::Settings, e))?;
    Ok(settings)
}

/// A frame's camera: None (the renderer's own), a scene camera index, or a `Camera` pose.
enum FrameCamera {
    Index(usize),
    Pose(Camera),
}

fn frame_camera(camera: Option<&Bound<'_, PyAny>>, default: usize, gpu: &SceneGpu) -> PyResult<FrameCamera> {
    let Some(camera) = camera else {
        return Ok(FrameCamera::Index(default));
    };
    if let Ok(pose) = camera.extract::<PyRef<PyCamera>>() {
        return Ok(FrameCamera::Pose(pose.camera.clone()));
    }
    let index: usize = camera
        .extract()
        .map_err(|_| error_of(Kind::Settings, "camera: a scene camera index or a restir_pt.Camera".into()))?;
    let count = gpu.info().cameras.len();
    if index >= count {
        return Err(error_of(
            Kind::Settings,
            format!(
                "{}: --camera {index} does not exist; the scene has {count} camera(s)",
                gpu.info().source.display()
            ),
        ));
    }
    Ok(FrameCamera::Index(index))
}

fn parse_enum<T: Copy>(flag: &str, value: &str, all: &[T], name: fn(T) -> &'static str) -> PyResult<T> {
    all.iter().copied().find(|v| name(*v) == value).ok_or_else(|| {
        let names: Vec<&str> = all.iter().map(|v| name(*v)).collect();
        error_of(Kind::Settings, format!("--{flag} {value:?}: expected one of {}", names.join(", ")))
    })
}

fn history_name(h: History) -> &'static str {
    match h {
        History::Temporal => "temporal",
        History::Spatial => "spatial",
    }
}

fn path_stats<'py>(py: Python<'py>, stats: &RenderStats, pixels: usize) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("spp", stats.spp)?;
    dict.set_item("gpu_ms", stats.gpu_ms)?;
    dict.set_item("wall_ms", stats.wall_ms)?;
    dict.set_item("paths_per_second", stats.paths_per_second(pixels))?;
    dict.set_item("nonfinite_paths", stats.nonfinite_paths)?;
    dict.set_item("interrupted", stats.interrupted)?;
    Ok(dict)
}

/// `tracer.render` with the GIL released; a signal (Ctrl-C) seen between submissions stops
/// it after the current one and is raised once the samples so far are summed.
pub(crate) fn render_interruptible(py: Python<'_>, tracer: &mut PathTracer) -> PyResult<RenderStats> {
    let cancel = AtomicBool::new(false);
    let signal: RefCell<Option<PyErr>> = RefCell::new(None);
    let tracer = OnThisThread(tracer);
    let result = without_gil(py, || {
        let tracer = tracer;
        let progress = |_done: u32| {
            if signal.borrow().is_none() {
                if let Err(e) = check_signals() {
                    *signal.borrow_mut() = Some(e);
                    cancel.store(true, Ordering::Relaxed);
                }
            }
        };
        tracer.0.render(&progress, &cancel)
    });
    let stats = result.map_err(|e| py_error(Kind::Device, e))?;
    match signal.into_inner() {
        Some(e) => Err(e),
        None => Ok(stats),
    }
}

/// Progressive path tracing (NEE and MIS) of one uploaded scene at one resolution.
#[pyclass(name = "PathTracer", module = "restir_pt", unsendable)]
pub struct PyPathTracer {
    tracer: PathTracer,
    scene: Arc<SceneGpu>,
    settings: RenderSettings,
}

#[pymethods]
impl PyPathTracer {
    /// A path tracer of `scene` (an `UploadedScene`), its kernel compiled. Settings as
    /// `restir-pt render --method pt`: width/height (a missing side follows the camera's
    /// aspect ratio, else 256), spp per render, max_depth (path segments), seed,
    /// russian_roulette, camera (index). Raises `SettingsError` with the CLI's message.
    #[new]
    #[pyo3(signature = (scene, *, width = None, height = None, spp = 64, max_depth = 7, seed = 0, russian_roulette = true, camera = 0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scene: &PyUploadedScene,
        width: Option<u32>,
        height: Option<u32>,
        spp: u32,
        max_depth: u32,
        seed: u32,
        russian_roulette: bool,
        camera: usize,
    ) -> PyResult<Self> {
        let settings = render_settings(&scene.gpu, width, height, spp, max_depth, seed, russian_roulette, camera)?;
        let gpu = scene.gpu.clone();
        let tracer = without_gil(py, || PathTracer::new(&gpu, &settings)).map_err(|e| py_error(Kind::Device, e))?;
        Ok(Self {
            tracer,
            scene: scene.gpu.clone(),
            settings,
        })
    }

    /// Traces up to the target spp (the settings' spp, plus `add_samples`) and returns the
    /// stats: spp, gpu_ms, wall_ms, paths_per_second, nonfinite_paths, interrupted. Ctrl-C
    /// stops after the current submission and raises `KeyboardInterrupt`; the samples so far
    /// stay and `image()` reads them.
    fn render<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let stats = render_interruptible(py, &mut self.tracer)?;
        path_stats(py, &stats, self.settings.pixel_count())
    }

    /// Starts a new image (cleared sums, sample 0) from `camera` (None: the settings' camera;
    /// an index or a `Camera` pose), optionally with another seed, spp, max_depth or
    /// russian_roulette; the kernel stays compiled and the resolution stays.
    #[pyo3(signature = (*, camera = None, seed = None, spp = None, max_depth = None, russian_roulette = None))]
    fn restart(
        &mut self,
        py: Python<'_>,
        camera: Option<&Bound<'_, PyAny>>,
        seed: Option<u32>,
        spp: Option<u32>,
        max_depth: Option<u32>,
        russian_roulette: Option<bool>,
    ) -> PyResult<()> {
        let mut settings = RenderSettings {
            seed: seed.unwrap_or(self.settings.seed),
            spp: spp.unwrap_or(self.settings.spp),
            max_depth: max_depth.unwrap_or(self.settings.max_depth),
            russian_roulette: russian_roulette.unwrap_or(self.settings.russian_roulette),
            ..self.settings.clone()
        };
        settings.validate_numbers().map_err(|e| py_error(Kind::Settings, e))?;
        let pose = match frame_camera(camera, settings.camera, &self.scene)? {
            FrameCamera::Index(i) => {
                settings.camera = i;
                self.scene.info().cameras[i].clone()
            }
            FrameCamera::Pose(pose) => pose,
        };
        let tracer = OnThisThread(&mut self.tracer);
        without_gil(py, || {
            let tracer = tracer;
            tracer.0.restart_from(&settings, &pose)
        })
        .map_err(|e| py_error(Kind::Settings, e))?;
        self.settings = settings;
        Ok(())
    }

    /// One frame of a moving camera: `restart(camera=camera)` then `render()`; returns the stats.
    #[pyo3(signature = (camera = None))]
    fn frame<'py>(&mut self, py: Python<'py>, camera: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyDict>> {
        self.restart(py, camera, None, None, None, None)?;
        self.render(py)
    }

    /// Raises the target by `spp` paths per pixel, keeping the sums: the next `render()`
    /// continues the same sample sequence (a static camera's next frame).
    fn add_samples(&mut self, spp: u32) {
        self.tracer.add_samples(spp);
    }

    /// Makes this render's samples the ones numbered first, first + 1, ... of its seed (a
    /// reference shard); call before `render()`.
    fn start_at_sample(&mut self, first: u32) {
        self.tracer.start_at_sample(first);
    }

    /// The paths per pixel `render()` runs up to.
    #[getter]
    fn target_spp(&self) -> u32 {
        self.tracer.target_spp()
    }

    /// (height, width) of the image.
    #[getter]
    fn shape(&self) -> (u32, u32) {
        (self.settings.height, self.settings.width)
    }

    /// Milliseconds spent compiling the kernel at construction.
    #[getter]
    fn compile_ms(&self) -> f64 {
        self.tracer.compile_report().total_ms()
    }

    /// The mean of the samples so far as float32 (height, width, 3), linear RGB, row 0 at the
    /// top; with `variance`, also the variance of each pixel's mean.
    #[pyo3(signature = (*, variance = false))]
    fn image<'py>(&self, py: Python<'py>, variance: bool) -> PyResult<Bound<'py, PyAny>> {
        let tracer = OnThisThread(&self.tracer);
        let image = without_gil(py, || {
            let tracer = tracer;
            tracer.0.image()
        })
        .map_err(|e| py_error(Kind::Device, e))?;
        let mean = to_array(py, image.width, image.height, image.mean)?;
        if variance {
            let var = to_array(py, image.width, image.height, image.variance)?;
            return Ok((mean, var).into_pyobject(py)?.into_any());
        }
        Ok(mean)
    }

    fn __repr__(&self) -> String {
        let s = &self.settings;
        format!(
            "PathTracer({}x{}, spp={}, max_depth={}, seed={})",
            s.width, s.height, s.spp, s.max_depth, s.seed
        )
    }
}

/// The per-frame statistics of a ReSTIR PT frame as a dict.
fn restir_stats<'py>(py: Python<'py>, frame: u32, camera: Option<usize>, stats: &FrameStats) -> PyResult<Bound<'py, PyDict>> {
    let c = &stats.counters;
    let dict = PyDict::new(py);
    dict.set_item("frame", frame)?;
    dict.set_item("camera", camera)?;
    dict.set_item("gpu_ms", stats.gpu_ms())?;
    let passes = PyDict::new(py);
    if let Some(ms) = stats.pass_ms {
        for (name, t) in PASS_NAMES.iter().zip(ms) {
            passes.set_item(*name, t)?;
        }
    }
    dict.set_item("pass_ms", passes)?;
    dict.set_item("wall_ms", stats.wall_ms)?;
    dict.set_item("shifts_attempted", c.shifts_attempted)?;
    dict.set_item("shifts_failed", c.shifts_failed)?;
    dict.set_item("failed_shift_rate", stats.failed_shift_rate())?;
    dict.set_item("traversals_per_shift", stats.traversals_per_shift())?;
    dict.set_item("shift_lane_use", stats.shift_lane_use())?;
    dict.set_item("nonfinite_weights", c.nonfinite_weights)?;
    dict.set_item("nonfinite_pixels", c.nonfinite_pixels)?;
    dict.set_item("candidates_dropped", c.candidates_dropped)?;
    Ok(dict)
}

/// ReSTIR PT of one uploaded scene at one resolution: one `frame()` per camera pose, the
/// temporal history and a static camera's running average kept between frames.
#[pyclass(name = "Restir", module = "restir_pt", unsendable)]
pub struct PyRestir {
    renderer: Restir,
    scene: Arc<SceneGpu>,
    settings: RenderSettings,
    restir: RestirSettings,
    frames_done: u32,
}

#[pymethods]
impl PyRestir {
    /// A ReSTIR PT renderer of `scene` (an `UploadedScene`), every kernel compiled. Settings as
    /// `restir-pt render --method restir` (names with underscores): width, height, max_depth
    /// (at most 7), seed, camera, russian_roulette (in the initial candidates), shift (reconnection|replay|hybrid), mis (gbh|pairwise),
    /// temporal, history (temporal|spatial), spatial, radius, rounds, m_cap, candidates,
    /// reservoirs, emission_rays; normal_threshold and depth_threshold (library only). Raises
    /// `SettingsError` with the CLI's message.
    #[new]
    #[pyo3(signature = (scene, *, width = None, height = None, max_depth = 7, seed = 0, camera = 0,
        russian_roulette = true, shift = "hybrid", mis = "gbh", temporal = true, history = "spatial", spatial = 1, radius = 5.0,
        rounds = 1, m_cap = 20.0, candidates = 1, reservoirs = 1, emission_rays = 4,
        normal_threshold = 0.9, depth_threshold = 0.1))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scene: &PyUploadedScene,
        width: Option<u32>,
        height: Option<u32>,
        max_depth: u32,
        seed: u32,
        camera: usize,
        russian_roulette: bool,
        shift: &str,
        mis: &str,
        temporal: bool,
        history: &str,
        spatial: u32,
        radius: f32,
        rounds: u32,
        m_cap: f32,
        candidates: u32,
        reservoirs: u32,
        emission_rays: u32,
        normal_threshold: f32,
        depth_threshold: f32,
    ) -> PyResult<Self> {
        let settings = render_settings(
            &scene.gpu,
            width,
            height,
            RenderSettings::DEFAULT_SPP,
            max_depth,
            seed,
            russian_roulette,
            camera,
        )?;
        let restir = RestirSettings {
            shift: parse_enum("shift", shift, &ShiftKind::ALL, ShiftKind::name)?,
            mis: parse_enum("mis", mis, &ReuseMis::ALL, ReuseMis::name)?,
            temporal,
            history: parse_enum("history", history, &[History::Temporal, History::Spatial], history_name)?,
            spatial,
            radius,
            rounds,
            m_cap,
            candidates,
            reservoirs,
            emission_rays,
            normal_threshold,
            depth_threshold,
        };
        restir.validate(settings.max_depth).map_err(|e| py_error(Kind::Settings, e))?;
        let thresholds_ok = normal_threshold.is_finite()
            && (-1.0..=1.0).contains(&normal_threshold)
            && depth_threshold.is_finite()
            && depth_threshold >= 0.0;
        if !thresholds_ok {
            return Err(error_of(
                Kind::Settings,
                format!(
                    "normal_threshold {normal_threshold} must be in [-1, 1] and depth_threshold {depth_threshold} finite and non-negative"
                ),
            ));
        }
        let gpu = scene.gpu.clone();
        let renderer = without_gil(py, || Restir::new(&gpu, &settings, &restir)).map_err(|e| py_error(Kind::Device, e))?;
        Ok(Self {
            renderer,
            scene: scene.gpu.clone(),
            settings,
            restir,
            frames_done: 0,
        })
    }

    /// Renders one frame from `camera` (None: the settings' camera; an index or a `Camera`
    /// pose) and returns its stats (gpu_ms, pass_ms per pass, wall_ms, shifts, failed-shift
    /// rate, non-finite counts). With `accumulate` the frame joins the running average (a
    /// static camera); otherwise the image is this frame alone.
    #[pyo3(signature = (camera = None, *, accumulate = false))]
    fn frame<'py>(&mut self, py: Python<'py>, camera: Option<&Bound<'py, PyAny>>, accumulate: bool) -> PyResult<Bound<'py, PyDict>> {
        let camera = frame_camera(camera, self.settings.camera, &self.scene)?;
        let index = match &camera {
            FrameCamera::Index(i) => Some(*i),
            FrameCamera::Pose(_) => None,
        };
        let renderer = OnThisThread(&mut self.renderer);
        let stats = without_gil(py, || {
            let renderer = renderer;
            match camera {
                FrameCamera::Index(i) => renderer.0.frame(i, accumulate),
                FrameCamera::Pose(pose) => renderer.0.frame_from(&pose, accumulate),
            }
        })
        .map_err(|e| py_error(Kind::Device, e))?;
        self.frames_done += 1;
        restir_stats(py, self.frames_done - 1, index, &stats)
    }

    /// Renders `count` frames and returns their stats. `cameras`: one per frame (indices or
    /// `Camera` poses); without it the camera follows the scene's camera path from the
    /// settings' camera, as `restir-pt render --frames` does, or stays put with
    /// `static_camera` (whose frames are averaged). Ctrl-C between frames raises
    /// `KeyboardInterrupt`; the renderer keeps the frames done.
    #[pyo3(signature = (count, *, cameras = None, static_camera = false))]
    fn frames<'py>(
        &mut self,
        py: Python<'py>,
        count: u32,
        cameras: Option<Vec<Bound<'py, PyAny>>>,
        static_camera: bool,
    ) -> PyResult<Vec<Bound<'py, PyDict>>> {
        if cameras.as_ref().is_some_and(|c| c.len() != count as usize) {
            return Err(error_of(Kind::Settings, format!("cameras: {count} frames need {count} cameras")));
        }
        let n = self.scene.info().cameras.len();
        let mut out = Vec::with_capacity(count as usize);
        for f in 0..count {
            py.check_signals()?;
            let camera = match &cameras {
                Some(list) => list[f as usize].clone(),
                None if static_camera => self.settings.camera.into_pyobject(py)?.into_any(),
                None => restir_pt::scene::camera_on_path(self.settings.camera, f, n)
                    .into_pyobject(py)?
                    .into_any(),
            };
            out.push(self.frame(py, Some(&camera), static_camera)?);
        }
        Ok(out)
    }

    /// Forgets the history and the average: the next frame starts a new chain with `seed`
    /// (None: the settings' seed).
    #[pyo3(signature = (seed = None))]
    fn reset(&mut self, seed: Option<u32>) -> PyResult<()> {
        let seed = seed.unwrap_or(self.settings.seed);
        self.renderer.reset(seed).map_err(|e| py_error(Kind::Device, e))?;
        self.settings.seed = seed;
        self.frames_done = 0;
        Ok(())
    }

    /// Changes the reservoirs per pixel of the next frames (1 to 16); the history is forgotten.
    fn set_reservoirs(&mut self, reservoirs: u32) -> PyResult<()> {
        let restir = RestirSettings {
            reservoirs,
            ..self.restir.clone()
        };
        restir.validate(self.settings.max_depth).map_err(|e| py_error(Kind::Settings, e))?;
        self.renderer.set_reservoirs(reservoirs).map_err(|e| py_error(Kind::Device, e))?;
        self.restir = restir;
        Ok(())
    }

    /// Milliseconds spent compiling the kernels at construction.
    #[getter]
    fn compile_ms(&self) -> f64 {
        self.renderer.compile_ms()
    }

    /// (height, width) of the image.
    #[getter]
    fn shape(&self) -> (u32, u32) {
        (self.settings.height, self.settings.width)
    }

    /// The label `compare` gives these settings, e.g. "restir:hybrid/gbh".
    #[getter]
    fn label(&self) -> String {
        self.restir.label()
    }

    /// The last frame (or the average of the accumulated frames) as float32 (height, width,
    /// 3), linear RGB, row 0 at the top; with `variance`, also the variance of the average.
    #[pyo3(signature = (*, variance = false))]
    fn image<'py>(&self, py: Python<'py>, variance: bool) -> PyResult<Bound<'py, PyAny>> {
        let renderer = OnThisThread(&self.renderer);
        let image = without_gil(py, || {
            let renderer = renderer;
            renderer.0.image()
        })
        .map_err(|e| py_error(Kind::Device, e))?;
        let mean = to_array(py, image.width, image.height, image.mean)?;
        if variance {
            let var = to_array(py, image.width, image.height, image.variance)?;
            return Ok((mean, var).into_pyobject(py)?.into_any());
        }
        Ok(mean)
    }

    fn __repr__(&self) -> String {
        let s = &self.settings;
        format!(
            "Restir({}x{}, {}, max_depth={}, seed={})",
            s.width,
            s.height,
            self.restir.label(),
            s.max_depth,
            s.seed
        )
    }
}
