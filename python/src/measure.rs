//! The measurement toolkit: metrics against a reference (relMSE, MAPE, MSE, energy, ꟻLIP),
//! EXR files, path-traced references and their shards, and `compare`'s equal-time sweep.

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::renderers::render_interruptible;
use crate::scene::PyUploadedScene;
use crate::{error_of, from_array, py_error, to_array, without_gil, Kind};
use restir_pt::image_io::{auto_exposure_ev, read_exr as read_exr_file, write_exr as write_exr_file};
use restir_pt::metrics;
use restir_pt::reference_shard::{merge_shards as merge_shard_files, write_shard, ShardMeta, ShardSpec, ShardSums};
use restir_pt::render::{Image, PathTracer, RenderSettings};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(rel_mse, m)?)?;
    m.add_function(wrap_pyfunction!(rel_mse_trimmed, m)?)?;
    m.add_function(wrap_pyfunction!(mape, m)?)?;
    m.add_function(wrap_pyfunction!(mse, m)?)?;
    m.add_function(wrap_pyfunction!(energy_ratio, m)?)?;
    m.add_function(wrap_pyfunction!(flip, m)?)?;
    m.add_function(wrap_pyfunction!(hdr_flip, m)?)?;
    m.add_function(wrap_pyfunction!(read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(write_exr, m)?)?;
    m.add_function(wrap_pyfunction!(reference, m)?)?;
    m.add_function(wrap_pyfunction!(merge_shards, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    Ok(())
}

/// Both images as pixels, checked to be of one size.
fn pair(image: &Bound<'_, PyAny>, reference: &Bound<'_, PyAny>) -> PyResult<(u32, u32, Vec<glam::Vec3>, Vec<glam::Vec3>)> {
    let (w, h, x) = from_array("image", image)?;
    let (rw, rh, r) = from_array("reference", reference)?;
    if (w, h) != (rw, rh) {
        return Err(error_of(Kind::Settings, format!("image is {w}x{h} but reference is {rw}x{rh}")));
    }
    Ok((w, h, x, r))
}

/// relMSE: mean over pixels and channels of (x - r)² / (r² + 0.01), in f64.
#[pyfunction]
fn rel_mse(image: &Bound<'_, PyAny>, reference: &Bound<'_, PyAny>) -> PyResult<f64> {
    let (_, _, x, r) = pair(image, reference)?;
    Ok(metrics::rel_mse(&x, &r))
}

/// relMSE without the largest `share` of per-pixel errors (default 0.1%).
#[pyfunction]
#[pyo3(signature = (image, reference, share = metrics::TRIMMED_SHARE))]
fn rel_mse_trimmed(image: &Bound<'_, PyAny>, reference: &Bound<'_, PyAny>, share: f64) -> PyResult<f64> {
    if !(0.0..1.0).contains(&share) {
        return Err(error_of(Kind::Settings, format!("share {share} must be in [0, 1)")));
    }
    let (_, _, x, r) = pair(image, reference)?;
    Ok(metrics::rel_mse_trimmed(&x, &r, share))
}

/// MAPE: mean over pixels and channels of |x - r| / (r + 0.01), in f64 (0.1 reads 10%).
#[pyfunction]
fn mape(image: &Bound<'_, PyAny>, reference: &Bound<'_, PyAny>) -> PyResult<f64> {
    let (_, _, x, r) = pair(image, reference)?;
    Ok(metrics::mape(&x, &r))
}

/// MSE: mean over pixels and channels of (x - r)².
#[pyfunction]
fn mse(image: &Bound<'_, PyAny>, reference: &Bound<'_, PyAny>) -> PyResult<f64> {
    let (_, _, x, r) = pair(image, reference)?;
    Ok(metrics::mse(&x, &r))
}

/// The image's mean luminance over the reference's.
#[pyfunction]
fn energy_ratio(image: &Bound<'_, PyAny>, reference: &Bound<'_, PyAny>) -> PyResult<f64> {
    let (_, _, x, r) = pair(image, reference)?;
    Ok(metrics::energy_ratio(&x, &r))
}

/// LDR-ꟻLIP (Andersson et al. 2020, NVIDIA's implementation through the `nv-flip` crate) of
/// the two images after one tonemapping: radiance times 2^exposure (None: the reference's
/// automatic exposure, as the CLI's PNG previews), clamped to [0, 1], sRGB-encoded to 8 bits.
/// Returns the mean ꟻLIP error in [0, 1], or (mean, error map (height, width) float32) with
/// `error_map`. `hdr_flip` is the HDR metric.
#[pyfunction]
#[pyo3(signature = (image, reference, *, exposure = None, pixels_per_degree = nv_flip::DEFAULT_PIXELS_PER_DEGREE, error_map = false))]
fn flip<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
    exposure: Option<f32>,
    pixels_per_degree: f32,
    error_map: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (w, h, x, r) = pair(image, reference)?;
    if !(pixels_per_degree.is_finite() && pixels_per_degree > 0.0) {
        return Err(error_of(
            Kind::Settings,
            format!("pixels_per_degree {pixels_per_degree} must be positive"),
        ));
    }
    let ev = match exposure {
        Some(ev) if ev.is_finite() => ev,
        Some(ev) => return Err(error_of(Kind::Settings, format!("exposure {ev} must be a finite EV"))),
        None => auto_exposure_ev(&r),
    };
    let errors = without_gil(py, || metrics::ldr_flip_map(&x, &r, w, h, ev, pixels_per_degree));
    mean_and_map(py, errors, (w, h), error_map)
}

/// HDR-ꟻLIP (Andersson et al. 2021; `restir_pt::metrics::hdr_flip`) of two linear-radiance
/// images: the per-pixel maximum of LDR-ꟻLIP over exposures from the reference's brightest to
/// its median luminance, ACES-tone-mapped. Returns the mean in [0, 1], or (mean, error map
/// (height, width) float32) with `error_map`.
#[pyfunction]
#[pyo3(signature = (image, reference, *, error_map = false))]
fn hdr_flip<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
    error_map: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (w, h, x, r) = pair(image, reference)?;
    let errors = without_gil(py, || metrics::hdr_flip_map(&x, &r, w, h));
    mean_and_map(py, errors, (w, h), error_map)
}

