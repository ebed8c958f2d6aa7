"""restir-pt from Python: ReSTIR PT and a reference path tracer on Vulkan compute.

The objects follow the Rust library (``cargo doc``): load a :class:`Scene`, open a
:class:`Device`, upload the scene once (:meth:`Device.upload`), build a :class:`PathTracer` or a
:class:`Restir` on the upload, render frames, read images as float32 NumPy arrays of shape
(height, width, 3). :func:`render` does all of it in one call, as ``restir-pt render`` does.
Errors raise :class:`SceneError`, :class:`SettingsError` or :class:`DeviceError` (all
:class:`RestirPtError`) with the CLI's one-line message; loader warnings are
:class:`SceneWarning`. docs/python.md has the whole API.
"""

from __future__ import annotations

import os
import warnings
from typing import Any, Dict, List, Optional, Sequence, Union

from ._errors import DeviceError, RestirPtError, SceneError, SceneWarning, SettingsError
from ._native import (
    Camera,
    Device,
    PathTracer,
    Restir,
    Scene,
    UploadedScene,
    camera_on_path,
    devices,
    energy_ratio,
    flip,
    hdr_flip,
    mape,
    merge_shards,
    mse,
    read_exr,
    reference,
    rel_mse,
    rel_mse_trimmed,
    write_exr,
)
from ._native import _CHECKOUT
from ._native import compare as _compare

__all__ = [
    "Camera", "Device", "DeviceError", "PathTracer", "Restir", "RestirPtError", "Scene",
    "SceneError", "SceneWarning", "SettingsError", "UploadedScene", "RESTIR_OPTIONS",
    "camera_on_path", "compare", "devices", "energy_ratio", "flip", "hdr_flip", "mape", "merge_shards",
    "mse", "read_exr", "reference", "rel_mse", "rel_mse_trimmed", "render", "write_exr",
]

#: ReSTIR PT's settings and their defaults (``RestirSettings::default()``), the keyword
#: arguments :class:`Restir` and :func:`render` take beside the common ones.
RESTIR_OPTIONS: Dict[str, Any] = {
    "shift": "hybrid", "mis": "gbh", "temporal": True, "history": "spatial", "spatial": 1,
    "radius": 5.0, "rounds": 1, "m_cap": 20.0, "candidates": 1, "reservoirs": 1,
    "emission_rays": 4,
}

#: The bundled Cornell box, the CLI's default scene: scenes/cornell.gltf of the working folder
#: if it has one, else of the checkout the module was built from.
DEFAULT_SCENE = "scenes/cornell.gltf" if os.path.exists("scenes/cornell.gltf") else os.path.join(_CHECKOUT, "scenes", "cornell.gltf")


def _flag(name: str, value: Any) -> str:
    if isinstance(value, bool):
        value = "on" if value else "off"
    return f"--{name.replace('_', '-')} {value}"


def _check_restir_names(settings: Dict[str, Any]) -> None:
    unknown = sorted(set(settings) - set(RESTIR_OPTIONS))
    if unknown:
        raise TypeError(f"render() got unexpected keyword argument(s) {', '.join(unknown)}; ReSTIR PT's are {', '.join(RESTIR_OPTIONS)}")


