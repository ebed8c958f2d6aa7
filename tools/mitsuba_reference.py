#!/usr/bin/env python3
"""Render a glTF file with Mitsuba 3 as an independent reference for restir-pt, and write its image
statistics (docs/independent-check.md).

The file is read here with pygltflib and numpy, not by restir-pt, so that a loader bug of either
side shows as a difference. The scene is what restir-pt renders for that file:

- meshes: every triangle primitive (lists, strips, fans; indexed or not; sparse accessors) of the
  scene's node tree, in world space, with NORMAL and the texture coordinate set the material's
  textures use; a mirroring node transform reverses the winding, as glTF asks;
- materials: glTF metallic-roughness as Mitsuba's `principled` BSDF (base_color, metallic,
  roughness; eta from KHR_materials_ior, spec_trans from KHR_materials_transmission), with
  textures as `bitmap`s: the base colour (sRGB, decoded here, times baseColorFactor), the
  metallic-roughness texture split into its B (metallic) and G (roughness) channels times their
  factors, KHR_texture_transform as the bitmap's `to_uv`, the sampler's wrap mode and filter;
  normalTexture through the `normalmap` BSDF (x and y scaled by `scale`); a non-metal with
  KHR_materials_specular specularFactor 0 (restir-pt's exact Lambertian) as `diffuse`;
- emission: emissiveFactor x KHR_materials_emissive_strength x emissiveTexture (sRGB) as an
  `area` emitter's radiance;
- lights and camera as restir-pt defaults them (docs/scenes.md): the constant environment of the
  scene's or the root's extras, else radiance 1 when the file has no emissive triangle and no
  punctual light; the first perspective camera in scene order, else the default camera that looks
  at the centre of the triangles' bounds along -(0, 1, 2)/sqrt(5) from r / sin(22.5 deg), yfov 45;
- the `path` integrator with restir-pt's --max-depth (segments; 1 = emitters seen directly), a
  box pixel filter (restir-pt jitters uniformly inside each pixel).

The image is rendered in `--passes` independent passes of spp / passes samples (seeds 0, 1, ...).
The JSON holds the settings, the mean RGB of the image and of each tile of a `--tiles` x `--tiles`
grid (row-major from the top-left), and each mean's standard error over the passes, so that a test
can tell Monte Carlo noise from a real difference.

    pip install mitsuba pygltflib numpy pillow
    python3 tools/mitsuba_reference.py ../shared/assets/BoxTextured/BoxTextured.gltf \\
        --width 64 --height 64 --spp 1024 --out out/mitsuba/BoxTextured.exr \\
        --json tests/data/independent/BoxTextured.json
"""
import argparse
import json
import math
import os
import sys
import time

import numpy as np
from gltf_reader import (GL_CLAMP, GL_MIRROR, GL_NEAREST, GL_REPEAT, Gltf, add_sun, make_emissive,
                         make_lambertian, scene_nodes, srgb_to_linear, texture_transform, triangle_indices, warn)

DEFAULT_VIEW = np.array([0.0, 1.0, 2.0]) / math.sqrt(5.0)
DEFAULT_YFOV = math.pi / 4