/// The mean of an error map, with the map as (height, width) float32 when asked.
fn mean_and_map(py: Python<'_>, errors: Vec<f32>, (w, h): (u32, u32), error_map: bool) -> PyResult<Bound<'_, PyAny>> {
    let mean = errors.iter().map(|&e| e as f64).sum::<f64>() / errors.len().max(1) as f64;
    if error_map {
        let map = numpy::PyArray1::from_vec(py, errors);
        let map = numpy::PyArrayMethods::reshape(&map, [h as usize, w as usize])?;
        return Ok((mean, map).into_pyobject(py)?.into_any());
    }
    Ok(mean.into_pyobject(py)?.into_any())
}

/// The first RGB layer of an EXR as float32 (height, width, 3); raises `RestirPtError`.
#[pyfunction]
fn read_exr<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let (w, h, pixels) = without_gil(py, || read_exr_file(&path)).map_err(|e| py_error(Kind::Other, e))?;
    to_array(py, w, h, pixels)
}

/// Writes an (height, width, 3) image as an RGB float EXR (as `render --out` does).
#[pyfunction]
fn write_exr(py: Python<'_>, path: PathBuf, image: &Bound<'_, PyAny>) -> PyResult<()> {
    let (w, h, pixels) = from_array("image", image)?;
    without_gil(py, || write_exr_file(&path, w, h, &pixels)).map_err(|e| py_error(Kind::Other, e))
}

/// The mean and variance EXRs and the JSON record `restir-pt reference --out` writes.
fn write_reference(out: &Path, image: &Image, scene: &Path, settings: &RenderSettings) -> anyhow::Result<()> {
    use crate::app::reference_record::{scene_name, write_record, ReferenceRecord};
    write_exr_file(out, image.width, image.height, &image.mean)?;
    write_exr_file(&out.with_extension("variance.exr"), image.width, image.height, &image.variance)?;
    let record = ReferenceRecord {
        scene: scene_name(scene),
        camera: settings.camera,
        width: image.width,
        height: image.height,
        spp: settings.spp,
    };
    write_record(out, &record)
}

/// A path-traced reference of `scene` (an `UploadedScene`), as `restir-pt reference`:
/// `spp` samples per pixel of camera `camera`. With `shard` ("I/N" or (I, N)) only that
/// share of the samples is rendered and `out` receives the shard file for `merge_shards`;
/// otherwise `out` (optional) receives the mean, NAME.variance.exr and NAME.json. Returns
/// (mean, variance) as float32 (height, width, 3). Ctrl-C raises `KeyboardInterrupt`.
#[pyfunction]
#[pyo3(signature = (scene, *, spp, width = 256, height = 256, camera = 0, max_depth = 7, seed = 0, shard = None, out = None))]
#[allow(clippy::too_many_arguments)]
fn reference<'py>(
    py: Python<'py>,
    scene: &PyUploadedScene,
    spp: u32,
    width: u32,
    height: u32,
    camera: usize,
    max_depth: u32,
    seed: u32,
    shard: Option<&Bound<'py, PyAny>>,
    out: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let shard = match shard {
        None => None,
        Some(s) => {
            let text = match s.extract::<(u32, u32)>() {
                Ok((i, n)) => format!("{i}/{n}"),
                Err(_) => s.str()?.to_string(),
            };
            Some(ShardSpec::parse(&text).map_err(|e| py_error(Kind::Settings, e))?)
        }
    };
    if spp == 0 {
        return Err(error_of(Kind::Settings, "--spp must be at least 1".into()));
    }
    if shard.is_some() && out.is_none() {
        return Err(error_of(
            Kind::Settings,
            "a shard needs out=, the shard file merge_shards reads".into(),
        ));
    }
    let samples = shard.map(|s| s.samples(spp)).unwrap_or(0..spp);
    if samples.is_empty() {
        let count = shard.map_or(1, |s| s.count);
        return Err(error_of(
            Kind::Settings,
            format!("--spp {spp} cannot be cut into {count} shards: each needs at least 1 sample"),
        ));
    }
    let settings = RenderSettings {
        width,
        height,
        spp: samples.len() as u32,
        max_depth,
        seed,
        camera,
        ..Default::default()
    };
    settings.validate(scene.gpu.info()).map_err(|e| py_error(Kind::Settings, e))?;
    let gpu = scene.gpu.clone();
    let mut tracer = without_gil(py, || PathTracer::new(&gpu, &settings)).map_err(|e| py_error(Kind::Device, e))?;
    tracer.start_at_sample(samples.start);
    let stats = render_interruptible(py, &mut tracer)?;
    let image = tracer.image().map_err(|e| py_error(Kind::Device, e))?;
    if let Some(out) = &out {
        let source = scene.gpu.info().source.clone();
        let written = match shard {
            Some(s) => tracer.sums().and_then(|(sums, sums_sq)| {
                let meta = ShardMeta {
                    scene: source.display().to_string(),
                    width,
                    height,
                    max_depth,
                    camera,
                    seed,
                    total_spp: spp,
                    shard: s.index,
                    shards: s.count,
                    first_sample: samples.start,
                    spp: stats.spp,
                };
                write_shard(out, &ShardSums { meta, sums, sums_sq })
            }),
            None => write_reference(out, &image, &source, &settings),
        };
        written.map_err(|e| py_error(Kind::Other, e))?;
    }
    let mean = to_array(py, image.width, image.height, image.mean)?;
    let variance = to_array(py, image.width, image.height, image.variance)?;
    Ok((mean, variance).into_pyobject(py)?.into_any())
}