def render(
    scene_path: Union[str, os.PathLike, None] = None,
    method: str = "restir",
    *,
    spp: Optional[int] = None,
    width: Optional[int] = None,
    height: Optional[int] = None,
    seed: int = 0,
    frames: int = 1,
    static_camera: bool = False,
    camera: int = 0,
    max_depth: int = 7,
    russian_roulette: Optional[bool] = None,
    env: Any = None,
    scene: Optional[int] = None,
    device: Union[int, str, Device, None] = None,
    return_stats: bool = False,
    **settings: Any,
):
    """Renders ``scene_path`` as ``restir-pt render`` does and returns the image.

    Keyword names are the CLI's options with underscores. ``method`` is ``"restir"`` (the
    CLI's default) or ``"pt"``; ``frames`` walk the scene's camera path from ``camera`` (or
    stay at it with ``static_camera``, averaging: the path tracer then holds frames x spp;
    one frame by default, the CLI's ``--frames 1``: without ``--frames`` the CLI renders
    ReSTIR PT to a time budget instead, which a script sets with ``frames``);
    ``settings`` are ReSTIR PT's options (:data:`RESTIR_OPTIONS`). The array is the last
    frame's float32 (height, width, 3) image, bit for bit the EXR the CLI writes for the same
    arguments. With ``return_stats`` returns ``(image, stats)``, one dict per frame. Flags the
    method ignores are warned about (``UserWarning``), as the CLI does.
    """
    rr = True if russian_roulette is None else russian_roulette
    if method not in ("pt", "restir"):
        raise SettingsError(f"method {method!r}: expected 'pt' or 'restir'")
    if frames < 1:
        raise SettingsError("--frames must be at least 1")
    _check_restir_names(settings)
    if method == "restir":
        if spp is not None:
            warnings.warn("--spp is ignored by ReSTIR PT, which renders --frames frames of --candidates paths per pixel (--method pt uses it)", stacklevel=2)
    else:
        changed = [_flag(k, v) for k, v in settings.items() if v != RESTIR_OPTIONS[k]]
        if changed:
            warnings.warn(f"--method pt ignores the ReSTIR PT options {', '.join(changed)}", stacklevel=2)
    path = os.fspath(scene_path) if scene_path is not None else DEFAULT_SCENE
    if not isinstance(device, Device):
        device = Device(device)
    loaded = Scene(path, scene=scene, env=env)
    count = len(loaded.cameras)
    if not static_camera and frames > 1 and count < 2:
        warnings.warn(f"{path}: the scene has one camera, so the camera cannot move; every frame is seen from it", stacklevel=2)
    uploaded = device.upload(loaded)

    def frame_camera(f: int) -> int:
        return camera if static_camera else camera_on_path(camera, f, count)

    stats: List[Dict[str, Any]] = []
    if method == "pt":
        per_frame = 64 if spp is None else spp
        tracer = PathTracer(uploaded, width=width, height=height, spp=per_frame, max_depth=max_depth, seed=seed, russian_roulette=rr, camera=camera)
        for f in range(frames):
            if f > 0 and static_camera:
                tracer.add_samples(per_frame)
            elif f > 0:
                tracer.restart(camera=frame_camera(f))
            stats.append(tracer.render())
        image = tracer.image()
    else:
        renderer = Restir(uploaded, width=width, height=height, max_depth=max_depth, seed=seed, camera=camera, russian_roulette=rr, **settings)
        stats = renderer.frames(frames, static_camera=static_camera)
        image = renderer.image()
    return (image, stats) if return_stats else image


def compare(
    scene_path: Union[str, os.PathLike],
    reference: Union[str, os.PathLike],
    *,
    methods: Sequence[str] = ("pt", "restir"),
    budgets_ms: Optional[Sequence[float]] = None,
    frames: int = 16,
    camera_path: bool = False,
    trials: int = 1,
    max_depth: int = 7,
    camera: int = 0,
    seed: int = 0,
    out_dir: Union[str, os.PathLike] = "out/compare",
    device: Union[int, str, None] = None,
    **settings: Any,
) -> List[Dict[str, Any]]:
    """``restir-pt compare`` from Python: error against GPU time per frame at equal budgets.

    Runs the CLI's own sweep (each method's cost calibrated, its knob fitted to each budget in
    ``budgets_ms``, default ReSTIR PT's cheapest frame x 1.05, 2.1 and 4.2; ``trials`` runs of
    ``frames`` frames, the last frame measured against the EXR ``reference``), writes
    results.csv, the charts and the equal-time strip to ``out_dir``, and returns the rows as
    dicts with results.csv's columns (``pandas.DataFrame(rows)`` takes them). ``methods`` are
    ``pt`` or ``restir[:SHIFT][/MIS][@sK]``; ``settings`` are ReSTIR PT's options
    (:data:`RESTIR_OPTIONS`) for every ``restir`` method. It opens its own device.
    """
    _check_restir_names(settings)
    argv = [os.fspath(scene_path), "--reference", os.fspath(reference), "--methods", ",".join(methods)]
    if budgets_ms:
        argv += ["--budgets-ms", ",".join(repr(float(b)) for b in budgets_ms)]
    argv += ["--frames", str(frames), "--trials", str(trials), "--max-depth", str(max_depth),
             "--camera", str(camera), "--seed", str(seed), "--out-dir", os.fspath(out_dir)]
    if camera_path:
        argv.append("--camera-path")
    for name, value in settings.items():
        argv += _flag(name, value).split(" ", 1)
    if device is not None:
        argv += ["--device", str(device)]
    return _compare(argv)
