#!/usr/bin/env python3
"""Mitsuba 3 on restir-pt's benchmark job, for docs/performance.md (a dev-time measurement tool,
not a dependency of restir-pt).

Converts a bundled glTF scene (flat node list; diffuse or emissive materials; the node named
"camera 0") to Mitsuba meshes, renders it with the `path` integrator at the given resolution, spp
and max depth with Russian roulette off (rr_depth past max depth), and prints the median paths/s
of the timed renders after one warm-up render, and the median paths per second of CPU time
(all threads), which a machine shared with other jobs still measures faithfully.

    pip install mitsuba
    # llvm_ad_rgb on Debian 12: apt-get install libllvm19 (Dr.Jit miscompiles with LLVM 15)
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \
        python3 tools/mitsuba_bench.py scenes/cornell.gltf --variant llvm_ad_rgb
"""
import argparse
import base64
import json
import math
import os
import statistics
import struct
import sys
import tempfile
import time


def quat_rotate(q, v):
    x, y, z, w = q
    # v + 2 w (q x v) + 2 q x (q x v)
    cx, cy, cz = y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0]
    ccx, ccy, ccz = y * cz - z * cy, z * cx - x * cz, x * cy - y * cx
    return (v[0] + 2 * (w * cx + ccx), v[1] + 2 * (w * cy + ccy), v[2] + 2 * (w * cz + ccz))


def accessor(g, blob, i):
    a = g["accessors"][i]
    view = g["bufferViews"][a["bufferView"]]
    start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
    comps = {"SCALAR": 1, "VEC3": 3}[a["type"]]
    fmt = {5126: "f", 5125: "I", 5123: "H"}[a["componentType"]]
    size = struct.calcsize(fmt)
    data = struct.unpack_from("<%d%s" % (a["count"] * comps, fmt), blob, start)
    assert view.get("byteStride", size * comps) == size * comps, "interleaved buffers are not supported"
    return [data[k:k + comps] for k in range(0, len(data), comps)] if comps > 1 else list(data)


def write_ply(path, positions, indices):
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
                 "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
                 % (len(positions), len(indices) // 3)).encode())
        for p in positions:
            f.write(struct.pack("<3f", *p))
        for k in range(0, len(indices), 3):
            f.write(struct.pack("<B3i", 3, *indices[k:k + 3]))


def scene_dict(path, width, height, spp, max_depth, tmp):
    g = json.load(open(path))
    uri = g["buffers"][0]["uri"]
    blob = base64.b64decode(uri.split(",", 1)[1]) if uri.startswith("data:") else open(
        os.path.join(os.path.dirname(path), uri), "rb").read()
    d = {"type": "scene", "integrator": {"type": "path", "max_depth": max_depth, "rr_depth": max_depth + 100}}
    for n, node in enumerate(g["nodes"]):
        if "camera" in node and node["name"] == "camera 0":
            q, t = node.get("rotation", [0, 0, 0, 1]), node.get("translation", [0, 0, 0])
            fwd, up = quat_rotate(q, (0, 0, -1)), quat_rotate(q, (0, 1, 0))
            yfov = g["cameras"][node["camera"]]["perspective"]["yfov"]
            d["sensor"] = {
                "type": "perspective", "fov": math.degrees(yfov), "fov_axis": "y",
                "to_world": mi.ScalarTransform4f().look_at(origin=t, target=[t[k] + fwd[k] for k in range(3)], up=up),
                "film": {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"}},
                "sampler": {"type": "independent", "sample_count": spp},
            }
        if "mesh" not in node:
            continue
        assert "scale" not in node and "children" not in node, "only translated and rotated nodes are supported"
        q, t = node.get("rotation", [0, 0, 0, 1]), node.get("translation", [0, 0, 0])
        for p, prim in enumerate(g["meshes"][node["mesh"]]["primitives"]):
            pos = [tuple(r[k] + t[k] for k in range(3)) for r in (quat_rotate(q, v) for v in accessor(g, blob, prim["attributes"]["POSITION"]))]
            ply = os.path.join(tmp, "mesh%d_%d.ply" % (n, p))
            write_ply(ply, pos, accessor(g, blob, prim["indices"]))
            m = g["materials"][prim["material"]]
            pbr = m.get("pbrMetallicRoughness", {})
            assert pbr.get("metallicFactor", 1.0) == 0.0 and "extensions" not in m or \
                "KHR_materials_emissive_strength" in m.get("extensions", {}), "only diffuse and emissive materials"
            shape = {"type": "ply", "filename": ply, "face_normals": True,
                     "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": pbr.get("baseColorFactor", [1, 1, 1])[:3]}}}
            strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
            emission = [c * strength for c in m.get("emissiveFactor", [0, 0, 0])]
            if max(emission) > 0:
                shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": emission}}
            d["shape%d_%d" % (n, p)] = shape
    return d


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--height", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--out", help="write the last render to this EXR")
    args = ap.parse_args()
    global mi
    import mitsuba as mi
    import drjit as dr
    mi.set_variant(args.variant)
    with tempfile.TemporaryDirectory() as tmp:
        scene = mi.load_dict(scene_dict(args.scene, args.width, args.height, args.spp, args.max_depth, tmp))
    rates, cpu_rates = [], []
    paths = args.width * args.height * args.spp
    for run in range(args.runs + 1):
        t0, c0 = time.perf_counter(), time.process_time()
        img = mi.render(scene, spp=args.spp, seed=run)
        dr.eval(img)
        dr.sync_thread()
        ms, cpu_s = (time.perf_counter() - t0) * 1e3, time.process_time() - c0
        if run > 0:
            rates.append(paths / (ms * 1e-3))
            cpu_rates.append(paths / cpu_s)
            print("run %d: %.1f ms, %.1f ms CPU, %.3f M paths/s" % (run, ms, cpu_s * 1e3, rates[-1] * 1e-6), file=sys.stderr)
    if args.out:
        mi.util.write_bitmap(args.out, img)
    print("mitsuba %s %s | %s %dx%d | %d spp | depth %d | median of %d runs: %.3f M paths/s (min %.3f, max %.3f), "
          "%.3f M paths per CPU second" % (
              mi.__version__, args.variant, args.scene, args.width, args.height, args.spp, args.max_depth, args.runs,
              statistics.median(rates) * 1e-6, min(rates) * 1e-6, max(rates) * 1e-6, statistics.median(cpu_rates) * 1e-6))


if __name__ == "__main__":
    main()