/// Adds up reference shards (`reference(..., shard=...)` files) into the (mean, variance)
/// of one process of the same seed and total spp; with `out`, also writes them and the
/// record as `restir-pt merge --out` does. Raises `RestirPtError` naming a bad file; warns
/// (`UserWarning`) when shards are missing.
#[pyfunction]
#[pyo3(signature = (paths, *, out = None))]
fn merge_shards<'py>(py: Python<'py>, paths: Vec<PathBuf>, out: Option<PathBuf>) -> PyResult<Bound<'py, PyAny>> {
    let (merged, missing) = without_gil(py, || merge_shard_files(&paths)).map_err(|e| py_error(Kind::Other, e))?;
    let meta = &merged.meta;
    if !missing.is_empty() {
        let text = format!(
            "shards {missing:?} of {} are missing: the reference has {} of {} spp",
            meta.shards, meta.spp, meta.total_spp
        );
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &std::ffi::CString::new(text).expect("no NUL"),
            1,
        )?;
    }
    let image = Image::from_sums(meta.width, meta.height, &merged.sums, &merged.sums_sq);
    if let Some(out) = &out {
        let mut argv: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
        argv.extend(["--out".into(), out.display().to_string(), "--allow-nonfinite".into()]);
        let argv: Vec<&str> = argv.iter().map(String::as_str).collect();
        let args = crate::app::parse_args::<crate::app::MergeArgs>(&argv).map_err(|e| py_error(Kind::Settings, e))?;
        without_gil(py, || crate::app::merge(args)).map_err(|e| py_error(Kind::Other, e))?;
    }
    let mean = to_array(py, image.width, image.height, image.mean)?;
    let variance = to_array(py, image.width, image.height, image.variance)?;
    Ok((mean, variance).into_pyobject(py)?.into_any())
}

/// `restir-pt compare` from Python: `argv` are its options after the scene (built by
/// restir_pt.compare from keyword arguments). Runs the CLI's sweep (writing results.csv,
/// the charts and the strip to its out_dir) and returns its rows as dicts with results.csv's
/// columns.
#[pyfunction]
fn compare<'py>(py: Python<'py>, argv: Vec<String>) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let argv: Vec<&str> = argv.iter().map(String::as_str).collect();
    let args = crate::app::parse_args::<crate::app::CompareArgs>(&argv).map_err(|e| py_error(Kind::Settings, e))?;
    let rows = without_gil(py, || crate::app::compare(args)).map_err(|e| py_error(Kind::Other, e))?;
    rows.into_iter()
        .map(|row| {
            let dict = PyDict::new(py);
            dict.set_item("method", row.method)?;
            dict.set_item("budget_ms", row.budget_ms)?;
            dict.set_item("knob", row.knob)?;
            dict.set_item("gpu_ms_per_frame", row.gpu_ms_per_frame)?;
            dict.set_item("rel_mse", row.rel_mse)?;
            dict.set_item("rel_mse_stderr", row.rel_mse_stderr)?;
            dict.set_item("rel_mse_trimmed", row.rel_mse_trimmed)?;
            dict.set_item("mse", row.mse)?;
            dict.set_item("energy_ratio", row.energy_ratio)?;
            dict.set_item("failed_shift_rate", row.failed_shift_rate)?;
            dict.set_item("nonfinite_pixels", row.nonfinite_pixels)?;
            dict.set_item("mape", row.mape)?;
            dict.set_item("hdr_flip", row.hdr_flip)?;
            dict.set_item("pt_samples_per_frame", row.pt_samples_per_frame)?;
            Ok(dict)
        })
        .collect()
}
