"""Memory stays flat over 200 frames; Ctrl-C stops a long render cleanly."""

import signal
import subprocess
import sys
import textwrap
import time

import restir_pt
from conftest import CORNELL, ROOT


def rss_kib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise AssertionError("no VmRSS")


def test_memory_stays_flat_over_200_frames(cornell):
    renderer = restir_pt.Restir(cornell, width=16, height=16)
    tracer = restir_pt.PathTracer(cornell, width=16, height=16, spp=1)
    rss = []
    for f in range(200):
        renderer.frame(restir_pt.camera_on_path(0, f, len(cornell.cameras)))
        image = renderer.image()
        tracer.frame(f % len(cornell.cameras))
        traced = tracer.image(variance=True)
        del image, traced
        if f in (49, 199):
            rss.append(rss_kib())
    # After a warm-up of 50 frames, 150 more frames (each reading two images back) may not
    # grow the process: a leak of one 16x16 image a frame would add 450 KiB.
    assert rss[1] - rss[0] < 256, rss


SCRIPT = textwrap.dedent(
    """
    import sys, restir_pt
    device = restir_pt.Device()
    scene = device.upload(restir_pt.Scene(sys.argv[1]))
    tracer = restir_pt.PathTracer(scene, width=64, height=64, spp=1_000_000)
    print("rendering", flush=True)
    try:
        tracer.render()
    except KeyboardInterrupt:
        image = tracer.image()
        assert image.shape == (64, 64, 3) and (image == image).all()
        tracer.restart(spp=2)
        assert tracer.render()["spp"] == 2
        print("interrupted cleanly", flush=True)
        sys.exit(0)
    sys.exit(3)
    """
)


def test_ctrl_c_stops_a_long_render_cleanly():
    proc = subprocess.Popen([sys.executable, "-c", SCRIPT, str(CORNELL)], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "rendering"
    time.sleep(1.0)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    assert "interrupted cleanly" in out
