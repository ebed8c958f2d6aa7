//! Scenes, cameras, devices and uploads: `Scene`, `Camera`, `Device`, `UploadedScene`,
//! `devices()`.

use std::ffi::CString;
use std::path::PathBuf;
use std::sync::Arc;

use glam::Vec3;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{error_of, py_error, without_gil, Kind};
use restir_pt::render::SceneGpu;
use restir_pt::scene::{collapse_warnings, load_scene_reporting, Camera, LoadOptions, Scene};
use restir_pt::vk::{list_devices, Context, ContextOptions};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScene>()?;
    m.add_class::<PyCamera>()?;
    m.add_class::<PyDevice>()?;
    m.add_class::<PyUploadedScene>()?;
    m.add_function(wrap_pyfunction!(devices, m)?)?;
    m.add_function(wrap_pyfunction!(camera_on_path, m)?)?;
    Ok(())
}

/// A glTF 2.0 scene loaded into host memory (triangles, BVH, materials, lights, cameras).
#[pyclass(name = "Scene", module = "restir_pt", frozen)]
pub struct PyScene {
    pub(crate) scene: Arc<Scene>,
    warnings: Vec<String>,
}

/// `env`: None, a path to an .exr/.hdr map, or three non-negative finite radiances.
fn environment(env: Option<&Bound<'_, PyAny>>) -> PyResult<(Option<Vec3>, Option<PathBuf>)> {
    let Some(env) = env else { return Ok((None, None)) };
    if let Ok(path) = env.extract::<PathBuf>() {
        return Ok((None, Some(path)));
    }
    let rgb: [f32; 3] = env.extract().map_err(|_| {
        error_of(
            Kind::Settings,
            "env takes (r, g, b), three finite, non-negative radiances, or the path of an .exr or .hdr map".into(),
        )
    })?;
    if rgb.iter().any(|c| !c.is_finite() || *c < 0.0) {
        return Err(error_of(
            Kind::Settings,
            format!("env {rgb:?}: radiances must be finite and non-negative"),
        ));
    }
    Ok((Some(Vec3::from_array(rgb)), None))
}

/// Issues each loader warning (identical ones collapsed with their count) as a `SceneWarning`.
fn warn_all(py: Python<'_>, warnings: &[String]) -> PyResult<()> {
    let category = py.import("restir_pt._errors")?.getattr("SceneWarning")?;
    for w in warnings {
        let text = CString::new(w.replace('\0', " ")).expect("NULs replaced");
        PyErr::warn(py, &category, &text, 2)?;
    }
    Ok(())
}

#[pymethods]
impl PyScene {
    /// Loads `path` (.gltf or .glb); `scene` picks one of the file's scenes, `env` replaces its
    /// environment ((r, g, b), an .exr/.hdr map, or "none" for no default sky), `env_rotation`
    /// turns a map about the up axis (degrees, as the CLI's --env-rotation). The loader's
    /// warnings are issued as `SceneWarning`s (also when the load then fails); errors raise
    /// `SceneError`.
    #[new]
    #[pyo3(signature = (path, *, scene = None, env = None, env_rotation = 0.0))]
    fn new(py: Python<'_>, path: PathBuf, scene: Option<usize>, env: Option<&Bound<'_, PyAny>>, env_rotation: f32) -> PyResult<Self> {
        let no_environment = env.is_some_and(|e| e.extract::<String>().is_ok_and(|s| s == "none"));
        let (environment, environment_map) = if no_environment { (None, None) } else { environment(env)? };
        if !env_rotation.is_finite() {
            return Err(error_of(
                Kind::Settings,
                format!("env_rotation {env_rotation}: give a finite angle in degrees"),
            ));
        }
        let options = LoadOptions {
            scene,
            environment,
            environment_map,
            env_rotation,
            no_environment,
            array_limit: None,
        };
        let (result, warnings) = without_gil(py, || {
            let mut warnings = vec![];
            let result = load_scene_reporting(&path, &options, &mut warnings);
            (result, collapse_warnings(&warnings))
        });
        warn_all(py, &warnings)?;
        let scene = result.map_err(|e| py_error(Kind::Scene, e))?;
        Ok(Self {
            scene: Arc::new(scene),
            warnings,
        })
    }

