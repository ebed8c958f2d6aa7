//! `restir_pt._native`: the Python binding of the restir-pt library (pyo3). The Python package
//! `restir_pt` (python/restir_pt/) re-exports it and adds `render`, the exception classes and
//! the stubs. Every call that works on the device releases the GIL; every error becomes a
//! Python exception carrying the one line the CLI would print after `error:`.

// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

// The CLI's commands, compiled into the module so that `compare` runs the CLI's own sweep
// (equal-time fitting, trials, outputs) rather than a copy of it; only `compare` is called.
#[allow(dead_code, unused_imports)]
#[path = "../../src/app/mod.rs"]
mod app;

mod measure;
mod renderers;
mod scene;

use glam::Vec3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyType;

use restir_pt::error::GpuError;

/// What failed, which picks the exception class (restir_pt/_errors.py).
#[derive(Clone, Copy)]
pub(crate) enum Kind {
    /// A scene that cannot be loaded: `SceneError`.
    Scene,
    /// A setting out of range or of the wrong kind: `SettingsError` (a `ValueError`).
    Settings,
    /// No device, a lost device, out of memory, a failed kernel: `DeviceError` (a `RuntimeError`).
    Device,
    /// Anything else, e.g. a file that cannot be read or written: `RestirPtError`.
    Other,
}

/// The exception of `kind` with `e`'s one-line message, as the CLI prints it after `error:`.
/// A [`GpuError`] anywhere in the chain makes it a `DeviceError` whatever `kind` says.
pub(crate) fn py_error(kind: Kind, e: anyhow::Error) -> PyErr {
    let gpu = e.chain().any(|c| c.downcast_ref::<GpuError>().is_some());
    let message = format!("{e:#}").replace('\n', " ");
    error_of(if gpu { Kind::Device } else { kind }, message)
}

/// The exception class of `kind` from restir_pt/_errors.py, holding `message`.
pub(crate) fn error_of(kind: Kind, message: String) -> PyErr {
    let name = match kind {
        Kind::Scene => "SceneError",
        Kind::Settings => "SettingsError",
        Kind::Device => "DeviceError",
        Kind::Other => "RestirPtError",
    };
    Python::attach(|py| {
        let class = py.import("restir_pt._errors").and_then(|m| m.getattr(name));
        match class.and_then(|c| c.cast_into::<PyType>().map_err(PyErr::from)) {
            Ok(class) => PyErr::from_type(class, message),
            Err(e) => e,
        }
    })
}

/// Marks a value as safe to move into `Python::detach`: the closure runs on the calling
/// thread, so the renderers' raw Vulkan handles never change threads.
pub(crate) struct OnThisThread<T>(pub T);

// SAFETY: `detach` runs its closure on the current thread before returning; the value is
// only carried across the GIL release, never used from another thread.
unsafe impl<T> Send for OnThisThread<T> {}

/// Runs `f` with the GIL released (the device works while Python threads run).
pub(crate) fn without_gil<T, F: FnOnce() -> T>(py: Python<'_>, f: F) -> T {
    let f = OnThisThread(f);
    let out = py.detach(move || {
        let f = f;
        OnThisThread((f.0)())
    });
    out.0
}

/// `pixels` (row-major from the top left) as a float32 NumPy array of shape (height, width, 3)
/// that owns the values (moved, not copied).
pub(crate) fn to_array<'py>(py: Python<'py>, width: u32, height: u32, pixels: Vec<Vec3>) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = pixels.into_iter().flat_map(|p| p.to_array()).collect();
    let array = PyArray1::from_vec(py, flat);
    Ok(array.reshape([height as usize, width as usize, 3])?.into_any())
}

/// An image argument: anything NumPy turns into float32 of shape (height, width, 3).
/// Returns (width, height, pixels). Errors: `SettingsError` naming `what` and the shape.
pub(crate) fn from_array(what: &str, image: &Bound<'_, PyAny>) -> PyResult<(u32, u32, Vec<Vec3>)> {
    let py = image.py();
    let numpy = py.import("numpy")?;
    let converted = numpy.call_method1("ascontiguousarray", (image, "float32"))?;
    let shape: Vec<usize> = converted.getattr("shape")?.extract()?;
    if shape.len() != 3 || shape[2] != 3 || shape[0] == 0 || shape[1] == 0 {
        return Err(error_of(
            Kind::Settings,
            format!("{what}: an image is an array of shape (height, width, 3), not {shape:?}"),
        ));
    }
    let array: PyReadonlyArray3<f32> = converted.extract()?;
    let (height, width) = (array.shape()[0] as u32, array.shape()[1] as u32);
    let values = array.as_slice()?;
    let pixels = values.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
    Ok((width, height, pixels))
}

/// Raises `KeyboardInterrupt` (or what a signal handler raised) if a signal arrived; called
/// between frames and between path-tracer submissions.
pub(crate) fn check_signals() -> PyResult<()> {
    Python::attach(|py| py.check_signals())
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    scene::register(m)?;
    renderers::register(m)?;
    measure::register(m)?;
    // Where the checkout was: `render()` without a scene finds the bundled Cornell box there.
    m.add("_CHECKOUT", concat!(env!("CARGO_MANIFEST_DIR"), "/.."))?;
    Ok(())
}