class Materials:
    """glTF materials as Mitsuba BSDF and emitter dicts."""

    def __init__(self, doc, mi):
        self.doc, self.mi = doc, mi

    def bitmap(self, info, pixels):
        """A Mitsuba bitmap texture of float `pixels` (h, w, c), already linear and multiplied by
        its factor, sampled as the glTF texture `info` says."""
        mi, g = self.mi, self.doc.g
        tex = g.textures[info.index]
        sampler = g.samplers[tex.sampler] if tex.sampler is not None else None
        wrap_s = (sampler.wrapS if sampler and sampler.wrapS else GL_REPEAT)
        wrap_t = (sampler.wrapT if sampler and sampler.wrapT else GL_REPEAT)
        if wrap_s != wrap_t:
            warn("texture %d: wrapS %d and wrapT %d differ; Mitsuba has one wrap mode, wrapS is used"
                 % (info.index, wrap_s, wrap_t))
        nearest = sampler is not None and sampler.magFilter == GL_NEAREST
        _, m = texture_transform(info)
        return {
            "type": "bitmap", "bitmap": mi.Bitmap(np.ascontiguousarray(pixels, np.float32)), "raw": True,
            "filter_type": "nearest" if nearest else "bilinear",
            "wrap_mode": {GL_REPEAT: "repeat", GL_CLAMP: "clamp", GL_MIRROR: "mirror"}[wrap_s],
            "to_uv": mi.ScalarTransform3f(m.tolist()),
        }

    def image(self, info):
        return self.doc.image_rgba(self.doc.g.textures[info.index].source)

    def uv_set(self, m):
        """The texture coordinate set this material's textures use (Mitsuba meshes have one)."""
        pbr = m.pbrMetallicRoughness
        infos = [i for i in (pbr and pbr.baseColorTexture, pbr and pbr.metallicRoughnessTexture,
                             m.emissiveTexture, m.normalTexture) if i is not None]
        sets = sorted({texture_transform(i)[0] for i in infos})
        if len(sets) > 1:
            warn("material %r: textures use coordinate sets %s; set %d is used for all" % (m.name, sets, sets[0]))
        return sets[0] if sets else 0

    def bsdf(self, m):
        """The BSDF dict of glTF material `m` (None: the glTF default material)."""
        if m is None:
            return {"type": "twosided", "bsdf": {"type": "principled", "base_color": {"type": "rgb", "value": [1, 1, 1]},
                                                 "metallic": 1.0, "roughness": 1.0}}
        pbr = m.pbrMetallicRoughness
        ext = m.extensions or {}
        factor = np.array(pbr.baseColorFactor if pbr and pbr.baseColorFactor else [1, 1, 1, 1], np.float64)
        metallic = pbr.metallicFactor if pbr and pbr.metallicFactor is not None else 1.0
        roughness = pbr.roughnessFactor if pbr and pbr.roughnessFactor is not None else 1.0
        if pbr and pbr.baseColorTexture is not None:
            rgb = srgb_to_linear(self.image(pbr.baseColorTexture)[:, :, :3]) * factor[:3].astype(np.float32)
            base = self.bitmap(pbr.baseColorTexture, rgb)
        else:
            base = {"type": "rgb", "value": factor[:3].tolist()}
        mr_tex = pbr.metallicRoughnessTexture if pbr else None
        specular = ext.get("KHR_materials_specular", {})
        if specular.get("specularFactor", 1.0) == 0.0 and metallic == 0.0 and mr_tex is None \
                and "KHR_materials_transmission" not in ext:
            bsdf = {"type": "diffuse", "reflectance": base}
        else:
            bsdf = {"type": "principled", "base_color": base, "metallic": metallic, "roughness": roughness,
                    "eta": ext.get("KHR_materials_ior", {}).get("ior", 1.5)}
            if mr_tex is not None:
                texels = self.image(mr_tex)
                bsdf["metallic"] = self.bitmap(mr_tex, texels[:, :, 2:3] * metallic)
                bsdf["roughness"] = self.bitmap(mr_tex, texels[:, :, 1:2] * roughness)
            if specular:
                warn("material %r: KHR_materials_specular other than specularFactor 0 is not mapped "
                     "(Mitsuba's principled has no specular colour)" % m.name)
            trans = ext.get("KHR_materials_transmission")
            if trans:
                bsdf["spec_trans"] = trans.get("transmissionFactor", 0.0)
                if "transmissionTexture" in trans:
                    warn("material %r: transmissionTexture ignored (the factor is used)" % m.name)
        if m.normalTexture is not None:
            n = self.image(m.normalTexture)[:, :, :3] * 2.0 - 1.0
            scale = m.normalTexture.scale if m.normalTexture.scale is not None else 1.0
            n[:, :, :2] *= scale
            n /= np.maximum(np.linalg.norm(n, axis=2, keepdims=True), 1e-8)
            bsdf = {"type": "normalmap", "normalmap": self.bitmap(m.normalTexture, (n + 1.0) * 0.5), "bsdf": bsdf}
        if m.alphaMode not in (None, "OPAQUE"):
            warn("material %r: alphaMode %s rendered opaque" % (m.name, m.alphaMode))
        if bsdf.get("spec_trans", 0.0) == 0.0:
            # restir-pt's opaque lobes reflect on whichever side the viewer is (materials.md,
            # "Sides"); Mitsuba's reflect on the front only.
            bsdf = {"type": "twosided", "bsdf": bsdf}
        if m.doubleSided and max(m.emissiveFactor or [0]) > 0:
            warn("material %r: double-sided emission; Mitsuba's area emitter emits from the front only" % m.name)
        return bsdf

    def emission(self, m):
        """The area emitter dict of material `m`, or None."""
        if m is None:
            return None
        strength = (m.extensions or {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
        e = np.array(m.emissiveFactor or [0, 0, 0], np.float64) * strength
        if "KHR_materials_unlit" in (m.extensions or {}):
            warn("material %r: KHR_materials_unlit is not mapped" % m.name)
        if e.max() <= 0.0:
            return None
        if m.emissiveTexture is not None:
            rgb = srgb_to_linear(self.image(m.emissiveTexture)[:, :, :3]) * e.astype(np.float32)
            return {"type": "area", "radiance": self.bitmap(m.emissiveTexture, rgb)}
        return {"type": "area", "radiance": {"type": "rgb", "value": e.tolist()}}


def build_meshes(doc, materials, nodes, mi):
    """Scene-dict entries of every triangle primitive, and the world bounds of their vertices."""
    g = doc.g
    entries, lo, hi = {}, np.full(3, np.inf), np.full(3, -np.inf)
    bsdfs, emitters = {}, {}
    for n_index, (node, world) in enumerate(nodes):
        if node.mesh is None:
            continue
        if node.extensions and "EXT_mesh_gpu_instancing" in node.extensions:
            warn("node %r: EXT_mesh_gpu_instancing is not expanded here" % node.name)
        normal_matrix = np.linalg.inv(world[:3, :3]).T
        mirrored = np.linalg.det(world[:3, :3]) < 0
        for p_index, prim in enumerate(g.meshes[node.mesh].primitives):
            attrs = prim.attributes
            pos = doc.accessor(attrs.POSITION)
            tris = triangle_indices(doc, prim, len(pos))
            if tris is None or len(tris) == 0:
                continue
            if mirrored:
                tris = tris[:, [0, 2, 1]]
            mat = g.materials[prim.material] if prim.material is not None else None
            uv_set = materials.uv_set(mat) if mat is not None else 0
            uv_acc = getattr(attrs, "TEXCOORD_%d" % uv_set, None)
            world_pos = pos @ world[:3, :3].T + world[:3, 3]
            lo, hi = np.minimum(lo, world_pos[tris.ravel()].min(0)), np.maximum(hi, world_pos[tris.ravel()].max(0))
            props = mi.Properties()
            if prim.material not in bsdfs:
                bsdfs[prim.material] = mi.load_dict(materials.bsdf(mat))
                em = materials.emission(mat)
                emitters[prim.material] = em
            props["bsdf"] = bsdfs[prim.material]
            if emitters[prim.material] is not None:
                props["emitter"] = mi.load_dict(emitters[prim.material])
            mesh = mi.Mesh("node%d_prim%d" % (n_index, p_index), len(pos), len(tris), props=props,
                           has_vertex_normals=attrs.NORMAL is not None, has_vertex_texcoords=uv_acc is not None)
            params = mi.traverse(mesh)
            params["vertex_positions"] = world_pos.astype(np.float32).ravel()
            if attrs.NORMAL is not None:
                nrm = doc.accessor(attrs.NORMAL) @ normal_matrix.T
                nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-12)
                params["vertex_normals"] = nrm.astype(np.float32).ravel()
            if uv_acc is not None:
                params["vertex_texcoords"] = doc.accessor(uv_acc).astype(np.float32).ravel()
            params["faces"] = tris.astype(np.uint32).ravel()
            params.update()
            entries["mesh_%d_%d" % (n_index, p_index)] = mesh
    if not entries:
        raise SystemExit("error: %s: the scene has no renderable triangles" % doc.path)
    return entries, (lo, hi)


def tan_half_fov(yfov, aspect_ratio, width, height):
    """restir-pt's Camera::tan_half_fov: an image narrower than the camera widens the view."""
    t = math.tan(0.5 * yfov)
    image_aspect = width / height
    return t * aspect_ratio / image_aspect if aspect_ratio and image_aspect < aspect_ratio else t


def sensor(doc, nodes, bounds, camera_index, args, mi):
    """The perspective sensor: the scene's camera `camera_index` (scene order), else restir-pt's
    default camera framing the bounds."""
    cams = [(n, w) for n, w in nodes if n.camera is not None
            and doc.g.cameras[n.camera].type == "perspective"]
    if camera_index < len(cams):
        node, world = cams[camera_index]
        persp = doc.g.cameras[node.camera].perspective
        eye = world[:3, 3]
        fwd = world[:3, :3] @ np.array([0, 0, -1.0])
        up = world[:3, :3] @ np.array([0, 1.0, 0])
        yfov, aspect = persp.yfov, persp.aspectRatio
    else:
        lo, hi = bounds
        centre, radius = 0.5 * (lo + hi), max(0.5 * np.linalg.norm(hi - lo), 1e-6)
        eye = centre + DEFAULT_VIEW * radius / math.sin(0.5 * DEFAULT_YFOV)
        fwd, up, yfov, aspect = centre - eye, np.array([0, 1.0, 0]), DEFAULT_YFOV, 1.0
    t = tan_half_fov(yfov, aspect, args.width, args.height)
    return {
        "type": "perspective", "fov_axis": "y", "fov": math.degrees(2 * math.atan(t)),
        "to_world": mi.ScalarTransform4f().look_at(origin=eye.tolist(), target=(eye + fwd).tolist(), up=up.tolist()),
        "film": {"type": "hdrfilm", "width": args.width, "height": args.height, "rfilter": {"type": "box"},
                 "pixel_format": "rgb"},
        "sampler": {"type": "independent", "sample_count": args.spp // args.passes},
    }


def punctual_lights(doc, nodes, mi):
    defs = ((doc.g.extensions or {}).get("KHR_lights_punctual") or {}).get("lights", [])
    out = {}
    for k, (node, world) in enumerate(nodes):
        ext = (node.extensions or {}).get("KHR_lights_punctual")
        if ext is None:
            continue
        light = defs[ext["light"]]
        value = (np.array(light.get("color", [1, 1, 1])) * light.get("intensity", 1.0)).tolist()
        pos = world[:3, 3]
        direction = world[:3, :3] @ np.array([0, 0, -1.0])
        direction /= np.linalg.norm(direction)
        kind = light["type"]
        if kind == "point":
            out["light%d" % k] = {"type": "point", "position": pos.tolist(), "intensity": {"type": "rgb", "value": value}}
        elif kind == "directional":
            out["light%d" % k] = {"type": "directional", "direction": direction.tolist(),
                                  "irradiance": {"type": "rgb", "value": value}}
        elif kind == "spot":
            spot = light.get("spot", {})
            warn("spot light %d: Mitsuba's falloff between the cone angles differs from the extension's" % k)
            up = [0, 1, 0] if abs(direction[1]) < 0.9 else [1, 0, 0]
            out["light%d" % k] = {
                "type": "spot", "intensity": {"type": "rgb", "value": value},
                "cutoff_angle": math.degrees(spot.get("outerConeAngle", math.pi / 4)),
                "beam_width": math.degrees(spot.get("innerConeAngle", 0.0)),
                "to_world": mi.ScalarTransform4f().look_at(origin=pos.tolist(), target=(pos + direction).tolist(), up=up)}
    return out


def environment(doc, scene_index):
    g = doc.g
    scene = g.scenes[scene_index if scene_index is not None else (g.scene or 0)]
    for extras in (scene.extras, g.extras):
        if isinstance(extras, dict) and "environment" in extras:
            return [float(c) for c in extras["environment"]]
    return [0.0, 0.0, 0.0]


def tile_means(img, tiles):
    """Mean RGB of each tile of a tiles x tiles grid, row-major from the top-left, (tiles^2, 3)."""
    h, w, _ = img.shape
    out = []
    for ty in range(tiles):
        for tx in range(tiles):
            block = img[ty * h // tiles:(ty + 1) * h // tiles, tx * w // tiles:(tx + 1) * w // tiles, :3]
            out.append(block.reshape(-1, 3).mean(0))
    return np.array(out)


def statistics(passes, tiles):
    """Means and standard errors over independent equal-spp passes, (h, w, 3) each."""
    p = len(passes)
    whole = np.array([img[:, :, :3].reshape(-1, 3).mean(0) for img in passes])
    grid = np.array([tile_means(img, tiles) for img in passes])
    se = (lambda a: (a.std(0, ddof=1) / math.sqrt(p)) if p > 1 else np.full(a.shape[1:], np.nan))
    return {
        "mean_rgb": whole.mean(0).tolist(), "mean_rgb_se": se(whole).tolist(),
        "tile_mean_rgb": grid.mean(0).tolist(), "tile_mean_rgb_se": se(grid).tolist(),
    }


def read_exr(path):
    import mitsuba as mi
    if not mi.variant():
        mi.set_variant("scalar_rgb")
    return np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False), np.float32)


def compare(exr, json_path):
    """Prints an EXR's tile means beside a reference JSON's, with the differences in standard errors."""
    ref = json.load(open(json_path))
    img = read_exr(exr)
    tiles = ref["settings"]["tiles"]
    ours, theirs = tile_means(img, tiles), np.array(ref["tile_mean_rgb"])
    se = np.array(ref["tile_mean_rgb_se"])
    print("mean RGB: this %s, reference %s, ratio %s" % (
        np.round(img[:, :, :3].reshape(-1, 3).mean(0), 4), np.round(ref["mean_rgb"], 4),
        np.round(img[:, :, :3].reshape(-1, 3).mean(0) / np.maximum(ref["mean_rgb"], 1e-9), 3)))
    for k in range(tiles * tiles):
        print("tile %2d: this %s reference %s ratio %s ref SE %s" % (
            k, np.round(ours[k], 4), np.round(theirs[k], 4), np.round(ours[k] / np.maximum(theirs[k], 1e-9), 3),
            np.round(se[k], 4)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("gltf", help="glTF 2.0 file (.gltf or .glb); with --compare, an EXR")
    ap.add_argument("--compare", metavar="JSON", help="print the tile means of the EXR given as gltf beside this JSON's")
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--width", type=int, default=64)
    ap.add_argument("--height", type=int, default=64)
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--passes", type=int, default=8, help="independent passes (for the standard errors)")
    ap.add_argument("--max-depth", type=int, default=7, help="path segments, as restir-pt's --max-depth")
    ap.add_argument("--camera", type=int, default=0)
    ap.add_argument("--scene", type=int, default=None)
    ap.add_argument("--tiles", type=int, default=4)
    ap.add_argument("--lambertian", action="store_true",
                    help="render every material as a Lambertian of its base colour (make_lambertian)")
    ap.add_argument("--emissive", action="store_true",
                    help="every base colour texture becomes the material's emission (make_emissive)")
    ap.add_argument("--sun", metavar="DX,DY,DZ,E,ENV",
                    help="add a directional light along (DX, DY, DZ) of irradiance E and a constant environment ENV")
    ap.add_argument("--out", help="EXR of the image (all passes)")
    ap.add_argument("--json", help="image statistics")
    args = ap.parse_args()
    if args.compare:
        compare(args.gltf, args.compare)
        return
    if args.spp % args.passes:
        raise SystemExit("error: --spp %d is not a multiple of --passes %d" % (args.spp, args.passes))
    import mitsuba as mi
    mi.set_variant(args.variant)
    edits = ([make_lambertian] if args.lambertian else []) + ([make_emissive] if args.emissive else []) + (
        [add_sun((lambda v: (v[:3], v[3], v[4]))([float(x) for x in args.sun.split(",")])[0],
                 *[float(x) for x in args.sun.split(",")][3:5])] if args.sun else [])
    doc = Gltf(args.gltf, edits)
    nodes = scene_nodes(doc, args.scene)
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": args.max_depth}}
    meshes, bounds = build_meshes(doc, Materials(doc, mi), nodes, mi)
    scene.update(meshes)
    scene["sensor"] = sensor(doc, nodes, bounds, args.camera, args, mi)
    lights = punctual_lights(doc, nodes, mi)
    scene.update(lights)
    env = environment(doc, args.scene)
    has_emitter = any(m.emitter() is not None for m in meshes.values())
    if max(env) <= 0 and not lights and not has_emitter:
        env = [1.0, 1.0, 1.0]
        warn("no light in the file: a uniform environment of radiance 1, as restir-pt uses")
    if max(env) > 0:
        scene["environment"] = {"type": "constant", "radiance": {"type": "rgb", "value": env}}
    loaded = mi.load_dict(scene)
    t0 = time.perf_counter()
    passes = [np.array(mi.render(loaded, seed=k), np.float32) for k in range(args.passes)]
    seconds = time.perf_counter() - t0
    image = np.mean(passes, axis=0)
    if not np.isfinite(image).all():
        raise SystemExit("error: %s: Mitsuba's image has non-finite pixels" % args.gltf)
    if args.out:
        os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
        mi.Bitmap(image).write(args.out)
    stats = {
        "source": os.path.relpath(os.path.abspath(args.gltf)),
        "renderer": "mitsuba %s %s, path integrator" % (mi.__version__, args.variant),
        "settings": {"width": args.width, "height": args.height, "spp": args.spp, "passes": args.passes,
                     "max_depth": args.max_depth, "camera": args.camera, "tiles": args.tiles,
                     "environment": env, "lambertian": args.lambertian, "emissive": args.emissive, "sun": args.sun},
        "command": "python3 tools/mitsuba_reference.py " + " ".join(sys.argv[1:]),
        "render_seconds": round(seconds, 1),
    }
    stats.update(statistics(passes, args.tiles))
    text = json.dumps(stats, indent=1)
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
        with open(args.json, "w") as f:
            f.write(text + "\n")
    print("mean RGB %s (SE %s), %.1f s" % (np.round(stats["mean_rgb"], 4), np.round(stats["mean_rgb_se"], 5), seconds))


if __name__ == "__main__":
    main()