    /// The file the scene came from.
    #[getter]
    fn path(&self) -> PathBuf {
        self.scene.source.clone()
    }

    /// The scene's cameras (a scene without one has a framing camera), in file order.
    #[getter]
    fn cameras(&self) -> Vec<PyCamera> {
        self.scene.cameras.iter().cloned().map(|camera| PyCamera { camera }).collect()
    }

    /// Triangles after instancing.
    #[getter]
    fn triangle_count(&self) -> usize {
        self.scene.triangles.len()
    }

    /// Emissive triangles plus punctual lights.
    #[getter]
    fn emitter_count(&self) -> usize {
        self.scene.emitters.len()
    }

    /// The loader's warnings, as issued.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// World position of the scene coordinates' origin: cameras and poses are given relative
    /// to it (scene coordinates = world - origin).
    #[getter]
    fn origin(&self) -> (f64, f64, f64) {
        self.scene.origin.into()
    }

    /// The image size the CLI would render for `width`/`height` (either may be None) from
    /// camera `camera`: a missing side follows the camera's aspect ratio, else 256.
    #[pyo3(signature = (width = None, height = None, camera = 0))]
    fn image_size(&self, width: Option<u32>, height: Option<u32>, camera: usize) -> (u32, u32) {
        let cameras = &self.scene.cameras;
        cameras.get(camera).unwrap_or(&cameras[0]).image_size(width, height)
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene({:?}, triangles={}, emitters={}, cameras={})",
            self.scene.source.display().to_string(),
            self.scene.triangles.len(),
            self.scene.emitters.len(),
            self.scene.cameras.len()
        )
    }
}

/// A pinhole camera pose in scene coordinates: position, unit forward/up/right axes and a
/// vertical field of view in radians.
#[pyclass(name = "Camera", module = "restir_pt", frozen)]
#[derive(Clone)]
pub struct PyCamera {
    pub(crate) camera: Camera,
}

fn tuple(v: Vec3) -> (f32, f32, f32) {
    (v.x, v.y, v.z)
}

#[pymethods]
impl PyCamera {
    /// A camera at `eye` looking at `target`, `up` the image's vertical (not parallel to the
    /// view), `yfov` the vertical field of view in radians. Raises `SettingsError` for a pose
    /// that cannot render.
    #[staticmethod]
    #[pyo3(signature = (eye, target, up = [0.0, 1.0, 0.0], yfov = std::f32::consts::FRAC_PI_4, name = "scripted camera"))]
    fn look_at(eye: [f32; 3], target: [f32; 3], up: [f32; 3], yfov: f32, name: &str) -> PyResult<Self> {
        let camera = Camera::look_at(name, Vec3::from(eye), Vec3::from(target), Vec3::from(up), yfov);
        camera.check_pose().map_err(|e| py_error(Kind::Settings, e))?;
        Ok(Self { camera })
    }

    #[getter]
    fn name(&self) -> String {
        self.camera.name.clone()
    }
    #[getter]
    fn position(&self) -> (f32, f32, f32) {
        tuple(self.camera.position)
    }
    #[getter]
    fn forward(&self) -> (f32, f32, f32) {
        tuple(self.camera.forward)
    }
    #[getter]
    fn up(&self) -> (f32, f32, f32) {
        tuple(self.camera.up)
    }
    #[getter]
    fn right(&self) -> (f32, f32, f32) {
        tuple(self.camera.right)
    }
    /// Vertical field of view in radians.
    #[getter]
    fn yfov(&self) -> f32 {
        self.camera.yfov
    }
    /// The glTF camera's aspectRatio (width / height), if it gives one.
    #[getter]
    fn aspect_ratio(&self) -> Option<f32> {
        self.camera.aspect_ratio
    }

    fn __repr__(&self) -> String {
        let c = &self.camera;
        format!(
            "Camera({:?}, position={}, forward={}, yfov={})",
            c.name, c.position, c.forward, c.yfov
        )
    }
}

