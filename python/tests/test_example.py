"""examples/moving_camera.py runs end to end at a tiny size and draws its chart."""

import subprocess
import sys

import pytest

from conftest import ROOT

pytest.importorskip("matplotlib")


def test_moving_camera_example_writes_rows_and_chart(tmp_path):
    out = tmp_path / "moving"
    proc = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "moving_camera.py"), "--scene", str(ROOT / "scenes" / "cornell-glossy.gltf"),
         "--size", "16", "--frames", "3", "--trials", "2", "--reference-spp", "64", "--methods", "pt,restir", "--out-dir", str(out)],
        cwd=ROOT, capture_output=True, text=True, timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    chart = out / "moving_camera.png"
    assert chart.stat().st_size > 10_000 and chart.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    lines = (out / "results.csv").read_text().splitlines()
    # Three default budgets per method.
    assert len(lines) == 1 + 6, lines
    assert sum("GPU ms per frame, relMSE" in l for l in proc.stdout.splitlines()) == 6
