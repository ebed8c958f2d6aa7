"""Renderers are reused across frames, camera poses and scenes on one device; the GIL is
released while the device works."""

import threading
import time

import numpy as np

import restir_pt
from conftest import ROOT


def test_restir_reused_across_frames_and_poses(cornell):
    renderer = restir_pt.Restir(cornell, width=24, height=24, seed=11)
    cameras = cornell.cameras
    stats = renderer.frames(3)
    assert [s["camera"] for s in stats] == [0, 1, 2]
    for s in stats:
        assert s["nonfinite_pixels"] == 0 and s["gpu_ms"] > 0
        assert set(s["pass_ms"]) == {"initial", "temporal", "spatial", "shade"}
        assert 0.0 <= s["failed_shift_rate"] <= 1.0
    moved = renderer.image()
    # A scene camera given as a pose renders what its index renders, bit for bit.
    renderer.reset()
    renderer.frame(0)
    by_index = renderer.image()
    renderer.reset()
    renderer.frame(cameras[0])
    assert np.array_equal(renderer.image(), by_index)
    # A scripted pose: a camera pulled back from camera 0 sees a different, finite image.
    eye = np.array(cameras[0].position) - 0.5 * np.array(cameras[0].forward)
    target = eye + np.array(cameras[0].forward)
    pose = restir_pt.Camera.look_at(eye, target, up=cameras[0].up, yfov=cameras[0].yfov)
    s = renderer.frame(pose)
    assert s["camera"] is None
    scripted = renderer.image()
    assert np.isfinite(scripted).all() and not np.array_equal(scripted, by_index)
    assert moved.shape == scripted.shape == (24, 24, 3)


def test_renderers_across_scenes_on_one_device(device, cornell):
    glossy = device.upload(restir_pt.Scene(ROOT / "scenes" / "cornell-glossy.gltf"))
    a = restir_pt.Restir(cornell, width=16, height=16)
    b = restir_pt.Restir(glossy, width=16, height=16)
    images = []
    for renderer in (a, b, a, b):
        renderer.reset()
        renderer.frame(0)
        images.append(renderer.image())
    # The same renderer and seed give the same image, whatever ran in between.
    assert np.array_equal(images[0], images[2]) and np.array_equal(images[1], images[3])
    assert not np.array_equal(images[0], images[1])


def test_path_tracer_restart_add_samples_and_variance(cornell):
    tracer = restir_pt.PathTracer(cornell, width=16, height=16, spp=4, seed=2)
    first = tracer.render()
    assert first["spp"] == 4 and not first["interrupted"]
    tracer.add_samples(4)
    assert tracer.render()["spp"] == 8
    mean, variance = tracer.image(variance=True)
    assert mean.shape == variance.shape == (16, 16, 3) and (variance >= 0).all()
    tracer.restart(camera=3, seed=9)
    assert tracer.render()["spp"] == 4
    other = tracer.image()
    tracer.frame(camera=cornell.cameras[3])
    assert np.array_equal(tracer.image(), other)


def test_gil_is_released_while_the_device_works(cornell):
    tracer = restir_pt.PathTracer(cornell, width=64, height=64, spp=64)
    stamps = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            stamps.append(time.perf_counter())
            time.sleep(0.001)

    thread = threading.Thread(target=tick)
    thread.start()
    try:
        start = time.perf_counter()
        tracer.render()
        end = time.perf_counter()
    finally:
        done.set()
        thread.join()
    # Held, the GIL would stop the other thread for the whole render: no tick in its middle.
    middle = [t for t in stamps if start + 0.25 * (end - start) < t < start + 0.75 * (end - start)]
    assert end - start > 0.05 and len(middle) >= 5, (end - start, len(middle))
