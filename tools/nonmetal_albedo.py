#!/usr/bin/env python3
"""Directional albedo of the glTF non-metal (metallic 0, IOR 1.5) under three models, to tell the
model difference between restir-pt and Mitsuba 3 from a bug (docs/independent-check.md):

- the glTF 2.0 specification (Appendix B): fresnel_mix with Schlick's F at each pair's |v.h|,
  (1 - F) base/pi + F D V, GGX D with alpha = roughness^2, height-correlated Smith V;
- restir-pt as docs/materials.md states it: the same terms with F taken at |cos_o|
  (a re-derivation here, not restir-pt's code);
- Mitsuba 3's `principled` (metallic 0, specular 0.5, i.e. eta 1.5), sampled through Mitsuba.

The albedo is what a convex surface of that material shows in a uniform environment of radiance 1.

    python3 tools/nonmetal_albedo.py
"""
import math

import numpy as np


def gltf_albedo(base, roughness, cos_o, fresnel_at_view, n=400_000, seed=1):
    """Albedo per channel by uniform hemisphere sampling of the incident direction."""
    rng = np.random.default_rng(seed)
    a2 = roughness ** 4
    v = np.array([math.sqrt(1 - cos_o ** 2), 0.0, cos_o])
    z = rng.random(n)
    r, phi = np.sqrt(1 - z * z), 2 * math.pi * rng.random(n)
    l = np.stack([r * np.cos(phi), r * np.sin(phi), z], 1)
    h = l + v
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    c = cos_o if fresnel_at_view else np.abs(h @ v)
    f_schlick = 0.04 + 0.96 * (1 - c) ** 5
    d = a2 / (math.pi * (h[:, 2] ** 2 * (a2 - 1) + 1) ** 2)
    nl = l[:, 2]
    vis = 0.5 / (nl * np.sqrt(cos_o ** 2 * (1 - a2) + a2) + cos_o * np.sqrt(nl ** 2 * (1 - a2) + a2))
    return np.array([np.mean(((1 - f_schlick) * b / math.pi + f_schlick * d * vis) * nl) * 2 * math.pi for b in base])


def mitsuba_albedo(base, roughness, cos_o, n=40_000, seed=1):
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    rng = np.random.default_rng(seed)
    bsdf = mi.load_dict({"type": "principled", "base_color": {"type": "rgb", "value": list(base)},
                         "roughness": roughness, "metallic": 0.0})
    si = mi.SurfaceInteraction3f()
    si.wi = mi.Vector3f(math.sqrt(1 - cos_o ** 2), 0, cos_o)
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    ctx, total = mi.BSDFContext(), np.zeros(3)
    for _ in range(n):
        _, weight = bsdf.sample(ctx, si, rng.random(), mi.Point2f(rng.random(), rng.random()))
        total += np.array(weight)
    return total / n


def main():
    print("| base colour | roughness | cos_o | glTF specification | restir-pt (materials.md) | Mitsuba principled |")
    print("|---|---|---|---|---|---|")
    fmt = lambda v: "(" + ", ".join("%.3f" % x for x in v) + ")"
    for base, roughness, cos_o in [((1, 1, 1), 1.0, 0.894), ((0.30, 0.45, 0.68), 1.0, 0.894),
                                   ((0.30, 0.45, 0.68), 1.0, 0.45), ((0.6, 0.5, 0.12), 0.5, 0.8),
                                   ((0.6, 0.5, 0.12), 0.5, 0.3)]:
        print("| %s | %.1f | %.3f | %s | %s | %s |" % (
            fmt(base), roughness, cos_o, fmt(gltf_albedo(base, roughness, cos_o, False)),
            fmt(gltf_albedo(base, roughness, cos_o, True)), fmt(mitsuba_albedo(base, roughness, cos_o))))


if __name__ == "__main__":
    main()
