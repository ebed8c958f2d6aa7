"""Bad input raises the right exception with the CLI's one-line message; odd input warns."""

import numpy as np
import pytest

import restir_pt
from conftest import BAD, CORNELL, cli_error_line, run_cli


@pytest.mark.parametrize("name", ["bad-json.gltf", "not-gltf.gltf", "nan-position.gltf", "negative-roughness.gltf", "no-scene.gltf"])
def test_bad_scene_raises_scene_error_with_the_cli_message(name):
    proc = run_cli("info", BAD / name, check=False)
    with pytest.raises(restir_pt.SceneError) as caught:
        restir_pt.Scene(BAD / name)
    assert str(caught.value) == cli_error_line(proc)
    assert name in str(caught.value)


def test_missing_scene_raises_scene_error():
    with pytest.raises(restir_pt.SceneError, match="no-such-scene.gltf"):
        restir_pt.Scene("no-such-scene.gltf")


def test_loader_warnings_are_scene_warnings():
    with pytest.warns(restir_pt.SceneWarning, match="no perspective camera: using a default one"):
        scene = restir_pt.Scene(BAD / "no-camera.gltf")
    assert any("default one" in w for w in scene.warnings)
    # Warnings come out also when the load then fails, as on the command line.
    with pytest.warns(restir_pt.SceneWarning):
        with pytest.raises(restir_pt.SceneError):
            restir_pt.Scene(BAD / "warnings-then-error.gltf")


@pytest.mark.parametrize(
    "cli_args,kwargs",
    [
        (["--spatial", "99"], dict(spatial=99)),
        (["--reservoirs", "0"], dict(reservoirs=0)),
        (["--radius", "0.5"], dict(radius=0.5)),
        (["--m-cap", "-1"], dict(m_cap=-1.0)),
        (["--max-depth", "9"], dict(max_depth=9)),
        (["--camera", "99"], dict(camera=99)),
        (["--width", "0", "--height", "8"], dict(width=0, height=8)),
    ],
)
def test_bad_setting_raises_settings_error_with_the_cli_message(cornell, cli_args, kwargs):
    proc = run_cli("render", CORNELL, *cli_args, "--out", "out/never.exr", check=False)
    with pytest.raises(restir_pt.SettingsError) as caught:
        restir_pt.Restir(cornell, **kwargs)
    assert str(caught.value) == cli_error_line(proc)
    assert isinstance(caught.value, ValueError)


def test_path_tracer_settings_and_names(cornell):
    with pytest.raises(restir_pt.SettingsError, match="--spp must be at least 1"):
        restir_pt.PathTracer(cornell, spp=0)
    with pytest.raises(restir_pt.SettingsError, match="expected one of reconnection, replay, hybrid"):
        restir_pt.Restir(cornell, shift="teleport")
    with pytest.raises(TypeError):
        restir_pt.Restir(cornell, no_such_option=1)
    with pytest.raises(TypeError):
        restir_pt.render(CORNELL, method="restir", no_such_option=1)
    with pytest.raises(OverflowError):
        restir_pt.PathTracer(cornell, spp=-1)


def test_bad_device_and_bad_arrays():
    with pytest.raises(restir_pt.DeviceError, match="no Vulkan device matches"):
        restir_pt.Device("no-such-device")
    assert any(d["compute"] for d in restir_pt.devices())
    with pytest.raises(restir_pt.SettingsError, match=r"shape \(height, width, 3\)"):
        restir_pt.rel_mse(np.zeros((4, 4)), np.zeros((4, 4)))
    with pytest.raises(restir_pt.SettingsError, match="image is 4x4 but reference is 5x4"):
        restir_pt.mape(np.zeros((4, 4, 3)), np.zeros((4, 5, 3)))
    with pytest.raises(restir_pt.RestirPtError, match="cannot read EXR"):
        restir_pt.read_exr("no-such-file.exr")


def test_bad_camera_pose_raises():
    with pytest.raises(restir_pt.SettingsError, match="parallel"):
        restir_pt.Camera.look_at((0, 0, 5), (0, 0, 0), up=(0, 0, 1))