/// The camera of frame `frame` on a scene's camera path from camera `start` of `cameras`:
/// its cameras in order, then back and forth, as `restir-pt render --frames` walks them.
#[pyfunction]
fn camera_on_path(start: usize, frame: u32, cameras: usize) -> PyResult<usize> {
    if cameras == 0 || start >= cameras {
        return Err(error_of(
            Kind::Settings,
            format!("camera {start} does not exist; the path has {cameras} camera(s)"),
        ));
    }
    Ok(restir_pt::scene::camera_on_path(start, frame, cameras))
}

/// Every Vulkan device, as dicts {index, name, type, compute}; `Device(index)` or
/// `Device(name)` opens one.
#[pyfunction]
fn devices(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    let list = without_gil(py, list_devices).map_err(|e| py_error(Kind::Device, e))?;
    list.into_iter()
        .map(|d| {
            let dict = PyDict::new(py);
            dict.set_item("index", d.index)?;
            dict.set_item("name", d.name)?;
            dict.set_item("type", format!("{:?}", d.device_type))?;
            dict.set_item("compute", d.compute)?;
            Ok(dict)
        })
        .collect()
}

/// An open Vulkan device (queue, allocator, kernel cache).
#[pyclass(name = "Device", module = "restir_pt", frozen)]
pub struct PyDevice {
    pub(crate) ctx: Arc<Context>,
}

#[pymethods]
impl PyDevice {
    /// Opens `device` (an index of `devices()` or a name substring; None: the first discrete,
    /// integrated, virtual then CPU device). `validation` turns the Vulkan validation layer on;
    /// `check_validation()` then raises on anything it reported (open and close validated
    /// devices from one thread at a time: Debian 12's layer races otherwise). Raises `DeviceError`.
    #[new]
    #[pyo3(signature = (device = None, *, validation = false))]
    fn new(py: Python<'_>, device: Option<&Bound<'_, PyAny>>, validation: bool) -> PyResult<Self> {
        let device = match device {
            None => None,
            Some(d) => Some(d.str()?.to_string()),
        };
        let options = ContextOptions {
            device,
            validation,
            ..Default::default()
        };
        let ctx = without_gil(py, || Context::new(&options)).map_err(|e| py_error(Kind::Device, e))?;
        Ok(Self { ctx: Arc::new(ctx) })
    }

    /// The device's name, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    #[getter]
    fn name(&self) -> String {
        self.ctx.info.name.clone()
    }

    /// Discrete, integrated, virtual or CPU.
    #[getter]
    fn device_type(&self) -> String {
        format!("{:?}", self.ctx.info.device_type)
    }

    /// Uploads `scene` once; every renderer built on the result shares its buffers.
    fn upload(&self, py: Python<'_>, scene: &PyScene) -> PyResult<PyUploadedScene> {
        let (ctx, host) = (self.ctx.clone(), scene.scene.clone());
        let gpu = without_gil(py, || SceneGpu::upload(&ctx, &host)).map_err(|e| py_error(Kind::Device, e))?;
        Ok(PyUploadedScene { gpu })
    }

    /// Raises `DeviceError` if the validation layer reported anything since the device opened.
    fn check_validation(&self) -> PyResult<()> {
        self.ctx.check_validation().map_err(|e| py_error(Kind::Device, e.into()))
    }

    fn __repr__(&self) -> String {
        format!("Device({:?}, {:?})", self.ctx.info.name, self.ctx.info.device_type)
    }
}

/// A scene in device memory (buffers, kernel defines); renderers are built on it.
#[pyclass(name = "UploadedScene", module = "restir_pt", frozen)]
pub struct PyUploadedScene {
    pub(crate) gpu: Arc<SceneGpu>,
}

#[pymethods]
impl PyUploadedScene {
    /// The file the scene came from.
    #[getter]
    fn path(&self) -> PathBuf {
        self.gpu.info().source.clone()
    }

    /// The scene's cameras.
    #[getter]
    fn cameras(&self) -> Vec<PyCamera> {
        self.gpu.info().cameras.iter().cloned().map(|camera| PyCamera { camera }).collect()
    }

    /// The name of the device it lives on.
    #[getter]
    fn device_name(&self) -> String {
        self.gpu.ctx().info.name.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "UploadedScene({:?} on {:?})",
            self.gpu.info().source.display().to_string(),
            self.gpu.ctx().info.name
        )
    }
}
