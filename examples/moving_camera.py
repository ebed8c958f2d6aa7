"""The README's moving-camera chart from Python: relMSE of the last of N frames along a
scene's camera path against GPU ms per frame, for the path tracer and ReSTIR PT with and
without spatial reuse, at equal time budgets (docs/results/motion-veach-door-8).

    python examples/moving_camera.py                       # the README's veach-door, 8 frames
    python examples/moving_camera.py --size 32 --trials 1 --reference-spp 256   # a quick look

Steps: a path-traced reference of the camera the last frame sees, then `compare`'s
equal-time sweep (the CLI's own), then a log-log chart with one standard error per point.
Writes OUT_DIR/reference.exr, OUT_DIR/results.csv (and compare's own charts) and
OUT_DIR/moving_camera.png; prints the rows. Needs matplotlib.
"""

import argparse
import os
from pathlib import Path

import restir_pt

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default=str(ROOT / "scenes" / "veach-door.gltf"))
    parser.add_argument("--size", type=int, default=128, help="image width and height")
    parser.add_argument("--frames", type=int, default=8)
    parser.add_argument("--trials", type=int, default=8, help="runs per point (mean relMSE, its standard error)")
    parser.add_argument("--reference-spp", type=int, default=4096)
    parser.add_argument("--methods", default="pt,restir,restir@s0")
    parser.add_argument("--budgets-ms", default=None, help="comma-separated; default: compare's own")
    parser.add_argument("--out-dir", default="out/python/moving-camera")
    args = parser.parse_args(argv)

    out = Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    device = restir_pt.Device()
    scene = restir_pt.Scene(args.scene)
    last_camera = restir_pt.camera_on_path(0, args.frames - 1, len(scene.cameras))
    reference = out / "reference.exr"
    restir_pt.reference(device.upload(scene), spp=args.reference_spp, width=args.size, height=args.size,
                        camera=last_camera, out=reference)
    budgets = [float(b) for b in args.budgets_ms.split(",")] if args.budgets_ms else None
    rows = restir_pt.compare(args.scene, reference, methods=args.methods.split(","), budgets_ms=budgets,
                             frames=args.frames, camera_path=True, trials=args.trials, out_dir=out)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.5))
    for method in dict.fromkeys(r["method"] for r in rows):
        mine = sorted((r for r in rows if r["method"] == method), key=lambda r: r["gpu_ms_per_frame"])
        ax.errorbar([r["gpu_ms_per_frame"] for r in mine], [r["rel_mse"] for r in mine],
                    yerr=[r["rel_mse_stderr"] or 0.0 for r in mine], marker="o", capsize=3, label=method)
    ax.set(xscale="log", yscale="log", xlabel="GPU ms per frame", ylabel="relMSE of the last frame",
           title=f"{Path(args.scene).stem}, {args.frames} moving frames, {args.size}x{args.size}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    chart = out / "moving_camera.png"
    fig.savefig(chart, dpi=120, bbox_inches="tight")
    for r in rows:
        print(f"{r['method']}: {r['knob']}, {r['gpu_ms_per_frame']:.1f} GPU ms per frame, relMSE {r['rel_mse']:.4g}")
    print(f"wrote {chart}")
    return rows


if __name__ == "__main__":
    main()
