"""Shared fixtures: the repository, the CLI binary (built by `cargo build --release`), one
device for the session, and a runner for the CLI."""

import os
import subprocess
from pathlib import Path

import pytest

import restir_pt

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "target" / "release" / "restir-pt"
CORNELL = ROOT / "scenes" / "cornell.gltf"
BAD = ROOT / "tests" / "data" / "bad"


@pytest.fixture(scope="session")
def device():
    return restir_pt.Device()


@pytest.fixture(scope="session")
def cornell(device):
    return device.upload(restir_pt.Scene(CORNELL))


def run_cli(*args, check=True):
    """Runs `restir-pt ARGS` from the repository root; returns the finished process."""
    if not CLI.exists():
        pytest.fail(f"{CLI} is missing: run `cargo build --release` first")
    proc = subprocess.run([str(CLI), *map(str, args)], cwd=ROOT, capture_output=True, text=True, timeout=600)
    if check and proc.returncode != 0:
        raise AssertionError(f"restir-pt {' '.join(map(str, args))} failed:\n{proc.stderr}")
    return proc


def cli_error_line(proc):
    """The one `error: ...` line of a failed CLI run, without the prefix."""
    lines = [l for l in proc.stderr.splitlines() if l.startswith("error: ")]
    assert proc.returncode == 1 and len(lines) == 1, proc.stderr
    return lines[0][len("error: "):]
