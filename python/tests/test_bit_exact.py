"""The array equals the CLI's EXR bit for bit for the same scene, seed and settings."""

import numpy as np
import pytest

import restir_pt
from conftest import CORNELL, ROOT, run_cli

CASES = [
    # (CLI options, render() keywords)
    (["--method", "pt", "--spp", "8", "--width", "32", "--height", "24", "--seed", "7"],
     dict(method="pt", spp=8, width=32, height=24, seed=7)),
    (["--method", "pt", "--spp", "4", "--width", "32", "--height", "32", "--frames", "3", "--static-camera", "--russian-roulette", "off"],
     dict(method="pt", spp=4, width=32, height=32, frames=3, static_camera=True, russian_roulette=False)),
    # Large enough that the path tracer splits its samples into dispatches by timing.
    (["--method", "pt", "--spp", "64", "--width", "96", "--height", "64", "--seed", "2"],
     dict(method="pt", spp=64, width=96, height=64, seed=2)),
    (["--width", "32", "--height", "32", "--frames", "1", "--seed", "3"],
     dict(method="restir", width=32, height=32, seed=3)),
    (["--width", "32", "--height", "32", "--frames", "2", "--seed", "4", "--russian-roulette", "off"],
     dict(method="restir", width=32, height=32, frames=2, seed=4, russian_roulette=False)),
    (["--width", "32", "--height", "32", "--frames", "4", "--seed", "5", "--shift", "reconnection", "--mis", "pairwise", "--reservoirs", "2", "--spatial", "2"],
     dict(method="restir", width=32, height=32, frames=4, seed=5, shift="reconnection", mis="pairwise", reservoirs=2, spatial=2)),
    (["--width", "32", "--height", "32", "--frames", "3", "--static-camera", "--camera", "2", "--temporal", "off"],
     dict(method="restir", width=32, height=32, frames=3, static_camera=True, camera=2, temporal=False)),
]


@pytest.mark.parametrize("cli_args,kwargs", CASES, ids=["pt", "pt-static", "pt-chunked", "restir", "restir-no-roulette", "restir-moving", "restir-static"])
def test_array_equals_cli_exr_bit_for_bit(tmp_path, device, cli_args, kwargs):
    out = tmp_path / "cli.exr"
    run_cli("render", CORNELL, *cli_args, "--out", out)
    expected = restir_pt.read_exr(out)
    image = restir_pt.render(CORNELL, device=device, **kwargs)
    assert image.dtype == np.float32 and image.shape == expected.shape
    assert image.shape == (kwargs["height"], kwargs["width"], 3)
    assert np.isfinite(image).all() and image.mean() > 0.01
    # Bit for bit: compare the raw float32 words, not values within a tolerance.
    assert np.array_equal(image.view(np.uint32), expected.view(np.uint32))


def test_exr_reader_agrees_with_write_exr(tmp_path):
    rng = np.random.default_rng(1)
    image = rng.random((5, 7, 3), dtype=np.float32) * 10
    restir_pt.write_exr(tmp_path / "x.exr", image)
    assert np.array_equal(restir_pt.read_exr(tmp_path / "x.exr"), image)
